"""The C kernel (ccproof/evaluate/_clib.c through ccproof/evaluate/_ckernel.py) against the numpy path, the
independent array formulation of the same sums: the same bits for every derivative order, every layer of
every corner, any thread count and any split of the points into calls; and the binding's edges (inputs
and outputs in other layouts, pickling, refused points)."""

from __future__ import annotations

import pickle
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from ccproof.errors import CCProofError
from ccproof.evaluate import natural_limit_surface
from ccproof.evaluate.backend import available_backends
from ccproof.mesh import read_obj
from ccproof.mesh.io import read_mesh

DATA = Path(__file__).resolve().parents[1] / "data"

pytestmark = pytest.mark.skipif("c" not in available_backends(),
                                reason="the C kernel was not built (python setup.py build_ext --inplace)")


def _points(S, n, seed):
    """Uniform points, and points in every layer at the four corners of their face."""
    rng = np.random.default_rng(seed)
    f = rng.integers(0, S.n_faces, n)
    u, v = rng.random(n), rng.random(n)
    k = n // 2
    a = 0.5 ** rng.integers(0, 120, k) * rng.random(k)
    b = a * rng.random(k)
    corner = rng.integers(0, 4, k)
    u[:k] = np.where((corner == 1) | (corner == 2), 1.0 - a, a)
    v[:k] = np.where(corner >= 2, 1.0 - b, b)
    u[k:k + 10], v[k:k + 10] = 0.0, 0.0  # exactly at corners and edges
    u[k + 10:k + 20], v[k + 10:k + 20] = 1.0, 0.5
    return f, u, v


@pytest.fixture(scope="module", params=["bunny", "smoothtris1"])
def surface(request):
    if request.param == "bunny":
        return natural_limit_surface(read_obj(DATA / "meshes" / "bunny_quads.obj"))
    return natural_limit_surface(read_mesh(DATA / "osd_features" / "meshes" / "catmark_smoothtris1.obj"))


@pytest.mark.parametrize("d", [0, 1, 2])
def test_c_kernel_gives_the_numpy_bits(surface, d):
    f, u, v = _points(surface, 30000, d)
    ref = surface.evaluate(f, u, v, d, backend="numpy")
    one = surface.evaluate(f, u, v, d, backend="c", threads=1)
    assert set(ref) == set(one)
    for k in ref:
        assert np.array_equal(ref[k], one[k]), k


def test_threads_and_calls_do_not_change_the_bits(surface):
    from ccproof.evaluate import _ckernel

    f, u, v = _points(surface, 40000, 11)
    one = surface.evaluate(f, u, v, 2, backend="c", threads=1)
    for threads in (2, 3, 5):
        many = surface.evaluate(f, u, v, 2, backend="c", threads=threads)
        for k in one:
            assert np.array_equal(one[k], many[k]), (threads, k)
    # the points split into calls of odd sizes (below and above the kernel's cache threshold of 256)
    lib, ct = _ckernel.load(), surface._c_table()
    outs = [np.zeros((f.size, 3)) for _ in range(6)]
    cuts = [0, 1, 7, 255, 256, 3001, 3002, 17000, f.size]
    for lo, hi in zip(cuts[:-1], cuts[1:]):
        assert _ckernel.evaluate_block(lib, ct, f[lo:hi], u[lo:hi], v[lo:hi], 2, [o[lo:hi] for o in outs]) == -1
    for k, o in zip(("P", "Pu", "Pv", "Puu", "Puv", "Pvv"), outs):
        assert np.array_equal(one[k], o), k


def test_a_call_writes_only_its_own_rows(surface):
    """The kernel stores a point's three coordinates with four-lane stores, the fourth on the next row, which
    the next point then writes: a call must still leave the row after its last point alone. Calls in
    reverse order into one array (a stray write lands on a row already written), and a call into the middle
    of an array of sentinels."""
    from ccproof.evaluate import _ckernel

    f, u, v = _points(surface, 5000, 13)
    one = surface.evaluate(f, u, v, 2, backend="c", threads=1)
    lib, ct = _ckernel.load(), surface._c_table()
    for d in (0, 1, 2):
        keys = ("P", "Pu", "Pv", "Puu", "Puv", "Pvv")[:3 * d if d else 1]
        outs = [np.zeros((f.size, 3)) for _ in range(6)]
        cuts = [0, 1, 2, 33, 300, 301, 2000, f.size]
        for lo, hi in reversed(list(zip(cuts[:-1], cuts[1:]))):
            got = [o[lo:hi] if i < len(keys) else None for i, o in enumerate(outs)]
            assert _ckernel.evaluate_block(lib, ct, f[lo:hi], u[lo:hi], v[lo:hi], d, got) == -1
        for k, o in zip(keys, outs):
            assert np.array_equal(one[k], o), (d, k)
        for lo, hi in ((10, 11), (10, 43), (10, 400)):
            outs = [np.full((f.size, 3), -7.0) for _ in range(6)]
            got = [o[lo:hi] if i < len(keys) else None for i, o in enumerate(outs)]
            assert _ckernel.evaluate_block(lib, ct, f[lo:hi], u[lo:hi], v[lo:hi], d, got) == -1
            for k, o in zip(keys, outs):
                assert np.array_equal(one[k][lo:hi], o[lo:hi]), (d, k, lo, hi)
                assert np.all(o[:lo] == -7.0) and np.all(o[hi:] == -7.0), (d, k, lo, hi)


