"""Exact local Catmull-Clark machinery: rings of faces, exact local refinement, patch nets, corner schemes.

Everything here works on *local* complexes (:class:`ccproof.mesh.rules.Complex`: the faces around
one face, in local vertex labels, with their tags) in exact rational arithmetic, and produces the
float tables that :mod:`ccproof.evaluate.surface` (quad meshes) and :mod:`ccproof.evaluate.tagged`
(tagged polygon meshes) evaluate; both use these functions, and the rules of
:mod:`ccproof.mesh.rules`.

* :func:`canonical_ring`: the *ring of a face* (all faces sharing a vertex with it, or the
  two-ring) listed by a deterministic walk that starts at a chosen corner; :func:`ring_key` its
  tagged key (faces, tags at the rule vertices, options). Two rings with the same key are
  isomorphic; the key is the cache key of every exact computation.
* :func:`refine_key`: one exact tagged Catmull-Clark step of a ring (:func:`ccproof.mesh.rules.refine_complex`).
* :func:`regular_net`: the 4 x 4 B-spline net of a face whose corners are regular (smooth of valence
  4, crease with two faces on the face's side, corner with one), rows across sharp and boundary
  edges completed by the ghost points ``2 B - I`` (which reproduce the crease rules exactly).
* :func:`corner_scheme`: for a face with one irregular corner whose ring is *stationary* (the ring
  of its child at that corner has the same key), the exact matrix ``A`` of Stam 1998 (for an
  interior vertex of valence k the (2k+8) x (2k+8) subdivision matrix of the face's one-ring),
  the exact limit mask ``l`` (left eigenvector of eigenvalue 1), and for every layer ``n`` (bmz04
  Fig. 3, R4) the three nets ``M_j A^n`` of the patches P_1, P_2, P_3 of layer n, stored as
  exact-then-rounded deviations ``D_{n,j} = M_j A^n - 1 l^T``.
"""

from __future__ import annotations

import functools
import itertools
import math

import numpy as np

from ccproof.errors import MeshError
from ccproof.evaluate import _diskcache, _powers
from ccproof.mesh.rules import CORNER, CREASE, SMOOTH, Complex, Options, refine_complex, to_float, vertex_rule

__all__ = [
    "canonical_ring",
    "quad_ring",
    "ring_key",
    "refine_key",
    "regular_net",
    "corner_is_regular",
    "corner_scheme",
    "CornerScheme",
    "CORNERS",
]

CORNERS = ((0, 0), (1, 0), (1, 1), (0, 1))

#: smallest deviation kept in a layer table: beyond it the layer equals the limit point in float64
LAYER_TOLERANCE = 2.0**-60
#: hard cap on the number of layers of one corner table
MAX_LAYERS = 400


def _group_eigenvalues(vals, tol):
    """Consecutive eigenvalues (sorted by modulus) within ``tol`` of their group's first one, as lists
    (a defective pair splits by ~sqrt(eps), so it lands in one group)."""
    groups = []
    for z in vals:
        if groups and abs(groups[-1][0] - z) < tol:
            groups[-1].append(z)
        else:
            groups.append([z])
    return groups


def _lin(*terms):
    """Linear combination of stencils: ``_lin((c1, s1), (c2, s2), ...)``."""
    out = {}
    for c, s in terms:
        for v, w in s.items():
            out[v] = out.get(v, 0) + c * w
    return {v: w for v, w in out.items() if w != 0}



def _stencil_matrix(stencils, ncols):
    """Dense float matrix of exact stencils (dict column -> weight), each entry correctly rounded."""
    rows, cols, vals = [], [], []
    for r, s in enumerate(stencils):
        rows.extend([r] * len(s))
        cols.extend(s)
        vals.extend(s.values())
    M = np.zeros((len(stencils), ncols))
    M[rows, cols] = [to_float(w) for w in vals]  # the columns of one stencil are distinct
    return M


# ------------------------------------------------------------------------------ local rings
def canonical_ring(cx, g, r, depth=1):
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

    Examples
    --------
    >>> from ccproof.mesh.examples import k_regular_disk
    >>> from ccproof.mesh.rules import Complex, Options
    >>> cx = Complex(k_regular_disk(5, 3).faces, {}, {}, Options())
    >>> ring, faces, nr = canonical_ring(cx, 0, 0)
    >>> len(ring), len(faces), faces[0], nr       # Stam's 2k+8 points for k = 5
    (18, 10, (0, 1, 2, 3), 4)
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
            if len(walk) > _BIG_FAN and isinstance(org, memoryview):  # (the centre of an n-gon)
                _read_fan(cx, walk, seen, pos, ring, first_corner, faces)
                continue
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


#: fans longer than this are read with array operations (:func:`_read_fan`)
_BIG_FAN = 48


