"""The two "not C1" certificates that need more than a generic pair of eigenvectors: dart:2 (the leading
eigenvalues have opposite signs, the normal flips at every level) and corner:4 (lam2 = 1/2 in a Jordan
chain). Cross-checks against the library's own Sdc stencils (exact integer subdivision, numpy, sympy),
forgeries, and the configurations that stay undecided."""

import copy
import math
from fractions import Fraction

import numpy as np
import pytest

from ccproof.certify.tagged import prove_tagged
from ccproof.certify.verify import TAGGED_SCHEMA, verify_certificate
from ccproof.certify.verify.tagged import eigenvalues, labels

from .test_tagged import _cert, library_matrix

QUIET = {"log": lambda line: None}
W, DW = (Fraction(1, 6), Fraction(4, 6), Fraction(1, 6)), (Fraction(-1, 2), Fraction(0), Fraction(1, 2))


def _fails(cert, why):
    res = verify_certificate(cert, **QUIET)
    assert not res
    text = (res.error or "") + " ".join(p.name + ": " + p.message for p in res.failures())
    assert why in text, text
    return res


def _parts(cert):
    res = verify_certificate(cert, **QUIET)
    return res, {p.name.split(" ")[0].rstrip(":"): p for p in res.parts}


# ----------------------------------------------------------------------- independent computations
def _exact_library_matrix(fam, n):
    """(D * M as python ints, D): the library's stencils (exact rationals with small denominators, read
    back from library_matrix's floats) over their common denominator D."""
    M = library_matrix(fam, n)
    Q = [[Fraction(float(v)).limit_denominator(10**4) for v in row] for row in M]
    assert all(abs(float(q) - v) < 1e-15 for row, qrow in zip(M, Q) for v, q in zip(row, qrow))
    D = math.lcm(*(q.denominator for row in Q for q in row))
    return [[int(q * D) for q in row] for row in Q], D


def _brute_force(fam, n, marks, ray=None, seed=3):
    """Subdivide a random integer net exactly (python ints, the library's stencils) and at each step in
    ``marks`` return the control-net normal at quadrant 0's (1,1) (central differences) and, when ``ray``
    is given, |cos| of its angle with that ray's tangent (from the centre)."""
    Mi, _ = _exact_library_matrix(fam, n)
    idx = {p: i for i, p in enumerate(labels(fam, n))}
    P = [[int(v) for v in row] for row in np.random.default_rng(seed).integers(-1000, 1000, size=(len(idx), 3))]
    a10, a01 = idx[("r", 0, 1, 0)], idx[("r", 1, 1, 0)]
    a21, a12 = idx[("q", 0, 2, 1)], idx[("q", 0, 1, 2)]
    out = {}
    for m in range(1, max(marks) + 1):
        P = [[sum(w * P[j][c] for j, w in enumerate(row) if w) for c in range(3)] for row in Mi]
        if m in marks:
            u = [P[a21][c] - P[a01][c] for c in range(3)]
            v = [P[a12][c] - P[a10][c] for c in range(3)]
            nv = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]]
            if ray is None:
                out[m] = nv
                continue
            t = [P[idx[("r", ray, 1, 0)]][c] - P[0][c] for c in range(3)]
            dot = sum(a * b for a, b in zip(nv, t))
            out[m] = float(Fraction(dot * dot, sum(a * a for a in nv) * sum(a * a for a in t))) ** 0.5
    return out


def _cos(u, v):
    """The cosine of the angle between two integer vectors (exact until the final square root)."""
    dot = sum(a * b for a, b in zip(u, v))
    return (1 if dot > 0 else -1) * float(Fraction(dot * dot, sum(a * a for a in u) * sum(b * b for b in v))) ** 0.5


def _jacobian(fam, n, x, y, q=0):
    """J_xy at quadrant q's (1,1) with B-spline tangent masks written here (not the verifier's)."""
    idx = {p: i for i, p in enumerate(labels(fam, n))}

    def at(a, b):
        if (a, b) == (0, 0):
            return 0
        if b == 0:
            return idx[("r", q, a, 0)]
        if a == 0:
            return idx[("r", (q + 1) % n if fam == "dart" else q + 1, b, 0)]
        return idx[("q", q, a, b)]

    def tangent(v, da, db):
        return sum(float(da[a] * db[b]) * v[at(a, b)] for a in range(3) for b in range(3))

    return tangent(x, DW, W) * tangent(y, W, DW) - tangent(x, W, DW) * tangent(y, DW, W)


