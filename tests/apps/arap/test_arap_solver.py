"""H2 (closed-form local step) and H3 (monotone local/global iteration, exact global solve).

Expected values: the det-corrected SVD polar factor (numpy SVD), brute-force comparison with random
rotations, and a dense least-squares solve (numpy lstsq) of the global step written out here.
"""

import importlib.util
import pathlib

import numpy as np
import scipy.sparse as sp

from ccproof.apps.arap.core import initial_texture
from ccproof.apps.arap.hierarchy import ChartHierarchy
from ccproof.apps.arap.samples import build_samples, isometric_frames
from ccproof.apps.arap.solver import closest_rotations, iterate, system_from_samples

_spec = importlib.util.spec_from_file_location("arap_meshes", pathlib.Path(__file__).with_name("_arap_meshes.py"))
M = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(M)


def polar_rotation(A):
    U, _, Vt = np.linalg.svd(A)
    D = np.ones((A.shape[0], 2))
    D[:, 1] = np.sign(np.linalg.det(U @ Vt))
    return np.einsum("sij,sj,sjk->sik", U, D, Vt)


def frob2(A, B):
    return ((A - B) ** 2).sum(axis=(-1, -2))


def rot(th):
    th = np.atleast_1d(th)
    return np.stack([np.stack([np.cos(th), -np.sin(th)], -1), np.stack([np.sin(th), np.cos(th)], -1)], -2)


def test_theorem1_equals_det_corrected_polar_rotation():
    rng = np.random.default_rng(0)
    A = rng.normal(size=(100_000, 2, 2))
    R = closest_rotations(A)
    assert np.abs(R - polar_rotation(A)).max() < 1e-12
    assert np.allclose(np.linalg.det(R), 1.0)
    # negative determinants included: still a proper rotation and optimal
    assert (np.linalg.det(A) < 0).sum() > 40_000


def test_theorem1_is_optimal_against_random_rotations():
    rng = np.random.default_rng(1)
    A = rng.normal(size=(200, 2, 2))
    R = closest_rotations(A)
    f = frob2(R, A)
    for th in rng.uniform(0, 2 * np.pi, size=100):
        assert (f <= frob2(rot(th), A) + 1e-12).all()


def test_degenerate_case_every_rotation_equally_good():
    a, b = 0.7, -1.3
    A = np.array([[[a, b], [b, -a]]])  # a = -d, b = c
    vals = frob2(rot(np.linspace(0, 2 * np.pi, 50)), A)
    assert np.ptp(vals) < 1e-12
    R = closest_rotations(A)
    assert np.allclose(R[0], np.eye(2))


def _system(level=2, rules="extended"):
    m, chart = M.curved_ev_mesh()
    h = ChartHierarchy(m, chart)
    S = build_samples(h.level(level), rules, "optimize")
    return h, S, system_from_samples(S, h.operator(level, rules))


def test_energy_never_increases_and_global_solve_is_exact():
    for rules in ("extended", "boundary"):
        h, S, sysk = _system(2, rules)
        rng = np.random.default_rng(2)
        X0 = initial_texture(h, rules) + 0.05 * rng.normal(size=(h.n_unknowns(rules), 2))
        res = iterate(sysk, X0, tol=0.0, max_iter=60, trace=True)
        tr = np.array(res.trace)
        assert tr[-1] < 0.5 * tr[0]
        assert (np.diff(tr) <= 1e-12 * tr[:-1]).all()
        assert max(res.residuals) < 1e-10


def test_global_step_is_the_least_squares_minimizer():
    h, S, sysk = _system(1, "extended")
    rng = np.random.default_rng(3)
    N = h.n_unknowns("extended")
    X = initial_texture(h, "extended")
    R = closest_rotations(rng.normal(size=(sysk.w.size, 2, 2)))
    Xn = sysk.global_step(R, X)
    # dense least squares: rows sqrt(w) (X^T [g1 g2] Q - R) = 0, pinned unknown 0 kept
    A = h.operator(1, "extended")
    G1 = (S.O1 @ A).toarray()
    G2 = (S.O2 @ A).toarray()
    a, b, c = isometric_frames(S.p1, S.p2)
    keep = S.weight > 1e-14 * S.weight.max()
    w = np.sqrt(S.weight[keep])[:, None]
    H0 = G1[keep] / a[keep, None]
    H1 = (G2[keep] - G1[keep] * (b / a)[keep, None]) / c[keep, None]
    for col in range(2):
        M = np.vstack([w * H0, w * H1])
        rhs = np.concatenate([w[:, 0] * R[:, col, 0], w[:, 0] * R[:, col, 1]])
        rhs = rhs - M[:, 0] * X[0, col]
        sol = np.linalg.lstsq(M[:, 1:], rhs, rcond=None)[0]
        assert np.abs(sol - Xn[1:, col]).max() < 1e-9 * np.abs(sol).max()
    assert Xn[0].tolist() == X[0].tolist()
    assert isinstance(sysk.L, sp.spmatrix) or sp.issparse(sysk.L)
    assert N == Xn.shape[0]


def test_matrix_is_factorized_once_per_level():
    h, S, sysk = _system(1, "extended")
    lu = sysk.lu
    X = initial_texture(h, "extended")
    iterate(sysk, X, tol=0.0, max_iter=5)
    assert sysk.lu is lu and not sysk.regularized


def test_anderson_acceleration_is_monotone_and_reaches_the_same_minimum():
    m, chart = M.curved_ev_mesh()
    h = ChartHierarchy(m, chart)
    sysk = system_from_samples(build_samples(h.level(2), "extended", "optimize"), h.operator(2, "extended"))
    X0 = initial_texture(h, "extended")
    plain = iterate(sysk, X0, tol=1e-12, max_iter=20000)
    fast = iterate(sysk, X0, tol=1e-12, max_iter=20000, accel=5)
    assert fast.converged and plain.converged
    assert (np.diff(fast.energies) <= 1e-15 * fast.energies[0]).all()  # the safeguard keeps it monotone
    E_ref = min(plain.energies[-1], fast.energies[-1])
    assert abs(fast.energies[-1] - E_ref) <= 1e-9 * E_ref and abs(plain.energies[-1] - E_ref) <= 1e-6 * E_ref
    assert fast.iterations < plain.iterations / 3
    # the minimizer itself: the global step of the final rotations does not move it
    R = closest_rotations(sysk.jacobians(fast.X))
    assert np.abs(sysk.global_step(R, fast.X) - fast.X).max() < 1e-5 * np.abs(fast.X).max()
