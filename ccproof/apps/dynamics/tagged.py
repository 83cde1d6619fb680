"""Tagged elements: faces of a control mesh with OpenSubdiv tags (creases, corners, boundaries, holes).

A face that is neither normal nor special (:mod:`ccproof.apps.dynamics.elements`) on a
:class:`~ccproof.apps.control_mesh.TaggedQuadMesh` is one *tagged element* whose control set is the face's
two-ring of faces (every vertex of a face that shares a vertex with a face sharing a vertex with it). Its limit
surface is computed by local tagged subdivision (:func:`ccproof.apps.control_mesh.tagged_step`, the rules of
:mod:`ccproof.mesh.rules`, restricted to the two-ring of each child; that is enough for the child's two-ring):

* a node face all of whose corners are regular is a *leaf*: a bicubic B-spline patch on its 4 x 4 net. A
  corner is regular when it is interior, smooth and of valence 4; or on an infinitely sharp crease (valence 4,
  its two sharp edges opposite, one of them a side of the face); or on the boundary with two faces. Across a
  sharp or boundary side the net gets the crease rule's ghost points ``2 c - x`` (the mirror image of the
  row inside): Catmull-Clark with the crease rules on such a net is the B-spline subdivision of the mirrored
  net, so the leaf is exact;
* any other node is subdivided once and its four children are nodes one level down.

Below the level where the tags around a node are stationary (0 or infinite) and the node has a single
irregular corner w, its rows are kept as deviations from w's limit point (exact limit mask,
:func:`~ccproof.apps.control_mesh.moving_limit_rows`), which decay like lambda^l: no cancellation in the
derivatives at deep levels (docs/qmv98.md section 2, item 4). Per level, the three leaves of a corner node
and the one irregular child are exactly the special element's level-l patches and its next ring.

Element matrices (docs/qmv98.md B3): a leaf of depth l contributes ``scale(l) W^T T W`` (``W`` its net rows,
``T`` the unit-square term matrix, the sector rotation of the leaf exchanging ``a11/a22``, ``b11/b22`` at odd
quarter turns). The mass sums leaves down to depth ``max(L, MASS_LEVELS)`` and adds the remaining squares
(area ``4^-D`` each) at their limit point ``area * b b^T``; what that leaves out is ``O((lambda / 4)^D)``,
below 1e-16 relative at D = 20 (tests compare with the special elements' Stein solution). The stiffness is
truncated at depth L, as for the special elements, with the last increment and a geometric tail estimate in
:meth:`TaggedElement.truncation`. Evaluation descends to the leaf that holds the point (deeper levels are
built on demand, down to ``MAX_DEPTH``; below, the limit point).
"""

from __future__ import annotations

import numpy as np

from ccproof.apps.control_mesh import INFINITE, edge_values, moving_limit_rows, tagged_step
from ccproof.apps.dynamics.basis import TERMS, patch_rows, term_matrix
from ccproof.errors import MeshError

__all__ = ["TaggedElement", "tagged_layout", "regular_corners", "MASS_LEVELS", "MAX_DEPTH"]

#: depth to which the mass of a tagged element is summed before its exact constant tail
MASS_LEVELS = 20
#: deepest level that evaluation descends to (then the limit point of the corner)
MAX_DEPTH = 60
_POS = ((1, 1), (2, 1), (2, 2), (1, 2))
_FWD = ((1, 0), (0, 1), (-1, 0), (0, -1))
_LEFT = ((0, 1), (-1, 0), (0, -1), (1, 0))
_CORNERS = np.array([(0, 0), (1, 0), (1, 1), (0, 1)], dtype=float)