def _numpy_vector(M, lam, pivot):
    w, V = np.linalg.eig(M)
    v = np.real(V[:, int(np.argmin(np.abs(w - lam)))])
    return v / v[pivot]


# ----------------------------------------------------------------------- dart:2: the flip
def test_dart2_certificate_verifies_with_a_flip():
    res, parts = _parts(_cert("dart:2"))
    assert res, [p.message for p in res.failures()]
    assert "alpha beta < 0" in parts["G"].message and parts["F"].ok


def test_dart2_spectrum_and_jacobian_against_numpy():
    """The two leading eigenvalues below 1 (numpy, library stencils) are the real roots 0.38785 and -0.28114 of
    64 x^3 - 16 x^2 - 6 x + 1 (numpy.roots), every other one below 1/4 + 1e-9 in modulus; J_xy from numpy's
    eigenvectors at the certificate's pivots and masks written here equals the verifier's."""
    M = library_matrix("dart", 2)
    ev = sorted(np.linalg.eigvals(M), key=lambda z: -abs(z))
    roots = sorted(np.roots([64, -16, -6, 1]).real, key=lambda r: -abs(r))
    assert abs(ev[0] - 1) < 1e-12 and abs(ev[1] - roots[0]) < 1e-9 and abs(ev[2] - roots[1]) < 1e-9
    assert roots[1] < -0.28 and max(abs(z) for z in ev[3:]) < 0.25 + 1e-9
    w = _cert("dart:2")["witness"]
    x = _numpy_vector(M, roots[0], w["x"]["pivot"])
    y = _numpy_vector(M, roots[1], w["y"]["pivot"])
    res, parts = _parts(_cert("dart:2"))
    J = float(parts["F"].message.split("[")[1].split(" ")[0])
    assert abs(_jacobian("dart", 2, x, y) - J) < 1e-5, (_jacobian("dart", 2, x, y), J)


def test_dart2_normals_flip_at_every_level_and_dart3_normals_do_not():
    """Exact subdivision of a random net with the library's stencils: the normals at quadrant 0's (1,1) of
    consecutive levels point opposite ways for dart:2 (cos -> -1), the same way for dart:3 (C1, cos -> 1)."""
    for k, sign in ((2, -1), (3, 1)):
        nv = _brute_force("dart", k, set(range(30, 41)))
        cosines = [_cos(nv[m], nv[m + 1]) for m in range(30, 40)]
        assert all(sign * c > 0.999 for c in cosines), (k, cosines)


# ----------------------------------------------------------------------- corner:4: the Jordan chain
def test_corner4_certificate_verifies_on_the_chain():
    res, parts = _parts(_cert("corner:4"))
    assert res, [p.message for p in res.failures()]
    assert "J_xe" in parts["N"].name and "algebraic multiplicity 3, geometric 2" in parts["G"].message


def _rref(rows):
    """Reduced row echelon form over Q (Fractions, written here): (rows, pivot columns)."""
    rows = [list(r) for r in rows]
    piv, r = [], 0
    for c in range(len(rows[0])):
        k = next((i for i in range(r, len(rows)) if rows[i][c] != 0), None)
        if k is None:
            continue
        rows[r], rows[k] = rows[k], rows[r]
        rows[r] = [v / rows[r][c] for v in rows[r]]
        for i in range(len(rows)):
            if i != r and rows[i][c] != 0:
                f = rows[i][c]
                rows[i] = [a - f * b for a, b in zip(rows[i], rows[r])]
        piv.append(c)
        r += 1
    return rows, piv


def _mul(A, B):
    return [[sum(a * b for a, b in zip(row, col)) for col in zip(*B)] for row in A]


