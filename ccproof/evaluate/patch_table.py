"""The patch table of the exact evaluator: per configuration the exact operators, per face its control points.

A *job* is one quad of the complex the classification starts from (a base face of a quad mesh, a
level-1 sub-face of a tagged polygon mesh), with its frame (where it sits in its ptex face). Its
*ring* (the faces sharing a vertex with it, :func:`ccproof.evaluate.local.canonical_ring`, listed from
a corner; the two-ring in the Chaikin semi-sharp phase) has a tagged key, and the key (with the
frame) determines everything the classification does with the face: which local subdivisions it
needs, which of the resulting virtual faces are regular bicubic patches and which are self-similar
corner faces, and every net and corner ring as a linear function of the ring's control points.
That is a *template*, built once per key by the exact local machinery of
:mod:`ccproof.evaluate.local` run on the identity (the builder is linear, column by column), and
shared by every face with that key
(:mod:`ccproof.evaluate.template_cache`, built by :mod:`ccproof.evaluate.factory`):

* per template: the tree of virtual faces (split, regular, corner) with their domains in the ptex
  face, the operators ``(17, N)`` of its regular patches (16 net rows relative to the origin, row 16
  the origin) and ``(Nc + 1, N)`` of its corner rings (the ring relative to the corner vertex, and
  the corner's limit point);
* per *configuration* (a corner scheme and the orientation of the corner in the ptex face): the
  exact-then-rounded layer operators ``L`` (n_layers, 3, 16, Nc) of
  :func:`ccproof.evaluate.local.corner_scheme`, shared by every corner face of that configuration;
* per job: the id of its template and its ring (int32 indices into the positions the rings index,
  one (V, 3) array shared by every job).

A point's net is computed when it is evaluated, from the positions of its job's ring: the net of a
regular patch is its template operator (17 x N) applied to ``rel = X[ring] - X[ring[0]]``, the net of
layer n of a corner face is ``L[n, code] @ (Q @ rel)`` (Q the corner face's ring operator), every sum
taken in one fixed order (ring point j = 1, 2, ... from 0.0) by every backend, so that all give the
same bits. Small tables keep the nets precomputed by the same sums (:data:`ccproof.evaluate.nets.NETS_BUDGET`,
:data:`ccproof.evaluate.nets.HOT_BUDGET`).

Memory: O(control points + ptex faces + configurations): per ptex face of a triangle scan 133 bytes
(the ring's indices, the offsets, the level-1 points); nothing is stored per layer or per net of a face,
nor any limit point.
"""

from __future__ import annotations

from array import array
from typing import NamedTuple

import numpy as np

from ccproof.errors import MeshError
from ccproof.evaluate.frames import oriented_layers

#: kinds of a virtual face: a regular bicubic patch, a corner face of a corner scheme, split into four children
KIND_REGULAR, KIND_CORNER, KIND_SPLIT = 0, 1, 2

#: layers of a corner face whose nets are one product with the ring: the layer operator composed with the
#: corner ring's (``Q L[n, code]``, (N, 16) per layer and code, per corner face of a template); the deeper
#: layers take the ring first (``L[n, code] @ (Q @ rel)``). A uniformly random point of a corner face is in
#: layer 0 or 1 with probability 15/16.
COMPOSED_LAYERS = 2


