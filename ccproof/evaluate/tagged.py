"""Exact limit evaluation on tagged polygon meshes (creases, corners, holes, boundary modes, n-gons).

The patch table of a :class:`~ccproof.mesh.polymesh.PolyMesh` is built like the all-quad one of
:mod:`ccproof.evaluate.surface` (same arrays, same locator and kernels), from the tagged rules of
:mod:`ccproof.mesh.rules`:

1. One global Catmull-Clark step (n-gons become quads; ``TRI_SUB_SMOOTH`` and the
   ``EDGE_AND_CORNER`` corners act here). A quad's ptex face is split into its four level-1
   children; sub-face k of an n-gon *is* level-1 child k (same (s, t)).
2. Semi-sharp phase: while an edge at a vertex of the face or the vertex itself has a semi-sharp
   sharpness (0 < s < 10), the face's neighbourhood is refined exactly and locally
   (``CREASE_UNIFORM``: the one-ring, all faces sharing a vertex with the face; ``CREASE_CHAIKIN``:
   the two-ring, because the child sharpness at a vertex depends on all its edges). After
   ceil(s) levels every sharpness is 0 or infinite.
3. Every face is then a regular bicubic B-spline patch (each corner: smooth of valence 4; crease
   rule with two faces on the face's side of the crease; corner rule with one face; rows across
   sharp edges completed by ghost points ``2 B - I``, which reproduce the crease rules), or has one
   irregular corner whose tagged one-ring is stationary (the child's one-ring at that corner has the
   same tagged key: extraordinary, dart, boundary or crease vertex of any valence, corner), evaluated
   by exact powers of its local subdivision matrix (:func:`tagged_corner_scheme`, the method of
   docs/evaluate.md), or it is subdivided once more (at most ``MAX_DEPTH`` times).

Exact data (stencils of a refinement, regular nets, corner schemes) are cached per tagged
configuration key, shared by all faces of the same configuration.
"""

from __future__ import annotations

import functools
import math

import flint
import numpy as np

from ccproof.errors import CCProofError, MeshError
from ccproof.evaluate.local import (
    CornerScheme,
    _fmpq_mat_to_float,
    _lin,
    _to_fmpq_mat,
    cached_scheme,
    power_layers,
)
from ccproof.evaluate.surface import (
    _CORNER,
    _REGULAR,
    _SPLIT,
    LimitSurface,
    _Builder,
    _child_frame,
    _compose,
    _domain,
    _net_permutation,
    _stencil_matrix,
)
from ccproof.mesh.polymesh import PolyMesh
from ccproof.mesh.rules import CORNER, CREASE, SMOOTH, Complex, refine_complex, vertex_rule

__all__ = ["TaggedLimitSurface", "tagged_corner_scheme", "canonical_ring"]

#: local subdivisions allowed after the semi-sharp phase
MAX_DEPTH = 4
#: local subdivisions allowed in the semi-sharp phase (sharpness < 10 decays in 10 uniform levels)
MAX_SEMI_DEPTH = 40


