"""The vectorized step (ccproof.mesh.step) against the exact stencils of ccproof.mesh.rules.refine_complex.

refine_complex states every Sdc rule as exact rationals, one vertex and one edge at a time (Python loops,
python-flint); catmark_operator assembles them over the whole mesh with numpy in floats. On every mesh of
tests/data/osd_features and tests/data/osd_nonmanifold (creases, corners, semi-sharp and Chaikin tags,
boundary modes, triangle rules, holes, n-gons, non-manifold splits), at levels 0, 1 and 2 (each level the
PolyMesh.refine of the one before): the same child faces, the same child tags, and every row equal, bit for bit,
to the correctly rounded exact stencil.

PolyMesh.refine and PolyMesh.subdivision_operator are that step: against the child mesh built from the
exact stencils (each row rounded, then summed in increasing columns from 0; the children and tags of
refine_complex; unused vertices NaN), the same vertices bit for bit, faces, tags, holes, options and level.
"""

import math
from pathlib import Path

import numpy as np
import pytest

from ccproof.mesh.csr import apply_csr
from ccproof.mesh.io import read_mesh
from ccproof.mesh.polymesh import PolyMesh
from ccproof.mesh.rules import refine_complex, to_float
from ccproof.mesh.step import StepOptions, catmark_operator

FEATURES = ["catmark_chaikin1.obj", "catmark_cube_corner2.obj", "catmark_cube_corner4.obj",
            "catmark_cube_creases0.obj", "catmark_cubes_infsharp.obj", "catmark_dart_edgeonly.obj",
            "catmark_edgecorner.obj", "catmark_edgenone.obj", "catmark_helmet.obj", "catmark_hole_test2.obj",
            "catmark_inf_crease1.obj", "catmark_nonquads.obj", "catmark_pyramid_creases1.obj",
            "catmark_smoothtris1.obj", "catmark_xord_boundary.obj"]
NONMANIFOLD = ["book4.obj", "two_cubes.obj", "bowtie.obj", "dupface.obj", "flipped.obj", "unused.obj", "prism.off",
               "book4_tags.obj", "book4_infpage.obj", "book4_semipage.obj", "bowtie_none.obj",
               "two_cubes_creases.obj", "two_cubes_chaikin.obj", "collapsed.obj"]
CASES = [("osd_features", m) for m in FEATURES] + [("osd_nonmanifold", m) for m in NONMANIFOLD]


def _operator(pm):
    return catmark_operator(pm.n_vertices, pm.indices, pm.sizes, edge_sharpness=dict(pm.edge_sharpness),
                            vertex_sharpness=dict(pm.vertex_sharpness), holes=pm.is_hole,
                            options=StepOptions(pm.options, pm.level))


def _check_level(pm):
    cx = pm.complex()
    stencils, children, ces, cvs = refine_complex(cx)
    st = _operator(pm)
    assert np.array_equal(st.faces, np.array(children, dtype=np.int64))
    S = st.S.tocsr()
    checked = 0
    for r, ref in enumerate(stencils):
        row = S.getrow(r)
        got = dict(zip(row.indices.tolist(), row.data.tolist()))
        if ref is None:  # an unused vertex: no stencil, no row
            assert not got, r
            continue
        want = {c: to_float(w) for c, w in ref.items() if w != 0}
        assert set(got) == set(want), (r, got, want)
        assert got == want, (r, got, want)  # bit for bit: the correctly rounded exact weights
        checked += 1
    got_ces = dict(zip(map(tuple, st.child_creases[0].tolist()), st.child_creases[1].tolist()))
    assert got_ces == ces
    got_cvs = dict(zip(st.child_corners[0].tolist(), st.child_corners[1].tolist()))
    assert got_cvs == {v: s for v, s in cvs.items() if cx.corners[v]}
    assert np.array_equal(st.child_holes, np.repeat(pm.is_hole, pm.sizes))
    _check_refine(pm, stencils, children, ces, cvs)
    return checked


def _rounded_rows(stencils):
    """The exact stencils rounded: per row, the sorted columns and their float weights (None: unused)."""
    return [None if st is None else sorted((c, to_float(w)) for c, w in st.items()) for st in stencils]


