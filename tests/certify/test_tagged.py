"""Tagged configurations (dart:K, crease:N, corner:N): the trusted sector matrices against the library's
independent Sdc stencils, the certified spectrum against numpy, the "not C1" certificates against
forgeries, and a brute-force subdivision that watches the normal."""

import copy
import json
import subprocess
import sys

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from ccproof.certify.verify import TAGGED_SCHEMA, certificate_files, verify_certificate
from ccproof.certify.verify.tagged import eigenvalues, labels, sector_matrix
from ccproof.mesh.polymesh import PolyMesh
from ccproof.tables.format import certificates_dir

QUIET = {"log": lambda line: None}


# ----------------------------------------------------------------------- an independent sector matrix
def tagged_mesh(fam, n, rng=None):
    """A mesh of the configuration with 3 rings per quadrant; returns (PolyMesh, vertex id of each
    level-0 grid position (quadrant q, a, b), with (a, 0) on ray q and (0, b) on ray q + 1)."""
    rays = n if fam == "dart" else n + 1
    vid = {}

    def vertex(q, a, b):
        if a == 0 and b == 0:
            return 0
        if a == 0:
            return vertex(q + 1, b, 0)
        if b == 0:
            r = q % n if fam == "dart" else q
            return vid.setdefault(("r", r, a), len(vid) + 1)
        return vid.setdefault(("q", q, a, b), len(vid) + 1)

    faces = []
    for q in range(n):
        for a in range(3):
            for b in range(3):
                faces.append([vertex(q, a, b), vertex(q, a + 1, b), vertex(q, a + 1, b + 1), vertex(q, a, b + 1)])
    del rays
    rng = rng or np.random.default_rng(1)
    V = rng.normal(size=(len(vid) + 1, 3))
    creases = corners = None
    if fam == "dart":
        creases = {(0, vertex(0, 1, 0)): 10.0, (vertex(0, 1, 0), vertex(0, 2, 0)): 10.0,
                   (vertex(0, 2, 0), vertex(0, 3, 0)): 10.0}
    if fam == "corner":
        corners = {0: 10.0}
    return PolyMesh(V, faces, creases=creases, corners=corners), vertex


