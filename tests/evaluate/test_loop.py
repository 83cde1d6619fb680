"""Exact Loop evaluation (ccproof.evaluate.loop) against brute-force global subdivision and OpenSubdiv.

The reference (tests/evaluate/_loop_brute.py) subdivides the whole mesh L levels with its own copy of
the Sdc Loop rules and reads the limit position (limit masks), and at vertices with a regular
neighbourhood the box spline's exact derivatives from the one-ring, at the dyadic parameters that land
on level-L vertices.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest

from ccproof.errors import CCProofError
from ccproof.evaluate.loop import LoopSurface
from ccproof.mesh.polymesh import PolyMesh

sys.path.insert(0, str(Path(__file__).parent))
from _loop_brute import Level, brute, levels  # noqa: E402

TOL = 1e-12
KEYS = ("P", "Pu", "Pv", "Puu", "Puv", "Pvv")


def octahedron(seed=1):
    V = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]], float)
    V += np.random.default_rng(seed).normal(0, 0.2, V.shape)
    return V, [[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]]


def icosahedron(seed=5):
    p = (1 + 5**0.5) / 2
    V = np.array([[-1, p, 0], [1, p, 0], [-1, -p, 0], [1, -p, 0], [0, -1, p], [0, 1, p], [0, -1, -p], [0, 1, -p],
                  [p, 0, -1], [p, 0, 1], [-p, 0, -1], [-p, 0, 1]], float)
    V += np.random.default_rng(seed).normal(0, 0.1, V.shape)
    T = [[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9], [5, 11, 4], [11, 10, 2], [10, 7, 6],
         [7, 1, 8], [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8], [3, 8, 9], [4, 9, 5], [2, 4, 11], [6, 2, 10],
         [8, 6, 7], [9, 8, 1]]
    return V, T


def grid(n, seed=2):
    V = np.array([[i, j, 0.0] for j in range(n + 1) for i in range(n + 1)])
    V[:, 2] = np.random.default_rng(seed).normal(0, 0.3, len(V))
    T = []
    for j in range(n):
        for i in range(n):
            a, b, c, d = j * (n + 1) + i, j * (n + 1) + i + 1, (j + 1) * (n + 1) + i, (j + 1) * (n + 1) + i + 1
            T += [(a, b, c), (b, d, c)]
    return V, T


def flip_edges(T, count, seed, max_valence=8):
    """``count`` random interior edge flips keeping valences in [3, max_valence]."""
    rng = np.random.default_rng(seed)
    T = [list(t) for t in T]
    for _ in range(50 * count):
        if count == 0:
            break
        opp, nb = {}, {}
        for fi, (a, b, c) in enumerate(T):
            opp[(a, b)], opp[(b, c)], opp[(c, a)] = (fi, c), (fi, a), (fi, b)
        for a, b in opp:
            nb.setdefault(a, set()).add(b)
        inner = sorted(e for e in opp if (e[1], e[0]) in opp and e[0] < e[1])
        a, b = inner[rng.integers(len(inner))]
        (f1, c), (f2, d) = opp[(a, b)], opp[(b, a)]
        if d in nb[c] or min(len(nb[a]), len(nb[b])) <= 3 or max(len(nb[c]), len(nb[d])) >= max_valence:
            continue
        T[f1], T[f2] = [c, d, b], [d, c, a]
        count -= 1
    return T


def compare(V, T, L, faces, derivatives=2, **tags):
    """Largest error per key (relative to max(1, |value|)) over the level-L vertices of ``faces``."""
    sharp, corner_tags = tags.get("sharp", ()), tags.get("corners", ())
    creases = dict(sharp) if isinstance(sharp, dict) else dict.fromkeys(sharp, math.inf)
    corners = dict(corner_tags) if isinstance(corner_tags, dict) else dict.fromkeys(corner_tags, math.inf)
    mesh = PolyMesh(V, T, creases=creases, corners=corners, options={"boundary": tags.get("boundary", "edge_only")})
    S = LoopSurface(mesh)
    # the tags as the mesh holds them (OpenSubdiv's float32 sharpness)
    lv = levels(V, T, L, sharp=dict(mesh.edge_sharpness), corners=dict(mesh.vertex_sharpness),
                boundary=mesh.options.boundary)
    pts = [(f, i / 2**L, j / 2**L) for f in faces for i in range(2**L + 1) for j in range(2**L + 1 - i)]
    R = S.evaluate([p[0] for p in pts], [p[1] for p in pts], [p[2] for p in pts], derivatives)
    err, count = {}, {}
    for m, (f, u, v) in enumerate(pts):
        for k, x in brute(lv, f, u, v).items():
            if k in R:
                err[k] = max(err.get(k, 0.0), float(np.abs(R[k][m] - x).max() / max(1.0, np.abs(x).max())))
                count[k] = count.get(k, 0) + 1
    return err, count, S


def _check(err, count, keys=KEYS, min_derivative_points=20):
    assert set(keys) <= set(err), (keys, err)
    assert min(count[k] for k in keys if k != "P") >= min_derivative_points, count
    assert max(err.values()) < TOL, err


@pytest.mark.parametrize("mesh, L, faces", [(octahedron, 4, (0, 3, 6)), (icosahedron, 3, range(0, 20, 3))])
def test_platonic_meshes_against_brute_force(mesh, L, faces):
    """Valence 4 (octahedron: every triangle has three extraordinary corners, split once) and valence 5."""
    V, T = mesh()
    err, count, S = compare(V, T, L, faces)
    _check(err, count)
    assert S.split_depth == 1 and S.n_corner == 3 * len(T)


def test_valences_3_to_8_against_brute_force():
    """Level-1 icosahedron with edge flips: interior vertices of valence 3 to 8, next to each other."""
    V, T = icosahedron(seed=7)
    one = Level(V, T).subdivide()
    F = flip_edges(one.F, 40, seed=11)
    val = Level(one.V, F)
    valences = {len(val.nbrs[v]) for v in val.nbrs}
    assert valences == set(range(3, 9)), valences
    err, count, _ = compare(one.V, F, 3, range(0, 80, 4))
    _check(err, count)


@pytest.mark.parametrize("boundary", ["edge_only", "edge_and_corner"])
def test_open_mesh_with_boundary_corners(boundary):
    """A grid with flips: boundary vertices of 1 to 4 triangles, boundary corners (one triangle: a crease
    vertex with edge_only, a corner with edge_and_corner), interior extraordinary vertices."""
    V, T = grid(4)
    T = flip_edges(T, 6, seed=3)
    err, count, _ = compare(V, T, 3, range(len(T)), boundary=boundary)
    _check(err, count)


def test_creases_corners_and_darts():
    """Icosahedron with a closed crease loop, a corner on it, and an open crease chain (two darts)."""
    V, T = icosahedron()
    loop = [0, 1, 9, 3, 2, 11, 0]
    sharp = [(a, b) for a, b in zip(loop, loop[1:])]
    err, count, S = compare(V, T, 3, range(20), sharp=sharp, corners=[9])
    _check(err, count)
    err, count, _ = compare(V, T, 3, range(20), sharp=[(5, 4), (4, 2)])
    _check(err, count)


@pytest.mark.parametrize("s", [0.5, 1.0, 1.7])
def test_semi_sharp_creases_and_corners(s):
    """Semi-sharp tags (Sdc's uniform creasing: decay by 1 per level, fractional edge and vertex rules):
    a closed crease loop of sharpness s, an open chain of mixed sharpness ending in the interior, a
    semi-sharp corner."""
    V, T = icosahedron()
    loop = [0, 1, 9, 3, 2, 11, 0]
    sharp = {(min(a, b), max(a, b)): s for a, b in zip(loop, loop[1:])}
    sharp.update({(4, 5): 2.5, (4, 11): s / 2})
    err, count, S = compare(V, T, 3, range(20), sharp=sharp, corners={7: 1.3})
    _check(err, count)
    assert S.split_depth >= 2


def test_points_near_and_at_an_extraordinary_vertex():
    """Deep layers: the distance to the limit point decays like lam^n (lam = 3/8 + cos(2 pi / 5) / 4 at
    valence 5); below the last layer and at the vertex itself the limit point of the limit mask."""
    V, T = icosahedron()
    S = LoopSurface(PolyMesh(V, T))
    lim = brute(levels(V, T, 0), 0, 0, 0)["P"]
    lam = 3 / 8 + math.cos(2 * math.pi / 5) / 4
    s = 2.0 ** -np.arange(1, 80)
    P = S.evaluate(np.zeros(s.size, int), s, np.zeros(s.size))["P"]
    d = np.linalg.norm(P - lim, axis=1)
    bound = lam ** np.arange(1, 80)
    assert np.all(d <= 10 * bound + 1e-15)
    assert np.all(d[10:30] >= 0.01 * bound[10:30])
    at = S.evaluate([0, 0], [0.0, 1e-300], [0.0, 0.0])["P"]
    assert np.abs(at - lim).max() < 1e-15


def test_refusals():
    V, T = octahedron()
    quad = PolyMesh([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [2, 0, 0]], [[0, 1, 4], [0, 4, 2, 3]])
    with pytest.raises(CCProofError, match=r"triangles only: face 1 has 4 vertices"):
        LoopSurface(quad)
    with pytest.raises(CCProofError, match=r"semi-sharp tags with uniform creasing only, not 'chaikin'"):
        LoopSurface(PolyMesh(V, T, creases={(0, 2): 2.0}, options={"crease_method": "chaikin"}))
    S = LoopSurface(PolyMesh(V, T))
    with pytest.raises(CCProofError, match=r"point 1: face 2, \(u, v\) = \(0.75, 0.5\) is not in a triangle"):
        S.evaluate([0, 2], [0.1, 0.75], [0.1, 0.5])
    with pytest.raises(CCProofError, match=r"point 0: face 8"):
        S.evaluate([8], [0.1], [0.1])
    with pytest.raises(CCProofError, match="'vanishing' parameterization is Catmull-Clark's"):
        S.evaluate([0], [0.1], [0.1], parameterization="vanishing")
    import ccproof

    with pytest.raises(CCProofError, match="alpha applies to the Catmull-Clark parameterizations"):
        ccproof.limit_surface(PolyMesh(V, T), 2.5, scheme="loop")
    with pytest.raises(CCProofError, match="scheme must be 'catmark' or 'loop', got 'butterfly'"):
        ccproof.limit_surface(PolyMesh(V, T), scheme="butterfly")


def test_limit_surface_scheme_switches_the_rules():
    """scheme="loop" evaluates Loop's surface (brute force), not Catmull-Clark's of the same triangles."""
    import ccproof

    V, T = octahedron()
    loop = ccproof.limit_surface(PolyMesh(V, T), scheme="loop")
    cc = ccproof.limit_surface(PolyMesh(V, T))
    lim = brute(levels(V, T, 0), 0, 0, 0)["P"]
    assert np.abs(loop.evaluate([0], [0.0], [0.0])["P"][0] - lim).max() < 1e-15
    assert np.abs(cc.evaluate([0], [0.0], [0.0])["P"][0] - lim).max() > 1e-3  # ptex face 0's corner 0: vertex 0


def test_cli_scheme_loop(tmp_path, capsys):
    from ccproof.cli.__main__ import main

    V, T = icosahedron()
    obj = tmp_path / "ico.obj"
    obj.write_text("".join(f"v {x} {y} {z}\n" for x, y, z in V) + "".join(f"f {a + 1} {b + 1} {c + 1}\n"
                                                                          for a, b, c in T))
    pts = tmp_path / "p.csv"
    pts.write_text("face,u,v\n3,0.25,0.5\n7,0,0\n")
    assert main(["eval", str(obj), "--scheme", "loop", "--points", str(pts), "--out", str(tmp_path / "o.npz"),
                 "--serial"]) == 0
    d = np.load(tmp_path / "o.npz")
    lv = levels(V, T, 2)
    for i, (f, u, v) in enumerate([(3, 0.25, 0.5), (7, 0.0, 0.0)]):
        assert np.abs(d["P"][i] - brute(lv, f, u, v)["P"]).max() < TOL
    pts.write_text("face,u,v\n3,0.75,0.5\n")
    assert main(["eval", str(obj), "--scheme", "loop", "--points", str(pts), "--out", str(tmp_path / "o2.npz")]) != 0
    assert "p.csv:2: point 0: u + v = 1.25 > 1 is outside triangle 3" in capsys.readouterr().err
    quads = tmp_path / "quad.obj"
    quads.write_text("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n")
    assert main(["eval", str(quads), "--scheme", "loop", "--samples", "3", "--out", str(tmp_path / "o3.npz")]) != 0
    assert "--scheme loop takes triangles only: face 0 has 4 vertices" in capsys.readouterr().err


# ------------------------------------------------------------------------------ OpenSubdiv
def _osd():
    root = Path(__file__).resolve().parents[2] / "scripts"
    sys.path.insert(0, str(root))
    import _osd

    why = _osd.why_unavailable()
    if why:
        pytest.skip(why)
    try:
        return _osd, _osd.load()
    except RuntimeError as e:
        pytest.skip(str(e))


@pytest.mark.parametrize("case", ["icosahedron", "creased_open_grid", "semi_sharp"])
def test_against_opensubdiv_loop_patches(case):
    """Far's Loop PatchTable (isolation level 6): at every point on a regular Loop patch (no end cap) the
    same P, Pu, Pv to 1e-12 (relative to max(1, |value|))."""
    _osd_mod, lib = _osd()
    if case == "icosahedron":
        V, T = icosahedron()
        mesh = PolyMesh(V, T)
    elif case == "semi_sharp":
        V, T = icosahedron()
        mesh = PolyMesh(V, T, creases={(0, 1): 1.5, (1, 9): 0.7, (3, 9): 3.2, (2, 4): 2.5}, corners={7: 1.3})
    else:
        V, T = grid(5)
        T = flip_edges(T, 8, seed=4)
        mesh = PolyMesh(V, T, creases={(7, 8): math.inf, (8, 9): math.inf}, corners={0: math.inf})
    far = _osd_mod.Evaluator(lib, "far", mesh, level=6, scheme="loop")
    rng = np.random.default_rng(0)
    n = 4000
    f = rng.integers(0, len(T), n)
    u, v = rng.random(n), rng.random(n)
    flip = u + v > 1
    u[flip], v[flip] = 1 - u[flip], 1 - v[flip]
    exact = far.patch_types(f, u, v) == 5  # PatchDescriptor::LOOP
    assert exact.sum() > 0.9 * n
    P, Ps, Pt = far.evaluate(f[exact], u[exact], v[exact])
    R = LoopSurface(mesh).evaluate(f[exact], u[exact], v[exact], 1)
    for ours, theirs in ((R["P"], P), (R["Pu"], Ps), (R["Pv"], Pt)):
        assert np.max(np.abs(ours - theirs) / np.maximum(1, np.abs(theirs))) < TOL


def test_numpy_backend_equals_compiled():
    """The vectorized numpy path (nets and layer tables times the box-spline basis) and the compiled kernel
    (precomputed polynomial blocks, deeper layers from the ring): equal to rounding."""
    V, T = icosahedron(seed=7)
    one = Level(V, T).subdivide()
    F = flip_edges(one.F, 40, seed=11)
    mesh = PolyMesh(one.V, F)
    rng = np.random.default_rng(3)
    n = 3000
    f = rng.integers(0, len(F), n)
    u, v = rng.random(n), rng.random(n)
    flip = u + v > 1
    u[flip], v[flip] = 1 - u[flip], 1 - v[flip]
    u[:50], v[:50] = 2.0 ** -rng.integers(1, 70, 50), 0.0  # deep layers
    A = LoopSurface(mesh).evaluate(f, u, v, 2)
    B = LoopSurface(mesh, backend="numpy").evaluate(f, u, v, 2)
    for k in KEYS:
        assert np.max(np.abs(A[k] - B[k]) / np.maximum(1, np.abs(B[k]))) < TOL, k


def test_outputs_do_not_depend_on_the_order_or_the_batch():
    """Each point's outputs are bit-identical whether it comes in a large call, permuted, or in small calls,
    on regular, split and corner patches, in the stored layers and deeper ones."""
    V, T = icosahedron(seed=3)
    F = flip_edges(Level(V, T).subdivide().F, 20, seed=4)
    S = LoopSurface(PolyMesh(Level(V, T).subdivide().V, F))
    rng = np.random.default_rng(8)
    n = 8192
    f = rng.integers(0, len(F), n)
    u, v = rng.random(n), rng.random(n)
    flip = u + v > 1
    u[flip], v[flip] = 1 - u[flip], 1 - v[flip]
    s = 2.0 ** -rng.integers(0, 80, n // 4)  # layers 0 .. 79 at every corner
    u[: n // 4], v[: n // 4] = s * rng.random(n // 4), 0.0
    v[: n // 8] = s[: n // 8] * (1 - u[: n // 8] / s[: n // 8]) * rng.random(n // 8)
    A = S.evaluate(f, u, v, 2)
    p = rng.permutation(n)
    B = S.evaluate(f[p], u[p], v[p], 2)
    C = [S.evaluate(f[i:i + 100], u[i:i + 100], v[i:i + 100], 2) for i in range(0, n, 100)]
    for k in KEYS:
        assert np.array_equal(A[k][p], B[k]), k
        assert np.array_equal(A[k], np.concatenate([c[k] for c in C])), k


def test_vectorized_regular_nets_equal_the_per_configuration_path():
    """The whole-mesh gather of regular nets (numpy) and the exact per-configuration nets agree."""
    from ccproof.evaluate.loop.complex import TriComplex
    from ccproof.evaluate.loop.plan import Regular, oriented_ring, plan
    from ccproof.evaluate.loop.regular import regular_triangles

    V, T = icosahedron(seed=7)
    one = Level(V, T).subdivide().subdivide()
    F = np.array(flip_edges(one.F, 8, seed=5))
    reg, labels, _, _ = regular_triangles(F, len(one.V))
    assert 0.2 * len(F) < reg.sum() < len(F)
    cx = TriComplex([tuple(f) for f in F.tolist()])
    for k, f in enumerate(np.flatnonzero(reg)):
        r, ring, key = oriented_ring(cx, tuple(F[f].tolist()))
        p = plan(key)
        assert r == 0 and isinstance(p, Regular)
        assert np.array_equal(p.net @ one.V[ring], one.V[labels[k]])


def _random_tags_icosphere():
    """A flipped level-1 icosphere with random semi-sharp and infinitely sharp creases, corners and holes: the
    level, the mesh and the generator (its stream goes on where the tags left it)."""
    V, T = icosahedron(seed=3)
    one = Level(V, T).subdivide()
    F = flip_edges(one.F, 25, seed=1)
    rng = np.random.default_rng(1)
    E = sorted({(min(a, b), max(a, b)) for f in F for a, b in zip(f, f[1:] + f[:1])})
    creases = {E[i]: float(rng.choice([0.25, 1.0, 1.5, 2.75, math.inf])) for i in rng.choice(len(E), 25, replace=False)}
    corners = {int(x): float(rng.choice([0.625, 2.25, math.inf])) for x in rng.choice(len(one.V), 3, replace=False)}
    return one, PolyMesh(one.V, F, creases=creases, corners=corners, holes=[5, 17]), rng


def _tagged_meshes():
    V, T = grid(6)
    T = flip_edges(T, 6, seed=3)
    out = [PolyMesh(V, T, options={"boundary": b}) for b in ("edge_only", "edge_and_corner")]
    V, T = grid(8)
    creases = {(i, i + 1): math.inf for i in range(36, 44)} | {(9 * i + 4, 9 * i + 13): math.inf for i in range(8)}
    out.append(PolyMesh(V, T, creases=creases, corners={40: math.inf}))
    one, mesh, _ = _random_tags_icosphere()
    out.append(mesh)
    two = one.subdivide()  # creases on every 40th edge: rings whose keys from corner 0 agree, from corner 1 not
    E = sorted({(min(a, b), max(a, b)) for f in two.F for a, b in zip(f, f[1:] + f[:1])})
    out.append(PolyMesh(two.V, two.F, creases=dict.fromkeys(E[::40], math.inf)))
    return out


@pytest.mark.parametrize("backend", ["numba", "numpy"])
def test_rings_read_at_once_equal_the_per_triangle_path(monkeypatch, backend):
    """The rings of the boundary, crease and corner triangles read at once and grouped by key (compiled) give the
    same surface, to the bit, as each triangle's ring read on its own (grids with boundary corners in both
    boundary modes, creases and a corner tag, semi-sharp tags and holes); the per-triangle way is kept for a
    new key only."""
    from ccproof.evaluate.loop import surface

    rng = np.random.default_rng(4)
    for mesh in _tagged_meshes():
        f = np.flatnonzero(~mesh.is_hole)[rng.integers(0, int((~mesh.is_hole).sum()), 2000)]
        u, v = rng.random(f.size), rng.random(f.size)
        flip = u + v > 1
        u[flip], v[flip] = 1 - u[flip], 1 - v[flip]
        u[:40], v[:40] = 2.0 ** -rng.integers(1, 60, 40), 0.0
        fast = LoopSurface(mesh, backend=backend)
        with monkeypatch.context() as m:
            m.setattr(surface.LoopSurface, "_ring_groups", lambda *a: {})
            slow = LoopSurface(mesh, backend=backend)
        assert fast.n_regular == slow.n_regular and fast.n_corner == slow.n_corner
        A, B = fast.evaluate(f, u, v, 2), slow.evaluate(f, u, v, 2)
        for k in KEYS:
            assert A[k].tobytes() == B[k].tobytes(), k


@pytest.mark.parametrize("k", range(3, 13))
def test_scheme_masks_are_left_eigenvectors(k):
    """The limit and tangent masks of ccproof.mesh.scheme on the one-ring subdivision matrices written here:
    Loop (vertex and its k neighbours) and Catmull-Clark (vertex, k edge and k diagonal neighbours)."""
    from ccproof.mesh.scheme import CATMARK, LOOP

    wV, we = LOOP.vertex_point(k, 1.0)
    ev, eo = LOOP.edge_point(1.0)
    S = np.zeros((k + 1, k + 1))
    S[0, 0], S[0, 1:] = wV, we
    for j in range(k):
        S[1 + j, 0] = S[1 + j, 1 + j] = ev
        S[1 + j, 1 + (j + 1) % k] += eo
        S[1 + j, 1 + (j - 1) % k] += eo
    lV, le = LOOP.limit(k, 1.0)
    lmask = np.r_[lV, [le] * k]
    assert np.abs(lmask @ S - lmask).max() < 1e-15
    lam = 3 / 8 + math.cos(2 * math.pi / k) / 4
    for t in LOOP.tangent_masks(k, 1.0):
        x = np.r_[0.0, t]
        assert np.abs(x @ S - lam * x).max() < 1e-14
    # Catmull-Clark: points V, e_0..e_{k-1}, d_0..d_{k-1} (d_j between e_j and e_{j+1})
    n = 2 * k + 1
    face = np.zeros((k, n))
    for j in range(k):
        face[j, [0, 1 + j, 1 + k + j, 1 + (j + 1) % k]] = 0.25
    C = np.zeros((n, n))
    cV, ce, cf = CATMARK.vertex_point(k, 1.0)
    C[0, 0] = cV
    C[0, 1:1 + k] = ce
    C[0] += cf * face.sum(axis=0)
    for j in range(k):
        C[1 + j, 0] = C[1 + j, 1 + j] = 0.25
        C[1 + j] += 0.25 * (face[j - 1] + face[j])
        C[1 + k + j] = face[j]
    wV, we_, wd = CATMARK.limit(k, 1.0)
    lmask = np.r_[wV, [we_] * k, [wd] * k]
    assert np.abs(lmask @ C - lmask).max() < 1e-15
    c = math.cos(2 * math.pi / k)
    lam_cc = (5 + c + math.cos(math.pi / k) * math.sqrt(18 + 2 * c)) / 16
    for e, d in CATMARK.tangent_masks(k, 1.0):
        x = np.r_[0.0, e, d]
        assert np.abs(x @ C - lam_cc * x).max() < 1e-13 * np.abs(x).max()


def test_holes_take_part_in_the_rules_and_have_no_surface():
    """A tagged hole and boundary interpolation "none": the other faces agree with Far (which builds no
    patch on holes), points on a hole are refused by name."""
    _osd_mod, lib = _osd()
    V, T = icosahedron()
    G, TG = grid(5)
    for mesh in (PolyMesh(V, T, holes=[3, 4]), PolyMesh(G, flip_edges(TG, 8, seed=4), options={"boundary": "none"})):
        S = LoopSurface(mesh)
        ok = np.flatnonzero(~mesh.is_hole)
        rng = np.random.default_rng(1)
        f = ok[rng.integers(0, ok.size, 3000)]
        u, v = rng.random(f.size), rng.random(f.size)
        flip = u + v > 1
        u[flip], v[flip] = 1 - u[flip], 1 - v[flip]
        far = _osd_mod.Evaluator(lib, "far", mesh, level=6, scheme="loop")
        exact = far.patch_types(f, u, v) == 5
        assert exact.sum() > 0.9 * f.size
        P, Ps, Pt = far.evaluate(f[exact], u[exact], v[exact])
        R = S.evaluate(f[exact], u[exact], v[exact], 1)
        for ours, theirs in ((R["P"], P), (R["Pu"], Ps), (R["Pv"], Pt)):
            assert np.max(np.abs(ours - theirs) / np.maximum(1, np.abs(theirs))) < TOL
        h = int(np.flatnonzero(mesh.is_hole)[0])
        with pytest.raises(CCProofError, match=rf"point 1: face {h} is a hole"):
            S.evaluate([int(ok[0]), h], [0.1, 0.1], [0.1, 0.1])


def test_non_manifold_vertex_and_edge_against_opensubdiv():
    """Two icosahedra sharing a vertex, and a flap on an interior edge of a grid (three triangles on one edge):
    OpenSubdiv's values on its regular Loop patches."""
    _osd_mod, lib = _osd()
    V, T = icosahedron()
    twin = [[0 if x == 0 else x + 11 for x in t] for t in T]
    G, TG = grid(4)
    meshes = [PolyMesh(np.vstack([V, V[1:] + [3.0, 0, 0]]), T + twin),
              PolyMesh(np.vstack([G, [[2.5, 2.0, 1.0]]]), [list(t) for t in TG] + [[12, 13, len(G)]])]
    for mesh in meshes:
        assert not mesh.is_manifold
        rng = np.random.default_rng(2)
        f = rng.integers(0, mesh.n_faces, 3000)
        u, v = rng.random(f.size), rng.random(f.size)
        flip = u + v > 1
        u[flip], v[flip] = 1 - u[flip], 1 - v[flip]
        far = _osd_mod.Evaluator(lib, "far", mesh, level=6, scheme="loop")
        exact = far.patch_types(f, u, v) == 5
        assert exact.sum() > 0.9 * f.size
        P, Ps, Pt = far.evaluate(f[exact], u[exact], v[exact])
        R = LoopSurface(mesh).evaluate(f[exact], u[exact], v[exact], 1)
        for ours, theirs in ((R["P"], P), (R["Pu"], Ps), (R["Pv"], Pt)):
            assert np.max(np.abs(ours - theirs) / np.maximum(1, np.abs(theirs))) < TOL