def _reference_child(pm, stencils, children, ces, cvs):
    """The child mesh from refine_complex's output: each new vertex the sum, in increasing columns from 0,
    of the rounded weights times the parent's vertices (NaN for an unused vertex)."""
    X = np.asarray(pm.vertices)
    V1 = np.zeros((len(stencils), 3))
    for r, row in enumerate(_rounded_rows(stencils)):
        if row is None:
            V1[r] = np.nan
            continue
        acc = np.zeros(3)
        for c, w in row:
            acc = acc + w * X[c]
        V1[r] = acc
    ref = PolyMesh(V1, children, creases=(list(ces), list(ces.values())) if ces else None, corners=cvs or None,
                   holes=np.flatnonzero(np.repeat(pm.is_hole, pm.sizes)), options=pm.options)
    ref.level = pm.level + 1
    return ref


def _same_matrix(S, rows):
    """``S`` (scipy) holds exactly ``rows`` (:func:`_rounded_rows`; NaN at column 0 for None), bit for bit."""
    S = S.tocsr()
    assert S.shape[0] == len(rows)
    for r, want in enumerate(rows):
        a, b = S.indptr[r], S.indptr[r + 1]
        got = list(zip(S.indices[a:b].tolist(), S.data[a:b].tolist()))
        if want is None:
            assert len(got) == 1 and got[0][0] == 0 and math.isnan(got[0][1]), (r, got)
            continue
        assert got == [(c, w) for c, w in want if w != 0], (r, got, want)


def _same_csr(csr, rows):
    """The CSR arrays ``csr`` hold exactly ``rows`` (:func:`_rounded_rows`; an empty row for None), bit for bit."""
    indptr, indices, data = csr
    assert indptr.size == len(rows) + 1
    for r, want in enumerate(rows):
        got = list(zip(indices[indptr[r]:indptr[r + 1]].tolist(), data[indptr[r]:indptr[r + 1]].tolist()))
        assert got == ([] if want is None else [(c, w) for c, w in want if w != 0]), r


def _check_refine(pm, stencils, children, ces, cvs):
    """PolyMesh.refine (with and without the operator) against the reference child, bit for bit."""
    ref = _reference_child(pm, stencils, children, ces, cvs)
    m1, S = pm.refine()
    m2, none = pm.refine(operator=False)
    assert none is None
    for m in (m1, m2):
        assert m.vertices.tobytes() == ref.vertices.tobytes()
        assert np.array_equal(m.indices, ref.indices) and np.array_equal(m.sizes, ref.sizes)
        assert list(m.edge_sharpness.items()) == list(ref.edge_sharpness.items())  # the same order, too
        assert list(m.vertex_sharpness.items()) == list(ref.vertex_sharpness.items())
        assert np.array_equal(m.is_hole, ref.is_hole) and np.array_equal(m.is_hole_tagged, ref.is_hole_tagged)
        assert m.options == ref.options and m.level == ref.level
    rows = _rounded_rows(stencils)
    _same_matrix(S, rows)
    _same_matrix(pm.subdivision_operator(), rows)
    used = ~m1.is_unused_vertex
    assert (S @ np.nan_to_num(pm.vertices))[used].tobytes() == m1.vertices[used].tobytes()
    # operator="csr": the same child, the step's CSR arrays (an unused vertex's row empty), which apply_csr
    # maps to the child's vertices
    m3, csr = pm.refine(operator="csr")
    assert m3.vertices.tobytes() == ref.vertices.tobytes() and np.array_equal(m3.indices, ref.indices)
    _same_csr(csr, rows)
    assert apply_csr(csr, pm.vertices)[used].tobytes() == ref.vertices[used].tobytes()


@pytest.mark.parametrize("folder,name", CASES)
def test_rows_equal_the_exact_stencils(refdir, folder, name):
    mesh = read_mesh(refdir / folder / "meshes" / name)
    if not mesh.is_manifold:  # the operator on the input's vertices: a vertex's copies merged exactly
        exact = mesh.subdivision_operator(exact=True)
        rows = [None if r is None else sorted((c, to_float(w)) for c, w in r.items()) for r in exact]
        _same_matrix(mesh.subdivision_operator(), rows)
        m1, S = mesh.refine()  # refine's operator is that one too; its child is the split mesh's
        _same_matrix(S, rows)
        assert m1.vertices.tobytes() == mesh.manifold.refine(operator=False)[0].vertices.tobytes()
        m3, csr = mesh.refine(operator="csr")  # the split mesh's step, its columns the split mesh's vertices
        assert m3.vertices.tobytes() == m1.vertices.tobytes()
        _same_csr(csr, _rounded_rows(refine_complex(mesh.manifold.complex())[0]))
    pm = mesh.manifold
    for _ in range(3):
        assert _check_level(pm) > 0
        if pm.n_faces > 2000:
            break
        pm, _ = pm.refine(operator=False)