# ------------------------------------------------------------------------------ local rings
def canonical_ring(cx, g, r, depth):
    """The ``depth``-ring of quad ``g`` of a complex, listed from its corner ``r``.

    Walk: the vertices of ``g`` from corner ``r``; then, layer by layer, for every vertex listed so
    far (in order), the faces around it counter-clockwise and then clockwise from its corner in the
    first listed face containing it; each new face read from that vertex on; vertices numbered by
    first appearance. Complexes with the same key (faces and tags) are isomorphic.

    Returns
    -------
    ring : list of int
        Vertex labels of ``cx`` in canonical order.
    faces : tuple of tuple of int
        The faces in canonical labels; ``faces[0] == (0, 1, 2, 3)`` is ``g``.
    rule_vertices : int
        The number of leading ring vertices whose whole fan is in the ring (4 for depth 1).
    """
    pos, ring = {}, []
    twin, prv, nxt, org, face_of, fstart, cfaces = cx.twin, cx.prv, cx.nxt, cx.org, cx.face_of, cx.start, cx.faces
    s0 = fstart[g]
    first_corner = {}
    for i in range(4):
        h = s0 + (r + i) % 4
        v = org[h]
        pos[v] = len(ring)
        ring.append(v)
        first_corner[v] = h
    faces = [(0, 1, 2, 3)]
    seen = {g}
    done = 0
    for _ in range(depth):
        upto = len(ring)
        for idx in range(done, upto):
            c0 = first_corner[ring[idx]]
            walk = [c0]
            c = twin[prv[c0]]
            while c >= 0 and c != c0:
                walk.append(c)
                c = twin[prv[c]]
            if c != c0:
                t = twin[c0]
                c = -1 if t < 0 else nxt[t]
                while c >= 0:
                    walk.append(c)
                    t = twin[c]
                    c = -1 if t < 0 else nxt[t]
            for c in walk:
                h = face_of[c]
                if h in seen:
                    continue
                seen.add(h)
                sh, k = fstart[h], len(cfaces[h])
                j0 = c - sh
                vs = []
                for t in range(k):
                    hc = sh + (j0 + t) % k
                    u = org[hc]
                    q = pos.get(u)
                    if q is None:
                        q = pos[u] = len(ring)
                        ring.append(u)
                        first_corner[u] = hc
                    vs.append(q)
                faces.append(tuple(vs))
        done = upto
    return ring, tuple(faces), done


def ring_key(cx, ring, faces, n_rule):
    """Tagged key of a ring: faces, sharpness of edges at rule vertices, their vertex sharpness."""
    tags = []
    rule = set(range(n_rule))
    seen = set()
    for f in faces:
        k = len(f)
        for i in range(k):
            a, b = f[i], f[(i + 1) % k]
            e = (a, b) if a < b else (b, a)
            if e in seen or (a not in rule and b not in rule):
                continue
            seen.add(e)
            ga, gb = ring[a], ring[b]
            gk = (ga, gb) if ga < gb else (gb, ga)
            if cx.twin[cx.edges[cx.edge_index[gk]]] < 0:
                continue  # boundary edge: infinitely sharp by the topology
            s = cx.edge_sharpness.get(gk, 0.0)
            if s > 0.0:
                tags.append((e, math.inf if s >= 10.0 else s))
    vs = []
    for i in range(n_rule):
        s = cx.vertex_sharpness.get(ring[i], 0.0)
        if s > 0.0:
            vs.append((i, math.inf if s >= 10.0 else s))
    return (faces, tuple(sorted(tags)), tuple(vs), cx.options.key())


def _key_complex(key):
    from ccproof.mesh.rules import Options

    faces, tags, vs, opts = key
    return Complex(faces, dict(tags), dict(vs), Options(*opts), level=1)


def _has_semi_sharp(key):
    return any(0.0 < s < math.inf for _, s in key[1]) or any(0.0 < s < math.inf for _, s in key[2])


@functools.lru_cache(maxsize=8192)
def refine_key(key, n_rule):
    """One exact tagged step of the ring ``key``, computing the rules at its ``n_rule`` rule vertices.

    Returns
    -------
    S : ndarray, shape (n_points, N)
        Float stencils (dense: local complexes are small), rows of uncomputable points NaN.
    stencils : tuple of dict or None (exact)
    child : Complex
        The children of all faces, with the child tags (positions are not part of it).
    """
    cx = _key_complex(key)
    rule = range(n_rule)
    edges = [e for e, h in enumerate(cx.edges) if cx.org[h] < n_rule or cx.dst(h) < n_rule]
    stencils, children, ces, cvs = refine_complex(cx, vertices=rule, edges=edges)
    child = Complex(children, ces, cvs, cx.options, level=2, n_vertices=len(stencils))
    S = _stencil_matrix([{} if st is None else st for st in stencils], cx.n_vertices)
    S[[i for i, st in enumerate(stencils) if st is None]] = np.nan
    S.setflags(write=False)
    return S, tuple(stencils), child