def test_random_tags_against_opensubdiv():
    """Random semi-sharp and infinitely sharp creases, corners and holes on a flipped icosphere: OpenSubdiv's
    values (whose fractional weights are float32: so are ours) on its regular Loop patches. The sharpness
    values have few bits, so that OpenSubdiv's float32 sums of three or more tags changing rule at one
    vertex do not depend on its order of the edges (which ours does not follow: docs/evaluate.md)."""
    _osd_mod, lib = _osd()
    _, mesh, rng = _random_tags_icosphere()
    ok = np.flatnonzero(~mesh.is_hole)
    f = ok[rng.integers(0, ok.size, 4000)]
    u, v = rng.random(f.size), rng.random(f.size)
    flip = u + v > 1
    u[flip], v[flip] = 1 - u[flip], 1 - v[flip]
    _agree_with_far(_osd_mod, lib, mesh, f, u, v)


def test_float32_fractional_weights_as_opensubdiv():
    """Two tags of sharpness 0.3 and 1.0 becoming smooth at one vertex (weight (0.3 + 1) / 2 and 1 - 0.3 in
    float32, as OpenSubdiv): its values to 1e-12 (in double the difference is about 1e-9)."""
    _osd_mod, lib = _osd()
    V, T = icosahedron()
    mesh = PolyMesh(V, T, creases={(0, 1): 0.3, (0, 5): 1.0, (1, 9): 0.3})
    rng = np.random.default_rng(4)
    f = rng.integers(0, 20, 4000)
    u, v = rng.random(f.size), rng.random(f.size)
    flip = u + v > 1
    u[flip], v[flip] = 1 - u[flip], 1 - v[flip]
    _agree_with_far(_osd_mod, lib, mesh, f, u, v)