def _read_fan(cx, walk, seen, pos, ring, first_corner, faces):
    """The face-reading step of :func:`canonical_ring` for one long fan ``walk`` (corners), on arrays: the
    same faces, labels and first corners as the loop there (each new face read from its corner in the walk,
    new vertices numbered by first appearance), at a cost linear in the fan with a small constant."""
    org = np.asarray(cx.org)
    start = np.asarray(cx.start)
    W = np.array(walk, dtype=np.int64)
    H = np.asarray(cx.face_of)[W]
    faces_h, first_h = np.unique(H, return_index=True)  # each face once, from its first corner in the walk
    keep = np.sort(first_h[~np.isin(faces_h, np.fromiter(seen, dtype=np.int64, count=len(seen)))])
    seen.update(faces_h.tolist())
    W, H = W[keep], H[keep]
    sh = start[H]
    nxt_start = np.where(H + 1 < start.size, start[np.minimum(H + 1, start.size - 1)], org.size)
    k = nxt_start - sh
    ends = np.cumsum(k)
    rep = np.repeat(np.arange(k.size), k)
    hc = sh[rep] + (W[rep] - sh[rep] + np.arange(ends[-1] if k.size else 0) - (ends - k)[rep]) % k[rep]
    U = org[hc]
    uniq, first, inv = np.unique(U, return_index=True, return_inverse=True)
    order = np.argsort(first, kind="stable")  # the vertices by first appearance
    us = uniq[order].tolist()
    known = np.fromiter(map(pos.get, us, itertools.repeat(-1)), dtype=np.int64, count=len(us))
    new = np.flatnonzero(known < 0)  # labelled in order of first appearance after the ring so far
    known[new] = np.arange(len(ring), len(ring) + new.size)
    fresh = uniq[order[new]].tolist()
    pos.update(zip(fresh, known[new].tolist()))
    ring.extend(fresh)
    first_corner.update(zip(fresh, hc[first[order[new]]].tolist()))
    lab = np.empty(uniq.size, dtype=np.int64)
    lab[order] = known
    L = lab[inv.reshape(-1)]
    if k.size and (k == k[0]).all():  # (all quads: one reshape)
        faces.extend(map(tuple, L.reshape(-1, int(k[0])).tolist()))
        return
    L, b = L.tolist(), [0] + ends.tolist()
    faces.extend(tuple(L[b[i]:b[i + 1]]) for i in range(k.size))


def quad_ring(faces, f, r):
    """The canonical one-ring of quad ``f`` of an untagged quad mesh, read from its corner ``r``.

    Parameters
    ----------
    faces : array_like of int, shape (m, 4)
    f, r : int

    Returns
    -------
    ring : list of int
        Vertex labels in canonical order (``ring[0]`` is corner ``r`` of ``f``).
    key : tuple
        The tagged key (:func:`ring_key`) of the ring: the key of :func:`corner_scheme`.

    Examples
    --------
    >>> from ccproof.mesh.examples import k_regular_disk
    >>> ring, key = quad_ring(k_regular_disk(5, 3).faces, 0, 0)
    >>> len(ring), len(key[0]), key[0][0]       # Stam's 2k+8 points for k = 5
    (18, 10, (0, 1, 2, 3))
    """
    cx = Complex(faces, {}, {}, Options())
    ring, fk, nr = canonical_ring(cx, f, r)
    return ring, ring_key(cx, ring, fk, nr)


def ring_key(cx, ring, faces, n_rule):
    """Tagged key of a ring: faces, sharpness of edges at rule vertices, their vertex sharpness.

    Parameters
    ----------
    cx : Complex
        The complex the ring was read from (:func:`canonical_ring`).
    ring : list of int
        Vertex labels of ``cx`` in canonical order.
    faces : tuple of tuple of int
        The ring's faces in canonical (local) labels.
    n_rule : int
        Number of leading ring vertices whose rules are computed (their tags enter the key).

    Returns
    -------
    tuple
        ``(faces, edge_tags, vertex_tags, options)``: ``edge_tags`` are ``((a, b), s)`` with local
        labels ``a < b`` and sharpness ``s`` (``inf`` from 10 on, OpenSubdiv's infinite sharpness),
        boundary edges left out (sharp by the topology); ``vertex_tags`` are ``(i, s)``;
        ``options`` is :meth:`ccproof.mesh.rules.Options.key`. Equal keys have equal exact
        subdivision data (docs/evaluate.md "Method", item 2).

    Examples
    --------
    A crease of sharpness 2 on the edge from the centre of the 5-regular disk:

    >>> from ccproof.mesh.examples import k_regular_disk
    >>> from ccproof.mesh.rules import Complex, Options
    >>> cx = Complex(k_regular_disk(5, 3).faces, {(0, 1): 2.0}, {}, Options())
    >>> ring, faces, nr = canonical_ring(cx, 0, 0)
    >>> ring_key(cx, ring, faces, nr)[1:3]
    ((((0, 1), 2.0),), ())
    """
    tags = []
    if len(cx.edge_sharpness):  # (no edge tags, as around an n-gon of an untagged mesh: nothing to look up)
        _edge_tags(cx, ring, faces, n_rule, tags)
    vs = []
    for i in range(n_rule):
        s = cx.vertex_sharpness.get(ring[i], 0.0)
        if s > 0.0:
            vs.append((i, math.inf if s >= 10.0 else s))
    return (faces, tuple(sorted(tags)), tuple(vs), cx.options.key())


