"""Exact local Catmull-Clark machinery: one-rings of faces, exact local refinement, patch nets.

Everything here works on *local* quad complexes (the faces around one face, in local vertex
labels) in exact rational arithmetic, and produces the float tables that
:mod:`ccproof.evaluate.surface` evaluates.

* :class:`LocalTopology`: half-edges of any list of consistently oriented quads (no validation;
  a local complex cut out of a valid mesh is consistent, though its outer vertices may look like
  boundary or non-manifold vertices: their rules are never used).
* :func:`canonical_ring`: the *one-ring of a face* (all faces sharing a vertex with it) listed by a
  deterministic walk that starts at a chosen corner. Two rings with the same key are isomorphic,
  and the key is the local face list itself: it is the cache key of every exact computation.
* :func:`refine_exact`: one Catmull-Clark step (R1, boundary rules of :mod:`ccproof.mesh.subdivision`)
  as exact :class:`fractions.Fraction` stencils, in the layout of :mod:`ccproof.mesh.subdivision`.
* :func:`regular_net`: the 4 x 4 B-spline net of a face whose four vertices are regular (interior
  of valence 4, or boundary with two faces), boundary rows completed by the ghost points
  ``2 B - I`` (which reproduce the boundary rules exactly).
* :func:`corner_scheme`: for a face with one irregular corner whose one-ring is *self-similar*
  (the one-ring of its child at that corner is isomorphic to its own), the exact matrix ``A`` of
  Stam 1998 (for an interior vertex of valence k the (2k+8) x (2k+8) subdivision matrix of the
  face's one-ring), the exact limit mask ``l`` (left eigenvector of eigenvalue 1), and for every
  layer ``n`` (bmz04 Fig. 3, R4) the three nets ``M_j A^n`` of the patches P_1, P_2, P_3 of layer n,
  stored as exact-then-rounded deviations ``D_{n,j} = M_j A^n - 1 l^T``.
"""

from __future__ import annotations

import functools
from fractions import Fraction

import flint
import numpy as np

from ccproof.errors import MeshError

__all__ = [
    "LocalTopology",
    "canonical_ring",
    "refine_exact",
    "regular_net",
    "corner_scheme",
    "CornerScheme",
    "CORNERS",
]

#: parameter positions of the four corners of a face (ptex convention)
CORNERS = ((0, 0), (1, 0), (1, 1), (0, 1))

#: smallest deviation kept in a layer table: beyond it the layer equals the limit point in float64
LAYER_TOLERANCE = 2.0**-60
#: hard cap on the number of layers of one corner table
MAX_LAYERS = 400


