"""The verifier accepts the published certificates and rejects every tampering with a reason."""

import copy
import json

import pytest

from ccproof.certify import verify as V
from ccproof.certify.verify import interval as I
from ccproof.certify.verify import maps as M
from ccproof.certify.verify import replay as R
from ccproof.certify.verify import statement as St
from ccproof.tables.format import certificates_dir

CERTS = certificates_dir() / "injectivity"


def load(k):
    return json.loads((CERTS / f"k{k:03d}.json").read_text())


def run(cert):
    lines = []
    res = V.verify_certificate(cert, log=lines.append)
    return res.ok, "\n".join(lines + [res.error or ""])


@pytest.fixture(scope="module")
def cert3():
    return load(3)


def test_published_certificate_verifies(cert3):
    ok, log = run(cert3)
    assert ok, log
    assert log.count("PASS") >= 6 and "FAIL" not in log


def test_box_removed(cert3):
    c = copy.deepcopy(cert3)
    key = next(iter(c["parts"]["cells"]))
    del c["parts"]["cells"][key]
    ok, log = run(c)
    assert not ok and f"D cell {key}" in log and "not in the certificate" in log


def test_box_removed_from_a_split_part(cert3):
    c = copy.deepcopy(cert3)
    c["parts"]["regularity"]["P2"] = [{"path": "0L", "bound": "0.001"}]
    ok, log = run(c)
    assert not ok and "do not partition" in log


def test_overlapping_boxes(cert3):
    c = copy.deepcopy(cert3)
    boxes = c["parts"]["corner"]["P2"]
    boxes.append({"path": boxes[0]["path"] + "2L", "bound": "0.001"})
    ok, log = run(c)
    assert not ok and "do not partition" in log


def test_bound_raised_above_true_minimum(cert3):
    c = copy.deepcopy(cert3)
    # the minimum of det J_G / h^2 on the corner is about 0.132 for k = 3 (docs/readings.md R9; the float
    # sampling in test_prover shows the certified bound is within 0.01 of it): claim 0.2 everywhere
    for name in c["parts"]["corner"]:
        for b in c["parts"]["corner"][name]:
            b["bound"] = "0.2"
    ok, log = run(c)
    assert not ok and "not above the claimed bound 0.2" in log


def test_nonpositive_bound_rejected(cert3):
    c = copy.deepcopy(cert3)
    c["parts"]["regularity"]["P3"][0]["bound"] = "-1"
    ok, log = run(c)
    assert not ok and "non-positive bound" in log


def test_N_lowered_to_three_for_k8():
    c = load(8)
    assert c["N"] == 4
    c["N"] = 3
    ok, log = run(c)
    assert not ok and "FAIL  A corner cell maps into [0,1/6)^2" in log


@pytest.mark.parametrize(
    "mutate, reason",
    [
        (lambda c: c.update(schema="ccproof.injectivity/0"), "unknown certificate schema"),
        (lambda c: c.update(schema="ccproof.injectivity/1"), "unknown certificate schema"),  # old format: has a table
        (lambda c: c.pop("parts"), "missing field"),
        (lambda c: c.update(valence="5"), "wrong type"),
        (lambda c: c["parts"]["corner"]["P2"][0].update(path="9Q"), "malformed box path"),
        (lambda c: c["parts"]["corner"]["P2"][0].update(bound="1/3"), "not a decimal string"),
        (lambda c: c.update(summary={"min_bound_det_J_phi_local": "1"}), "unknown field"),
        (lambda c: c.update(table={"hash": "sha256:0"}), "unknown field"),
        (lambda c: c["parts"].update(extra={}), "unknown field"),
    ],
)
def test_malformed_certificates(cert3, mutate, reason):
    c = copy.deepcopy(cert3)
    mutate(c)
    res = V.verify_certificate(c, log=lambda s: None)
    assert not res and reason in res.error


def test_verify_file_names_the_failure(cert3, tmp_path, capsys):
    c = copy.deepcopy(cert3)
    c["parts"]["corner"]["P3"][0]["bound"] = "5"
    p = tmp_path / "k003.json"
    p.write_text(json.dumps(c))
    assert not V.verify_file(p)
    out = capsys.readouterr().out
    assert "FAILED" in out and "VERIFIED" not in out and "corner P3" in out
    p.write_text("{")
    assert not V.verify_file(p)
    assert "not a readable certificate" in capsys.readouterr().out


