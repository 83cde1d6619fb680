"""LimitSurface.basis: the sparse rows of the limit stencils, cross-checked against evaluation.

Independent references: (1) the columns of the rows, probed one control vertex at a time through
``with_vertices`` (an indicator vector as the control points: the evaluator's own table, recomputed,
evaluates column j of W); (2) ``evaluate`` of the file's control points; (3) the numpy reference path
against the compiled one. Meshes: extraordinary vertices (cube, valence-5 disk with its boundary),
creases, corners, n-gons, triangles, holes and a non-manifold mesh (OpenSubdiv's regression meshes).
"""

import numpy as np
import pytest

from ccproof.errors import CCProofError
from ccproof.evaluate import LimitSurface, natural_limit_surface
from ccproof.evaluate._basis import basis_rows
from ccproof.mesh.examples import cube, k_regular_disk, torus
from ccproof.mesh.io import read_mesh
from ccproof.mesh.polymesh import PolyMesh

PAIRS = (("P", "P"), ("Du", "Pu"), ("Dv", "Pv"), ("Duu", "Puu"), ("Duv", "Puv"), ("Dvv", "Pvv"))


def _points(S, n, seed=0):
    """Random points, a tenth of them within 10^-1 .. 10^-15 of a face corner (deep corner layers), and
    exact corners and edges; holes left out."""
    rng = np.random.default_rng(seed)
    ok = np.flatnonzero(~S._refused_faces())
    f = ok[rng.integers(0, ok.size, n)]
    u, v = rng.random(n), rng.random(n)
    k = n // 10
    u[:k], v[:k] = 10.0 ** -rng.uniform(1, 15, k), 10.0 ** -rng.uniform(1, 15, k)
    flip = rng.random(k) < 0.5
    u[:k][flip] = 1.0 - u[:k][flip]
    u[k:k + 8], v[k:k + 8] = [0, 1, 1, 0, 0.5, 1, 0.5, 0], [0, 0, 1, 1, 0, 0.5, 1, 0.5]
    return f, u, v


def _osd(refdir, name, folder="osd_features"):
    return LimitSurface(read_mesh(refdir / folder / "meshes" / f"{name}.obj"))


def _surfaces(refdir):
    c = cube()
    out = {"cube": natural_limit_surface(c), "disk5": natural_limit_surface(k_regular_disk(5, 3)),
           "cube_corner": LimitSurface(PolyMesh(c.vertices, c.faces.tolist(), corners={0: 10}))}
    for name in ("catmark_pyramid_creases1", "catmark_nonquads", "catmark_smoothtris1", "catmark_hole_test2",
                 "catmark_xord_boundary"):
        out[name] = _osd(refdir, name)
    out["bowtie"] = _osd(refdir, "bowtie", "osd_nonmanifold")
    return out


@pytest.fixture(scope="module")
def surfaces(refdir):
    return _surfaces(refdir)


NAMES = ["cube", "disk5", "cube_corner", "catmark_pyramid_creases1", "catmark_nonquads", "catmark_smoothtris1",
         "catmark_hole_test2", "catmark_xord_boundary", "bowtie"]


#: relative tolerance of W @ X against evaluate (per point, relative to max(|value|, |X|)): P and the first
#: derivatives and the second derivatives at 1e-3 and more from the corners (in layer n near a corner,
#: both sides scale the nets' deviations, of size lam^n, by 4^n: their last digits are rounding there)
TOL = {"P": 1e-15, "Du": 4e-15, "Dv": 4e-15, "Duu": 1e-12, "Duv": 1e-12, "Dvv": 1e-12}
#: the same where the rings index a Catmull-Clark step of the file (triangles, n-gons: the rows are the
#: products of the step's weights with the table's; evaluate applies them one after the other)
TOL_STEP = 4e-15
#: first derivatives at the points within 1e-3 of a corner (the cancellation above, one order less)
TOL_DEEP = 1e-11


