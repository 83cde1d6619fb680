"""Q6 (integrators: order, equivalences, equilibria) and Q7 (matrix-free = assembled, SPD, CG residuals)."""

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ccproof.apps.dynamics.forces import Springs
from ccproof.apps.dynamics.integrate import ImplicitIntegrator, MatrixSystem, pcg
from ccproof.apps.dynamics.meshes import flat_sheet, open_surface_valence5, paper_initial_model
from ccproof.apps.dynamics.model import DynamicSurface, Material
from ccproof.errors import CCProofError

MAT = Material(mu=1.0, gamma=0.5, a11=0.3, a22=0.6, b11=0.2, b12=0.5, b22=0.4)


def test_q6_scheme31_first_order_on_oscillator():
    """m = 1, d = 0.5, k = 4, p(0) = 1 at rest, T = 5: errors 0.159, 0.099, 0.056, 0.030 (docs/qmv98.md B5)."""
    m, d, k, T = 1.0, 0.5, 4.0, 5.0
    z = d / (2 * m)
    w = np.sqrt(k / m - z * z)
    exact = np.exp(-z * T) * (np.cos(w * T) + z / w * np.sin(w * T))
    errs = []
    for dt in (0.1, 0.05, 0.025, 0.0125):
        integ = ImplicitIntegrator(MatrixSystem([[m]], [[d]], [[k]]), dt, P=np.array([[1.0]]), tol=1e-14)
        for _ in range(int(round(T / dt))):
            integ.step()
        errs.append(abs(integ.P[0, 0] - exact))
    assert np.round(errs, 3).tolist() == [0.159, 0.099, 0.056, 0.030]
    ratios = [errs[i] / errs[i + 1] for i in range(3)]
    assert all(1.6 < r < 2.3 for r in ratios)


def test_q6_scheme32_is_backward_euler_with_step_2dt():
    rng = np.random.default_rng(0)
    n = 6
    A = rng.standard_normal((n, n))
    K = A @ A.T + n * np.eye(n)
    D = np.diag(rng.uniform(0.5, 2, n))
    f = rng.standard_normal((n, 1))
    dt = 0.07
    p0 = rng.standard_normal((n, 1))
    p1 = rng.standard_normal((n, 1))
    integ = ImplicitIntegrator(MatrixSystem(np.zeros((n, n)), D, K), dt, P=p1, P_prev=p0, scheme="massless",
                               tol=1e-14)
    seq = [p0, p1]
    for _ in range(6):
        integ.step(force=f)
        seq.append(integ.P.copy())
    # backward Euler for D p' + K p = f with step h = 2 dt, separately on even and odd steps
    h = 2 * dt
    for start in (0, 1):
        q = seq[start]
        for j in range(start + 2, len(seq), 2):
            q = np.linalg.solve(D + h * K, D @ q + h * f)
            assert np.abs(q - seq[j]).max() < 1e-12


@pytest.mark.parametrize("scheme,dt,steps", [("inertial", 20.0, 300), ("massless", 50.0, 300)])
def test_q6_long_time_limit_is_equilibrium(scheme, dt, steps):
    mesh = open_surface_valence5()
    model = DynamicSurface(mesh, MAT)
    rng = np.random.default_rng(1)
    f_ids = rng.choice(np.flatnonzero(model.layout.face_kind > 0), 12)
    u, v = rng.random(12), rng.random(12)
    anchors = model.evaluate(f_ids, u, v)["P"] + np.array([0, 0, 0.3])
    springs = Springs(model, f_ids, u, v, anchors, 5.0)
    force = 0.01 * rng.standard_normal((model.n_vertices, 3))
    # free vertices (no patch) have no stiffness: pin them with the identity so the system is regular
    used = np.zeros(model.n_vertices, bool)
    used[model.layout.normal_nets.reshape(-1)] = True
    for r in model.layout.special_rings:
        used[r] = True
    assert used.all()
    integ = ImplicitIntegrator(model, dt, scheme=scheme, tol=1e-12)
    for _ in range(steps):
        integ.step(force=force, springs=springs)
    Ktot = (model.stiffness_matrix() + springs.matrix()).tocsc()
    ref = spla.spsolve(Ktot, force + springs.rest_force())
    assert np.linalg.norm(integ.P - ref) / np.linalg.norm(ref) < 1e-8


