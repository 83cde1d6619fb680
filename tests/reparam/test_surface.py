"""The parameterizations of bmz04 section 4 on meshes: divergence / vanishing / non-degeneracy at
extraordinary vertices, same point set, tangent continuity across edges, corner limits, errors.

Independent expected values: log2(2 lam) from the closed form of lam (R2); the limit normal at a
vertex from the eigen masks of :func:`ccproof.mesh.limit_normals`; central differences of the
composition for the chain rule; bitwise equality with the natural evaluation at F_b(t).
"""

import math

import numpy as np
import pytest

import ccproof
from ccproof.errors import CCProofError
from ccproof.mesh import QuadMesh, limit_normals, write_obj
from ccproof.mesh.examples import grid, k_regular_disk
from ccproof.reparam import Parameterization, corner_valence, limit_surface
from ccproof.reparam.blend import face_map
from ccproof.reparam.corner import _left_masks, characteristic_tangent_masks
from ccproof.reparam.quadrant import alpha_bound, default_alpha

VALENCES = [3, 5, 6, 8, 13, 20]


def lam_closed(k):
    c = math.cos(2 * math.pi / k)
    return (5 + c + math.sqrt((1 + c) * (9 + c))) / 16


def height(x, y):
    return 0.3 * x * x - 0.2 * x * y + 0.1 * y**3 + 0.05 * np.sin(2 * x)


def disk(k, roll_seed=None):
    """Non-planar k-regular disk; with a seed, each face's vertex list is rotated at random."""
    m = k_regular_disk(k, 2, height=height)
    if roll_seed is None:
        return m
    rng = np.random.default_rng(roll_seed)
    F = np.array([np.roll(f, int(rng.integers(4))) for f in m.faces])
    return QuadMesh(m.vertices, F)


@pytest.fixture(scope="module", params=VALENCES)
def surf(request):
    return request.param, limit_surface(disk(request.param))


def diagonal(S, m, param, key="Pu"):
    d = 2.0 ** -np.asarray(m, dtype=float)
    r = S.evaluate(np.zeros(d.size, dtype=np.int64), d, 0.7 * d, parameterization=param)
    return r


def test_natural_rate_is_2lam(surf):
    k, S = surf
    m = np.arange(30, 46)
    g = np.log2(np.linalg.norm(diagonal(S, m, "natural")["Pu"], axis=1))
    slope = np.polyfit(m, g, 1)[0]
    assert abs(slope - math.log2(2 * lam_closed(k))) < 2e-3, (slope, math.log2(2 * lam_closed(k)))
    if k >= 5:
        assert slope > 0.13  # diverges


def test_vanishing_tends_to_zero(surf):
    k, S = surf
    m = np.arange(12, 26)
    n = np.linalg.norm(diagonal(S, m, "vanishing")["Pu"], axis=1)
    assert (np.diff(n) < 0).all() and n[-1] < 1e-6
    # default alpha: |f o F(t) - x0| ~ |t|^2, so |dP/du| ~ |t|: slope -1 per halving
    slope = np.polyfit(m, np.log2(n), 1)[0]
    assert abs(slope + 1) < 0.06, slope
    c = S.evaluate([0], [0.0], [0.0], parameterization="vanishing")
    assert (c["Pu"] == 0).all() and (c["Pv"] == 0).all()


def test_vanishing_user_alpha():
    k = 7
    a = 1.5 * alpha_bound(k)
    S = limit_surface(disk(k), alpha=a)
    assert S.parameterizations["vanishing"].alphas(S) == {7: a}
    m = np.arange(20, 36)
    n = np.linalg.norm(diagonal(S, m, "vanishing")["Pu"], axis=1)
    slope = np.polyfit(m, np.log2(n), 1)[0]
    beta = -math.log2(lam_closed(k))
    assert abs(slope + (a * beta - 1)) < 0.03, (slope, -(a * beta - 1))  # = -0.5


