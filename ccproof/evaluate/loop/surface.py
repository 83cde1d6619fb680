"""Exact Loop limit evaluation: :class:`LoopSurface`.

Parameter of a triangle (OpenSubdiv's Loop patches): corner 0 at (0, 0), corner 1 at (1, 0), corner 2
at (0, 1), ``u, v >= 0``, ``u + v <= 1``; ``face`` is the triangle's index::

    v
    1  c2
       | \\
       |   \\
       |     \\
    0  c0 ---- c1
       0        1  u

Method (exact up to the rounding of the stored tables, :mod:`ccproof.evaluate.loop.plan`): the one-ring
of each triangle is read from its irregular corner when it has exactly one. A triangle whose corners are
regular (smooth, valence 6) is a box-spline patch (:mod:`ccproof.evaluate.loop.box_spline`); a triangle
with one irregular corner is evaluated by Stam's self-similar layers (exact matrix powers, once per
configuration); any other triangle is subdivided locally and exactly until its children are one of
these (on a closed mesh once). Every configuration's data are computed once (cached by its ring key);
per triangle its control points are stored (memory O(faces)), and for the compiled backend each patch's
polynomial coefficients (per corner piece those of its first layers, :mod:`ccproof.evaluate.loop.kernel`).
The numpy backend evaluates in batches: a vectorized descent through the local subdivisions, then one
gather and product per patch kind.
"""

from __future__ import annotations

import functools
import math

import numpy as np

from ccproof.errors import CCProofError
from ccproof.evaluate.loop.box_spline import basis
from ccproof.evaluate.loop.complex import TriComplex
from ccproof.evaluate.loop.plan import MAX_DEPTH, Corner, Regular, irregular_corners, oriented_ring, plan
from ccproof.evaluate.loop.regular import regular_triangles

__all__ = ["LoopSurface", "ROTATIONS", "loop_limit_surface"]

#: per ring-key encoding (:mod:`ccproof.evaluate.loop.rings`) with the boundary mode: the rotation (read from
#: corner 0) or the plan (read from corner r)
_RING_PLANS: dict = {}

#: (Jacobian, offset) of the parameter of a triangle listed from its corner r: (u', v') = J (u, v) + o
ROTATIONS = (
    (np.array([[1.0, 0.0], [0.0, 1.0]]), (0.0, 0.0)),
    (np.array([[0.0, 1.0], [-1.0, -1.0]]), (0.0, 1.0)),
    (np.array([[-1.0, -1.0], [1.0, 0.0]]), (1.0, 0.0)),
)
_KEYS = {0: ("P",), 1: ("P", "Pu", "Pv"), 2: ("P", "Pu", "Pv", "Puu", "Puv", "Pvv")}
_REGULAR, _CORNER, _SPLIT = 0, 1, 2


def _triangles(mesh):
    """The faces of a PolyMesh, checked: triangles, tags the evaluator handles."""
    from ccproof.mesh.polymesh import PolyMesh

    if not isinstance(mesh, PolyMesh):
        raise CCProofError(f"the Loop scheme evaluates triangle meshes (a PolyMesh), not a {type(mesh).__name__}")
    bad = np.flatnonzero(mesh.sizes != 3)
    if bad.size:
        f = int(bad[0])
        raise CCProofError(f"the Loop scheme takes triangles only: face {f} has {int(mesh.sizes[f])} vertices")
    semi = [e for e, s in mesh.edge_sharpness.items() if 0 < s < math.inf] + \
        [v for v, s in mesh.vertex_sharpness.items() if 0 < s < math.inf]
    if semi and mesh.options.crease_method != "uniform":
        raise CCProofError(f"the Loop evaluator takes semi-sharp tags with uniform creasing only, not "
                           f"{mesh.options.crease_method!r} (semi-sharp tag at {semi[0]})")
    return mesh.polygons