def _edge_tags(cx, ring, faces, n_rule, tags):
    """Append ``(local edge, sharpness)`` of the tagged interior edges at the ``n_rule`` rule vertices."""
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
            s = cx.edge_sharpness.get(gk, 0.0)
            if s > 0.0 and cx.twin[cx.edges[cx.edge_index[gk]]] >= 0:  # boundary edges: sharp by the topology
                tags.append((e, math.inf if s >= 10.0 else s))


@functools.lru_cache(maxsize=8192)
def key_complex(key):
    """The complex of a ring key (shared by the functions cached per key; not to be modified)."""
    faces, tags, vs, opts = key
    return Complex(faces, dict(tags), dict(vs), Options(*opts), level=1)


def has_semi_sharp(key):
    """Whether the ring ``key`` has a semi-sharp (finite, positive sharpness) edge or vertex tag."""
    return any(0.0 < s < math.inf for _, s in key[1]) or any(0.0 < s < math.inf for _, s in key[2])


@functools.lru_cache(maxsize=8192)
def refine_key(key, n_rule):
    """One exact tagged step of the ring ``key``, computing the rules at its ``n_rule`` rule vertices.

    Parameters
    ----------
    key : tuple
        A ring key (:func:`ring_key`) with N ring vertices.
    n_rule : int
        The rules are computed at ring vertices ``0 .. n_rule - 1`` and at the edges touching them.

    Returns
    -------
    S : ndarray or scipy.sparse.csr_matrix, shape (n_points, N)
        Float stencils (dense: local complexes are small, but for rings of ``SPARSE_RING`` points or more,
        the centre of a large n-gon), rows of uncomputable points NaN.
        Row v < N is the vertex point of ring vertex v (docs/evaluate.md "Conventions").
    stencils : tuple of dict or None (exact)
    child : Complex
        The children of all faces, with the child tags (positions are not part of it).

    Notes
    -----
    The rules of :mod:`ccproof.mesh.rules` in exact rationals (bmz04 Fig. 1, docs/readings.md R1).

    Examples
    --------
    At the centre of valence k = 5 the vertex point keeps ``1 - 7 / (4k) = 13/20`` of the old vertex
    (``(F + 2R + (k - 3)V) / k``, R1), and every stencil sums to 1:

    >>> import numpy as np
    >>> from ccproof.mesh.examples import k_regular_disk
    >>> ring, key = quad_ring(k_regular_disk(5, 3).faces, 0, 0)
    >>> S, stencils, child = refine_key(key, 4)
    >>> S.shape, stencils[0][0], np.nansum(S, axis=1)[:4].tolist()
    ((55, 18), 13/20, [1.0, 1.0, 1.0, 1.0])
    """
    cx = key_complex(key)
    rule = range(n_rule)
    edges = [e for e, h in enumerate(cx.edges) if cx.org[h] < n_rule or cx.dst(h) < n_rule]
    stencils, children, ces, cvs = refine_complex(cx, vertices=rule, edges=edges)
    child = Complex(children, ces, cvs, cx.options, level=2, n_vertices=len(stencils))
    if cx.n_vertices >= SPARSE_RING:
        return _sparse_stencils(stencils, cx.n_vertices), tuple(stencils), child
    S = _stencil_matrix([{} if st is None else st for st in stencils], cx.n_vertices)
    S[[i for i, st in enumerate(stencils) if st is None]] = np.nan
    S.setflags(write=False)
    return S, tuple(stencils), child


#: rings of at least this many points (the centre of an n-gon, n >= 124) keep their float stencils sparse
SPARSE_RING = 256


def _sparse_stencils(stencils, ncols):
    """The float stencils as a sparse matrix (``scipy.sparse.csr_matrix``), a row of an uncomputable point
    one NaN (so that ``S @ X`` is NaN in that row, as with the dense NaN row)."""
    import scipy.sparse

    rows, cols, vals = [], [], []
    for r, st in enumerate(stencils):
        if st is None:
            rows.append(r)
            cols.append(0)
            vals.append(math.nan)
            continue
        rows.extend([r] * len(st))
        cols.extend(st)
        vals.extend(to_float(w) for w in st.values())
    return scipy.sparse.csr_matrix((vals, (rows, cols)), shape=(len(stencils), ncols))


@functools.lru_cache(maxsize=1 << 16)
def child_ring(key, n_rule, g, r, depth):
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

    Parameters
    ----------
    cx : Complex
    c : int
        A half-edge (corner) of ``cx``: corner i of face g is ``cx.start[g] + i``.

    Returns
    -------
    bool

    Examples
    --------
    Face 0 of the 5-regular disk has its corner 0 at the centre (valence 5); the others have valence 4:

    >>> from ccproof.mesh.examples import k_regular_disk
    >>> from ccproof.mesh.rules import Complex, Options
    >>> cx = Complex(k_regular_disk(5, 3).faces, {}, {}, Options())
    >>> [corner_is_regular(cx, cx.start[0] + i) for i in range(4)]
    [False, True, True, True]
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