@pytest.mark.parametrize("options", [
    {"boundary": "edge_and_corner", "triangle_subdivision": "smooth"},
    {"boundary": "none", "crease_method": "chaikin", "triangle_subdivision": "smooth"},
    {"crease_method": "chaikin"},
])
def test_refine_with_an_unused_tagged_vertex(options):
    """An unused vertex holding NaN and a sharpness tag (the step skips it, refine_complex decays its tag),
    a quad, two triangles, a pentagon, a semi-sharp crease, a semi-sharp corner and a hole, under each
    boundary mode, crease method and triangle rule: refine equals the reference at levels 0, 1 and 2."""
    V = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0.3], [2, 0.5, 0.1], [np.nan, 0, 0], [0.5, -1, 0.2],
         [-1, 0.5, 0.1], [-0.8, 1.4, 0]]
    faces = [[0, 1, 2, 3], [1, 4, 2], [0, 6, 1], [0, 3, 8, 7, 0][:-1], [3, 2, 8]]
    pm = PolyMesh(V, faces, creases={(1, 2): 1.5, (0, 3): 2.25, (0, 1): 0.75}, corners={5: 3.0, 3: 0.5, 2: 1.25},
                  holes=[2], options=options)
    for level in range(3):
        assert _check_level(pm) > 0
        assert pm.level == level and (level == 0 or pm.vertex_sharpness.get(5) == 3.0 - level)
        assert np.isnan(pm.vertices[5]).any() and pm.is_unused_vertex[5]
        pm, _ = pm.refine(operator=False)


def test_subdivision_operator_merges_the_copies_exactly():
    """A face touching itself at vertex 0 (two fans: a copy, 8, on the split mesh) next to triangles with
    TRI_SUB_SMOOTH and semi-sharp edges: the edge point of (1, 2) holds both copies, that of (0, 1) the
    end 0 and its copy in the hexagon; the operator on the input's vertices is refine_complex's stencil
    with the copies' exact weights summed, rounded once."""
    V = np.random.default_rng(1).random((8, 3))
    # (0, 1) at 0.25: there the end's and its copy's weights rounded apart and summed differ from their
    # exact sum rounded (checked with Fractions when the test was written)
    mesh = PolyMesh(V, [[0, 1, 2, 0, 3, 4], [2, 1, 7], [1, 0, 6]], creases={(1, 2): 0.5, (0, 1): 0.25},
                    options={"triangle_subdivision": "smooth"})
    assert not mesh.is_manifold and mesh.manifold.polygons[0] == (0, 1, 2, 8, 3, 4)
    exact = mesh.subdivision_operator(exact=True)
    e = mesh.manifold.n_vertices + mesh.manifold.complex().edge_index[(1, 2)]
    assert set(exact[e]) == {0, 1, 2, 3, 4, 7}
    rows = [None if r is None else sorted((c, to_float(w)) for c, w in r.items()) for r in exact]
    _same_matrix(mesh.subdivision_operator(), rows)
    _same_matrix(mesh.refine()[1], rows)
    pm = mesh.manifold
    for _ in range(3):
        assert _check_level(pm) > 0
        pm, _ = pm.refine(operator=False)


def _same_step(x, y):
    assert x.faces.tobytes() == y.faces.tobytes() and x.edges.tobytes() == y.edges.tobytes()
    for u, v in zip(x.csr, y.csr):
        assert u.dtype == v.dtype and u.tobytes() == v.tobytes()
    for u, v in zip(x.child_creases + x.child_corners, y.child_creases + y.child_corners):
        assert u.tobytes() == v.tobytes()
    assert np.array_equal(x.child_holes, y.child_holes)


