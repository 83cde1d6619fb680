"""The interval certificates crease:>=N0 and corner:>=N0 (ccproof/certify/verify/tagged_limit.py): H against
independent computations, the window check, forgeries, coverage and the command line."""

import copy
import json
import subprocess
import sys

import numpy as np
import pytest
from flint import acb, arb, ctx, fmpq

from ccproof.certify.verify import tagged as tg
from ccproof.certify.verify import tagged_limit as tl
from ccproof.certify.verify import tagged_modes as tm
from ccproof.certify.verify import verify_certificate
from ccproof.certify.verify.dart_spectrum import check_construction
from ccproof.certify.verify.errors import CertificateError
from ccproof.certify.verify.statement import lam_of
from ccproof.certify.verify.tagged import labels, parse_configuration
from ccproof.certify.verify.tagged_c1 import _jacobian
from ccproof.tables.format import certificates_dir

from .test_tagged import library_matrix

QUIET = {"log": lambda line: None}


def _tail(fam):
    return json.loads((certificates_dir() / "c1" / fam / "n_ge_101.json").read_text())


def _fails(cert, why):
    res = verify_certificate(cert, **QUIET)
    assert not res
    text = (res.error or "") + " ".join(p.name + ": " + p.message for p in res.failures())
    assert why in text, text


@pytest.mark.parametrize("fam", ["crease", "corner"])
def test_published_interval_certificates_verify(fam):
    res = verify_certificate(_tail(fam), **QUIET)
    assert res and res.configuration == f"{fam}:>=101"
    assert [p.name.split(":")[0].split(" ")[0] for p in res.parts] == ["S", "range", "z", "G", "B", "N", "x,", "N", "N"]


def test_parse_configuration_of_an_interval():
    assert parse_configuration("corner:>=16") == ("corner", {"min": 16})
    for bad in ("crease:>=1", "crease:>=", "crease:>= 5", "crease:>=10000000"):
        with pytest.raises(CertificateError):
            parse_configuration(bad)


@pytest.mark.parametrize("fam,n", [("crease", 40), ("corner", 101), ("crease", 150)])
def test_h_is_the_per_n_verifiers_jacobian(fam, n):
    """H(pi/N) against J_xy of the per-N route (mode_vector, its own pivot and sector indexing, _jacobian):
    f(j theta) is 2 i sin(j theta) at ray 1's point (1,0), so H = -4 sin(theta) sin(2 theta) J there."""
    with ctx.workprec(128):
        at = labels(fam, n).index(("r", 1, 1, 0))
        vec = {}
        for j in (1, 2):
            f = tm.mode_vector(fam, n, j, lam_of(arb(fmpq(j, n)).cos_pi()))
            vec[j] = [v if isinstance(v, fmpq) else (v / f[at]).real for v in f]
        J = _jacobian(fam, n, 0, vec[1], vec[2])
        th = arb.pi() / n
        h = tl.limit_h(acb(th))
        assert h.imag.contains(0) and abs(h.imag) < 1e-20
        assert h.real.overlaps(-4 * th.sin() * (2 * th).sin() * J)
        assert h.real > 0 and J < 0


@pytest.mark.parametrize("fam,n", [("crease", 24), ("corner", 30)])
def test_h_against_numpy_eigenvectors_of_the_library_matrix(fam, n):
    """Independent: numpy's eigenvectors of the sector matrix from the library's Sdc stencils, the tangent
    masks written here, normalized at ray 1's point (1,0)."""
    M = library_matrix(fam, n)
    vals, vecs = np.linalg.eig(M)
    order = [i for i in np.argsort(-vals.real) if abs(vals[i] - 1) > 1e-9 and abs(vals[i].imag) < 1e-12][:2]
    pts = labels(fam, n)
    at = pts.index(("r", 1, 1, 0))
    x, y = (vecs[:, i].real / vecs[at, i].real for i in order)
    assert np.allclose(vals[order].real, [float(lam_of(arb(fmpq(j, n)).cos_pi()).mid()) for j in (1, 2)])

    def grid(v, a, b):
        key = ("C",) if (a, b) == (0, 0) else ("r", 0, a, 0) if b == 0 else ("r", 1, b, 0) if a == 0 else ("q", 0, a, b)
        return v[pts.index(key)]

    w, dw = np.array([1, 4, 1]) / 6, np.array([-1, 0, 1]) / 2
    t = [[sum(da[a] * db[b] * grid(v, a, b) for a in range(3) for b in range(3)) for da, db in ((dw, w), (w, dw))]
         for v in (x, y)]
    J = t[0][0] * t[1][1] - t[0][1] * t[1][0]
    th = np.pi / n
    h = float(tl.limit_h(acb(arb.pi() / n)).real.mid())
    assert h == pytest.approx(-4 * np.sin(th) * np.sin(2 * th) * J, rel=1e-6)


