"""The mesh's half-edges as the ring walks read them: no copy, no Python object per face.

:class:`TaggedHalfEdges` is a tagged all-quad :class:`~ccproof.mesh.halfedges.HalfEdges` as the compiled
ring walk reads it (plus the tags of walked rings); :class:`ComplexView` reads a
:class:`~ccproof.mesh.halfedges.HalfEdges` through the part of the interface of
:class:`ccproof.mesh.rules.Complex` that :func:`ccproof.evaluate.local.canonical_ring` and
:func:`ccproof.evaluate.local.ring_key` use (the Python walk of :class:`ccproof.evaluate.factory.Builder`).
"""

from __future__ import annotations

import bisect

import numpy as np

from ccproof.mesh.halfedges import HalfEdges


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


class ComplexView:
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