@pytest.mark.parametrize("folder,name", CASES)
def test_the_step_reads_the_pairing_of_halfedges(refdir, folder, name):
    """The step pairs no half-edges: its topology is read from HalfEdges (the mesh's, or built once when none
    is passed), at levels 0 and 1 (the child's HalfEdges derived by HalfEdges.refined). Against the pairing of
    rules.Complex (its own code: a dict of directed edges, or its numpy sort): the same twins, the edges
    numbered by first occurrence, each as its first half-edge; in HalfEdges' sorted numbering (the QuadMesh
    numbering) the edges where that numbering puts them; the step the same bits whichever HalfEdges it reads."""
    from ccproof.mesh.step_topology import step_topology

    pm = read_mesh(refdir / folder / "meshes" / name).manifold
    for _ in range(2):
        he = pm.halfedges
        assert he.edge_manifold
        kw = dict(edge_sharpness=dict(pm.edge_sharpness), vertex_sharpness=dict(pm.vertex_sharpness),
                  holes=pm.is_hole, options=StepOptions(pm.options, pm.level, sparse=False))
        built = catmark_operator(pm.n_vertices, pm.indices, pm.sizes, **kw)
        _same_step(catmark_operator(pm.n_vertices, pm.indices, pm.sizes, halfedges=he, **kw), built)
        cx = pm.complex()
        t = step_topology(pm.n_vertices, pm.indices, pm.sizes, he, None)
        assert t.twin.tolist() == cx.twin and t.he_edge.tolist() == cx.he_edge and t.h1.tolist() == cx.edges
        assert [[cx.org[h], cx.org[cx.nxt[h]]] for h in cx.edges] == built.edges.tolist()
        got = catmark_operator(pm.n_vertices, pm.indices, pm.sizes, halfedges=he, edge_of_halfedge=he.edge_of, **kw)
        assert np.array_equal(np.sort(got.edges, axis=1), he.edges)
        pm, _ = pm.refine(operator=False)


def test_a_non_manifold_edge_is_refused_by_name():
    """Three faces on the edge (0, 1), or two faces running along (1, 2) the same way: the step refuses the
    mesh naming the edge, whether it reads the mesh's HalfEdges or builds them."""
    from ccproof.errors import MeshError

    pm = PolyMesh(np.zeros((5, 3)), [[0, 1, 2], [1, 0, 3], [0, 1, 4]])
    assert not pm.halfedges.edge_manifold
    for he in (pm.halfedges, None):
        with pytest.raises(MeshError, match=r"edge \(0, 1\) has 3 faces"):
            catmark_operator(pm.n_vertices, pm.indices, pm.sizes, halfedges=he)
    with pytest.raises(MeshError, match=r"edge \(1, 2\) has 2 faces that do not pair"):
        catmark_operator(5, [0, 1, 2, 4, 1, 2, 3], [3, 4])


def test_halfedges_of_another_mesh_are_refused():
    pm = PolyMesh(np.zeros((5, 3)), [[0, 1, 2, 3], [1, 4, 2]])
    other = PolyMesh(np.zeros((5, 3)), [[0, 1, 2, 3]])
    with pytest.raises(ValueError, match="not the half-edges"):
        catmark_operator(pm.n_vertices, pm.indices, pm.sizes, halfedges=other.halfedges)


def test_pack_csr_widens_the_indices_past_int32():
    """Indices that do not fit 32 bits (a column index 2**31, or 2**31 stored entries in indptr) stay int64;
    one below the limit is packed to int32. Small arrays stand for the huge mesh (only the values matter)."""
    from ccproof.mesh.csr import pack_csr

    data = np.array([0.25, 0.5, 0.25])
    for top, want in ((2**31 - 2, np.int32), (2**31 - 1, np.int64), (2**31, np.int64)):
        csr = (np.array([0, 3], dtype=np.int64), np.array([0, 1, top], dtype=np.int64), data)
        p = pack_csr(csr)
        assert p.indices.dtype == want and p.indptr.dtype == want
        assert int(p.indices[-1]) == top
    p = pack_csr((np.array([0, 3, 2**31], dtype=np.int64), np.array([0, 1, 2]), data))
    assert p.indptr.dtype == np.int64 and int(p.indptr[-1]) == 2**31