def test_h_vanishes_to_order_four():
    """H(theta)/theta^4 tends to 1.37136 (and H is even: H(-theta) = H(theta))."""
    with ctx.workprec(128):
        ratios = [tl.limit_h(acb(arb.pi() / n)) / (arb.pi() / n) ** 4 for n in (101, 10**4, 10**6)]
        assert all(abs(r.real - arb("1.37136")) < 1e-3 for r in ratios)
        th = acb("0.05", "0.02")
        assert (tl.limit_h(th) - tl.limit_h(-th)).contains(0)


@pytest.mark.parametrize("fam", ["crease", "dart"])
def test_window_check_refuses_a_row_that_depends_on_n(monkeypatch, fam):
    """A middle quadrant row of fam:8 changed (not fam:7's): its window class has two rows (the crease and
    corner tails' check_windows, the dart tail's check_construction)."""
    real = tg.sector_rows
    check = check_construction if fam == "dart" else tl.check_windows

    def rows(fam, n):
        out = list(real(fam, n))
        if n == 8:
            i = labels(fam, n).index(("q", 4, 1, 1))
            row = dict(out[i])
            a, b = sorted(row)[:2]
            row[a], row[b] = row[a] + fmpq(1, 64), row[b] - fmpq(1, 64)
            out[i] = row
        return tuple(out)

    args = () if fam == "dart" else (fam,)
    monkeypatch.setattr(tg, "sector_rows", rows)
    check.cache_clear()
    with pytest.raises(CertificateError, match="window class"):
        check(*args)
    monkeypatch.undo()
    check.cache_clear()
    assert check(*args)


@pytest.mark.parametrize("prec", [63, 1025, "128"])
def test_forgery_precision_out_of_range(prec):
    """prec outside 64..1024 (or not an integer) FAILs the tail and a single tagged certificate alike."""
    one = json.loads((certificates_dir() / "c1" / "crease" / "n005.json").read_text())
    why = "prec must lie in 64..1024" if isinstance(prec, int) else "field 'prec' has the wrong type"
    for cert in (_tail("corner"), one):
        _fails(dict(cert, prec=prec), why)

def test_forgery_statement_and_family():
    cert = _tail("crease")
    _fails(dict(cert, statement="C1"), 'certified "not C1" only')
    _fails(dict(cert, configuration="dart:>=101"), 'dart:>=K0 is certified "C1" only')
    per_n = json.loads((certificates_dir() / "c1" / "crease" / "n100.json").read_text())
    _fails(dict(cert, witness=per_n["witness"]), "witness")  # a single configuration's witness: unknown keys
    _fails(dict(per_n, configuration="crease:>=101"), "missing field(s) 'limit'")  # a witness of N = 100
    _fails(dict(_tail("corner"), configuration="crease:>=101"), "no eigenvector for 1/2")  # the corner's z
    smooth = json.loads((certificates_dir() / "c1" / "k_ge_40.json").read_text())
    _fails(dict(smooth, schema=cert["schema"], configuration="crease:>=101", statement="not C1"), "unknown")


def test_forgery_range_and_radii():
    cert = _tail("crease")
    lim = cert["limit"]
    _fails(dict(cert, limit=dict(lim, rho="0.0311")), "not certainly above pi/101")  # pi/101 = 0.031104...
    _fails(dict(cert, configuration="crease:>=15"), "not certainly above pi/15")  # rho = 0.2 < pi/15
    assert verify_certificate(dict(cert, configuration="crease:>=16"), **QUIET)  # pi/16 = 0.196 < 0.2
    _fails(dict(cert, configuration="crease:>=6"), "N0 >= 7")
    _fails(dict(cert, limit=dict(lim, R="0.2")), "rho < R")
    _fails(dict(cert, limit=dict(lim, R="0.19")), "rho < R")
    _fails(dict(cert, limit=dict(lim, arcs=10**6)), "arcs must lie in 1..8192")


def test_forgery_too_few_arcs():
    cert = _tail("crease")
    _fails(dict(cert, limit=dict(cert["limit"], arcs=256)), "its image may touch 0")
    _fails(dict(cert, limit=dict(cert["limit"], outer_arcs=128)), "its image may touch 0")  # a cruder M


def test_forgery_gamma():
    cert = copy.deepcopy(_tail("crease"))
    cert["witness"]["z"]["eigenvalue"] = "0.25"  # the crease block's 1/4 is an eigenvalue, not the largest
    cert["witness"]["z"]["crease"] = ["-1", "2", "-1", "2", "-1"]
    _fails(cert, "z")
    cert["witness"]["z"]["crease"] = ["0", "0", "0", "0", "0"]
    _fails(cert, "c != 0 fails")


