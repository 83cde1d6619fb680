"""The C kernel's lookup structures (ccproof/evaluate/_ckernel.py, CTable): the corner nets of layers 1 to 3
kept precomputed, the grid of 4 x 4 cells per ptex face that finds a point's job and virtual face in one
read, and the reciprocals of the sides (powers of two) that turn the kernel's divisions by them into
multiplications. With any number of precomputed layers, with and without the grid and the reciprocals, the
kernel gives the bits of the numpy path (the independent array formulation of the same sums), on points in
every layer at the corners, on the cells' borders and next to them, on meshes whose faces split 1 to 5
levels deep; and the layer-0 nets the kernel computes equal the table's own (computed with numpy)."""

from __future__ import annotations

import mmap
from pathlib import Path

import numpy as np
import pytest

from ccproof.errors import CCProofError
from ccproof.evaluate import natural_limit_surface
from ccproof.evaluate.backend import available_backends
from ccproof.mesh import read_obj
from ccproof.mesh.io import read_mesh

DATA = Path(__file__).resolve().parents[1] / "data"
MESHES = DATA / "osd_features" / "meshes"

pytestmark = pytest.mark.skipif("c" not in available_backends(),
                                reason="the C kernel was not built (python setup.py build_ext --inplace)")

_KEYS = ("P", "Pu", "Pv", "Puu", "Puv", "Pvv")


@pytest.fixture(scope="module", params=["bunny", "smoothtris1", "cubes_infsharp", "cube_corner2"])
def surface(request):
    if request.param == "bunny":
        return natural_limit_surface(read_obj(DATA / "meshes" / "bunny_quads.obj"))
    name = {"smoothtris1": "catmark_smoothtris1", "cubes_infsharp": "catmark_cubes_infsharp",
            "cube_corner2": "catmark_cube_corner2"}[request.param]
    return natural_limit_surface(read_mesh(MESHES / f"{name}.obj"))


def _points(S, n, seed):
    """Uniform points; points in layers 0 to 120 at the four corners of their face; points on the borders of
    the 4 x 4 cells (multiples of 1/4) and one ulp either side of them."""
    rng = np.random.default_rng(seed)
    f = rng.integers(0, S.n_faces, n)
    u, v = rng.random(n), rng.random(n)
    k = n // 3
    a = 0.5 ** rng.integers(0, 120, k) * rng.random(k)
    b = a * rng.random(k)
    corner = rng.integers(0, 4, k)
    u[:k] = np.where((corner == 1) | (corner == 2), 1.0 - a, a)
    v[:k] = np.where(corner >= 2, 1.0 - b, b)
    # the cells' borders and their neighbours, in u, in v or in both
    edges = np.array([0.0, 0.25, 0.5, 0.75, 1.0])
    edges = np.concatenate([edges, np.nextafter(edges, 2.0), np.nextafter(edges, -1.0)])
    edges = edges[(edges >= 0.0) & (edges <= 1.0)]
    m = n - 2 * k
    which = rng.integers(0, 3, m)
    e1, e2 = edges[rng.integers(0, edges.size, m)], edges[rng.integers(0, edges.size, m)]
    u[2 * k:] = np.where(which != 1, e1, u[2 * k:])
    v[2 * k:] = np.where(which != 0, e2, v[2 * k:])
    return f, u, v


_REF = {}


@pytest.mark.parametrize("layers", [1, 2, 3, 4])
@pytest.mark.parametrize("grid", [False, True])
@pytest.mark.parametrize("reciprocals", [False, True])
def test_every_lookup_gives_the_numpy_bits(surface, layers, grid, reciprocals):
    from ccproof.evaluate import _ckernel

    f, u, v = _points(surface, 9000, 1)
    if _REF.get("surface") is not surface:  # the surface itself, not its id (a new one may reuse a freed id)
        _REF.update(surface=surface, ref=surface.evaluate(f, u, v, 2, backend="numpy"))
    ref = _REF["ref"]
    ct = _ckernel.CTable(surface._table, layers=layers, grid=grid, reciprocals=reciprocals)
    assert ct.struct.n_layer_nets == layers and bool(ct.struct.grid) == grid
    assert bool(ct.struct.inv_h) == bool(ct.struct.inv_unit) == reciprocals
    lib = _ckernel.load()
    for lo, hi in ((0, f.size), (5, 200)):  # a call with the corner-net cache, one below its threshold
        outs = [np.full((hi - lo, 3), np.nan) for _ in _KEYS]
        assert _ckernel.evaluate_block(lib, ct, f[lo:hi], u[lo:hi], v[lo:hi], 2, outs) == -1
        for key, o in zip(_KEYS, outs):
            assert np.array_equal(ref[key][lo:hi].view(np.int64), o.view(np.int64)), (key, lo, hi)