def test_halfedges_of_the_same_size_but_other_faces_are_refused():
    """The half-edges of a mesh with as many vertices, faces and half-edges: its faces each started one
    corner later (the same surface, other half-edge numbers), or the faces in another order; the step
    refuses them (ValueError) rather than reading twins that belong to other half-edges."""
    from ccproof.mesh.examples import grid

    g = grid(3, 3)
    F = np.asarray(g.faces)
    sz = np.full(F.shape[0], 4)
    for F2 in (np.roll(F, 1, axis=1), F[::-1]):
        assert F2.size == F.size and not np.array_equal(F2, F)
        with pytest.raises(ValueError, match="not the half-edges"):
            catmark_operator(g.n_vertices, F2.reshape(-1), sz, halfedges=g.halfedges)
    # the faces' own half-edges are read (the comparison is not always refusing)
    catmark_operator(g.n_vertices, F.reshape(-1), sz, halfedges=g.halfedges)


def test_a_forged_weight_is_caught(refdir):
    """The comparison can fail: a stencil with one weight moved by 1 ulp is told apart."""
    pm = read_mesh(refdir / "osd_features" / "meshes" / "catmark_pyramid_creases1.obj").manifold
    S = _operator(pm).S.tocsr()
    stencils = refine_complex(pm.complex())[0]
    c, w = next(iter(stencils[0].items()))
    x = to_float(w)
    forged = x + math.ulp(x)
    assert S[0, c] == x != forged