@functools.lru_cache(maxsize=1 << 16)
def _child_ring(key, n_rule, g, r, depth):
    """Ring (ring positions as an index array, tagged key, rule count) of face ``g`` of the child
    complex of :func:`refine_key` ``(key, n_rule)``, from corner ``r``."""
    _, _, child = refine_key(key, n_rule)
    ring, faces, nr = canonical_ring(child, g, r, depth)
    return np.array(ring, dtype=np.int64), ring_key(child, ring, faces, nr), nr


# ------------------------------------------------------------------------------ regularity
def _corner_info(cx, c):
    """(rule, sector size, closed, valence) of the corner ``c`` (a rule vertex of ``cx``)."""
    v = cx.org[c]
    ve = cx.vertex_edges(v)
    if ve is None:
        return None
    es, _, fan, closed = ve
    pe = [cx.sharpness(e) for e in es]
    rule = vertex_rule(cx.vsharp(v), pe)
    n = 1
    cur = c
    while True:  # counter-clockwise: across the incoming edge of cur
        if cx.sharpness(cx.he_edge[cx.prv[cur]]) > 0.0:
            break
        nxt = cx.ccw(cur)
        if nxt < 0 or nxt == c:
            break
        cur, n = nxt, n + 1
    if cur != c or n == 1:
        cur = c
        while True:  # clockwise: across the outgoing edge of cur
            if cx.sharpness(cx.he_edge[cur]) > 0.0:
                break
            nxt = cx.cw(cur)
            if nxt < 0 or nxt == c:
                break
            cur, n = nxt, n + 1
    return rule, min(n, len(fan)), closed, len(fan)


def corner_is_regular(cx, c):
    """Whether the corner ``c`` of a quad is regular for the bicubic B-spline patch (no semi-sharp tags).

    Smooth rule with a closed fan of 4 faces; crease rule with 2 faces in the corner's sector;
    corner rule with 1 face in the sector.
    """
    info = _corner_info(cx, c)
    if info is None:
        return False
    rule, sector, closed, nf = info
    if rule == SMOOTH:
        return closed and nf == 4
    if rule == CREASE:
        return sector == 2
    if rule == CORNER:
        return sector == 1
    return False


_SIDES = (
    ((1, 0), (2, 0), (0, 0), (0, 1)),
    ((3, 1), (3, 2), (3, 0), (-1, 0)),
    ((2, 3), (1, 3), (3, 3), (0, -1)),
    ((0, 2), (0, 1), (0, 3), (1, 0)),
)
_CENTER = ((1, 1), (2, 1), (2, 2), (1, 2))


def tagged_regular_net(cx, g):
    """The 4 x 4 B-spline net of quad ``g`` as integer stencils, or None if a corner is irregular.

    Rows across infinitely sharp edges (and boundary edges) of the face are ghost points
    ``2 B - I``; at a corner-rule corner the diagonal ghost is ``4 V - 2 E1 - 2 E2 + D``.
    """
    s0 = cx.start[g]
    if not all(corner_is_regular(cx, s0 + i) for i in range(4)):
        return None
    fv = [cx.org[s0 + s] for s in range(4)]
    grid = {}
    for s in range(4):
        grid[_CENTER[s]] = {fv[s]: 1}
    bnd = [cx.sharpness(cx.he_edge[s0 + s]) > 0.0 for s in range(4)]
    for s in range(4):
        if not bnd[s]:
            t = cx.twin[s0 + s]
            grid[_SIDES[s][0]] = {cx.dst(cx.nxt[t]): 1}
            grid[_SIDES[s][1]] = {cx.org[cx.prv[t]]: 1}

    def ghost(p, nrm):
        q = (p[0] + nrm[0], p[1] + nrm[1])
        r = (p[0] + 2 * nrm[0], p[1] + 2 * nrm[1])
        return _lin((2, grid[q]), (-1, grid[r]))

    for s in range(4):
        if bnd[s]:
            for p in _SIDES[s][:2]:
                grid[p] = ghost(p, _SIDES[s][3])
    for s in range(4):
        sp, sm = s, (s + 3) % 4
        p = _SIDES[s][2]
        if not bnd[sp] and not bnd[sm]:
            t = cx.twin[s0 + s]
            t2 = cx.twin[cx.nxt[t]]
            if t2 < 0:
                return None
            grid[p] = {cx.org[cx.prv[t2]]: 1}
        else:
            grid[p] = ghost(p, _SIDES[sp if bnd[sp] else sm][3])
    return [grid[(i, j)] for j in range(4) for i in range(4)]