@pytest.mark.parametrize("name", NAMES)
def test_rows_reproduce_evaluate(surfaces, name):
    """W @ X equals evaluate (numpy path) to 1e-15 relative, point by point (module tolerances)."""
    S = surfaces[name]
    f, u, v = _points(S, 3000)
    X = np.asarray(S.mesh.vertices, dtype=np.float64)
    X = np.where(np.isfinite(X), X, 0.0)
    W, r = S.basis(f, u, v, 2), S.evaluate(f, u, v, 2, backend="numpy")
    size = np.abs(X).max()
    step = isinstance(S.mesh, PolyMesh) and not S.mesh.manifold.is_all_quads
    near = np.maximum(np.minimum(u, 1 - u), np.minimum(v, 1 - v))  # max-norm distance to the nearest corner
    deep = near < 1e-3
    for key, ref in PAIRS:
        assert W[key].shape == (f.size, S.mesh.n_vertices)
        tol = max(TOL[key], TOL_STEP if step else 0.0)
        err = np.abs(W[key] @ X - r[ref]).max(axis=1) / np.maximum(np.abs(r[ref]).max(axis=1), size)
        if len(key) == 3:
            err = err[~deep]
        elif key != "P":
            assert err[deep].max() <= TOL_DEEP, (name, key)
            err = err[~deep]
        assert err.max() <= tol, (name, key, err.max())


@pytest.mark.parametrize("name", NAMES)
def test_columns_equal_probed_indicator_surfaces(surfaces, name):
    """Column j of W is the surface of the indicator vector e_j (three vertices per probe, one per
    coordinate), evaluated by the evaluator with those control points; P and the first derivatives."""
    S = surfaces[name]
    f, u, v = _points(S, 200, seed=1)
    W = S.basis(f, u, v, 1)
    n = S.mesh.n_vertices
    unused = np.asarray(getattr(S.mesh, "is_unused_vertex", np.zeros(n, bool)))
    for j0 in range(0, n, 3):
        E = np.zeros((n, 3))
        js = list(range(j0, min(n, j0 + 3)))
        for c, j in enumerate(js):
            E[j, c] = 1.0
        r = S.with_vertices(E).evaluate(f, u, v, 1, backend="numpy")
        for key, ref in PAIRS[:3]:
            cols = W[key][:, js].toarray()
            scale = max(1.0, np.abs(r[ref]).max())
            for c, j in enumerate(js):
                if unused[j]:
                    assert not cols[:, c].any()
                    continue
                tol = 2e-15 if key == "P" else TOL_DEEP  # the derivatives: the corner layers (above)
                assert np.abs(cols[:, c] - r[ref][:, c]).max() <= tol * scale, (name, key, j)


def test_partition_of_unity_and_sparsity():
    """Rows of P sum to 1, those of derivatives to 0; a regular point has the 16 weights of its 4 x 4 net,
    the tensor products of the uniform cubic B-spline values (1/6, 2/3, 1/6 at a knot)."""
    S = natural_limit_surface(torus())
    f, u, v = _points(S, 500)
    W = S.basis(f, u, v, 2)
    assert np.allclose(np.asarray(W["P"].sum(axis=1)).ravel(), 1.0, rtol=0, atol=1e-14)
    for key in ("Du", "Dv", "Duu", "Duv", "Dvv"):
        assert np.abs(np.asarray(W[key].sum(axis=1))).max() <= 1e-12
    assert (np.diff(W["P"].indptr) == 16).all()
    w = np.sort(S.basis([0], [0.0], [0.0])["P"].data)
    assert np.allclose(w[w > 0], np.sort([1 / 36] * 4 + [1 / 9] * 4 + [4 / 9]), rtol=0, atol=1e-16)


@pytest.mark.parametrize("name", ["cube", "catmark_nonquads", "catmark_xord_boundary"])
def test_compiled_and_numpy_paths_agree(surfaces, name):
    S = surfaces[name]
    f, u, v = _points(S, 2000, seed=2)
    fc, uc, vc = S._check(f, u, v)
    A, B = basis_rows(S, fc, uc, vc, 1), basis_rows(S, fc, uc, vc, 1, backend="numpy")
    for key in A:
        D = abs(A[key] - B[key]).max(axis=1).toarray().ravel()
        assert (D <= 1e-10 * np.maximum(1.0, abs(B[key]).max(axis=1).toarray().ravel())).all(), key


def test_rows_serve_moved_control_points():
    """The rows depend on the topology only: W @ Y is the surface of control points Y."""
    S = natural_limit_surface(k_regular_disk(5, 3))
    f, u, v = _points(S, 1000, seed=3)
    Y = np.random.default_rng(4).standard_normal((S.mesh.n_vertices, 3))
    W = S.basis(f, u, v, 1)
    r = S.with_vertices(Y).evaluate(f, u, v, 1)
    assert np.abs(W["P"] @ Y - r["P"]).max() <= 1e-14
    assert np.abs(W["Du"] @ Y - r["Pu"]).max() <= 1e-14 * max(1.0, np.abs(r["Pu"]).max())