def test_corner4_jordan_structure_and_chain_top_exactly():
    """Exactly (Fractions, library stencils, elimination written here): 1/2 has rank(M - 1/2) = 25 and
    rank((M - 1/2)^2) = 24 on the 27 points (blocks of sizes 2 and 1); the certificate's y (its crease values,
    any solution of (M - 1/2)^2 y = 0) gives e = (M - 1/2) y != 0, 0 on the crease points, M e = e/2; J_xe with
    numpy's x equals the verifier's."""
    Mi, D = _exact_library_matrix("corner", 4)
    M = [[Fraction(v, D) for v in row] for row in Mi]
    A = [[v - (Fraction(1, 2) if i == j else 0) for j, v in enumerate(row)] for i, row in enumerate(M)]
    A2 = _mul(A, A)
    assert (len(_rref(A)[1]), len(_rref(A2)[1])) == (25, 24)
    w = _cert("corner:4")["witness"]
    pts = labels("corner", 4)
    crease = [pts.index(p) for p in (("C",), ("r", 0, 1, 0), ("r", 0, 2, 0), ("r", 4, 1, 0), ("r", 4, 2, 0))]
    vals = [Fraction(v) for v in w["y"]["crease"]]
    free = [i for i in range(27) if i not in crease]
    system = [[row[j] for j in free] + [-sum(row[j] * v for j, v in zip(crease, vals))] for row in A2]
    R, piv = _rref(system)
    assert len(free) not in piv  # consistent
    y = [Fraction(0)] * 27
    for i, v in zip(crease, vals):
        y[i] = v
    for r, c in enumerate(piv):
        y[free[c]] = R[r][-1]
    e = [row[0] for row in _mul(A, [[v] for v in y])]
    assert any(e) and not any(e[i] for i in crease) and not any(row[0] for row in _mul(A, [[v] for v in e]))
    lam1 = max(z for z in np.linalg.eigvals(library_matrix("corner", 4)).real if z < 0.99)
    x = _numpy_vector(library_matrix("corner", 4), lam1, w["x"]["pivot"])
    res, parts = _parts(_cert("corner:4"))
    J = float(parts["N"].message.split("[")[1].split(" ")[0])
    mine = _jacobian("corner", 4, x, [float(v) for v in e])
    assert abs(mine - J) < 1e-7, (mine, J)


def test_corner4_normal_keeps_away_from_both_boundary_tangents():
    """Exact subdivision of a random net: |cos(normal at quadrant 0's (1,1), ray tangent)| converges like 1/m
    (the chain's m 2^-m term); extrapolated from m = 300, 400 (c + A/m) it is about 0.35 (ray 0) and 0.50
    (ray 4), where a C1 surface has 0. The control, crease:4 (undecided), extrapolates to 0 (< 0.01)."""
    for fam, ray, lo, hi in (("corner", 0, 0.2, 1), ("corner", 4, 0.2, 1), ("crease", 4, -0.01, 0.01)):
        c = _brute_force(fam, 4, {300, 400}, ray=ray)
        limit = (400 * c[400] - 300 * c[300]) / 100
        assert lo < limit < hi, (fam, ray, c, limit)


# ----------------------------------------------------------------------- forgeries
@pytest.mark.parametrize("name,why", [("dart:3", "does not isolate"), ("dart:4", "does not isolate"),
                                      ("dart:5", "K < 5 only"), ("crease:4", "missing field")])
def test_dart2_relabelled(name, why):
    _fails(dict(_cert("dart:2"), configuration=name), why)


@pytest.mark.parametrize("name,ray,why", [("corner:3", 3, "not certainly regular"), ("corner:2", 2, "does not isolate"),
                                          ("corner:5", 5, "missing field"), ("crease:4", 4, "no eigenvector for 1/2"),
                                          ("corner:3", 4, "is not sharp"), ("dart:4", 4, "unknown field")])
def test_corner4_relabelled(name, ray, why):
    cert = copy.deepcopy(dict(_cert("corner:4"), configuration=name))
    cert["witness"]["ray"] = ray
    _fails(cert, why)