def test_default_lookup_and_threads(surface):
    """The table evaluate uses (the default CTable: grid and layers by their budgets) on 1 and 3 threads."""
    f, u, v = _points(surface, 6000, 7)
    ref = surface.evaluate(f, u, v, 1, backend="numpy")
    ct = surface._c_table()
    assert ct.struct.grid and ct.struct.n_layer_nets == 3 and ct.struct.inv_h
    for threads in (1, 3):
        got = surface.evaluate(f, u, v, 1, backend="c", threads=threads)
        assert all(np.array_equal(ref[k], got[k]) for k in ref), threads


def test_layer_nets_of_the_kernel_equal_the_tables(surface):
    """Layer 0 computed by the kernel's own sums (ccp_nets, corner kind) equals the table's ``hot`` (numpy's
    layer0_nets), bit for bit; deeper layers differ from it. The regular nets (ccp_nets, regular kind) equal
    the table's ``nets`` (numpy's); another kind is refused."""
    from ccproof.evaluate import _ckernel

    T = surface._table
    ct = _ckernel.CTable(T, layers=2)
    lib = _ckernel.load()
    w = np.empty_like(T.hot)
    assert lib.ccp_nets(ct.ref, T.job_root.shape[0], _ckernel._CORNER, 0, w.ctypes.data) == 0
    assert np.array_equal(w.view(np.int64), np.ascontiguousarray(T.hot).view(np.int64))
    deeper = ct._keep["layer_nets"][1]
    assert deeper.shape == T.hot.shape and not np.array_equal(deeper[:, :16], T.hot[:, :16])
    assert np.array_equal(deeper[:, 16], T.hot[:, 16])  # the corner's limit point, in every layer
    assert T.nets.shape[0] == T.n_regular  # small tables keep them (numpy's sums)
    r = np.full((T.n_regular, 17, 3), np.nan)
    assert lib.ccp_nets(ct.ref, T.job_root.shape[0], _ckernel._REGULAR, 0, r.ctypes.data) == 0
    assert np.array_equal(r.view(np.int64), np.ascontiguousarray(T.nets).view(np.int64))
    assert lib.ccp_nets(ct.ref, T.job_root.shape[0], 2, 0, r.ctypes.data) == -2


def test_a_wrong_number_of_layers_is_refused(surface):
    from ccproof.evaluate import _ckernel

    for bad in (0, 5):
        with pytest.raises(CCProofError, match="layers must be 1 to 4"):
            _ckernel.CTable(surface._table, layers=bad)


def test_reciprocals_need_powers_of_two(surface):
    from ccproof.evaluate import _ckernel

    T = surface._table
    assert _ckernel._powers_of_two(T.h) and _ckernel._powers_of_two(T.unit[:, :, 2])
    odd = T._replace(h=T.h * 0.75)  # not a power of two: the default takes the divisions
    assert not _ckernel.CTable(odd, layers=1).struct.inv_h
    with pytest.raises(CCProofError, match="power of two"):
        _ckernel.CTable(odd, layers=1, reciprocals=True)


def test_no_grid_where_a_face_does_not_hold_whole_cells(surface):
    """The grid is made only where every job's face holds whole cells (dyadic squares, as the table builds
    them); a table whose faces were shifted by a third of a cell gets none (the kernel then walks the splits)."""
    from ccproof.evaluate import _ckernel

    T = surface._table
    assert _ckernel.CTable(T, layers=1, grid=True).struct.grid
    shifted = T._replace(u0=T.u0 + 1.0 / 12)
    assert not _ckernel.CTable(shifted, layers=1, grid=True).struct.grid


