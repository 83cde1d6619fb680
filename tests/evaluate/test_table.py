"""The patch table: memory per ptex face flat in the refinement level and the evaluation depth, and deep
points at tagged vertices of valence 3..8 against brute-force subdivision.

Brute force: the mesh is refined N = 12 times with the tagged rules (:meth:`PolyMesh.refine`), keeping
after each step only the faces within a few rings of the vertex under test (the Catmull-Clark rules
read one ring, so the points near the vertex stay exact: the kept region grows twice as fast as the
influence of the cut). At a level-N vertex v next to the vertex, at the dyadic ptex point of v (2^-12
from the vertex: layer 10 or 11 of its corner face), the limit position is v's closed-form limit mask
(smooth, crease, corner rule), and at a smooth regular v (four faces, no tags) the first derivatives
are the bicubic B-spline's at a knot: ``P_s = (4 (A - A') + (d_AB - d_A'B) + (d_AB' - d_A'B')) / 12``
in the face's own parameter (A, B the edge neighbours along s and t, A', B' the opposite ones, d_xy
the diagonal between x and y), divided by the face's side in the ptex face. Neither uses the evaluator's tables.
"""

import tracemalloc

import numpy as np
import pytest

from ccproof.evaluate import limit_surface
from ccproof.evaluate.backend import available_backends
from ccproof.evaluate.local import CORNERS
from ccproof.evaluate.surface import LimitSurface
from ccproof.mesh.examples import k_regular_disk
from ccproof.mesh.io import read_obj_tagged
from ccproof.mesh.polymesh import PolyMesh

from .test_tagged_bruteforce import limit_point

LEVELS = 12
KEEP = 4  # rings kept around the vertex after each step


# ------------------------------------------------------------------------------ memory
def _table_bytes(build):
    """Bytes a built surface keeps (tracemalloc, the exact-data caches warmed by a first build)."""
    from ccproof.evaluate.patch_table import forget_kept
    from ccproof.evaluate.template_cache import forget_parsed

    build()
    forget_parsed()  # the templates' operators are the surface's: allocated in the traced build
    forget_kept()  # (and the table's concatenated operators, shared with the last setup's where kept)
    tracemalloc.start()
    S = build()
    forget_parsed()  # (the process's parsed templates and operators kept for the next setup are not the surface's)
    forget_kept()
    cur, _ = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    return S, cur


def test_bytes_per_ptex_face_flat_under_refinement_and_depth(refdir, monkeypatch):
    """Refining a mesh with extraordinary vertices 1, 2, 3 times before building multiplies the ptex
    faces by 4 each time; the bytes a surface keeps (tracemalloc), less those held once per
    configuration (the layer operators: O(configurations)), per ptex face stay below 4 kB and within
    a factor 5 of each other, and evaluating ever deeper points (down to 2^-60 from the vertices)
    adds nothing. The per-face cost depends only on the kind of face (on a once-refined triangle
    mesh every face has two extraordinary corners and is split into two corner faces and two
    regular patches, about four times a regular face; after more refinements most faces are
    regular); a table of stored layers would cost some 90 layers x 1.2 kB per corner face.
    """
    from ccproof.evaluate import nets

    monkeypatch.setattr(nets, "HOT_BUDGET", 0)  # no precomputed layer 0 (it is kept on small meshes only)
    monkeypatch.setattr(nets, "NETS_BUDGET", 0)  # nor regular nets
    mesh = read_obj_tagged(refdir / "osd_features" / "meshes" / "catmark_smoothtris1.obj")
    per_face = []
    m = mesh
    for _ in range(3):
        m, _ = m.refine()
        S, cur = _table_bytes(lambda m=m: LimitSurface(m, progress=False))
        assert S.table_bytes <= cur
        per_face.append((cur - S.configuration_bytes) / m.n_ptex)
    print("bytes per ptex face after 1, 2, 3 refinements:", [round(b) for b in per_face])
    assert max(per_face) <= 5 * min(per_face), per_face
    # the rings' indices and the offsets, and the rings of the few corners of valence >= 16: no float net is
    # kept per face (a stored layer table alone would be ~90 layers x 1.2 kB; stored nets and rings: 1.9 kB)
    assert max(per_face) < 600, per_face
    # deep points at every ptex corner: the retained memory does not change
    P = m.n_ptex
    f = np.repeat(np.arange(P), 4)
    c = np.tile(np.array(CORNERS, dtype=float), (P, 1))
    deep = []
    for e in (4, 12, 30, 60):  # inside every ptex corner, at 2^-e
        d = 2.0**-e
        deep.append((c[:, 0] + d * (1 - 2 * c[:, 0]), c[:, 1] + 0.5 * d * (1 - 2 * c[:, 1])))
    out = {k: np.empty((f.size, 3)) for k in ("P", "Pu", "Pv")}
    S.evaluate(f, *deep[0], 1, out=out)  # (the compiled kernel loaded for these argument types)
    tracemalloc.start()
    before, _ = tracemalloc.get_traced_memory()
    for u, v in deep:
        S.evaluate(f, u, v, 1, out=out)
    after, _ = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    assert after - before < 1 << 12, after - before