class LocalTopology:
    """Half-edge topology of a list of consistently oriented quads.

    Parameters
    ----------
    faces : array_like of int, shape (m, 4)
        Vertex labels need not be contiguous.

    Notes
    -----
    Half-edge / corner ``h = 4 f + i`` runs from ``faces[f, i]`` to ``faces[f, (i+1) % 4]``.
    """

    def __init__(self, faces):
        F = np.asarray(faces, dtype=np.int64).reshape(-1, 4)
        self.faces = F
        self.flat = F.reshape(-1).tolist()
        org = F.reshape(-1)
        dst = np.roll(F, -1, axis=1).reshape(-1)
        nv = int(F.max()) + 1
        key = org * nv + dst
        rev = dst * nv + org
        order = np.argsort(key, kind="stable")
        pos = np.searchsorted(key[order], rev)
        pos = np.minimum(pos, key.size - 1)
        hit = key[order][pos] == rev
        twin = np.where(hit, order[pos], -1)
        self.twin = twin.tolist()
        self.n_vertices = nv
        corners = [[] for _ in range(nv)]
        for h, v in enumerate(self.flat):
            corners[v].append(h)
        self.corners = corners

    @staticmethod
    def next(h):
        return h - h % 4 + (h + 1) % 4

    @staticmethod
    def prev(h):
        return h - h % 4 + (h + 3) % 4

    def org(self, h):
        return self.flat[h]

    def dst(self, h):
        return self.flat[self.next(h)]

    def ccw(self, c):
        """Next corner counter-clockwise around the same vertex, or -1."""
        return self.twin[self.prev(c)]

    def cw(self, c):
        """Next corner clockwise around the same vertex, or -1."""
        t = self.twin[c]
        return -1 if t < 0 else self.next(t)

    def fan(self, start):
        """Corners around ``org(start)``: counter-clockwise from ``start``, then (open fan) clockwise.

        Returns
        -------
        corners : list of int
        closed : bool
        """
        out = [start]
        c = self.ccw(start)
        while c >= 0 and c != start:
            out.append(c)
            c = self.ccw(c)
        if c == start:
            return out, True
        c = self.cw(start)
        while c >= 0:
            out.append(c)
            c = self.cw(c)
        return out, False

    def ordered_fan(self, v):
        """Fan of vertex ``v`` in counter-clockwise order (open fans start at the clockwise end).

        Returns ``(corners, closed)``, or ``(None, None)`` if the faces at ``v`` form several fans.
        """
        cs = self.corners[v]
        fan, closed = self.fan(cs[0])
        if len(fan) != len(cs):
            return None, None
        if not closed:
            c = cs[0]
            while self.cw(c) >= 0:
                c = self.cw(c)
            fan, _ = self.fan(c)
        return fan, closed

    def is_regular(self, v):
        """Interior with four faces, or boundary with two faces."""
        fan, closed = self.ordered_fan(v)
        if fan is None:
            return False
        return len(fan) == (4 if closed else 2)


def group_eigenvalues(vals, tol):
    """Consecutive eigenvalues (sorted by modulus) within ``tol`` of their group's first one, as lists
    (a defective pair splits by ~sqrt(eps), so it lands in one group)."""
    groups = []
    for z in vals:
        if groups and abs(groups[-1][0] - z) < tol:
            groups[-1].append(z)
        else:
            groups.append([z])
    return groups

def canonical_ring(topo, f, r):
    """The one-ring of face ``f`` listed from its corner ``r``.

    The walk: the four vertices of ``f`` from corner ``r``; then for each of them in that order,
    the faces around it counter-clockwise from ``f`` (for an open fan, then clockwise from ``f``),
    each face read from that vertex on; vertices are numbered by first appearance.

    Parameters
    ----------
    topo : LocalTopology
    f, r : int

    Returns
    -------
    ring : list of int
        Vertex labels of ``topo`` in canonical order (``ring[0]`` is corner ``r`` of ``f``).
    key : tuple of tuple of int
        The faces of the one-ring in canonical labels; ``key[0] == (0, 1, 2, 3)`` is ``f``.
    faces : list of int
        The faces of ``topo`` in the same order as ``key``.

    Examples
    --------
    >>> from ccproof.mesh.examples import k_regular_disk
    >>> ring, key, _ = canonical_ring(LocalTopology(k_regular_disk(5, 3).faces), 0, 0)
    >>> len(ring), len(key), key[0]       # Stam's 2k+8 points for k = 5
    (18, 10, (0, 1, 2, 3))
    """
    pos = {}
    ring = []

    def add(v):
        if v not in pos:
            pos[v] = len(ring)
            ring.append(v)

    fv = [topo.flat[4 * f + (r + i) % 4] for i in range(4)]
    for v in fv:
        add(v)
    key, faces, seen = [], [], set()
    for i in range(4):
        fan, _ = topo.fan(4 * f + (r + i) % 4)
        for c in fan:
            g = c // 4
            if g in seen:
                continue
            seen.add(g)
            vs = [topo.flat[4 * g + (c + t) % 4] for t in range(4)]
            for v in vs:
                add(v)
            key.append(tuple(pos[v] for v in vs))
            faces.append(g)
    return ring, tuple(key), faces