def test_rows_in_any_order_write_only_their_own_rows(surface):
    """A call on given rows (``rows``: a shuffled subset, read and written in place, three coordinates at a time)
    writes each chosen row with the numpy path's bits and leaves every other row alone; a refused point is
    reported at its position in ``rows``."""
    from ccproof.evaluate import _ckernel

    f, u, v = _points(surface, 5000, 19)
    ref = surface.evaluate(f, u, v, 2, backend="numpy")
    lib, ct = _ckernel.load(), surface._c_table()
    rng = np.random.default_rng(5)
    for d, n_rows in ((0, 1), (1, 300), (2, 4001)):
        keys = ("P", "Pu", "Pv", "Puu", "Puv", "Pvv")[:3 * d if d else 1]
        rows = rng.permutation(f.size)[:n_rows].astype(np.int64)
        outs = [np.full((f.size, 3), -7.0) if i < len(keys) else None for i in range(6)]
        assert _ckernel.evaluate_block(lib, ct, f, u, v, d, outs, rows) == -1
        rest = np.setdiff1d(np.arange(f.size), rows)
        for k, o in zip(keys, outs):
            assert np.array_equal(ref[k][rows].view(np.int64), o[rows].view(np.int64)), (d, k)
            assert np.all(o[rest] == -7.0), (d, k)
    bad_u = u.copy()
    bad_u[rows[17]] = 1.5
    outs = [np.empty((f.size, 3)) for _ in range(3)] + [None] * 3
    assert _ckernel.evaluate_block(lib, ct, f, bad_u, v, 1, outs, rows) == 17


@pytest.mark.skipif(shutil.which("gcc") is None, reason="no gcc to build the portable variant")
def test_the_portable_code_gives_the_same_bits(surface, tmp_path):
    """_clib.c built with -DCCP_SCALAR -DCCP_NO_CLONES (the scalar code that compilers without GNU vector
    extensions use, one variant for every CPU), with setup.py's flags, against the numpy path."""
    import ctypes

    from ccproof.evaluate import _ckernel

    src = Path(_ckernel.__file__).with_name("_clib.c")
    lib_path = tmp_path / "clib_scalar.so"
    subprocess.run(["gcc", "-shared", "-fPIC", "-std=c99", "-O3", "-ffp-contract=off", "-fno-math-errno",
                    "-Wno-psabi", "-DCCP_SCALAR", "-DCCP_NO_CLONES", str(src), "-o", str(lib_path)], check=True)
    lib = ctypes.CDLL(str(lib_path))
    lib.ccp_evaluate.restype = ctypes.c_int64
    lib.ccp_evaluate.argtypes = [ctypes.POINTER(_ckernel._Table), ctypes.c_int64] + [ctypes.c_void_p] * 3 + \
        [ctypes.c_int64] + [ctypes.c_void_p] * 7
    f, u, v = _points(surface, 6000, 17)
    ref = surface.evaluate(f, u, v, 2, backend="numpy")
    ct = surface._c_table()
    for d in (0, 1, 2):
        keys = ("P", "Pu", "Pv", "Puu", "Puv", "Pvv")[:3 * d if d else 1]
        outs = [np.full((f.size, 3), np.nan) for _ in keys]
        ptrs = [o.ctypes.data for o in outs] + [None] * (6 - len(outs))
        cache = np.zeros(_ckernel.load().ccp_cache_words())
        fi = np.ascontiguousarray(f, dtype=np.int64)
        assert lib.ccp_evaluate(ct.ref, f.size, fi.ctypes.data, u.ctypes.data, v.ctypes.data, d, *ptrs,
                                cache.ctypes.data) == -1
        for k, o in zip(keys, outs):
            assert np.array_equal(ref[k].view(np.int64), o.view(np.int64)), (d, k)


def test_inputs_and_outputs_in_other_layouts(surface):
    f, u, v = _points(surface, 3000, 5)
    ref = surface.evaluate(f, u, v, 1, backend="numpy")
    # outputs: Fortran order, float32 and a strided view are written through temporaries
    out = {"P": np.zeros((3000, 3), order="F"), "Pu": np.zeros((3000, 3), dtype=np.float32),
           "Pv": np.zeros((3000, 6))[:, ::2]}
    r = surface.evaluate(f.astype(np.int32), u[::-1][::-1], v, 1, backend="c", out=out)
    assert r is out
    assert np.array_equal(out["P"], ref["P"]) and np.array_equal(out["Pv"], ref["Pv"])
    assert np.array_equal(out["Pu"], ref["Pu"].astype(np.float32))
    # broadcast inputs (stride 0) and a non-contiguous face array
    ff = np.repeat(f[:50], 2)[::2]
    a = surface.evaluate(ff, 0.25, v[:50], 1, backend="c")
    b = surface.evaluate(ff, np.full(50, 0.25), v[:50], 1, backend="numpy")
    assert all(np.array_equal(a[k], b[k]) for k in a)


