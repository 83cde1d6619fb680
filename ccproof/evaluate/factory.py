"""The factory of the patch table: classifies jobs into templates, and assembles the table.

A *job* is one quad of the complex the classification starts from (a base face of a quad mesh, a level-1
sub-face of a tagged polygon mesh), with its frame (where it sits in its ptex face, :mod:`ccproof.evaluate.frames`).
Its *ring* (the faces sharing a vertex with it, :func:`ccproof.evaluate.local.canonical_ring`, listed from a
corner; the two-ring in the Chaikin semi-sharp phase) has a tagged key, and the key (with the frame) determines
everything the classification does with the face: a *template* (:mod:`ccproof.evaluate.template_cache`), built
once per key by the exact local machinery of :mod:`ccproof.evaluate.local` run on the identity and shared by
every face with that key. :class:`Builder` walks the rings (the compiled walk where a backend has one,
:func:`ccproof.evaluate.backend.compiled_ring_walk`), registers every job with its template, and lays the templates out
as the :class:`~ccproof.evaluate.patch_table.PatchTable`.
"""

from __future__ import annotations

import functools
import sys
from array import array
from typing import NamedTuple

import numpy as np

from ccproof.errors import MeshError
from ccproof.evaluate import backend
from ccproof.evaluate.frames import axis_signs, child_frame, compose, corner_frame, domain, net_permutation
from ccproof.evaluate.halfedge_views import ComplexView, TaggedHalfEdges
from ccproof.evaluate.local import (
    CENTER,
    SIDES,
    canonical_ring,
    child_ring,
    corner_scheme,
    has_semi_sharp,
    irregular_corners,
    key_complex,
    refine_key,
    regular_net_matrix,
    ring_key,
)
from ccproof.evaluate.nets import with_nets
from ccproof.evaluate.patch_table import KIND_CORNER, KIND_REGULAR, KIND_SPLIT, assemble
from ccproof.evaluate.template_cache import Template, cached_template, finished

#: how many times a face may be subdivided before it must be regular or self-similar
MAX_DEPTH = 4
#: local subdivisions allowed in the semi-sharp phase of a tagged mesh (sharpness < 10 decays in
#: 10 uniform levels)
MAX_SEMI_DEPTH = 40


class Depth(NamedTuple):
    """How many local subdivisions lie above a virtual face: ``local`` ones (at most :data:`MAX_DEPTH`), and
    ``semi`` in the semi-sharp phase (at most :data:`MAX_SEMI_DEPTH`).

    >>> Depth(0, 0).split().semi_split()
    Depth(local=1, semi=1)
    """

    local: int
    semi: int

    def split(self):
        return Depth(self.local + 1, self.semi)

    def semi_split(self):
        return Depth(self.local, self.semi + 1)


def _same_as_first(rep, nring, faces, nfaces, tv=None):
    """Per walked ring: whether it is the ring ``rep`` of its group, face by face (the first ``nfaces`` of
    ``faces``), in size (``nring``, ``nfaces``) and, where ``tv`` (the rings' tag rows) is given, tag by tag."""
    used = np.arange(faces.shape[1]) < nfaces[:, None]
    same = (nfaces == nfaces[rep]) & (nring == nring[rep]) & \
        ((faces == faces[rep]).all(axis=2) | ~used).all(axis=1)
    if tv is not None:
        same &= (tv == tv[rep]).all(axis=1)
    return same