def test_corner4_as_crease4_with_its_own_eigenvalue_fails_on_the_crease():
    """The chain witness on crease:4 with x moved to crease:4's lam1: crease:4's 1/2 has one eigenvector and one
    chain, both fixed by the crease tangent; the corner's crease values fit neither."""
    from ccproof.certify.tagged import _interior_candidates, _pivot

    cert = copy.deepcopy(dict(_cert("corner:4"), configuration="crease:4"))
    t = _interior_candidates("crease", 4, 128)[0]
    cert["witness"]["x"] = {"eigenvalue": t[2], "crease": ["0"] * 5, "pivot": _pivot("crease", 4, t[1], 128)}
    _fails(cert, "no eigenvector for 1/2")
    cert["witness"]["y"]["crease"] = ["0", "-0.5", "-1", "0.5", "1"]  # crease:4's own crease tangent: a chain
    cert["witness"]["z"]["crease"] = ["0", "-0.5", "-1", "0.5", "1"]
    _fails(cert, "z or x is one")  # z: the crease tangent has no eigenvector of 1/2, only a chain


def test_dart2_witness_changed():
    from ccproof.certify.tagged import _pivot

    cert = _cert("dart:2")
    forged = copy.deepcopy(cert)
    quarter = next(t[0] for t in eigenvalues("dart", 2, 128) if t[1].degree() == 1 and t[1][0] == -1 and t[1][1] == 4)
    forged["witness"]["y"] = {"eigenvalue": ["0.2", "0.3"], "crease": [], "pivot": _pivot("dart", 2, quarter, 128)}
    _fails(forged, "alpha or beta is not an eigenvalue")  # a rational root counts only when given exactly
    forged["witness"]["y"]["eigenvalue"] = "0.25"  # y: the eigenvector of 1/4 (the sign changed), exactly
    _fails(forged, "alpha beta < 0 is not certain")
    forged = copy.deepcopy(cert)
    forged["witness"]["y"] = forged["witness"]["x"]  # the same eigenvector twice
    _fails(forged, "distinct")
    forged = copy.deepcopy(cert)
    forged["witness"]["y"]["eigenvalue"] = ["-0.38", "0.2"]  # touches -0.28 and 0.14: isolates nothing
    _fails(forged, "does not isolate")
    forged = copy.deepcopy(cert)
    forged["witness"]["x"], forged["witness"]["y"] = forged["witness"]["y"], forged["witness"]["x"]
    assert verify_certificate(forged, **QUIET)  # the flip is symmetric in alpha and beta: still a refutation
    forged = copy.deepcopy(cert)
    forged["witness"]["z"] = {"eigenvalue": "0.25", "crease": []}
    _fails(forged, "unknown field")
    forged = copy.deepcopy(cert)
    forged["witness"]["y"]["crease"] = ["0"]
    _fails(forged, "crease values must be 0 decimals")


def test_corner4_witness_changed():
    cert = _cert("corner:4")
    w = cert["witness"]
    forged = copy.deepcopy(cert)
    forged["witness"]["ray"] = 0  # y (the chain) is not 0 on ray 0: no boundary segment
    _fails(forged, "B boundary segment")
    forged = copy.deepcopy(cert)
    forged["witness"]["z"] = copy.deepcopy(w["y"])  # z the chain too: the normal's limit is no longer checked
    _fails(forged, "z or x is one")
    forged = copy.deepcopy(cert)
    forged["witness"]["y"] = copy.deepcopy(w["z"])  # y the eigenvector: lam2 = 1/2 is then in a Jordan block
    _fails(forged, "Jordan block")
    forged = copy.deepcopy(cert)
    forged["witness"]["y"]["eigenvalue"] = "0.25"  # a claimed eigenvalue changed
    _fails(forged, "no eigenvector for 1/4")
    forged = copy.deepcopy(cert)
    forged["witness"]["z"]["crease"] = ["0", "0.5", "1", "-0.5", "-1"]  # the combination that does not lift
    _fails(forged, "z or x is one")
    forged = copy.deepcopy(cert)
    forged["witness"]["x"]["eigenvalue"] = ["0.3", "0.4"]  # x: lam = 0.366, the next root of the quartic
    _fails(forged, "alpha > beta > 0 is not certain")
    forged = copy.deepcopy(cert)
    forged["witness"]["y"]["pivot"] = 3  # a chain with y = 1 at point 3, where its top (S - 1/2) y is not 0: the
    _fails(forged, "(S - 1/2) z is not 0 on the crease points")  # one check of the top on the fixed points


