"""Q4 (special elements = limit surface near extraordinary vertices) and Q5 (refinement identities)."""

import numpy as np
import pytest

from ccproof.apps.dynamics.meshes import open_surface_valence5, paper_initial_model, torus_32
from ccproof.apps.dynamics.model import DynamicSurface, Material
from ccproof.mesh import limit_positions, subdivide

CORNER = np.array([(0, 0), (1, 0), (1, 1), (0, 1)], dtype=float)


def to_child(f, u, v):
    """The child face of ccproof.mesh.subdivide holding (u, v) of face f, the child parameter and d(child)/d(parent).

    Child 4 f + i covers the quarter at corner i; its corner 0 is the parent's corner i and its u axis runs
    towards the parent's corner i + 1 (ccproof.mesh.subdivision docstring).
    """
    i = np.where(u < 0.5, np.where(v < 0.5, 0, 3), np.where(v < 0.5, 1, 2))
    d = np.stack([u, v], -1) - CORNER[i]
    eu = CORNER[(i + 1) % 4] - CORNER[i]
    ev = CORNER[(i + 3) % 4] - CORNER[i]
    J = 2 * np.stack([eu, ev], 1)  # rows: d(u', v')/d(u, v)
    x = np.einsum("nab,nb->na", J, d)
    return 4 * f + i, x[:, 0], x[:, 1], J


def perturbed(mesh, seed=0, amp=0.1):
    rng = np.random.default_rng(seed)
    return mesh.with_vertices(np.asarray(mesh.vertices) + amp * rng.standard_normal(mesh.vertices.shape))


def sector_points(model, rng, ring, count):
    """Random points of every special face in ring `ring` (2^-(ring+1) <= max(s, t) < 2^-ring)."""
    lay = model.layout
    F, U, W = [], [], []
    for e in range(lay.n_special):
        for f, c in zip(lay.special_faces[e], lay.special_corners[e]):
            s = rng.uniform(0, 2.0**-ring, (4 * count, 2))
            s = s[s.max(1) >= 2.0 ** -(ring + 1)][:count]
            st = [(s[:, 0], s[:, 1]), (1 - s[:, 1], s[:, 0]), (1 - s[:, 0], 1 - s[:, 1]), (s[:, 1], 1 - s[:, 0])]
            u, v = st[c]
            F.append(np.full(u.size, f))
            U.append(u)
            W.append(v)
    return np.concatenate(F), np.concatenate(U), np.concatenate(W)


@pytest.mark.parametrize("make", [paper_initial_model, open_surface_valence5])
def test_q4_special_element_equals_explicit_subdivision(make):
    """J(u, v) p in ring i equals the regular patch after i + 1 global CC steps (values, 1st, 2nd derivatives)."""
    mesh = perturbed(make())
    model = DynamicSurface(mesh)
    rng = np.random.default_rng(1)
    meshes = [mesh]
    for _ in range(4):
        meshes.append(subdivide(meshes[-1]))
    for ring in range(4):
        f, u, v = sector_points(model, rng, ring, 5)
        got = model.evaluate(f, u, v, 2)
        J = np.broadcast_to(np.eye(2), (f.size, 2, 2))
        ff, uu, vv = f, u, v
        for _ in range(ring + 1):
            ff, uu, vv, Jm = to_child(ff, uu, vv)
            J = Jm @ J
        fine = DynamicSurface(meshes[ring + 1])
        assert (fine.layout.face_kind[ff] == 1).all()  # regular patches at level ring + 1
        ref = fine.evaluate(ff, uu, vv, 2)
        a, b, c, d = J[:, 0, 0, None], J[:, 0, 1, None], J[:, 1, 0, None], J[:, 1, 1, None]
        chain = {
            "P": ref["P"],
            "Pu": a * ref["Pu"] + c * ref["Pv"],
            "Pv": b * ref["Pu"] + d * ref["Pv"],
            "Puu": a * a * ref["Puu"] + 2 * a * c * ref["Puv"] + c * c * ref["Pvv"],
            "Puv": a * b * ref["Puu"] + (a * d + c * b) * ref["Puv"] + c * d * ref["Pvv"],
            "Pvv": b * b * ref["Puu"] + 2 * b * d * ref["Puv"] + d * d * ref["Pvv"],
        }
        h = 2.0 ** (ring + 1)
        for k, order in (("P", 0), ("Pu", 1), ("Pv", 1), ("Puu", 2), ("Puv", 2), ("Pvv", 2)):
            assert np.abs(got[k] - chain[k]).max() / h**order < 1e-12, (ring, k)


@pytest.mark.parametrize("make", [paper_initial_model, open_surface_valence5])
def test_q4_converges_to_limit_point(make):
    mesh = perturbed(make(), seed=2)
    model = DynamicSurface(mesh)
    lay = model.layout
    lim = limit_positions(mesh)
    from ccproof.algebra.specialize import subdominant_eigenvalue

    for e in range(lay.n_special):
        f, c = lay.special_faces[e][0], lay.special_corners[e][0]
        ev = lay.special_ev[e]
        lam = subdominant_eigenvalue(int(lay.special_valence[e]), "float")
        for L in (4, 8, 12, 20):
            t = 2.0**-L
            u, v = [(t, t), (1 - t, t), (1 - t, 1 - t), (t, 1 - t)][c]
            err = np.linalg.norm(model.evaluate([f], [u], [v])["P"][0] - lim[ev])
            assert err < 3 * lam**L
        u, v = CORNER[c]
        assert np.abs(model.evaluate([f], [u], [v])["P"][0] - lim[ev]).max() < 1e-14