class PatchTable(NamedTuple):
    """The arrays the evaluation kernels read (one argument for numba; see the module docstring).

    Attributes
    ----------
    top : int32 (P, 4) (int64 beyond 2^31 jobs)
        Job of each quadrant ``(u >= 1/2) + 2 (v >= 1/2)`` of every ptex face (all four equal
        unless the ptex face is a quad split into its four level-1 children).
    refused : bool (P,)
        Ptex faces evaluation refuses (holes).
    job_root, job_net, job_corner, job_ring : int32 (J,) (int64 where the offsets need it)
        Per job: the root virtual face of its template, and the index of its first regular patch, of its
        first corner face and of its ring in ``rings``.
    kind : int8 (T,)
        Per template virtual face: 0 regular patch, 1 corner face, 2 split into four children.
    child : int64 (T, 4)
        Children of a split virtual face by quadrant.
    u0, v0, h : float64 (T,)
        Domain of a virtual face in its ptex face (lower-left corner, side: a power of 2).
    leaf : int64 (T,)
        Index of a leaf among its template's regular patches or corner faces.
    cfg : int64 (T,)
        Configuration of a corner face.
    cu, cv : bool (T,)
        Whether a corner face's irregular corner is at ``u0 + h`` (``v0 + h``).
    vop_start, vn : int64 (T,)
        Per leaf its operator's offset in ``vop`` and its template's ring size N.
    vop : float64
        Per regular leaf its operator (N, 17): row j the weights of ring point j in the 16 net rows
        (relative to row 16) and in row 16 (less the ring's point 0); per corner face (N, Nc - 1): row j
        the weights of ring point j in the rows 1 .. Nc - 1 of the corner ring relative to its vertex,
        then (N,) the weights in its limit point (less the ring's point 0), then the composed operators
        (N, 16) of its first layers (:data:`COMPOSED_LAYERS`), layer by layer, code by code: row j the
        weights of ring point j in the 16 rows of that net.
    split_depth : int
        Deepest split in any template.
    n_regular, n_corner : int
        Regular patches and corner faces (leaves) of all jobs together.
    points : float64 (V, 3)
        The positions the rings index (the mesh's vertices, or the level-1 points of a polygon mesh).
    rings : int32 (sum of the jobs' ring sizes,)
        The rings of the jobs, one after the other.
    nets : float64 (n_regular, 17, 3) or (0, 17, 3)
        The nets of the regular patches (base orientation, row 16 the origin) computed by the kernels'
        sums, kept when they fit :data:`ccproof.evaluate.nets.NETS_BUDGET`; empty otherwise (computed when evaluated).
    ops : float64 (sum of n_layers * 48 * Nc,)
        Per configuration its layer operators ``L`` laid out (n_layers, 3, Nc, 16): ``[n, code, j, i]``
        the weight of ring point j in entry i of the net of layer n, patch ``code`` (0 along u, 1
        diagonal, 2 along v), base orientation (the 16 entries of one ring point contiguous).
    op_start, op_size, n_layers : int64 (n_cfg,)
        Offset in ``ops``, ring size Nc and number of layers of each configuration.
    unit : float64 (n_cfg, 3, 3)
        ``(u0, v0, h)`` of the three patches of layer 0 for a corner frame of side 1 at the origin.
    hot : float64 (3 n_corner, 17, 3) or (0, 17, 3)
        The nets of layer 0 of every corner face (patch ``3 c + code``, row 16 the limit point),
        computed like the kernel computes them (the same sums in the same order), kept when they fit
        :data:`ccproof.evaluate.nets.HOT_BUDGET`; empty otherwise. A uniformly random point of a corner
        face is in layer 0 with probability 3/4.
    cor_ring : int64 (n_corner,) or (0,)
        Per corner face the row in ``ring`` of its kept ring, or -1 (computed when needed); empty where no
        ring is kept.
    ring : float64 (rows, 3)
        The kept rings (rows 1 .. Nc - 1 of each, relative to the corner vertex, computed by the kernels'
        sums) of the corner faces of configurations with Nc >= :data:`ccproof.evaluate.nets.KEEP_RING_NC`
        (the centres of large n-gons, vertices of high valence: a deep net computed from the job's ring
        costs N (Nc - 1) x 3 products there), for the layers from :data:`COMPOSED_LAYERS` on.

    Examples
    --------
    A surface's table is ``S.patch_map.table`` (:class:`ccproof.evaluate.patch_map.PatchMap`). The 5-regular
    disk of two rings: 20 ptex faces, 10 regular patches (their nets kept: a small table), 10 corner faces:

    >>> from ccproof.evaluate import natural_limit_surface
    >>> from ccproof.mesh.examples import k_regular_disk
    >>> T = natural_limit_surface(k_regular_disk(5, 2)).patch_map.table
    >>> T.top.shape, T.n_regular, T.nets.shape, T.n_corner
    ((20, 4), 10, (10, 17, 3), 10)
    """

    top: np.ndarray
    refused: np.ndarray
    job_root: np.ndarray
    job_net: np.ndarray
    job_corner: np.ndarray
    job_ring: np.ndarray
    kind: np.ndarray
    child: np.ndarray
    u0: np.ndarray
    v0: np.ndarray
    h: np.ndarray
    leaf: np.ndarray
    cfg: np.ndarray
    cu: np.ndarray
    cv: np.ndarray
    vop_start: np.ndarray
    vn: np.ndarray
    vop: np.ndarray
    split_depth: int
    n_regular: int
    n_corner: int
    points: np.ndarray
    rings: np.ndarray
    nets: np.ndarray
    ops: np.ndarray
    op_start: np.ndarray
    op_size: np.ndarray
    n_layers: np.ndarray
    unit: np.ndarray
    hot: np.ndarray
    cor_ring: np.ndarray
    ring: np.ndarray