def test_statement_flipped_to_c1():
    """dart:3's and corner:1's "C1" records relabelled dart:2 and corner:4, and the refutations with their
    statement flipped: each FAILs with the spectral reason or the missing fields."""
    _fails(dict(_cert("dart:3"), configuration="dart:2"), "not certainly real and positive")
    _fails(dict(_cert("corner:1"), configuration="corner:4"), "Jordan block")
    _fails(dict(_cert("dart:2"), statement="C1"), "unknown field")
    _fails(dict(_cert("corner:4"), statement="C1"), "unknown field")


@pytest.mark.parametrize("name", ["crease:1", "crease:4", "corner:2"])
def test_still_undecided_with_the_reason(name):
    cert, why = prove_tagged(name)
    assert cert is None and why.startswith("undecided") and "Jordan block" in why, why


def test_the_prover_writes_the_published_files():
    for name in ("dart:2", "corner:4"):
        cert, why = prove_tagged(name)
        assert cert == _cert(name) and why.startswith("not C1"), why
        assert cert["schema"] == TAGGED_SCHEMA


def _paths(obj, prefix=()):
    yield prefix
    items = obj.items() if isinstance(obj, dict) else enumerate(obj) if isinstance(obj, list) else ()
    for k, v in items:
        yield from _paths(v, prefix + (k,))


@pytest.mark.parametrize("name", ["dart:2", "corner:4"])
def test_every_mutation_of_the_new_records_ends_in_a_verdict(name):
    """Every field deleted, retyped (6 odd values) or altered (strings reversed): FAILED with a reason, never an
    exception, unless the mutation left the record as it was."""
    base = _cert(name)
    for path in list(_paths(base))[1:]:
        for value in ("delete", "alter", None, -1, 2**70, "x", [], {}):
            cert = copy.deepcopy(base)
            parent = cert
            for key in path[:-1]:
                parent = parent[key]
            if value == "delete":
                del parent[path[-1]]
            elif value == "alter":
                if not isinstance(parent[path[-1]], str):
                    continue
                parent[path[-1]] = parent[path[-1]][::-1] + "1"
            else:
                parent[path[-1]] = value
            res = verify_certificate(cert, **QUIET)
            if res:  # only the mutations that change nothing (a dart's crease [] set to [])
                assert cert == base, (path, value)
            else:
                assert res.error or res.failures(), (path, value)


def test_a_witness_whose_alpha_or_beta_is_the_eigenvalue_1_fails_part_g():
    """alpha or beta claimed as the eigenvalue 1 (x or y the constant vector) is refused by part G itself: its root
    finder skips the factor x - 1. Without that, crease:2's record (alpha = 1 >= beta = gamma = 1/2, 1/2 double
    and non-defective) passes G and only B and N (the constant's tangents vanish) fail; dart:2's flip with y = 1
    would fail on the signs instead."""
    crease2 = _cert("crease:2")
    witness = {"x": {"eigenvalue": "1", "crease": ["1"] * 5}, "y": crease2["map"]["x"],
               "z": {"eigenvalue": "0.5", "crease": ["0", "-0.5", "-1", "0.5", "1"]}, "ray": 0, "quadrant": 0}
    forged = {k: crease2[k] for k in ("schema", "configuration", "prec")} | {"statement": "not C1", "witness": witness}
    res, parts = _parts(forged)
    assert not res and parts["x"].ok and parts["y"].ok and parts["z"].ok
    assert not parts["G"].ok and parts["G"].message == "alpha is not an eigenvalue", parts["G"].message
    flip = copy.deepcopy(_cert("dart:2"))
    flip["witness"]["y"] = {"eigenvalue": "1", "crease": [], "pivot": 0}
    res, parts = _parts(flip)
    assert not res and parts["y"].ok
    assert parts["G"].message == "alpha or beta is not an eigenvalue (distinct from the other)", parts["G"].message