#: per side s of a face, in its 4 x 4 net's (i, j) positions: the two net points across side s, the diagonal point
#: beyond corner s, and the unit step from that side towards the face (the ghost points' direction)
SIDES = (
    ((1, 0), (2, 0), (0, 0), (0, 1)),
    ((3, 1), (3, 2), (3, 0), (-1, 0)),
    ((2, 3), (1, 3), (3, 3), (0, -1)),
    ((0, 2), (0, 1), (0, 3), (1, 0)),
)
#: the (i, j) net position of each corner of the face
CENTER = ((1, 1), (2, 1), (2, 2), (1, 2))


def regular_net(cx, g):
    """The 4 x 4 B-spline net of quad ``g`` as integer stencils, or None if a corner is irregular.

    Rows across infinitely sharp edges (and boundary edges) of the face are ghost points
    ``2 B - I``; at a corner-rule corner the diagonal ghost is ``4 V - 2 E1 - 2 E2 + D``.

    Parameters
    ----------
    cx : Complex
    g : int
        A quad of ``cx``.

    Returns
    -------
    list of dict or None
        16 stencils ``{vertex: integer weight}``, net point ``i + 4 j`` (i along the face's u),
        as :func:`ccproof.evaluate.bspline.eval_patches` takes them; None if a corner is irregular
        (:func:`corner_is_regular`). docs/evaluate.md "Method", item 1.

    Examples
    --------
    On the 4 x 4 grid (vertex ``i + 5 j`` at (i, j)) the net of the inner face 5 is the 4 x 4 block of
    vertices around it; face 1 on the boundary gets the ghost row ``2 B - I``; the corner face 0 has a
    boundary vertex with one face, which is irregular:

    >>> from ccproof.mesh.examples import grid
    >>> from ccproof.mesh.rules import Complex, Options
    >>> cx = Complex(grid(4, 4).faces, {}, {}, Options())
    >>> regular_net(cx, 5) == [{i + 5 * j: 1} for j in range(4) for i in range(4)]
    True
    >>> regular_net(cx, 1)[:2], regular_net(cx, 0)
    ([{0: 2, 5: -1}, {1: 2, 6: -1}], None)
    """
    s0 = cx.start[g]
    if not all(corner_is_regular(cx, s0 + i) for i in range(4)):
        return None
    fv = [cx.org[s0 + s] for s in range(4)]
    grid = {}
    for s in range(4):
        grid[CENTER[s]] = {fv[s]: 1}
    bnd = [cx.sharpness(cx.he_edge[s0 + s]) > 0.0 for s in range(4)]
    for s in range(4):
        if not bnd[s]:
            t = cx.twin[s0 + s]
            grid[SIDES[s][0]] = {cx.dst(cx.nxt[t]): 1}
            grid[SIDES[s][1]] = {cx.org[cx.prv[t]]: 1}

    def ghost(p, nrm):
        q = (p[0] + nrm[0], p[1] + nrm[1])
        r = (p[0] + 2 * nrm[0], p[1] + 2 * nrm[1])
        return _lin((2, grid[q]), (-1, grid[r]))

    for s in range(4):
        if bnd[s]:
            for p in SIDES[s][:2]:
                grid[p] = ghost(p, SIDES[s][3])
    for s in range(4):
        sp, sm = s, (s + 3) % 4
        p = SIDES[s][2]
        if not bnd[sp] and not bnd[sm]:
            t = cx.twin[s0 + s]
            t2 = cx.twin[cx.nxt[t]]
            if t2 < 0:
                return None
            grid[p] = {cx.org[cx.prv[t2]]: 1}
        else:
            grid[p] = ghost(p, SIDES[sp if bnd[sp] else sm][3])
    return [grid[(i, j)] for j in range(4) for i in range(4)]


@functools.lru_cache(maxsize=8192)
def regular_net_matrix(key):
    """Float (16, N) matrix of the regular net of face 0 of the ring ``key``, or None."""
    cx = key_complex(key)
    net = regular_net(cx, 0)
    if net is None:
        return None
    return _stencil_matrix(net, cx.n_vertices)


@functools.lru_cache(maxsize=8192)
def irregular_corners(key):
    """The corners of face 0 of the ring ``key`` that are not regular (:func:`corner_is_regular`).

    Parameters
    ----------
    key : tuple
        A ring key (:func:`ring_key`, :func:`quad_ring`).

    Returns
    -------
    tuple of int
        Corner indices in 0..3 (corner 0 is the corner the ring was read from).

    Examples
    --------
    >>> from ccproof.mesh.examples import cube, k_regular_disk
    >>> irregular_corners(quad_ring(k_regular_disk(5, 3).faces, 0, 0)[1])
    (0,)
    >>> irregular_corners(quad_ring(cube().faces, 0, 0)[1])   # eight vertices of valence 3
    (0, 1, 2, 3)
    """
    cx = key_complex(key)
    return tuple(i for i in range(4) if not corner_is_regular(cx, i))