class _Local:
    """A small quad mesh with its tags (local labels): faces (m, 4), edge/vertex sharpness.

    Its topology is the QuadMesh's :class:`~ccproof.mesh.halfedges.HalfEdges` (``mesh.halfedges``); what is
    held here is the tags over its edges and vertices (``es``, ``vs``, ``sharp``, ``n_sharp``, ``semi_v``) and
    the cached children of the tagged step."""

    def __init__(self, faces, creases, corners, like=None):
        from ccproof.mesh import QuadMesh
        from ccproof.mesh.quadmesh import shared_halfedges

        self.faces = np.asarray(faces, dtype=np.int64).reshape(-1, 4)
        n = int(self.faces.max()) + 1
        # ``like``: a mesh whose topology is shared when the faces are its faces (a two-ring that is the whole mesh)
        he = None if like is None else shared_halfedges(like, self.faces, n)
        self.mesh = QuadMesh(np.zeros((n, 3)), self.faces, _halfedges=he)
        pairs, vals = creases
        self.es = edge_values(self.mesh, pairs, vals) if len(pairs) else np.zeros(self.mesh.n_edges)
        self.es = np.where(self.es >= INFINITE, np.inf, self.es)
        self.vs = np.zeros(n)
        cv, cs = corners
        if len(cv):
            self.vs[np.asarray(cv, dtype=np.int64)] = cs
        m = self.mesh
        self._children = {}
        sharp = m.is_boundary_edge | (self.es > 0)
        self.sharp = sharp
        self.n_sharp = np.bincount(m.edges[sharp].reshape(-1), minlength=n)
        semi = (self.es > 0) & np.isfinite(self.es)
        self.semi_v = np.zeros(n, dtype=bool)
        self.semi_v[m.edges[semi].reshape(-1)] = True
        self.semi_v |= (self.vs > 0) & np.isfinite(self.vs)

    def children(self, g):
        """The tagged step of this mesh (sparse (n', n)) and the four children of face ``g``: each
        ``(sub-mesh of its two-ring, the step's rows it keeps, its face in the sub-mesh)``; computed once."""
        if g not in self._children:
            from ccproof.mesh import child_faces

            S, creases, corners = tagged_step(self.mesh, self.es, self.vs)
            CF = child_faces(self.mesh)
            kids = []
            for i in range(4):
                c = 4 * g + i
                keep = _two_ring_faces(CF, c)
                sub, used = _restrict(CF, creases, corners, keep)
                kids.append((sub, used, int(np.flatnonzero(keep == c)[0])))
            self._children[g] = (S, kids)
        return self._children[g]


def regular_corners(loc, g):
    """Which corners of face ``g`` of a local mesh are regular (module docstring), and its sharp sides.

    Returns ``(regular (4,) bool, sharp_side (4,) bool)``; side ``k`` runs from corner k to corner k + 1.
    """
    m = loc.mesh
    nxt, prv, twin, edge_of = m.halfedges.nxt, m.halfedges.prv, m.twin, m.edge_of_halfedge
    F = loc.faces[g]
    side = loc.sharp[edge_of[4 * g + np.arange(4)]]  # side k: the half-edge 4 g + k
    reg = np.zeros(4, dtype=bool)
    for c in range(4):
        v = int(F[c])
        if loc.vs[v] > 0 or loc.semi_v[v]:
            continue
        ns = int(loc.n_sharp[v])
        if m.is_boundary_vertex[v]:
            reg[c] = m.face_count[v] == 2 and ns == 2 and (side[c] or side[c - 1])
            continue
        if m.valence[v] != 4 or m.face_count[v] != 4:
            continue
        if ns == 0:
            reg[c] = True
        elif ns == 2 and side[c] != side[c - 1]:
            if side[c]:  # the edge opposite side c: into v, in the face across side c - 1 (interior: twins exist)
                e = edge_of[prv[twin[4 * g + (c - 1) % 4]]]
            else:  # opposite side c - 1: out of v, in the face across side c
                e = edge_of[nxt[twin[4 * g + c]]]
            reg[c] = loc.sharp[e]
    return reg, side


