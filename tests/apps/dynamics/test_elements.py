"""Q1 (regular patches = tensor B-spline), Q2 (element matrices), Q3 (special-element bookkeeping)."""

from fractions import Fraction as Fr

import numpy as np
import pytest
from scipy.interpolate import BSpline

from ccproof.apps.dynamics.basis import gram, paper_patch_jacobian, patch_rows, term_matrix
from ccproof.apps.dynamics.elements import special_scheme
from ccproof.apps.dynamics.meshes import torus_32
from ccproof.apps.dynamics.model import DynamicSurface, Material

# docs/qmv98.md B5, copied by hand (independent of the code under test)
SPEC_G0 = [[Fr(1, 252), Fr(43, 1680), Fr(1, 84), Fr(1, 5040)], [Fr(43, 1680), Fr(33, 140), Fr(311, 1680), Fr(1, 84)],
           [Fr(1, 84), Fr(311, 1680), Fr(33, 140), Fr(43, 1680)], [Fr(1, 5040), Fr(1, 84), Fr(43, 1680), Fr(1, 252)]]
SPEC_G1 = [[Fr(1, 20), Fr(7, 120), Fr(-1, 10), Fr(-1, 120)], [Fr(7, 120), Fr(17, 60), Fr(-29, 120), Fr(-1, 10)],
           [Fr(-1, 10), Fr(-29, 120), Fr(17, 60), Fr(7, 120)], [Fr(-1, 120), Fr(-1, 10), Fr(7, 120), Fr(1, 20)]]
SPEC_G2 = [[Fr(1, 3), Fr(-1, 2), Fr(0), Fr(1, 6)], [Fr(-1, 2), Fr(1), Fr(-1, 2), Fr(0)],
           [Fr(0), Fr(-1, 2), Fr(1), Fr(-1, 2)], [Fr(1, 6), Fr(0), Fr(-1, 2), Fr(1, 3)]]


def _basis_spec(x, r):
    """B0..B3 of docs/qmv98.md B2 and their derivatives, written out independently."""
    x = np.asarray(x, dtype=float)
    if r == 0:
        return np.stack([(1 - x) ** 3 / 6, (3 * x**3 - 6 * x**2 + 4) / 6, (-3 * x**3 + 3 * x**2 + 3 * x + 1) / 6,
                         x**3 / 6], -1)
    if r == 1:
        return np.stack([-((1 - x) ** 2) / 2, (9 * x**2 - 12 * x) / 6, (-9 * x**2 + 6 * x + 3) / 6, x**2 / 2], -1)
    return np.stack([1 - x, (18 * x - 12) / 6, (-18 * x + 6) / 6, x], -1)


def test_grams_equal_spec_tables():
    for r, G in enumerate((SPEC_G0, SPEC_G1, SPEC_G2)):
        assert [list(row) for row in gram(r)] == G


@pytest.mark.parametrize("term,orders", [("mass", (0, 0)), ("uu1", (1, 0)), ("vv1", (0, 1)), ("uu2", (2, 0)),
                                         ("uv2", (1, 1)), ("vv2", (0, 2))])
def test_element_matrices_equal_gauss_quadrature(term, orders):
    x, w = np.polynomial.legendre.leggauss(4)
    x, w = 0.5 * (x + 1), 0.5 * w
    ru, rv = orders
    Q = np.zeros((16, 16))
    for xu, wu in zip(x, w):
        for xv, wv in zip(x, w):
            row = np.outer(_basis_spec(xu, ru), _basis_spec(xv, rv)).reshape(-1)  # index 4 i + j, i along u
            Q += wu * wv * np.outer(row, row)
    assert np.abs(term_matrix(term) - Q).max() < 1e-14


def test_normal_element_translation_and_total_mass():
    mat = Material(mu=2.5, gamma=0.3, a11=0.7, a22=1.9, b11=0.4, b12=1.1, b22=0.6)
    model = DynamicSurface(torus_32(), mat)
    Mn, Kn = model.normal_element_matrices()
    assert abs(mat.mu * Mn.sum() - mat.mu) < 1e-14  # 1^T M 1 = mu per patch
    assert np.abs(Kn @ np.ones(16)).max() < 1e-14  # K 1 = 0 (translations free)
    assert np.abs(model.stiffness_matrix() @ np.ones(model.n_vertices)).max() < 1e-13


def test_paper_patch_jacobian_interleave():
    u, v = 0.3, 0.8
    J = paper_patch_jacobian(u, v)
    row = np.outer(_basis_spec(u, 0), _basis_spec(v, 0)).reshape(-1)
    for k in range(16):
        assert J[0, 3 * k] == pytest.approx(row[k], abs=1e-15)
        assert J[1, 3 * k + 1] == pytest.approx(row[k], abs=1e-15)
        assert J[2, 3 * k + 2] == pytest.approx(row[k], abs=1e-15)
        assert J[0, 3 * k + 1] == J[0, 3 * k + 2] == J[1, 3 * k] == 0
    assert np.allclose(patch_rows([u], [v])["P"][0], row, atol=1e-15)