# ------------------------------------------------------------------------------ corner schemes
@functools.lru_cache(maxsize=2048)
def corner_scheme(key):
    """Exact layered-patch data of face 0 of the ring ``key`` (irregular corner 0), cached.

    :func:`_corner_scheme` (the method: self-similar layers, bmz04 section 3, Stam 1998,
    docs/readings.md R4 and R12, docs/evaluate.md "Method", item 2), kept in memory and between runs
    on disk (:func:`_cached_scheme`).

    Parameters
    ----------
    key : tuple
        The tagged one-ring (:func:`canonical_ring`, :func:`ring_key`, :func:`quad_ring`) of a face,
        read from its irregular corner.

    Returns
    -------
    CornerScheme or None
        None unless the configuration is self-similar with regular other children.

    Examples
    --------
    At an interior vertex of valence k the limit mask is ``(k^2 V + 4 sum e + sum d) / (k (k + 5))``:
    1/2, 4/50 and 1/50 for k = 5; the ring has Stam's 2k + 8 = 18 points and the table 70 layers:

    >>> from ccproof.mesh.examples import k_regular_disk
    >>> sch = corner_scheme(quad_ring(k_regular_disk(5, 3).faces, 0, 0)[1])
    >>> sch.size, sch.limit_mask[:3].round(15).tolist(), sch.n_layers
    (18, [0.5, 0.08, 0.02], 70)
    """
    # a module-level function bound by partial (not a lambda): a scheme read from the disk cache keeps it to
    # rebuild its exact A, and pickles with it (a surface sent to the workers of a cluster)
    return _cached_scheme("tagged", key, functools.partial(_corner_scheme, key))


def _corner_scheme(key):
    """Exact layered-patch data of face 0 of the tagged one-ring ``key`` (irregular corner 0).

    Parameters
    ----------
    key : tuple
        The tagged one-ring (:func:`canonical_ring`, :func:`ring_key`) of a face, read from its
        irregular corner.

    Returns
    -------
    CornerScheme or None
        ``None`` unless the configuration is stationary (the tagged one-ring of the child at corner
        0 has the same key) and the three other children are regular patches: such a face must be
        subdivided once more.

    Notes
    -----
    Self-similarity (bmz04 section 3, Stam 1998): with C the control points of the one-ring of the
    face, ``A^n C`` are those of its level-n child at the corner, the square [0, 2^-n]^2. Layer n
    (R4) is that square minus [0, 2^-(n+1)]^2; it consists of the level-(n+1) children at the other
    three corners, regular bicubic patches with nets ``M_j A^n C`` (``M_j``: one step followed by the
    net of child j). The matrices are built exactly (flint ``fmpq_mat``); ``A^n`` is never rounded,
    only the final deviations ``M_j A^n - 1 l^T``, whose entries decay like lam^n: they keep full
    relative precision at every layer, so the derivatives (which grow like (2 lam)^n, bmz04 eq. 3)
    are as accurate deep down as near the face centre. The limit mask is exact.
    """
    _, stencils, child = refine_key(key, 4)
    N = key_complex(key).n_vertices
    ring1, faces1, nr = canonical_ring(child, 0, 0, 1)
    key1 = ring_key(child, ring1, faces1, nr)
    if key1 != key:
        return None
    rows = [stencils[v] for v in ring1]
    if any(r is None for r in rows):
        return None
    nets = _child_nets(child, stencils)
    if nets is None:
        return None
    support = set()
    for row in nets:
        support.update(row)
    support = _powers.closure(rows, support)  # the rows of A at the support use only the support
    lmask = _limit_mask(rows, N)
    layers = _powers.class_layers(nets, rows, lmask, N, LAYER_TOLERANCE, MAX_LAYERS)
    if layers is None:
        raise MeshError(f"corner configuration of {N} vertices does not converge to its limit point")
    mask = np.array([int(w.p) / int(w.q) for w in map(_fmpq, lmask)], dtype=np.float64)
    A = functools.partial(_to_fmpq_mat, rows, N)  # exact A: built on first use (tangent masks)
    return CornerScheme(N, A, mask, layers.reshape(-1, 3, 16, N), support)


def _fmpq(w):
    import flint  # imported where exact matrices are built: not on a filled disk cache
    return flint.fmpq(w)


def _child_nets(child, stencils):
    """The 48 exact stencils (in the parent ring) of the nets of children 1, 2, 3, or None if irregular."""
    nets = []
    for j in (1, 2, 3):
        net = regular_net(child, j)
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
    return nets


#: rings up to this size solve for the limit mask densely (exact, and it detects a multiple eigenvalue 1);
#: larger ones (the centre of an n-gon, n > 28) on the quotient of an equitable partition (3 x 3 there)
DENSE_RING = 64


