"""Subdivision hierarchy of one chart: the surface, the extended chart and the boundary-rule chart.

For a chart (a disk of control faces) we keep, at every level k, one local quad complex ``E_k``:
the level-k chart faces (first) plus the *ring* of level-k faces that share a vertex with them
(docs/hsh10.md A8: "all vertices of faces outside the chart that share a vertex with the chart boundary").
Its control points are the level-k surface points ``P^k`` restricted to ``E_k``.

Why one ring is enough (docs/hsh10.md A11.5): a level-(k+1) vertex of ``E_{k+1}`` is a vertex point of a
level-k *chart* vertex, an edge point of an edge with a chart end point, or a face point of an
``E_k`` face; all three stencils (full fan of a chart vertex, the two faces of such an edge, the
four face vertices) lie in ``E_k``, and the mesh layer's rules there are the global ones. On a tagged
surface (:class:`~ccproof.apps.control_mesh.TaggedQuadMesh`) every level carries the sharpness of its edges
and vertices (decayed level by level) and the rules are :func:`~ccproof.apps.control_mesh.tagged_step`'s:
a vertex rule needs the vertex's edges and fan, a ``CREASE_UNIFORM`` edge rule its own sharpness and two
faces, all in ``E_k`` for the points kept. This is asserted at every refinement (:class:`HierarchyError`
otherwise). Vertices of ``E_k`` outside the chart whose faces form several fans are duplicated so that
``E_k`` is a valid :class:`~ccproof.mesh.QuadMesh`; the duplicates share one unknown.

Three linear subdivision operators act on values attached to the vertices of ``E_k``:

* ``S_E[k]`` (*extended chart*, hsh10 section 3.2 (c), and the surface itself): the surface rules
  (mesh layer: interior Catmull-Clark, crease rules on the surface boundary; OpenSubdiv's tags).
  Exact on chart vertices and the ring.
* ``S_B[k]`` (*boundary rules*, hsh10 section 3.2 (b)): the chart as a surface with boundary. Chart
  boundary edges get the midpoint rule, chart boundary vertices the cubic B-spline crease rule
  ``(e0 + 6 V + e1) / 8`` on their two chart-boundary neighbours, except *corners* (one chart face,
  i.e. "valence 2" in the chart) which are kept (``V' = V``), as Biermann et al. 2000 do. Where the
  chart boundary runs along the surface boundary the rules coincide with the surface's; a vertex
  that is a one-face corner of the surface itself keeps the surface's crease rule. Rows outside the
  chart are zero (boundary-rule textures live on the chart only).

Texture unknowns ``T^0``: for the extended chart, one per distinct control vertex of ``E_0``
(chart vertices first); for the boundary-rule chart, one per chart control vertex (the same first
ones). ``A_E[k]`` and ``A_B[k]`` map them to level k.

>>> from ccproof.mesh.examples import grid
>>> h = ChartHierarchy(grid(4, 4), [5, 6, 9, 10])
>>> h.n_unknowns("extended"), h.n_unknowns("boundary")
(25, 9)
>>> L = h.level(2)                  # 64 chart faces and the 36 faces of their ring
>>> L.n_chart_faces, L.mesh.n_faces
(64, 100)
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ccproof.apps.control_mesh import edge_values, tagged_step, tags_of, vertex_rules
from ccproof.errors import CCProofError, MeshError
from ccproof.mesh import Options, QuadMesh, child_faces
from ccproof.mesh.halfedges import HalfEdges
from ccproof.mesh.quadmesh import shared_halfedges
from ccproof.mesh.subdivision import boundary_neighbours
from ccproof.rule_weights import crease_vertex_weights, sharp_edge_weight

__all__ = ["ChartHierarchy", "Level", "HierarchyError", "split_nonmanifold", "RULES"]

#: texture rule sets: "extended" = surface rules on chart + ring, "boundary" = chart boundary rules
RULES = ("extended", "boundary")


class HierarchyError(CCProofError):
    """An internal consistency check of the chart hierarchy failed.

    Parameters
    ----------
    message : str

    Examples
    --------
    >>> issubclass(HierarchyError, CCProofError)
    True
    """


def _refuse_zero_area(mesh, faces):
    """Raise :class:`~ccproof.errors.MeshError` naming the first of ``faces`` whose two triangles (0, 1, 2)
    and (0, 2, 3) both have zero area (relative to the mesh's size): the ARAP energy and the distortion
    metrics (per unit area) are undefined there.

    >>> from ccproof.mesh import QuadMesh
    >>> m = QuadMesh([[0, 0, 0], [1, 0, 0], [1, 0, 0], [0, 0, 0]], [[0, 1, 2, 3]])
    >>> _refuse_zero_area(m, [0])
    Traceback (most recent call last):
    ...
    ccproof.errors.MeshError: face 0 (vertices 0, 1, 2, 3) has zero area: ARAP needs faces of positive area
    """
    V = np.asarray(mesh.vertices, dtype=np.float64)
    faces = np.asarray(faces, dtype=np.int64)
    if faces.size == 0:
        return
    P = V[mesh.faces[faces]]
    a = np.linalg.norm(np.cross(P[:, 1] - P[:, 0], P[:, 2] - P[:, 0]), axis=1)
    b = np.linalg.norm(np.cross(P[:, 2] - P[:, 0], P[:, 3] - P[:, 0]), axis=1)
    size = float(np.ptp(V, axis=0).max()) if V.size else 0.0
    bad = np.flatnonzero(a + b <= 1e-12 * size * size)
    if bad.size:
        f = int(faces[bad[0]])
        raise MeshError(f"face {f} (vertices {', '.join(map(str, mesh.faces[f].tolist()))}) has zero area: "
                        "ARAP needs faces of positive area")


def split_nonmanifold(F, n, halfedges=None):
    """Duplicate every vertex whose faces form several fans (edge-manifold, oriented input).

    The fans are those of the faces' :class:`~ccproof.mesh.halfedges.HalfEdges`
    (:attr:`~ccproof.mesh.halfedges.HalfEdges.fan_of_corner`).

    Parameters
    ----------
    F : int array (m, 4), indices in ``[0, n)``, every vertex used
    n : int
    halfedges : HalfEdges, optional
        The half-edges of ``F`` (built here when None).

    Returns
    -------
    F_new : int array (m, 4)
    orig : int array (n_new,)
        ``orig[v]`` is the input vertex of output vertex ``v``; the first fan of a vertex (the one of its
        smallest corner) keeps its index, extra fans get ``n, n + 1, ...`` (by vertex, then smallest corner).

    >>> F = [[0, 1, 2, 3], [0, 4, 5, 6]]          # two quads touching at vertex 0
    >>> Fn, orig = split_nonmanifold(F, 7)
    >>> Fn.tolist(), orig.tolist()
    ([[0, 1, 2, 3], [7, 4, 5, 6]], [0, 1, 2, 3, 4, 5, 6, 0])
    """
    F = np.asarray(F, dtype=np.int64)
    m = F.shape[0]
    he = HalfEdges.from_quads(F, n, Options()) if halfedges is None else halfedges
    lab = he.fan_of_corner  # fans numbered in the order of their smallest corner
    ncomp = int(lab.max()) + 1 if lab.size else 0
    pair = F.ravel() * ncomp + lab
    uniq, inv = np.unique(pair, return_inverse=True)
    uorg = uniq // ncomp if ncomp else uniq
    if uniq.size == n:
        return F.copy(), np.arange(n)
    first = np.r_[True, uorg[1:] != uorg[:-1]]
    newid = np.empty(uniq.size, dtype=np.int64)
    newid[first] = uorg[first]
    extra = np.flatnonzero(~first)
    newid[extra] = n + np.arange(extra.size)
    orig = np.r_[np.arange(n), uorg[extra]]
    return newid[inv].reshape(m, 4), orig


class Level:
    """One level ``E_k`` of a chart hierarchy and its chart bookkeeping.

    Attributes
    ----------
    mesh : QuadMesh
        ``E_k``; its vertices are the level-k surface control points. Faces ``0 .. n_chart_faces-1``
        are the chart's.
    chart_vertex, chart_interior, chart_boundary : bool (n,)
        Vertex of a chart face; chart vertex all of whose faces are chart faces and which is not on
        the surface boundary; the other chart vertices.
    chart_face_count : int (n,)
    chart_boundary_edge : bool (n_edges,)
        Edges with exactly one chart face.
    chart_boundary_nbrs : int (n, 2)
        The two chart-boundary neighbours of a chart boundary vertex (-1 elsewhere).
    corner : bool (n,)
        Chart corners of the boundary rules (one chart face; not a one-face surface corner unless
        ``surface_corners``).
    surface_boundary_nbrs : int (n, 2)
        The two surface-boundary neighbours (crease rule of the surface), -1 elsewhere.
    edge_sharpness : float (n_edges,), vertex_sharpness : float (n,)
        Sharpness of the interior edges and of the vertices of a tagged surface at this level
        (:class:`~ccproof.apps.control_mesh.TaggedQuadMesh`; ``inf`` infinitely sharp); 0 on an untagged one.
    has_tags : bool
    smooth, corner_rule, crease_rule, dart_rule, stationary : bool (n,)
        The surface's vertex rules (:func:`~ccproof.apps.control_mesh.vertex_rules`; smooth: no sharp or
        boundary edge, not a sharp vertex; stationary: no semi-sharp tag at the vertex); ``crease_nbrs``
        (n, 2) the two sharp neighbours of a crease vertex.

    Examples
    --------
    A 2 x 2 chart in the corner of a 3 x 3 grid: at level 1 its 16 faces have 5 x 5 vertices, and
    three of its four corners are chart corners (the fourth is a corner of the surface):

    >>> from ccproof.mesh.examples import grid
    >>> L = ChartHierarchy(grid(3, 3), [0, 1, 3, 4]).level(1)
    >>> L.chart_faces().shape, int(L.chart_vertex.sum()), int(L.corner.sum())
    ((16, 4), 25, 3)
    """

    def __init__(self, mesh: QuadMesh, n_chart_faces: int, surface_corners: bool = False, edge_sharpness=None,
                 vertex_sharpness=None):
        self.mesh = mesh
        if edge_sharpness is None:
            edge_sharpness, vertex_sharpness = tags_of(mesh)
        self.edge_sharpness, self.vertex_sharpness = edge_sharpness, vertex_sharpness
        self.has_tags = bool((edge_sharpness > 0).any() or (vertex_sharpness > 0).any())
        ns, self.corner_rule, self.crease_rule, self.dart_rule, self.crease_nbrs, self.stationary = vertex_rules(
            mesh, edge_sharpness, vertex_sharpness)
        self.smooth = (ns == 0) & ~self.corner_rule
        mc = int(n_chart_faces)
        self.n_chart_faces = mc
        F = mesh.faces
        n = mesh.n_vertices
        cfc = np.bincount(F[:mc].ravel(), minlength=n)
        self.chart_face_count = cfc
        self.chart_vertex = cfc > 0
        self.chart_interior = (cfc == mesh.face_count) & ~mesh.is_boundary_vertex
        self.chart_boundary = self.chart_vertex & ~self.chart_interior
        ef = mesh.edge_faces
        nchart = (ef[:, 0] < mc).astype(np.int64) + ((ef[:, 1] >= 0) & (ef[:, 1] < mc))
        self.chart_boundary_edge = nchart == 1
        e = mesh.edges[self.chart_boundary_edge]
        src = np.r_[e[:, 0], e[:, 1]]
        tgt = np.r_[e[:, 1], e[:, 0]]
        order = np.argsort(src, kind="stable")
        src, tgt = src[order], tgt[order]
        cnt = np.bincount(src, minlength=n)
        if (cnt[self.chart_boundary] != 2).any() or (cnt[~self.chart_boundary] != 0).any():
            raise HierarchyError("chart boundary is not a simple closed curve (is the chart a disk?)")
        start = np.cumsum(cnt) - cnt
        nb = np.full((n, 2), -1, dtype=np.int64)
        nb[src, np.arange(src.size) - start[src]] = tgt
        self.chart_boundary_nbrs = nb
        self.corner = self.chart_boundary & (cfc == 1)
        if not surface_corners:
            self.corner &= ~(mesh.is_boundary_vertex & (mesh.face_count == 1))
        self.surface_boundary_nbrs = np.column_stack(boundary_neighbours(mesh))

    @property
    def n_vertices(self):
        return self.mesh.n_vertices

    def chart_faces(self):
        """Faces of the chart at this level, int (n_chart_faces, 4), local vertex indices."""
        return self.mesh.faces[: self.n_chart_faces]


class ChartHierarchy:
    """Levels ``E_0, E_1, ...`` of one chart with the subdivision operators of both boundary treatments.

    Parameters
    ----------
    mesh : QuadMesh
        The whole control mesh (the surface).
    chart_faces : array_like of int
        Face indices of the chart in ``mesh`` (a topological disk; not re-checked here).
    surface_corners : bool, optional
        The boundary rules also keep the one-face corners of the surface itself (``V' = V``), as
        OpenSubdiv's face-varying "corners only" rule does (``FVAR_LINEAR_CORNERS_ONLY`` with the default
        ``VTX_BOUNDARY_EDGE_ONLY``: every face-varying value whose span is one face is sharp); default
        False: they keep the surface's crease rule (hsh10 (b), docs/hsh10.md).

    Notes
    -----
    hsh10 section 3 (the subdivision hierarchy of a chart; extended charts and boundary rules),
    docs/hsh10.md.

    Examples
    --------
    >>> from ccproof.mesh.examples import grid
    >>> h = ChartHierarchy(grid(3, 3), [0, 1, 3, 4])
    >>> h.n_chart_vertices, h.level(2).chart_faces().shape          # 3 x 3 vertices; 4 * 4**2 faces
    (9, (64, 4))
    """

    def __init__(self, mesh: QuadMesh, chart_faces, surface_corners: bool = False):
        chart = np.asarray(chart_faces, dtype=np.int64)
        self.surface_corners = bool(surface_corners)
        self.surface = mesh
        self.chart_faces = chart
        Fg = mesh.faces
        in_chart = np.zeros(mesh.n_faces, dtype=bool)
        in_chart[chart] = True
        cv = np.unique(Fg[chart])
        isc = np.zeros(mesh.n_vertices, dtype=bool)
        isc[cv] = True
        ring = np.flatnonzero(~in_chart & isc[Fg].any(axis=1))
        _refuse_zero_area(mesh, np.r_[chart, ring])
        self.ring_faces = ring
        faces0 = np.r_[chart, ring]
        allv = np.unique(Fg[faces0])
        rv = allv[~isc[allv]]
        gid = np.r_[cv, rv]
        loc = np.full(mesh.n_vertices, -1, dtype=np.int64)
        loc[gid] = np.arange(gid.size)
        F = loc[Fg[faces0]]
        he = shared_halfedges(mesh, F, gid.size)  # (the whole mesh: its own)
        he = HalfEdges.from_quads(F, gid.size, Options()) if he is None else he
        F0, orig = split_nonmanifold(F, gid.size, he)
        #: global control-vertex index of every texture unknown (chart vertices first)
        self.unknown_vertices = gid
        self.n_chart_vertices = cv.size
        #: unknown of every vertex of E_0 (duplicated outer vertices share one)
        self.orig0 = orig
        E0 = QuadMesh(mesh.vertices[gid[orig]], F0, _halfedges=he if orig.size == gid.size else None)  # (split: new)
        es, vs = tags_of(mesh)
        g0 = gid[orig]  # the control vertex of every vertex of E_0
        sharp = es > 0
        es0 = edge_values(E0, mesh.edges[sharp], es[sharp], g0, mesh.n_vertices)
        vs0 = vs[g0]
        n0 = orig.size
        self.A0 = {
            "extended": sp.csr_matrix((np.ones(n0), (np.arange(n0), orig)), shape=(n0, gid.size)),
        }
        cm = orig < cv.size
        self.A0["boundary"] = sp.csr_matrix(
            (np.ones(int(cm.sum())), (np.flatnonzero(cm), orig[cm])), shape=(n0, cv.size)
        )
        self.levels = [Level(E0, chart.size, self.surface_corners, es0, vs0)]
        self.S = {"extended": [], "boundary": []}
        self._A = {"extended": [self.A0["extended"]], "boundary": [self.A0["boundary"]]}

    # ------------------------------------------------------------------ construction
    def n_unknowns(self, rules):
        """Number of texture unknowns for ``rules`` ("extended" or "boundary")."""
        return self.unknown_vertices.size if check_rules(rules) == "extended" else self.n_chart_vertices

    def level(self, k) -> Level:
        """Level ``k`` (built on demand)."""
        while len(self.levels) <= k:
            self._refine()
        return self.levels[k]

    def _refine(self):
        L = self.levels[-1]
        E = L.mesh
        n, ne, m = E.n_vertices, E.n_edges, E.n_faces
        S, (ce, cs), (cv, cvs) = tagged_step(E, L.edge_sharpness, L.vertex_sharpness)  # untagged: subdivision_matrix
        CF = child_faces(E)
        mc = L.n_chart_faces
        cc = CF[: 4 * mc]
        isc = np.zeros(n + ne + m, dtype=bool)
        isc[cc.ravel()] = True
        other = CF[4 * mc :]
        ring = other[isc[other].any(axis=1)]
        kept = np.concatenate([cc, ring])
        used, inv = np.unique(kept, return_inverse=True)
        # validity of the local stencils (module docstring)
        vp = used < n
        if not L.chart_vertex[used[vp]].all():
            raise HierarchyError("a kept vertex point is not that of a chart vertex")
        ep = (used >= n) & (used < n + ne)
        ee = E.edges[used[ep] - n]
        if not (L.chart_vertex[ee[:, 0]] | L.chart_vertex[ee[:, 1]]).all():
            raise HierarchyError("a kept edge point belongs to an edge without a chart vertex")
        Fk = inv.reshape(-1, 4)
        P = S[used] @ E.vertices
        he = HalfEdges.from_quads(Fk, used.size, Options())  # the kept faces' topology (QuadMesh's), built once
        try:  # usually manifold: no split
            new = QuadMesh(P, Fk, _halfedges=he)
            rows = used
        except MeshError:
            Fs, orig = split_nonmanifold(Fk, used.size, he)
            rows = used[orig]
            new = QuadMesh(P[orig], Fs)
        SE = S[rows]
        chart_rows = isc[rows]
        SB = self._boundary_rows(L, SE, rows, chart_rows)
        self.S["extended"].append(SE)
        self.S["boundary"].append(SB)
        es = edge_values(new, ce, cs, rows, S.shape[0])
        vs = np.zeros(rows.size)
        if cv.size:
            srt = np.argsort(cv)
            pos = np.minimum(np.searchsorted(cv[srt], rows), cv.size - 1)
            hit = cv[srt][pos] == rows
            vs[hit] = cvs[srt][pos[hit]]
        self.levels.append(Level(new, cc.shape[0], self.surface_corners, es, vs))

    @staticmethod
    def _boundary_rows(L: Level, SE, rows, chart_rows):
        E = L.mesh
        n, ne = E.n_vertices, E.n_edges
        isvp = rows < n
        repl_v = np.zeros(rows.size, dtype=bool)
        repl_v[isvp] = L.chart_boundary[rows[isvp]]
        isep = (rows >= n) & (rows < n + ne)
        repl_e = np.zeros(rows.size, dtype=bool)
        repl_e[isep] = L.chart_boundary_edge[rows[isep] - n]
        keep = chart_rows & ~repl_v & ~repl_e
        base = sp.diags(keep.astype(np.float64)) @ SE
        r_v = np.flatnonzero(repl_v)
        v = rows[r_v]
        cor = L.corner[v]
        nb = L.chart_boundary_nbrs[v]
        # the chart boundary is a crease curve: corners stay, boundary vertices and edges take the
        # crease rules (one rule set: ccproof.rule_weights)
        w_vertex, w_neighbour = crease_vertex_weights(1.0)
        w_edge = sharp_edge_weight(1.0)
        rr, cc, ww = [r_v[cor]], [v[cor]], [np.ones(int(cor.sum()))]
        cr = ~cor
        m = int(cr.sum())
        rr += [r_v[cr]] * 3
        cc += [v[cr], nb[cr, 0], nb[cr, 1]]
        ww += [np.full(m, w_vertex), np.full(m, w_neighbour), np.full(m, w_neighbour)]
        r_e = np.flatnonzero(repl_e)
        ed = E.edges[rows[r_e] - n]
        rr += [r_e, r_e]
        cc += [ed[:, 0], ed[:, 1]]
        ww += [np.full(r_e.size, w_edge)] * 2
        extra = sp.coo_matrix(
            (np.concatenate(ww), (np.concatenate(rr), np.concatenate(cc))), shape=SE.shape
        )
        out = (base + extra).tocsr()
        out.eliminate_zeros()
        return out

    def release(self):
        """Drop every level above 0 and the cached operators and samples (rebuilt on demand): keeps
        the memory of a multi-chart run at that of its largest chart."""
        del self.levels[1:]
        self.S = {"extended": [], "boundary": []}
        self._A = {"extended": [self.A0["extended"]], "boundary": [self.A0["boundary"]]}
        self.__dict__.pop("_metric_samples", None)

    def n_faces(self, k):
        """Faces of ``E_k`` (chart and ring) without building it: ``4^k`` times those of ``E_0``."""
        return self.levels[0].mesh.n_faces * 4 ** int(k)

    # ------------------------------------------------------------------ operators
    def operator(self, k, rules):
        """Sparse ``A_k``: texture unknowns -> level-k values on ``E_k`` (shape (n_k, n_unknowns))."""
        r = check_rules(rules)
        self.level(k)
        A = self._A[r]
        while len(A) <= k:
            A.append((self.S[r][len(A) - 1] @ A[-1]).tocsr())
        return A[k]

    def subdivide_values(self, X, rules, from_level, to_level):
        """Push values given on ``E_{from_level}`` to ``E_{to_level}`` with the rules ``rules``."""
        r = check_rules(rules)
        self.level(to_level)
        X = np.asarray(X, dtype=np.float64)
        for k in range(from_level, to_level):
            X = self.S[r][k] @ X
        return X

    def lift_unknowns(self, X, rules):
        """Level-0 values on ``E_0`` of the unknowns ``X`` (n_unknowns, d)."""
        return self.A0[check_rules(rules)] @ np.asarray(X, dtype=np.float64)


def check_rules(rules):
    """``rules`` if it names texture rules (one of ``RULES``), else a CCProofError naming it."""
    if rules not in RULES:
        raise CCProofError(f"unknown texture rules {rules!r}; expected one of {RULES}")
    return rules