def test_grid_in_32_and_64_bits(surface):
    """The grid's entries ``job << shift | virtual face`` in uint32 (what the binding makes on these meshes) and
    in int64 are the same numbers; each names its cell's job (``top`` of the cell's quadrant) and a virtual face
    of that job's tree that holds the whole cell; the kernel gives the numpy bits with either; a shift that
    leaves the virtual faces too few bits is refused."""
    from ccproof.evaluate import _ckernel

    T = surface._table
    lib = _ckernel.load()
    ct = _ckernel.CTable(T, layers=1, grid=True)
    g32, shift = ct._keep["grid"], ct.struct.grid_shift
    assert g32.dtype == np.uint32 and ct.struct.grid_wide == 0
    g64 = np.empty(g32.size, dtype=np.int64)
    assert lib.ccp_grid(ct.ref, g64.ctypes.data, 1, shift) == 0
    assert np.array_equal(g64, g32.astype(np.int64))
    n_ptex = T.refused.shape[0]
    pf, j, i = (a.ravel() for a in np.meshgrid(np.arange(n_ptex), np.arange(4), np.arange(4), indexing="ij"))
    ok = ~np.asarray(T.refused, dtype=bool)[pf]
    job, vf = g64 >> shift, g64 & ((1 << shift) - 1)
    top = np.asarray(T.top).reshape(n_ptex, 4)
    assert np.array_equal(job[ok], top[pf, (i >= 2) + 2 * (j >= 2)][ok])
    vf, i, j = vf[ok], i[ok], j[ok]
    assert np.all((T.u0[vf] <= i / 4) & (T.u0[vf] + T.h[vf] >= (i + 1) / 4) & (T.v0[vf] <= j / 4)
                  & (T.v0[vf] + T.h[vf] >= (j + 1) / 4))
    f, u, v = _points(surface, 3000, 5)
    ref = surface.evaluate(f, u, v, 1, backend="numpy")
    for g in (g32, g64):
        ct._keep["grid"] = g
        ct.struct.grid, ct.struct.grid_wide = g.ctypes.data, int(g.dtype == np.int64)
        outs = [np.full((f.size, 3), np.nan) for _ in range(3)] + [None] * 3
        assert _ckernel.evaluate_block(lib, ct, f, u, v, 1, outs) == -1
        for key, o in zip(_KEYS, outs[:3]):
            assert np.array_equal(ref[key].view(np.int64), o.view(np.int64)), (key, g.dtype)
    if vf.max() >= 2:
        assert lib.ccp_grid(ct.ref, g64.ctypes.data, 0, 1) == -1
    assert lib.ccp_grid(ct.ref, g64.ctypes.data, 0, 32) == -1


def test_arrays_on_mappings_of_their_own_give_the_same_bits(surface, monkeypatch):
    """With every array the binding fills on an anonymous mapping of its own (``fresh`` from 0 bytes: the kept
    nets, the layer nets, the grid), the kernel gives the numpy bits."""
    from ccproof.evaluate import _ckernel

    monkeypatch.setattr(_ckernel, "FRESH_MIN", 0)
    T = surface._table
    ct = _ckernel.CTable(T._replace(nets=T.nets[:0], hot=T.hot[:0]), layers=3, grid=True)
    for name in ("nets", "hot", "grid"):
        base = ct._keep[name]
        while isinstance(base, (np.ndarray, memoryview)):
            base = base.obj if isinstance(base, memoryview) else base.base
        assert isinstance(base, mmap.mmap), name
    f, u, v = _points(surface, 3000, 9)
    ref = surface.evaluate(f, u, v, 1, backend="numpy")
    outs = [np.full((f.size, 3), np.nan) for _ in range(3)] + [None] * 3
    assert _ckernel.evaluate_block(_ckernel.load(), ct, f, u, v, 1, outs) == -1
    for key, o in zip(_KEYS, outs[:3]):
        assert np.array_equal(ref[key].view(np.int64), o.view(np.int64)), key


def test_a_tree_deeper_than_the_walk_falls_back_to_the_cache():
    """A table whose split faces are their own children (a tree without end: deeper than any table the
    builder makes) gets no precomputed layers beyond 0 and a finite grid walk, instead of an error or a
    hang."""
    from ccproof.evaluate import _ckernel

    S = natural_limit_surface(read_mesh(MESHES / "catmark_cubes_infsharp.obj"))
    T = S._table
    split = np.flatnonzero(T.kind == 2)
    assert split.size
    child = T.child.copy()
    child[split] = split[:, None]
    ct = _ckernel.CTable(T._replace(child=child), layers=3, grid=True)
    assert ct.struct.n_layer_nets == 1 and ct.struct.grid
    assert _ckernel.CTable(T, layers=3).struct.n_layer_nets == 3