def test_characteristic_nondegenerate(surf):
    k, S = surf
    m = np.arange(0, 61)
    r = diagonal(S, m, "characteristic")
    nu, nv = np.linalg.norm(r["Pu"], axis=1), np.linalg.norm(r["Pv"], axis=1)
    cr = np.linalg.norm(np.cross(r["Pu"], r["Pv"]), axis=1)
    assert 0.3 < nu.min() and nu.max() < 3 and 0.3 < nv.min() and nv.max() < 3
    c = S.evaluate([0], [0.0], [0.0], parameterization="characteristic")
    c0 = np.linalg.norm(np.cross(c["Pu"][0], c["Pv"][0]))
    assert c0 > 0.2  # rank 2 at the extraordinary vertex
    assert cr.min() > 0.2
    # the corner value is the limit of the values along the diagonal
    err = np.linalg.norm(r["Pu"] - c["Pu"], axis=1) / np.linalg.norm(c["Pu"])
    assert err[-1] < (1e-6 if k <= 8 else 2e-3) and err[-1] < err[20] < err[5]


def test_corner_normal_matches_eigen_masks(surf):
    k, S = surf
    nrm = limit_normals(S.mesh)[0]
    for f in range(0, S.mesh.n_faces, 4):  # the faces at the centre: corner 0 is the vertex
        if S.mesh.faces[f, 0] != 0:
            continue
        c = S.evaluate([f], [0.0], [0.0], parameterization="characteristic")
        n = np.cross(c["Pu"][0], c["Pv"][0])
        assert np.linalg.norm(np.cross(n / np.linalg.norm(n), nrm)) < 1e-12
        assert n @ nrm > 0


@pytest.mark.parametrize("k", [3, 5, 13])
def test_tangent_masks_structure(k):
    """T_k = rho [l_c ; cos(2pi/k) l_c + sin(2pi/k) l_s] (rotational symmetry of Phi and the masks)."""
    T = characteristic_tangent_masks(k)
    _, L = _left_masks(k)
    rho = T[0] @ L[0] / (L[0] @ L[0])
    c, s = math.cos(2 * math.pi / k), math.sin(2 * math.pi / k)
    assert rho > 0
    assert np.abs(T[0] - rho * L[0]).max() < 1e-14
    assert np.abs(T[1] - rho * (c * L[0] + s * L[1])).max() < 1e-14


def test_same_points_and_chain_rule():
    S = limit_surface(disk(5, roll_seed=1))
    rng = np.random.default_rng(7)
    n = 3000
    f = rng.integers(0, S.mesh.n_faces, n)
    u, v = rng.uniform(1e-3, 1 - 1e-3, n), rng.uniform(1e-3, 1 - 1e-3, n)
    for param in ("vanishing", "characteristic"):
        r = S.evaluate(f, u, v, 2, parameterization=param)
        y = face_map(corner_valence(S.mesh)[f], u, v, param, S.parameterizations["vanishing"].alphas(S))
        nat = S.evaluate(f, y["u"], y["v"], 0)
        assert np.abs(r["P"] - nat["P"]).max() < 1e-14  # bitwise, but for points evaluated in a corner frame
        far = ~(y["active"] & (y["quarter"] > 0) & (y["local"].max(axis=1) < 2.0**-8))
        assert np.array_equal(r["P"][far], nat["P"][far])
        assert y["active"].sum() > 100
        h = 1e-6
        for i, (du, dv) in enumerate(((h, 0), (0, h))):
            p = S.evaluate(f, u + du, v + dv, 1, parameterization=param)
            m = S.evaluate(f, u - du, v - dv, 1, parameterization=param)
            d1 = (p["P"] - m["P"]) / (2 * h)
            ref = r["Pu" if i == 0 else "Pv"]
            scale = np.linalg.norm(r["Pu"], axis=1) + np.linalg.norm(r["Pv"], axis=1)
            assert (np.linalg.norm(d1 - ref, axis=1) / scale).max() < 1e-6
            scale2 = scale + sum(np.linalg.norm(r[key], axis=1) for key in ("Puu", "Puv", "Pvv"))
            for key_d, key_2 in (("Pu", "Puu" if i == 0 else "Puv"), ("Pv", "Puv" if i == 0 else "Pvv")):
                d2 = (p[key_d] - m[key_d]) / (2 * h)
                assert (np.linalg.norm(d2 - r[key_2], axis=1) / scale2).max() < 1e-5