def library_matrix(fam, n):
    """The sector matrix read from the library's exact Sdc stencils (ccproof.mesh.rules), as floats."""
    mesh, vertex = tagged_mesh(fam, n)
    stencils, _, _, _ = mesh.subdivision_operator(exact=True), None, None, None
    nv = mesh.n_vertices
    edges = {}
    for f in mesh.polygons:
        for k in range(len(f)):
            e = frozenset((f[k], f[(k + 1) % len(f)]))
            edges.setdefault(e, len(edges))
    face_index = {frozenset(f): i for i, f in enumerate(mesh.polygons)}

    def child(label):  # level-1 point of a 2-ring label
        if label == ("C",):
            return 0
        kind, s, A, B = label
        q = s if kind == "q" else s
        if kind == "r":
            q = s if (fam == "dart" or s < n) else s - 1
            if not (fam == "dart" or s < n):  # the last ray is the (0, B) side of quadrant n - 1
                A, B = 0, A
        pos = lambda a, b: vertex(q, a, b)  # noqa: E731
        if A % 2 and B % 2:
            a, b = (A - 1) // 2, (B - 1) // 2
            return nv + len(edges) + face_index[frozenset((pos(a, b), pos(a + 1, b), pos(a + 1, b + 1), pos(a, b + 1)))]
        if A % 2:
            a, b = (A - 1) // 2, B // 2
            return nv + edges[frozenset((pos(a, b), pos(a + 1, b)))]
        if B % 2:
            a, b = A // 2, (B - 1) // 2
            return nv + edges[frozenset((pos(a, b), pos(a, b + 1)))]
        return pos(A // 2, B // 2)

    def parent(label):
        if label == ("C",):
            return 0
        kind, s, a, b = label
        if kind == "r":
            return vertex(s, a, 0) if (fam == "dart" or s < n) else vertex(s - 1, 0, a)
        return vertex(s, a, b)

    pts = labels(fam, n)
    col = {parent(p): j for j, p in enumerate(pts)}
    M = np.zeros((len(pts), len(pts)))
    for i, p in enumerate(pts):
        for v, w in stencils[child(p)].items():
            assert v in col, f"{fam}:{n}: the stencil of {p} reaches outside the 2-ring"
            M[i, col[v]] = int(w.p) / int(w.q)
    return M


def trusted_matrix(fam, n):
    S = sector_matrix(fam, n)
    return np.array([[int(S[i, j].p) / int(S[i, j].q) for j in range(S.ncols())] for i in range(S.nrows())])


CONFIGS = [(f, n) for f in ("crease", "corner") for n in range(1, 13)] + [("dart", k) for k in range(2, 13)]
SLOW = [(f, n) for f in ("crease", "corner") for n in range(13, 31)] + [("dart", k) for k in range(13, 31)]


def _check_spectrum(fam, n):
    M = library_matrix(fam, n)
    assert np.array_equal(M, trusted_matrix(fam, n)), f"{fam}:{n}: the two rule implementations differ"
    num = np.sort_complex(np.linalg.eigvals(M).round(6))
    cert = np.sort_complex(np.array([complex(float(z.real.mid()), float(z.imag.mid()))
                                     for z, _, _, _ in eigenvalues(fam, n, 64)]).round(6))
    assert len(num) == len(cert)
    # defective eigenvalues move by ~sqrt(eps) in floats; 1e-5 separates every distinct pair here
    assert np.max(np.abs(num - cert)) < 1e-5, f"{fam}:{n}"


@pytest.mark.parametrize("fam,n", CONFIGS)
def test_sector_matrix_and_spectrum_match_the_library_rules_and_numpy(fam, n):
    _check_spectrum(fam, n)


@pytest.mark.slow
@pytest.mark.parametrize("fam,n", SLOW)
def test_sector_matrix_and_spectrum_up_to_30(fam, n):
    _check_spectrum(fam, n)


# ----------------------------------------------------------------------- brute force: the normal
def _normal_vs_boundary(fam, n, steps, seed=3):
    """|cos| of the angle between the control-net normal at quadrant 0's (1,1) and the boundary tangent
    (ray n, from the centre), after each step of the library's subdivision of a random generic net."""
    M = library_matrix(fam, n)
    pts = labels(fam, n)
    P = np.random.default_rng(seed).normal(size=(len(pts), 3))
    idx = {p: i for i, p in enumerate(pts)}
    q = 0
    a10, a01 = idx[("r", q, 1, 0)], idx[("r", q + 1, 1, 0)]
    a21, a12 = idx[("q", q, 2, 1)], idx[("q", q, 1, 2)]
    rN = idx[("r", n, 1, 0)]
    out = []
    for _ in range(steps):
        P = M @ P
        P = P - P[0]  # affine invariance: keep the centre at 0 and the scale at 1 (no cancellation,
        P = P / np.abs(P).max()  # no underflow); directions and angles are unchanged
        normal = np.cross(P[a21] - P[a01], P[a12] - P[a10])  # central differences around (1,1)
        tangent = P[rN] - P[0]
        out.append(abs(normal @ tangent) / np.linalg.norm(normal) / np.linalg.norm(tangent))
    return np.array(out)


@pytest.mark.parametrize("n", [5, 6, 7, 9])
def test_refuted_crease_normal_never_contains_the_boundary_tangent(n):
    """Where the certificate says "not C1" a generic net's interior normal keeps a component along the
    boundary tangent, settling at a positive value over steps 30..60 (a C1 surface would send it to 0)."""
    c = _normal_vs_boundary("crease", n, 60)
    assert c[29:].min() > 0.05 and abs(c[-1] - c[-2]) < 1e-2 * c[-1], c[-5:]


def test_regular_boundary_normal_does_contain_the_boundary_tangent():
    """The control: the regular boundary (crease:2, a bicubic B-spline) is C1; the same measure -> 0."""
    c = _normal_vs_boundary("crease", 2, 30)
    assert c[-1] < 1e-6 and c[-1] < c[10] * 1e-3


@pytest.mark.parametrize("fam,n,rate", [("crease", 3, (0.5 / 0.5797) ** 10), ("corner", 1, 0.5 ** 10)])
def test_certified_c1_normal_converges_onto_the_boundary_tangent(fam, n, rate):
    """Where the certificate says "C1" the same measure tends to 0, geometrically: over 10 steps it
    shrinks at least like (lam2 / lam1)^10 (with a factor 2 of slack for the transient), or has reached
    rounding level (corner:1 is a bilinear-like B-spline corner: 0 after a few steps)."""
    c = _normal_vs_boundary(fam, n, 60)
    assert c[-1] < 1e-3 and (c[-1] < 2 * rate * c[-11] or c[-1] < 1e-12), c[-12:]


def test_certified_c1_dart_normals_agree_across_the_crease():
    """dart:5 (certified C1): the control-net normals at the (1,1) vertices of the quadrants on both sides
    of the sharp ray converge to one direction (the surface has a crease along the ray, yet not at v)."""
    M = library_matrix("dart", 5)
    pts = labels("dart", 5)
    idx = {p: i for i, p in enumerate(pts)}
    P = np.random.default_rng(5).normal(size=(len(pts), 3))

    def normal(q):
        a01, a10 = idx[("r", (q + 1) % 5, 1, 0)], idx[("r", q, 1, 0)]
        a21, a12 = idx[("q", q, 2, 1)], idx[("q", q, 1, 2)]
        v = np.cross(P[a21] - P[a01], P[a12] - P[a10])
        return v / np.linalg.norm(v)

    gaps = []
    for _ in range(80):
        P = M @ P
        P = (P - P[0]) / np.abs(P - P[0]).max()
        gaps.append(np.linalg.norm(normal(0) - normal(4)))
    assert gaps[-1] < 1e-2 and gaps[-1] < 0.1 * gaps[20], gaps[::10]


# ----------------------------------------------------------------------- certificates and forgeries
def _cert(name):
    fam, n = name.split(":")
    stem = f"{'k' if fam == 'dart' else 'n'}{int(n):03d}.json"
    return json.loads((certificates_dir() / "c1" / fam / stem).read_text())


def _fails(cert, why):
    res = verify_certificate(cert, **QUIET)
    assert not res
    text = (res.error or "") + " ".join(p.message + p.name for p in res.failures())
    assert why in text, text
    return res


def test_published_tagged_certificates_verify():
    files = [f for f in certificate_files(certificates_dir()) if f.parent.name in ("crease", "corner")]
    assert len(files) >= 10
    for f in files[:6]:
        cert = json.loads(f.read_text())
        assert verify_certificate(cert, **QUIET), f


def test_forgery_relabelled_configuration():
    cert = _cert("crease:5")
    _fails(dict(cert, configuration="crease:3"), "does not isolate")
    _fails(dict(cert, configuration="crease:101"), "needs")


def test_forgery_another_configurations_data():
    cert = _cert("crease:5")
    other = _cert("crease:6")
    _fails(dict(cert, witness=other["witness"]), "does not isolate")  # its lam2 does not fit


def test_forgery_identity_map():
    """x = y: the same eigenvector twice (an identity-like, rank-one map) has J_xy = 0."""
    cert = copy.deepcopy(_cert("crease:5"))
    cert["witness"]["y"] = cert["witness"]["x"]
    _fails(cert, "beta is not an eigenvalue")
    cert = copy.deepcopy(_cert("crease:5"))
    cert["witness"]["z"]["crease"] = ["0"] * 5
    _fails(cert, "no eigenvector")


def test_forgery_refutation_of_a_c1_candidate():
    """crease:3 passes the spectral part of Reif's criterion. A net of eigenvectors that kills the
    lam2 = 1/2 component (x: lam1, y: the next interior eigenvalue, z: the 1/4 crease vector) does make a
    non-C1 surface, but it is a degenerate net: the verifier refuses it (part G)."""
    from ccproof.certify.tagged import _interior_candidates, _pivot

    inner = _interior_candidates("crease", 3, 128)
    coord = [{"eigenvalue": t[2], "crease": ["0"] * 5, "pivot": _pivot("crease", 3, t[1], 128)} for t in inner[:2]]
    cert = {"schema": TAGGED_SCHEMA, "configuration": "crease:3", "statement": "not C1", "prec": 128,
            "witness": {"x": coord[0], "y": coord[1], "ray": 0, "quadrant": 0,
                        "z": {"eigenvalue": "0.25", "crease": ["-0.125", "0.0625", "0.5", "0.0625", "0.5"]}}}
    res = verify_certificate(cert, **QUIET)
    assert not res
    assert any(p.name.startswith("G ") for p in res.failures()) or any(
        "eigenvector" in p.message for p in res.failures()), [p.message for p in res.failures()]
    _fails(dict(_cert("crease:5"), configuration="crease:2"), "isolate")


def test_forgery_c1_claim_for_a_refuted_configuration():
    """crease:3's C1 certificate relabelled crease:5 (refuted): the spectral part alone would pass."""
    res = _fails(dict(_cert("crease:3"), configuration="crease:5"), "sends the sharp edges to v")
    assert res.parts[1].ok  # the spectral part alone would have passed: it decides nothing


def test_forgery_unknown_field_and_statement():
    _fails(dict(_cert("crease:5"), summary="trust me"), "unknown field")
    _fails(dict(_cert("crease:5"), statement="smooth"), "statement must be")


def test_verify_json_prints_configuration_statement_verdict():
    files = [str(certificates_dir() / "c1" / "k005.json"), str(certificates_dir() / "c1" / "crease" / "n005.json")]
    out = subprocess.run([sys.executable, "-m", "ccproof.cli", "verify", "--serial", "--json", *files],
                         capture_output=True, text=True, check=True).stdout
    objs = [json.loads(line) for line in out.splitlines() if line.startswith("{")]
    assert [(o["configuration"], o["statement"], o["verdict"]) for o in objs] == [
        ("smooth:5", "C1", "VERIFIED"), ("crease:5", "not C1", "VERIFIED")]
    assert all(o["parts"] for o in objs)


def test_c1_certificates_verify_and_resist_forgeries():
    cert = _cert("crease:3")
    assert cert["statement"] == "C1" and verify_certificate(cert, **QUIET)
    _fails(dict(cert, configuration="crease:5"), "sends the sharp edges to v")
    _fails(dict(cert, configuration="crease:4"), "Jordan block")
    forged = copy.deepcopy(cert)
    forged["map"]["y"] = forged["map"]["x"]  # x twice: not lam2's eigenvector
    _fails(forged, "not the eigenvalue")
    forged = copy.deepcopy(_cert("crease:2"))
    forged["map"]["y"] = forged["map"]["x"]  # the double eigenvalue: the same vector twice, det J = 0
    _fails(forged, "regularity")
    forged = copy.deepcopy(cert)
    box = forged["parts"]["regularity"]["0:P2"][0]
    box["bound"] = "1e3"
    _fails(forged, "not above the claimed bound")
    forged = copy.deepcopy(cert)
    forged["parts"]["winding"]["axis"] = "+y"
    _fails(forged, "not allowed")
    forged = copy.deepcopy(cert)
    forged["map"]["orientation"] = -forged["map"]["orientation"]
    _fails(forged, "regularity")


# ----------------------------------------------------------------------- mutations end in a verdict
ODD = [None, True, -1, 0, 2**70, 1.5, "", "x", "1e-999999999", "9" * 100, [], {}, [[]], {"a": 1}, "0L" * 200]


def _paths(obj, prefix=()):
    yield prefix
    items = obj.items() if isinstance(obj, dict) else enumerate(obj) if isinstance(obj, list) else ()
    for k, v in items:
        yield from _paths(v, prefix + (k,))


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.data())
def test_mutated_tagged_certificates_end_in_a_verdict(data):
    """Any deletion, retyping or alteration of a field of a tagged certificate ends in FAILED with a
    reason (or, rarely, still VERIFIED), never in an exception."""
    base = data.draw(st.sampled_from([_cert("crease:5"), _cert("crease:3"), _cert("dart:6"), _cert("corner:41")]))
    path = data.draw(st.sampled_from(list(_paths(base))))
    op = data.draw(st.sampled_from(["delete", "retype", "alter"]))
    value = data.draw(st.sampled_from(ODD))
    cert = copy.deepcopy(base)
    if not path:
        cert = value
    else:
        parent = cert
        for key in path[:-1]:
            parent = parent[key]
        last = path[-1]
        if op == "delete":
            del parent[last]
        elif op == "alter" and isinstance(parent[last], str):
            parent[last] = parent[last][::-1] + "1"
        else:
            parent[last] = value
    res = verify_certificate(cert, **QUIET)  # must not raise
    if not res:
        assert res.error or any(p.name for p in res.failures())