def test_characteristic_parameterization_rows():
    """With a parameterization the rows follow the chain rule of evaluate (first and second derivatives)."""
    import ccproof

    S = ccproof.limit_surface(cube())
    f, u, v = _points(S, 2000, seed=5)
    keep = np.maximum(np.minimum(u, 1 - u), np.minimum(v, 1 - v)) > 1e-3  # away from the corners
    f, u, v = f[keep], u[keep], v[keep]
    X = np.asarray(S.mesh.vertices)
    W = S.basis(f, u, v, 2, parameterization="characteristic")
    r = S.evaluate(f, u, v, 2, parameterization="characteristic")
    for key, ref in PAIRS:
        tol = 4e-15 if len(key) < 3 else 1e-12
        assert np.abs(W[key] @ X - r[ref]).max() <= tol * max(1.0, np.abs(r[ref]).max()), key
    # and it differs from the natural rows (the map F_b is not the identity near the corners)
    N = S.basis(f, u, v, 0)["P"]
    assert np.abs((N - W["P"]) @ X).max() > 1e-3


def test_errors_name_the_point():
    S = natural_limit_surface(cube())
    with pytest.raises(CCProofError, match="derivatives must be 0, 1 or 2"):
        S.basis([0], [0.5], [0.5], 3)
    with pytest.raises(CCProofError, match="point 1: u = 1.5 is outside"):
        S.basis([0, 0], [0.5, 1.5], [0.5, 0.5])
    with pytest.raises(CCProofError, match="unknown parameterization"):
        S.basis([0], [0.5], [0.5], parameterization="characteristic")