@pytest.mark.slow
def test_bench_step_runs(capsys):
    """Smoke test of scripts/bench_step.py (one round, the smallest inputs): it prints every ratio."""
    import importlib.util
    import sys
    from pathlib import Path

    path = Path(__file__).resolve().parents[2] / "scripts" / "bench_step.py"
    spec = importlib.util.spec_from_file_location("bench_step", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    argv = sys.argv
    sys.argv = ["bench_step.py", "--smoke"]
    try:
        mod.main()
    finally:
        sys.argv = argv
    out = capsys.readouterr().out
    assert out.count("new/old") == 4


@pytest.mark.slow
def test_bench_refine_runs(capsys):
    """Smoke test of scripts/bench_refine.py (one round, small icospheres): the two refines agree on every
    mesh (it stops otherwise) and it prints every ratio."""
    import importlib.util
    import sys
    from pathlib import Path

    path = Path(__file__).resolve().parents[2] / "scripts" / "bench_refine.py"
    spec = importlib.util.spec_from_file_location("bench_refine", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    argv = sys.argv
    sys.argv = ["bench_refine.py", "--rounds", "1", "--tri-levels", "2", "--setup-levels", "1"]
    try:
        mod.main()
    finally:
        sys.argv = argv
    out = capsys.readouterr().out
    assert out.count("new/old") == 7


@pytest.mark.slow
def test_bench_refine_before_runs():
    """Smoke test of scripts/bench_refine.py --before HEAD (one round, small icospheres): the workers of both
    trees run and agree bit for bit (it stops otherwise), and every case is printed."""
    import shutil
    import subprocess
    import sys
    from pathlib import Path

    root = Path(__file__).resolve().parents[2]
    if shutil.which("git") is None or not (root / ".git").exists():
        pytest.skip("not a git checkout")
    p = subprocess.run([sys.executable, str(root / "scripts" / "bench_refine.py"), "--before", "HEAD", "--rounds", "1",
                        "--reps", "1", "--tri-levels", "2"], cwd=root, capture_output=True, text=True)
    assert p.returncode == 0, p.stderr + p.stdout
    assert p.stdout.count("new/old") == 4 and p.stdout.count("tracemalloc peak") == 4


def test_pack_csr_restores_the_bits():
    """PackedCSR: the weights told apart by their bits (-0.0, 0.0, NaN payloads), codes widened past 256
    distinct weights; apply (scipy's product) gives the bits of apply_csr (numpy) and of scipy on the
    unpacked int64 arrays."""
    import scipy.sparse as sp

    from ccproof.mesh.csr import apply_csr, pack_csr

    rng = np.random.default_rng(5)
    for k in (3, 300):
        A = sp.random(40, 30, density=0.3, random_state=rng, format="csr")
        A.sort_indices()
        pool = np.r_[-0.0, 0.0, rng.standard_normal(k - 2)]
        data = pool[rng.integers(0, k, A.nnz)]
        data[:k] = pool  # every weight present (nnz = 360)
        csr = (A.indptr.astype(np.int64), A.indices.astype(np.int64), data)
        p = pack_csr(csr)
        assert p.codes.dtype == (np.uint8 if k <= 256 else np.uint16) and p.indices.dtype == np.int32
        assert np.array_equal(p.csr[2].view(np.int64), data.view(np.int64))
        assert np.array_equal(p.csr[0], csr[0]) and np.array_equal(p.csr[1], csr[1])
        assert p.nbytes < sum(a.nbytes for a in csr)
        X = rng.standard_normal((30, 3))
        Y = p.apply(X)
        assert np.array_equal(Y, apply_csr(csr, X))
        assert np.array_equal(Y, sp.csr_matrix((data, csr[1], csr[0]), shape=(40, 30)) @ X)


def test_a_third_quad_scheme_is_a_scheme_value():
    """The step reads its weights through the scheme: OpenSubdiv's bilinear rules written as a Scheme value
    (vertex points stay, edge points are midpoints, face points centroids), no change to the step, give the
    bilinear operator, checked row by row against the faces; CATMARK's differs (the seam is read)."""
    import dataclasses

    from ccproof.mesh.scheme import CATMARK

    bilinear = dataclasses.replace(CATMARK, name="bilinear", edge_point=lambda one: (one / 2, 0 * one),
                                   vertex_point=lambda k, one: (one, 0 * one, 0 * one),
                                   crease_vertex=lambda one: (one, 0 * one))
    pm = read_mesh(Path(__file__).resolve().parents[1] / "data" / "osd_features" / "meshes"
                   / "catmark_nonquads.obj").manifold
    n = pm.n_vertices
    st = catmark_operator(n, pm.indices, pm.sizes, halfedges=pm.halfedges, scheme=bilinear)
    S = st.S.toarray()
    E = st.edges.shape[0]
    want = np.zeros_like(S)
    used = np.bincount(pm.indices, minlength=n) > 0
    want[np.flatnonzero(used), np.flatnonzero(used)] = 1.0
    for e, (a, b) in enumerate(st.edges.tolist()):
        want[n + e, a] += 0.5
        want[n + e, b] += 0.5
    off = np.r_[0, np.cumsum(pm.sizes)]
    for f in range(pm.sizes.size):
        want[n + E + f, pm.indices[off[f]:off[f + 1]]] += 1.0 / pm.sizes[f]
    assert np.array_equal(S, want)
    assert not np.array_equal(catmark_operator(n, pm.indices, pm.sizes).S.toarray(), want)


def _fast_and_operator(pm):
    """(catmark_step's points and faces, the operator's points, faces and |S| @ |X| with its row lengths)."""
    from ccproof.mesh.step_fast import catmark_step

    X = np.asarray(pm.vertices, dtype=np.float64)
    st = catmark_operator(pm.n_vertices, pm.indices, pm.sizes, halfedges=pm.halfedges,
                          options=StepOptions(pm.options, pm.level, sparse=False))
    indptr, indices, data = st.csr
    return catmark_step(pm), (apply_csr(st.csr, X), st.faces,
                              apply_csr((indptr, indices, np.abs(data)), np.abs(X)), np.diff(indptr))


@pytest.mark.parametrize("name", FEATURES)
def test_the_fast_step_is_the_operator_to_round_off(refdir, name):
    """catmark_step (mesh/step_fast.py: the points from the face points) against catmark_operator applied
    (the correctly rounded exact weights summed by column) on the untagged polygons of every OpenSubdiv
    feature mesh: the same child faces bit for bit, and every coordinate within Higham's bound of two
    evaluations of the same row, ``2 (terms + 4) eps (|S| |X|)`` (a weight off by one part in 10^13 breaks
    it: the forgery below). Not bit for bit: the fast path sums face points, the operator old vertices."""
    t = read_mesh(refdir / "osd_features" / "meshes" / name)
    pm = PolyMesh(t.vertices, [list(p) for p in t.polygons])  # the same polygons, untagged
    fast, (X1, F1, scale, terms) = _fast_and_operator(pm)
    assert fast is not None
    assert np.array_equal(fast[1], F1)
    bound = 2 * (terms[:, None] + 4) * np.finfo(float).eps * scale
    assert (np.abs(fast[0] - X1) <= bound).all()
    forged = X1.copy()
    forged[0] += 1e-13 * max(abs(forged[0, 0]), 1.0)
    assert not (np.abs(fast[0] - forged) <= bound).all()


def test_the_fast_step_declines_tagged_meshes(refdir):
    """Creases, corners, holes and smooth triangle subdivision are the operator's: the fast path returns None."""
    from ccproof.mesh.step_fast import catmark_step

    for name in ("catmark_cubes_infsharp.obj", "catmark_hole_test2.obj", "catmark_cube_corner4.obj"):
        assert catmark_step(read_mesh(refdir / "osd_features" / "meshes" / name).manifold) is None, name
    t = read_mesh(refdir / "osd_features" / "meshes" / "catmark_smoothtris1.obj")
    assert catmark_step(PolyMesh(t.vertices, [list(p) for p in t.polygons],
                                 options={"triangle_subdivision": "smooth"})) is None


def test_the_rule_table_is_the_one_of_both_steps():
    """The step and the exact stencils read one rule table (ccproof.mesh.crease.rule_code, rule_blend,
    midpoint_weight, chaikin_sharpness, becomes_smooth):
    against Sdc's rules written out by hand here, per (vertex sharpness, sharp edges) and per (parent, child)
    rule: corner above two sharp edges or a sharp vertex, and the blend only from a non-smooth parent to
    another mask (a dart uses the smooth mask)."""
    from fractions import Fraction

    from ccproof.mesh.crease import RULES, becomes_smooth, chaikin_sharpness, midpoint_weight, rule_blend, rule_code

    want = {(0.0, 0): "smooth", (0.0, 1): "dart", (0.0, 2): "crease", (0.0, 3): "corner", (0.0, 7): "corner",
            (0.5, 0): "corner", (math.inf, 2): "corner"}
    got = rule_code(np.array([k[0] for k in want]), np.array([k[1] for k in want]))
    assert [RULES[c] for c in got.tolist()] == list(want.values())
    w, one = Fraction(3, 8), Fraction(1)
    blended = {(p, c) for p in range(4) for c in range(4) if rule_blend(p, c, w, one) == (w, one - w)}
    assert blended == {(2, 0), (2, 1), (2, 3), (3, 0), (3, 1), (3, 2)}
    assert all(rule_blend(p, c, w, one) == (one, 0) for p in range(4) for c in range(4) if (p, c) not in blended)
    # the edge rule: the midpoint where sharp and both halves stay sharp, the float32 sharpness as the blend
    # where a half becomes smooth, the smooth rule (0) where not sharp; a number and an array alike
    edges = [(0.0, True, 0.0), (-1.0, False, 0.0), (math.inf, True, 1.0), (2.5, True, 1.0), (0.1, False, 0.1),
             (1.5, False, 1.5)]
    for s, halves, pw in edges:
        assert midpoint_weight(s, halves) == float(np.float32(pw)), (s, halves)
    assert midpoint_weight(np.array([e[0] for e in edges]), np.array([e[1] for e in edges])).tolist() == [
        float(np.float32(e[2])) for e in edges]
    # Chaikin: 0.75 s + 0.25 mean(other semi-sharp) - 1, 0 below (edges 2, 1, 0.5 at a vertex: the sum 3.5)
    want = [0.75 * 2 + 0.25 * 0.75 - 1, 0.75 * 1 + 0.25 * 1.25 - 1, 0.0]
    got = chaikin_sharpness(np.array([2.0, 1.0, 0.5]), np.float32(3.5), 3)
    assert got.tolist() == want and [chaikin_sharpness(x, np.float32(3.5), 3) for x in (2.0, 1.0, 0.5)] == want
    # the fractional weight counts 0 < p <= 1 under uniform creasing, else p > 0 with a smooth child
    feats = [(0.5, 0.0, True, True), (1.0, 0.0, True, True), (1.5, 0.5, True, False), (0.0, 0.0, True, False),
             (1.5, 0.0, False, True), (1.5, 0.25, False, False), (-1.0, 0.0, False, False)]
    assert [bool(becomes_smooth(p, c, u)) for p, c, u, _ in feats] == [x[3] for x in feats]
    cp, cc = rule_blend(np.arange(4).repeat(4), np.tile(np.arange(4), 4), np.full(16, 0.375), 1.0)
    assert [(float(a), float(b)) for a, b in zip(cp, cc)] == [
        (float(x), float(y)) for x, y in (rule_blend(p, c, w, one) for p in range(4) for c in range(4))]