def _limit_mask(rows, N):
    """The exact limit mask (list of fmpq) of ring vertex 0 of the subdivision matrix with rows ``rows``."""
    import flint  # imported where exact matrices are built: not on a filled disk cache
    if N > DENSE_RING:
        lm = _powers.limit_mask(rows, N)
        if lm is not None:
            return lm
    A = _to_fmpq_mat(rows, N)
    Bt = (A - flint.fmpq_mat(N, N, [int(i == j) for i in range(N) for j in range(N)])).transpose()
    for j in range(N):
        Bt[N - 1, j] = 1
    rhs = flint.fmpq_mat(N, 1, [0] * (N - 1) + [1])
    try:
        lvec = Bt.solve(rhs)
    except ZeroDivisionError:
        raise MeshError("corner configuration whose subdivision matrix has a multiple eigenvalue 1") from None
    return [lvec[i, 0] for i in range(N)]


def _to_fmpq_mat(rows, ncols):
    import flint  # imported where exact matrices are built: not on a filled disk cache
    M = flint.fmpq_mat(len(rows), ncols)
    for i, s in enumerate(rows):
        for j, w in s.items():
            M[i, j] = w  # exact: int or flint.fmpq
    return M


def _fmpq_mat_to_float(M):
    """Correctly rounded float matrix of an exact one (common denominator, Python int true division)."""
    num, den = M.numer_denom()
    q = int(den)
    out = np.array([int(p) / q for p in num.entries()], dtype=np.float64)
    return out.reshape(M.nrows(), M.ncols())


#: what computes the data
_SOURCES = ("evaluate/local.py", "evaluate/_powers.py", "evaluate/_diskcache.py", "mesh/rules.py", "mesh/complex.py",
            "mesh/crease.py", "mesh/scheme.py", "rule_weights.py")


@functools.lru_cache(maxsize=1)
def code_version():
    """Hash of the sources that define the exact data (a change invalidates the disk cache)."""
    import hashlib
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]
    h = hashlib.sha256()
    for rel in _SOURCES:
        h.update((root / rel).read_bytes())
    return h.hexdigest()[:16]



def _cached_scheme(kind, key, compute):
    """``compute()`` (a CornerScheme or None), kept between runs in a disk cache.

    The cache (default ``~/.cache/ccproof/corner_schemes``; environment variable
    ``CCPROOF_CACHE`` = another folder, or ``off``) holds two files per configuration, named by
    the SHA-256 of the configuration key and of the sources that compute it: ``.f64``, one raw
    little-endian float64 vector ``[N, n_layers, n_support, limit mask (N), support, layers]``
    (read at setup), and ``.A``, the exact matrix ``A`` (its denominator and integer numerators in
    decimal, read only when the tangent masks need it; written at once only for rings of at most
    ``DENSE_RING`` points, larger ones when first needed). Both are sealed
    (:mod:`ccproof.evaluate._diskcache`: the SHA-256 of the name and the content follows the
    content, checked before any use): a cached scheme is the computed one bit for bit, and a corrupt
    file is reported once, recomputed and rewritten. Unreadable or unwritable cache files are
    ignored (the data are then computed).
    """
    import hashlib

    d = _diskcache.cache_dir()
    if d is None:
        return compute()
    name = hashlib.sha256(f"{kind}|{code_version()}|{key!r}".encode()).hexdigest()
    path, apath = d / f"{name}.f64", d / f"{name}.A"
    sch = _diskcache.read_entry(path, name, functools.partial(_parse_scheme, apath=apath, name=name, compute=compute))
    if sch is not None:
        return sch
    sch = compute()
    if sch is None:
        return None
    if sch.size <= DENSE_RING:  # a larger exact A (N^2 entries) is rebuilt if the tangent masks need it
        num, den = sch.A.numer_denom()
        _diskcache.store(d, name, ".A", _matrix_bytes(num, den))
    sup = list(sch.support) if sch.support else []
    head = np.array([sch.size, sch.n_layers, len(sup)] + sup, dtype=np.float64)
    vec = np.concatenate([head[:3], sch.limit_mask, head[3:], sch.layers.reshape(-1)]).astype("<f8")
    _diskcache.store(d, name, ".f64", vec.tobytes())
    return sch


def _parse_scheme(body, apath, name, compute):
    """The CornerScheme of a verified ``.f64`` body (ValueError if its sizes disagree)."""
    z = np.frombuffer(bytearray(body), dtype="<f8")
    if z.size < 3 or not all(0 <= x < 2**31 and x == int(x) for x in z[:3]):
        raise ValueError("bad header")
    N, nl, ns = (int(x) for x in z[:3])
    if z.size != 3 + N + ns + nl * 48 * N:
        raise ValueError("sizes do not match its header")
    mask = z[3:3 + N]  # views of the freshly read vector
    sup = [int(i) for i in z[3 + N:3 + N + ns]]
    layers = z[3 + N + ns:].reshape(nl, 3, 16, N)
    # the exact A is only needed for the tangent masks: read and converted on first use
    loader = functools.partial(_cached_exact_matrix, apath, name, N, compute)
    return CornerScheme(N, loader, mask, layers, sup or None)


def _matrix_bytes(num, den):
    """An exact matrix ``num / den`` as ASCII: the denominator, then the numerators row by row."""
    return (str(den) + "\n" + " ".join(str(x) for x in num.entries()) + "\n").encode()