def check_positions(X, rings):
    """MeshError unless every position the ``rings`` index is finite and below 1e300 in magnitude (the
    nets computed from their differences are then finite).

    >>> check_positions(np.array([[0.0, 1, 2], [np.nan, 0, 0]]), np.array([0], np.int32))
    >>> check_positions(np.array([[0.0, 1, 2], [np.nan, 0, 0]]), np.array([0, 1], np.int32))
    Traceback (most recent call last):
    ...
    ccproof.errors.MeshError: control point 1 of the patch table is not finite or beyond 1e300 in magnitude
    """
    used = np.zeros(X.shape[0], dtype=bool)
    used[rings] = True
    bad = np.flatnonzero(used & ~(np.abs(X) <= 1e300).all(axis=1))
    if bad.size:
        raise MeshError(f"control point {int(bad[0])} of the patch table is not finite or beyond 1e300 in magnitude")


def _configuration_ops(schemes):
    """Per configuration its layer operators, flat (layer, code, j, i), their offsets in the
    concatenation, its ring size Nc, its number of layers, its layer-0 domains ``unit``."""
    ops, op_start, op_size, n_layers, unit = [], [], [], [], []
    off = 0
    for scheme, orient in schemes:
        flat, u = _flat_layers(scheme, orient)
        ops.append(flat)
        op_start.append(off)
        op_size.append(scheme.layers.shape[-1])
        n_layers.append(scheme.n_layers)
        unit.append(u)
        off += flat.size
    return ops, op_start, op_size, n_layers, unit


#: per configuration (id of its corner scheme, orientation): (scheme, flat operators, unit), read-only, those of
#: recent setups in this process, within :data:`_FLAT_BUDGET` bytes (the oldest dropped first)
_FLAT: dict = {}
_FLAT_BUDGET = 16 << 20


def _flat_layers(scheme, orient):
    """The layer operators of a configuration, flat (layer, code, j, i), and its ``unit``: the same array for
    the same (scheme, orientation) while it stays within :data:`_FLAT_BUDGET` (the scheme is kept with it)."""
    key = (id(scheme), orient)
    hit = _FLAT.get(key)
    if hit is not None and hit[0] is scheme:
        return hit[1], hit[2]
    L, u = oriented_layers(scheme, orient)
    nl, nc = scheme.n_layers, L.shape[1]
    flat = L.reshape(nl * 3, 16, nc).transpose(0, 2, 1).reshape(-1)
    flat.setflags(write=False)
    held = sum(x[1].nbytes for x in _FLAT.values())
    while _FLAT and held + flat.nbytes > _FLAT_BUDGET:
        held -= _FLAT.pop(next(iter(_FLAT)))[1].nbytes
    if flat.nbytes <= _FLAT_BUDGET:
        _FLAT[key] = (scheme, flat, u)
    return flat, u


