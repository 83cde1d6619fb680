"""The natural parameterization of a Catmull-Clark surface, evaluated exactly (bmz04 section 2, R12).

:func:`natural_limit_surface` turns a :class:`~ccproof.mesh.QuadMesh` into a :class:`LimitSurface` whose
:meth:`~LimitSurface.evaluate` returns positions and first and second derivatives at batches of
points ``(face, u, v)``, with respect to the face's own parameter (corner i of the face's vertex
list at (0,0), (1,0), (1,1), (0,1) for i = 0..3: the ptex convention of OpenSubdiv).

Method (everything below is exact up to floating-point round-off):

* A face whose four vertices are regular (interior valence 4, or boundary with two faces) is a
  bicubic uniform B-spline patch on its 4 x 4 net (boundary rows completed by ghost points
  ``2 B - I``, which reproduce the boundary curve rule; OpenSubdiv ``VTX_BOUNDARY_EDGE_ONLY``).
* A face with one irregular vertex (interior valence != 4, or boundary with a number of faces
  other than two) whose one-ring is self-similar is evaluated by self-similarity (Stam 1998, bmz04
  section 3 and Fig. 3): a point in layer n = floor(-log2 max(u, v)) (corner at the origin) lies in
  one of three regular sub-patches of level n + 1 whose nets are ``M_j A^n C`` (exact matrices of
  :func:`ccproof.evaluate.local.corner_scheme`, precomputed for every layer), derivatives scaled
  by 2^(n+1). Points closer to the corner than the last stored layer (where every net equals the
  limit point to 2^-60 of the one-ring's size) get the limit point and the derivatives of that layer.
* Any other face (several irregular vertices, or a one-ring that is not yet self-similar, e.g. an
  extraordinary vertex next to the boundary) is subdivided once, exactly and locally; its four
  children are classified again (at most ``MAX_DEPTH`` times; beyond that a MeshError).

At evaluation time a point is a gather of one precomputed 4 x 4 net plus one bicubic evaluation: no
Python loop over points, memory bounded by evaluating in chunks.
"""

from __future__ import annotations

import functools
import weakref

import numpy as np

from ccproof.errors import CCProofError, MeshError
from ccproof.evaluate.bspline import bspline_basis
from ccproof.evaluate.local import (
    _CENTER,
    _SIDES,
    CORNERS,
    _child_ring,
    _has_semi_sharp,
    _regular_net_matrix,
    canonical_ring,
    corner_scheme,
    irregular_corners,
    refine_key,
    ring_key,
)
from ccproof.mesh import QuadMesh, limit_normals, limit_positions
from ccproof.mesh.rules import Complex, Options

__all__ = ["natural_limit_surface", "LimitSurface"]

#: how many times a face may be subdivided before it must be regular or self-similar
MAX_DEPTH = 4
#: local subdivisions allowed in the semi-sharp phase of a tagged mesh (sharpness < 10 decays in
#: 10 uniform levels)
MAX_SEMI_DEPTH = 40
#: points evaluated per chunk (bounds the temporary memory: about 1 kB per point)
CHUNK = 1 << 15
#: layers of every corner table stored with the regular patches ("hot" region, for cache locality:
#: a uniformly random point lies in layer >= 3 of a corner face with probability 1/64)
HOT_LAYERS = 3

_REGULAR, _CORNER, _SPLIT = 0, 1, 2

_KEYS = {0: ("P",), 1: ("P", "Pu", "Pv"), 2: ("P", "Pu", "Pv", "Puu", "Puv", "Pvv")}


# ---------------------------------------------------------------------------------- frames
# A frame maps a face's own parameter (s, t) to the base face's (u, v): (u, v) = o + s a + t b,
# with a, b axis-aligned of the same length (a power of 2). Frames are tuples of three float pairs
# (o, a, b): they are composed once per virtual face, so plain floats (every value dyadic, every
# operation exact) instead of small arrays.
_C = tuple((float(x), float(y)) for x, y in CORNERS)


def _compose(frame, sub):
    (ox, oy), (ax, ay), (bx, by) = frame
    (p, q), (sa0, sa1), (sb0, sb1) = sub
    return ((ox + ax * p + bx * q, oy + ay * p + by * q), (ax * sa0 + bx * sa1, ay * sa0 + by * sa1),
            (ax * sb0 + bx * sb1, ay * sb0 + by * sb1))


def _corner_frame(i, scale=1.0):
    """Frame of the square at corner i of [0,1]^2, rotated so that corner i is its origin."""
    c, c1, c3 = _C[i], _C[(i + 1) % 4], _C[(i + 3) % 4]
    return (c, ((c1[0] - c[0]) * scale, (c1[1] - c[1]) * scale), ((c3[0] - c[0]) * scale, (c3[1] - c[1]) * scale))


def _child_frame(i):
    return _corner_frame(i, 0.5)


def _layer_frame(n, j):
    """Frame of patch P_j of layer n in the corner frame (corner at the origin), bmz04 Fig. 3."""
    h = 2.0 ** -(n + 1)
    o, a, b = _corner_frame(j, h)
    return ((o[0] * 2.0 * h, o[1] * 2.0 * h), a, b)


def _domain(frame):
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


#: rows x columns x 3 of one product in :func:`_skinny_product` (below OpenBLAS's threading
#: threshold of 4 * 65536 multiply-adds)
_SKINNY_BLOCK = 1 << 17