def test_partition_checker():
    assert R.check_partition([""], 2)
    assert R.check_partition(["0L", "0H1L", "0H1H"], 2)
    assert not R.check_partition(["0L", "0H1L"], 2)  # gap
    assert not R.check_partition(["0L", "0L1L", "0H"], 2)  # overlap
    assert not R.check_partition(["0L", "1H"], 2)  # different axes at one node
    assert not R.check_partition(["0L", "0L"], 2)  # duplicate


def test_weight_is_the_bspline_sum_R5():
    """b = 1 - 36x^3 near 0, C2 at 1/6 and 1/3, zero with two derivatives at 1/2."""
    from flint import fmpq

    b = [M.weight_piece(p) for p in range(3)]
    assert b[0](fmpq(0)) == 1 and b[0](fmpq(1, 12)) == 1 - fmpq(36, 12**3)
    for p, x in ((0, fmpq(1, 6)), (1, fmpq(1, 3))):
        f, g = b[p], b[p + 1]
        for _ in range(3):
            assert f(x) == g(x)
            f, g = f.derivative(), g.derivative()
    d = b[2].derivative()
    assert b[2](fmpq(1, 2)) == 0 and d(fmpq(1, 2)) == 0 and d.derivative()(fmpq(1, 2)) == 0


def test_every_valence_3_to_39_has_a_certificate():
    ks = sorted(json.loads(p.read_text())["valence"] for p in CERTS.glob("k[0-9]*.json"))
    assert ks == list(range(3, 40))


@pytest.mark.slow
def test_verify_all_published_certificates():
    from ccproof.cli import main

    assert main(["verify", "--all", "--quiet"]) == 0


# ---------------------------------------------------------------- C1 (Reif) certificates
C1 = certificates_dir() / "c1"


def test_c1_certificates_cover_every_valence_once():
    vals = [json.loads(p.read_text())["valence"] for p in C1.glob("k*.json")]
    ok, msg = V.check_coverage(vals)
    assert ok, msg
    assert not V.check_coverage([v for v in vals if v != 17])[0]  # gap
    assert not V.check_coverage(vals + [17])[0]  # a single valence twice
    assert V.check_coverage(vals + [45])[0]  # overlaps with an interval are accepted (proved twice)
    assert V.check_coverage(vals + [{"min": 30}])[0]  # ... and so are overlapping intervals
    assert not V.check_coverage([v for v in vals if v != 35] + [{"min": 36}])[0]  # 35 is now missing
    assert not V.check_coverage([v for v in vals if isinstance(v, int)])[0]  # no tail


@pytest.mark.parametrize("name", ["k003.json", "k005.json", "k_ge_40.json"])
def test_c1_certificate_verifies(name):
    lines = []
    assert V.verify_certificate(json.loads((C1 / name).read_text()), log=lines.append), lines


def test_c1_tampering_rejected():
    c = json.loads((C1 / "k_ge_40.json").read_text())
    bad = copy.deepcopy(c)
    bad["pieces"][0]["parts"]["star"]["P2s1"][0]["bound"] = "0.9"
    lines = []
    assert not V.verify_certificate(bad, log=lines.append)
    assert any("FAIL  [piece 0] outer boundary star-shaped on P2s1" in s for s in lines)
    bad = copy.deepcopy(c)
    bad["valence"] = {"min": 30}  # widen the interval: lam(30) is not in the pieces, the claim is not established
    lines = []
    assert not V.verify_certificate(bad, log=lines.append)
    assert any("FAIL  lam(k) in" in s for s in lines)
    bad["valence"] = {"min": 3}  # the mode-0 argument for all k >= k0 does not hold from k0 = 3
    lines = []
    assert not V.verify_certificate(bad, log=lines.append)
    assert any("FAIL  spectral ordering" in s and "mode-0" in s for s in lines)


def _compose(b, X):
    """b(X) for an fmpq_poly b and a Poly X (Horner)."""
    from ccproof.certify.poly import Poly

    c = b.coeffs()
    acc = Poly.constant(c[-1], X.nvars, X.prec)
    for a in c[-2::-1]:
        acc = acc * X + a
    return acc


def cell_det_poly(nets, lam, N, l, m, p, q, prec):
    """det dG/d(s,t) on cell (l, m) for the w piece (p, q), directly on the cell's own restricted nets (not
    from one form per piece restricted, as the verifier does); G = w y + (1 - w) Phi (docs/readings.md R6)."""
    from flint import ctx, fmpq

    from ccproof.certify.poly import Poly, to_poly
    from ccproof.rigorous import BernsteinForm, jacobian_determinant

    i, name, box = M.cell_geometry(l, m, N)
    with ctx.workprec(prec):
        li = lam**i
        X, Y = (to_poly(BernsteinForm((4, 4), M.net_form(nets[name], d, prec).restrict(box).coeffs, prec=prec)) * li
                for d in range(2))  # the cell's restricted net, relabelled as the unit box
        s, t = Poly.variable(0, 2), Poly.variable(1, 2)
        y1, y2 = (s + l) * fmpq(1, 2**N), (t + m) * fmpq(1, 2**N)
        w = _compose(M.weight_piece(p), X) * _compose(M.weight_piece(q), Y)
        return jacobian_determinant([X + w * (y1 - X), Y + w * (y2 - Y)])