def _edge_pairs(mesh):
    where = {}
    for f, face in enumerate(mesh.faces):
        for i in range(4):
            where.setdefault((int(face[i]), int(face[(i + 1) % 4])), (f, i))
    out = []
    for (a, b), (f, i) in where.items():
        if (b, a) in where and a < b:
            out.append((f, i, *where[(b, a)]))
    return out


CU = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])


@pytest.mark.parametrize("param", ["natural", "vanishing", "characteristic"])
@pytest.mark.parametrize("k", [3, 5, 8])
def test_tangent_continuity_across_edges(param, k):
    S = limit_surface(disk(k, roll_seed=k))
    lam_pts = np.concatenate([2.0 ** -np.arange(1, 30), np.linspace(0, 1, 41)])
    F1, U1, V1, F2, U2, V2 = [], [], [], [], [], []
    for f, i, g, j in _edge_pairs(S.mesh):
        # point at fraction x from face f's corner i (= face g's corner j+1)
        for x in lam_pts:
            p = CU[i] + x * (CU[(i + 1) % 4] - CU[i])
            q = CU[(j + 1) % 4] + x * (CU[j] - CU[(j + 1) % 4])
            F1.append(f), U1.append(p[0]), V1.append(p[1])
            F2.append(g), U2.append(q[0]), V2.append(q[1])
    a = S.evaluate(F1, U1, V1, parameterization=param)
    b = S.evaluate(F2, U2, V2, parameterization=param)
    assert np.abs(a["P"] - b["P"]).max() < 1e-12
    na, nb = np.cross(a["Pu"], a["Pv"]), np.cross(b["Pu"], b["Pv"])
    good = (np.linalg.norm(na, axis=1) > 1e-8) & (np.linalg.norm(nb, axis=1) > 1e-8)
    if param == "natural":  # not differentiable at the extraordinary vertex itself
        irregular = corner_valence(S.mesh) > 0
        at_ev = np.concatenate([(lam_pts == 0) & irregular[f, i] | (lam_pts == 1) & irregular[f, (i + 1) % 4]
                                for f, i, _, _ in _edge_pairs(S.mesh)])
        good &= ~at_ev
    if param == "characteristic":
        assert good.all()  # non-degenerate everywhere, the vertex included
    na = na[good] / np.linalg.norm(na[good], axis=1)[:, None]
    nb = nb[good] / np.linalg.norm(nb[good], axis=1)[:, None]
    assert np.linalg.norm(na - nb, axis=1).max() < 1e-10


def test_boundary_and_regular_corners_are_identity():
    S = limit_surface(grid(3, 3))  # boundary corners with one face, valence-4 interior vertices
    rng = np.random.default_rng(0)
    f, u, v = rng.integers(0, 9, 500), rng.random(500), rng.random(500)
    nat = S.evaluate(f, u, v, 2)
    for param in ("vanishing", "characteristic"):
        r = S.evaluate(f, u, v, 2, parameterization=param)
        for key in nat:
            assert np.array_equal(r[key], nat[key])
    D = limit_surface(k_regular_disk(5, 2))
    assert (corner_valence(D.mesh)[D.mesh.is_boundary_vertex[D.mesh.faces]] == 0).all()