@functools.lru_cache(maxsize=8192)
def regular_net_matrix(key):
    """Float (16, N) matrix of the regular net of face 0 of the ring ``key``, or None."""
    cx = _key_complex(key)
    net = tagged_regular_net(cx, 0)
    if net is None:
        return None
    return _stencil_matrix(net, cx.n_vertices)


@functools.lru_cache(maxsize=8192)
def irregular_corners(key):
    cx = _key_complex(key)
    return tuple(i for i in range(4) if not corner_is_regular(cx, i))


# ------------------------------------------------------------------------------ corner schemes
@functools.lru_cache(maxsize=2048)
def tagged_corner_scheme(key):
    """:func:`_tagged_corner_scheme`, kept between runs (:func:`ccproof.evaluate.local.cached_scheme`)."""
    return cached_scheme("tagged", key, lambda: _tagged_corner_scheme(key))


def _tagged_corner_scheme(key):
    """Exact layered-patch data of face 0 of the tagged one-ring ``key`` (irregular corner 0).

    ``None`` unless the configuration is stationary (the tagged one-ring of the child at corner 0
    has the same key) and the three other children are regular patches. Otherwise as
    :func:`ccproof.evaluate.local.corner_scheme`: ``A`` exact, ``A^n`` exact (flint), the limit mask
    exact, the deviations ``M_j A^n - 1 l^T`` rounded.
    """
    _, stencils, child = refine_key(key, 4)
    N = _key_complex(key).n_vertices
    ring1, faces1, nr = canonical_ring(child, 0, 0, 1)
    key1 = ring_key(child, ring1, faces1, nr)
    if key1 != key:
        return None
    rows = [stencils[v] for v in ring1]
    if any(r is None for r in rows):
        return None
    A = _to_fmpq_mat(rows, N)
    nets = []
    for j in (1, 2, 3):
        net = tagged_regular_net(child, j)
        if net is None:
            return None
        for s in net:
            row = {}
            for v, w in s.items():
                sv = stencils[v]
                if sv is None:
                    return None
                for u, x in sv.items():
                    row[u] = row.get(u, 0) + w * x
            nets.append(row)
    M = _to_fmpq_mat(nets, N)
    support = set()
    for row in nets:
        support.update(row)
    todo = list(support)
    while todo:  # close under A: the rows of A at the support use only the support
        i = todo.pop()
        for j in rows[i]:
            if j not in support:
                support.add(j)
                todo.append(j)
    Bt = (A - flint.fmpq_mat(N, N, [int(i == j) for i in range(N) for j in range(N)])).transpose()
    for j in range(N):
        Bt[N - 1, j] = 1
    rhs = flint.fmpq_mat(N, 1, [0] * (N - 1) + [1])
    try:
        lvec = Bt.solve(rhs)
    except ZeroDivisionError:
        raise MeshError("corner configuration whose subdivision matrix has a multiple eigenvalue 1") from None
    l_row = flint.fmpq_mat(1, N, [lvec[i, 0] for i in range(N)])
    layers = power_layers(M, A, l_row)
    return CornerScheme(N, A, _fmpq_mat_to_float(l_row)[0], layers, sorted(support))