def test_dart_certificates_and_the_rotated_axis():
    """A dart's winding may be counted on any ray only when lam1 = lam2 (D is a multiple of the identity):
    dart:4 uses one; the same ray on dart:5 (lam1 > lam2: the ray is no orbit) is refused."""
    cert4, cert5 = _cert("dart:4"), _cert("dart:5")
    assert verify_certificate(cert4, **QUIET) and verify_certificate(cert5, **QUIET)
    assert isinstance(cert4["parts"]["winding"]["axis"], list)
    forged = copy.deepcopy(cert5)
    forged["parts"]["winding"]["axis"] = [2, 1]
    _fails(forged, "not allowed")


# ----------------------------------------------------------------------- the cost budget of one configuration
_CPU_CHILD = r"""
import json, resource, sys
from ccproof.certify.verify import verify_file
res = verify_file(sys.argv[1], log=lambda line: None)
use = resource.getrusage(resource.RUSAGE_SELF)
why = res.error or "; ".join(p.message for p in res.failures())
print(json.dumps({"ok": bool(res), "error": why, "cpu": use.ru_utime + use.ru_stime}))
"""


def test_a_large_configuration_on_the_exact_route_fails_on_its_budget_within_10_s(tmp_path):
    """crease:3's "C1" file renamed crease:100 (1.6 KB): the exact spectrum of S (603 points) took 9 s of
    CPU before the spectral part failed; it is refused from N alone."""
    c = json.loads((certificates_dir() / "c1" / "crease" / "n003.json").read_text())
    c["configuration"] = "crease:100"
    p = tmp_path / "n100.json"
    p.write_text(json.dumps(c))
    out = subprocess.run([sys.executable, "-c", _CPU_CHILD, str(p)], capture_output=True, text=True, timeout=90)
    got = json.loads(out.stdout.splitlines()[-1])
    assert not got["ok"] and "exceeds the budget" in got["error"], got
    assert got["cpu"] < 10.0, got


