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
shared by every face with that key:

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
same bits. Small tables keep the nets precomputed by the same sums (:data:`NETS_BUDGET`,
:data:`HOT_BUDGET`).

Memory: O(control points + ptex faces + configurations): per ptex face of a triangle scan 133 bytes
(the ring's indices, the offsets, the level-1 points); nothing is stored per layer or per net of a face,
nor any limit point.
"""

from __future__ import annotations

import bisect
import functools
import sys
from array import array
from typing import NamedTuple

import numpy as np

from ccproof.errors import MeshError
from ccproof.evaluate import _diskcache
from ccproof.evaluate.local import (
    CENTER,
    CORNERS,
    SIDES,
    canonical_ring,
    child_ring,
    code_version,
    corner_scheme,
    has_semi_sharp,
    irregular_corners,
    key_complex,
    refine_key,
    regular_net_matrix,
    ring_key,
)
from ccproof.mesh.halfedges import HalfEdges

#: kinds of a virtual face: a regular bicubic patch, a corner face of a corner scheme, split into four children
KIND_REGULAR, KIND_CORNER, KIND_SPLIT = 0, 1, 2

#: how many times a face may be subdivided before it must be regular or self-similar
MAX_DEPTH = 4
#: local subdivisions allowed in the semi-sharp phase of a tagged mesh (sharpness < 10 decays in
#: 10 uniform levels)
MAX_SEMI_DEPTH = 40
#: jobs per block when the limit points or precomputed nets are computed (bounds the temporaries)
_BLOCK = 1 << 13
#: largest size of the layer-0 nets of the corner faces kept precomputed (``PatchTable.hot``, 1,224
#: bytes per corner face); beyond it every corner net is computed at evaluation time
HOT_BUDGET = 32 << 20
#: layers of a corner face whose nets are one product with the ring: the layer operator composed with the
#: corner ring's (``Q L[n, code]``, (N, 16) per layer and code, per corner face of a template); the deeper
#: layers take the ring first (``L[n, code] @ (Q @ rel)``). A uniformly random point of a corner face is in
#: layer 0 or 1 with probability 15/16.
COMPOSED_LAYERS = 2
#: corner rings of at least this many points are kept per corner face (``PatchTable.ring``)
KEEP_RING_NC = 40
#: largest size of the regular nets kept precomputed (``PatchTable.nets``, 408 bytes per regular patch);
#: beyond it every regular net is computed at evaluation time from the ring
NETS_BUDGET = 32 << 20


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
        sums, kept when they fit :data:`NETS_BUDGET`; empty otherwise (computed when evaluated).
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
        :data:`HOT_BUDGET`; empty otherwise. A uniformly random point of a corner face is in layer 0
        with probability 3/4.
    cor_ring : int64 (n_corner,) or (0,)
        Per corner face the row in ``ring`` of its kept ring, or -1 (computed when needed); empty where no
        ring is kept.
    ring : float64 (rows, 3)
        The kept rings (rows 1 .. Nc - 1 of each, relative to the corner vertex, computed by the kernels'
        sums) of the corner faces of configurations with Nc >= :data:`KEEP_RING_NC` (the centres of large
        n-gons, vertices of high valence: a deep net computed from the job's ring costs N (Nc - 1) x 3
        products there), for the layers from :data:`COMPOSED_LAYERS` on.

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


# ---------------------------------------------------------------------------------- frames
# A frame maps a face's own parameter (s, t) to the base face's (u, v): (u, v) = o + s a + t b,
# with a, b axis-aligned of the same length (a power of 2). Frames are tuples of three float pairs
# (o, a, b): they are composed once per virtual face, so plain floats (every value dyadic, every
# operation exact) instead of small arrays.
_C = tuple((float(x), float(y)) for x, y in CORNERS)


def compose(frame, sub):
    """Frame ``sub`` (given in the coordinates of ``frame``) in the coordinates ``frame`` is given in."""
    (ox, oy), (ax, ay), (bx, by) = frame
    (p, q), (sa0, sa1), (sb0, sb1) = sub
    return ((ox + ax * p + bx * q, oy + ay * p + by * q), (ax * sa0 + bx * sa1, ay * sa0 + by * sa1),
            (ax * sb0 + bx * sb1, ay * sb0 + by * sb1))


def _corner_frame(i, scale=1.0):
    """Frame of the square at corner i of [0,1]^2, rotated so that corner i is its origin."""
    c, c1, c3 = _C[i], _C[(i + 1) % 4], _C[(i + 3) % 4]
    return (c, ((c1[0] - c[0]) * scale, (c1[1] - c[1]) * scale), ((c3[0] - c[0]) * scale, (c3[1] - c[1]) * scale))


def child_frame(i):
    """Frame of the half-size child square at corner ``i`` of [0,1]^2 (corner ``i`` its origin)."""
    return _corner_frame(i, 0.5)


def _layer_frame(n, j):
    """Frame of patch P_j of layer n in the corner frame (corner at the origin), bmz04 Fig. 3."""
    h = 2.0 ** -(n + 1)
    o, a, b = _corner_frame(j, h)
    return ((o[0] * 2.0 * h, o[1] * 2.0 * h), a, b)


def domain(frame):
    """``(u0, v0, size)``: the axis-aligned square a frame covers, its lower-left corner and side."""
    (ox, oy), (ax, ay), (bx, by) = frame
    return ox + min(ax, 0.0) + min(bx, 0.0), oy + min(ay, 0.0) + min(by, 0.0), max(abs(ax), abs(ay))


@functools.lru_cache(maxsize=64)
def _permutation(ah, bh):
    perm = np.empty(16, dtype=np.int64)
    for q in range(4):
        for p in range(4):
            i = int(round(1.5 + (p - 1.5) * ah[0] + (q - 1.5) * bh[0]))
            j = int(round(1.5 + (p - 1.5) * ah[1] + (q - 1.5) * bh[1]))
            perm[i + 4 * j] = p + 4 * q
    perm.setflags(write=False)
    return perm


def _net_permutation(frame):
    """Index map sending a net in the frame's own orientation to the base orientation."""
    _, a, b = frame
    return _permutation(_sign(a), _sign(b))


def _sign(x):
    return (int(x[0] > 0) - int(x[0] < 0), int(x[1] > 0) - int(x[1] < 0))


@functools.lru_cache(maxsize=16)
def _corner_orientation(orient):
    """Rows of a scheme's layer nets and layer-0 domains for a corner frame with axis directions
    ``orient``: ``rows`` (48,), row ``16 code + i`` of a layer in the base orientation is row
    ``rows[16 code + i]`` of its ``3 x 16`` nets ``D[n, j-1]``; ``unit`` (3, 3), the domains of the
    three patches of layer 0 for a unit frame at the origin."""
    a, b = orient
    unit_rot = ((0.0, 0.0), (float(a[0]), float(a[1])), (float(b[0]), float(b[1])))
    # P_1 lies along the frame's a-axis: code 0 (u-distance >= 1/2, v-distance < 1/2) if a is
    # along u, else code 2; P_2 (diagonal) is code 1; P_3 the other one
    a_along_u = a[0] != 0
    codes = {1: 0 if a_along_u else 2, 2: 1, 3: 2 if a_along_u else 0}
    rows = np.empty(48, dtype=np.int64)
    unit = np.empty((3, 3))
    for j in (1, 2, 3):
        f0 = compose(unit_rot, _layer_frame(0, j))
        rows[16 * codes[j]:16 * codes[j] + 16] = 16 * (j - 1) + _net_permutation(f0)
        unit[codes[j]] = domain(f0)
    rows.setflags(write=False)
    unit.setflags(write=False)
    return rows, unit


def _oriented_layers(scheme, orient):
    """The layer operators of ``scheme`` for a corner frame with axis directions ``orient``:
    ``L`` (n_layers * 3 * 16, N), row ``(n, code, i)`` entry i of the net of layer n, patch ``code``,
    in the base orientation, and ``unit`` (3, 3) (see :func:`_corner_orientation`)."""
    rows, unit = _corner_orientation(orient)
    Ls = scheme.layers
    nl, N = Ls.shape[0], Ls.shape[-1]
    return np.take(Ls.reshape(nl, 48, N), rows, axis=1).reshape(-1, N), unit


def _smooth_regular_vertices(he):
    """Bool (n_vertices,): the vertices of ``he`` (:class:`~ccproof.mesh.halfedges.HalfEdges`) with
    four faces and no boundary edge, sharp edge or vertex sharpness (regular for the bicubic patch
    under any options)."""
    org, nxt, twin = he.org, he.nxt, he.twin
    ok = np.bincount(org, minlength=he.n_vertices) == 4
    open_h = twin < 0
    ok[org[open_h]] = False
    ok[org[nxt[open_h]]] = False
    if he.edge_keys.size:  # (the tags of interior edges: boundary ones are out already)
        ok[he.edge_keys // he.n_vertices] = False
        ok[he.edge_keys % he.n_vertices] = False
    if he.vertex_values is not None:
        ok[he.vertex_values > 0.0] = False
    return ok


# ---------------------------------------------------------------------------------- templates
class _Template:
    """Virtual faces and leaf operators of one configuration of a job (see the module docstring)."""

    def __init__(self, n):
        self.n = n  # ring size N
        self.kind, self.dom, self.child, self.leaf, self.pts, self.cfg, self.corner = [], [], [], [], [], [], []
        self.reg = []  # (17, N) per regular patch
        self.cor = []  # (Nc, N) per corner face: ring relative to its vertex (rows 1..), then the limit point
        self.cor_vertex = []  # ring position of each corner face's vertex (-1: a new point)
        self.schemes = []  # per configuration used (``cfg``: index here): (corner key, orientation)
        self.n_pts = 0
        self.jobs = array("q")
        self.rings = array("i")

    def new_vface(self, kind, frame):
        self.kind.append(kind)
        self.dom.append(domain(frame))
        self.child.append([-1, -1, -1, -1])
        self.leaf.append(-1)
        self.pts.append(0)
        self.cfg.append(-1)
        self.corner.append((0, 0))
        return len(self.kind) - 1

    def finish(self):
        """Freeze the operators: ``R`` (n_reg * 17, N), ``Q`` (n_pts, N), ``O`` (n_corner, N)."""
        N = self.n
        self.R = np.concatenate(self.reg).reshape(-1, N) if self.reg else np.zeros((0, N))
        self.Q = np.concatenate([c[:-1] for c in self.cor]) if self.cor else np.zeros((0, N))
        self.O = np.array([c[-1] for c in self.cor]).reshape(-1, N)
        for a in (self.R, self.Q, self.O):
            if not np.isfinite(a).all():  # pragma: no cover - would be a bug in the local refinement
                raise MeshError("internal error: a patch uses a point outside the exact local refinement")
        self.reg = self.cor = None


def _finished(t):
    t.finish()
    return t


@functools.lru_cache(maxsize=1)
def _template_version():
    """Hash of the sources that define a template (:func:`code_version` and this module)."""
    import hashlib
    from pathlib import Path

    return hashlib.sha256((code_version() + "|").encode() + Path(__file__).read_bytes()).hexdigest()[:16]


_TPL_MAGIC = 20261202.0  # first value of a template file (the format below)


def _template_bytes(t):
    """A finished template as bytes: one little-endian float64 vector ``[magic, N, n_pts, V, n_reg,
    n_cor, len(json)]``, then per virtual face ``kind``, ``dom`` (3), ``child`` (4), ``leaf``,
    ``pts``, ``cfg``, ``corner`` (2), then ``cor_vertex`` (n_cor), ``R`` (17 n_reg, N), ``Q``
    (n_pts, N), ``O`` (n_cor, N) (integers are exact in float64), then the JSON of the corner keys
    and orientations of its configurations (the file seals these bytes, :mod:`._diskcache`)."""
    import json

    V, N = len(t.kind), t.n
    js = json.dumps(t.schemes).encode()
    ints = np.array([t.kind, t.leaf, t.pts, t.cfg], dtype=np.float64).reshape(4, V)
    return np.concatenate([
        [_TPL_MAGIC, N, t.n_pts, V, t.R.shape[0] // 17, t.O.shape[0], len(js)],
        np.array(t.dom, dtype=np.float64).reshape(-1), np.array(t.child, dtype=np.float64).reshape(-1),
        ints.reshape(-1), np.array(t.corner, dtype=np.float64).reshape(-1),
        np.array(t.cor_vertex, dtype=np.float64), t.R.reshape(-1), t.Q.reshape(-1), t.O.reshape(-1),
    ]).astype("<f8").tobytes() + js


def _tuples(x):
    return tuple(_tuples(y) for y in x) if isinstance(x, list) else x


def _read_template(path, name):
    """The template stored at ``path`` for the cache name ``name`` (:func:`_template_bytes`, sealed by
    :func:`ccproof.evaluate._diskcache.seal`); ValueError unless the file holds exactly what was
    written for that name (digest of name and content, magic, sizes)."""
    try:
        return _parse_template(_diskcache.unseal(path.read_bytes(), name))
    except ValueError as e:
        raise ValueError(f"{path}: {e}") from None


def _parse_template(body):
    import json

    body = bytes(body)
    if len(body) < 56:
        raise ValueError("too short for a template file")
    head = np.frombuffer(body, dtype="<f8", count=7)
    if head[0] != _TPL_MAGIC or not all(0 <= x < 2**40 and x == int(x) for x in head[1:]):
        raise ValueError("not a template file")
    N, n_pts, V, n_reg, n_cor, n_js = (int(x) for x in head[1:])
    n = 7 + 13 * V + n_cor + (17 * n_reg + n_pts + n_cor) * N
    if len(body) != 8 * n + n_js:
        raise ValueError("sizes do not match its header")
    z = np.frombuffer(body, dtype="<f8", count=n)
    o = 7

    def take(k):
        nonlocal o
        o += k
        return z[o - k:o]

    t = _Template(N)
    t.dom = [tuple(d) for d in take(3 * V).reshape(V, 3).tolist()]
    t.child = take(4 * V).astype(np.int64).reshape(V, 4).tolist()
    t.kind, t.leaf, t.pts, t.cfg = take(4 * V).astype(np.int64).reshape(4, V).tolist()
    t.corner = [tuple(c) for c in take(2 * V).astype(np.int64).reshape(V, 2).tolist()]
    t.cor_vertex = take(n_cor).astype(np.int64).tolist()
    t.R = take(17 * n_reg * N).reshape(-1, N)
    t.Q = take(n_pts * N).reshape(-1, N)
    t.O = take(n_cor * N).reshape(-1, N)
    t.n_pts = n_pts
    t.schemes = [(_tuples(k), _tuples(o_)) for k, o_ in json.loads(body[8 * n:].decode())]
    t.reg = t.cor = None
    return t


def _cached_template(tkey, depth_semi, make):
    """``make()`` finished (a :class:`_Template`), kept between runs in the disk cache of
    :func:`ccproof.evaluate.local.corner_scheme` (same folder, ``CCPROOF_CACHE``).

    One file per template, ``SHA-256(key, depth_semi, sources).tpl`` (:func:`_template_bytes`: the
    virtual faces, the leaf operators ``R``, ``Q``, ``O``, the corner keys of its configurations),
    sealed by the SHA-256 of its name and content (:mod:`ccproof.evaluate._diskcache`), checked on
    read with the header's sizes; a missing, unreadable or corrupt file is rebuilt (exact local
    refinement, from corner schemes that were themselves verified) and rewritten atomically, a
    corrupt one reported once. A cached template is the built one bit for bit; with every file
    present a setup does no exact local step.
    """
    import hashlib

    d = _diskcache.cache_dir()
    if d is None:
        return _finished(make())
    name = hashlib.sha256(f"template|{_template_version()}|{depth_semi}|{tkey!r}".encode()).hexdigest()
    t = _diskcache.read_entry(d / f"{name}.tpl", name, _parse_template)
    if t is not None:
        return t
    t = _finished(make())
    _diskcache.store(d, name, ".tpl", _template_bytes(t))
    return t


#: jobs from which the numba ring walk pays for loading numba and its cached kernel (~1 to 1.5 s in a
#: fresh process, against ~0.15 ms per job for the Python walk); below, the Python walk, unless the
#: numba kernels are loaded already. The C kernel's walk (loaded in milliseconds) is taken at any size.
COMPILED_WALK_MIN = 8192


def _ring_walks(n_jobs):
    """The compiled ring walk for ``n_jobs`` rings: the C kernel's where the install built it (no numba
    import), else numba's, or None: the Python walk (neither installed, or fewer than
    :data:`COMPILED_WALK_MIN` jobs in a process that has not loaded the numba kernels)."""
    from ccproof.evaluate import _ckernel

    if _ckernel.load() is not None:
        return _ckernel.ring_walks
    if n_jobs < COMPILED_WALK_MIN and "ccproof.evaluate._numba_kernel" not in sys.modules:
        return None
    from ccproof.evaluate._numba_kernel import ring_walks

    return ring_walks


def _progress(progress, total, desc):
    """A tqdm bar on stderr shown after 2 s (None: when stderr is a terminal), or a no-op."""
    if progress is None:
        progress = sys.stderr.isatty()
    if progress:
        try:
            from tqdm import tqdm
        except ImportError:  # pragma: no cover - tqdm is a dependency
            progress = False
        else:
            return tqdm(total=total, desc=desc, unit="face", delay=2, file=sys.stderr, leave=False)
    return _NoBar()


class _NoBar:
    def update(self, n=1):
        pass

    def close(self):
        pass


class Jobs:
    """The quads to classify: ``g`` (J,) quads of the complex, ``fid`` (J,) index of each one's frame
    in ``frames``, ``base`` (J,) the ptex face errors name. ``jobs[i]`` is ``(g, frame, base)``."""

    def __init__(self, g, fid, base, frames):
        self.g = np.asarray(g, dtype=np.int64)
        self.fid = np.asarray(fid, dtype=np.int64)
        self.base = np.asarray(base, dtype=np.int64)
        self.frames = list(frames)

    @classmethod
    def of(cls, jobs):
        if isinstance(jobs, cls):
            return jobs
        frames, fid = {}, []
        for j in jobs:
            fid.append(frames.setdefault(j[1], len(frames)))
        return cls([j[0] for j in jobs], fid, [j[2] for j in jobs], list(frames))

    def __len__(self):
        return self.g.size

    def __getitem__(self, i):
        return int(self.g[i]), self.frames[self.fid[i]], int(self.base[i])


class TaggedHalfEdges(HalfEdges):
    """A tagged all-quad :class:`~ccproof.mesh.halfedges.HalfEdges` as the tagged ring walk reads it:
    the same arrays (shared, not copied; tags as ``edge_keys``, ``edge_values``, ``vertex_values``),
    plus :meth:`ring_tags`, which hashes the tags of walked rings into their signatures.

    Built by :meth:`of` from a mesh's :class:`~ccproof.mesh.halfedges.HalfEdges` (no copy).
    """

    @classmethod
    def of(cls, src):
        """The view of the half-edges ``src`` (:class:`~ccproof.mesh.halfedges.HalfEdges`, its tags
        from :meth:`~ccproof.mesh.halfedges.HalfEdges.with_tags`): its arrays shared, ``vertex_values``
        zeros where it has none."""
        he = object.__new__(cls)
        he.__dict__.update(src.__dict__)
        if he.vertex_values is None:
            he.vertex_values = np.zeros(he.n_vertices, dtype=np.float64)
        return he

    def ring_tags(self, rings, nring, faces, nfaces, n_rule=4):
        """The tags of walked rings as rows of floats: per face slot ``(i, t)`` the sharpness of
        edge ``t`` of ring face ``i`` when it touches one of the first ``n_rule`` ring vertices
        (0 otherwise, and for boundary edges), then the vertex sharpness of those vertices. Rings
        with equal faces have equal keys (:func:`ccproof.evaluate.local.ring_key`) exactly when
        these rows are equal.

        Parameters
        ----------
        rings : ndarray of int32, shape (k, maxn)
        nring : ndarray of int64, shape (k,)
            Negative for a ring the walk gave up on (its row is zeros).
        faces : ndarray of int64, shape (k, maxf, 4)
            Local labels.
        nfaces : ndarray of int64, shape (k,)

        Returns
        -------
        ndarray of float64, shape (k, 4 f + n_rule)
            ``f``: the most faces of a ring in the block (at most ``maxf``).
        """
        ok = nring >= 0
        faces = faces[:, :max(int(np.where(ok, nfaces, 0).max(initial=0)), 1)]  # the slots some ring uses
        k, maxf = faces.shape[0], faces.shape[1]
        a = faces
        b = np.roll(faces, -1, axis=2)
        live = (np.arange(maxf)[None, :] < np.where(ok, nfaces, 0)[:, None])[:, :, None]
        rule = live & ((a < n_rule) | (b < n_rule))
        rows = np.arange(k)[:, None, None]
        ga = rings[rows, np.clip(a, 0, rings.shape[1] - 1)].astype(np.int64)
        gb = rings[rows, np.clip(b, 0, rings.shape[1] - 1)].astype(np.int64)
        out = np.zeros((k, 4 * maxf + n_rule), dtype=np.float64)
        if self.edge_keys.size:
            ek = np.minimum(ga, gb) * self.n_vertices + np.maximum(ga, gb)
            i = np.minimum(np.searchsorted(self.edge_keys, ek), self.edge_keys.size - 1)
            hit = rule & (self.edge_keys[i] == ek)
            out[:, :4 * maxf] = np.where(hit, self.edge_values[i], 0.0).reshape(k, -1)
        v = rings[:, :n_rule].astype(np.int64)
        out[:, 4 * maxf:] = np.where(ok[:, None] & (v >= 0), self.vertex_values[np.maximum(v, 0)], 0.0)
        return out


class _ComplexView:
    """A :class:`~ccproof.mesh.halfedges.HalfEdges` read through the part of the interface of
    :class:`ccproof.mesh.rules.Complex` that :func:`ccproof.evaluate.local.canonical_ring` and
    :func:`ccproof.evaluate.local.ring_key` use (``org``, ``nxt``, ``prv``, ``twin``, ``face_of``,
    ``start``, ``len(faces[f])``, ``edges``, ``edge_index``, ``edge_sharpness.get``,
    ``vertex_sharpness.get``, ``options``), in the mesh's own labels.

    No copy and no Python object per face or half-edge: the arrays are read through memoryviews
    (Python ints and floats at the speed of list indexing), an edge or a tag is found by bisection
    in the sorted edge keys (``a * n + b``) and tag keys. Twins are the mesh's (across manifold
    edges), the tags its tag arrays (sharpness ``inf`` from 10 on, as the keys hold it).
    """

    def __init__(self, he):
        def mv(a):
            return memoryview(np.ascontiguousarray(a))

        self.org, self.nxt, self.prv, self.twin = mv(he.org), mv(he.nxt), mv(he.prv), mv(he.twin)
        self.face_of, self.start = mv(he.face_of), mv(he.start)
        self.faces = _FaceSizes(mv(he.sizes))
        self.edges = mv(he.edge_halfedge)
        n = he.n_vertices
        self.edge_index = _Sorted(mv(he.edges[:, 0] * n + he.edges[:, 1]), None, n)
        self.edge_sharpness = _Sorted(mv(he.edge_keys), mv(he.edge_values), n)
        self.vertex_sharpness = _VertexTags(None if he.vertex_values is None else mv(he.vertex_values))
        self.options = he.options
        self.n_vertices = n


class _FaceSizes:
    """``len(faces[f])``: the size of face f (a range of that length)."""

    def __init__(self, sizes):
        self._s = sizes

    def __getitem__(self, f):
        return range(self._s[f])

    def __len__(self):
        return len(self._s)


class _Sorted:
    """A mapping ``(a, b) -> value`` (``a < b``) over sorted keys ``a * n + b``: ``values[i]``, or the
    index ``i`` itself when ``values`` is None (an edge's id)."""

    def __init__(self, keys, values, n):
        self._k, self._v, self._n = keys, values, n

    def _find(self, ab):
        k = ab[0] * self._n + ab[1]
        i = bisect.bisect_left(self._k, k)
        return i if i < len(self._k) and self._k[i] == k else -1

    def __getitem__(self, ab):
        i = self._find(ab)
        if i < 0:
            raise KeyError(ab)
        return i if self._v is None else self._v[i]

    def __contains__(self, ab):
        return self._find(ab) >= 0

    def __len__(self):
        return len(self._k)

    def get(self, ab, default=None):
        i = self._find(ab)
        return default if i < 0 else (i if self._v is None else self._v[i])


class _VertexTags:
    """``get(v, default)``: the vertex sharpness of v (``default`` where 0 or untagged)."""

    def __init__(self, values):
        self._v = values

    def get(self, v, default=None):
        if self._v is None:
            return default
        s = self._v[v]
        return s if s > 0.0 else default


def _row_hash(a):
    """An int64 hash of every row of a 2-d array: each 8-byte word salted with its column and mixed by
    splitmix64's finalizer (float tags differ in their high bits), the words' mixes summed per row."""
    w = np.ascontiguousarray(a).view(np.uint64).reshape(a.shape[0], -1)
    c1, c2, c3 = np.uint64(0xBF58476D1CE4E5B9), np.uint64(0x94D049BB133111EB), np.uint64(0x9E3779B97F4A7C15)
    with np.errstate(over="ignore"):
        z = w + (np.arange(1, w.shape[1] + 1, dtype=np.uint64) * c3)[None, :]
        z = (z ^ (z >> np.uint64(30))) * c1
        z = (z ^ (z >> np.uint64(27))) * c2
        z ^= z >> np.uint64(31)
        return z.sum(axis=1, dtype=np.uint64).view(np.int64)


class Builder:
    """Classifies the jobs of a mesh into templates; :meth:`table` assembles the patch table."""

    def __init__(self, depth_semi=1, what="face", progress=None):
        self.depth_semi = depth_semi  # ring depth refined in the semi-sharp phase (2: Chaikin)
        self.what = what  # how errors name a base face
        self.progress = progress
        self.templates = {}  # template key -> _Template
        self.configs = {}  # (id(scheme), orientation) -> index
        self.schemes = []  # per configuration (CornerScheme, orientation)
        self.n_jobs = 0
        self.job_base = array("q")

    def _config(self, key_r, orient):
        """The table's configuration index of the corner scheme of ``key_r`` in orientation ``orient``."""
        scheme = corner_scheme(key_r)
        ck = (id(scheme), orient)
        cfg = self.configs.get(ck)
        if cfg is None:
            cfg = self.configs[ck] = len(self.schemes)
            self.schemes.append((scheme, orient))
        return cfg

    # ------------------------------------------------------------------ jobs
    def _register(self, tkey, make, jobs, rings):
        t = self.templates.get(tkey)
        if t is None:
            t = self.templates[tkey] = _cached_template(tkey, self.depth_semi, make) \
                if tkey[0] != "smooth" else _finished(make())
            glob = [self._config(skey, orient) for skey, orient in t.schemes]
            t.cfg = [glob[c] if c >= 0 else -1 for c in t.cfg]  # the template's configurations: the table's
        if isinstance(jobs, np.ndarray):  # whole blocks of jobs: as bytes (extend would iterate in Python)
            t.jobs.frombytes(np.ascontiguousarray(jobs, dtype=np.int64).tobytes())
        else:
            t.jobs.extend(jobs)
        if isinstance(rings, np.ndarray):
            t.rings.frombytes(np.ascontiguousarray(rings, dtype=np.intc).tobytes())
        else:
            t.rings.extend(rings)

    def classify(self, he, X, jobs, vmap=None):
        """Classify the quads ``jobs`` (``[(g, frame, base), ...]`` or :class:`Jobs`) of the mesh with
        half-edges ``he`` (:class:`~ccproof.mesh.halfedges.HalfEdges`; a :class:`TaggedHalfEdges` for
        the tagged walk: its tags enter the rings' keys) with positions ``X``; job ids are assigned in
        order. ``vmap``: the mesh vertex of every vertex of ``he`` (records where the corner faces'
        vertices are, for the vertex normals).

        The smooth regular ones (:meth:`smooth_regular_patches`) in one vectorized pass, the others
        by their rings: a quad with three smooth regular corners is first tried as a corner face at
        the fourth (:meth:`corner_at`), anything else reads its ring from corner 0 (:meth:`face`).
        The rings of an all-quad mesh are walked by the compiled kernel where it is there
        (:meth:`_walk_all`), else face by face on the mesh read as a complex (:class:`_ComplexView`).
        """
        jobs = Jobs.of(jobs)
        self.X = X
        self.vmap = vmap
        j0 = self.n_jobs
        self.n_jobs += len(jobs)
        self.job_base.extend(jobs.base.tolist())
        if not len(jobs):
            return
        ok = _smooth_regular_vertices(he)
        done = np.asarray(self.smooth_regular_patches(he, X, jobs), dtype=bool)
        g = jobs.g
        start = np.append(he.start, he.org.size)
        org = he.org
        quad = start[g + 1] - start[g] == 4
        corners = ok[org[np.minimum(start[g][:, None] + np.arange(4), org.size - 1)]]
        single = np.where(quad & (corners.sum(axis=1) == 3), np.argmin(corners, axis=1), -1)
        todo = np.flatnonzero(~done)
        tagged = isinstance(he, TaggedHalfEdges)
        walkable = he.edge_manifold and bool((he.sizes == 4).all()) and (todo.size or not tagged)
        if walkable and _ring_walks(todo.size) is not None:
            return self._walk_all(he, jobs, j0, todo, single[todo])
        self._python_walk(he, jobs, j0, todo, single[todo])

    def _python_walk(self, he, jobs, j0, todo, single, view=None):
        """Register the jobs ``todo`` (``single``: the one irregular corner of each, or -1) face by face:
        :meth:`corner_at` or :meth:`face` on the mesh read as a complex (:class:`_ComplexView`)."""
        cx = _ComplexView(he) if view is None else view
        bar = _progress(self.progress, todo.size, "patch table")
        for n, (i, r) in enumerate(zip(todo.tolist(), single.tolist())):
            g_, frame, base = jobs[i]
            if not (r >= 0 and self.corner_at(cx, self.X, g_, r, frame, base, j0 + i, self.vmap)):
                self.face(cx, self.X, g_, frame, base, j0 + i, self.vmap)
            if n % 256 == 255:
                bar.update(256)
        bar.close()

    def _walk_all(self, he, jobs, j0, todo, single):
        """Register the jobs ``todo`` (``single``: the one irregular corner of each, or -1) of an
        all-quad mesh (:class:`~ccproof.mesh.halfedges.HalfEdges`, or :class:`TaggedHalfEdges`): their
        rings walked by the compiled kernel (:func:`ccproof.evaluate._numba_kernel.ring_walks`, the walk
        of :func:`ccproof.evaluate.local.canonical_ring`), grouped by the hash of their faces and of
        their tags (:meth:`TaggedHalfEdges.ring_tags`), each group checked face by face and tag by
        tag against its first ring and registered with the key of that ring
        (:func:`ccproof.evaluate.local.ring_key` on the mesh read as a complex, :class:`_ComplexView`;
        untagged: the faces and the options). Rings the walk cannot classify
        (beyond its arrays; a semi-sharp ring that needs the Chaikin two-ring) take the Python walk."""
        walks = _ring_walks(todo.size)
        opts = he.options.key()
        view = _ComplexView(he) if isinstance(he, TaggedHalfEdges) else None  # (keys of tagged rings)
        pos = np.full(he.n_vertices, -1, dtype=np.int64)
        seen = np.zeros(he.n_faces, dtype=np.bool_)
        bar = _progress(self.progress, todo.size, "patch table")
        step = 1 << 15
        fallback = []
        for lo in range(0, todo.size, step):
            idx = todo[lo:lo + step]
            r0 = single[lo:lo + step]
            retry, fb = self._walk_block(he, walks, pos, seen, jobs, j0, idx, np.maximum(r0, 0), r0 >= 0, opts, view)
            fallback.append(fb)
            if retry.size:  # corner candidates that are not corner faces: from corner 0
                fallback.append(self._walk_block(he, walks, pos, seen, jobs, j0, retry, np.zeros(retry.size, np.int64),
                                                 np.zeros(retry.size, bool), opts, view)[1])
            bar.update(idx.size)
        bar.close()
        fallback = np.concatenate(fallback) if fallback else np.zeros(0, dtype=np.int64)
        if fallback.size:
            where = {int(i): n for n, i in enumerate(todo.tolist())}
            self._python_walk(he, jobs, j0, fallback, single[[where[i] for i in fallback.tolist()]], view)

    def _walk_block(self, he, walks, pos, seen, jobs, j0, idx, r, at_corner, opts, view=None, maxn=64, maxf=48):
        k = idx.size
        rings = np.full((k, maxn), -1, dtype=np.int32)
        faces = np.zeros((k, maxf, 4), dtype=np.int64)
        nring = np.empty(k, dtype=np.int64)
        nfaces = np.empty(k, dtype=np.int64)
        hashes = np.empty(k, dtype=np.uint64)
        walks(he.org, he.nxt, he.prv, he.twin, pos, seen, jobs.g[idx], r, rings, nring, faces, nfaces, hashes)
        fallback = [idx[nring < 0]]  # a ring beyond the arrays (a valence above ~25): the Python walk
        tagged = isinstance(he, TaggedHalfEdges)
        cols = [hashes.view(np.int64), r + 4 * at_corner + 8 * jobs.fid[idx]]
        if tagged:
            tv = he.ring_tags(rings, nring, faces, nfaces)
            cols.append(_row_hash(tv))
        sig = np.stack(cols, axis=1)
        sig[nring < 0] = -1
        _, first, inv = np.unique(sig, axis=0, return_index=True, return_inverse=True)
        inv = inv.reshape(-1)
        order = np.argsort(inv, kind="stable")
        bounds = np.searchsorted(inv[order], np.arange(first.size + 1))
        retry = []
        for gi in range(first.size):
            mem = order[bounds[gi]:bounds[gi + 1]]
            rep = first[gi]
            if nring[rep] < 0:
                continue
            nf, n = int(nfaces[rep]), int(nring[rep])
            same = (nfaces[mem] == nf) & (nring[mem] == n) & (faces[mem, :nf] == faces[rep, :nf]).all(axis=(1, 2))
            if tagged:
                same &= (tv[mem] == tv[rep]).all(axis=1)
            if not same.all():  # a hash collision: those jobs by the Python walk
                fallback.append(idx[mem[~same]])
                mem = mem[same]
            ftup = tuple(map(tuple, faces[rep, :nf].tolist()))
            if tagged:
                key = ring_key(view, rings[rep, :n].tolist(), ftup, 4)
            else:
                key = (ftup, (), (), opts)
            if tagged and self.depth_semi != 1 and has_semi_sharp(key) and not at_corner[rep]:
                fallback.append(idx[mem])  # the Chaikin phase reads the two-ring: the Python walk
                continue
            frame = jobs.frames[jobs.fid[idx[rep]]]
            base = int(jobs.base[idx[rep]])
            rr = int(r[rep])
            if at_corner[rep]:
                if not self._corner_ok(key):
                    retry.append(idx[mem])
                    continue
                tkey, make = ("corner", key, rr, frame), functools.partial(self._corner_template, key, rr, frame, base)
            else:
                tkey, make = ("face", key, frame), functools.partial(self._face_template, key, frame, base)
            self._register(tkey, make, j0 + idx[mem], rings[mem, :n].ravel())
        return (np.concatenate(retry) if retry else np.zeros(0, dtype=np.int64)), np.concatenate(fallback)

    def smooth_regular_patches(self, cx, X, jobs):
        """Register the quads of ``jobs`` whose four vertices are smooth regular as bicubic patches.

        Smooth regular (:func:`_smooth_regular_vertices`): four faces around the vertex, no
        boundary, sharp edge or vertex sharpness at it. Such a face's tagged one-ring has no tags
        and no irregular corner, and its net (:func:`ccproof.evaluate.local.regular_net`) is its
        4 x 4 grid of vertices: gathered here for all of them at once with the half-edge arrays (the
        same walks as :func:`ccproof.evaluate.local.regular_net`); the grid, in the base
        orientation, is the job's ring. Returns a bool array, True for the jobs handled.
        """
        if not jobs:
            return np.zeros(0, dtype=bool)
        jobs = Jobs.of(jobs)
        org, nxt, prv, twin = cx.org, cx.nxt, cx.prv, cx.twin
        ok = _smooth_regular_vertices(cx)
        g = jobs.g
        start = np.append(cx.start, org.size)
        H = start[g][:, None] + np.arange(4)
        sel = (start[g + 1] - start[g] == 4) & ok[org[np.minimum(H, org.size - 1)]].all(axis=1)
        idx = np.flatnonzero(sel)
        if idx.size == 0:
            return sel
        H = H[idx]
        grid = np.empty((idx.size, 16), dtype=np.int64)
        for s_ in range(4):
            h = H[:, s_]
            t = twin[h]
            cell = [p[0] + 4 * p[1] for p in (CENTER[s_],) + SIDES[s_][:3]]
            grid[:, cell[0]] = org[h]
            grid[:, cell[1]] = org[nxt[nxt[t]]]
            grid[:, cell[2]] = org[prv[t]]
            grid[:, cell[3]] = org[prv[twin[nxt[t]]]]
        fid = jobs.fid[idx]
        j0 = self.n_jobs - len(jobs)
        for k, f in enumerate(jobs.frames):
            rows = np.flatnonzero(fid == k)
            if rows.size:
                ring = grid[rows][:, _net_permutation(f)]  # the grid in the base orientation
                self._register(("smooth", f), functools.partial(_smooth_template, f), j0 + idx[rows],
                               ring.astype(np.int32).ravel())
        return sel

    def corner_at(self, cx, X, g, r, frame, base, job, vmap=None):
        """Register quad ``g`` of ``cx`` (a :class:`_ComplexView` of the mesh, or a complex) as a corner
        face at corner ``r`` if that is its classification (its other corners regular, its ring from
        ``r`` stationary), with its ring listed from ``r`` (the tags of a ring, hence the semi-sharp
        test, do not depend on the corner it is listed from). Returns True if registered."""
        ring_r, faces_r, nr = canonical_ring(cx, g, r)
        key_r = ring_key(cx, ring_r, faces_r, nr)
        if not self._corner_ok(key_r):
            return False
        self._register(("corner", key_r, r, frame), functools.partial(self._corner_template, key_r, r, frame, base),
                       (job,), ring_r)
        return True

    def face(self, cx, X, g, frame, base, job, vmap=None):
        """Register quad ``g`` of ``cx`` (as in :meth:`corner_at`) with its ring read from corner 0 (the
        two-ring when the Chaikin semi-sharp phase needs it), building its template on first use
        (:meth:`_face_template`)."""
        ring, faces, nr = canonical_ring(cx, g, 0, 1)
        key = ring_key(cx, ring, faces, nr)
        if self.depth_semi != 1 and has_semi_sharp(key):
            ring, faces, nr = canonical_ring(cx, g, 0, self.depth_semi)
            key = ring_key(cx, ring, faces, nr)
        self._register(("face", key, frame), functools.partial(self._face_template, key, frame, base), (job,), ring)

    @staticmethod
    def _corner_ok(key_r):
        """Whether a ring read from a face's corner makes the face a corner face at that corner."""
        if has_semi_sharp(key_r) or irregular_corners(key_r) != (0,):
            return False
        return corner_scheme(key_r) is not None

    def _corner_template(self, key_r, r, frame, base):
        N = key_complex(key_r).n_vertices
        t = _Template(N)
        root = t.new_vface(KIND_REGULAR, frame)
        self.scheme_face(t, key_r, np.eye(N), list(range(N)), r, frame, base, root, np.arange(N))
        return t

    def _face_template(self, key, frame, base):
        """The template of a face whose ring (read from corner 0) has the tagged key ``key``: the
        classification run on the key's own complex (the ring in canonical labels: the same walks
        read the same rings) with the identity as control points."""
        kc = key_complex(key)
        N = kc.n_vertices
        depth = 1 if self.depth_semi == 1 or len(key[0]) == len(canonical_ring(kc, 0, 0, 1)[1]) else self.depth_semi
        ring, faces, _ = canonical_ring(kc, 0, 0, depth)
        if faces != key[0] or ring != list(range(N)):  # pragma: no cover - the premise of the key caches
            raise MeshError(f"internal error: the ring of {self.what} {base} is not read back from its key")
        t = _Template(N)
        root = t.new_vface(KIND_REGULAR, frame)
        self._face(t, kc, np.eye(N), 0, frame, 0, 0, base, root, vmap=np.arange(N))
        return t

    # ------------------------------------------------------------------ template building
    def _face(self, t, cx, X, g, frame, depth, semi_depth, base, vid, src=None, vmap=None):
        """Classify quad ``g`` of complex ``cx`` with positions ``X`` (NaN where not exact) into
        virtual face ``vid`` of template ``t``.

        ``src = (key, n_rule)``: ``cx`` is the child complex of that ring (its rings are cached).
        ``vmap``: ring position of every vertex of ``cx`` (-1 for new points).
        """

        def ring_of(r, depth_):
            if src is not None:
                return child_ring(src[0], src[1], g, r, depth_)
            ring_, faces_, nr_ = canonical_ring(cx, g, r, depth_)
            return ring_, ring_key(cx, ring_, faces_, nr_), nr_

        ring, key, nr = ring_of(0, 1)
        if has_semi_sharp(key):
            if semi_depth >= MAX_SEMI_DEPTH:
                raise MeshError(f"{self.what} {base}: semi-sharp creases did not decay in {MAX_SEMI_DEPTH} levels")
            D = self.depth_semi
            if D != 1:
                ring, key, nr = ring_of(0, D)
            return self.split_face(t, key, nr, X[ring], frame, depth, semi_depth + 1, base, vid, vmap[ring])
        irr = irregular_corners(key)
        if not irr:
            M = regular_net_matrix(key)
            Xl = X[ring]
            origin = Xl.mean(axis=0)
            op = np.empty((17, Xl.shape[1]))
            op[:16] = (M @ (Xl - origin))[_net_permutation(frame)]
            op[16] = origin
            t.kind[vid] = KIND_REGULAR
            t.leaf[vid] = len(t.reg)
            t.reg.append(op)
            return vid
        if len(irr) == 1:
            r = irr[0]
            ring_r, key_r, _ = ring_of(r, 1)
            if corner_scheme(key_r) is not None:
                return self.scheme_face(t, key_r, X, ring_r, r, frame, base, vid, vmap)
        if depth >= MAX_DEPTH:
            raise MeshError(
                f"{self.what} {base}: the configuration around it is not supported "
                f"(still irregular after {MAX_DEPTH} local subdivisions)"
            )
        return self.split_face(t, key, nr, X[ring], frame, depth + 1, semi_depth, base, vid, vmap[ring])

    def scheme_face(self, t, key_r, X, ring_r, r, frame, base, vid, vmap):
        """Virtual face ``vid`` of ``t`` is a corner face of the scheme of ``key_r``
        (:func:`ccproof.evaluate.local.corner_scheme`) at its corner ``r``, ring ``X[ring_r]``
        (listed from that corner)."""
        scheme = corner_scheme(key_r)
        C = X[ring_r]
        rot = compose(frame, _corner_frame(r))
        orient = (_sign(rot[1]), _sign(rot[2]))
        src = (key_r, orient)
        cfg = t.schemes.index(src) if src in t.schemes else len(t.schemes)
        if cfg == len(t.schemes):
            t.schemes.append(src)
        t.kind[vid] = KIND_CORNER
        U0, V0, H = t.dom[vid]
        corner = rot[0]
        t.corner[vid] = (int(corner[0] > U0), int(corner[1] > V0))
        rel = C - C[0]
        op = np.empty((C.shape[0], C.shape[1]))  # row 0 of the relative ring is 0: not stored
        op[:-1] = rel[1:]
        op[-1] = C[0] + scheme.limit_mask @ rel
        t.leaf[vid] = len(t.cor)
        t.pts[vid] = t.n_pts
        t.cfg[vid] = cfg
        t.n_pts += C.shape[0] - 1
        t.cor.append(op)
        t.cor_vertex.append(int(vmap[ring_r[0]]))
        return vid

    def split_face(self, t, key, nr, Xr, frame, depth, semi_depth, base, vid, vmap):
        """Subdivide the ring ``key`` (positions ``Xr``) once, exactly and locally; classify the
        four children of its face 0 into new virtual faces of ``t``.

        Only the points whose stencils lie inside the ring are exact (the rules at its ``nr`` rule
        vertices, :func:`ccproof.evaluate.local.refine_key`); the others are NaN, so that any use
        would show up in the checks of the tables instead of passing silently. ``vmap``: the ring
        position of every ring vertex (vertex points keep their vertex).
        """
        S, _, child = refine_key(key, nr)
        X1 = S @ Xr
        vmap1 = np.full(S.shape[0], -1, dtype=np.int64)
        vmap1[: len(vmap)] = vmap
        t.kind[vid] = KIND_SPLIT
        U0, V0, _ = t.dom[vid]
        for i in range(4):
            cf = compose(frame, child_frame(i))
            cu, cv, _ = domain(cf)
            q = int(cu > U0) + 2 * int(cv > V0)
            c = t.new_vface(KIND_REGULAR, cf)
            t.child[vid][q] = c
            self._face(t, child, X1, i, cf, depth, semi_depth, base, c, src=(key, nr), vmap=vmap1)
        return vid

    # ------------------------------------------------------------------ assembly
    def _configuration_ops(self):
        """Per configuration its layer operators, flat (layer, code, j, i), their offsets in the
        concatenation, its ring size Nc, its number of layers, its layer-0 domains ``unit``."""
        ops, op_start, op_size, n_layers, unit = [], [], [], [], []
        off = 0
        for scheme, orient in self.schemes:
            L, u = _oriented_layers(scheme, orient)
            nl_, nc_ = scheme.n_layers, L.shape[1]
            ops.append(L.reshape(nl_ * 3, 16, nc_).transpose(0, 2, 1).reshape(-1))  # (layer, code, j, i)
            op_start.append(off)
            op_size.append(L.shape[1])
            n_layers.append(scheme.n_layers)
            unit.append(u)
            off += L.size
        return ops, op_start, op_size, n_layers, unit

    def table(self, top, refused):
        """The :class:`PatchTable` (floats from the positions given to :meth:`classify`), and the
        template groups ``[(template, jobs, rings)]`` (:func:`with_nets`; ``rings``
        views of the table's ``rings``)."""
        temps = list(self.templates.values())
        J = self.n_jobs
        job_root = np.full(J, -1, dtype=np.int64)
        job_net = np.zeros(J, dtype=np.int64)
        job_corner = np.zeros(J, dtype=np.int64)
        job_ring = np.zeros(J, dtype=np.int64)
        kind, child, dom, leaf, cfg, corner, vop_start, vn, vop = [], [], [], [], [], [], [], [], []
        n_tv = n_reg = n_cor = n_ring = n_vop = 0
        groups = []
        depth = 0
        ops, op_start, op_size, n_layers, unit = self._configuration_ops()
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
            for ops_ in _leaf_operators(t, ops):
                vop_start.append(n_vop if ops_ is not None else -1)
                vn.append(t.n)
                if ops_ is not None:
                    vop.append(ops_.reshape(-1))
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
        X = np.ascontiguousarray(self.X, dtype=np.float64)
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
            vop=np.concatenate(vop) if vop else np.zeros(0), split_depth=depth, n_regular=n_reg, n_corner=n_cor,
            points=X, rings=rings_flat, nets=np.zeros((0, 17, 3)),
            ops=np.concatenate(ops) if ops else np.zeros(0), op_start=np.array(op_start, dtype=np.int64),
            op_size=np.array(op_size, dtype=np.int64), n_layers=np.array(n_layers, dtype=np.int64),
            unit=np.array(unit, dtype=np.float64).reshape(-1, 3, 3), hot=np.zeros((0, 17, 3)),
            cor_ring=np.zeros(0, np.int64), ring=np.zeros((0, 3)))
        return with_nets(T, groups), groups


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


def with_nets(T, groups):
    """``T`` with the precomputed nets that fit their budgets: the regular nets (:data:`NETS_BUDGET`, or the
    environment variable ``CCPROOF_NETS_BUDGET`` in bytes) and the layer-0 corner nets (:data:`HOT_BUDGET`,
    ``CCPROOF_HOT_BUDGET``), both by the kernels' sums (none where they do not fit: the same bits)."""
    n_cor = T.n_corner
    if 0 < T.n_regular and T.n_regular * 17 * 3 * 8 <= _budget("CCPROOF_NETS_BUDGET", NETS_BUDGET):
        T = T._replace(nets=regular_nets(T, groups))
    if 0 < n_cor and n_cor * 3 * 17 * 3 * 8 <= _budget("CCPROOF_HOT_BUDGET", HOT_BUDGET):
        T = T._replace(hot=layer0_nets(T, groups))
    return kept_rings(T, groups)


def kept_rings(T, groups):
    """``T`` with the rings of its corner faces with at least :data:`KEEP_RING_NC` points kept
    (:attr:`PatchTable.ring`, by :func:`corner_rings`: the kernels' sums), or ``T`` where there are none."""
    parts, off = [], 0
    cor_ring = None
    for t, jobs, _ in groups:
        if not jobs.size:
            continue
        root = int(T.job_root[jobs[0]])
        for vf, kind in enumerate(t.kind):
            g = root + vf
            if kind != KIND_CORNER or T.op_size[T.cfg[g]] < KEEP_RING_NC:
                continue
            if cor_ring is None:
                cor_ring = np.full(T.n_corner, -1, dtype=np.int64)
            m = int(T.op_size[T.cfg[g]]) - 1
            for lo in range(0, jobs.size, _BLOCK):
                jb = jobs[lo:lo + _BLOCK]
                parts.append(corner_rings(T, jb, g)[:, 1:].reshape(-1, 3))
                cor_ring[T.job_corner[jb] + t.leaf[vf]] = off + m * np.arange(jb.size)
                off += m * jb.size
    if cor_ring is None:
        return T
    return T._replace(cor_ring=cor_ring, ring=np.concatenate(parts))


def _budget(name, default):
    """The byte budget in the environment variable ``name`` (a non-negative integer), else ``default``.

    >>> _budget("CCPROOF_NO_SUCH_BUDGET", 7)
    7
    """
    import os

    v = os.environ.get(name)
    if v is None or v == "":
        return default
    try:
        b = int(v)
    except ValueError:
        b = -1
    if b < 0:
        raise MeshError(f"{name}={v!r}: a budget in bytes, a non-negative integer")
    return b


def _smooth_template(frame):
    """The template of a smooth regular quad: its ring is its 4 x 4 grid in the base orientation."""
    t = _Template(16)
    t.new_vface(KIND_REGULAR, frame)
    op = np.empty((17, 16))
    op[:16] = np.eye(16) - 1.0 / 16
    op[16] = 1.0 / 16
    t.leaf[0] = 0
    t.reg.append(op)
    t.smooth_grid = np.argsort(_net_permutation(frame))  # ring[:, smooth_grid]: the grid as walked
    return t


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


def ring_products(op, X, rings):
    """``op`` (N, r) applied to the rings (k, N) of positions ``X``, the kernels' sums: per ring
    ``sum_j op[j] * (X[ring[j]] - X[ring[0]])`` over j = 1, 2, ... in order from 0.0. Shape (k, r, 3).

    >>> X = np.array([[0.0, 0, 0], [1, 0, 0], [0, 2, 0]])
    >>> ring_products(np.array([[9.0], [1.0], [0.5]]), X, np.array([[0, 1, 2]]))[0].tolist()
    [[1.0, 1.0, 0.0]]
    """
    X0 = X[rings[:, 0]]
    acc = np.zeros((rings.shape[0], op.shape[1], 3))
    for j in range(1, op.shape[0]):
        acc += op[j][None, :, None] * (X[rings[:, j]] - X0)[:, None, :]
    return acc


def regular_nets(T, groups):
    """The nets of every regular patch of table ``T`` (:attr:`PatchTable.nets`), computed as the kernels
    compute them (:func:`ring_products` of the leaf's operator, row 16 plus the ring's point 0)."""
    nets = np.empty((T.n_regular, 17, 3))
    X = T.points
    for t, jobs, rings in groups:
        if not jobs.size:
            continue
        root = int(T.job_root[jobs[0]])
        for vf, kind in enumerate(t.kind):
            if kind != KIND_REGULAR:
                continue
            g = root + vf
            st, N = int(T.vop_start[g]), int(T.vn[g])
            for lo in range(0, jobs.size, _BLOCK):
                R = rings[lo:lo + _BLOCK]
                a = ring_products(T.vop[st:st + 17 * N].reshape(N, 17), X, R)
                a[:, 16] += X[R[:, 0]]
                nets[T.job_net[jobs[lo:lo + _BLOCK]] + t.leaf[vf]] = a
    return nets


def composed_nets(T, jobs, vf, lay, code=None):
    """The nets (k, 17, 3) of patch ``code`` of layer ``lay`` < :data:`COMPOSED_LAYERS` of the corner face
    ``vf`` of ``jobs`` (k,): :func:`ring_products` of the composed operator, row 16 the limit point. ``code``
    None: the three patch codes at once, shape (k, 3, 17, 3), their operators side by side in one product (each
    entry's sum the same, in the same order)."""
    N, st, Nc = int(T.vn[vf]), int(T.vop_start[vf]), int(T.op_size[T.cfg[vf]])
    codes = 3 if code is None else 1
    st += N * (Nc - 1) + N + (3 * lay + (0 if code is None else code)) * N * 16
    op = T.vop[st:st + codes * N * 16].reshape(codes, N, 16).transpose(1, 0, 2).reshape(N, codes * 16)
    R = T.rings[T.job_ring[jobs][:, None] + np.arange(N)]
    out = np.empty((R.shape[0], codes, 17, 3))
    out[:, :, :16] = ring_products(op, T.points, R).reshape(-1, codes, 16, 3)
    out[:, :, 16] = corner_limits(T, jobs, vf)[:, None, :]
    return out if code is None else out[:, 0]


def corner_limits(T, jobs, vf):
    """The limit points (k, 3) at the irregular corner of the corner face ``vf`` of ``jobs`` (k,), computed
    as the kernels compute them (:func:`ring_products` of its operator row, plus the ring's point 0)."""
    N, st, Nc = int(T.vn[vf]), int(T.vop_start[vf]), int(T.op_size[T.cfg[vf]])
    st += N * (Nc - 1)
    R = T.rings[T.job_ring[jobs][:, None] + np.arange(N)]
    return ring_products(T.vop[st:st + N].reshape(N, 1), T.points, R)[:, 0] + T.points[R[:, 0]]


def corner_rings(T, jobs, vf):
    """The rings (k, Nc, 3) relative to their corner vertex (row 0 zero) of the corner face ``vf`` (a
    virtual face of the table ``T``) of ``jobs`` (k,), computed as the kernels compute them."""
    N, st, Nc = int(T.vn[vf]), int(T.vop_start[vf]), int(T.op_size[T.cfg[vf]])
    R = T.rings[T.job_ring[jobs][:, None] + np.arange(N)]
    out = np.zeros((R.shape[0], Nc, 3))
    op = T.vop[st:st + N * (Nc - 1)].reshape(N, Nc - 1)
    parts = _sparse_parts(op) if N >= 256 and Nc >= 256 else None
    if parts is None:
        out[:, 1:] = ring_products(op, T.points, R)
    else:  # an n-gon centre's ring: linear in n, the same sums but in another order (rounding ~1e-16)
        S, m = parts
        D = T.points[R] - T.points[R[:, :1]]  # (k, N, 3)
        for c in range(3):
            out[:, 1:, c] = (S.T @ D[:, :, c].T).T + (D[:, :, c] @ m)[:, None]
    return out


def _sparse_parts(op):
    """``(S, m)`` with ``op = S + m 1^T`` (``m`` the row medians: the part every output shares, as the centre
    of an n-gon's ring is in every point relative to the corner), ``S`` sparse (at most 10 % entries), or None."""
    import scipy.sparse

    m = np.median(op, axis=1)
    S = op - m[:, None]
    if np.count_nonzero(S) > 0.1 * S.size:
        return None
    return scipy.sparse.csr_matrix(S), m


def catmark_step(mesh):
    """One Catmull-Clark step of an untagged manifold polygon mesh, vectorized; None otherwise.

    The rules of :func:`ccproof.mesh.rules.refine_complex` for a mesh without tags, holes or
    non-default options (bmz04 Fig. 1, docs/readings.md R1; boundary edges infinitely sharp: edge
    midpoints and the crease rule ``(3/4) V + (1/8)(e0 + e1)`` at boundary vertices), in the layout of
    :meth:`ccproof.mesh.polymesh.PolyMesh.refine`: vertex points (n), edge points (E, edges numbered
    by first occurrence along the faces' corners), face points (m); child ``offsets[f] + i`` of face
    f is ``(v_i, edge point (v_i, v_i+1), face point, edge point (v_i-1, v_i))``. Evaluated from the
    face points (float weights of :mod:`ccproof.rule_weights`), not as stencils of the old vertices:
    the same values to round-off. This is the one step not built on
    :func:`ccproof.mesh.step.catmark_operator` (``S @ X``): assembling the operator costs the setup
    of a triangle mesh 2 to 27 % more (median 8 %; ``scripts/bench_step.py``); the same child faces and vertex
    numbering. The topology is the mesh's own (``mesh.halfedges``), not paired again.

    Parameters
    ----------
    mesh : PolyMesh

    Returns
    -------
    (X1, F1) or None
        ``X1`` (n + E + m, 3) float64, ``F1`` (sum of face sizes, 4) int64; None for a tagged mesh
        (creases, corners, holes, boundary mode "none", smooth triangle subdivision, a one-face
        boundary vertex under "edge_and_corner"), one with unused vertices, a non-manifold edge or a
        vertex with more than one boundary edge pair.
    """
    from ccproof.rule_weights import smooth_edge_weights

    opts = mesh.options
    if (mesh.edge_sharpness or mesh.vertex_sharpness or np.asarray(mesh.is_hole).any()
            or opts.triangle_subdivision != "catmark" or opts.boundary == "none"):
        return None
    X = np.asarray(mesh.vertices, dtype=np.float64)
    he = mesh.halfedges  # the mesh's own topology: no pairing of the half-edges again
    idx, sizes, off = he.org, he.sizes, he.start
    n, m = X.shape[0], sizes.size
    face, prv = he.face_of, he.prv
    org, dst = idx, idx[he.nxt]
    if not he.edge_manifold:  # a directed edge twice (non-manifold or misoriented), a face holding an edge twice
        return None
    first = he.edge_halfedge  # the first half-edge of every edge (edges sorted by their vertices)
    E = first.size
    order = np.argsort(first, kind="stable")  # edges by first occurrence along the faces' corners
    rank = np.empty(E, dtype=np.int64)
    rank[order] = np.arange(E)
    he_edge = rank[he.edge_of]  # edge id of every half-edge (first-occurrence order)
    count = he.edge_face_count[order]
    valence = np.bincount(org, minlength=n)  # faces (outgoing half-edges) at every vertex
    if (valence == 0).any():
        return None
    bnd_h = count[he_edge] == 1  # boundary half-edges
    nb_out = np.bincount(org[bnd_h], minlength=n)
    nb_in = np.bincount(dst[bnd_h], minlength=n)
    if (nb_out > 1).any() or (nb_in != nb_out).any():
        return None
    if opts.boundary == "edge_and_corner" and ((nb_out > 0) & (valence == 1)).any():
        return None  # a one-face corner: sharp from level 1 on (a tagged level-1 mesh)
    one = 1.0
    fp = np.add.reduceat(X[idx], off, axis=0) / sizes[:, None] if m else np.zeros((0, 3))
    # edge points
    h1 = first[order]  # the first half-edge of every edge, in edge order
    h2 = he.twin[h1]  # the other one (-1 on the boundary)
    a, b = org[h1], dst[h1]
    vw, fw = smooth_edge_weights(one)
    ep = 0.5 * (X[a] + X[b])
    inner = h2 >= 0
    ep[inner] = vw * (X[a[inner]] + X[b[inner]]) + fw * (fp[face[h1[inner]]] + fp[face[h2[inner]]])
    vp = _step_vertex_points(X, (org, dst, face), fp, valence, bnd_h, nb_out)
    X1 = np.concatenate([vp, ep, fp])
    F1 = np.stack([org, n + he_edge, n + E + face, n + he_edge[prv]], axis=1)
    return X1, F1


def _step_vertex_points(X, corners, fp, valence, bnd_h, nb_out):
    """The vertex points of :func:`catmark_step`: the smooth rule, the crease rule at the boundary vertices.
    ``corners`` = (origin, destination, face) of every half-edge, ``fp`` the face points, ``bnd_h`` the
    boundary half-edges, ``nb_out`` the boundary half-edges leaving every vertex."""
    from ccproof.rule_weights import crease_vertex_weights, smooth_vertex_weights

    org, dst, face = corners
    n, one = X.shape[0], 1.0
    vp = np.empty((n, 3))
    sum_e = np.stack([np.bincount(org, weights=X[dst, c], minlength=n) for c in range(3)], axis=1)
    sum_f = np.stack([np.bincount(org, weights=fp[face, c], minlength=n) for c in range(3)], axis=1)
    wv, we, wf = smooth_vertex_weights(valence, one)
    vp[:] = wv[:, None] * X + we[:, None] * sum_e + wf[:, None] * sum_f
    bv = np.flatnonzero(nb_out > 0)
    if bv.size:
        cw, ce = crease_vertex_weights(one)
        bn = np.zeros((n, 3))
        np.add.at(bn, org[bnd_h], X[dst[bnd_h]])
        np.add.at(bn, dst[bnd_h], X[org[bnd_h]])
        vp[bv] = cw * X[bv] + ce * bn[bv]
    return vp


def layer0_nets(T, groups):
    """The nets of layer 0 of every corner face of table ``T`` (see :attr:`PatchTable.hot`): per
    corner face c and patch code the composed operator's sums (:func:`composed_nets`, the compiled
    kernel's), row 16 the limit point. Shape (3 n_corner, 17, 3)."""
    hot = np.empty((3 * T.n_corner, 17, 3))
    for t, jobs, _ in groups:
        if jobs is None or not jobs.size or not t.O.shape[0]:
            continue
        root = int(T.job_root[jobs[0]])
        for vf, kind in enumerate(t.kind):
            if kind != KIND_CORNER:
                continue
            for lo in range(0, jobs.size, _BLOCK):
                jb = jobs[lo:lo + _BLOCK]
                ci = T.job_corner[jb] + t.leaf[vf]
                nets = composed_nets(T, jb, root + vf, 0)
                for code in range(3):
                    hot[3 * ci + code] = nets[:, code]
    return hot

