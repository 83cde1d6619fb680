"""The C evaluation kernel (``_clib.c``), loaded with ctypes: the default backend where it was built.

``setup.py`` builds ``ccproof/evaluate/_clib.c`` as the optional extension ``ccproof.evaluate._clib`` (a
plain shared library: no Python API, so loading it imports nothing); an install without a compiler skips
it and :meth:`ccproof.evaluate.surface.LimitSurface.evaluate` falls back to the numba kernel, then to
numpy. The kernel computes the same sums in the same order as the numba kernel and the numpy path
(compiled without floating-point contraction), so all backends give the same bits. A ctypes call
releases the GIL: threads evaluate blocks of points in parallel.
"""

from __future__ import annotations

import ctypes
import importlib.machinery
import os
import threading

import numpy as np

from ccproof.errors import CCProofError
from ccproof.evaluate.nets import budget
from ccproof.evaluate.patch_table import COMPOSED_LAYERS

__all__ = ["load", "CTable", "evaluate_block", "face_order", "point_blocks", "ring_walks"]

_P = ctypes.c_void_p
_I = ctypes.c_int64
#: most layers of corner nets precomputed (CCP_LAYER_NETS in _clib.c)
_LAYER_NETS = 4
#: layers of a corner face with composed operators (CCP_COMPOSED in _clib.c)
_COMPOSED = 2
#: the kinds of virtual face whose nets ``ccp_nets`` computes (CCP_REGULAR, CCP_CORNER in _clib.c)
_REGULAR, _CORNER = 0, 1
#: the bytes the precomputed corner nets of layers 1, 2, ... may take together (layer 0 is the table's own
#: ``hot``): a point in layer n of a corner face reads its net there instead of the kernel's corner-net cache
LAYER_NETS_BUDGET = 4 << 20
#: the largest grid of cells the binding makes (``ccp_grid``: 64 bytes per ptex face where a job and a virtual face fit
#: 32 bits together, else 128): 983,040 ptex faces (327,680 triangles) in 60 MiB
GRID_BUDGET = 64 << 20
#: the bytes of the nets the binding computes where the table keeps none, by the kernel's own sums: the regular
#: nets first (408 bytes per regular patch: a ptex face of a triangle scan has two, and they serve half its area),
#: then layer 0 of the corner faces (1,224 bytes per corner face, a face of a scan has two: 3/8 of its area) in
#: what is left. The environment variables ``CCPROOF_NETS_BUDGET`` and ``CCPROOF_HOT_BUDGET`` (bytes) replace
#: the two shares (0: none, every such net computed when evaluated). At 327,680 triangles: the regular nets
#: (800 MB), not layer 0 (2.4 GB).
KEPT_NETS_BUDGET = 1536 << 20


class _Table(ctypes.Structure):
    """``ccp_table`` of ``_clib.c`` (the same fields in the same order)."""

    _fields_ = [("top", _P), ("job_root", _P), ("job_net", _P), ("job_corner", _P), ("job_ring", _P),
                ("wide", _I * 5), ("refused", _P), ("kind", _P), ("child", _P), ("u0", _P), ("v0", _P),
                ("h", _P), ("leaf", _P), ("cfg", _P), ("cu", _P), ("cv", _P), ("vop_start", _P), ("vn", _P),
                ("vop", _P), ("points", _P), ("rings", _P), ("split_depth", _I), ("n_ptex", _I),
                ("max_layers", _I), ("n_corner", _I), ("n_nets", _I), ("nets", _P), ("ops", _P),
                ("op_start", _P), ("op_size", _P), ("n_layers", _P), ("unit", _P), ("hot", _P), ("n_hot", _I),
                ("cor_ring", _P), ("ring", _P),
                ("layer_nets", _P * _LAYER_NETS), ("n_layer_nets", _I), ("grid", _P), ("grid_wide", _I),
                ("grid_shift", _I), ("inv_h", _P),
                ("inv_unit", _P)]