def _agree_with_far(osd_module, lib, mesh, f, u, v):
    far = osd_module.Evaluator(lib, "far", mesh, level=8, scheme="loop")
    exact = far.patch_types(f, u, v) == 5
    assert exact.sum() > 0.9 * f.size
    P, Ps, Pt = far.evaluate(f[exact], u[exact], v[exact])
    R = LoopSurface(mesh).evaluate(f[exact], u[exact], v[exact], 1)
    for ours, theirs in ((R["P"], P), (R["Pu"], Ps), (R["Pv"], Pt)):
        assert np.max(np.abs(ours - theirs) / np.maximum(1, np.abs(theirs))) < TOL


@pytest.mark.parametrize("case", ["triangle", "triangle_corners", "tetrahedron", "tetrahedron_crease"])
def test_tiny_meshes_against_opensubdiv(case):
    """Rings that overlap themselves (every vertex of a tetrahedron is in every triangle's ring) and a lone
    triangle (three boundary vertices of one triangle: creases, or corners with edge_and_corner)."""
    _osd_mod, lib = _osd()
    T4 = np.array([[1, 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1]], float)
    F4 = [[0, 1, 2], [0, 2, 3], [0, 3, 1], [1, 3, 2]]
    one = [[0, 0, 0], [1, 0, 0], [0, 1, 0.3]]
    mesh = {"triangle": lambda: PolyMesh(one, [[0, 1, 2]]),
            "triangle_corners": lambda: PolyMesh(one, [[0, 1, 2]], options={"boundary": "edge_and_corner"}),
            "tetrahedron": lambda: PolyMesh(T4, F4),
            "tetrahedron_crease": lambda: PolyMesh(T4, F4, creases={(0, 1): math.inf, (1, 2): 1.5})}[case]()
    rng = np.random.default_rng(6)
    f = rng.integers(0, mesh.n_faces, 3000)
    u, v = rng.random(f.size), rng.random(f.size)
    flip = u + v > 1
    u[flip], v[flip] = 1 - u[flip], 1 - v[flip]
    _agree_with_far(_osd_mod, lib, mesh, f, u, v)