def assemble(temps, schemes, n_jobs, X, top, refused):
    """The :class:`PatchTable` of the finished templates ``temps`` (their ``cfg`` indices into ``schemes``, the
    configurations ``[(CornerScheme, orientation)]``) of ``n_jobs`` jobs with positions ``X``, without
    precomputed nets (:func:`ccproof.evaluate.nets.with_nets` adds them), and the template groups
    ``[(template, jobs, rings)]`` (``rings`` views of the table's ``rings``). ``top`` (P, 4): the job of each
    quadrant of every ptex face; ``refused`` (P,): the ptex faces evaluation refuses."""
    J = n_jobs
    job_root = np.full(J, -1, dtype=np.int64)
    job_net = np.zeros(J, dtype=np.int64)
    job_corner = np.zeros(J, dtype=np.int64)
    job_ring = np.zeros(J, dtype=np.int64)
    kind, child, dom, leaf, cfg, corner, vop_start, vn, vop = [], [], [], [], [], [], [], [], []
    n_tv = n_reg = n_cor = n_ring = n_vop = 0
    groups = []
    depth = 0
    ops, op_start, op_size, n_layers, unit = _configuration_ops(schemes)
    rings_flat = np.empty(sum(len(t.rings) for t in temps), dtype=np.int32)
    for t in temps:
        jobs = np.frombuffer(t.jobs, dtype=np.int64).astype(np.int32 if J < 2**31 else np.int64) \
            if len(t.jobs) else np.zeros(0, np.int64)
        k = jobs.size
        rings = rings_flat[n_ring:n_ring + k * t.n].reshape(k, t.n)
        if k:
            rings[...] = np.frombuffer(t.rings, dtype=np.int32).reshape(k, t.n)
        t.rings = None  # (the table's copy is the one kept)
        t.jobs = array("q")  # (the group's copy is the one kept)
        job_root[jobs] = n_tv
        nr, nc = t.R.shape[0] // 17, t.O.shape[0]
        job_net[jobs] = n_reg + nr * np.arange(k)
        job_corner[jobs] = n_cor + nc * np.arange(k)
        job_ring[jobs] = n_ring + t.n * np.arange(k)
        t.offsets = (n_reg, n_cor, n_ring)
        n_reg += nr * k
        n_cor += nc * k
        n_ring += t.n * k
        kind += t.kind
        child += [[c + n_tv if c >= 0 else -1 for c in ch] for ch in t.child]
        dom += t.dom
        leaf += t.leaf
        cfg += t.cfg
        corner += t.corner
        for ops_ in _cached_leaf_operators(t, ops):
            vop_start.append(n_vop if ops_ is not None else -1)
            vn.append(t.n)
            if ops_ is not None:
                vop.append(ops_)
                n_vop += ops_.size
        dv = np.zeros(len(t.kind), dtype=np.int64)
        for v, ch in enumerate(t.child):  # children are created after their parents
            if t.kind[v] == KIND_SPLIT:
                dv[ch] = dv[v] + 1
        depth = max(depth, int(dv.max()))
        n_tv += len(t.kind)
        groups.append((t, jobs, rings))
    if (job_root < 0).any():  # pragma: no cover - would be a bug in the classification
        raise MeshError(f"internal error: job {int(np.flatnonzero(job_root < 0)[0])} was not classified")
    d = np.array(dom, dtype=np.float64).reshape(-1, 3)
    c = np.array(corner, dtype=bool).reshape(-1, 2)
    X = np.ascontiguousarray(X, dtype=np.float64)
    check_positions(X, rings_flat)

    def small(a, bound):  # int32 where it fits (the per-face arrays are the big ones)
        return np.ascontiguousarray(a, dtype=np.int32 if bound < 2**31 else np.int64)

    T = PatchTable(
        top=small(top, J), refused=np.ascontiguousarray(refused, dtype=np.bool_),
        job_root=small(job_root, n_tv), job_net=small(job_net, n_reg), job_corner=small(job_corner, n_cor),
        job_ring=small(job_ring, n_ring),
        kind=np.array(kind, dtype=np.int8), child=np.array(child, dtype=np.int64).reshape(-1, 4),
        u0=d[:, 0].copy(), v0=d[:, 1].copy(), h=d[:, 2].copy(), leaf=np.array(leaf, dtype=np.int64),
        cfg=np.array(cfg, dtype=np.int64), cu=c[:, 0].copy(), cv=c[:, 1].copy(),
        vop_start=np.array(vop_start, dtype=np.int64), vn=np.array(vn, dtype=np.int64),
        vop=_shared_concatenation(vop), split_depth=depth, n_regular=n_reg, n_corner=n_cor,
        points=X, rings=rings_flat, nets=np.zeros((0, 17, 3)),
        ops=_shared_concatenation(ops), op_start=np.array(op_start, dtype=np.int64),
        op_size=np.array(op_size, dtype=np.int64), n_layers=np.array(n_layers, dtype=np.int64),
        unit=np.array(unit, dtype=np.float64).reshape(-1, 3, 3), hot=np.zeros((0, 17, 3)),
        cor_ring=np.zeros(0, np.int64), ring=np.zeros((0, 3)))
    return T, groups


#: per sequence of operator arrays (their identities): (the arrays, their concatenation, read-only), those of
#: recent setups in this process within :data:`_CONCAT_BUDGET` bytes (the oldest dropped first)
_CONCAT: dict = {}
_CONCAT_BUDGET = 32 << 20