_LIB = None
_TRIED = False
#: the version of the kernel's interface (``ccp_abi`` in _clib.c)
_ABI = 8
#: calls on fewer points use no corner-net cache (CCP_CACHE_MIN in _clib.c)
_CACHE_MIN = 256


def load():
    """The loaded library (``ctypes.CDLL``), or None when the extension was not built (or is stale).

    Looks for ``_clib`` with this interpreter's extension suffixes next to this module; the environment
    variable ``CCPROOF_CLIB`` names another file (tests, benchmarks). Loaded once per process.
    """
    global _LIB, _TRIED
    if _TRIED:
        return _LIB
    _TRIED = True
    here = os.path.dirname(os.path.abspath(__file__))
    paths = [os.environ["CCPROOF_CLIB"]] if os.environ.get("CCPROOF_CLIB") else \
        [os.path.join(here, "_clib" + s) for s in importlib.machinery.EXTENSION_SUFFIXES]
    for p in paths:
        if not os.path.isfile(p):
            continue
        try:
            lib = ctypes.CDLL(p)
        except OSError:
            continue
        lib.ccp_abi.restype = _I
        lib.ccp_abi.argtypes = []
        if lib.ccp_abi() != 1000 * ctypes.sizeof(_Table) + _ABI:  # built from another version of _clib.c
            continue
        lib.ccp_evaluate.restype = _I
        lib.ccp_evaluate.argtypes = [ctypes.POINTER(_Table), _I, _P, _P, _P, _I, _P, _P, _P, _P, _P, _P, _P]
        lib.ccp_evaluate_at.restype = _I
        lib.ccp_evaluate_at.argtypes = [ctypes.POINTER(_Table), _I, _P, _P, _P, _P, _I, _P, _P, _P, _P, _P, _P, _P]
        lib.ccp_cache_words.restype = _I
        lib.ccp_cache_words.argtypes = []
        lib.ccp_nets.restype = _I
        lib.ccp_nets.argtypes = [ctypes.POINTER(_Table), _I, _I, _I, _P]
        lib.ccp_face_order.restype = _I
        lib.ccp_face_order.argtypes = [_I, _P, _I, _I, _P, _P]
        lib.ccp_grid.restype = _I
        lib.ccp_grid.argtypes = [ctypes.POINTER(_Table), _P, _I, _I]
        lib.ccp_ring_walks.restype = _I
        lib.ccp_ring_walks.argtypes = [_P] * 6 + [_I, _P, _P, _P, _I, _P, _P, _I, _P, _P]
        _LIB = lib
        break
    return _LIB


#: arrays of at least this many bytes that the binding fills (the kept nets, the grid) get memory of their own
#: (:func:`fresh`)
FRESH_MIN = 64 << 20


def fresh(shape, dtype=np.float64):
    """An array to fill once: ``np.empty``, or from :data:`FRESH_MIN` bytes on an anonymous mapping of its own.

    numpy advises the system to back large allocations with huge pages (``MADV_HUGEPAGE``); where transparent huge
    pages compact memory on demand for such advice (``defrag`` ``madvise``, as on the machine these figures come
    from) and find none, every first write stalls: filling the 800 MB of regular nets of 327,680 triangles took the
    first evaluation 8.4 s instead of 1.5 s, with no huge page obtained either way (``AnonHugePages`` 0). A mapping
    without that advice is faulted in small pages (in huge pages where the system gives them to every mapping).

    >>> a = fresh((4, 3)); a.shape, a.dtype.name, a.flags.writeable
    ((4, 3), 'float64', True)
    """
    n = int(np.prod(shape)) * np.dtype(dtype).itemsize
    if n < FRESH_MIN:
        return np.empty(shape, dtype=dtype)
    import mmap

    return np.frombuffer(mmap.mmap(-1, n), dtype=dtype).reshape(shape)