def _matrix_from_bytes(N, body):
    """The exact N x N matrix of :func:`_matrix_bytes` (ValueError if the sizes disagree).

    >>> import flint
    >>> M = flint.fmpq_mat(2, 2, [flint.fmpq(1, 3), 0, 2, flint.fmpq(-5, 6)])
    >>> _matrix_from_bytes(2, _matrix_bytes(*M.numer_denom())) == M
    True
    """
    import flint  # imported where exact matrices are built: not on a filled disk cache

    den, num = bytes(body).decode("ascii").split("\n", 1)
    q, nums = int(den), num.split()
    if len(nums) != N * N or q <= 0:
        raise ValueError("sizes do not match the configuration")
    return flint.fmpq_mat(N, N, [flint.fmpq(int(x), q) for x in nums])


def _cached_exact_matrix(apath, name, N, compute):
    """The exact ``A`` of a cached scheme from its ``.A`` file (recomputed and rewritten if that file
    is missing or corrupt)."""
    A = _diskcache.read_entry(apath, name, functools.partial(_matrix_from_bytes, N))
    if A is None:
        A = compute().A
        _diskcache.store(apath.parent, name, ".A", _matrix_bytes(*A.numer_denom()))
    return A


class CornerScheme:
    """Exact self-similar evaluation data of one corner configuration (see :func:`corner_scheme`).

    Attributes
    ----------
    size : int
        N, the number of vertices of the face's one-ring (2k + 8 at an interior vertex of valence k).
    A : flint.fmpq_mat, shape (N, N)
        Exact subdivision matrix from the one-ring of the face to the one-ring of its child at the
        corner (a scheme read from the disk cache builds it on first access: the parameter may be a
        function returning it).
    limit_mask : ndarray, shape (N,)
        Limit position of the corner vertex (exact left eigenvector of ``A`` for 1, rounded).
    layers : ndarray, shape (n_layers, 3, 16, N)
        ``D[n, j-1] = M_j A^n - 1 l^T`` (exact, then rounded): deviation of the net of patch P_j of
        layer n from the limit point. Layers beyond ``n_layers - 1`` equal the limit point to
        within ``LAYER_TOLERANCE`` times the size of the one-ring.
    support : tuple of int or None
        The ring points the surface over the face depends on (closed under ``A``), when fewer
        than all: across an infinitely sharp crease the other sector is decoupled, and its
        eigenvalues must not enter the tangent plane of this one. ``None``: all points.

    Notes
    -----
    Self-similar layers (bmz04 section 3, Stam 1998; docs/readings.md R4, R12); the limit mask and
    the tangent masks (Halstead et al. 1993 at interior vertices) of docs/evaluate.md "Method",
    item 4.

    Examples
    --------
    The tangent masks at the centre of a 5-regular disk annihilate constants (their entries sum to 0):

    >>> from ccproof.mesh.examples import k_regular_disk
    >>> sch = corner_scheme(quad_ring(k_regular_disk(5, 3).faces, 0, 0)[1])
    >>> isinstance(sch, CornerScheme), sch.layers.shape[1:], bool(abs(sch.tangent_masks.sum(axis=1)).max() < 1e-12)
    (True, (3, 16, 18), True)
    """

    def __init__(self, size, A, limit_mask, layers, support=None):
        self.size = size
        self._A = A
        self.limit_mask = limit_mask
        self.layers = layers
        self.support = None if support is None or len(support) == size else tuple(support)

    @property
    def A(self):
        if callable(self._A):
            self._A = self._A()
        return self._A

    def __getstate__(self):
        """Pickled by value (a surface sent to the workers of a cluster): the exact ``A`` as its loader when it
        was not built yet, else as its exact entries (a flint matrix does not pickle)."""
        state = dict(self.__dict__)
        if not callable(state["_A"]):
            state["_A"] = functools.partial(_matrix_from_bytes, self.size, _matrix_bytes(*state["_A"].numer_denom()))
        return state

    @property
    def n_layers(self):
        return self.layers.shape[0]

    @functools.cached_property
    def tangent_masks(self):
        """Masks of two limit tangents at the corner, shape (2, N), or ``None`` if undetermined.

        The tangent plane at the corner vertex is spanned by the coefficients of the dominant
        eigenfunctions after the constant one: the left eigenvectors of ``A`` of the largest
        eigenvalue below 1, and, if that one is simple, of the next eigenvalue (its true left
        eigenvector when it is defective: the Jordan chain's ``n mu^n`` term dominates there, as at a
        boundary vertex with one face). Computed from the exact ``A`` in 80-digit arithmetic.
        ``None`` when the second eigenspace has several directions (the tangent plane would depend
        on the direction of approach).
        """
        import flint  # imported where exact matrices are built: not on a filled disk cache
        A = self.A
        if self.support is not None:
            idx = self.support
            A = flint.fmpq_mat(len(idx), len(idx), [A[i, j] for i in idx for j in idx])
        T = _tangent_masks_sparse(A) if A.nrows() >= SPARSE_RING else None
        if T is None:
            T = _tangent_masks_float(A)
        if T is None:
            T = _tangent_masks(A)
        if T is None or self.support is None:
            return T
        out = np.zeros((2, self.size))
        out[:, list(self.support)] = T
        return out