def test_q1_regular_torus_equals_tensor_bspline():
    mesh = torus_32()  # 8 x 4 periodic grid: vertex i * 4 + j, face i * 4 + j, u along i
    V = np.asarray(mesh.vertices).reshape(8, 4, 3)
    rng = np.random.default_rng(3)
    V = V + 0.2 * rng.standard_normal(V.shape)
    model = DynamicSurface(mesh.with_vertices(V.reshape(-1, 3)))
    N = BSpline.basis_element([0, 1, 2, 3, 4], extrapolate=False)
    dN = [N, N.derivative(1), N.derivative(2)]

    def ev(x, r):
        return np.nan_to_num(dN[r](x))

    f = rng.integers(0, 32, 300)
    u, v = rng.random(300), rng.random(300)
    got = model.evaluate(f, u, v, 2)
    i, j = f // 4, f % 4
    for name, (ru, rv) in {"P": (0, 0), "Pu": (1, 0), "Pv": (0, 1), "Puu": (2, 0), "Puv": (1, 1),
                           "Pvv": (0, 2)}.items():
        ref = np.zeros((300, 3))
        for a in range(-1, 3):
            for b in range(-1, 3):
                # control point (i + a, j + b) has the cardinal B-spline N(U - (i + a) + 2) with U = i + u
                w = ev(u - a + 2, ru) * ev(v - b + 2, rv)
                ref += w[:, None] * V[(i + a) % 8, (j + b) % 4]
        assert np.abs(got[name] - ref).max() < 1e-12, name


# ---------------------------------------------------------------------------- Q3


def _lam(n):
    c = np.cos(2 * np.pi / n)
    return (5 + c + np.sqrt((1 + c) * (9 + c))) / 16


@pytest.mark.parametrize("n", [3, 5, 6])
def test_q3_truncated_mass_total_and_stein(n):
    S = special_scheme(n)
    for L in (1, 2, 5, 9):
        assert abs(S.mass_truncated(L).sum() - n * (1 - 4.0**-L)) < 1e-13
    X = S.mass_exact()
    assert abs(X.sum() - n) < 1e-12
    # the truncated sum converges to the Stein solution like 4^-L
    assert np.abs(S.mass_truncated(30) - X).max() < 1e-14
    assert np.abs(S.mass_truncated(6) - X).max() > 1e-5
    # the Stein solution solves X = Z/4 + C^T X C / 4 (checked on the equation, not on the code path)
    assert np.abs(X - S.level_increment("mass", 1) - 0.25 * S.C.T @ X @ S.C).max() < 1e-14


@pytest.mark.parametrize("n", [3, 5, 6])
def test_q3_level_ratios(n):
    """Level increments of p^T dX_L p: mass -> 1/4, tension -> lam^2, rigidity -> 4 lam^2.

    The target of docs/qmv98.md Q3, "within 5% by L = 8", holds for the mass and (n = 3) the tension; the rigidity terms
    at n = 5, 6 approach 4 lam^2 like (mu2/lam)^L with a large prefactor (30% off at L = 8 for a random p),
    so the ratios are measured at L = 14, where all are within 1%.
    """
    S = special_scheme(n)
    lam = _lam(n)
    p = np.random.default_rng(n).standard_normal(S.d)
    for term, expected, L in (("mass", 0.25, 8), ("uu1", lam**2, 14), ("uv2", 4 * lam**2, 14),
                              ("uu2", 4 * lam**2, 14)):
        e = [p @ S.level_increment(term, lev) @ p for lev in (L - 1, L)]
        assert e[1] / e[0] == pytest.approx(expected, rel=0.01 if L == 14 else 0.05), term
    if n == 3:
        assert 4 * lam**2 < 1  # plate series converges
    else:
        assert 4 * lam**2 > 1  # and diverges for n >= 5


def test_q3_truncation_report_flags_divergence():
    from ccproof.apps.dynamics.meshes import open_surface_valence5, paper_initial_model

    rep3 = DynamicSurface(paper_initial_model(), levels=6).truncation_report()
    rep5 = DynamicSurface(open_surface_valence5(), levels=6).truncation_report()
    assert all(np.isfinite(r["rigidity"]["tail_estimate"]) for r in rep3)
    assert rep3[0]["rigidity"]["ratio"] == pytest.approx(4 * _lam(3) ** 2)
    assert rep5[0]["valence"] == 5 and rep5[0]["rigidity"]["tail_estimate"] == np.inf
    assert np.isfinite(rep5[0]["tension"]["tail_estimate"])
    # more levels, more rigidity energy (divergent series) for n = 5
    P = np.asarray(open_surface_valence5(height=1.0).vertices)
    e6 = DynamicSurface(open_surface_valence5(), levels=6).truncation_report(P)[0]["rigidity"]["truncated"]
    e12 = DynamicSurface(open_surface_valence5(), levels=12).truncation_report(P)[0]["rigidity"]["truncated"]
    assert e12 > e6


def test_special_scheme_C_is_the_exact_two_ring_matrix():
    from ccproof.algebra.subdivision import subdivision_matrix

    for n in (3, 5):
        C = np.array([[float(x) for x in row] for row in subdivision_matrix(n, "two_ring")])
        assert np.array_equal(special_scheme(n).C, C)
        assert np.allclose(special_scheme(n).B.sum(axis=1), 1.0, atol=1e-15)