# ------------------------------------------------------------------------------ builder
class _TaggedBuilder(_Builder):
    def __init__(self, depth_semi):
        super().__init__()
        self.depth_semi = depth_semi

    def tagged_face(self, cx, X, g, frame, depth, semi_depth, base, vid, src=None):
        """Classify quad ``g`` of complex ``cx`` with positions ``X`` (NaN where not exact).

        ``src = (key, n_rule)``: ``cx`` is the child complex of that ring (its rings are cached).
        """

        def ring_of(r, depth_):
            if src is not None:
                return _child_ring(src[0], src[1], g, r, depth_)
            ring_, faces_, nr_ = canonical_ring(cx, g, r, depth_)
            return ring_, ring_key(cx, ring_, faces_, nr_), nr_

        ring, key, nr = ring_of(0, 1)
        if _has_semi_sharp(key):
            if semi_depth >= MAX_SEMI_DEPTH:
                raise MeshError(f"ptex face {base}: semi-sharp creases did not decay in {MAX_SEMI_DEPTH} levels")
            D = self.depth_semi
            if D != 1:
                ring, key, nr = ring_of(0, D)
            return self.split(key, nr, X[ring], frame, depth, semi_depth + 1, base, vid)
        irr = irregular_corners(key)
        if not irr:
            M = regular_net_matrix(key)
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
            scheme = tagged_corner_scheme(key_r)
            if scheme is not None:
                C = X[ring_r]
                self._check_finite(C, base)
                return self.corner_face(scheme, C, r, frame, vid)
        if depth >= MAX_DEPTH:
            raise MeshError(
                f"ptex face {base}: the configuration around it is not supported "
                f"(still irregular after {MAX_DEPTH} local subdivisions)"
            )
        return self.split(key, nr, X[ring], frame, depth + 1, semi_depth, base, vid)

    def classify(self, cx, X, jobs):
        """Classify the quads ``jobs = [(g, frame, base, vid), ...]`` of ``cx`` (positions ``X``).

        The smooth regular ones (:meth:`smooth_regular_patches`) in one vectorized pass, the
        others face by face (:meth:`tagged_face`).
        """
        done = self.smooth_regular_patches(cx, X, jobs)
        for (g, frame, base, vid), d in zip(jobs, done):
            if not d:
                self.tagged_face(cx, X, g, frame, 0, 0, base, vid)

    def smooth_regular_patches(self, cx, X, jobs):
        """Store the bicubic patches of the quads of ``jobs`` whose four vertices are smooth regular.

        Smooth regular: four faces around the vertex, no boundary, sharp edge or vertex sharpness
        at it. Such a face's tagged one-ring has no tags and no irregular corner, and its net
        (:func:`tagged_regular_net`) is its 4 x 4 grid of vertices: gathered here for all of them at
        once with the half-edge arrays (the same walks as :func:`tagged_regular_net`). Returns a
        bool array, True for the jobs handled.
        """
        if not jobs:
            return np.zeros(0, dtype=bool)
        org, nxt, prv, twin = (np.asarray(a, dtype=np.int64) for a in (cx.org, cx.nxt, cx.prv, cx.twin))
        ok = np.bincount(org, minlength=cx.n_vertices) == 4
        open_h = twin < 0
        ok[org[open_h]] = False
        ok[org[nxt[open_h]]] = False
        for (a, b_), sh in cx.edge_sharpness.items():
            if sh > 0.0:
                ok[a] = ok[b_] = False
        for v, sh in cx.vertex_sharpness.items():
            if sh > 0.0:
                ok[v] = False
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

    @staticmethod
    def _check_finite(a, base):
        if not np.isfinite(a).all():  # pragma: no cover - would be a bug in the local refinement
            raise MeshError(f"internal error: ptex face {base} uses a point outside the exact local refinement")

    def split(self, key, nr, Xr, frame, depth, semi_depth, base, vid):
        S, _, child = refine_key(key, nr)
        X1 = S @ Xr
        self.vkind[vid] = _SPLIT
        self.max_depth = max(self.max_depth, depth + semi_depth)
        U0, V0, _ = self.vdom[vid]
        for i in range(4):
            cf = _compose(frame, _child_frame(i))
            cu, cv, _ = _domain(cf)
            q = int(cu > U0) + 2 * int(cv > V0)
            c = self.new_vface(_REGULAR, cf, base)
            self.vchild[vid][q] = c
            self.tagged_face(child, X1, i, cf, depth, semi_depth, base, c, src=(key, nr))
        return vid