def _tangent_masks_sparse(A, k=8):
    """:meth:`CornerScheme.tangent_masks` of a large ring (an n-gon centre), or None (then the dense paths).

    The ``k`` eigenvalues of largest modulus of the rounded ``A`` by Arnoldi iteration on the sparse
    ``A^T`` (ARPACK: cost about linear in the ring, not cubic), grouped within 1e-6; the real span of a
    group's eigenvectors (SVD of their real and imaginary parts). Accepted only when unambiguous, as in
    :func:`_tangent_masks_float`: real groups, one eigenvalue 1, two directions in all, residuals
    ``|x (A - mu)| <= 1e-12 |x|``; a simple eigenvalue with a defective partner (a Jordan chain) is left
    to the dense paths.
    """
    import scipy.sparse
    import scipy.sparse.linalg

    Af = scipy.sparse.csr_matrix(_fmpq_mat_to_float(A))
    try:
        vals, vecs = scipy.sparse.linalg.eigs(Af.T.tocsr(), k=k, which="LM", tol=0)
    except (scipy.sparse.linalg.ArpackError, ValueError):
        return None
    order = np.argsort(-np.abs(vals), kind="stable")
    vals, vecs = vals[order], vecs[:, order]
    masks, i = [], 0
    for g in _group_eigenvalues(list(vals), 1e-6):
        idx = list(range(i, i + len(g)))
        i += len(g)
        mu = sum(g) / len(g)
        if abs(mu - 1) < 1e-9:
            if len(g) != 1:
                return None
            continue
        if abs(mu.imag) > 1e-9 or i == len(vals):  # complex, or possibly a group cut off by k
            return None
        V = np.vstack([vecs[:, idx].real.T, vecs[:, idx].imag.T])
        _, S, Wt = np.linalg.svd(V, full_matrices=False)
        span = [Wt[j] for j in range(len(S)) if S[j] > 1e-8 * S[0]]
        if len(span) != len(g) or (masks and len(span) > 1):
            return None
        for x in span[: 2 - len(masks)]:
            if np.linalg.norm(Af.T @ x - mu.real * x) > 1e-12 * np.linalg.norm(x):
                return None
            masks.append(x)
        if len(masks) == 2:
            return np.array(masks)
    return None


def _tangent_masks_float(A):
    """:meth:`CornerScheme.tangent_masks` in double precision, or None (then the 80-digit path decides).

    Eigenvalues of the rounded ``A`` (numpy), grouped within 1e-6 (a defective pair splits by about
    sqrt(eps)); the left null vectors of ``A - mu`` for the group mean ``mu`` by SVD (singular
    values below 1e-9). Accepted only when every step is unambiguous: real groups, the expected
    null-space dimensions, and residuals ``|x (A - mu)| <= 1e-12 |x|``.
    """
    Af = _fmpq_mat_to_float(A)
    N = Af.shape[0]
    vals = np.linalg.eigvals(Af)
    vals = vals[np.argsort(-np.abs(vals), kind="stable")]
    groups = _group_eigenvalues(vals, 1e-6)
    masks = []
    for g in groups:
        mu = sum(g) / len(g)
        if abs(mu - 1) < 1e-9:
            continue
        if abs(mu.imag) > 1e-9:
            return None
        B = Af.T - mu.real * np.eye(N)
        _, S, Vt = np.linalg.svd(B)
        null = [i for i in range(N) if S[i] < 1e-9]
        if not null or (masks and len(null) > 1):
            return None
        for i in null[: 2 - len(masks)]:
            x = Vt[i]
            if np.linalg.norm(x @ Af - mu.real * x) > 1e-12 * np.linalg.norm(x):
                return None
            masks.append(x)
        if len(masks) == 2:
            return np.array(masks)
    return None


def _tangent_masks(A):
    import mpmath

    with mpmath.workdps(80):
        N = A.nrows()
        M = mpmath.matrix([[mpmath.mpf(int(x.p)) / int(x.q) for x in row] for row in A.tolist()])
        E = mpmath.eig(M.T, left=False, right=False)
        vals = sorted(E, key=lambda z: -abs(z))
        # group numerically equal eigenvalues (a defective pair splits by ~sqrt(eps))
        groups = _group_eigenvalues(vals, 1e-15)
        masks = []
        for g in groups:
            mu = sum(g) / len(g)
            if abs(mu - 1) < 1e-12:
                continue
            if abs(mpmath.im(mu)) > 1e-12:
                return None
            B = M.T - mpmath.re(mu) * mpmath.eye(N)
            U, S, V = mpmath.svd_r(B)
            null = [i for i in range(N) if abs(S[i]) < mpmath.mpf(10) ** -25]
            if not null:
                return None
            if masks and len(null) > 1:
                return None
            for i in null[: 2 - len(masks)]:
                masks.append([float(V[i, j]) for j in range(N)])
            if len(masks) == 2:
                return np.array(masks)
    return None
