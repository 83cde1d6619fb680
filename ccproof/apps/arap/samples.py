"""Limit tangent masks (hsh10 Eq. 2, docs/hsh10.md A3) and the level-k samples of Eq. 3 and of the metrics.

Tangent masks. For an interior vertex of valence n with edge neighbours e_0 .. e_{n-1}
(counter-clockwise) and face-diagonal neighbours f_i (face i between e_i and e_{i+1}):

    alpha_i = (1/n + cos(pi/n) / (n sqrt(4 + cos^2(pi/n)))) cos(2 pi i/n)      on e_i
    beta_i  = cos((2 pi i + pi)/n) / (n sqrt(4 + cos^2(pi/n)))                  on f_i

``p_1 = sum alpha_i e_i + beta_i f_i`` and ``p_2`` uses the same weights rotated once around the
vertex (``p_2 = sum alpha_i e_{i+1} + beta_i f_{i+1}``); the centre weight is 0. They are exact limit
tangents (left eigenvectors of the subdominant eigenvalue), the derivatives along the limit curves
of the edges e_0 and e_1 in the characteristic-map parameter, scaled so that for n = 4 they are the
bicubic B-spline derivative with unit knot spacing (edge weights 1/3, face weights 1/12).

Samples. A *sample* is one term of the quadrature of hsh10 Eq. 1 at level k: two surface tangents
p_1, p_2 (3-vectors), two linear texture operators O_1, O_2 (rows acting on the level-k texture
values of ``E_k``) for the *same* two parametric directions, and a weight. Two kinds:

* *mask sample* at a vertex whose texture and surface both follow the interior rules there: A3
  masks for both; weight ``||p_1 x p_2||`` times the fraction of its faces that belong to the chart.
* *corner samples* at every other chart vertex (chart boundary for boundary-rule textures; the
  surface boundary for all): one per chart face corner (v, f), with the secants of *limit points*
  along the two edges of f at v, ``d_a = L(a) - L(v)`` and ``d_b = L(b) - L(v)``, for the surface
  and for the texture (each with its own rules, so the secant pairs span the same parameter
  triangle); weight ``||d_a x d_b|| / 4`` (a quarter face). hsh10 gives no masks at chart boundary
  vertices (docs/hsh10.md A11.2); secants are exact for affine maps and reproduce the texture's own boundary
  behaviour, which is what (b) is about.

Limit position masks: interior ``(n^2 V + 4 sum e + sum f) / (n (n + 5))``; crease (cubic B-spline
boundary) ``(e0 + 4 V + e1) / 6``; corner ``V``.

>>> import numpy as np
>>> a, b = mask_weights(4)
>>> (np.round(a * 12, 12) + 0.0).tolist(), (np.round(b * 12, 12) + 0.0).tolist()
([4.0, 0.0, -4.0, 0.0], [1.0, -1.0, -1.0, 1.0])
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from ccproof.apps.arap.hierarchy import HierarchyError, Level, check_rules
from ccproof.apps.control_mesh import moving_limit_rows
from ccproof.rule_weights import crease_limit_weights, smooth_limit_weights

__all__ = [
    "mask_weights",
    "tangent_mask_operators",
    "limit_operator",
    "SampleSet",
    "build_samples",
    "isometric_frames",
]


def mask_weights(n):
    """The tangent-mask weights (alpha_i, beta_i), i = 0 .. n-1, of a valence-``n`` vertex.

    The limit tangent masks of hsh10 Eq. 2 (edge neighbours weighted by alpha, face neighbours by beta).

    Parameters
    ----------
    n : int
        Valence, n >= 3.

    Returns
    -------
    alpha, beta : ndarray, shape (n,) float64

    Examples
    --------
    Derivatives of a constant vanish: both sets of weights sum to 0:

    >>> import numpy as np
    >>> a, b = mask_weights(5)
    >>> bool(abs(a.sum()) < 1e-15 and abs(b.sum()) < 1e-15), np.round(mask_weights(4)[0], 6).tolist()
    (True, [0.333333, 0.0, -0.333333, -0.0])
    """
    n = int(n)
    i = np.arange(n)
    c = np.cos(np.pi / n)
    s = 1.0 / (n * np.sqrt(4.0 + c * c))
    alpha = (1.0 / n + c * s) * np.cos(2 * np.pi * i / n)
    beta = s * np.cos((2 * np.pi * i + np.pi) / n)
    return alpha, beta


def _fan_corners(mesh, verts):
    """All corners (half-edges) of the fans of ``verts`` in fan order: (row, position j, corner)."""
    ptr, fan = mesh.fan_ptr, mesh.fan_corners
    cnt = mesh.face_count[verts]
    row = np.repeat(np.arange(verts.size), cnt)
    j = np.arange(row.size) - np.repeat(np.cumsum(cnt) - cnt, cnt)
    c = fan[np.repeat(ptr[verts], cnt) + j]
    return row, j, c


def tangent_mask_operators(mesh, verts):
    """Sparse (len(verts), n) operators of the tangent masks p_1, p_2 at interior vertices ``verts``.

    hsh10 Eq. 2: ``P1 @ X`` and ``P2 @ X`` are the two limit tangents at the vertices.

    Parameters
    ----------
    mesh : QuadMesh
    verts : array_like of int
        Interior vertices.

    Returns
    -------
    P1, P2 : scipy.sparse matrix, shape (len(verts), n_vertices)

    Examples
    --------
    At the middle vertex of a flat 2 x 2 grid of unit squares the tangents are unit and orthogonal:

    >>> import numpy as np
    >>> from ccproof.mesh.examples import grid
    >>> m = grid(2, 2)
    >>> P1, P2 = tangent_mask_operators(m, [4])
    >>> t1, t2 = (P1 @ m.vertices)[0], (P2 @ m.vertices)[0]
    >>> round(float(np.linalg.norm(t1)), 12), round(float(np.linalg.norm(t2)), 12), round(float(t1 @ t2), 12)
    (1.0, 1.0, 0.0)
    """
    verts = np.asarray(verts, dtype=np.int64)
    F = mesh.faces
    row, j, c = _fan_corners(mesh, verts)
    f, i = c // 4, c % 4
    e = F[f, (i + 1) % 4]
    d = F[f, (i + 2) % 4]
    n = mesh.face_count[verts][row].astype(np.float64)
    cn = np.cos(np.pi / n)
    s = 1.0 / (n * np.sqrt(4.0 + cn * cn))
    a0 = 1.0 / n + cn * s

    def op(jj):
        al = a0 * np.cos(2 * np.pi * jj / n)
        be = s * np.cos((2 * np.pi * jj + np.pi) / n)
        return sp.csr_matrix(
            (np.concatenate([al, be]), (np.concatenate([row, row]), np.concatenate([e, d]))),
            shape=(verts.size, mesh.n_vertices),
        )

    return op(j), op(j - 1)


@functools.lru_cache(maxsize=64)
def dart_limit_mask(n, sigma):
    """Exact limit mask of a dart: an interior vertex of valence ``n`` with one infinitely sharp edge.

    The dart keeps the smooth vertex rule, but its sharp edge's point is the midpoint: the one-ring matrix
    ``A`` differs from the smooth one, and so does its left eigenvector of eigenvalue 1 (no closed form).
    It is solved exactly (``l (A - I) = 0``, ``sum l = 1``, rationals) from the stencils of
    :func:`ccproof.mesh.rules.refine_complex` on the fan.

    Parameters
    ----------
    n : int
        Valence (faces around the vertex), n >= 2.
    sigma : {1, -1}
        Fan orientation: face j is ``(v, a_j, d_j, a_{j + sigma})`` (indices mod n).

    Returns
    -------
    ndarray, shape (2 n + 1,)
        Weights of ``v``, the edge neighbours ``a_0 .. a_{n-1}`` (``a_0`` the sharp edge's far end) and the
        diagonals ``d_0 .. d_{n-1}``; they sum to 1.

    Examples
    --------
    >>> m = dart_limit_mask(4, 1)
    >>> round(float(m.sum()), 15), bool(m[1] > m[3]), bool(abs(m[2] - m[4]) < 1e-15)
    (1.0, True, True)
    """
    import flint

    from ccproof.mesh.rules import Complex, Options, refine_complex, to_float

    faces = [(0, 1 + j, 1 + n + j, 1 + (j + sigma) % n) for j in range(n)]
    cx = Complex(faces, {(0, 1): math.inf}, {}, Options(), level=1, n_vertices=2 * n + 1)
    edges = [cx.edge_index[(0, 1 + j)] for j in range(n)]
    stencils, _, _, _ = refine_complex(cx, vertices=[0], edges=edges)
    nv, ne = cx.n_vertices, len(cx.edges)
    rows = [stencils[0]] + [stencils[nv + e] for e in edges] + [stencils[nv + ne + j] for j in range(n)]
    N = 2 * n + 1
    Bt = flint.fmpq_mat(N, N)
    for i, r in enumerate(rows):  # (A - I)^T
        for j, w in r.items():
            Bt[j, i] = w
        Bt[i, i] -= 1
    for j in range(N):
        Bt[N - 1, j] = 1
    lvec = Bt.solve(flint.fmpq_mat(N, 1, [0] * (N - 1) + [1]))
    return np.array([to_float(lvec[i, 0]) for i in range(N)])


def _dart_rows(mesh, verts, sharp_nbrs):
    """Sparse rows (len(verts), n) of the exact limit masks of the darts ``verts`` (:func:`dart_limit_mask`).

    ``sharp_nbrs``: the far end of each dart's sharp edge.
    """
    F = mesh.faces
    rows, cols, vals = [], [], []
    for r, (v, s) in enumerate(zip(verts.tolist(), sharp_nbrs.tolist())):
        c = mesh.fan_corners[mesh.fan_ptr[v]: mesh.fan_ptr[v] + mesh.face_count[v]]
        f, i = c // 4, c % 4
        a, d, b = F[f, (i + 1) % 4], F[f, (i + 2) % 4], F[f, (i + 3) % 4]
        k = a.size
        j0 = int(np.flatnonzero(a == s)[0])
        order = (j0 + np.arange(k)) % k
        a, d, b = a[order], d[order], b[order]
        sigma = 1 if (k > 1 and b[0] == a[1]) else -1
        if k > 1 and b[0] != a[sigma % k]:
            raise HierarchyError(f"vertex {v}: its fan is not a closed ring of quads")
        m = dart_limit_mask(k, sigma)
        rows.append(np.full(2 * k + 1, r))
        cols.append(np.r_[v, a, d])
        vals.append(m)
    if not rows:
        return sp.csr_matrix((0, mesh.n_vertices))
    return sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                         shape=(verts.size, mesh.n_vertices))


def _limit_rule_sets(level: Level, r):
    """The chart vertices of ``level`` by limit rule for the rules ``r``: (smooth, crease, corner, dart, moving)
    masks and the two crease neighbours of every vertex (moving: semi-sharp tags, not yet stationary)."""
    n = level.mesh.n_vertices
    dart = np.zeros(n, dtype=bool)
    moving = np.zeros(n, dtype=bool)
    if r == "extended":
        inner = level.chart_vertex & ~level.mesh.is_boundary_vertex
        crease = level.chart_vertex & level.mesh.is_boundary_vertex
        nbrs = level.surface_boundary_nbrs
        corner = np.zeros(n, dtype=bool)
        if level.has_tags:  # the surface's stationary rules (on an untagged surface the same sets)
            cvx = level.chart_vertex & level.stationary
            moving = level.chart_vertex & ~level.stationary
            inner, crease, corner = cvx & level.smooth, cvx & level.crease_rule, cvx & level.corner_rule
            dart, nbrs = cvx & level.dart_rule, level.crease_nbrs
        return inner, crease, corner, dart, moving, nbrs
    inner = level.chart_interior
    corner = level.corner
    crease = level.chart_boundary & ~corner
    nbrs = level.chart_boundary_nbrs
    if level.has_tags:  # chart-interior vertices follow the surface's rules
        ci = level.chart_interior & level.stationary
        moving = level.chart_interior & ~level.stationary
        inner = ci & level.smooth
        corner = corner | (ci & level.corner_rule)
        dart = ci & level.dart_rule
        nbrs = np.where((ci & level.crease_rule)[:, None], level.crease_nbrs, nbrs)
        crease = crease | (ci & level.crease_rule)
    return inner, crease, corner, dart, moving, nbrs


def limit_operator(level: Level, rules):
    """Sparse (n, n) limit-position operator on ``E_k`` for ``rules``; rows of chart vertices only.

    Interior (smooth) vertices: ``(n^2 V + 4 sum e + sum f) / (n (n + 5))``; crease vertices (the surface
    boundary, an infinitely sharp crease, the chart boundary of the boundary rules):
    ``(e0 + 4 V + e1) / 6`` along it; corners: ``V``; darts: :func:`dart_limit_mask`; vertices with
    semi-sharp tags: :func:`~ccproof.apps.control_mesh.moving_limit_rows` (subdivided until stationary). All
    exact (rounded once).

    Parameters
    ----------
    level : Level
        A level of a :class:`~ccproof.apps.arap.hierarchy.ChartHierarchy`.
    rules : {"boundary", "extended"}

    Returns
    -------
    scipy.sparse matrix, shape (n_k, n_k)

    Examples
    --------
    Limit masks are affine combinations: every row of a chart vertex sums to 1, the others are 0:

    >>> import numpy as np
    >>> from ccproof.mesh.examples import grid
    >>> from ccproof.apps.arap.hierarchy import ChartHierarchy
    >>> A = limit_operator(ChartHierarchy(grid(3, 3), range(9)).level(1), "extended")
    >>> r = np.asarray(A.sum(axis=1)).ravel()
    >>> A.shape, bool(np.all((np.abs(r - 1) < 1e-12) | (r == 0))), bool((r != 0).any())
    ((49, 49), True, True)
    """
    mesh = level.mesh
    F = mesh.faces
    n = mesh.n_vertices
    inner, crease, corner, dart, moving, nbrs = _limit_rule_sets(level, check_rules(rules))
    org = F.ravel()
    h = np.flatnonzero(inner[org])
    v = org[h]
    k = mesh.valence[v].astype(np.float64)
    f, i = h // 4, h % 4
    e = F[f, (i + 1) % 4]
    d = F[f, (i + 2) % 4]
    iv = np.flatnonzero(inner)
    ki = mesh.valence[iv].astype(np.float64)
    cv = np.flatnonzero(crease)
    kv = np.flatnonzero(corner)
    rows = np.concatenate([v, v, iv, cv, cv, cv, kv])
    cols = np.concatenate([e, d, iv, cv, nbrs[cv, 0], nbrs[cv, 1], kv])
    _, we, wd = smooth_limit_weights(k, 1.0)
    wV = smooth_limit_weights(ki, 1.0)[0]
    cV, ce = crease_limit_weights(1.0)
    vals = np.concatenate(
        [we, wd, wV, np.full(cv.size, cV), np.full(cv.size, ce), np.full(cv.size, ce), np.ones(kv.size)]
    )
    out = sp.csr_matrix((vals, (rows, cols)), shape=(n, n))
    mv = np.flatnonzero(moving)
    if mv.size:
        place = sp.csr_matrix((np.ones(mv.size), (mv, np.arange(mv.size))), shape=(n, mv.size))
        out = (out + place @ moving_limit_rows(mesh, mv, level.edge_sharpness, level.vertex_sharpness)).tocsr()
    dv = np.flatnonzero(dart)
    if dv.size:
        se = (level.edge_sharpness > 0) | mesh.is_boundary_edge
        a, b = mesh.edges[se, 0], mesh.edges[se, 1]
        far = np.full(n, -1, dtype=np.int64)
        far[a], far[b] = b, a
        place = sp.csr_matrix((np.ones(dv.size), (dv, np.arange(dv.size))), shape=(n, dv.size))
        out = (out + place @ _dart_rows(mesh, dv, far[dv])).tocsr()
    return out


def isometric_frames(p1, p2):
    """The isometric images (a, b, c) of the frames: p^_1 = (a, 0), p^_2 = (b, c) (docs/hsh10.md A2).

    ``a = |p1|``, ``b = p1.p2 / |p1|``, ``c = |p1 x p2| / |p1|`` (c >= 0).

    Parameters
    ----------
    p1, p2 : ndarray, shape (s, 3) float64

    Returns
    -------
    a, b, c : ndarray, shape (s,) float64

    Examples
    --------
    >>> import numpy as np
    >>> [x.tolist() for x in isometric_frames(np.array([[2.0, 0, 0]]), np.array([[1.0, 1, 0]]))]
    [[2.0], [1.0], [1.0]]
    """
    a = np.linalg.norm(p1, axis=1)
    b = np.einsum("ij,ij->i", p1, p2) / a
    c = np.linalg.norm(np.cross(p1, p2), axis=1) / a
    return a, b, c


@dataclass
class SampleSet:
    """Level-k samples of one chart (module docstring).

    Attributes
    ----------
    p1, p2 : (s, 3) surface tangents
    O1, O2 : sparse (s, n_k) texture operators on ``E_k`` values
    weight : (s,) quadrature weights (surface area elements)
    area_factor : (s,) factor turning ``|det(t1, t2)|`` into the texture area element
    vertex : (s,) level-k vertex of each sample
    corner : (s,) bool, corner sample

    Examples
    --------
    >>> from ccproof.mesh.examples import grid
    >>> from ccproof.apps.arap.hierarchy import ChartHierarchy
    >>> L = ChartHierarchy(grid(3, 3), range(9)).level(1)
    >>> S = build_samples(L, "extended")
    >>> S.p1.shape[1], S.O1.shape == (S.p1.shape[0], L.mesh.n_vertices), bool((S.weight > 0).all())
    (3, True, True)
    """

    p1: np.ndarray
    p2: np.ndarray
    O1: sp.csr_matrix
    O2: sp.csr_matrix
    weight: np.ndarray
    area_factor: np.ndarray
    vertex: np.ndarray
    corner: np.ndarray

    @property
    def size(self):
        return self.weight.size

    def texture_tangents(self, T):
        """t1, t2 (s, d) of level-k texture values ``T`` (n_k, d)."""
        return self.O1 @ T, self.O2 @ T


def build_samples(level: Level, rules, purpose="optimize") -> SampleSet:
    """The samples of one level.

    Parameters
    ----------
    level : Level
    rules : "extended" or "boundary"
        The texture's subdivision rules.
    purpose : "optimize" or "metric"
        "optimize": the energy of hsh10 Eq. 3 for that variant (mask samples wherever the texture
        follows the interior rules, i.e. at every chart vertex off the surface boundary for
        extended charts). "metric": the same sampling for every method (mask samples at
        chart-interior vertices, corner samples on the chart boundary), docs/hsh10.md A9 / A11.4.

    Returns
    -------
    SampleSet

    Examples
    --------
    On a flat grid the surface tangents lie in the plane z = 0:

    >>> from ccproof.mesh.examples import grid
    >>> from ccproof.apps.arap.hierarchy import ChartHierarchy
    >>> S = build_samples(ChartHierarchy(grid(3, 3), range(9)).level(1), "extended", "metric")
    >>> float(abs(S.p1[:, 2]).max()), float(abs(S.p2[:, 2]).max())
    (0.0, 0.0)
    """
    r = check_rules(rules)
    mesh = level.mesh
    F = mesh.faces
    P = mesh.vertices
    if purpose == "optimize" and r == "extended":
        mask_v = np.flatnonzero(level.chart_vertex & ~mesh.is_boundary_vertex)
    elif purpose in ("optimize", "metric"):
        mask_v = np.flatnonzero(level.chart_interior)
    else:
        raise ValueError(f"purpose must be 'optimize' or 'metric', got {purpose!r}")
    if level.has_tags:  # masks where the surface's rule is the smooth one; secants at creases, corners, darts
        mask_v = mask_v[level.smooth[mask_v]]
    corner_v = np.zeros(mesh.n_vertices, dtype=bool)
    corner_v[level.chart_vertex] = True
    corner_v[mask_v] = False
    M1, M2 = tangent_mask_operators(mesh, mask_v)
    p1m, p2m = M1 @ P, M2 @ P
    frac = level.chart_face_count[mask_v] / mesh.face_count[mask_v]
    wm = np.linalg.norm(np.cross(p1m, p2m), axis=1) * frac
    # corner samples: chart faces' corners at corner_v vertices
    hc = np.arange(4 * level.n_chart_faces)
    hc = hc[corner_v[F.ravel()[hc]]]
    f, i = hc // 4, hc % 4
    v = F[f, i]
    a = F[f, (i + 1) % 4]
    b = F[f, (i + 3) % 4]
    Ls = limit_operator(level, "extended")
    Lt = Ls if r == "extended" else limit_operator(level, "boundary")
    Da = Lt[a] - Lt[v]
    Db = Lt[b] - Lt[v]
    LP = Ls @ P
    p1c, p2c = LP[a] - LP[v], LP[b] - LP[v]
    wc = np.linalg.norm(np.cross(p1c, p2c), axis=1) / 4
    return SampleSet(
        p1=np.concatenate([p1m, p1c]),
        p2=np.concatenate([p2m, p2c]),
        O1=sp.vstack([M1, Da]).tocsr(),
        O2=sp.vstack([M2, Db]).tocsr(),
        weight=np.concatenate([wm, wc]),
        area_factor=np.concatenate([frac, np.full(hc.size, 0.25)]),
        vertex=np.concatenate([mask_v, v]),
        corner=np.r_[np.zeros(mask_v.size, dtype=bool), np.ones(hc.size, dtype=bool)],
    )