def _lin(*terms):
    """Linear combination of stencils: ``_lin((c1, s1), (c2, s2), ...)``."""
    out = {}
    for c, s in terms:
        for v, w in s.items():
            out[v] = out.get(v, 0) + c * w
    return {v: w for v, w in out.items() if w != 0}


@functools.lru_cache(maxsize=4096)
def local_edges(key):
    """Edges of the local complex ``key`` in the order of :func:`refine_exact` (first half-edge seen).

    Returns
    -------
    edges : tuple of int
        One half-edge ``4 f + i`` per edge (from ``key[f][i]`` to ``key[f][(i+1) % 4]``).
    edge_of_halfedge : tuple of int
    """
    eid, edges, he_edge = {}, [], []
    for f, face in enumerate(key):
        for i in range(4):
            a, b = face[i], face[(i + 1) % 4]
            e = (min(a, b), max(a, b))
            if e not in eid:
                eid[e] = len(edges)
                edges.append(4 * f + i)
            he_edge.append(eid[e])
    return tuple(edges), tuple(he_edge)


@functools.lru_cache(maxsize=4096)
def refine_exact(key):
    """One exact Catmull-Clark step of the local complex ``key`` (faces in labels 0..N-1).

    Returns
    -------
    stencils : tuple of (dict[int, Fraction] or None)
        New vertex ``i`` as a combination of old vertices; layout of
        :mod:`ccproof.mesh.subdivision` (vertex points, edge points, face points). ``None`` for the
        vertex point of a vertex whose faces form several fans in the local complex.
    children : tuple of tuple of int
        Child ``4 f + i`` = (vertex point of corner i, edge point, face point, edge point).

    Examples
    --------
    >>> S, ch = refine_exact(((0, 1, 2, 3),))
    >>> S[0] == {0: Fraction(3, 4), 1: Fraction(1, 8), 3: Fraction(1, 8)}, ch[0]
    (True, (0, 4, 8, 7))
    """
    topo = LocalTopology(key)
    F = topo.faces
    n, m = topo.n_vertices, F.shape[0]
    edges, he_edge = local_edges(key)
    E = len(edges)
    q4, q8, q16 = Fraction(1, 4), Fraction(1, 8), Fraction(1, 16)
    fpts = [{int(v): q4 for v in F[f]} for f in range(m)]
    epts = []
    for h in edges:
        a, b = topo.org(h), topo.dst(h)
        t = topo.twin[h]
        if t < 0:
            epts.append({a: Fraction(1, 2), b: Fraction(1, 2)})
        else:
            s = {a: q4, b: q4}
            for g in (h // 4, t // 4):
                for v in F[g]:
                    s[int(v)] = s.get(int(v), 0) + q16
            epts.append(s)
    vpts = []
    for v in range(n):
        if not topo.corners[v]:
            vpts.append(None)
            continue
        fan, closed = topo.ordered_fan(v)
        if fan is None:
            vpts.append(None)
        elif closed:
            k = len(fan)
            s = {v: Fraction(k - 3, k) + Fraction(1, k)}
            wf, we = Fraction(1, 4 * k * k), Fraction(1, k * k)
            for c in fan:
                for u in F[c // 4]:
                    s[int(u)] = s.get(int(u), 0) + wf
                e = topo.dst(c)
                s[e] = s.get(e, 0) + we
            vpts.append(s)
        else:
            e0 = topo.dst(fan[0])
            e1 = topo.org(topo.prev(fan[-1]))
            s = {v: Fraction(3, 4)}
            s[e0] = s.get(e0, 0) + q8
            s[e1] = s.get(e1, 0) + q8
            vpts.append(s)
    stencils = tuple(vpts) + tuple(epts) + tuple(fpts)
    children = []
    for f in range(m):
        fp = n + E + f
        for i in range(4):
            h = 4 * f + i
            children.append((int(F[f, i]), n + he_edge[h], fp, n + he_edge[4 * f + (i + 3) % 4]))
    return stencils, tuple(children)


# grid positions (i, j) of the 4 x 4 net around a face, i along u: for side s (edge corner s -> s+1)
# the two outer points next to corner s and corner s+1, the diagonal point at corner s, and the
# inward normal of the side in grid steps
_SIDES = (
    ((1, 0), (2, 0), (0, 0), (0, 1)),
    ((3, 1), (3, 2), (3, 0), (-1, 0)),
    ((2, 3), (1, 3), (3, 3), (0, -1)),
    ((0, 2), (0, 1), (0, 3), (1, 0)),
)
_CENTER = ((1, 1), (2, 1), (2, 2), (1, 2))


def regular_net(topo, f):
    """The 4 x 4 bicubic B-spline net of face ``f`` as stencils over the vertices of ``topo``.

    Parameters
    ----------
    topo : LocalTopology
    f : int
        A face whose four vertices are regular (interior of valence 4 or boundary with two faces).

    Returns
    -------
    list of 16 dict or None
        ``net[i + 4 j]`` (i along the face's u, corner 0 at grid (1, 1)), with integer weights
        (1 for a vertex, ``2 B - I`` for a ghost point); ``None`` if the face is not regular.

    Examples
    --------
    >>> from ccproof.mesh.examples import grid
    >>> net = regular_net(LocalTopology(grid(3, 3).faces), 4)   # the middle face: no ghosts
    >>> [min(s) for s in net[:4]]
    [0, 1, 2, 3]
    >>> regular_net(LocalTopology(grid(3, 3).faces), 1)[1]      # bottom face: ghost 2*1 - 5
    {1: 2, 5: -1}
    """
    F = topo.flat
    fv = [F[4 * f + s] for s in range(4)]
    if not all(topo.is_regular(v) for v in fv):
        return None
    grid = {}
    for s in range(4):
        grid[_CENTER[s]] = {fv[s]: 1}
    bnd = [topo.twin[4 * f + s] < 0 for s in range(4)]
    for s in range(4):
        if not bnd[s]:
            t = topo.twin[4 * f + s]
            grid[_SIDES[s][0]] = {topo.dst(topo.next(t)): 1}
            grid[_SIDES[s][1]] = {topo.org(topo.prev(t)): 1}

    def ghost(p, nrm):
        q = (p[0] + nrm[0], p[1] + nrm[1])
        r = (p[0] + 2 * nrm[0], p[1] + 2 * nrm[1])
        return _lin((2, grid[q]), (-1, grid[r]))

    for s in range(4):
        if bnd[s]:
            for p in _SIDES[s][:2]:
                grid[p] = ghost(p, _SIDES[s][3])
    for s in range(4):
        sp, sm = s, (s + 3) % 4  # the two sides at corner s
        p = _SIDES[s][2]
        if bnd[sp] and bnd[sm]:
            return None
        if not bnd[sp] and not bnd[sm]:
            t = topo.twin[4 * f + s]
            t2 = topo.twin[topo.next(t)]
            if t2 < 0:
                return None
            grid[p] = {topo.org(topo.prev(t2)): 1}
        else:
            grid[p] = ghost(p, _SIDES[sp if bnd[sp] else sm][3])
    return [grid[(i, j)] for j in range(4) for i in range(4)]


def _to_fmpq_mat(rows, ncols):
    M = flint.fmpq_mat(len(rows), ncols)
    for i, s in enumerate(rows):
        for j, w in s.items():
            M[i, j] = flint.fmpq(w.numerator, w.denominator) if isinstance(w, Fraction) else w
    return M


def _fmpq_mat_to_float(M):
    """Correctly rounded float matrix of an exact one (common denominator, Python int true division)."""
    num, den = M.numer_denom()
    q = int(den)
    out = np.array([int(p) / q for p in num.entries()], dtype=np.float64)
    return out.reshape(M.nrows(), M.ncols())


def power_layers(M, A, l_row):
    """Rounded deviations ``M A^n - 1 l^T`` for n = 0, 1, ... until below ``LAYER_TOLERANCE``.

    Parameters
    ----------
    M : flint.fmpq_mat, shape (48, N)
    A : flint.fmpq_mat, shape (N, N)
    l_row : flint.fmpq_mat, shape (1, N)

    Returns
    -------
    ndarray, shape (n_layers, 3, 16, N)

    Notes
    -----
    Exact throughout: with ``A = Ai / a``, ``M = Mi / m`` and ``l = li / c`` (integer matrices and
    common denominators) the n-th deviation is ``(c Mi Ai^n - m a^n 1 li^T) / (c m a^n)``; the powers
    are integer matrix products (flint ``fmpz_mat``), and only the final quotients are rounded.
    """
    N = A.nrows()
    Ai, a = A.numer_denom()
    Mi, m = M.numer_denom()
    li, c = l_row.numer_denom()
    a, m, c = int(a), int(m), int(c)
    Lrow = [int(x) for x in li.entries()]
    ones = flint.fmpz_mat(48, 1, [1] * 48)
    L1 = ones * flint.fmpz_mat(1, N, Lrow)
    R = Mi
    den = m
    layers = []
    for _ in range(MAX_LAYERS):
        num = R * c - L1 * den
        q = c * den
        D = np.array([int(p) / q for p in num.entries()], dtype=np.float64).reshape(48, N)
        layers.append(D.reshape(3, 16, N))
        if np.abs(D).max() < LAYER_TOLERANCE:
            return np.array(layers)
        R = R * Ai
        den *= a
    raise MeshError(f"corner configuration of {N} vertices does not converge to its limit point")


_SOURCES = ("evaluate/local.py", "evaluate/tagged.py", "mesh/rules.py")


@functools.lru_cache(maxsize=1)
def _code_version():
    """Hash of the sources that define the exact data (a change invalidates the disk cache)."""
    import hashlib
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]
    h = hashlib.sha256()
    for rel in _SOURCES:
        h.update((root / rel).read_bytes())
    return h.hexdigest()[:16]


def _cache_dir():
    import os
    from pathlib import Path

    d = os.environ.get("CCPROOF_CACHE")
    if d is not None and d.strip().lower() in ("", "0", "off", "none", "no"):
        return None
    return Path(d) if d else Path.home() / ".cache" / "ccproof" / "corner_schemes"


def cached_scheme(kind, key, compute):
    """``compute()`` (a CornerScheme or None), kept between runs in a disk cache.

    The cache (default ``~/.cache/ccproof/corner_schemes``; environment variable
    ``CCPROOF_CACHE`` = another folder, or ``off``) holds two files per configuration, named by
    the SHA-256 of the configuration key and of the sources that compute it: ``.npy``, one float
    vector ``[N, n_layers, n_support, limit mask (N), support, layers]`` (read at setup), and
    ``.A.npz``, the exact matrix ``A`` (integer numerators as decimal strings and one denominator,
    read only when the tangent masks need it). A cached scheme is the computed one bit for bit.
    Unreadable or unwritable cache files are ignored (the data are then computed).
    """
    import hashlib
    import os

    d = _cache_dir()
    if d is None:
        return compute()
    name = hashlib.sha256(f"{kind}|{_code_version()}|{key!r}".encode()).hexdigest()
    path, apath = d / f"{name}.npy", d / f"{name}.A.npz"
    if path.exists() and apath.exists():
        try:
            z = np.load(path, allow_pickle=False)
            N, nl, ns = (int(x) for x in z[:3])
            mask = z[3:3 + N].copy()
            sup = [int(i) for i in z[3 + N:3 + N + ns]]
            layers = z[3 + N + ns:].reshape(nl, 3, 16, N).copy()
            # the exact A is only needed for the tangent masks: read and converted on first use
            loader = functools.partial(_cached_exact_matrix, apath, N, compute)
            return CornerScheme(N, loader, mask, layers, sup or None)
        except (OSError, ValueError, KeyError):
            pass
    sch = compute()
    if sch is None:
        return None
    try:
        d.mkdir(parents=True, exist_ok=True)
        num, den = sch.A.numer_denom()
        tmp = d / f".{name}.{os.getpid()}.A.npz"
        np.savez(tmp, A_den=np.array(str(den)), A_num=np.array([str(x) for x in num.entries()]))
        os.replace(tmp, apath)
        sup = list(sch.support) if sch.support else []
        head = np.array([sch.size, sch.n_layers, len(sup)] + sup, dtype=np.float64)
        tmp = d / f".{name}.{os.getpid()}.npy"
        np.save(tmp, np.concatenate([head[:3], sch.limit_mask, head[3:], sch.layers.reshape(-1)]))
        os.replace(tmp, path)
    except OSError:
        pass
    return sch


def _cached_exact_matrix(apath, N, compute):
    """The exact ``A`` of a cached scheme from its ``.A.npz`` (recomputed if that file is gone)."""
    try:
        with np.load(apath, allow_pickle=False) as z:
            den = int(str(z["A_den"]))
            return flint.fmpq_mat(N, N, [flint.fmpq(int(x), den) for x in z["A_num"].tolist()])
    except (OSError, ValueError, KeyError):
        return compute().A


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
        A = self.A
        if self.support is not None:
            idx = self.support
            A = flint.fmpq_mat(len(idx), len(idx), [A[i, j] for i in idx for j in idx])
        T = _tangent_masks_float(A)
        if T is None:
            T = _tangent_masks(A)
        if T is None or self.support is None:
            return T
        out = np.zeros((2, self.size))
        out[:, list(self.support)] = T
        return out


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
    groups = group_eigenvalues(vals, 1e-6)
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
        groups = group_eigenvalues(vals, 1e-15)
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


@functools.lru_cache(maxsize=1024)
def corner_scheme(key):
    """Exact layered-patch data of a face with one irregular corner (:func:`_corner_scheme`),
    kept between runs in the disk cache of :func:`cached_scheme`."""
    return cached_scheme("quad", key, lambda: _corner_scheme(key))


def _corner_scheme(key):
    """Exact layered-patch data of a face with one irregular corner, or ``None`` if not self-similar.

    Parameters
    ----------
    key : tuple of tuple of int
        The canonical one-ring (:func:`canonical_ring`) of a face, read from the irregular corner.

    Returns
    -------
    CornerScheme or None
        ``None`` when the one-ring of the child at the corner is not isomorphic to the face's own
        one-ring, or when one of the three children away from the corner is not a regular patch:
        such a face must be subdivided once more.

    Notes
    -----
    Self-similarity (bmz04 section 3, Stam 1998): with C the control points of the one-ring of the
    face, ``A^n C`` are those of its level-n child at the corner, the square [0, 2^-n]^2. Layer n
    (R4) is that square minus [0, 2^-(n+1)]^2; it consists of the level-(n+1) children at the other
    three corners, regular bicubic patches with nets ``M_j A^n C`` (``M_j``: one step followed by the
    net of child j). The matrices are built exactly (fractions, flint ``fmpq_mat``); ``A^n`` is
    never rounded, only the final deviations ``M_j A^n - 1 l^T``, whose entries decay like lam^n:
    they keep full relative precision at every layer, so the derivatives (which grow like
    (2 lam)^n, bmz04 eq. 3) are as accurate deep down as near the face centre.
    """
    topo = LocalTopology(key)
    N = topo.n_vertices
    stencils, children = refine_exact(key)
    topo1 = LocalTopology(children)
    ring1, key1, _ = canonical_ring(topo1, 0, 0)
    if key1 != key:
        return None
    rows = [stencils[v] for v in ring1]
    if any(r is None for r in rows):
        return None
    A = _to_fmpq_mat(rows, N)
    nets = []
    for j in (1, 2, 3):
        net = regular_net(topo1, j)
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
    M = _to_fmpq_mat(nets, N)  # (48, N)
    # limit mask: l (A - I) = 0, sum(l) = 1
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
    return CornerScheme(N, A, _fmpq_mat_to_float(l_row)[0], layers)