def test_forgery_perturbed_stencil(monkeypatch):
    """A stencil that breaks the reflection identity: refused by the identity check itself, and (a perturbed
    ring rule) already by the ring check."""
    block = tl.ring_block

    def perturbed(w):
        rows = block(w)
        rows[0][1] += w / 100  # not symmetric under w -> 1/w with the swap
        return rows

    monkeypatch.setattr(tl, "ring_block", perturbed)
    tl.reflection_identity.cache_clear()
    _fails(_tail("crease"), "breaks the reflection identity")
    monkeypatch.undo()
    tl.reflection_identity.cache_clear()
    stencil = [dict(r) for r in tm.ring_stencil()]
    stencil[3][next(iter(stencil[3]))] += fmpq(1, 32)
    monkeypatch.setattr(tm, "ring_stencil", lambda: tuple(stencil))
    tm.check_ring.cache_clear()
    tl.check_windows.cache_clear()
    tm.check_structure.cache_clear()
    _fails(_tail("corner"), "reflection")
    monkeypatch.undo()
    for f in (tm.check_ring, tl.check_windows, tm.check_structure, tl.reflection_identity):
        f.cache_clear()
    assert verify_certificate(_tail("corner"), **QUIET)


def test_verify_json_and_certify_on_the_command_line(tmp_path):
    files = [str(certificates_dir() / "c1" / fam / "n_ge_101.json") for fam in ("crease", "corner")]
    out = subprocess.run([sys.executable, "-m", "ccproof.cli", "verify", "--serial", "--json", *files],
                         capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    rows = [json.loads(s) for s in out.stdout.splitlines()]
    assert [(r["configuration"], r["statement"], r["verdict"]) for r in rows] == [
        ("crease:>=101", "not C1", "VERIFIED"), ("corner:>=101", "not C1", "VERIFIED")]
    out = subprocess.run([sys.executable, "-m", "ccproof.cli", "certify", "corner:>=101", "--c1", "--out",
                          str(tmp_path)], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    assert json.loads((tmp_path / "corner" / "n_ge_101.json").read_text()) == _tail("corner")
    out = subprocess.run([sys.executable, "-m", "ccproof.cli", "certify", "crease:>=1", "--c1", "--out",
                          str(tmp_path)], capture_output=True, text=True, timeout=300)
    assert out.returncode == 2 and "error:" in out.stderr and "N0" in out.stderr


@pytest.mark.parametrize("path,value", [
    (("limit", "rho"), 0.2), (("limit", "rho"), "-0.2"), (("limit", "rho"), "1e-400"), (("limit", "box"), "1e-30"),
    (("limit", "box"), "0"), (("limit", "arcs"), True), (("limit", "arcs"), 0), (("limit", "outer_arcs"), "512"),
    (("limit", "R"), "2"), (("limit",), []), (("limit", "extra"), 1), (("witness", "z", "crease"), ["0"] * 4),
    (("witness", "z", "crease"), [0, 0, 0, 0, 1]), (("witness", "z", "eigenvalue"), ["0.5", "0.5"]),
    (("witness", "z", "eigenvalue"), "0"), (("witness",), {"z": None}), (("prec",), 10**9),
    (("configuration",), "crease:>=99999999"), (("configuration",), "crease:>=0101x"), (("statement",), None),
])
def test_malformed_interval_records_fail_with_a_reason(path, value):
    """Hostile values in every field end in FAILED with a reason, never an exception (and at once)."""
    cert = copy.deepcopy(_tail("crease"))
    obj = cert
    for key in path[:-1]:
        obj = obj[key]
    obj[path[-1]] = value
    res = verify_certificate(cert, **QUIET)
    assert not res and (res.error or res.failures())


@pytest.mark.slow
@pytest.mark.parametrize("fam", ["crease", "corner"])
def test_the_interval_argument_alone_covers_every_n_from_seven(fam):
    """rho = 0.45 > pi/7 with R = 0.5 on a finer grid: every N >= 7 (the window's least N), about 13 s each."""
    lim = {"rho": "0.45", "R": "0.5", "arcs": 4096, "outer_arcs": 8192, "box": "0.0125"}
    res = verify_certificate(dict(_tail(fam), configuration=f"{fam}:>=7", limit=lim), **QUIET)
    assert res, res.failures()
    _fails(dict(_tail(fam), configuration=f"{fam}:>=7", limit=dict(lim, R="0.55")), "not proved regular")