def test_the_direct_cell_determinant_is_4_to_the_minus_N_for_the_identity_map():
    from flint import arb

    nets, lam = St.nets_for_valence(4, 64), St.c_lam(4, 64)[1]  # k = 4: Phi is the identity, lam = 1/2
    assert cell_det_poly(nets, lam, 1, 1, 0, 2, 2, 64).coeffs[0].overlaps(arb(1) / 4)


# ---------------------------------------------------------------- mirror symmetry (parts B, D, E)
def test_mirror_symmetry_of_the_exact_nets_and_its_consequence():
    from flint import ctx

    from ccproof.certify.poly import bernstein_coefficients

    assert St.derivation().symmetric
    # consequence, checked on the determinants themselves: the Bernstein form of det J_G on the mirrored
    # cell (m, l) with piece (q, p) is the transpose of that on (l, m) with (p, q)
    with ctx.workprec(128):
        nets = St.nets_for_valence(5, 128)
        lam = St.c_lam(5, 128)[1]
        full = _cells(nets, lam, 3)
        half = _cells(nets, lam, 3, symmetric=True)
        assert set(half) == {c for c in full if c[0] <= c[1]}
        assert {(m, l, q, p) for l, m, p, q in full} == set(full)  # the required set itself is symmetric
        for l, m, p, q in [(0, 1, 0, 0), (1, 6, 1, 2), (2, 7, 2, 2)]:
            a = bernstein_coefficients(cell_det_poly(nets, lam, 3, l, m, p, q, 128))
            b = bernstein_coefficients(cell_det_poly(nets, lam, 3, m, l, q, p, 128))
            n0, n1 = a.shape
            assert b.shape == (n1, n0)
            for i in range(n0):
                for j in range(n1):
                    x, y = a.coeffs[i * n1 + j], b.coeffs[j * n0 + i]
                    assert x.overlaps(y) and abs(x.mid() - y.mid()) < 1e-30


def _cells(nets, lam, N, symmetric=False):
    """The (l, m, p, q) of part D for one valence, as the verifier lists them."""
    return [tuple(map(int, key.split(","))) for key, _ in I.valence_cells(nets, lam, N, 128, symmetric)]


def test_cell_forms_restricted_from_one_piece_form_equal_the_direct_cell_determinants():
    """The verifier builds det J_G once per (layer, piece, w piece) and restricts it to each cell (times
    h^2); the direct computation on the cell's own restricted nets must give the same Bernstein
    coefficients (the same polynomial in the same basis), and both balls must stay tight."""
    from flint import ctx

    from ccproof.certify.poly import bernstein_coefficients

    with ctx.workprec(128):
        nets = St.nets_for_valence(7, 128)
        lam = St.c_lam(7, 128)[1]
        builds = dict(I.valence_cells(nets, lam, 4, 128, symmetric=True))
        cells = _cells(nets, lam, 4, symmetric=True)
        layers = {M.cell_geometry(l, m, 4)[0] for l, m, _, _ in cells}
        picked = [next(c for c in cells if M.cell_geometry(c[0], c[1], 4)[0] == i) for i in sorted(layers)]
        assert len(picked) == 4  # one cell on each layer 0..3 (h = 1/8 .. 1)
        for l, m, p, q in picked + cells[-3:]:
            a = builds[f"{l},{m},{p},{q}"]()
            b = bernstein_coefficients(cell_det_poly(nets, lam, 4, l, m, p, q, 128))
            assert a.shape == b.shape
            for x, y in zip(a.coeffs, b.coeffs):
                assert x.overlaps(y) and abs(x.mid() - y.mid()) < 1e-25 and x.rad() < 1e-25, (l, m, p, q)


def test_mirrored_cells_are_not_needed_but_their_twins_are(cert3):
    c = copy.deepcopy(cert3)
    keys = list(c["parts"]["cells"])
    assert keys and all(int(k.split(",")[0]) <= int(k.split(",")[1]) for k in keys)  # only l <= m written
    twin = keys[-1]
    del c["parts"]["cells"][twin]
    ok, log = run(c)
    assert not ok and f"D cell {twin}" in log
