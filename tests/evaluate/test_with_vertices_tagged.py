"""LimitSurface.with_vertices on PolyMesh surfaces (tags, n-gons, holes, non-manifold) against a fresh build.

The reference is the evaluator built from scratch on a PolyMesh constructed anew from the moved
vertices and the mesh's polygons and tags (its own topology, split, level-1 step and patch table).
``with_vertices`` recomputes the positions the rings index (the split base vertices, the vectorized
untagged step, or the tagged step kept by the build) and the table's float data from the kept rings:
the same operations on the same numbers, so positions and all derivatives agree bit for bit.
"""

import numpy as np
import pytest

from ccproof.errors import MeshError
from ccproof.evaluate import LimitSurface
from ccproof.evaluate.tagged import vertex_corners
from ccproof.mesh.io import read_mesh
from ccproof.mesh.polymesh import PolyMesh

FEATURES = ["catmark_chaikin1.obj", "catmark_cube_corner2.obj", "catmark_cube_corner4.obj",
            "catmark_cube_creases0.obj", "catmark_cubes_infsharp.obj", "catmark_dart_edgeonly.obj",
            "catmark_edgecorner.obj", "catmark_edgenone.obj", "catmark_helmet.obj", "catmark_hole_test2.obj",
            "catmark_inf_crease1.obj", "catmark_nonquads.obj", "catmark_pyramid_creases1.obj",
            "catmark_smoothtris1.obj", "catmark_xord_boundary.obj"]
NONMANIFOLD = ["book4.obj", "two_cubes.obj", "bowtie.obj", "dupface.obj", "flipped.obj", "unused.obj", "prism.off",
               "book4_tags.obj", "book4_infpage.obj", "book4_semipage.obj", "bowtie_none.obj",
               "two_cubes_creases.obj", "two_cubes_chaikin.obj", "collapsed.obj"]
CASES = [("osd_features", n) for n in FEATURES] + [("osd_nonmanifold", n) for n in NONMANIFOLD] + \
    [("", "pyramid"), ("", "open_pyramid")]


def _read(refdir, folder, name):
    """A test mesh; two untagged ones made here (the vectorized untagged level-1 step): a square
    pyramid (a quad, four triangles) closed and without its base (a boundary of four edges)."""
    if folder:
        return read_mesh(refdir / folder / "meshes" / name)
    V = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0.5, 0.5, 0.8]]
    F = [[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]] + ([[3, 2, 1, 0]] if name == "pyramid" else [])
    return PolyMesh(V, F)


def _fresh(mesh, X):
    """The PolyMesh of ``mesh`` with vertices ``X``, through the constructor (nothing shared)."""
    es = mesh.edge_sharpness
    return PolyMesh(X, [list(p) for p in mesh.polygons],
                    creases=(list(es.keys()), list(es.values())) if es else None,
                    corners=dict(mesh.vertex_sharpness) or None, holes=np.flatnonzero(mesh.is_hole_tagged),
                    options=mesh.options)


def _points(rng, S, mesh, per_face=40):
    """Random points on the ptex faces that are not holes, biased to the corners, plus every ptex corner."""
    P = np.flatnonzero(~S._refused_faces())
    f = np.repeat(P, per_face)
    u, v = rng.random(f.size) ** 3, rng.random(f.size) ** 3
    flip = rng.random((2, f.size)) < 0.5
    u, v = np.where(flip[0], 1 - u, u), np.where(flip[1], 1 - v, v)
    fc = np.repeat(P, 4)
    uc, vc = np.tile([0.0, 1.0, 1.0, 0.0], P.size), np.tile([0.0, 0.0, 1.0, 1.0], P.size)
    return np.r_[f, fc], np.r_[u, uc], np.r_[v, vc]


def _same(a, b):
    return np.array_equal(a, b, equal_nan=True)


@pytest.mark.parametrize("folder,name", CASES)
def test_tagged_with_vertices_equals_a_fresh_build_bit_for_bit(refdir, folder, name):
    mesh = _read(refdir, folder, name)
    rng = np.random.default_rng(11)
    S = LimitSurface(mesh, progress=False)
    f, u, v = _points(rng, S, mesh)
    before = S.evaluate(f, u, v, 2)
    V = np.asarray(mesh.vertices)
    used = ~mesh.is_unused_vertex
    scale = np.abs(V[used]).max()
    T = S
    for trial in range(3):  # the later calls re-use the step operator; the last one chained from a derived surface
        X = V + 0.2 * scale * rng.standard_normal(V.shape) + trial
        X[~used] = np.nan  # unused vertices may hold anything
        T = (S if trial < 2 else T).with_vertices(X)
        R = LimitSurface(_fresh(mesh, X), progress=False)
        assert _same(T.mesh.vertices, X) and T.n_patches == R.n_patches and T.n_faces == R.n_faces
        assert _same(T.mesh.manifold.vertices, R.mesh.manifold.vertices)
        for k in ("nets", "points", "rings", "hot"):
            assert _same(getattr(T._table, k), getattr(R._table, k)), k
        a, b = T.evaluate(f, u, v, 2), R.evaluate(f, u, v, 2)
        for k in a:  # P and every first and second derivative, bit for bit
            assert np.array_equal(a[k], b[k]), (k, np.abs(a[k] - b[k]).max())
            assert np.isfinite(a[k]).all(), k
        assert _same(T.vertex_limits(), R.vertex_limits())
        assert _same(T.vertex_normals(), R.vertex_normals())
        assert _same(T.normals(f, u, v), R.normals(f, u, v))
        # and the surface did move: the limit points at the ptex corners are not the old ones
        fc, uc, vc, _ = vertex_corners(mesh)
        keep = ~S._refused_faces()[fc]
        assert not np.allclose(T.evaluate(fc[keep], uc[keep], vc[keep])["P"],
                               S.evaluate(fc[keep], uc[keep], vc[keep])["P"])
    after = S.evaluate(f, u, v, 2)  # the original surface is untouched
    assert all(np.array_equal(before[k], after[k]) for k in before)
    assert _same(S.mesh.vertices, V)