def test_bad_input():
    S = limit_surface(disk(5))
    with pytest.raises(CCProofError, match="unknown parameterization"):
        S.evaluate([0], [0.1], [0.1], parameterization="smooth")
    with pytest.raises(CCProofError, match="outside"):
        S.evaluate([0], [1.5], [0.1], parameterization="characteristic")
    with pytest.raises(CCProofError, match="outside"):
        S.evaluate([0], [0.5], [float("nan")], parameterization="vanishing")
    with pytest.raises(CCProofError, match="derivatives"):
        S.evaluate([0], [0.5], [0.5], 3, parameterization="vanishing")
    with pytest.raises(CCProofError, match="not above the bound"):
        limit_surface(disk(5), alpha=1.0)
    with pytest.raises(CCProofError, match="not above the bound"):
        limit_surface(disk(5), alpha={5: alpha_bound(5)})
    S5 = limit_surface(disk(5), alpha={3: 2.0})
    assert S5.parameterizations["vanishing"].alphas(S5) == {5: default_alpha(5)}


def test_top_level_and_out_argument():
    S = ccproof.limit_surface(disk(6))
    out = {key: np.empty((2, 3)) for key in ("P", "Pu", "Pv")}
    r = S.evaluate([0, 1], [0.1, 0.3], [0.2, 0.0], parameterization="characteristic", out=out)
    assert r is out and np.isfinite(out["Pu"]).all()


def test_cli(tmp_path):
    from ccproof.cli import main

    mesh = disk(5, roll_seed=2)
    obj = tmp_path / "d5.obj"
    write_obj(obj, mesh)
    pts = tmp_path / "pts.csv"
    rng = np.random.default_rng(1)
    f, u, v = rng.integers(0, mesh.n_faces, 50), rng.random(50), rng.random(50)
    u[0] = v[0] = 0.0
    pts.write_text("face,u,v\n" + "".join(f"{a},{float(b)!r},{float(c)!r}\n" for a, b, c in zip(f, u, v)))
    out = tmp_path / "o.npz"
    assert main(["eval", str(obj), "--points", str(pts), "--parameterization", "characteristic",
                 "--derivatives", "1", "--out", str(out)]) == 0
    z = np.load(out)
    ref = limit_surface(obj).evaluate(f, u, v, 1, parameterization="characteristic")
    for key in ("P", "Pu", "Pv"):
        assert np.array_equal(z[key], ref[key])
    assert main(["eval", str(obj), "--samples", "10", "--parameterization", "vanishing", "--alpha", "0.5",
                 "--out", str(out)]) == 2


def test_positions_do_not_depend_on_the_derivative_order():
    S = limit_surface(disk(6, roll_seed=3))
    rng = np.random.default_rng(4)
    f = rng.integers(0, S.mesh.n_faces, 2000)
    u = np.concatenate([rng.random(1000), 1 - 2.0 ** -rng.uniform(5, 40, 1000)])
    v = np.concatenate([rng.random(1000), 1 - 2.0 ** -rng.uniform(5, 40, 1000)])
    for param in ("vanishing", "characteristic"):
        p0 = S.evaluate(f, u, v, 0, parameterization=param)["P"]
        for d in (1, 2):
            assert np.array_equal(S.evaluate(f, u, v, d, parameterization=param)["P"], p0)