def test_precomputed_layer_zero_gives_the_same_bits(refdir, monkeypatch):
    """The layer-0 nets and the regular nets kept precomputed (by the table on small meshes, by the C kernel's
    table where the table keeps none) are the sums the kernels compute otherwise from the rings: the same
    numbers, bit for bit, on every backend (points in every layer of every corner)."""
    from ccproof.evaluate import nets

    mesh = read_obj_tagged(refdir / "osd_features" / "meshes" / "catmark_smoothtris1.obj")
    hot = LimitSurface(mesh, progress=False)
    monkeypatch.setattr(nets, "HOT_BUDGET", 0)
    monkeypatch.setattr(nets, "NETS_BUDGET", 0)
    mid = LimitSurface(mesh, progress=False)  # no nets in the table; the C kernel's table computes its own
    if "c" in available_backends():
        s = mid._c_table().struct
        assert (s.n_nets, s.n_hot) == (mid._table.n_regular, 3 * mid._table.n_corner)
    monkeypatch.setenv("CCPROOF_NETS_BUDGET", "0")  # nor the C kernel's own (its table is made when evaluating)
    monkeypatch.setenv("CCPROOF_HOT_BUDGET", "0")
    cold = LimitSurface(mesh, progress=False)
    assert hot._table.hot.shape[0] == 3 * hot._table.n_corner > 0 and cold._table.hot.shape[0] == 0
    assert hot._table.nets.shape[0] == hot._table.n_regular > 0 and cold._table.nets.shape[0] == 0
    rng = np.random.default_rng(5)
    n = 20000
    f = rng.integers(0, mesh.n_ptex, n)
    u, v = rng.random(n), rng.random(n)
    u[: n // 2] = np.ldexp(u[: n // 2], -rng.integers(0, 12, n // 2))
    v[: n // 2] *= u[: n // 2]
    for backend in available_backends():
        a = hot.evaluate(f, u, v, 2, backend=backend)
        b = cold.evaluate(f, u, v, 2, backend=backend)
        c = mid.evaluate(f, u, v, 2, backend=backend)
        for k in a:
            assert np.array_equal(a[k], b[k]), (backend, k)
            assert np.array_equal(a[k], c[k]), (backend, k)


# ------------------------------------------------------------------------------ brute force
def _fan_mesh(k, kind, seed):
    """A tagged mesh around vertex 0: ``kind`` "ev" (smooth, valence k), "dart" (one sharp edge),
    "crease" (two), "corner" (vertex sharpness), "boundary" (k faces, open fan)."""
    rng = np.random.default_rng(seed)
    height = lambda x, y: 0.3 * np.sin(x + 2 * y) + 0.1 * x * y  # noqa: E731
    R = 3
    if kind == "boundary":
        d = k_regular_disk(k + 1, R, height)
        F = np.asarray(d.faces)[: k * R * R]  # drop the last sector
    else:
        d = k_regular_disk(k, R, height)
        F = np.asarray(d.faces)
    used = np.unique(F)
    remap = np.full(d.n_vertices, -1)
    remap[used] = np.arange(used.size)
    V = np.asarray(d.vertices)[used] + 0.05 * rng.standard_normal((used.size, 3))
    F = remap[F]

    def spoke(j):  # vertex (j, 1, 0): the edge from the centre along e_j
        return int(remap[1 + (j * R) * (R + 1)])

    creases, corners = {}, {}
    if kind == "dart":
        creases = {(0, spoke(0)): 10.0}
    elif kind == "crease":
        creases = {(0, spoke(0)): 10.0, (0, spoke(k // 2)): 10.0}
    elif kind == "corner":
        corners = {0: 10.0}
    return PolyMesh(V, F.tolist(), creases=creases or None, corners=corners or None)


def _refine_near(mesh, levels, keep):
    """Refine ``levels`` times, keeping the faces within ``keep`` rings of vertex 0 (which stays 0);
    returns the mesh and per face (ptex face, frame (o, a, b) in its (s, t))."""
    ident = (np.zeros(2), np.array([1.0, 0.0]), np.array([0.0, 1.0]))
    frames = [(f, ident) for f in range(mesh.n_faces)]  # all quads: ptex face = face
    m = mesh
    C = np.array(CORNERS, dtype=float)
    for _ in range(levels):
        m1, _ = m.refine()
        fr = []
        for p, (o, a, b) in frames:
            for i in range(4):
                ca, c1, c3 = C[i], C[(i + 1) % 4], C[(i + 3) % 4]
                fr.append((p, (o + a * ca[0] + b * ca[1], a * (c1 - ca)[0] / 2 + b * (c1 - ca)[1] / 2,
                               a * (c3 - ca)[0] / 2 + b * (c3 - ca)[1] / 2)))
        polys = [list(p) for p in m1.polygons]
        dist = {0: 0}
        frontier = [0]
        adj = {}
        for p in polys:
            for i, v in enumerate(p):
                adj.setdefault(v, set()).update((p[i - 1], p[(i + 1) % 4]))
        for r in range(1, keep + 1):
            nxt = []
            for v in frontier:
                for w in adj[v]:
                    if w not in dist:
                        dist[w] = r
                        nxt.append(w)
            frontier = nxt
        kept = [g for g, p in enumerate(polys) if any(dist.get(v, keep + 1) <= keep - 1 for v in p)]
        used = sorted({v for g in kept for v in polys[g]})
        new = {v: i for i, v in enumerate(used)}
        assert new[0] == 0
        creases = {(new[a], new[b]): s for (a, b), s in m1.edge_sharpness.items() if a in new and b in new}
        corners = {new[v]: s for v, s in m1.vertex_sharpness.items() if v in new}
        m = PolyMesh(m1.vertices[used], [[new[v] for v in polys[g]] for g in kept], creases=creases or None,
                     corners=corners or None, options=m1.options)
        frames = [fr[g] for g in kept]
    return m, frames


def _bspline_derivatives(m, cx, v, g, i):
    """Derivatives at a smooth regular vertex v (corner i of face g) along g's edges towards its
    corners i + 1 and i - 1 (unit: the edge), or None."""
    ve = cx.vertex_edges(v)
    if ve is None:
        return None
    es, nb, fan, closed = ve
    if not closed or len(fan) != 4 or any(cx.sharpness(e) > 0 for e in es) or cx.vsharp(v) > 0:
        return None
    X = m.vertices
    quad = {frozenset((cx.dst(c), cx.org[cx.prv[c]])): cx.org[cx.nxt[cx.nxt[c]]] for c in fan}  # {e, e'} -> d
    A, B = m.polygons[g][(i + 1) % 4], m.polygons[g][(i + 3) % 4]
    A2 = next(w for w in nb if w != A and frozenset((A, w)) not in quad)  # opposite A
    B2 = next(w for w in nb if w != B and frozenset((B, w)) not in quad)

    def d(x, y):
        return X[quad[frozenset((x, y))]]

    Ps = (4 * (X[A] - X[A2]) + (d(A, B) - d(A2, B)) + (d(A, B2) - d(A2, B2))) / 12
    Pt = (4 * (X[B] - X[B2]) + (d(A, B) - d(A, B2)) + (d(A2, B) - d(A2, B2))) / 12
    return Ps, Pt


@pytest.mark.parametrize("k", [3, 4, 5, 6, 7, 8])
@pytest.mark.parametrize("kind", ["ev", "dart", "crease", "corner", "boundary"])
def test_deep_points_match_brute_force(kind, k):
    mesh = _fan_mesh(k, kind, seed=10 * k + len(kind))
    S = limit_surface(mesh)
    m, frames = _refine_near(mesh, LEVELS, KEEP)
    cx = m.complex()
    pts, want, dpts, dwant = [], [], [], []
    near = _near(cx, 0, 2)  # the level-N vertices within two edges of the vertex
    for g, poly in enumerate(m.polygons):
        p, (o, a, b) = frames[g]
        for i, v in enumerate(poly):
            if v not in near:
                continue
            st = o + a * CORNERS[i][0] + b * CORNERS[i][1]
            L = limit_point(m, cx, v)
            if L is not None:
                pts.append((p, st[0], st[1]))
                want.append(L)
            D = None if v == 0 else _bspline_derivatives(m, cx, v, g, i)
            if D is not None:
                PA, PB = D
                # the edges towards corners i + 1 and i - 1 of g in the ptex face (axis-aligned, of
                # length 2^-LEVELS): grad . edge = the derivative along it
                C = np.array(CORNERS, dtype=float)
                eA, eB = C[(i + 1) % 4] - C[i], C[(i + 3) % 4] - C[i]
                vA, vB = a * eA[0] + b * eA[1], a * eB[0] + b * eB[1]
                Pu, Pv = (PA / vA[0], PB / vB[1]) if vA[0] != 0 else (PB / vB[0], PA / vA[1])
                dpts.append((p, st[0], st[1]))
                dwant.append((Pu, Pv))
    assert len(pts) >= 2 * k and len(dpts) >= k, (len(pts), len(dpts))
    diag = mesh.bounding_box_diagonal
    f, s, t = (np.array([q[j] for q in pts]) for j in range(3))
    got = S.evaluate(f.astype(int), s, t, 0)["P"]
    err = np.abs(got - np.array(want)).max() / diag
    assert err <= 1e-13, err
    f, s, t = (np.array([q[j] for q in dpts]) for j in range(3))
    r = S.evaluate(f.astype(int), s, t, 1)
    W = np.array(dwant)
    # the brute-force difference quotients divide round-off of the level-N points (~eps x diagonal)
    # by the spacing 2^-LEVELS
    tol = 1e-13 * diag * 2.0**LEVELS
    for key, col in (("Pu", 0), ("Pv", 1)):
        derr = np.abs(r[key] - W[:, col]).max()
        assert derr <= tol, (key, derr / (diag * 2.0**LEVELS))
    # deep: layer 10 or 11 of the corner face (within 2^-11 of a ptex corner, not at it)
    cdist = np.min([np.maximum(np.abs(s - c[0]), np.abs(t - c[1])) for c in CORNERS], axis=0)
    assert (cdist <= 2.0**-10).all() and (cdist > 0).all()


def _near(cx, v, r):
    seen = {v}
    frontier = [v]
    for _ in range(r):
        nxt = []
        for w in frontier:
            ve = cx.vertex_edges(w)
            if ve is None:
                continue
            for u in ve[1]:
                if u not in seen:
                    seen.add(u)
                    nxt.append(u)
        frontier = nxt
    return seen


# ------------------------------------------------------------------------------ the vectorized step
@pytest.mark.parametrize("name", ["smoothtris1", "nonquads", "helmet", "xord_boundary", "edgecorner"])
def test_vectorized_step_equals_the_tagged_rules(refdir, name):
    """The untagged Catmull-Clark step of the evaluator (numpy) against PolyMesh.refine (exact
    stencils of the tagged rules): the same faces, the same points to round-off; and the surfaces
    built on either agree."""
    from ccproof.mesh.step_fast import catmark_step

    t = read_obj_tagged(refdir / "osd_features" / "meshes" / f"catmark_{name}.obj")
    m = PolyMesh(t.vertices, [list(p) for p in t.polygons])  # the same polygons, untagged
    X1, F1 = catmark_step(m)
    m1, _ = m.refine()
    assert np.array_equal(np.array(m1.polygons), F1)
    assert np.abs(m1.vertices - X1).max() <= 4e-16 * np.abs(m1.vertices).max()
    tagged_opts = PolyMesh(t.vertices, [list(p) for p in t.polygons], options={"boundary": "edge_and_corner"})
    if tagged_opts.is_all_quads:
        return
    boundary_corner = catmark_step(tagged_opts)
    if boundary_corner is not None:  # no one-face boundary vertex: the same step
        assert np.array_equal(boundary_corner[1], F1)


def test_kept_rings_of_large_corners_give_the_same_bits(monkeypatch):
    """The rings kept per corner face where they are large (the centre of a 60-gon: Nc - 1 = 127 points) are
    the sums the kernels compute otherwise from the job's ring: deep points there, the same bits on every
    backend with the rings kept and with none kept; a vertex of valence <= 15 keeps none."""
    from ccproof.evaluate import nets

    n = 60
    t = np.linspace(0, 2 * np.pi, n, endpoint=False)
    V = np.stack([np.cos(t), np.sin(t), 0.1 * np.sin(3 * t)], 1)
    F = [list(range(n))] + [[(i + 1) % n, n + (i + 1) % n, n + i, i] for i in range(n)]
    mesh = PolyMesh(np.vstack([V, 2 * V]), F)
    kept = LimitSurface(mesh, progress=False)
    assert kept._table.ring.shape == (n * (2 * n + 7), 3) and (kept._table.cor_ring >= 0).sum() == n
    monkeypatch.setattr(nets, "KEEP_RING_NC", 10**9)
    none = LimitSurface(mesh, progress=False)
    assert none._table.ring.shape[0] == 0 and none._table.cor_ring.shape[0] == 0
    rng = np.random.default_rng(0)
    k = 4000
    f = rng.integers(0, n, k)  # the n-gon's ptex faces: their corner (1, 1) is its centre
    u = np.ldexp(rng.random(k), -rng.integers(0, 20, k))
    v = rng.random(k) * u
    ref = none.evaluate(f, 1 - u, 1 - v, 2, backend="numpy")
    for backend in available_backends():
        for S in (kept, none):
            r = S.evaluate(f, 1 - u, 1 - v, 2, backend=backend)
            for key in r:
                assert np.array_equal(r[key], ref[key]), (backend, key)
    assert LimitSurface(k_regular_disk(15, 2), progress=False)._table.ring.shape[0] == 0


@pytest.mark.parametrize("name", ["catmark_cubes_infsharp", "catmark_smoothtris1"])
def test_setups_sharing_kept_operators_give_the_same_bits(refdir, name):
    """A second setup of a mesh in the process takes the operators the first one kept (the table's ``ops`` and
    ``vop`` views of one read-only concatenation, the nets' side-by-side operators): its table is the first's bit
    for bit, field by field, after the process's kept arrays were dropped before the first; no user of either
    table can write the shared operators (nor make them writable)."""
    from ccproof.evaluate.patch_table import forget_kept
    from ccproof.evaluate.template_cache import forget_parsed

    mesh = read_obj_tagged(refdir / "osd_features" / "meshes" / f"{name}.obj")
    forget_kept()
    forget_parsed()
    first = LimitSurface(mesh, progress=False).patch_map.table
    second = LimitSurface(mesh, progress=False).patch_map.table
    assert second.ops.base is first.ops.base and second.vop.base is first.vop.base  # shared, not copied
    for f in first._fields:
        a, b = getattr(first, f), getattr(second, f)
        if isinstance(a, np.ndarray):
            assert a.dtype == b.dtype and a.shape == b.shape and a.tobytes() == b.tobytes(), f
        else:
            assert a == b, f
    for T in (first, second):
        for a in (T.ops, T.vop):
            with pytest.raises(ValueError):
                a[0] = 1.0
            with pytest.raises(ValueError):
                a.setflags(write=True)