def test_q7_matrix_free_equals_assembled():
    rng = np.random.default_rng(2)
    for mesh in (paper_initial_model(), open_surface_valence5(), flat_sheet()):
        for mat in (MAT, Material(mu=0.1, a11=2, a22=0.5, b11=0, b12=0, b22=3)):
            model = DynamicSurface(mesh, mat, levels=5)
            X = rng.standard_normal((model.n_vertices, 3))
            for cm, ck in ((1, 0), (0, 1), (2.3, 0.7)):
                A = model.assemble(cm, ck)
                Y = A @ X
                assert np.linalg.norm(model.matvec(X, cm, ck) - Y) <= 1e-12 * np.linalg.norm(Y)
                assert np.abs(model.diagonal(cm, ck) - A.diagonal()).max() <= 1e-13 * np.abs(A.diagonal()).max()
            A = model.assemble(1.0, 1.0)
            assert abs(A - A.T).max() < 1e-14


def test_q7_step_matrix_spd_and_cg_residuals():
    model = DynamicSurface(paper_initial_model(), MAT)
    integ = ImplicitIntegrator(model, 0.1, tol=1e-10)
    apply, diag = integ.system_operator()
    A = integ._A.toarray()
    assert np.linalg.eigvalsh(A).min() > 0
    rng = np.random.default_rng(3)
    force = rng.standard_normal((model.n_vertices, 3))
    for _ in range(5):
        info = integ.step(force=force)
        assert info.residual < 1e-10
    # matrix-free integrator follows the same trajectory
    mf = ImplicitIntegrator(model, 0.1, tol=1e-12, matrix_free=True)
    ref = ImplicitIntegrator(model, 0.1, tol=1e-12)
    for _ in range(5):
        mf.step(force=force)
        ref.step(force=force)
    assert np.abs(mf.P - ref.P).max() < 1e-9


def test_pcg_against_direct_solve():
    rng = np.random.default_rng(4)
    A = sp.random(60, 60, density=0.1, random_state=4)
    A = (A @ A.T + 60 * sp.eye(60)).tocsr()
    B = rng.standard_normal((60, 3))
    X, info = pcg(lambda X: A @ X, B, A.diagonal(), tol=1e-12)
    assert np.abs(X - spla.spsolve(A.tocsc(), B)).max() < 1e-10
    assert info["residual"] < 1e-12


def test_bad_inputs():
    model = DynamicSurface(paper_initial_model())
    for dt in (0, -1.0, float("nan"), float("inf")):
        with pytest.raises(CCProofError, match="dt"):
            ImplicitIntegrator(model, dt)
    with pytest.raises(CCProofError, match="scheme"):
        ImplicitIntegrator(model, 0.1, scheme="rk4")
    for name in ("mu", "gamma", "a11", "a22", "b11", "b12", "b22"):
        with pytest.raises(CCProofError, match=name):
            Material(**{name: -0.5})
        with pytest.raises(CCProofError, match=name):
            Material(**{name: float("nan")})
    with pytest.raises(CCProofError, match="level"):
        DynamicSurface(paper_initial_model(), levels=0)
    with pytest.raises(CCProofError):
        model.evaluate([0], [1.5], [0.2])
    with pytest.raises(CCProofError):
        model.evaluate([500], [0.5], [0.2])
    with pytest.raises(CCProofError, match="stiffness"):
        Springs(model, [0], [0.5], [0.5], [[0, 0, 1]], -1.0)
    sheet = DynamicSurface(flat_sheet())
    boundary_face = int(np.flatnonzero(sheet.layout.face_kind == 0)[0])
    with pytest.raises(CCProofError, match="no limit patch"):
        sheet.evaluate([boundary_face], [0.5], [0.5])