def _net(loc, g, side):
    """(16, n_local) rows of the B-spline net of a regular face ``g`` (ghost points across sharp sides)."""
    m = loc.mesh
    Ff = loc.faces.reshape(-1)
    tw, nxt, prv = m.twin, m.halfedges.nxt, m.halfedges.prv
    F = loc.faces[g]
    net = [None] * 16
    idx = {}
    for c in range(4):
        idx[_POS[c]] = int(F[c])

    def at(p):
        return 4 * p[0] + p[1]

    def add(p, q):
        return (p[0] + q[0], p[1] + q[1])

    def sub(p, q):
        return (p[0] - q[0], p[1] - q[1])

    ghosts = []
    for c in range(4):
        pos, fwd, left = _POS[c], _FWD[c], _LEFT[c]
        v = {pos: {int(F[c]): 1.0}}
        p1, p3, p4 = sub(pos, left), sub(pos, fwd), sub(sub(pos, fwd), left)
        if side[c]:
            v[p1] = {int(F[c]): 2.0, int(F[(c + 3) % 4]): -1.0}
        else:
            v[p1] = {int(Ff[nxt[nxt[tw[4 * g + c]]]]): 1.0}
        if side[c - 1]:
            v[p3] = {int(F[c]): 2.0, int(F[(c + 1) % 4]): -1.0}
        else:
            v[p3] = {int(Ff[prv[tw[4 * g + (c - 1) % 4]]]): 1.0}
        if side[c]:
            ghosts.append((p4, p3, add(p3, left)))  # 2 (pos - fwd) - (pos - fwd + left)
        elif side[c - 1]:
            ghosts.append((p4, p1, add(p1, fwd)))
        else:
            t2 = tw[nxt[tw[4 * g + c]]]
            v[p4] = {int(Ff[prv[t2]]): 1.0}
        for p, w in v.items():
            net[at(p)] = w
    for p4, a, b in ghosts:
        w = {}
        for k, x in net[at(a)].items():
            w[k] = w.get(k, 0.0) + 2.0 * x
        for k, x in net[at(b)].items():
            w[k] = w.get(k, 0.0) - x
        net[at(p4)] = w
    G = np.zeros((16, m.n_vertices))
    for i, w in enumerate(net):
        for k, x in w.items():
            G[i, k] += x
    return G


def _two_ring_faces(faces, g):
    F = np.asarray(faces)
    n = int(F.max()) + 1
    inc = np.zeros((F.shape[0], n), dtype=bool)
    inc[np.arange(F.shape[0])[:, None], F] = True
    one = inc[:, F[g]].any(axis=1)
    verts = inc[one].any(axis=0)
    return np.flatnonzero(inc[:, verts].any(axis=1))


class _Node:
    __slots__ = ("loc", "g", "R", "base", "o", "A", "depth", "w")

    def __init__(self, loc, g, R, base, o, A, depth, w=None):
        self.loc, self.g, self.R, self.base, self.o, self.A, self.depth = loc, g, R, base, o, A, depth
        self.w = w  # face parameter of the irregular corner whose limit point is ``base``


#: the small meshes already built, by their exact local faces and tags (:func:`_local`)
_LOCALS: dict = {}
#: how many small meshes :data:`_LOCALS` keeps before it is emptied
_LOCALS_MAX = 4096


def _local(faces, pairs, vals, cv, cs, like=None):
    """The :class:`_Local` of these local faces and tags: built once, then reused while it is cached.

    The key is the exact arrays (faces (m, 4), crease pairs (k, 2) and values (k,), corner labels (j,) and
    values (j,), their bytes and dtypes), so a reused mesh is the one a new build would give; a ``_Local``
    is never changed once built (its children, :meth:`_Local.children`, are cached on it too).
    """
    arrays = [np.ascontiguousarray(a) for a in (faces, pairs, vals, cv, cs)]
    key = tuple((a.dtype.str, a.shape, a.tobytes()) for a in arrays)
    loc = _LOCALS.get(key)
    if loc is None:
        if len(_LOCALS) >= _LOCALS_MAX:
            _LOCALS.clear()
        loc = _LOCALS[key] = _Local(arrays[0], (arrays[1], arrays[2]), (arrays[3], arrays[4]), like=like)
    return loc


def _restrict(faces, creases, corners, keep_faces):
    """The sub-mesh of ``keep_faces`` (order kept), relabelled, with its tags; and its vertices (the rows kept)."""
    sub = faces[keep_faces]
    used, inv = np.unique(sub, return_inverse=True)
    new = np.full(faces.max() + 1, -1, dtype=np.int64)
    new[used] = np.arange(used.size)
    pairs, vals = creases
    pairs = np.asarray(pairs, dtype=np.int64).reshape(-1, 2)
    ok = (new[pairs] >= 0).all(axis=1) if pairs.size else np.zeros(0, dtype=bool)
    cv, cs = corners
    cv = np.asarray(cv, dtype=np.int64)
    okv = new[cv] >= 0 if cv.size else np.zeros(0, dtype=bool)
    loc = _local(inv.reshape(-1, 4), new[pairs[ok]], np.asarray(vals)[ok], new[cv[okv]], np.asarray(cs)[okv])
    return loc, used