def _skinny_product(L, rel):
    """``L @ rel`` for a tall ``L`` (R, N) and ``rel`` (N, 3), in row blocks small enough for
    single-threaded BLAS: at setup these products are many and small, and waking BLAS threads for
    each costs more than the product (much more on a loaded machine). Same sums, same result."""
    R, N = L.shape
    step = max(1, _SKINNY_BLOCK // (rel.shape[1] * max(N, 1)))
    if R <= step:
        return L @ rel
    out = np.empty((R, rel.shape[1]))
    for lo in range(0, R, step):
        np.matmul(L[lo:lo + step], rel, out=out[lo:lo + step])
    return out


#: per corner scheme, its layer tables in every orientation of a corner frame (see _oriented_layers)
_ORIENTED = weakref.WeakKeyDictionary()


def _oriented_layers(scheme, rot):
    """The layer deviations of ``scheme`` laid out for a corner frame ``rot`` of any side and origin.

    Returns
    -------
    L : ndarray, shape (n_layers * 3 * 16, N)
        Row ``(n, code, i)``: entry ``i`` of the net of layer ``n``, patch ``code`` (0: the patch
        along u, 1: the diagonal one, 2: the one along v, bmz04 Fig. 3), in the base orientation.
    unit : ndarray, shape (n_layers, 3, 3)
        ``(u0, v0, h)`` of those patches for a corner frame of side 1 with the corner at the origin
        (dyadic: scaling by the side and shifting by the corner are exact).

    Depends on ``rot`` only through the directions of its axes; computed once per scheme and
    orientation.
    """
    orient = (_sign(rot[1]), _sign(rot[2]))
    per_scheme = _ORIENTED.setdefault(scheme, {})
    hit = per_scheme.get(orient)
    if hit is not None:
        return hit
    rows, unit0 = _corner_orientation(orient)
    Ls = scheme.layers
    nl, N = Ls.shape[0], Ls.shape[-1]
    L = np.take(Ls.reshape(nl, 48, N), rows, axis=1).reshape(-1, N)  # contiguous: the reshape is a view
    unit = unit0[None] * (0.5 ** np.arange(nl))[:, None, None]  # layer n: layer 0 scaled by 2^-n
    L.setflags(write=False)
    unit.setflags(write=False)
    per_scheme[orient] = (L, unit)
    return L, unit


@functools.lru_cache(maxsize=16)
def _corner_orientation(orient):
    """Rows of a scheme's layer nets and layer-0 domains for a corner frame with axis directions
    ``orient`` (see :func:`_oriented_layers`): ``rows`` (48,), row ``16 code + i`` of a layer in the
    base orientation is row ``rows[16 code + i]`` of its ``3 x 16`` nets ``D[n, j-1]``; ``unit``
    (3, 3), the domains of the three patches of layer 0 for a unit frame at the origin."""
    a, b = orient
    unit_rot = ((0.0, 0.0), (float(a[0]), float(a[1])), (float(b[0]), float(b[1])))
    # P_1 lies along the frame's a-axis: code 0 (u-distance >= 1/2, v-distance < 1/2) if a is
    # along u, else code 2; P_2 (diagonal) is code 1; P_3 the other one
    a_along_u = a[0] != 0
    codes = {1: 0 if a_along_u else 2, 2: 1, 3: 2 if a_along_u else 0}
    rows = np.empty(48, dtype=np.int64)
    unit = np.empty((3, 3))
    for j in (1, 2, 3):
        f0 = _compose(unit_rot, _layer_frame(0, j))
        rows[16 * codes[j]:16 * codes[j] + 16] = 16 * (j - 1) + _net_permutation(f0)
        unit[codes[j]] = _domain(f0)
    rows.setflags(write=False)
    unit.setflags(write=False)
    return rows, unit


def _smooth_regular_vertices(cx):
    """Bool (n_vertices,): the vertices of ``cx`` with four faces and no boundary edge, sharp edge
    or vertex sharpness (regular for the bicubic patch under any options)."""
    org, nxt, twin = (np.asarray(a, dtype=np.int64) for a in (cx.org, cx.nxt, cx.twin))
    ok = np.bincount(org, minlength=cx.n_vertices) == 4
    open_h = twin < 0
    ok[org[open_h]] = False
    ok[org[nxt[open_h]]] = False
    for (a, b), sh in cx.edge_sharpness.items():
        if sh > 0.0:
            ok[a] = ok[b] = False
    for v, sh in cx.vertex_sharpness.items():
        if sh > 0.0:
            ok[v] = False
    return ok


class _Builder:
    """Collects patches and virtual faces while classifying the faces of a mesh."""

    def __init__(self, depth_semi=1, what="face"):
        self.depth_semi = depth_semi  # ring depth refined in the semi-sharp phase (2: Chaikin)
        self.what = what  # how errors name a base face
        self.hot = ([], [], [])  # nets (k, 17, 3) with the origin as row 16; domains (k, 3)
        self.cold = ([], [], [])
        self.n_hot = 0
        self.n_cold = 0
        self.vcold = []
        self.vkind, self.vdom, self.vpatch, self.vchild, self.vcorner, self.vnmax = [], [], [], [], [], []
        self.vbase = []
        self.corner_of_vertex = {}
        self.corner_data = {}  # corner virtual face -> (CornerScheme, ring control points)

    def new_vface(self, kind, frame, base_face):
        self.vbase.append(base_face)
        self.vkind.append(kind)
        self.vdom.append(_domain(frame))
        self.vpatch.append(-1)
        self.vcold.append(0)
        self.vchild.append([-1, -1, -1, -1])
        self.vcorner.append((0, 0))
        self.vnmax.append(0)
        return len(self.vkind) - 1

    def add_patch(self, net, origin, frame):
        """net: (16, 3) in the frame's own orientation, relative to origin."""
        self._store(self.hot, net[_net_permutation(frame)][None], origin, np.array([_domain(frame)]))
        self.n_hot += 1
        return self.n_hot - 1

    @staticmethod
    def _store(region, nets, origin, doms):
        block = np.empty((nets.shape[0], 17, nets.shape[-1]))  # 3 coordinates (or probe columns)
        block[:, :16] = nets
        block[:, 16] = origin
        region[0].append(block)
        region[1].append(doms)

    # ------------------------------------------------------------------ classification
    def classify(self, cx, X, jobs, vmap=None):
        """Classify the quads ``jobs = [(g, frame, base, vid), ...]`` of ``cx`` (positions ``X``).

        The smooth regular ones (:meth:`smooth_regular_patches`) in one vectorized pass, the
        others face by face (:meth:`face`); a quad with three smooth regular corners is first
        tried as a corner face at the fourth. ``vmap``: the mesh vertex of every vertex of ``cx``
        (records the corner scheme of each irregular vertex, for the vertex normals).
        """
        if not jobs:
            return
        ok = _smooth_regular_vertices(cx)
        done = self.smooth_regular_patches(cx, X, jobs)
        g = np.array([j[0] for j in jobs], dtype=np.int64)
        start = np.asarray(cx.start + [len(cx.org)], dtype=np.int64)
        org = np.asarray(cx.org, dtype=np.int64)
        quad = start[g + 1] - start[g] == 4
        corners = ok[org[np.minimum(start[g][:, None] + np.arange(4), org.size - 1)]]
        single = np.where(quad & (corners.sum(axis=1) == 3), np.argmin(corners, axis=1), -1)
        for (g_, frame, base, vid), d, r in zip(jobs, done, single.tolist()):
            if d:
                continue
            if r >= 0 and self.corner_at(cx, X, g_, r, frame, base, vid, vmap):
                continue
            self.face(cx, X, g_, frame, 0, 0, base, vid, vmap=vmap)

    def corner_at(self, cx, X, g, r, frame, base, vid, vmap=None):
        """Store quad ``g`` as a corner face at corner ``r`` if that is its classification (its
        other corners regular, its ring from ``r`` stationary): the path of :meth:`face` for such a
        face, without listing its ring from corner 0 first (the tags of a ring, hence the
        semi-sharp test, do not depend on the corner it is listed from). Returns True if stored."""
        ring_r, faces_r, nr = canonical_ring(cx, g, r)
        key_r = ring_key(cx, ring_r, faces_r, nr)
        if _has_semi_sharp(key_r) or irregular_corners(key_r) != (0,):
            return False
        scheme = corner_scheme(key_r)
        if scheme is None:
            return False
        self.scheme_face(scheme, X, ring_r, r, frame, base, vid, vmap)
        return True

    def scheme_face(self, scheme, X, ring_r, r, frame, base, vid, vmap=None):
        """:meth:`corner_face` on the ring ``ring_r`` (listed from the face's irregular corner
        ``r``), and the first corner scheme of each mesh vertex recorded (``vmap``) for its normal."""
        C = X[ring_r]
        self._check_finite(C, base)
        vid = self.corner_face(scheme, C, r, frame, vid)
        vertex = -1 if vmap is None else int(vmap[ring_r[0]])
        if vertex >= 0 and vertex not in self.corner_of_vertex:
            self.corner_of_vertex[vertex] = (scheme, C, vid)
        return vid

    def smooth_regular_patches(self, cx, X, jobs):
        """Store the bicubic patches of the quads of ``jobs`` whose four vertices are smooth regular.

        Smooth regular (:func:`_smooth_regular_vertices`): four faces around the vertex, no
        boundary, sharp edge or vertex sharpness at it. Such a face's tagged one-ring has no tags
        and no irregular corner, and its net (:func:`ccproof.evaluate.local.regular_net`) is its
        4 x 4 grid of vertices: gathered here for all of them at once with the half-edge arrays (the
        same walks as :func:`ccproof.evaluate.local.regular_net`). Returns a bool array, True for
        the jobs handled.
        """
        if not jobs:
            return np.zeros(0, dtype=bool)
        org, nxt, prv, twin = (np.asarray(a, dtype=np.int64) for a in (cx.org, cx.nxt, cx.prv, cx.twin))
        ok = _smooth_regular_vertices(cx)
        g = np.array([j[0] for j in jobs], dtype=np.int64)
        start = np.asarray(cx.start + [org.size], dtype=np.int64)
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
            cell = [p[0] + 4 * p[1] for p in (_CENTER[s_],) + _SIDES[s_][:3]]
            grid[:, cell[0]] = org[h]
            grid[:, cell[1]] = org[nxt[nxt[t]]]
            grid[:, cell[2]] = org[prv[t]]
            grid[:, cell[3]] = org[prv[twin[nxt[t]]]]
        frames = [jobs[i][1] for i in idx]
        perm = np.array([_net_permutation(f) for f in frames])
        origin = X[grid].mean(axis=1)
        nets = X[np.take_along_axis(grid, perm, axis=1)] - origin[:, None, :]
        self._check_finite(nets, int(jobs[idx[0]][2]))
        self._store(self.hot, nets, origin, np.array([_domain(f) for f in frames]))
        for r, i in enumerate(idx):
            vid = jobs[i][3]
            self.vkind[vid] = _REGULAR
            self.vpatch[vid] = self.n_hot + r
        self.n_hot += idx.size
        return sel

    def face(self, cx, X, g, frame, depth, semi_depth, base, vid, src=None, vmap=None):
        """Classify quad ``g`` of complex ``cx`` with positions ``X`` (NaN where not exact).

        ``src = (key, n_rule)``: ``cx`` is the child complex of that ring (its rings are cached).
        ``vmap``: mesh vertex of every vertex of ``cx`` (-1 for new points), or None.
        """

        def ring_of(r, depth_):
            if src is not None:
                return _child_ring(src[0], src[1], g, r, depth_)
            ring_, faces_, nr_ = canonical_ring(cx, g, r, depth_)
            return ring_, ring_key(cx, ring_, faces_, nr_), nr_

        ring, key, nr = ring_of(0, 1)
        if _has_semi_sharp(key):
            if semi_depth >= MAX_SEMI_DEPTH:
                raise MeshError(f"{self.what} {base}: semi-sharp creases did not decay in {MAX_SEMI_DEPTH} levels")
            D = self.depth_semi
            if D != 1:
                ring, key, nr = ring_of(0, D)
            return self.split_face(key, nr, X[ring], frame, depth, semi_depth + 1, base, vid,
                                   None if vmap is None else vmap[ring])
        irr = irregular_corners(key)
        if not irr:
            M = _regular_net_matrix(key)
            Xl = X[ring]
            self._check_finite(Xl, base)
            origin = Xl.mean(axis=0)
            net = M @ (Xl - origin)
            self._check_finite(net, base)
            self.vkind[vid] = _REGULAR
            self.vpatch[vid] = self.add_patch(net, origin, frame)
            return vid
        if len(irr) == 1:
            r = irr[0]
            ring_r, key_r, _ = ring_of(r, 1)
            scheme = corner_scheme(key_r)
            if scheme is not None:
                return self.scheme_face(scheme, X, ring_r, r, frame, base, vid, vmap)
        if depth >= MAX_DEPTH:
            raise MeshError(
                f"{self.what} {base}: the configuration around it is not supported "
                f"(still irregular after {MAX_DEPTH} local subdivisions)"
            )
        return self.split_face(key, nr, X[ring], frame, depth + 1, semi_depth, base, vid,
                               None if vmap is None else vmap[ring])

    def _check_finite(self, a, base):
        if not np.isfinite(a).all():  # pragma: no cover - would be a bug in the local refinement
            raise MeshError(f"internal error: {self.what} {base} uses a point outside the exact local refinement")

    def corner_face(self, scheme, C, r, frame, vid):
        self.corner_data[vid] = (scheme, C)
        rot = _compose(frame, _corner_frame(r))
        self.vkind[vid] = _CORNER
        U0, V0, H = self.vdom[vid]
        corner = rot[0]
        self.vcorner[vid] = (int(corner[0] > U0), int(corner[1] > V0))
        rel = C - C[0]
        origin = C[0] + scheme.limit_mask @ rel
        L, unit = _oriented_layers(scheme, rot)
        nl = unit.shape[0]
        nets = _skinny_product(L, rel).reshape(nl, 3, 16, rel.shape[-1])
        # layer domains: the unit corner frame's scaled by the side H (exact: powers of two)
        doms = unit * H
        doms[..., 0] += corner[0]
        doms[..., 1] += corner[1]
        K = min(HOT_LAYERS, nl)
        self._store(self.hot, nets[:K].reshape(-1, 16, rel.shape[-1]), origin, doms[:K].reshape(-1, 3))
        self._store(self.cold, nets[K:].reshape(-1, 16, rel.shape[-1]), origin, doms[K:].reshape(-1, 3))
        self.vpatch[vid] = self.n_hot
        self.vcold[vid] = self.n_cold - 3 * K  # patch of layer n >= K: vcold + n_hot_total + 3 n + code
        self.n_hot += 3 * K
        self.n_cold += 3 * (nl - K)
        self.vnmax[vid] = nl - 1
        return vid

    def split_face(self, key, nr, Xr, frame, depth, semi_depth, base, vid, vmap=None):
        """Subdivide the ring ``key`` (positions ``Xr``) once, exactly and locally; classify the
        four children of its face 0.

        Only the points whose stencils lie inside the ring are exact (the rules at its ``nr`` rule
        vertices, :func:`ccproof.evaluate.local.refine_key`); the others are NaN, so that any use
        would show up in the checks of the tables instead of passing silently. ``vmap``: the mesh
        vertex of every ring vertex (vertex points keep their vertex), or None.
        """
        S, _, child = refine_key(key, nr)
        X1 = S @ Xr
        vmap1 = None
        if vmap is not None:
            vmap1 = np.full(S.shape[0], -1, dtype=np.int64)
            vmap1[: len(vmap)] = vmap
        self.vkind[vid] = _SPLIT
        U0, V0, _ = self.vdom[vid]
        for i in range(4):
            cf = _compose(frame, _child_frame(i))
            cu, cv, _ = _domain(cf)
            q = int(cu > U0) + 2 * int(cv > V0)
            c = self.new_vface(_REGULAR, cf, base)
            self.vchild[vid][q] = c
            self.face(child, X1, i, cf, depth, semi_depth, base, c, src=(key, nr), vmap=vmap1)
        return vid


class LimitSurface:
    """Exact evaluator of the limit surface of a quad mesh (natural parameterization, bmz04 section 2).

    Build it with :func:`natural_limit_surface`.

    Parameters
    ----------
    mesh : QuadMesh
        m faces, n vertices ``(n, 3) float64``.

    Attributes
    ----------
    mesh : QuadMesh
    n_patches : int
        Bicubic patches stored (17 x 3 floats each: net and origin).
    max_layers : int
        Deepest layer stored at an irregular corner.
    split_depth : int
        How many local subdivisions the most irregular face needed.

    Notes
    -----
    Regular faces are bicubic B-spline patches, faces at one irregular vertex exact self-similar
    layers (docs/readings.md R4, R12; Stam 1998), other faces are split locally: docs/evaluate.md
    "Method". :meth:`evaluate` takes ``face, u, v`` of shape (n,) and returns ``P`` (n, 3) and its
    derivatives.

    Examples
    --------
    The cube's corner limit point is ``(9 V + 4 sum e + sum d) / 24 = (-1/2, -1/2, -1/2)`` at
    ``V = (-1, -1, -1)``; every face has four irregular corners, so it is split once:

    >>> from ccproof.mesh.examples import cube
    >>> S = LimitSurface(cube())
    >>> S.evaluate([0], [0.0], [0.0])["P"].round(12).tolist(), S.split_depth
    ([[-0.5, -0.5, -0.5]], 1)
    """

    def __init__(self, mesh: QuadMesh):
        self.mesh = mesh
        b = _Builder()
        cx = Complex(mesh.faces, {}, {}, Options(), n_vertices=mesh.n_vertices)
        X = mesh.vertices
        base = ((0.0, 0.0), (1.0, 0.0), (0.0, 1.0))
        m = mesh.n_faces
        vmap = np.arange(mesh.n_vertices)
        for f in range(m):  # virtual faces 0..m-1 are the base faces
            b.new_vface(_REGULAR, base, f)
        b.classify(cx, X, [(f, base, f, f) for f in range(m)], vmap=vmap)
        self._finish(b)

    def _finish(self, b):
        """The evaluation tables from a :class:`_Builder` that has classified every base face."""
        self._nets = np.ascontiguousarray(np.concatenate(b.hot[0] + b.cold[0]))  # (n_patches, 17, 3)
        if not np.isfinite(self._nets).all():  # pragma: no cover - would be a bug in the classification
            bad = int(np.flatnonzero(~np.isfinite(self._nets).all(axis=(1, 2)))[0])
            raise MeshError(f"internal error: patch {bad} uses a point outside the exact local refinement")
        pd = np.concatenate(b.hot[1] + b.cold[1])
        self._pu0, self._pv0, self._ph = pd[:, 0].copy(), pd[:, 1].copy(), pd[:, 2].copy()
        self._vcold = np.array(b.vcold, dtype=np.int64) + b.n_hot
        self.hot_layers = HOT_LAYERS
        self._vkind = np.array(b.vkind, dtype=np.int8)
        vd = np.array(b.vdom).reshape(-1, 3)
        self._vu0, self._vv0, self._vh = vd[:, 0].copy(), vd[:, 1].copy(), vd[:, 2].copy()
        self._vpatch = np.array(b.vpatch, dtype=np.int64)
        self._vchild = np.array(b.vchild, dtype=np.int64).reshape(-1, 4)
        vc = np.array(b.vcorner, dtype=bool).reshape(-1, 2)
        self._vcu, self._vcv = vc[:, 0].copy(), vc[:, 1].copy()
        self._vnmax = np.array(b.vnmax, dtype=np.int64)
        depth = np.zeros(len(b.vkind), dtype=np.int64)
        for vid in np.flatnonzero(self._vkind == _SPLIT):  # children are created after their parents
            depth[self._vchild[vid]] = depth[vid] + 1
        self.split_depth = int(depth.max())  # the descent steps of _vface_of
        self._corner_of_vertex = b.corner_of_vertex
        self._corner_data = b.corner_data
        self._corner_normal = {}
        self._vbase = np.array(b.vbase, dtype=np.int64)
        self.n_patches = self._nets.shape[0]
        self.max_layers = int(self._vnmax.max()) + 1 if (self._vkind == _CORNER).any() else 0

    @property
    def n_faces(self):
        """Number of (ptex) faces: the valid ``face`` ids of :meth:`evaluate`."""
        return self.mesh.n_faces

    # ------------------------------------------------------------------ input checks
    def _check(self, face_ids, u, v):
        """Face ids and (u, v) as flat int64 / float64 arrays, checked (errors name the point)."""
        f, u, v = self._check_shapes(face_ids, u, v)
        self._check_values(f, u, v)
        return f, u, v

    def _refused_faces(self):
        """Per face id, whether evaluation refuses it (none here; holes in the tagged evaluator)."""
        return np.zeros(self.n_faces, dtype=np.bool_)

    def _check_shapes(self, face_ids, u, v):
        f = np.asarray(face_ids)
        u = np.asarray(u, dtype=np.float64)
        v = np.asarray(v, dtype=np.float64)
        try:
            f, u, v = np.broadcast_arrays(f, u, v)
        except ValueError:
            raise CCProofError(
                f"face_ids, u, v must have the same length, got {np.shape(face_ids)}, {u.shape}, {v.shape}"
            ) from None
        f, u, v = f.reshape(-1), u.reshape(-1), v.reshape(-1)
        if f.size and not np.issubdtype(f.dtype, np.integer):
            fi = f.astype(np.int64) if np.isfinite(f.astype(float)).all() else None
            if fi is None or not np.array_equal(fi, f):
                bad = int(np.flatnonzero(fi != f)[0]) if fi is not None else 0
                raise CCProofError(f"point {bad}: face id {f[bad].item()!r} is not an integer")
            f = fi
        return f.astype(np.int64, copy=False), u, v

    def _check_values(self, f, u, v):
        m = self.n_faces
        step = 1 << 18  # bounded temporaries
        for lo in range(0, f.size, step):
            fb, ub, vb = f[lo : lo + step], u[lo : lo + step], v[lo : lo + step]
            bad = np.flatnonzero((fb < 0) | (fb >= m))
            if bad.size:
                i = lo + int(bad[0])
                raise CCProofError(f"point {i}: face id {int(f[i])} out of range [0, {m})")
            for name, x, xb in (("u", u, ub), ("v", v, vb)):
                bad = np.flatnonzero(~((xb >= 0.0) & (xb <= 1.0)))
                if bad.size:
                    i = lo + int(bad[0])
                    raise CCProofError(f"point {i}: {name} = {float(x[i])!r} is outside [0, 1]")
        return f, u, v

    # ------------------------------------------------------------------ evaluation
    def locate(self, face_ids, u, v):
        """The stored patch of every point and the point's parameter in it.

        Returns
        -------
        patch : ndarray of int, shape (n,)
        s, t : ndarray, shape (n,)
            Parameter in the patch, in [0, 1]; exact (dyadic rescaling).
        scale : ndarray, shape (n,)
            ``1 / h``: d/du = scale * d/ds for a patch of side h (a power of 2).
        """
        f, u, v = self._check(face_ids, u, v)
        return self._locate(f, u, v)

    def _locate(self, f, u, v):
        vf, kind = self._vface_of(f, u, v)
        patch = self._vpatch[vf].copy()
        idx = np.flatnonzero(kind == _CORNER)
        if idx.size:
            w = vf[idx]
            U0, V0, H = self._vu0[w], self._vv0[w], self._vh[w]
            uu, vv = u[idx], v[idx]
            du = np.where(self._vcu[w], (U0 + H) - uu, uu - U0) / H  # exact: dyadic, Sterbenz
            dv = np.where(self._vcv[w], (V0 + H) - vv, vv - V0) / H
            mx = np.maximum(du, dv)
            _, e = np.frexp(mx)  # mx in [2^(e-1), 2^e): layer n = -e
            nmax = self._vnmax[w]
            n = np.where(mx > 0, np.clip(-e, 0, nmax), nmax)
            du, dv = np.ldexp(du, n), np.ldexp(dv, n)
            a, b = du >= 0.5, dv >= 0.5
            code = np.where(a & ~b, 0, np.where(a & b, 1, np.where(b, 2, 1)))
            start = np.where(n < self.hot_layers, patch[idx], self._vcold[w])
            patch[idx] = start + 3 * n + code
        h = self._ph[patch]
        s = np.clip((u - self._pu0[patch]) / h, 0.0, 1.0)
        t = np.clip((v - self._pv0[patch]) / h, 0.0, 1.0)
        return patch, s, t, 1.0 / h

    def evaluate(self, face_ids, u, v, derivatives=1, *, chunk=CHUNK, out=None, backend=None, threads=None):
        """Positions and derivatives of the limit surface at points (face, u, v).

        Parameters
        ----------
        face_ids : array_like of int, shape (n,)
        u, v : array_like of float, shape (n,)
            Face parameters in [0, 1] (corner i of the face at (0,0), (1,0), (1,1), (0,1)).
        derivatives : int, 0, 1 or 2
        chunk : int
            Points per chunk (memory beyond the outputs is about 1 kB per chunk point).
        out : dict of ndarray, optional
            Preallocated outputs (shape (n, 3) each) to fill.
        backend : {None, "numpy", "numba"}
            ``None``: the compiled kernel if numba is installed (and the environment variable
            ``CCPROOF_BACKEND`` is not ``numpy``), else numpy. Both compute the same formulas.
        threads : int, optional
            Threads for the compiled kernel (it releases the GIL; the points are split into
            contiguous blocks, the results are identical). Default: all cores
            (``os.cpu_count()``, or the environment variable ``CCPROOF_THREADS``) for batches of
            at least 2^17 points, else 1. The numpy path always runs on one thread.

        Returns
        -------
        dict of ndarray, shape (n, 3)
            ``P``; with ``derivatives >= 1`` also ``Pu``, ``Pv``; with 2 also ``Puu``, ``Puv``,
            ``Pvv``: derivatives with respect to the face's own (u, v).

        Raises
        ------
        CCProofError
            Face id out of range or not an integer, (u, v) outside [0, 1]^2 or NaN (names the point).

        Examples
        --------
        >>> from ccproof.mesh.examples import cube
        >>> S = natural_limit_surface(cube())
        >>> r = S.evaluate([0, 1], [0.0, 0.5], [0.0, 0.5])
        >>> np.round(r["P"][0], 12).tolist()     # a cube corner: limit point (9 V + 4 sum e + sum d)/24
        [-0.5, -0.5, -0.5]
        >>> round(float(r["P"][1, 2] * 81), 12)  # centre of the top face: 68/81 (one step + mask)
        68.0
        """
        if derivatives not in (0, 1, 2):
            raise CCProofError(f"derivatives must be 0, 1 or 2, got {derivatives!r}")
        kernel = _numba_kernel(backend)
        if kernel is None:
            f, u, v = self._check(face_ids, u, v)
        else:  # the compiled kernel checks the values itself, in the threads
            f, u, v = self._check_shapes(face_ids, u, v)
        n = f.size
        keys = _KEYS[derivatives]
        if out is None:
            out = {k: np.empty((n, 3)) for k in keys}
        if kernel is not None:
            dummy = np.empty((0, 3))
            arrs = [out.get(k, dummy) for k in _KEYS[2]]
            tables = (self._refused_faces(), *self._kernel_tables())

            def block(lo, hi):
                return kernel(f[lo:hi], u[lo:hi], v[lo:hi], derivatives, *tables,
                              *[a[lo:hi] if a.shape[0] else a for a in arrs])

            bad = _in_blocks(block, n, _threads(threads, n), 32768)
            if max(bad) >= 0:
                self._check_values(f, u, v)  # raises, naming the first bad point
                raise CCProofError("internal error: the compiled kernel refused a point the checks accept")
            return out
        for lo in range(0, n, chunk):
            hi = min(n, lo + chunk)
            self._eval_chunk(f[lo:hi], u[lo:hi], v[lo:hi], derivatives, {k: out[k][lo:hi] for k in keys})
        return out

    def _kernel_tables(self):
        """The patch table as the compiled kernels take it (after the point arrays)."""
        return (self._vkind, self._vchild, self._vu0, self._vv0, self._vh, self._vpatch, self._vcold,
                self.hot_layers, self._vcu, self._vcv, self._vnmax, self.split_depth, self._nets, self._pu0,
                self._pv0, self._ph)

    def _newton_kernel(self, backend=None):
        """The compiled Newton descent of the closest points on this surface, or None: numpy backend,
        or a subclass that evaluates another parameterization."""
        if type(self).evaluate is not LimitSurface.evaluate or _numba_kernel(backend) is None:
            return None
        from ccproof.evaluate._numba_kernel import newton_points

        return newton_points

    def _eval_chunk(self, f, u, v, d, out):
        patch, s, t, g = self._locate(f, u, v)
        bs = bspline_basis(s, d)
        bt = bspline_basis(t, d)
        G = np.take(self._nets.reshape(-1, 51), patch, axis=0)
        N = G[:, :48].reshape(-1, 4, 4, 3)  # [n, j, i, c]
        T0 = np.einsum("nj,njic->nic", bt[0], N)
        np.add(G[:, 48:], np.einsum("ni,nic->nc", bs[0], T0), out=out["P"])
        if d >= 1:
            T1 = np.einsum("nj,njic->nic", bt[1], N)
            gg = g[:, None]
            np.multiply(np.einsum("ni,nic->nc", bs[1], T0), gg, out=out["Pu"])
            np.multiply(np.einsum("ni,nic->nc", bs[0], T1), gg, out=out["Pv"])
        if d >= 2:
            T2 = np.einsum("nj,njic->nic", bt[2], N)
            g2 = (g * g)[:, None]
            np.multiply(np.einsum("ni,nic->nc", bs[2], T0), g2, out=out["Puu"])
            np.multiply(np.einsum("ni,nic->nc", bs[1], T1), g2, out=out["Puv"])
            np.multiply(np.einsum("ni,nic->nc", bs[0], T2), g2, out=out["Pvv"])

    # ------------------------------------------------------------------ normals
    def _vface_of(self, f, u, v):
        """The virtual face holding (u, v) after descending the split faces, and its kind."""
        vf = f.copy()
        kind = self._vkind[vf]
        for _ in range(self.split_depth):
            idx = np.flatnonzero(kind == _SPLIT)
            if idx.size == 0:
                break
            w = vf[idx]
            half = self._vh[w] * 0.5
            q = (u[idx] >= self._vu0[w] + half).astype(np.int64) + 2 * (v[idx] >= self._vv0[w] + half)
            vf[idx] = self._vchild[w, q]
            kind[idx] = self._vkind[vf[idx]]
        return vf, kind

    def _eigen_normal(self, vid):
        """Unit normal at the irregular corner of corner face ``vid`` from the exact tangent masks."""
        if vid not in self._corner_normal:
            scheme, C = self._corner_data[vid]
            T = scheme.tangent_masks
            nrm = None
            if T is not None:
                t1, t2 = T @ (C - C[0])
                c = np.cross(t1, t2)
                if np.linalg.norm(c) > 0:
                    nrm = c / np.linalg.norm(c)
            self._corner_normal[vid] = nrm
        return self._corner_normal[vid]

    def closest_points(self, X, **options):
        """Globally nearest limit points to the rows of ``X`` (n, 3): face, u, v, P, distance, normal
        (see :func:`ccproof.evaluate.closest.closest_points`)."""
        from .closest import closest_points

        return closest_points(self, X, **options)

    def normals(self, face_ids, u, v):
        """Unit limit normals, shape (n, 3), oriented like ``Pu x Pv``.

        ``Pu x Pv`` normalized, except closer to an irregular corner than the innermost stored layer
        (including the corner itself, where ``Pu x Pv`` degenerates): there the normal of the exact
        tangent plane at the vertex (left eigenvectors of the corner's exact subdivision matrix,
        :attr:`ccproof.evaluate.local.CornerScheme.tangent_masks`); it differs from ``Pu x Pv`` at
        the innermost layer by the decay of the third eigenvalue over some 50 layers (round-off).
        NaN where the tangent plane at such a corner is not determined by two eigenvectors.
        """
        f, u, v = self._check(face_ids, u, v)
        r = self.evaluate(f, u, v, 1)
        N = np.cross(r["Pu"], r["Pv"])
        vf, kind = self._vface_of(f, u, v)
        idx = np.flatnonzero(kind == _CORNER)
        if idx.size:
            w = vf[idx]
            U0, V0, H = self._vu0[w], self._vv0[w], self._vh[w]
            du = np.where(self._vcu[w], (U0 + H) - u[idx], u[idx] - U0) / H
            dv = np.where(self._vcv[w], (V0 + H) - v[idx], v[idx] - V0) / H
            mx = np.maximum(du, dv)
            inner = mx < np.ldexp(1.0, -(self._vnmax[w] + 1))
            for j in np.flatnonzero(inner):
                e = self._eigen_normal(int(w[j]))
                i = idx[j]
                if e is None:
                    N[i] = np.nan
                else:
                    N[i] = e if np.dot(e, N[i]) >= 0 else -e
        with np.errstate(invalid="ignore", divide="ignore"):
            return N / np.linalg.norm(N, axis=1)[:, None]

    # ------------------------------------------------------------------ vertices
    def vertex_limits(self):
        """Exact limit positions of the control vertices (masks), shape (n_vertices, 3)."""
        return limit_positions(self.mesh)

    def vertex_normals(self):
        """Unit limit normals at the control vertices, shape (n_vertices, 3).

        Eigen masks (:func:`ccproof.mesh.limit_normals`) at interior and regular boundary vertices;
        at other boundary vertices the tangent masks of the exact corner matrix
        (:attr:`ccproof.evaluate.local.CornerScheme.tangent_masks`), oriented like ``Pu x Pv``.
        NaN where the tangent plane is not determined by the dominant eigenvectors.
        """
        Nn = limit_normals(self.mesh)
        for v in np.flatnonzero(np.isnan(Nn).any(axis=1)):
            item = self._corner_of_vertex.get(int(v))
            if item is None:
                continue
            scheme, C, vid = item
            T = scheme.tangent_masks
            if T is None:
                continue
            t1, t2 = T @ (C - C[0])
            nrm = np.cross(t1, t2)
            # orientation: Pu x Pv just inside the corner's virtual face
            U0, V0, H = self._vu0[vid], self._vv0[vid], self._vh[vid]
            d = 2.0**-12 * H
            u = U0 + H - d if self._vcu[vid] else U0 + d
            w = V0 + H - d if self._vcv[vid] else V0 + d
            f = self._base_face_of(vid)
            r = self.evaluate([f], [u], [w], 1)
            if np.dot(nrm, np.cross(r["Pu"][0], r["Pv"][0])) < 0:
                nrm = -nrm
            Nn[v] = nrm / np.linalg.norm(nrm)
        return Nn

    def _base_face_of(self, vid):
        return int(self._vbase[vid])

    # ------------------------------------------------------------------ moved control points
    def with_vertices(self, X):
        """The limit surface of the same mesh with the control points ``X`` (n_vertices, 3).

        Everything that depends only on the connectivity (classification, patch domains, the
        locator's tables, the corner schemes) is shared with ``self``; the patch nets and the
        irregular corners' control points are recomputed as ``W X`` with the linear map ``W`` from
        the control points to them (per patch a dense block on its base face's one-ring;
        :func:`_vertex_maps`, computed once per connectivity and shared by all surfaces derived with
        this method). The result evaluates like
        ``LimitSurface(mesh.with_vertices(X))`` to round-off, at a fraction of its cost (for the
        moving surfaces of ccproof.apps.dynamics).

        Parameters
        ----------
        X : array_like, shape (n_vertices, 3)

        Returns
        -------
        LimitSurface

        Examples
        --------
        >>> from ccproof.mesh.examples import cube
        >>> S = natural_limit_surface(cube())
        >>> T = S.with_vertices(2.0 * np.asarray(cube().vertices))
        >>> np.round(T.evaluate([0], [0.0], [0.0])["P"][0], 12).tolist()
        [-1.0, -1.0, -1.0]
        """
        if type(self) is not LimitSurface:
            raise CCProofError(f"with_vertices is implemented for LimitSurface only, not {type(self).__name__}")
        mesh = self.mesh.with_vertices(X)  # checks the shape and finiteness (MeshError)
        maps = self.__dict__.get("_maps")
        if maps is None:
            maps = self._maps = _vertex_maps(self)
        V = np.where(mesh.is_unused_vertex[:, None], 0.0, mesh.vertices)  # unused: any value, weight 0
        new = object.__new__(LimitSurface)
        new.__dict__.update(self.__dict__)
        new.mesh = mesh
        new._nets = np.ascontiguousarray(maps.apply(maps.nets, V))
        C = maps.apply(maps.corners, V)
        new._corner_data = {vid: (self._corner_data[vid][0], C[i, : maps.corner_rows[i]])
                            for i, vid in enumerate(maps.corner_vids)}
        new._corner_of_vertex = {v: (sch, new._corner_data[vid][1], vid)
                                 for v, (sch, _, vid) in self._corner_of_vertex.items()}
        new._corner_normal = {}
        return new


class _VertexMaps:
    """Linear maps from the control points to the stored nets and corner rings of a LimitSurface.

    ``nets``, ``corners``: ``(W, idx)`` with ``W`` of shape (k, rows, s) and ``idx`` (k, s) vertex ids
    (padded with weight 0): item i is ``W[i] @ X[idx[i]]``, of shape (rows, 3).
    """

    def __init__(self, nets, corners, corner_vids, corner_rows):
        self.nets, self.corners = nets, corners
        self.corner_vids, self.corner_rows = corner_vids, corner_rows

    @staticmethod
    def apply(m, X):
        W, idx = m
        return W @ X[idx]


def _vertex_maps(surface):
    """The linear maps of :meth:`LimitSurface.with_vertices`, by probing.

    Every stored net and every corner ring of base face f is a linear function, the same for each
    coordinate, of the control points of the one-ring of f (the faces sharing a vertex with f: the
    builder reads nothing else). The vertices are coloured so that no one-ring holds two vertices
    of the same colour (greedy colouring of the graph "in a common one-ring"); the tables are built
    once more with the c indicator vectors of the colours as coordinates (c columns instead of x, y,
    z: the builder treats every column alike), and the coefficient of vertex v in an item of face f
    is read off the column of v's colour. The cost is about that of one more build (c is 16 to 27
    on the meshes of ccproof.apps.dynamics).
    """
    import scipy.sparse as sp

    mesh = surface.mesh
    n, m = mesh.n_vertices, mesh.n_faces
    F = np.asarray(mesh.faces)
    A = sp.csr_matrix((np.ones(4 * m), (F.ravel(), np.repeat(np.arange(m), 4))), shape=(n, m))
    ring = ((A @ ((A.T @ A) > 0)) > 0).tocsc()  # ring[v, f]: v in the one-ring of face f
    ring.sort_indices()
    G = (ring @ ring.T).tocsr()
    color = np.full(n, -1, dtype=np.int64)
    for v in range(n):
        used = color[G.indices[G.indptr[v] : G.indptr[v + 1]]]
        free = np.flatnonzero(np.bincount(used[used >= 0], minlength=len(used) + 1) == 0)
        color[v] = free[0]
    # base face of every patch and of every corner ring
    pbase = np.full(surface.n_patches, -1, dtype=np.int64)
    kind, vp, vb = surface._vkind, surface._vpatch, surface._vbase
    reg = np.flatnonzero((kind == _REGULAR) & (vp >= 0))
    pbase[vp[reg]] = vb[reg]
    for vid in np.flatnonzero(kind == _CORNER):
        nl = int(surface._vnmax[vid]) + 1
        k = min(surface.hot_layers, nl)
        pbase[vp[vid] : vp[vid] + 3 * k] = vb[vid]
        pbase[surface._vcold[vid] + 3 * k : surface._vcold[vid] + 3 * nl] = vb[vid]
    if (pbase < 0).any():  # pragma: no cover - would be a bug in the tables
        raise MeshError(f"internal error: patch {int(np.flatnonzero(pbase < 0)[0])} has no base face")
    cvids = sorted(surface._corner_data)
    crows = np.array([surface._corner_data[v][1].shape[0] for v in cvids], dtype=np.int64)
    cbase = vb[np.array(cvids, dtype=np.int64)] if cvids else np.zeros(0, dtype=np.int64)
    size = np.diff(ring.indptr)
    smax = int(size.max())

    def support(base):
        idx = np.zeros((base.size, smax), dtype=np.int64)
        slot = np.arange(smax)[None, :] < size[base][:, None]
        idx[slot] = ring.indices[(ring.indptr[base][:, None] + np.arange(smax)[None, :])[slot]]
        return idx, slot

    pidx, pslot = support(pbase)
    cidx, cslot = support(cbase)
    # one build with the colours' indicator vectors as coordinates (the builder is linear, column by column)
    probe = np.zeros((n, int(color.max()) + 1))
    probe[np.arange(n), color] = 1.0
    b = _Builder()
    cx = Complex(mesh.faces, {}, {}, Options(), n_vertices=n)
    frame = ((0.0, 0.0), (1.0, 0.0), (0.0, 1.0))
    for f in range(m):
        b.new_vface(_REGULAR, frame, f)
    b.classify(cx, probe, [(f, frame, f, f) for f in range(m)], vmap=np.arange(n))
    nets = np.concatenate(b.hot[0] + b.cold[0])
    Wn = np.zeros((surface.n_patches, 17, smax))
    it, sl = np.nonzero(pslot)
    Wn[it, :, sl] = nets[it, :, color[pidx[it, sl]]]
    Wc = np.zeros((len(cvids), int(crows.max()) if cvids else 0, smax))
    for i, vid in enumerate(cvids):
        sl = np.flatnonzero(cslot[i])
        Wc[i, : crows[i], sl] = b.corner_data[vid][1][:, color[cidx[i, sl]]].T
    return _VertexMaps((Wn, pidx), (Wc, cidx), cvids, crows)


def _in_blocks(fn, n, nt, size):
    """``fn(lo, hi)`` over contiguous blocks of ``range(n)`` on ``nt`` threads; the results in block order.

    Many more blocks than threads (about ``size`` points each, at most 16 per thread), taken in turn:
    the cost per point varies (points near irregular vertices go down the layers), so equal shares
    would finish unequally. One thread: a single call on everything.
    """
    if nt <= 1:
        return [fn(0, n)]
    from concurrent.futures import ThreadPoolExecutor

    nb = max(nt, min(16 * nt, n // size))
    bounds = np.linspace(0, n, nb + 1).astype(np.int64)
    with ThreadPoolExecutor(nt) as ex:
        return list(ex.map(lambda i: fn(bounds[i], bounds[i + 1]), range(nb)))


def _threads(threads, n):
    """Number of threads for n points (see :meth:`LimitSurface.evaluate`)."""
    import os

    if threads is None:
        if n < 1 << 17:
            return 1
        threads = int(os.environ.get("CCPROOF_THREADS", os.cpu_count() or 1))
    threads = int(threads)
    if threads < 1:
        raise CCProofError(f"threads must be >= 1, got {threads}")
    return max(1, min(threads, n // 1024 or 1))


def _numba_kernel(backend):
    """The compiled kernel for ``backend`` (None: automatic), or None for the numpy path."""
    import os

    if backend is None:
        backend = os.environ.get("CCPROOF_BACKEND", "auto")
    if backend == "numpy":
        return None
    if backend not in ("auto", "numba"):
        raise CCProofError(f"unknown backend {backend!r} (use 'numpy' or 'numba')")
    from ccproof.evaluate._numba_kernel import evaluate_points

    if evaluate_points is None and backend == "numba":
        raise CCProofError("backend 'numba' requested but numba is not installed")
    return evaluate_points


def natural_limit_surface(mesh):
    """Prepare the exact evaluation of the limit surface of ``mesh`` in its natural parameterization.

    The package-wide entry point is :func:`ccproof.limit_surface` (the same surfaces, plus the
    parameterizations of bmz04 on quad meshes); this one is the evaluator alone.

    Parameters
    ----------
    mesh : QuadMesh, PolyMesh, or str or os.PathLike
        A QuadMesh gives a :class:`LimitSurface`; a PolyMesh the tagged evaluator
        (:class:`ccproof.evaluate.tagged.TaggedLimitSurface`, ``face`` = ptex face index; on
        untagged all-quad meshes the same numbers as LimitSurface to round-off). A path is read by
        :func:`ccproof.mesh.io.read_mesh` (OBJ with OpenSubdiv tags, OFF, or any meshio format): an
        untagged manifold all-quad file gives a LimitSurface on a QuadMesh, anything else (triangles,
        n-gons, creases, corners, holes, boundary modes, non-manifold edges and vertices) the
        tagged evaluator.

    Returns
    -------
    LimitSurface

    Examples
    --------
    >>> from ccproof.mesh.examples import torus
    >>> natural_limit_surface(torus()).evaluate([0], [0.5], [0.5])["P"].shape
    (1, 3)
    """
    if isinstance(mesh, QuadMesh):
        return LimitSurface(mesh)
    from ccproof.evaluate.tagged import TaggedLimitSurface
    from ccproof.mesh.polymesh import PolyMesh

    if isinstance(mesh, PolyMesh):
        return TaggedLimitSurface(mesh)
    from ccproof.mesh.io import read_mesh

    mesh = read_mesh(mesh)
    if mesh.is_plain_quads:
        # a file holding an untagged manifold all-quad mesh: the QuadMesh evaluator, as before (same
        # numbers as the tagged one to round-off; ``S.mesh`` is a QuadMesh)
        return LimitSurface(mesh.to_quad_mesh())
    return TaggedLimitSurface(mesh)


#: former name, kept importable for ccproof/evaluate/cli.py, ccproof/reparam/cli.py and tests; the
#: package-wide ``limit_surface`` is :func:`ccproof.reparam.limit_surface` (= ``ccproof.limit_surface``)
limit_surface = natural_limit_surface
