"""The verifier's own derivation of the statement, checked against independent computations.

References: ccproof.algebra (sympy derivation of the nets and the exact (6k+1) two-ring matrix, itself
tested against a naive Catmull-Clark step on an explicit mesh), numpy's eigenvalues, mpmath's cos/sqrt.
"""

import mpmath
import numpy as np
import pytest
from flint import arb, ctx, fmpq, fmpq_poly

from ccproof.algebra.subdivision import ring_subdivision_matrix, two_ring_vertices
from ccproof.certify.verify import rules, spectrum
from ccproof.certify.verify import statement as St
from ccproof.certify.verify.statement import QL
from ccproof.tables.format import read_table_json, table_nets_exact, table_path


def _same_form(f, g):
    A1, B1, D1 = (fmpq_poly(x) for x in f)
    A2, B2, D2 = (fmpq_poly(x) for x in g)
    return A1 * D2 == A2 * D1 and B1 * D2 == B2 * D1


@pytest.mark.parametrize("valence", [3, 7, {"min": 40}])
def test_derived_nets_equal_the_sympy_tables(valence):
    """Two implementations (flint field + rules written out; sympy + grid stencils) give the same forms."""
    table = table_nets_exact(read_table_json(table_path(valence)))
    mine = St.derivation().integer_forms()
    for n in St.PATCHES:
        for i in range(4):
            for j in range(4):
                for d in range(2):
                    assert _same_form(mine[n][i][j][d], table[n][i][j][d]), (n, i, j, d)


@pytest.mark.parametrize("k", [3, 5, 7, 12])
def test_eigenvector_of_the_exact_two_ring_matrix(k):
    """v(j, p) = R^j v(0, p) with the derived sector-0 values is an eigenvector of the algebra package's
    exact (6k+1) matrix for lam(k): residual balls contain 0 and are tiny; a perturbed value is not."""
    S = [[fmpq(x.numerator, x.denominator) for x in row] for row in ring_subdivision_matrix(k)]
    verts = two_ring_vertices(k)
    d = St.derivation()
    with ctx.workprec(200):
        c, lam = St.c_lam(k, 200)
        vals = {p: tuple(q.evaluate(c, lam) for q in v) for p, v in d.eigenvector.items()}

        def rot(j, p):
            x, y = p
            for _ in range(j):
                x, y = -y, x + 2 * c * y
            return (x, y)

        for perturb in (0, 1):
            vec = [(arb(0), arb(0))]
            for j, a, b in verts[1:]:
                x, y = rot(j, vals[(a, b)])
                if perturb and (j, a, b) == (0, 2, 1):
                    x = x * (1 + arb(1) / 1000)
                vec.append((x, y))
            worst = arb(0)
            for i in range(len(verts)):
                for dd in range(2):
                    r = sum((S[i][m] * vec[m][dd] for m in range(len(verts)) if S[i][m] != 0), arb(0))
                    r -= lam * vec[i][dd]
                    if not perturb:
                        assert r.contains(0) and r.rad() < 1e-50
                    worst = max(worst, abs(r).upper())
            if perturb:
                assert worst > 1e-5


@pytest.mark.parametrize("k", [3, 5, 6, 9])
def test_block_spectra_equal_numpy_eigenvalues(k):
    """The union of the Fourier blocks' roots (stated characteristic polynomials) is the spectrum of the
    algebra package's two-ring matrix, in floats."""
    assert spectrum.check_block_polynomials()
    ev = np.sort(np.linalg.eigvals(np.array(ring_subdivision_matrix(k), dtype=float)).real)
    roots = []
    for m in range(k):
        cm = np.cos(2 * np.pi * m / k)
        if m == 0:
            roots += [1] + list(np.roots([16 * k, -(12 * k - 28), k - 3]))
        else:
            roots += list(np.roots([16, -2 * (5 + cm), 1]))
        roots += [1 / 8, 1 / 16, 1 / 32, 1 / 64]
    np.testing.assert_allclose(np.sort(np.real(roots)), ev, atol=1e-8)


def test_block_identity_detects_a_wrong_rule(monkeypatch):
    """Change the edge rule's weights (3/8, 1/16 -> 5/16, 3/32): the stated polynomials no longer hold."""
    true_rule = rules.level1_rule

    def wrong(A, B):
        comb = true_rule(A, B)
        if A % 2 != B % 2:
            comb = {p: (w * fmpq(5, 6) if w == fmpq(3, 8) else w * fmpq(3, 2)) for p, w in comb.items()}
        return comb

    monkeypatch.setattr(spectrum, "level1_rule", wrong)
    assert not spectrum.check_block_polynomials()


def test_a_wrong_net_offset_breaks_the_continuity_hypotheses(monkeypatch):
    St.derivation.cache_clear()
    monkeypatch.setitem(St.NET_OFFSETS, "P3", (0, 0))
    try:
        hyp = dict(St.derivation().hypotheses)
    finally:
        St.derivation.cache_clear()
    assert not hyp["Phi continuous across P2 | P3 (u = 1/2)"]
    assert hyp["eigen-equation M(c) v = lam v on the two-ring (identity in F)"]


@pytest.mark.parametrize("k", [3, 4, 5, 40, 10**6])
def test_c_and_lam_enclose_and_are_tight(k):
    mpmath.mp.dps = 60
    c_true = mpmath.cos(2 * mpmath.pi / k)
    lam_true = (5 + c_true + mpmath.sqrt((1 + c_true) * (9 + c_true))) / 16
    c, lam = St.c_lam(k, 128)
    with ctx.workprec(256):
        for ball, x in ((c, c_true), (lam, lam_true)):
            gap = abs(ball.mid() - arb(mpmath.nstr(x, 58)).mid())  # mpmath at 60 digits: error << 1e-55
            assert gap.upper() <= (ball.rad() + arb("1e-55")).upper()  # enclosure
            assert ball.rad() < 2.0**-118  # tightness (128 bits asked)
    with ctx.workprec(128):
        assert (16 * lam**2 - 2 * (5 + c) * lam + 1).contains(0) and lam > (5 + c) / 16  # the larger root


def test_field_arithmetic_against_sympy():
    import sympy

    cs, ls = sympy.symbols("c lam")
    q = 16 * ls**2 - 2 * (5 + cs) * ls + 1
    x = (QL(fmpq_poly([1, 2]), fmpq_poly([0, 3])) * QL.lam() + 7) / (QL.c() * QL.lam() - 2)
    xs = (((1 + 2 * cs) + 3 * cs * ls) * ls + 7) / (cs * ls - 2)
    # compare at a few (c, lam) on the curve q = 0
    for cv in (sympy.Rational(1, 3), sympy.Rational(-2, 7)):
        lv = max(sympy.solve(q.subs(cs, cv), ls), key=lambda r: float(r))
        num = complex(sympy.N(xs.subs({cs: cv, ls: lv}), 30))
        with ctx.workprec(128):
            got = x.evaluate(arb(fmpq(cv.p, cv.q)), arb(sympy.N(lv, 40).__str__()))
        assert abs(float(got.mid()) - num.real) < 1e-12