def _shared_concatenation(parts):
    """The arrays ``parts`` flattened and concatenated (float64), read-only: a view of the same concatenation
    again for the same arrays (a setup of the same mesh shares its tables' operators with the last one's; no
    copy of them is writable: the view's base is read-only, so the view cannot be made writable either).

    >>> a, b = np.arange(2.0), np.ones((1, 2))
    >>> c = _shared_concatenation([a, b]); c.tolist(), c.flags.writeable
    ([0.0, 1.0, 1.0, 1.0], False)
    >>> d = _shared_concatenation([a, b]); d.base is c.base
    True
    >>> d.setflags(write=True)
    Traceback (most recent call last):
    ...
    ValueError: cannot set WRITEABLE flag to True of this array
    """
    key = tuple(map(id, parts))
    hit = _CONCAT.get(key)
    if hit is None or len(hit[0]) != len(parts) or not all(a is b for a, b in zip(hit[0], parts)):
        whole = np.concatenate([np.asarray(a, dtype=np.float64).reshape(-1) for a in parts]) if parts \
            else np.zeros(0)
        whole.setflags(write=False)
        hit = (tuple(parts), whole)
        held = sum(h[1].nbytes for h in _CONCAT.values())
        while _CONCAT and held + whole.nbytes > _CONCAT_BUDGET:
            held -= _CONCAT.pop(next(iter(_CONCAT)))[1].nbytes
        if whole.nbytes <= _CONCAT_BUDGET:
            _CONCAT[key] = hit
    view = hit[1][:]
    view.setflags(write=False)
    return view


#: per template and configurations (the identities of its operators and of its configurations' flat layer
#: operators, which are kept with it): the leaf operators of :func:`_leaf_operators`, those of recent setups in
#: this process (a template read from the disk cache keeps its arrays), within :data:`_VOPS_BUDGET` bytes
_VOPS: dict = {}
_VOPS_BUDGET = 8 << 20


def forget_kept():
    """Drop the leaf and flat layer operators this process keeps from recent setups (computed again on use)."""
    _VOPS.clear()
    _FLAT.clear()
    _CONCAT.clear()


def _cached_leaf_operators(t, ops):
    """:func:`_leaf_operators` of ``t``, the same arrays again for the same template arrays and configurations."""
    refs = (t.R, t.Q, t.O, *(ops[c] for c in t.cfg if c >= 0))
    key = tuple(map(id, refs))
    hit = _VOPS.get(key)
    if hit is not None and len(hit[0]) == len(refs) and all(a is b for a, b in zip(hit[0], refs)):
        return hit[1]
    out = _leaf_operators(t, ops)
    size = sum(x.nbytes for x in out if x is not None)
    held = sum(h[2] for h in _VOPS.values())
    while _VOPS and held + size > _VOPS_BUDGET:
        held -= _VOPS.pop(next(iter(_VOPS)))[2]
    if size <= _VOPS_BUDGET:
        _VOPS[key] = (refs, out, size)
    return out


def _leaf_operators(t, ops):
    """Per virtual face of the finished template ``t`` (its ``cfg`` the table's) its operators as
    :attr:`PatchTable.vop` stores them, or None (a split face): regular (N, 17); corner (N, Nc - 1), its
    limit point's (N,), then per layer n < min(:data:`COMPOSED_LAYERS`, layers) and code the composed (N,
    16) ``Q L[n, code]``
    (``ops``: the flat layer operators of each configuration, (n_layers, 3, Nc, 16))."""
    out = []
    starts = sorted(t.pts[v] for v, k in enumerate(t.kind) if k == KIND_CORNER) + [t.Q.shape[0]]
    for v, k in enumerate(t.kind):
        if k == KIND_REGULAR:
            r = 17 * t.leaf[v]
            out.append(np.ascontiguousarray(t.R[r:r + 17].T))
        elif k == KIND_CORNER:
            p = t.pts[v]
            Q = t.Q[p:starts[starts.index(p) + 1]].T  # (N, Nc - 1)
            L = ops[t.cfg[v]].reshape(-1, 3, Q.shape[1] + 1, 16)  # (layer, code, j, i)
            comp = [Q @ L[n, c, 1:] for n in range(min(COMPOSED_LAYERS, L.shape[0])) for c in range(3)]
            out.append(np.concatenate([Q.reshape(-1), t.O[t.leaf[v]]] + [m.reshape(-1) for m in comp]))
        else:
            out.append(None)
    return out