def test_every_published_configuration_on_the_exact_route_fits_the_budget_with_room():
    from ccproof.certify.verify.tagged import EXACT_BUDGET, check_exact_budget
    from ccproof.certify.verify.tagged_modes import MIN_N

    sizes = []
    for p in sorted((certificates_dir() / "c1").glob("*/*.json")):
        c = json.loads(p.read_text())
        fam, _, n = c["configuration"].partition(":")
        if n.isdigit() and (int(n) < MIN_N or c["statement"] == "C1" and fam != "dart"):
            check_exact_budget(fam, int(n))
            sizes.append(len(labels(fam, int(n))))
    assert sizes and max(sizes) ** 3 * 64 < EXACT_BUDGET  # room: 4x in the points, 64x in the work
    for fam in ("dart", "crease", "corner"):
        check_exact_budget(fam, 20)
        with pytest.raises(Exception, match="exceeds the budget"):
            check_exact_budget(fam, 22)


def _verify_in_child(path):
    out = subprocess.run([sys.executable, "-c", _CPU_CHILD, str(path)], capture_output=True, text=True, timeout=90)
    return json.loads(out.stdout.splitlines()[-1])


def test_an_interval_record_over_its_budget_fails_from_its_declared_sizes_within_10_s(tmp_path):
    """crease:>=101 with the most arcs and nearly the most disc boxes the grammar allows at 1024 bits: 22,784
    evaluations of H (a record of 24,484 verified after 10.6 s of CPU); refused from the declared sizes before any
    arithmetic."""
    c = json.loads((certificates_dir() / "c1" / "crease" / "n_ge_101.json").read_text())
    c["prec"] = 1024
    c["limit"].update(arcs=8192, outer_arcs=8192, box="0.0075")  # an 80 x 80 grid
    p = tmp_path / "n_ge_101.json"
    p.write_text(json.dumps(c))
    got = _verify_in_child(p)
    assert not got["ok"] and "exceed the budget" in got["error"], got
    assert got["cpu"] < 10.0, got


def test_the_published_interval_records_fit_the_budget_with_room():
    import math
    from fractions import Fraction

    from ccproof.certify.verify.tagged_limit import TAIL_BUDGET

    for fam in ("crease", "corner"):
        c = json.loads((certificates_dir() / "c1" / fam / "n_ge_101.json").read_text())
        lim = c["limit"]
        boxes = (2 * math.ceil(Fraction(lim["R"]) / Fraction(lim["box"]))) ** 2
        assert (lim["arcs"] + lim["outer_arcs"] + boxes) * Fraction(c["prec"] + 1024, 1024) * 4 < TAIL_BUDGET