class TaggedElement:
    """The tagged element of one face of a tagged control mesh (module docstring).

    Parameters
    ----------
    mesh : QuadMesh
        The control mesh.
    face : int
    edge_sharpness : ndarray, shape (E,)
        Over ``mesh.edges`` (boundary edges are sharp anyway).
    vertex_sharpness : ndarray, shape (n,)
    levels : int
        Truncation depth L of the stiffness.

    Attributes
    ----------
    ids : ndarray of int64, shape (k,)
        The control set (global vertex ids): the face's two-ring.
    leaves : list of tuple
        ``(depth, o, A, rows (16, k), base (k,) or None)``: the leaf's patch ``(s, t) -> o + A (s, t)`` in
        the face parameter, its net rows (deviations from ``base`` when given).

    Examples
    --------
    A 3 x 3 grid with a crease along the middle row: the middle face's corners are regular crease vertices,
    so the element is one B-spline patch with ghost points, and its limit point at a crease vertex is the
    crease mask ``(e0 + 4 V + e1) / 6`` of the crease:

    >>> import numpy as np
    >>> from ccproof.mesh.examples import grid
    >>> from ccproof.apps.control_mesh import edge_values
    >>> g = grid(3, 3)
    >>> es = edge_values(g, [[4, 5], [5, 6], [6, 7]])
    >>> el = TaggedElement(g, 4, es, np.zeros(16))
    >>> len(el.leaves), el.leaves[0][0]
    (1, 0)
    >>> P = g.vertices[el.ids]
    >>> r = el.rows([0.0], [0.0])["P"] @ P
    >>> bool(np.allclose(r, (g.vertices[4] + 4 * g.vertices[5] + g.vertices[6]) / 6))
    True
    """

    def __init__(self, mesh, face, edge_sharpness, vertex_sharpness, levels=8):
        self.face = int(face)
        self.levels = int(levels)
        F = mesh.faces
        ring = _two_ring_faces(F, self.face)
        ids, inv = np.unique(F[ring], return_inverse=True)
        self.ids = ids
        k = ids.size
        new = np.full(mesh.n_vertices, -1, dtype=np.int64)
        new[ids] = np.arange(k)
        sel = np.flatnonzero(edge_sharpness > 0)
        pairs = new[mesh.edges[sel]]
        ok = (pairs >= 0).all(axis=1)
        cv = np.flatnonzero(vertex_sharpness > 0)
        okv = new[cv] >= 0
        loc = _local(inv.reshape(-1, 4), pairs[ok], edge_sharpness[sel][ok], new[cv[okv]],
                     vertex_sharpness[cv][okv], like=mesh)
        g = int(np.flatnonzero(ring == self.face)[0])
        self.leaves = []
        self._pending = []  # irregular nodes at the deepest built level
        self._built = -1
        root = _Node(loc, g, np.eye(k), None, np.zeros(2), np.eye(2), 0)
        self._pending = [root]
        self._grow(max(self.levels, MASS_LEVELS))

    # ------------------------------------------------------------------ construction
    def _grow(self, depth):
        while self._pending and self._built < depth:
            nxt = []
            for node in self._pending:
                reg, side = regular_corners(node.loc, node.g)
                if reg.all():
                    G = _net(node.loc, node.g, side)
                    self.leaves.append((node.depth, node.o, node.A, G @ node.R, node.base))
                    continue
                if node.base is None and (~reg).sum() == 1 and not node.loc.semi_v.any():
                    wc = int(np.flatnonzero(~reg)[0])
                    w = int(node.loc.faces[node.g][wc])
                    node.w = node.o + node.A @ _CORNERS[wc]
                    lrow = moving_limit_rows(node.loc.mesh, [w], node.loc.es, node.loc.vs).toarray()[0]
                    node.base = lrow @ node.R
                    node.R = node.R - node.base[None, :]
                if node.depth >= MAX_DEPTH and node.base is None:
                    raise MeshError(f"face {self.face}: a tagged element that does not become regular in "
                                    f"{MAX_DEPTH} levels (internal error)")
                nxt.extend(self._children(node))
            self._pending = nxt
            self._built += 1

    def _children(self, node):
        S, kids = node.loc.children(node.g)
        R = S @ node.R
        out = []
        for i, (sub, used, gc) in enumerate(kids):
            ci = _CORNERS[i]
            cols = np.c_[(_CORNERS[(i + 1) % 4] - ci) / 2, (_CORNERS[(i + 3) % 4] - ci) / 2]
            out.append(_Node(sub, gc, R[used], node.base, node.o + node.A @ ci, node.A @ cols, node.depth + 1,
                             node.w))
        return out

    # ------------------------------------------------------------------ matrices
    @staticmethod
    def _swap(A):
        return bool(abs(A[0, 0]) < abs(A[0, 1]))

    def matrices(self, coefficients):
        """``(unit mass (k, k), stiffness (k, k))`` with ``coefficients(swap) -> {term: c}``."""
        k = self.ids.size
        M = np.zeros((k, k))
        K = np.zeros((k, k))
        T0 = term_matrix("mass")
        for depth, _, A, W, base in self.leaves:
            Wt = W if base is None else W + base[None, :]
            if depth <= MASS_LEVELS or depth <= self.levels:
                M += 4.0 ** (-depth) * (Wt.T @ T0 @ Wt)
            if depth <= self.levels:
                coef = coefficients(self._swap(A))
                for t, c in coef.items():
                    if c and t != "mass":
                        K += c * 4.0 ** (depth * (sum(TERMS[t]) - 1)) * (W.T @ term_matrix(t) @ W)
        for node in self._pending:  # the squares below the deepest mass level, at their limit point
            if node.base is None:
                raise MeshError(f"face {self.face}: a tagged element without a limit point (internal error)")
            M += 4.0 ** (-node.depth) * np.outer(node.base, node.base)
        return M, K

    def truncation(self, coefficients, P=None):
        """``(K(L), its depth-L increment, ratio of the last two increments)`` as Frobenius norms, or with ``P``
        (control points (n, 3) of the whole mesh) as energies ``1/2 tr(P_e^T X P_e)``."""
        incs = {}
        for depth, _, A, W, _ in self.leaves:
            if 1 <= depth <= self.levels:
                coef = coefficients(self._swap(A))
                X = sum(c * 4.0 ** (depth * (sum(TERMS[t]) - 1)) * (W.T @ term_matrix(t) @ W)
                        for t, c in coef.items() if c and t != "mass")
                incs[depth] = incs.get(depth, 0.0) + X
        _, K = self.matrices(coefficients)
        L = self.levels
        if P is None:
            def size(X):
                return float(np.linalg.norm(X))
        else:
            Pe = np.asarray(P, dtype=np.float64)[self.ids]

            def size(X):
                return 0.5 * float(np.sum(Pe * (np.asarray(X) @ Pe))) if np.ndim(X) else 0.0
        last, prev = size(incs.get(L, 0.0)), size(incs.get(L - 1, 0.0))
        return size(K), last, (last / prev if prev > 0 else 0.0)

    # ------------------------------------------------------------------ evaluation
    def rows(self, u, v, derivatives=0):
        """Rows over :attr:`ids` of the limit surface (and derivatives in the face parameter) at (u, v)."""
        u = np.asarray(u, dtype=np.float64).reshape(-1)
        v = np.asarray(v, dtype=np.float64).reshape(-1)
        names = ["P"] + (["Pu", "Pv"] if derivatives >= 1 else []) + (["Puu", "Puv", "Pvv"] if derivatives >= 2 else [])
        out = {x: np.zeros((u.size, self.ids.size)) for x in names}
        todo = np.ones(u.size, dtype=bool)
        for node in self._pending:  # exactly at an irregular corner: its limit point
            if node.w is not None:
                at = todo & (u == node.w[0]) & (v == node.w[1])
                out["P"][at] = node.base[None, :]
                todo &= ~at
        while True:
            for _, o, A, W, base in self.leaves:
                if not todo.any():
                    return out
                Ai = np.linalg.inv(A)
                st = (np.c_[u, v] - o) @ Ai.T
                tol = 1e-12
                inside = todo & (st >= -tol).all(axis=1) & (st <= 1 + tol).all(axis=1)
                if not inside.any():
                    continue
                idx = np.flatnonzero(inside)
                s, t = np.clip(st[idx, 0], 0, 1), np.clip(st[idx, 1], 0, 1)
                pr = patch_rows(s, t, derivatives)
                out["P"][idx] = pr["P"] @ W + (0.0 if base is None else base[None, :])
                if derivatives >= 1:
                    Ps, Pt = pr["Pu"] @ W, pr["Pv"] @ W
                    out["Pu"][idx] = Ai[0, 0] * Ps + Ai[1, 0] * Pt
                    out["Pv"][idx] = Ai[0, 1] * Ps + Ai[1, 1] * Pt
                if derivatives >= 2:
                    H = {(0, 0): pr["Puu"] @ W, (0, 1): pr["Puv"] @ W, (1, 1): pr["Pvv"] @ W}
                    H[(1, 0)] = H[(0, 1)]
                    for name, (r1, r2) in (("Puu", (0, 0)), ("Puv", (0, 1)), ("Pvv", (1, 1))):
                        out[name][idx] = sum(Ai[a1, r1] * Ai[a2, r2] * H[(a1, a2)] for a1 in range(2)
                                             for a2 in range(2))
                todo[idx] = False
            if not todo.any():
                return out
            if self._built >= MAX_DEPTH - 1 or not self._pending:
                for node in self._pending:
                    st = (np.c_[u, v] - node.o) @ np.linalg.inv(node.A).T
                    at = todo & (st >= -1e-12).all(axis=1) & (st <= 1 + 1e-12).all(axis=1)
                    out["P"][at] = node.base[None, :]
                    todo &= ~at
                return out
            self._grow(self._built + 1)