def loop_limit_surface(mesh, *, scheme="loop", alpha=None):
    """``ccproof.limit_surface(mesh, scheme=...)`` for a scheme other than Catmull-Clark: the
    :class:`LoopSurface` of a PolyMesh, a QuadMesh (refused: quads) or a mesh file.

    >>> loop_limit_surface("m.obj", alpha=2.0)
    Traceback (most recent call last):
    ...
    ccproof.errors.CCProofError: alpha applies to the Catmull-Clark parameterizations (bmz04), not to scheme='loop'
    >>> loop_limit_surface("m.obj", scheme="butterfly")
    Traceback (most recent call last):
    ...
    ccproof.errors.CCProofError: scheme must be 'catmark' or 'loop', got 'butterfly'
    """
    from ccproof.mesh import QuadMesh
    from ccproof.mesh.polymesh import PolyMesh

    if scheme != "loop":
        raise CCProofError(f"scheme must be 'catmark' or 'loop', got {scheme!r}")
    if alpha is not None:
        raise CCProofError("alpha applies to the Catmull-Clark parameterizations (bmz04), not to scheme='loop'")
    if isinstance(mesh, QuadMesh):
        mesh = PolyMesh(mesh.vertices, mesh.faces.tolist())
    elif not isinstance(mesh, PolyMesh):
        from ccproof.mesh.io import read_mesh

        mesh = read_mesh(mesh)
    return LoopSurface(mesh)