class TaggedLimitSurface(LimitSurface):
    """Exact evaluator of the limit surface of a tagged polygon mesh, by ptex face.

    Build it with :func:`ccproof.limit_surface`. ``evaluate(ptex, s, t, derivatives)``
    as :meth:`LimitSurface.evaluate`, with ``face`` the ptex face index (OpenSubdiv's
    ``Far::PtexIndices``, :meth:`PolyMesh.ptex_of`) and derivatives with respect to its (s, t).
    Points on hole faces raise an error naming the point and the face.
    """

    def __init__(self, mesh: PolyMesh):
        self.mesh = mesh
        b = _TaggedBuilder(2 if mesh.options.crease_method == "chaikin" else 1)
        ident = ((0.0, 0.0), (1.0, 0.0), (0.0, 1.0))
        P = mesh.n_ptex
        self._ptex_face = np.empty(P, dtype=np.int64)
        for p in range(P):
            b.new_vface(_REGULAR, ident, p)
        if mesh.is_all_quads:
            # no global step needed: start on the base mesh, with the one level-0-only rule that
            # can act on quads (EDGE_AND_CORNER sharpens one-face boundary vertices) made explicit
            cx = mesh.complex()
            if mesh.options.boundary == "edge_and_corner":
                vs = dict(cx.vertex_sharpness)
                for v in range(mesh.n_vertices):
                    fan, closed = cx.fan(v)
                    if fan is not None and not closed and len(fan) == 1:
                        vs[v] = math.inf
                cx = Complex(cx.faces, cx.edge_sharpness, vs, cx.options, level=1, n_vertices=cx.n_vertices)
            X = np.asarray(mesh.vertices)
            self._ptex_face[:] = np.arange(mesh.n_faces)
            b.classify(cx, X, [(f, ident, f, f) for f in range(mesh.n_faces)])
            self._finish(b)
            self._hole_ptex = mesh.is_hole[self._ptex_face]
            return
        m1, _ = mesh.refine()
        cx = m1.complex()
        X = np.asarray(m1.vertices)
        jobs = []
        for f in range(mesh.n_faces):
            k = int(mesh.sizes[f])
            p0 = int(mesh.ptex_start[f])
            c0 = int(mesh.offsets[f])
            if k == 4:
                self._ptex_face[p0] = f
                b.vkind[p0] = _SPLIT
                b.max_depth = max(b.max_depth, 1)
                for i in range(4):
                    cf = _compose(ident, _child_frame(i))
                    cu, cv, _ = _domain(cf)
                    q = int(cu > 0) + 2 * int(cv > 0)
                    c = b.new_vface(_REGULAR, cf, p0)
                    b.vchild[p0][q] = c
                    jobs.append((c0 + i, cf, p0, c))
            else:
                for i in range(k):
                    self._ptex_face[p0 + i] = f
                    jobs.append((c0 + i, ident, p0 + i, p0 + i))
        b.classify(cx, X, jobs)
        self._finish(b)
        self._hole_ptex = mesh.is_hole[self._ptex_face]

    def _finish(self, b):
        self._nets = np.ascontiguousarray(np.concatenate(b.hot[0] + b.cold[0]))
        pd = np.concatenate(b.hot[1] + b.cold[1])
        self._pu0, self._pv0, self._ph = pd[:, 0].copy(), pd[:, 1].copy(), pd[:, 2].copy()
        self._vcold = np.array(b.vcold, dtype=np.int64) + b.n_hot
        self.hot_layers = 3
        self._vkind = np.array(b.vkind, dtype=np.int8)
        vd = np.array(b.vdom).reshape(-1, 3)
        self._vu0, self._vv0, self._vh = vd[:, 0].copy(), vd[:, 1].copy(), vd[:, 2].copy()
        self._vpatch = np.array(b.vpatch, dtype=np.int64)
        self._vchild = np.array(b.vchild, dtype=np.int64).reshape(-1, 4)
        vc = np.array(b.vcorner, dtype=bool).reshape(-1, 2)
        self._vcu, self._vcv = vc[:, 0].copy(), vc[:, 1].copy()
        self._vnmax = np.array(b.vnmax, dtype=np.int64)
        depth = np.zeros(len(b.vkind), dtype=np.int64)
        for vid in range(len(b.vkind)):  # children are created after their parents
            for c in b.vchild[vid]:
                if c >= 0:
                    depth[c] = depth[vid] + 1
        self.split_depth = int(depth.max())
        self._corner_of_vertex = {}
        self._corner_data = b.corner_data
        self._corner_normal = {}
        self._vbase = np.array(b.vbase, dtype=np.int64)
        self.n_patches = self._nets.shape[0]
        self.max_layers = int(self._vnmax.max()) + 1 if (self._vkind == _CORNER).any() else 0

    @property
    def n_faces(self):
        """Number of ptex faces (the valid ``face`` ids)."""
        return self.mesh.n_ptex

    def _check(self, face_ids, u, v):
        f, u, v = super()._check(face_ids, u, v)
        if self._hole_ptex.any():
            bad = np.flatnonzero(self._hole_ptex[f])
            if bad.size:
                i = int(bad[0])
                raise CCProofError(
                    f"point {i}: ptex face {int(f[i])} (face {int(self._ptex_face[f[i]])}) is a hole"
                )
        return f, u, v

    def _vertex_corners(self):
        """One ptex corner (face, s, t) per corner of every base face, and its vertex."""
        from ccproof.evaluate.local import CORNERS

        mesh = self.mesh
        faces, us, vs, verts = [], [], [], []
        for f, p in enumerate(mesh.polygons):
            for i, v in enumerate(p):
                if len(p) == 4:
                    faces.append(int(mesh.ptex_start[f]))
                    us.append(float(CORNERS[i][0]))
                    vs.append(float(CORNERS[i][1]))
                else:
                    faces.append(int(mesh.ptex_start[f]) + i)
                    us.append(0.0)
                    vs.append(0.0)
                verts.append(v)
        return np.array(faces, dtype=np.int64), np.array(us), np.array(vs), np.array(verts, dtype=np.int64)

    def vertex_limits(self):
        """Limit positions of the base vertices (shape (n_vertices, 3)), NaN at unused vertices.

        Evaluated at the ptex corner (0, 0) of a sub-face at the vertex, or at the quad corner
        (hole faces included: holes do not change the surface of the other faces).
        """
        out = np.full((self.mesh.n_vertices, 3), np.nan)
        f, u, v, verts = self._vertex_corners()
        r = {"P": np.empty((f.size, 3))}
        self._eval_chunk(f, u, v, 0, r)
        out[verts] = r["P"]
        return out

    def vertex_normals(self):
        """Unit limit normals of the base vertices (shape (n_vertices, 3)), see :meth:`normals`.

        Each vertex takes the normal of its first face corner that is not on a hole; NaN where the
        tangent plane is not determined (see :meth:`normals`) or the vertex has only hole faces.
        """
        out = np.full((self.mesh.n_vertices, 3), np.nan)
        f, u, v, verts = self._vertex_corners()
        keep = ~self._hole_ptex[f]
        f, u, v, verts = f[keep][::-1], u[keep][::-1], v[keep][::-1], verts[keep][::-1]
        out[verts] = self.normals(f, u, v)  # reversed: the first corner of a vertex is written last
        return out