def test_refused_points_are_named(surface):
    f, u, v = _points(surface, 1000, 3)
    u[700] = -0.25
    with pytest.raises(CCProofError, match=r"point 700: u = -0.25 is outside \[0, 1\]"):
        surface.evaluate(f, u, v, 1, backend="c", threads=1)
    u[700] = 0.5
    f[999] = surface.n_faces
    with pytest.raises(CCProofError, match=rf"point 999: face id {surface.n_faces} out of range"):
        surface.evaluate(f, u, v, 0, backend="c", threads=2)


def test_the_c_table_pickles_as_its_patch_table(surface):
    """Surfaces are shipped by rebuilding them (ccproof.scale), but a kept C table must not make anything
    that holds it unpicklable: it pickles as the patch table and rebuilds its pointers."""
    from ccproof.evaluate import _ckernel

    f, u, v = _points(surface, 500, 9)
    a = surface.evaluate(f, u, v, 1, backend="c")
    ct = pickle.loads(pickle.dumps(surface._c_table()))
    outs = [np.empty((500, 3)) for _ in range(3)] + [None] * 3
    assert _ckernel.evaluate_block(_ckernel.load(), ct, f, u, v, 1, outs) == -1
    assert all(np.array_equal(a[k], o) for k, o in zip(("P", "Pu", "Pv"), outs))


def test_moved_control_points_use_their_own_table():
    S = natural_limit_surface(read_obj(DATA / "meshes" / "bunny_quads.obj"))
    f, u, v = _points(S, 2000, 4)
    S.evaluate(f, u, v, 1, backend="c")  # the C table of S made and kept
    T = S.with_vertices(2.0 * np.asarray(S.mesh.vertices))
    a, b = T.evaluate(f, u, v, 1, backend="c"), T.evaluate(f, u, v, 1, backend="numpy")
    assert all(np.array_equal(a[k], b[k]) for k in a)


def test_the_c_backend_loads_without_numba():
    """Importing the package and choosing the C kernel does not import numba (a fresh process)."""
    code = ("import sys; import ccproof, ccproof.evaluate.surface, ccproof.evaluate.backend as b; "
            "print(b.evaluation_kernel(None)[0], 'numba' in sys.modules, 'llvmlite' in sys.modules)")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                       cwd=Path(__file__).resolve().parents[2])
    assert r.stdout.split() == ["c", "False", "False"], r.stdout + r.stderr
    code = "import sys; import ccproof.evaluate; print('numba' in sys.modules, 'scipy' in sys.modules)"
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                       cwd=Path(__file__).resolve().parents[2])
    assert r.stdout.split() == ["False", "False"], r.stdout + r.stderr


@pytest.mark.parametrize("maxn, maxf", [(64, 48), (9, 5)])
def test_ring_walks_equal_the_numba_walk(maxn, maxf):
    """The setup's ring walk in C (no numba import) against the numba walk, step for step: the same rings,
    faces and hashes, on closed and open fans, and when the rings overflow the arrays."""
    pytest.importorskip("numba")
    from ccproof.evaluate import _ckernel
    from ccproof.evaluate._numba_kernel import ring_walks
    from ccproof.mesh.examples import k_regular_disk, l_shape
    from ccproof.mesh.halfedges import HalfEdges
    from ccproof.mesh.rules import Options

    for m in (read_obj(DATA / "meshes" / "bunny_quads.obj"), l_shape(), k_regular_disk(5)):
        he = HalfEdges.from_quads(m.faces, m.n_vertices, Options(), edges=False)
        g = np.arange(m.n_faces, dtype=np.int64)
        r = np.random.default_rng(0).integers(0, 4, g.size)
        res = []
        for walk in (ring_walks, _ckernel.ring_walks):
            pos, seen = np.full(m.n_vertices, -1, np.int64), np.zeros(m.n_faces, bool)
            out = (np.full((g.size, maxn), -1, np.int32), np.empty(g.size, np.int64),
                   np.zeros((g.size, maxf, 4), np.int64), np.empty(g.size, np.int64), np.empty(g.size, np.uint64))
            walk((he.org, he.nxt, he.prv, he.twin), (pos, seen), g, r, tuple(out))
            assert (pos == -1).all() and not seen.any()  # the scratch arrays restored
            res.append(out)
        for a, b in zip(*res):
            assert np.array_equal(a, b)