def test_bench_script_smoke(capsys):
    """scripts/bench_basis.py --smoke [--cpu] runs and prints the ratio line per derivative order."""
    import importlib.util
    from pathlib import Path

    path = Path(__file__).resolve().parents[2] / "scripts" / "bench_basis.py"
    spec = importlib.util.spec_from_file_location("bench_basis", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    for extra in ([], ["--cpu"]):
        assert mod.main(["--smoke", *extra]) == 0
        out = capsys.readouterr().out
        assert out.count("basis/evaluate min") == 2 and "median" in out and "load" in out
        assert ("CPU time of the thread" in out) == bool(extra)


def test_no_points_and_derived_surfaces():
    """An empty batch gives empty matrices; a surface from with_vertices shares the rows' topology."""
    S = natural_limit_surface(cube())
    W = S.basis([], [], [], 2)
    assert sorted(W) == ["Du", "Duu", "Duv", "Dv", "Dvv", "P"] and all(w.shape == (0, 8) for w in W.values())
    T = S.with_vertices(2.0 * np.asarray(cube().vertices))
    a, b = S.basis([0], [0.3], [0.2])["P"], T.basis([0], [0.3], [0.2])["P"]
    assert abs(a - b).max() == 0.0


def test_rows_of_many_points_on_threads_equal_the_numpy_path():
    """Over 8192 points (several kernel calls per block) on one and two threads: the same matrices bit for
    bit, whose indices are those of the numpy path."""
    S = natural_limit_surface(cube())
    f, u, v = _points(S, 20000, seed=6)
    fc, uc, vc = S._check(f, u, v)
    one, two = basis_rows(S, fc, uc, vc, 2, threads=1), basis_rows(S, fc, uc, vc, 2, threads=2)
    ref = basis_rows(S, fc, uc, vc, 2, backend="numpy")
    for key, W in one.items():
        for a in ("indptr", "indices", "data"):
            assert np.array_equal(getattr(W, a), getattr(two[key], a)), (key, a)
        assert np.array_equal(W.indptr, ref[key].indptr) and np.array_equal(W.indices, ref[key].indices), key
        D = abs(W - ref[key]).max(axis=1).toarray().ravel()  # as test_compiled_and_numpy_paths_agree
        assert (D <= 1e-10 * np.maximum(1.0, abs(ref[key]).max(axis=1).toarray().ravel())).all(), key


def _strictly_increasing_rows(W):
    """Every row's columns strictly increasing (checked here, not by scipy's flags)."""
    step = np.diff(W.indices.astype(np.int64))
    inside = np.ones(W.nnz, dtype=bool)
    inside[W.indptr[:-1][W.indptr[:-1] < W.nnz]] = False  # a row's first entry follows nothing
    return bool((step[inside[1:]] > 0).all())


@pytest.mark.parametrize("name", ["cube", "cube_corner", "catmark_xord_boundary", "catmark_nonquads"])
def test_rows_sorted_by_column_and_shared_index_arrays(surfaces, name):
    """Rows sorted by column, each column once (canonical CSR, flagged so); the matrices of one call share
    one pair of read-only index arrays: an in-place change of one's structure (eliminate_zeros) raises and
    leaves all as they were, its copy can be pruned, and sort_indices / sum_duplicates change nothing."""
    S = surfaces[name]
    f, u, v = _points(S, 3000, seed=7)
    W = S.basis(f, u, v, 1)
    before = {k: [getattr(w, a).copy() for a in ("indptr", "indices", "data")] for k, w in W.items()}
    for key, w in W.items():
        assert _strictly_increasing_rows(w) and w.has_canonical_format, key
    if S._ptex_face is None:  # rows of the file's vertices themselves (a step's rows are scipy's products)
        assert np.shares_memory(W["P"].indices, W["Du"].indices) and not W["P"].indices.flags.writeable
        with pytest.raises(ValueError):
            W["Du"].eliminate_zeros()
    D = W["Du"].copy()
    D.eliminate_zeros()
    assert D.nnz <= W["Du"].nnz and abs(D - W["Du"]).max() == 0.0
    for w in W.values():
        w.sort_indices()
        w.sum_duplicates()
    for key, w in W.items():
        assert all(np.array_equal(getattr(w, a), b) for a, b in zip(("indptr", "indices", "data"), before[key]))
    X = np.asarray(S.mesh.vertices, dtype=float)  # (the accuracy per key: test_rows_reproduce_evaluate)
    assert np.abs(W["P"] @ X - S.evaluate(f, u, v)["P"]).max() <= 1e-14 * max(1.0, float(np.abs(X).max()))


def test_repeated_columns_are_counted_and_keep_their_own_arrays():
    """A row naming a column twice (no mesh here does; the kernel counts them): the sort is stable, the
    count is returned, and such matrices get their own index arrays, sorted but not canonical."""
    import scipy.sparse as sp

    from ccproof.evaluate import _basis

    kernels = _basis._kernel()
    fns = [(_basis._sort_row, _basis._permute)]
    if kernels is not None:  # the compiled ones, and the Python functions they were made of
        fns.append(tuple(getattr(fn, "py_func", fn) for fn in fns[0]))
    for sort_row, permute in fns:
        ind, place, tmp = np.array([0, 9, 5, 7, 5, 1, 7], dtype=np.int32), np.zeros(6, dtype=np.int64), np.zeros(6)
        data = (np.arange(7.0) - 1, 10 * np.arange(7.0) - 10)
        assert sort_row(1, 6, ind, place) == 2
        for d in data:
            permute(1, 6, place, tmp, d)
        assert ind.tolist() == [0, 1, 5, 5, 7, 7, 9] and data[0].tolist() == [-1, 4, 1, 3, 2, 5, 0]
        assert data[1].tolist() == [-10, 40, 10, 30, 20, 50, 0]
    ind, ptr = np.array([1, 5, 5], dtype=np.int32), np.array([0, 3], dtype=np.int32)
    W = _basis._matrices(("P", "Du"), [np.ones(3), np.ones(3)], ind, ptr, (1, 8), False, None)
    assert not np.shares_memory(W["P"].indices, W["Du"].indices) and W["P"].has_sorted_indices
    W["P"].sum_duplicates()
    assert W["P"].nnz == 2 and W["Du"].nnz == 3 and W["Du"].indices.tolist() == [1, 5, 5]
    assert abs(W["Du"] - sp.csr_matrix(([1.0, 2.0], [1, 5], [0, 2]), shape=(1, 8))).max() == 0.0


def test_operators_first_needed_in_a_later_batch():
    """A batch whose points need operators no earlier batch built (deep corner layers after regular
    points): the rows equal those of a fresh surface's numpy path."""
    S = natural_limit_surface(cube())
    f, u, v = _points(S, 4000, seed=8)
    fc, uc, vc = S._check(f, u, v)
    mid = np.abs(uc - 0.5) + np.abs(vc - 0.5) < 0.1
    basis_rows(S, fc[mid], uc[mid], vc[mid], 1)  # operators of the middles of the faces only
    A = basis_rows(S, fc, uc, vc, 1)
    B = basis_rows(natural_limit_surface(cube()), fc, uc, vc, 1, backend="numpy")
    for key in A:
        assert np.array_equal(A[key].indptr, B[key].indptr) and np.array_equal(A[key].indices, B[key].indices)
        D = abs(A[key] - B[key]).max(axis=1).toarray().ravel()
        assert (D <= 1e-10 * np.maximum(1.0, abs(B[key]).max(axis=1).toarray().ravel())).all(), key