class _BlockWalk(NamedTuple):
    """What every block of :meth:`Builder._walk_all` shares: the half-edges ``he``, the compiled ring walk
    ``walks`` and its scratch arrays ``pos`` and ``seen``, the :class:`Jobs` and the id ``j0`` of the first,
    the options' key ``opts``, and the view ``view`` that computes the keys of tagged rings (or None)."""

    he: object
    walks: object
    pos: np.ndarray
    seen: np.ndarray
    jobs: object
    j0: int
    opts: tuple
    view: object


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
        self.templates = {}  # template key -> Template
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
            t = self.templates[tkey] = cached_template(tkey, self.depth_semi, make) \
                if tkey[0] != "smooth" else finished(make())
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
        (:meth:`_walk_all`), else face by face on the mesh read as a complex (:class:`ComplexView`).
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
        if walkable and backend.compiled_ring_walk(todo.size) is not None:
            return self._walk_all(he, jobs, j0, todo, single[todo])
        self._python_walk(he, jobs, j0, todo, single[todo])

    def _python_walk(self, he, jobs, j0, todo, single, view=None):
        """Register the jobs ``todo`` (``single``: the one irregular corner of each, or -1) face by face:
        :meth:`corner_at` or :meth:`face` on the mesh read as a complex (:class:`ComplexView`)."""
        cx = ComplexView(he) if view is None else view
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
        (:func:`ccproof.evaluate.local.ring_key` on the mesh read as a complex, :class:`ComplexView`;
        untagged: the faces and the options). Rings the walk cannot classify
        (beyond its arrays; a semi-sharp ring that needs the Chaikin two-ring) take the Python walk."""
        w = _BlockWalk(he, backend.compiled_ring_walk(todo.size), np.full(he.n_vertices, -1, dtype=np.int64),
                       np.zeros(he.n_faces, dtype=np.bool_), jobs, j0, he.options.key(),
                       ComplexView(he) if isinstance(he, TaggedHalfEdges) else None)  # (view: keys of tagged rings)
        bar = _progress(self.progress, todo.size, "patch table")
        step = 1 << 15
        fallback = []
        for lo in range(0, todo.size, step):
            idx = todo[lo:lo + step]
            r0 = single[lo:lo + step]
            retry, fb = self._walk_block(w, idx, np.maximum(r0, 0), r0 >= 0)
            fallback.append(fb)
            if retry.size:  # corner candidates that are not corner faces: from corner 0
                zero = np.zeros(retry.size, np.int64)
                fallback.append(self._walk_block(w, retry, zero, zero.astype(bool))[1])
            bar.update(idx.size)
        bar.close()
        fallback = np.concatenate(fallback) if fallback else np.zeros(0, dtype=np.int64)
        if fallback.size:
            where = {int(i): n for n, i in enumerate(todo.tolist())}
            self._python_walk(he, jobs, j0, fallback, single[[where[i] for i in fallback.tolist()]], w.view)

    def _walk_block(self, w, idx, r, at_corner, maxn=64, maxf=48):
        """Walk the rings of the jobs ``idx`` of ``w`` (a :class:`_BlockWalk`) from their corners ``r`` (corner
        candidates where ``at_corner``) and register them by groups of equal rings (:meth:`_walk_all`). Returns
        the corner candidates that are not corner faces and the jobs left to the Python walk."""
        he, jobs, j0, view = w.he, w.jobs, w.j0, w.view
        k = idx.size
        rings = np.full((k, maxn), -1, dtype=np.int32)
        faces = np.zeros((k, maxf, 4), dtype=np.int64)
        nring = np.empty(k, dtype=np.int64)
        nfaces = np.empty(k, dtype=np.int64)
        hashes = np.empty(k, dtype=np.uint64)
        w.walks((he.org, he.nxt, he.prv, he.twin), (w.pos, w.seen), jobs.g[idx], r,
                (rings, nring, faces, nfaces, hashes))
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
        bounds = np.searchsorted(inv[order], np.arange(first.size + 1)).tolist()
        same = _same_as_first(first[inv], nring, faces, nfaces, tv if tagged else None)
        n_other = np.bincount(inv, weights=~same, minlength=first.size).tolist()  # per group: not its first's
        retry = []
        nring_l, nfaces_l, r_l, corner_l = nring.tolist(), nfaces.tolist(), r.tolist(), at_corner.tolist()
        for gi, rep in enumerate(first.tolist()):
            mem = order[bounds[gi]:bounds[gi + 1]]
            if nring_l[rep] < 0:
                continue
            nf, n = nfaces_l[rep], nring_l[rep]
            if n_other[gi]:  # a hash collision: those jobs by the Python walk
                fallback.append(idx[mem[~same[mem]]])
                mem = mem[same[mem]]
            ftup = tuple(map(tuple, faces[rep, :nf].tolist()))
            if tagged:
                key = ring_key(view, rings[rep, :n].tolist(), ftup, 4)
            else:
                key = (ftup, (), (), w.opts)
            if tagged and self.depth_semi != 1 and has_semi_sharp(key) and not corner_l[rep]:
                fallback.append(idx[mem])  # the Chaikin phase reads the two-ring: the Python walk
                continue
            frame = jobs.frames[jobs.fid[idx[rep]]]
            base = int(jobs.base[idx[rep]])
            rr = r_l[rep]
            if corner_l[rep]:
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
                ring = grid[rows][:, net_permutation(f)]  # the grid in the base orientation
                self._register(("smooth", f), functools.partial(_smooth_template, f), j0 + idx[rows],
                               ring.astype(np.int32).ravel())
        return sel

    def corner_at(self, cx, X, g, r, frame, base, job, vmap=None):
        """Register quad ``g`` of ``cx`` (a :class:`ComplexView` of the mesh, or a complex) as a corner
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
        t = Template(N)
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
        t = Template(N)
        root = t.new_vface(KIND_REGULAR, frame)
        self._face(t, kc, np.eye(N), 0, frame, Depth(0, 0), base, root, vmap=np.arange(N))
        return t

    # ------------------------------------------------------------------ template building
    def _face(self, t, cx, X, g, frame, depth, base, vid, src=None, vmap=None):
        """Classify quad ``g`` of complex ``cx`` with positions ``X`` (NaN where not exact) into
        virtual face ``vid`` of template ``t``.

        ``depth``: the local subdivisions above it (a :class:`Depth`). ``src = (key, n_rule)``: ``cx`` is the
        child complex of that ring (its rings are cached).
        ``vmap``: ring position of every vertex of ``cx`` (-1 for new points).
        """

        def ring_of(r, depth_):
            if src is not None:
                return child_ring(src[0], src[1], g, r, depth_)
            ring_, faces_, nr_ = canonical_ring(cx, g, r, depth_)
            return ring_, ring_key(cx, ring_, faces_, nr_), nr_

        ring, key, nr = ring_of(0, 1)
        if has_semi_sharp(key):
            if depth.semi >= MAX_SEMI_DEPTH:
                raise MeshError(f"{self.what} {base}: semi-sharp creases did not decay in {MAX_SEMI_DEPTH} levels")
            D = self.depth_semi
            if D != 1:
                ring, key, nr = ring_of(0, D)
            return self.split_face(t, key, nr, X[ring], frame, depth.semi_split(), base, vid, vmap[ring])
        irr = irregular_corners(key)
        if not irr:
            M = regular_net_matrix(key)
            Xl = X[ring]
            origin = Xl.mean(axis=0)
            op = np.empty((17, Xl.shape[1]))
            op[:16] = (M @ (Xl - origin))[net_permutation(frame)]
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
        if depth.local >= MAX_DEPTH:
            raise MeshError(
                f"{self.what} {base}: the configuration around it is not supported "
                f"(still irregular after {MAX_DEPTH} local subdivisions)"
            )
        return self.split_face(t, key, nr, X[ring], frame, depth.split(), base, vid, vmap[ring])

    def scheme_face(self, t, key_r, X, ring_r, r, frame, base, vid, vmap):
        """Virtual face ``vid`` of ``t`` is a corner face of the scheme of ``key_r``
        (:func:`ccproof.evaluate.local.corner_scheme`) at its corner ``r``, ring ``X[ring_r]``
        (listed from that corner)."""
        scheme = corner_scheme(key_r)
        C = X[ring_r]
        rot = compose(frame, corner_frame(r))
        orient = (axis_signs(rot[1]), axis_signs(rot[2]))
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

    def split_face(self, t, key, nr, Xr, frame, depth, base, vid, vmap):
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
            self._face(t, child, X1, i, cf, depth, base, c, src=(key, nr), vmap=vmap1)
        return vid

    # ------------------------------------------------------------------ assembly
    def table(self, top, refused):
        """The :class:`~ccproof.evaluate.patch_table.PatchTable` (floats from the positions given to
        :meth:`classify`; :func:`~ccproof.evaluate.patch_table.assemble`) with the precomputed nets that fit
        (:func:`~ccproof.evaluate.nets.with_nets`), and the template groups ``[(template, jobs, rings)]``
        (``rings`` views of the table's ``rings``)."""
        T, groups = assemble(list(self.templates.values()), self.schemes, self.n_jobs, self.X, top, refused)
        return with_nets(T, groups), groups


def _smooth_template(frame):
    """The template of a smooth regular quad: its ring is its 4 x 4 grid in the base orientation."""
    t = Template(16)
    t.new_vface(KIND_REGULAR, frame)
    op = np.empty((17, 16))
    op[:16] = np.eye(16) - 1.0 / 16
    op[16] = 1.0 / 16
    t.leaf[0] = 0
    t.reg.append(op)
    t.smooth_grid = np.argsort(net_permutation(frame))  # ring[:, smooth_grid]: the grid as walked
    return t