def test_q4_matches_exact_evaluator():
    from ccproof import evaluate

    rng = np.random.default_rng(5)
    for make in (paper_initial_model, open_surface_valence5):
        mesh = perturbed(make(), seed=3, amp=0.05)
        model = DynamicSurface(mesh)
        f = rng.choice(np.flatnonzero(model.layout.face_kind > 0), 3000)
        u, v = rng.random(3000) ** 3, rng.random(3000) ** 3  # many points close to the corners
        u, v = np.maximum(u, 1e-9), np.maximum(v, 1e-9)
        a = model.evaluate(f, u, v, 2)
        b = evaluate.limit_surface(mesh).evaluate(f, u, v, 2)
        for k in a:
            rel = np.linalg.norm(a[k] - b[k], axis=1) / (1 + np.linalg.norm(b[k], axis=1))
            assert rel.max() < 1e-11, k


def test_basis_rows_equal_evaluation():
    mesh = perturbed(open_surface_valence5(), seed=4)
    model = DynamicSurface(mesh)
    rng = np.random.default_rng(0)
    f = rng.choice(np.flatnonzero(model.layout.face_kind > 0), 500)
    u, v = rng.random(500), rng.random(500)
    B = model.basis(f, u, v, 2)
    E = model.evaluate(f, u, v, 2)
    assert sorted(B) == ["Du", "Duu", "Duv", "Dv", "Dvv", "P"]  # LimitSurface.basis's keys
    for k in E:
        rows = B[k if k == "P" else "D" + k[1:]]
        assert np.abs(rows @ np.asarray(mesh.vertices) - E[k]).max() < 1e-11 * (1 + np.abs(E[k]).max())
    assert np.allclose(np.asarray(B["P"].sum(axis=1)).ravel(), 1.0, atol=1e-13)


# ---------------------------------------------------------------------------- Q5


ISO = Material(mu=1.3, gamma=0.4, a11=0.8, a22=0.8, b11=0.5, b12=1.0, b22=0.5)
ANISO = Material(mu=1.3, gamma=0.4, a11=0.7, a22=1.3, b11=0.5, b12=1.1, b22=1.7)


@pytest.mark.parametrize("mat", [ISO, ANISO])
def test_q5_refinement_identities_torus(mat):
    mem = Material(mu=mat.mu, gamma=mat.gamma, a11=mat.a11, a22=mat.a22, b11=0, b12=0, b22=0)
    plate = Material(mu=mat.mu, gamma=mat.gamma, a11=0, a22=0, b11=mat.b11, b12=mat.b12, b22=mat.b22)
    for m, factor in ((mem, 1.0), (plate, 0.25)):
        coarse = DynamicSurface(torus_32(), m)
        fine, A = coarse.refine(rescale=False)
        assert np.abs(A.T @ fine.mass_matrix() @ A - 4 * coarse.mass_matrix()).max() < 1e-12
        assert np.abs(A.T @ fine.stiffness_matrix() @ A - factor * coarse.stiffness_matrix()).max() < 1e-12
    # with the rescaled densities (Material.refined) every energy is unchanged
    coarse = DynamicSurface(torus_32(), mat)
    fine, A = coarse.refine(rescale=True)
    assert np.abs(A.T @ fine.mass_matrix() @ A - coarse.mass_matrix()).max() < 1e-12
    assert np.abs(A.T @ fine.stiffness_matrix() @ A - coarse.stiffness_matrix()).max() < 1e-12


def test_q5_least_squares_route_is_not_the_refined_model():
    """Eq. (22) taken literally (M_q = B^T M B) is rank-deficient: it is not the rebuilt matrix."""
    coarse = DynamicSurface(torus_32(), ISO)
    fine, A = coarse.refine(rescale=True)
    A = A.toarray()
    Bm = np.linalg.solve(A.T @ A, A.T)
    Mq = Bm.T @ coarse.mass_matrix().toarray() @ Bm
    assert np.linalg.matrix_rank(Mq) == coarse.n_vertices < fine.n_vertices
    assert np.linalg.matrix_rank(fine.mass_matrix().toarray()) == fine.n_vertices


@pytest.mark.parametrize("mat", [ISO, ANISO])
def test_q5_refinement_with_extraordinary_vertices(mat):
    """Cube x2: mass identity exact (Stein); stiffness identity exact with one more truncation level."""
    mesh = perturbed(paper_initial_model(), seed=6)
    coarse = DynamicSurface(mesh, mat, levels=4)
    fine, A = coarse.refine(rescale=True)
    assert np.abs(A.T @ fine.mass_matrix() @ A - coarse.mass_matrix()).max() < 1e-12
    deeper = DynamicSurface(mesh, mat, levels=5)
    KA = A.T @ fine.stiffness_matrix() @ A
    assert np.abs(KA - deeper.stiffness_matrix()).max() < 1e-11
    assert np.abs(KA - coarse.stiffness_matrix()).max() > 1e-6  # the level-5 increment is really there


def test_q5_limit_surface_unchanged_by_refinement():
    for make in (torus_32, paper_initial_model, open_surface_valence5):
        mesh = perturbed(make(), seed=7)
        coarse = DynamicSurface(mesh)
        fine, A = coarse.refine()
        rng = np.random.default_rng(8)
        f = rng.choice(np.flatnonzero(coarse.layout.face_kind > 0), 400)
        u, v = rng.random(400), rng.random(400)
        fc, uc, vc, _ = to_child(f, u, v)
        a = coarse.evaluate(f, u, v)["P"]
        b = fine.evaluate(fc, uc, vc, P=np.asarray(A @ np.asarray(mesh.vertices)))["P"]
        assert np.abs(a - b).max() < 1e-12