class LoopSurface:
    """Exact evaluator of the Loop limit surface of a triangle mesh (OpenSubdiv's Sdc Loop rules).

    Parameters
    ----------
    mesh : PolyMesh
        Triangles only (another face size is refused, naming the face); non-manifold edges and vertices
        as OpenSubdiv takes them (:attr:`PolyMesh.manifold`). Hole faces (tagged, or
        at the boundary with boundary interpolation "none") take part in the rules but have no surface:
        points on them are refused.
    backend : {"numba", "numpy"}
        The compiled point loop (:mod:`ccproof.evaluate.loop.kernel`, default) or the vectorized numpy
        path (the nets and layer tables times the box-spline basis: the tests' second implementation).

    Attributes
    ----------
    mesh : PolyMesh
    n_regular : int
        Box-spline patches stored.
    n_corner : int
        Triangles (or local children) evaluated by self-similar layers.
    split_depth : int
        Most local subdivisions a triangle needed.

    Examples
    --------
    An octahedron (six vertices of valence 4): every triangle is split once; at a vertex the limit
    point is ``(1 - 4 eps) V + eps sum e`` with ``eps = 1 / (4 + 3 / (8 beta))``, ``beta = 31/256``:

    >>> from ccproof.mesh.polymesh import PolyMesh
    >>> V = [[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]]
    >>> T = [[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]]
    >>> S = LoopSurface(PolyMesh(V, T))
    >>> eps = 1 / (4 + 3 / (8 * 31 / 256))
    >>> P = S.evaluate([0], [0.0], [0.0])["P"]
    >>> S.split_depth, bool(abs(P[0, 0] - (1 - 4 * eps)) < 1e-15)
    (1, True)
    """

    def __init__(self, mesh, *, backend="numba"):
        if backend not in ("numba", "numpy"):
            raise CCProofError(f"backend must be 'numba' or 'numpy', got {backend!r}")
        self.backend = backend
        _triangles(mesh)
        self.mesh = mesh
        # non-manifold edges and vertices as OpenSubdiv takes them: PolyMesh's split (the same faces, the
        # non-manifold vertices copied per fan and tagged infinitely sharp)
        mesh = mesh.manifold
        self._holes = np.asarray(mesh.is_hole, dtype=bool) if mesh.is_hole.any() else None
        X = np.asarray(mesh.vertices, dtype=np.float64)
        self._kind, self._rot, self._ref, self._children, self._gid = [], [], [], [], []
        self._nets, self._n_nets, self._groups = [], 0, {}  # nets: (12, 3) or (m, 12, 3) each
        self.split_depth = 0
        tagged = {v for e in mesh.edge_sharpness for v in e} | set(mesh.vertex_sharpness)
        F = mesh.indices.reshape(-1, 3)
        reg, labels, simple, boundary = regular_triangles(F, len(X), tagged, mesh.halfedges.twin)
        # the complex of the other triangles' corners' fans (the rings walked below)
        near = np.zeros(len(X), dtype=bool)
        near[F[~reg].reshape(-1)] = True
        self._cx = None  # built when a ring is read the per-triangle way (_complex)
        self._cx_faces = F[near[F].any(axis=1)]
        self._tags = (dict(mesh.edge_sharpness), dict(mesh.vertex_sharpness), None, mesh.options.boundary)
        # corners decided without the complex: simple ones regular, untagged interior others irregular
        ask = boundary.copy()
        ask[list(tagged)] = True
        self._simple, self._ask = simple.tolist(), ask.tolist()
        self._root = np.empty(F.shape[0], dtype=np.int64)
        self._root[reg] = np.arange(labels.shape[0])  # the regular triangles first: nodes 0 .. R-1
        nr = labels.shape[0]
        self._nreg = nr  # nodes 0 .. nr - 1; the lists hold the nodes from nr on
        self._labels, self._X = labels, X  # the regular triangles' nets: X[labels] (_finish)
        known = self._ring_groups(mesh, F, near[F].any(axis=1), reg, simple, ask)
        rest = ~reg
        rest[[f for f, hit in known.items() if hit is True]] = False
        for f, tri in zip(np.flatnonzero(rest).tolist(), F[rest].tolist()):
            hit = known.get(f)
            if hit is None:
                self._root[f] = self._add_face(X, tri)
            else:
                self._root[f] = self._add(hit[0], hit[1], X[hit[2]], 0)
        self._finish()

    def _complex(self):
        """The complex of the fans of the non-regular triangles' corners (the rings read the per-triangle way)."""
        if self._cx is None:
            self._cx = TriComplex(self._cx_faces.tolist(), *self._tags)
        return self._cx

    def _ring_groups(self, mesh, F, in_cx, reg, simple, ask):
        """The rings of the triangles without a corner known irregular, read at once (:mod:`.rings`) and grouped by
        key: per face (plan, rotation, ring labels); ``True`` for those whose box-spline nets are stored here at once
        (their roots set). A key's plan and rotation are read once the per-triangle way (the ring checked against the
        compiled one) and kept for the process; faces left out go the per-triangle way."""
        from ccproof.evaluate.loop.rings import equal_rows, halfedge_sharpness, triangle_rings, vertex_sharpness_array

        faces = np.flatnonzero(~reg & (simple | ask)[F].all(axis=1))
        if not faces.size:
            return {}
        twin = mesh.halfedges.twin.copy()
        twin[(twin < 0) | ~in_cx[np.maximum(twin, 0) // 3]] = -1
        args = (F, twin, halfedge_sharpness(F, mesh.edge_sharpness),
                vertex_sharpness_array(len(ask), mesh.vertex_sharpness))
        max_fan = int(np.bincount(F.reshape(-1)).max()) + 1

        rings, rows, lengths = triangle_rings(*args, faces, max_fan)
        rot, groups = np.zeros(faces.size, dtype=np.int64), []
        for i, members in equal_rows(rows):
            rot[members] = r = self._rotation(rows[i, :lengths[i]], F[faces[i]].tolist())
            if r == 0:
                groups.append((0, rings, rows[:, :lengths[i]], i, members))
        turned = np.flatnonzero(rot)  # rings read from corner r; grouped again (their keys from there)
        if turned.size:
            rt, wt, lt = triangle_rings(*args, faces[turned], max_fan, rot[turned])
            groups += [(int(rot[turned[j]]), rt, wt[:, :lt[j]], j, sub)
                       for j, sub in equal_rows(np.column_stack([rot[turned], wt]))]
        known = {}
        for r, rg, rw, j, sub in groups:
            f0 = faces[j] if r == 0 else faces[turned[j]]
            p = self._ring_plan(r, rw[j], F[f0].tolist(), rg[j])
            if p is None:
                continue
            fs, x = (faces[sub] if r == 0 else faces[turned[sub]]), rg[sub, :int(rw[j, 0])]
            if isinstance(p, (Regular, Corner)):
                (self._add_regular if isinstance(p, Regular) else self._add_corners)(p, r, fs, x)
                known.update(dict.fromkeys(fs.tolist(), True))
            else:
                known.update((f, (p, r, y)) for f, y in zip(fs.tolist(), x))
        return known

    def _rotation(self, row, tri):
        """The corner r a triangle's ring is read from (:func:`~ccproof.evaluate.loop.plan.oriented_ring`), per key
        encoding ``row`` (read from corner 0) of the triangle ``tri`` (kept for the process)."""
        key = ("rotation", self._tags[3], row.tobytes())
        if key not in _RING_PLANS:
            irr = irregular_corners(self._complex(), tri)
            _RING_PLANS[key] = irr[0] if len(irr) == 1 else 0
        return _RING_PLANS[key]

    def _ring_plan(self, r, row, tri, ring):
        """The plan of the triangles of key encoding ``row`` from their corner r (the triangle ``tri`` one of them,
        its compiled ring ``ring``), or None where the compiled ring is not the per-triangle one (kept for the
        process)."""
        key = (r, self._tags[3], row.tobytes())
        hit = _RING_PLANS.get(key)
        if hit is None:
            r2, labels, k = oriented_ring(self._complex(), tri)
            n = len(labels)
            if r2 != r or ring[:n].tolist() != labels or ring[n:n + 1].tolist() not in ([], [-1]):
                return None
            hit = _RING_PLANS[key] = plan(k)
        return hit

    def _add_corners(self, p, r, faces, rings):
        """Corner nodes (Stam's layers, read from corner r) for triangles of one configuration: their rings' points."""
        m = faces.size
        g = self._groups.setdefault(id(p), (len(self._groups), p, []))
        self._root[faces] = self._nreg + len(self._kind) + np.arange(m)
        self._kind += [_CORNER] * m
        self._rot += [r] * m
        self._ref += range(len(g[2]), len(g[2]) + m)
        self._children += [(-1, -1, -1, -1)] * m
        self._gid += [g[0]] * m
        g[2].extend(self._X[rings])

    def _add_regular(self, p, r, faces, rings):
        """Box-spline nodes for triangles of one configuration (read from corner r): nets ``p.net @ X[ring]`` in one
        batched product."""
        m = faces.size
        node = self._nreg + len(self._kind)
        self._root[faces] = node + np.arange(m)
        ref = self._nreg + self._n_nets
        self._kind += [_REGULAR] * m
        self._rot += [r] * m
        self._ref += range(ref, ref + m)
        self._children += [(-1, -1, -1, -1)] * m
        self._gid += [-1] * m
        self._nets.append(np.matmul(p.net, self._X[rings]))
        self._n_nets += m

    def _add_face(self, X, tri):
        cx, simple, ask = self._complex(), self._simple, self._ask
        irr = [i for i in range(3) if not simple[tri[i]]
               and (not ask[tri[i]] or not cx.is_regular(tri[i], tri[(i + 1) % 3]))]
        r, ring, key = oriented_ring(cx, tri, irr)
        return self._add(plan(key), r, X[ring], 0)

    def _add(self, p, r, C, depth):
        node = self._nreg + len(self._kind)
        self._kind.append(_SPLIT)
        self._rot.append(r)
        self._ref.append(-1)
        self._children.append((-1, -1, -1, -1))
        self._gid.append(-1)
        self.split_depth = max(self.split_depth, depth)
        if isinstance(p, Regular):
            i = node - self._nreg
            self._kind[i], self._ref[i] = _REGULAR, self._nreg + self._n_nets
            self._nets.append(p.net @ C)
            self._n_nets += 1
        elif isinstance(p, Corner):
            g = self._groups.setdefault(id(p), (len(self._groups), p, []))
            i = node - self._nreg
            self._kind[i], self._ref[i], self._gid[i] = _CORNER, len(g[2]), g[0]
            g[2].append(C)
        else:
            kids = tuple(self._add(cp, cr, rows @ C, depth + 1) for cr, rows, _, cp in p.children)
            self._children[node - self._nreg] = kids
        return node

    def _finish(self):
        nr = self._nreg
        self._kind = np.r_[np.full(nr, _REGULAR, dtype=np.int8), np.array(self._kind, dtype=np.int8)]
        self._rot = np.r_[np.zeros(nr, dtype=np.int8), np.array(self._rot, dtype=np.int8)]
        self._ref = np.r_[np.arange(nr, dtype=np.int64), np.array(self._ref, dtype=np.int64)]
        self._children = np.concatenate([np.full((nr, 4), -1, dtype=np.int64),
                                         np.array(self._children, dtype=np.int64).reshape(-1, 4)])
        local_nets = np.concatenate([x.reshape(-1, 12, 3) for x in self._nets] + [np.zeros((0, 12, 3))])
        self._gid = np.r_[np.full(nr, -1, dtype=np.int64), np.array(self._gid, dtype=np.int64)]
        self._corner_data = []
        groups = sorted(self._groups.values(), key=lambda g: g[0])
        for _, p, coords in groups:
            self._corner_data.append((p, np.array(coords)))
        self._groups = None
        self.n_regular = nr + local_nets.shape[0]
        self.n_corner = sum(len(c) for _, c in self._corner_data)
        labels, X = self._labels, self._X
        self._labels = self._X = None
        if self.backend == "numba":
            self._nets = None
            self._kernel_tables(X, labels, local_nets)
        else:
            self._nets = np.concatenate([X[labels], local_nets])

    def _kernel_tables(self, X, labels, local_nets):
        """The flat tables of :func:`ccproof.evaluate.loop.kernel.evaluate_loop_points`: the quartic blocks (box-spline
        patches, then per corner piece its first layers, limit point included), per piece its first block, ring
        offset and limit point, per configuration its ring size, layer count and layer offset. The blocks of the
        regular triangles are summed from the vertices ``X`` and their nets' ``labels`` (:mod:`.blocks`), those of
        the local subdivisions' box-spline patches from ``local_nets``."""
        from ccproof.evaluate.loop.blocks import quartic_blocks
        from ccproof.evaluate.loop.kernel import PRECOMPUTED_LAYERS

        K = _box_spline_matrix()
        counts = [len(c) for _, c in self._corner_data]
        start = np.cumsum([0] + counts)
        cref = self._ref.copy()
        corner = self._kind == _CORNER
        cref[corner] += start[self._gid[corner]]
        nb = self.n_regular
        n_blocks = nb + sum(3 * min(PRECOMPUTED_LAYERS, p.poly_layers.shape[0]) * len(c) for p, c in self._corner_data)
        blocks = np.empty((n_blocks, 3, 15))
        nr = labels.shape[0]
        quartic_blocks(X, labels, K, blocks[:nr])
        blocks[nr:nb] = np.matmul(local_nets.transpose(0, 2, 1), K.T)
        pblock, plim = [], []
        for p, coords in self._corner_data:
            KD = p.poly_layers  # (layers, 3, N, 15)
            nl = min(PRECOMPUTED_LAYERS, KD.shape[0])
            lim = np.einsum("N,mNk->mk", p.limit_mask, coords)  # (m, 3)
            m = len(coords)
            W = _layer_matrix(p, nl)
            B = (W @ coords.transpose(1, 0, 2).reshape(p.size, 3 * m)).reshape(nl, 3, 15, m, 3)
            B = B.transpose(3, 0, 1, 4, 2)  # (m, layer, child, coordinate, monomial)
            out = blocks[nb:nb + 3 * nl * m].reshape(m, nl, 3, 3, 15)
            out[...] = B
            out[..., 0] += lim[:, None, None, :]
            pblock.append(nb + 3 * nl * np.arange(m, dtype=np.int64))
            nb += 3 * nl * m
            plim.append(lim)
        sizes = np.array([p.size for p, _ in self._corner_data], dtype=np.int64)
        pieces = (np.concatenate(pblock + [np.zeros(0, dtype=np.int64)]), np.repeat(np.arange(len(counts)), counts),
                  np.r_[0, np.cumsum(np.repeat(sizes * 3, counts))][:-1].astype(np.int64),
                  np.concatenate(plim + [np.zeros((0, 3))]))
        groups = (sizes, np.array([p.layers.shape[0] for p, _ in self._corner_data], dtype=np.int64),
                  np.cumsum([0] + [p.poly_layers.size for p, _ in self._corner_data])[:-1].astype(np.int64))
        flat = np.concatenate([c.reshape(-1) for _, c in self._corner_data] + [np.zeros(0)])
        # per node one word: its reference (block; piece; for a split its row of cinfo), rotation and kind
        split = self._kind == _SPLIT
        cref[split] = np.arange(int(split.sum()))
        info = cref * 16 + self._rot.astype(np.int64) * 4 + self._kind.astype(np.int64)
        cinfo = info[self._children[split]]
        self._k = (info[self._root], cinfo.reshape(-1, 4), blocks,
                   (pieces, groups, _flat_layers(tuple(p for p, _ in self._corner_data)), flat))

    # ------------------------------------------------------------------ evaluation
    def evaluate(self, face, u, v, derivatives=0, *, parameterization="natural", threads=None):
        """Position and derivatives at points (face, u, v): dict of (n, 3) arrays ``P`` (and ``Pu``,
        ``Pv``; ``Puu``, ``Puv``, ``Pvv``) with respect to the triangle's (u, v).

        ``parameterization``: ``"natural"`` only (bmz04's reparameterizations are Catmull-Clark's);
        ``threads``: accepted for the interface of :class:`~ccproof.evaluate.surface.LimitSurface`
        (this evaluator runs on the calling thread). Raises CCProofError for a face out of range or a
        point outside its triangle (naming it).
        """
        if parameterization != "natural":
            raise CCProofError(f"the {parameterization!r} parameterization is Catmull-Clark's (bmz04); "
                               "the Loop surface has the natural one only")
        face, u, v = self._checked(face, u, v, derivatives)
        if self.backend == "numba":
            return self._evaluate_compiled(face, u, v, derivatives)
        return self._evaluate_numpy(face, u, v, derivatives)

    def _evaluate_numpy(self, face, u, v, derivatives):
        """The vectorized path: descent through the splits, then one product per patch kind."""
        n = face.size
        node = self._root[face]
        T = np.broadcast_to(np.eye(2), (n, 2, 2)).copy()
        u, v = self._turn(node, u.copy(), v.copy(), T)
        for _ in range(MAX_DEPTH + 2):
            idx = np.flatnonzero(self._kind[node] == _SPLIT)
            if idx.size == 0:
                break
            c, (a, b), s = _child(u[idx], v[idx])
            u[idx], v[idx] = a, b
            T[idx] *= s[:, None, None]
            node[idx] = self._children[node[idx], c]
            self._turn_some(node, u, v, T, idx)
        out = {k: np.empty((n, 3)) for k in _KEYS[derivatives]}
        local = {k: np.empty((n, 3)) for k in _KEYS[derivatives]}
        reg = np.flatnonzero(self._kind[node] == _REGULAR)
        if reg.size:
            _put(local, reg, _patch(basis(u[reg], v[reg], derivatives), self._nets[self._ref[node[reg]]]))
        gid = self._gid[node]
        for g in np.unique(gid[gid >= 0]):
            p, coords = self._corner_data[g]
            idx = np.flatnonzero(gid == g)
            if idx.size:
                _put(local, idx, _layers(p, coords[self._ref[node[idx]]], u[idx], v[idx], derivatives))
        _chain(out, local, T, derivatives)
        return out

    def _evaluate_compiled(self, face, u, v, derivatives):
        from ccproof.evaluate.loop.kernel import evaluate_loop_points

        nrows = (1, 3, 6)[derivatives]
        out = np.empty((nrows, face.size, 3))
        evaluate_loop_points(face, u, v, nrows, self._k, out)
        return {key: out[r] for r, key in enumerate(_KEYS[derivatives])}

    def _turn(self, node, u, v, T):
        self._turn_some(node, u, v, T, np.arange(node.size))
        return u, v

    def _turn_some(self, node, u, v, T, idx):
        r = self._rot[node[idx]]
        for k in (1, 2):
            sel = idx[r == k]
            if sel.size:
                J, (ou, ov) = ROTATIONS[k]
                a = J[0, 0] * u[sel] + J[0, 1] * v[sel] + ou
                b = J[1, 0] * u[sel] + J[1, 1] * v[sel] + ov
                u[sel], v[sel] = a, b
                T[sel] = J @ T[sel]

    def _checked(self, face, u, v, derivatives):
        if derivatives not in _KEYS:
            raise CCProofError(f"derivatives must be 0, 1 or 2, got {derivatives!r}")
        face = np.asarray(face).reshape(-1)
        u = np.asarray(u, dtype=np.float64).reshape(-1)
        v = np.asarray(v, dtype=np.float64).reshape(-1)
        if not (face.shape == u.shape == v.shape):
            raise CCProofError(f"face, u and v must have the same length, got {face.size}, {u.size}, {v.size}")
        if face.size and not np.issubdtype(face.dtype, np.integer):
            raise CCProofError(f"face indices must be integers, got {face.dtype}")
        face = face.astype(np.int64)
        m = len(self._root)
        bad = np.flatnonzero((face < 0) | (face >= m) | ~(u >= 0) | ~(v >= 0) | ~(u + v <= 1 + 4e-16))
        if not bad.size and self._holes is not None:
            hole = np.flatnonzero(self._holes[face])
            if hole.size:
                i = int(hole[0])
                raise CCProofError(f"point {i}: face {int(face[i])} is a hole (tagged, or at the boundary with "
                                   "boundary interpolation 'none'): it has no limit surface")
        if bad.size:
            i = int(bad[0])
            raise CCProofError(f"point {i}: face {int(face[i])}, (u, v) = ({float(u[i])!r}, {float(v[i])!r}) is not in "
                               f"a triangle of this mesh ({m} faces; u, v >= 0, u + v <= 1)")
        return face, u, v


_LAYER_MATRICES: dict = {}
_FLAT_LAYERS: dict = {}


def _flat_layers(plans):
    """The layer tables (monomial form) of corner configurations one after the other, flat (kept for the last few
    sequences of configurations: the same mesh set up again shares them; the kernel only reads them)."""
    key = tuple(id(p) for p in plans)
    hit = _FLAT_LAYERS.get(key)
    if hit is None or any(a is not b for a, b in zip(hit[0], plans)):
        if len(_FLAT_LAYERS) >= 8:
            _FLAT_LAYERS.clear()
        hit = _FLAT_LAYERS[key] = (plans, np.concatenate([p.poly_layers.reshape(-1) for p in plans] + [np.zeros(0)]))
    return hit[1]


def _layer_matrix(p, nl):
    """The first ``nl`` layers of a corner configuration's monomial form as one (nl 45, N) matrix (kept)."""
    hit = _LAYER_MATRICES.get((id(p), nl))
    if hit is None or hit[0] is not p:
        W = p.poly_layers[:nl].transpose(0, 1, 3, 2).reshape(nl * 45, p.size)
        hit = _LAYER_MATRICES[(id(p), nl)] = (p, W)
    return hit[1]


@functools.lru_cache(maxsize=1)
def _box_spline_matrix():
    """The box spline's (15, 12) coefficient matrix (rationals of denominators up to 12) in float64, read-only."""
    from ccproof.evaluate.loop.box_spline import basis_coefficients

    K = np.array([[int(x.p) / int(x.q) for x in row] for row in basis_coefficients()])
    K.setflags(write=False)
    return K


def _child(u, v):
    """(child index, child parameters, derivative factor) of points of a split triangle (loop_step's order)."""
    c = np.where(u >= 0.5, 1, np.where(v >= 0.5, 2, np.where(u + v <= 0.5, 0, 3)))
    a = np.where(c == 3, 1 - 2 * u, np.where(c == 1, 2 * u - 1, 2 * u))
    b = np.where(c == 3, 1 - 2 * v, np.where(c == 2, 2 * v - 1, 2 * v))
    return c, (a, b), np.where(c == 3, -2.0, 2.0)


def _patch(w, nets):
    """Local P and derivatives of box-spline patches: weights dict (basis) and nets (m, 12, 3)."""
    names = {(0, 0): "P", (1, 0): "Pu", (0, 1): "Pv", (2, 0): "Puu", (1, 1): "Puv", (0, 2): "Pvv"}
    return {names[k]: np.einsum("mk,mkc->mc", x, nets) for k, x in w.items()}


def _put(dst, idx, src):
    for k, x in src.items():
        dst[k][idx] = x


def _layers(p, C, u, v, derivatives):
    """Local P and derivatives at corner 0 of configuration ``p`` (Stam's layers) on rings C (m, N, 3)."""
    nl = p.layers.shape[0]
    _, e = np.frexp(u + v)  # u + v = f 2^e, f in [1/2, 1): layer n = -e
    n = np.where(u + v > 0, np.maximum(-e, 0), nl)
    deep = n >= nl
    n = np.minimum(n, nl - 1)
    U, V = np.ldexp(u, n), np.ldexp(v, n)
    U, V = np.where(deep, 0.5, U), np.where(deep, 0.0, V)
    j = np.where(U >= 0.5, 0, np.where(V >= 0.5, 1, 2))
    a = np.where(j == 0, 2 * U - 1, np.where(j == 1, 2 * U, 1 - 2 * U))
    b = np.where(j == 0, 2 * V, np.where(j == 1, 2 * V - 1, 1 - 2 * V))
    scale = np.ldexp(np.where(j == 2, -1.0, 1.0), n + 1)
    limit = np.einsum("N,mNc->mc", p.limit_mask, C)
    nets = np.einsum("mkN,mNc->mkc", p.layers[n, j], C)
    out = _patch(basis(a, b, derivatives), nets)
    out["P"] = np.where(deep[:, None], limit, out["P"] + limit)
    for k in ("Pu", "Pv"):
        if k in out:
            out[k] *= scale[:, None]
    for k in ("Puu", "Puv", "Pvv"):
        if k in out:
            out[k] *= (scale * scale)[:, None]
    return out


def _chain(out, local, T, derivatives):
    """Derivatives with respect to the face's (u, v): local (u', v') = T (u, v) + o."""
    out["P"][:] = local["P"]
    if derivatives >= 1:
        g = np.stack([local["Pu"], local["Pv"]], axis=1)
        G = np.einsum("mba,mbc->mac", T, g)
        out["Pu"][:], out["Pv"][:] = G[:, 0], G[:, 1]
    if derivatives >= 2:
        H = np.stack([np.stack([local["Puu"], local["Puv"]], 1), np.stack([local["Puv"], local["Pvv"]], 1)], 1)
        H2 = np.einsum("mba,mdc,mbdk->mack", T, T, H)
        out["Puu"][:], out["Puv"][:], out["Pvv"][:] = H2[:, 0, 0], H2[:, 0, 1], H2[:, 1, 1]