def _addr(a):
    return a.ctypes.data if a.size else None


def _powers_of_two(a):
    """Whether every value of ``a`` is a power of two whose reciprocal is a normal double (dividing by it is
    then multiplying by the reciprocal, bit for bit).

    >>> _powers_of_two(np.array([1.0, 0.5, 2.0 ** -40])), _powers_of_two(np.array([0.75]))
    (True, False)
    """
    a = np.asarray(a, dtype=np.float64)
    m, e = np.frexp(a)
    return bool(np.all((m == 0.5) & (e >= -1020) & (e <= 1020)))


class CTable:
    """The patch table (:class:`ccproof.evaluate.patch_table.PatchTable`) as the C kernel reads it.

    Holds the arrays in the dtypes the kernel reads (the table's own arrays where they already are), the
    ``ccp_table`` structure pointing into them, and the corner-net caches of the calls (7.3 MB each, one
    per concurrent call, kept for the next calls); pickles as the table it was made from and the arrays it
    computed (the corner nets, the grid), which it points into again when unpickled.

    Parameters
    ----------
    table : PatchTable
    layers : int, optional
        Layers of corner nets to keep precomputed, 1 to 4 (layer 0 is the table's ``hot``; the others are
        computed here by the kernel's own sums, ``ccp_nets``). Default: 3, fewer where they would
        exceed :data:`LAYER_NETS_BUDGET`; none where the table has no ``hot``.
    grid : bool, optional
        Make the grid of 4 x 4 cells per ptex face (``ccp_grid``: a point's job and virtual face in one
        read, uint32 where the numbers of both fit 32 bits, else int64). Default: where it takes at most
        :data:`GRID_BUDGET` bytes. None is made (whatever ``grid``
        says) where a job's face does not hold whole cells.
    reciprocals : bool, optional
        Store the reciprocals of the sides (1 / h per virtual face, of the corner patches' unit sides) so that
        the kernel multiplies instead of dividing. Default: where every side is a power of two (then the two
        give the same bits).

    The results are the same bits with any of these.

    Raises
    ------
    CCProofError
        ``layers`` outside 1 to 4; ``reciprocals=True`` on a table with a side that is not a power of two.
    """

    def __init__(self, table, layers=None, grid=None, reciprocals=None, derived=None):
        self.table = T = table
        self.layers, self.grid, self.reciprocals = layers, grid, reciprocals
        keep = {}
        derived = derived or {}  # (a pickled CTable) the arrays computed below, as computed then

        def arr(name, dtype):
            a = np.ascontiguousarray(getattr(T, name), dtype=dtype)
            keep[name] = a
            return _addr(a)

        def arr_of(name, a):
            keep[name] = a = np.ascontiguousarray(a, dtype=np.float64)
            return _addr(a)

        def offsets(name):  # int32 or int64, as the table stores them
            a = getattr(T, name)
            a = np.ascontiguousarray(a, dtype=np.int32 if a.dtype == np.int32 else np.int64)
            keep[name] = a
            return _addr(a), int(a.dtype == np.int64)

        s = _Table()
        wide = []
        for name in ("top", "job_root", "job_net", "job_corner", "job_ring"):
            p, w = offsets(name)
            setattr(s, name, p)
            wide.append(w)
        s.wide = (_I * 5)(*wide)
        s.refused = arr("refused", np.bool_)
        s.kind = arr("kind", np.int8)
        for name in ("child", "leaf", "cfg", "op_start", "op_size", "n_layers", "vop_start", "vn"):
            setattr(s, name, arr(name, np.int64))
        for name in ("u0", "v0", "h", "nets", "ops", "unit", "hot", "vop", "points"):
            setattr(s, name, arr(name, np.float64))
        s.rings = arr("rings", np.int32)
        s.cu = arr("cu", np.bool_)  # one byte each, 0 or 1
        s.cv = arr("cv", np.bool_)
        s.split_depth = int(T.split_depth)
        s.n_ptex = int(T.refused.shape[0])
        s.max_layers = max(1, int(T.n_layers.max()) if T.n_layers.size else 1)
        s.n_hot = int(T.hot.shape[0])
        if T.cor_ring.size:  # (NULL otherwise: no kept ring)
            s.cor_ring = arr("cor_ring", np.int64)
            s.ring = arr("ring", np.float64)
        s.n_nets = int(T.nets.shape[0])
        s.n_corner = int(T.n_corner)
        if COMPOSED_LAYERS != _COMPOSED:
            raise CCProofError(f"the C kernel composes {_COMPOSED} layers, the table {COMPOSED_LAYERS}")
        self._keep = keep
        self.struct = s
        self.ref = ctypes.byref(s)
        self._kept_nets(derived)
        if s.n_hot:  # the corner nets of layers 0 (the table's or computed here) to n - 1 (computed here)
            n = layers if layers is not None else 1 + min(2, LAYER_NETS_BUDGET // max(1, keep["hot"].nbytes))
            if not 1 <= n <= _LAYER_NETS:
                raise CCProofError(f"layers must be 1 to {_LAYER_NETS}, got {n}")
            nets = [keep["hot"]]
            lib = load()
            for lay in range(1, n) if "layer_nets" not in derived else ():
                w = fresh(keep["hot"].shape)
                if lib.ccp_nets(self.ref, T.job_root.shape[0], _CORNER, lay, _addr(w)) != 0:
                    break  # a tree of virtual faces deeper than the walk's stack: the cache serves these layers
                nets.append(w)
            nets = derived.get("layer_nets", nets)
            n = len(nets)
            keep["layer_nets"] = nets
            s.layer_nets = (_P * _LAYER_NETS)(*[_addr(a) for a in nets])
            s.n_layer_nets = n
        self._make_grid(grid, derived)
        sides = T.unit[:, :, 2].reshape(-1)
        if reciprocals if reciprocals is not None else (_powers_of_two(T.h) and _powers_of_two(sides)):
            if not (_powers_of_two(T.h) and _powers_of_two(sides)):
                raise CCProofError("reciprocals need every side of the table to be a power of two")
            s.inv_h = arr_of("inv_h", 1.0 / T.h)
            s.inv_unit = arr_of("inv_unit", 1.0 / sides)
        self._caches = []  # corner-net caches not in use (one per concurrent call, kept between calls)
        self._lock = threading.Lock()

    def _make_grid(self, grid, derived):
        """The grid of cells (``ccp_grid``) where ``grid`` asks for it (None: within :data:`GRID_BUDGET`), or
        ``derived``'s; its entries ``job << shift | virtual face``, shift the bits of the largest virtual face:
        uint32 where the largest job fits the bits left, else int64."""
        T, s = self.table, self.struct
        n_ptex = T.refused.shape[0]
        shift = max(1, int(T.kind.shape[0] - 1).bit_length())
        wide = int(shift + max(1, int(T.job_root.shape[0] - 1).bit_length()) > 32)
        if "grid" in derived:
            g = derived["grid"]
        elif "grid_none" in derived or not (grid if grid is not None
                                            else 0 < n_ptex and 64 * (1 + wide) * n_ptex <= GRID_BUDGET):
            return
        else:
            g = fresh(16 * n_ptex, dtype=np.int64 if wide else np.uint32)
            if load().ccp_grid(self.ref, _addr(g), wide, shift) != 0:
                return
        self._keep["grid"] = g
        s.grid, s.grid_wide, s.grid_shift = _addr(g), int(g.dtype == np.int64), shift

    def _kept_nets(self, derived):
        """The regular nets and the layer-0 corner nets the table does not keep, computed here by the kernel's
        own sums (``ccp_nets``: the same bits as when evaluated) where they fit
        :data:`KEPT_NETS_BUDGET` (or ``derived``'s, as a pickled CTable computed them)."""
        T, s, keep, lib = self.table, self.struct, self._keep, load()
        n_jobs = T.job_root.shape[0]
        left = KEPT_NETS_BUDGET
        if s.n_nets == 0 and T.n_regular:
            w = derived.get("nets")
            if (w is None or w.shape[0] != T.n_regular) and \
                    T.n_regular * 408 <= budget("CCPROOF_NETS_BUDGET", KEPT_NETS_BUDGET):
                w = fresh((T.n_regular, 17, 3))
                if lib.ccp_nets(self.ref, n_jobs, _REGULAR, 0, _addr(w)) != 0:
                    w = None  # a tree deeper than the walk's stack: computed when evaluated
            if w is not None and w.shape[0] == T.n_regular:
                keep["nets"] = w
                s.nets, s.n_nets = _addr(w), T.n_regular
                left -= w.nbytes
        if s.n_hot == 0 and T.n_corner:
            w = derived["layer_nets"][0] if "layer_nets" in derived else None
            if w is None and 3 * T.n_corner * 408 <= budget("CCPROOF_HOT_BUDGET", left):
                w = fresh((3 * T.n_corner, 17, 3))
                if lib.ccp_nets(self.ref, n_jobs, _CORNER, 0, _addr(w)) != 0:
                    w = None
            if w is not None:
                keep["hot"] = w
                s.hot, s.n_hot = _addr(w), 3 * T.n_corner

    def take_cache(self, lib):
        """A corner-net cache for one call (:meth:`give_cache` it back after the call)."""
        with self._lock:
            if self._caches:
                return self._caches.pop()
        return np.zeros(lib.ccp_cache_words())  # the kernel's layout; zero: empty

    def give_cache(self, cache):
        with self._lock:
            self._caches.append(cache)

    def __reduce__(self):
        """Pickled with the arrays it computed (corner nets, grid): unpickled, it points into them again (a
        worker of a cluster maps them from shared memory instead of computing its own)."""
        derived = {k: self._keep[k] for k in ("layer_nets", "grid", "nets") if k in self._keep}
        if "grid" not in derived:
            derived["grid_none"] = True
        return CTable, (self.table, self.layers, self.grid, self.reciprocals, derived)


def evaluate_block(lib, ct, f, u, v, d, outs, rows=None):
    """Evaluate points ``f, u, v`` (contiguous int64 / float64, shape (n,)) into ``outs`` (the arrays
    P, Pu, Pv, Puu, Puv, Pvv: contiguous float64 (n, 3), or None beyond derivative order ``d``); with ``rows``
    (contiguous int64, distinct rows of the inputs and outputs) the points of those rows, in that order.

    Returns -1, or the index (in ``rows`` where given) of the first point the kernel refuses (face out of
    range or a hole, (u, v) outside [0, 1]^2 or NaN); the outputs from that point on are not written.
    """
    ptrs = [None if a is None else _addr(a) for a in outs]
    n = f.size if rows is None else rows.size
    cache = ct.take_cache(lib) if n >= _CACHE_MIN else None
    try:
        if rows is None:
            return int(lib.ccp_evaluate(ct.ref, n, _addr(f), _addr(u), _addr(v), d, *ptrs,
                                        None if cache is None else _addr(cache)))
        return int(lib.ccp_evaluate_at(ct.ref, n, _addr(rows), _addr(f), _addr(u), _addr(v), d, *ptrs,
                                       None if cache is None else _addr(cache)))
    finally:
        if cache is not None:
            ct.give_cache(cache)


def point_blocks(lib, ct, f, u, v, d, outs, order=None):
    """``(block, back)`` for :func:`ccproof.evaluate.backend.evaluation_blocks`: ``block(lo, hi)`` calls
    :func:`evaluate_block` on the points lo:hi (``f, u, v`` contiguous) of the table ``ct`` (a :class:`CTable`);
    with ``order`` (a permutation of the points) on the points ``order[lo:hi]``, each written to its own row;
    ``outs`` the six outputs (None where absent), those beyond derivative order ``d`` not written; ``back``:
    ``[(index, temporary)]`` for the outputs it cannot write in place (not contiguous float64 (n, 3))."""
    f, u, v = (np.ascontiguousarray(a) for a in (f, u, v))
    n = f.size
    back, arrs = [], []
    for i, a in enumerate(outs):
        a = a if i < (1, 3, 6)[d] else None
        if a is not None and not (isinstance(a, np.ndarray) and a.dtype == np.float64
                                  and a.shape == (n, 3) and a.flags.c_contiguous):
            back.append((i, np.empty((n, 3))))
            a = back[-1][1]
        arrs.append(a)

    if order is not None:
        order = np.ascontiguousarray(order, dtype=np.int64)
        return (lambda lo, hi: evaluate_block(lib, ct, f, u, v, d, arrs, order[lo:hi])), back

    def block(lo, hi):
        return evaluate_block(lib, ct, f[lo:hi], u[lo:hi], v[lo:hi], d, [None if a is None else a[lo:hi] for a in arrs])
    return block, back


def face_order(f, n_faces, shift):
    """The points in the order of their faces ``f`` (int64; out of range ones as the nearest face) ``>> shift``,
    stable: ``np.argsort(np.clip(f, 0, n_faces - 1) >> shift, kind="stable")`` by a counting sort in C
    (``ccp_face_order``). Requires :func:`load` to have found the library.

    >>> if load() is not None:
    ...     print(face_order(np.array([5, 0, 3, 9, 1]), 6, 1).tolist())
    ... else:
    ...     print([1, 4, 2, 0, 3])
    [1, 4, 2, 0, 3]
    """
    f = np.ascontiguousarray(f, dtype=np.int64)
    order = np.empty(f.size, dtype=np.int64)
    counts = np.empty(((max(1, n_faces) - 1) >> shift) + 2, dtype=np.int64)
    load().ccp_face_order(f.size, _addr(f), max(1, n_faces), shift, _addr(counts), _addr(order))
    return order


def _arg(a, dtype, name):
    """The address of ``a``, which the kernel reads or writes in place: it must be C-contiguous ``dtype``."""
    if not (isinstance(a, np.ndarray) and a.dtype == dtype and a.flags.c_contiguous):
        raise TypeError(f"ring_walks: {name} must be a C-contiguous {np.dtype(dtype).name} array")
    return _addr(a)


def ring_walks(halfedges, scratch, g, r, out):
    """The ring walk of :func:`ccproof.evaluate._numba_kernel.ring_walks` (the same arguments and results)
    in C: ``ccp_ring_walks`` of ``_clib.c``. Requires :func:`load` to have found the library."""
    (org, nxt, prv, twin), (pos, seen), (rings, nring, faces, nfaces, hashes) = halfedges, scratch, out
    lib = load()
    k, maxn = rings.shape
    maxf = faces.shape[1]
    i64 = np.int64
    org, nxt, prv, twin, g, r = (np.ascontiguousarray(a, dtype=i64) for a in (org, nxt, prv, twin, g, r))  # read
    ptrs = [_addr(a) for a in (org, nxt, prv, twin)] + [_arg(pos, i64, "pos"), _arg(seen, np.bool_, "seen")]
    rc = lib.ccp_ring_walks(*ptrs, k, _addr(g), _addr(r), _arg(rings, np.int32, "rings"), maxn,
                            _arg(nring, i64, "nring"), _arg(faces, i64, "faces"), maxf, _arg(nfaces, i64, "nfaces"),
                            _arg(hashes, np.uint64, "hashes"))
    if rc != 0:
        raise MemoryError("ring_walks: no memory for the walk's scratch arrays")