def test_parameterization_is_a_value():
    """The value passed to the evaluator of any quad mesh gives the named parameterization's bits;
    the natural value is the evaluator's own; names unknown to a surface and tagged meshes are refused."""
    from ccproof.evaluate import natural_limit_surface
    from ccproof.mesh import PolyMesh

    mesh = disk(5, roll_seed=5)
    S, N = limit_surface(mesh, alpha=2.5), natural_limit_surface(mesh)
    rng = np.random.default_rng(6)
    f = rng.integers(0, mesh.n_faces, 400)
    u = np.concatenate([rng.random(200), 1 - 2.0 ** -rng.uniform(5, 40, 200)])
    v = np.concatenate([rng.random(200), 2.0 ** -rng.uniform(5, 40, 200)])
    for p in (Parameterization("vanishing", 2.5), Parameterization("characteristic")):
        a = S.evaluate(f, u, v, 2, parameterization=p.kind)
        b = N.evaluate(f, u, v, 2, parameterization=p)
        for key in a:
            assert np.array_equal(a[key], b[key], equal_nan=True), (p, key)
    nat = N.evaluate(f, u, v, 2)
    r = N.evaluate(f, u, v, 2, parameterization=Parameterization("natural"))
    assert all(np.array_equal(r[k], nat[k]) for k in nat)
    assert Parameterization("vanishing", {5: 2.5}) == Parameterization("vanishing", {5: 2.5})
    with pytest.raises(CCProofError, match="unknown parameterization 'vanishing' for this surface"):
        N.evaluate(f, u, v, parameterization="vanishing")
    with pytest.raises(CCProofError, match="evaluate_on"):
        N.evaluate(f, u, v, parameterization=3)
    with pytest.raises(CCProofError, match="unknown parameterization"):
        Parameterization("smooth")
    with pytest.raises(CCProofError, match="alpha applies to the vanishing"):
        Parameterization("characteristic", alpha=2.0)
    with pytest.raises(CCProofError, match="not above the bound"):
        N.evaluate(f, u, v, parameterization=Parameterization("vanishing", 1.0))
    tri = PolyMesh([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0.5]], [[0, 1, 2], [1, 3, 2]])
    T = ccproof.limit_surface(tri)
    with pytest.raises(CCProofError, match="unknown parameterization 'characteristic'"):
        T.evaluate([0], [0.1], [0.1], parameterization="characteristic")
    with pytest.raises(CCProofError, match="need an untagged all-quad mesh"):
        T.evaluate([0], [0.1], [0.1], parameterization=Parameterization("characteristic"))


@pytest.mark.parametrize("param", ["natural", "vanishing", "characteristic"])
def test_a_point_does_not_depend_on_its_batch_or_the_threads(param):
    """Every parameterization gives a point the same bits alone, in batches of any size, at any place
    in its batch and on 1 or 2 threads (what makes chunked and distributed evaluations equal an
    evaluation of all points at once). Points near and at the corners of valence 3, 5 and boundary."""
    S = limit_surface(disk(5, roll_seed=2))
    rng = np.random.default_rng(8)
    n = 3000
    f = rng.integers(0, S.mesh.n_faces, n)
    u = np.concatenate([rng.random(n // 2), 2.0 ** -rng.uniform(1, 40, n // 2)])
    v = np.concatenate([rng.random(n // 2), rng.random(n // 2) * 2.0 ** -rng.uniform(0, 30, n // 2)])
    u[:60], v[:60] = rng.choice([0.0, 1.0], 60), rng.choice([0.0, 1.0], 60)  # at the corners
    flip = rng.random(n) < 0.5
    u[flip], v[flip] = 1.0 - u[flip], v[flip]
    whole = S.evaluate(f, u, v, 2, parameterization=param)

    def same(r, rows=slice(None)):
        return all(np.ascontiguousarray(whole[k][rows]).tobytes() == np.ascontiguousarray(r[k]).tobytes()
                   for k in whole)

    cuts = np.unique(np.r_[0, np.cumsum(rng.integers(1, 40, n)), n])
    parts = [S.evaluate(f[a:b], u[a:b], v[a:b], 2, parameterization=param) for a, b in zip(cuts[:-1], cuts[1:])
             if a < n]
    assert same({k: np.concatenate([p[k] for p in parts]) for k in whole})
    for i in range(0, n, 97):
        assert same(S.evaluate(f[i:i + 1], u[i:i + 1], v[i:i + 1], 2, parameterization=param), slice(i, i + 1)), i
    rev = np.arange(n)[::-1]
    assert same(S.evaluate(f[rev], u[rev], v[rev], 2, parameterization=param), rev)
    assert same(S.evaluate(f, u, v, 2, parameterization=param, threads=2))