def test_tagged_with_vertices_paths(refdir, monkeypatch):
    """Which positions the rings index: the split base vertices (all quads), the vectorized untagged
    step (nothing kept), the tagged step (kept by the build, shared when chained, never recomputed)."""
    feats = refdir / "osd_features" / "meshes"
    from ccproof.mesh.csr import PackedCSR
    from ccproof.mesh.step_fast import catmark_step

    assert catmark_step(_read(refdir, "", "pyramid")) is not None  # the vectorized path is tested above
    quads = LimitSurface(read_mesh(refdir / "osd_nonmanifold" / "meshes" / "book4.obj"), progress=False)
    untagged = LimitSurface(read_mesh(refdir / "osd_nonmanifold" / "meshes" / "prism.off"), progress=False)
    tagged = LimitSurface(read_mesh(feats / "catmark_pyramid_creases1.obj"), progress=False)
    assert set(tagged._moving) == {"step"}  # kept by the build, before any move
    step = tagged._moving["step"]
    assert isinstance(step, PackedCSR)
    for S in (quads, untagged, tagged):
        T = S.with_vertices(np.asarray(S.mesh.vertices) * 2.0)
        assert T._moving is S._moving
        T.with_vertices(np.asarray(S.mesh.vertices) * 3.0)
    assert not quads._moving and not untagged._moving
    assert set(tagged._moving) == {"step"} and tagged._moving["step"] is step
    # the kept step is the step's: as a matrix, the float stencil matrix of subdivision_operator, and it
    # maps the vertices to the level-1 vertices of refine
    X = np.asarray(tagged.mesh.vertices)
    M = tagged.mesh.subdivision_operator().toarray()
    indptr, indices, data = step.csr
    K = np.zeros_like(M)
    K[np.repeat(np.arange(indptr.size - 1), np.diff(indptr)), indices] = data
    assert np.array_equal(K, M)
    m1, _ = tagged.mesh.refine(operator=False)
    assert np.array_equal(step.apply(X), m1.vertices)
    # a move never runs the step again
    import ccproof.mesh.step as st

    calls = []
    real = st.catmark_operator
    monkeypatch.setattr(st, "catmark_operator", lambda *a, **k: calls.append(1) or real(*a, **k))
    tagged.with_vertices(X * 4.0)
    assert not calls
    tagged.mesh.refine(operator=False)  # (the patch does count the step)
    assert calls


def test_tagged_with_vertices_bad_input(refdir):
    mesh = read_mesh(refdir / "osd_nonmanifold" / "meshes" / "bowtie.obj")
    S = LimitSurface(mesh, progress=False)
    with pytest.raises(MeshError, match="shape"):
        S.with_vertices(np.zeros((mesh.n_vertices + 1, 3)))
    X = np.array(mesh.vertices)
    X[2, 0] = np.inf
    with pytest.raises(MeshError, match="vertex 2"):
        S.with_vertices(X)


def test_kept_step_with_more_than_256_distinct_weights():
    """A triangulated 10 x 10 grid whose 280 interior edges each carry their own semi-sharpness in (0, 1):
    the kept step has hundreds of distinct weights (two-byte codes); the moved surface still equals a fresh
    build bit for bit (table float arrays, positions and derivatives)."""
    k = 10
    xs, ys = np.meshgrid(np.arange(k + 1), np.arange(k + 1))
    V = np.c_[xs.ravel(), ys.ravel(), 0.1 * np.sin(xs.ravel() + ys.ravel())].astype(np.float64)
    F = []
    for i in range(k):
        for j in range(k):
            a = i * (k + 1) + j
            F += [[a, a + 1, a + k + 2], [a, a + k + 2, a + k + 1]]
    plain = PolyMesh(V, F)
    inner = np.flatnonzero(~plain.is_boundary_edge)
    creases = {(int(plain.edges[e, 0]), int(plain.edges[e, 1])): float(s)
               for e, s in zip(inner, np.linspace(0.05, 0.95, inner.size))}
    S = LimitSurface(PolyMesh(V, F, creases=creases), progress=False)
    step = S._moving["step"]
    assert step.weights.size > 256 and step.codes.dtype == np.uint16
    X = V + 0.1 * np.random.default_rng(2).standard_normal(V.shape)
    T = S.with_vertices(X)
    R = LimitSurface(PolyMesh(X, F, creases=creases), progress=False)
    for name in ("nets", "points", "rings", "hot"):
        assert _same(getattr(T._table, name), getattr(R._table, name)), name
    f, u, v = _points(np.random.default_rng(3), S, T.mesh, per_face=4)
    a, b = T.evaluate(f, u, v, 2), R.evaluate(f, u, v, 2)
    for name in a:
        assert np.array_equal(a[name], b[name]), name