def tagged_layout(mesh):
    """The element layout of a tagged control mesh: normal, special, tagged (kind 3) and hole (kind 0) faces.

    A face is normal when its four corners are interior, smooth (no sharp edge, no vertex sharpness) and of
    valence 4; special when it lies in the fan of a smooth interior extraordinary vertex whose fan has no hole
    and all of whose other fan corners are such regular vertices; a hole carries no patch; every other face is
    a tagged element (:class:`TaggedElement`). Without tags this is :func:`element_layout
    <ccproof.apps.dynamics.elements.element_layout>`'s layout except that boundary faces, faces with two
    extraordinary vertices and the fans of skipped extraordinary vertices become tagged elements.

    Parameters
    ----------
    mesh : QuadMesh or TaggedQuadMesh

    Returns
    -------
    layout : ElementLayout
        ``face_kind`` 3 for tagged faces, ``face_element`` their index in ``tagged_faces``.
    tagged_faces : ndarray of int64, shape (k,)

    Examples
    --------
    The cube: every face has four valence-3 corners, so with one infinitely sharp edge all six faces are
    tagged elements:

    >>> from ccproof.mesh.examples import cube
    >>> from ccproof.apps.control_mesh import TaggedQuadMesh
    >>> c = cube()
    >>> lay, tf = tagged_layout(TaggedQuadMesh(c.vertices, c.faces, creases=([c.faces[0][:2]], [10.0])))
    >>> tf.tolist(), lay.face_kind.tolist()
    ([0, 1, 2, 3, 4, 5], [3, 3, 3, 3, 3, 3])
    """
    from ccproof.apps.control_mesh import tags_of, vertex_rules
    from ccproof.apps.dynamics.elements import ElementLayout, normal_nets, special_elements

    es, vs = tags_of(mesh)
    ns = vertex_rules(mesh, es, vs)[0]
    hole = getattr(mesh, "hole", np.zeros(mesh.n_faces, dtype=bool))
    smooth = ~mesh.is_boundary_vertex & (ns == 0) & (vs == 0)
    regular = smooth & (mesh.valence == 4)
    F = mesh.faces
    m = mesh.n_faces
    kind = np.full(m, 3, dtype=np.int64)
    kind[hole] = 0
    elem = np.full(m, -1, dtype=np.int64)
    sector = np.full(m, -1, dtype=np.int64)
    corner = np.full(m, -1, dtype=np.int64)
    normal = np.flatnonzero(regular[F].all(axis=1) & ~hole)
    kind[normal] = 1
    elem[normal] = np.arange(normal.size)
    evs = []
    for ev in np.flatnonzero(smooth & (mesh.valence != 4)):
        fan = mesh.fan_corners[mesh.fan_ptr[ev]: mesh.fan_ptr[ev + 1]] // 4
        others = F[fan][F[fan] != ev]
        if not hole[fan].any() and regular[others].all():
            evs.append(int(ev))
    specials = special_elements(mesh, evs, kind, elem, sector, corner)
    tagged = np.flatnonzero(kind == 3)
    elem[tagged] = np.arange(tagged.size)
    lay = ElementLayout(normal_faces=normal, normal_nets=normal_nets(mesh, normal), **specials,
                        face_kind=kind, face_element=elem, face_sector=sector, face_corner=corner,
                        skipped_ev=np.zeros(0, dtype=np.int64))
    return lay, tagged
