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
  :func:`ccproof.evaluate.local.corner_scheme`, stored once per configuration for every layer and
  applied to the face's ring C at evaluation time), derivatives scaled by 2^(n+1). Points closer to
  the corner than the last layer (where every net equals the limit point to 2^-60 of the one-ring's
  size) get the limit point and the derivatives of that layer.
* Any other face (several irregular vertices, or a one-ring that is not yet self-similar, e.g. an
  extraordinary vertex next to the boundary) is subdivided once, exactly and locally; its four
  children are classified again (at most ``MAX_DEPTH`` times; beyond that a MeshError).

The patch table (:mod:`ccproof.evaluate.patch_table`) holds per configuration the exact operators and per
face its control points: at evaluation time a point is a gather of a stored 4 x 4 net (regular
patches), or one ``16 x N`` product of its layer's operator with its corner face's ring, plus one
bicubic evaluation: no Python loop over points, memory bounded by evaluating in chunks.
"""

from __future__ import annotations

import numpy as np

from ccproof.errors import CCProofError
from ccproof.evaluate._numpy_kernel import evaluate_chunk
from ccproof.evaluate._parallel import in_blocks, threads_for
from ccproof.evaluate.backend import evaluation_blocks, evaluation_kernel, newton_kernel
from ccproof.evaluate.factory import Builder, Jobs
from ccproof.evaluate.nets import corner_rings, with_nets
from ccproof.evaluate.patch_map import PatchMap
from ccproof.evaluate.patch_table import KIND_CORNER, check_positions
from ccproof.mesh import QuadMesh, limit_normals, limit_positions
from ccproof.mesh.polymesh import PolyMesh
from ccproof.mesh.step_fast import catmark_step

__all__ = ["natural_limit_surface", "LimitSurface"]


#: points evaluated per chunk (bounds the temporary memory: about 1 kB per point)
CHUNK = 1 << 15
#: calls on at least this many points (faces not in order) evaluate them batched by face
SORT_MIN = 1 << 12
#: ... on surfaces of at least this many ptex faces (their tables outgrow the caches)
SORT_FACES = 1 << 14
#: points per kernel call of the batched evaluation (bounds its temporaries: 8 bytes per point and output)
SORT_CHUNK = 1 << 16

_KEYS = {0: ("P",), 1: ("P", "Pu", "Pv"), 2: ("P", "Pu", "Pv", "Puu", "Puv", "Pvv")}
#: corner faces whose rings are computed at once by :meth:`LimitSurface.vertex_normals` (temporaries in cache)
_RING_BLOCK = 1024


class LimitSurface:
    """Exact evaluator of the limit surface of a mesh (natural parameterization, bmz04 section 2).

    The one evaluator: quad meshes and tagged polygon meshes share its table, locator and kernels;
    other parameterizations are values passed to :meth:`evaluate`. Build it with
    :func:`ccproof.limit_surface` or :func:`natural_limit_surface`.

    Parameters
    ----------
    mesh : QuadMesh or PolyMesh
        A QuadMesh: m faces, n vertices ``(n, 3) float64``, ``face`` = face index. A PolyMesh
        (triangles, n-gons, OpenSubdiv's tags, non-manifold edges and vertices): ``face`` = ptex face
        index (OpenSubdiv's ``Far::PtexIndices``, :meth:`PolyMesh.ptex_of`), derivatives with respect
        to its (s, t); points on hole faces raise an error naming the point and the face
        (:mod:`ccproof.evaluate.tagged`; docs/evaluate.md "Tagged polygon meshes").

    Attributes
    ----------
    mesh : QuadMesh or PolyMesh
    parameterizations : dict of str -> parameterization value
        The names :meth:`evaluate` accepts besides ``"natural"``: the ``parameterizations`` argument (given
        when the surface is built; ``ccproof.limit_surface`` gives ``"vanishing"`` and ``"characteristic"``,
        :class:`ccproof.reparam.Parameterization` values).
    n_patches : int
        Regular bicubic patches stored (17 x 3 floats each: net and origin).
    max_layers : int
        Most layers of a corner configuration (0 without corner faces).
    split_depth : int
        How many local subdivisions the most irregular face needed.
    patch_map : ccproof.evaluate.patch_map.PatchMap
        Locates points (face, u, v) in the patch table (OpenSubdiv ``Far::PatchMap``); :meth:`locate`.

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

    An infinitely sharp corner on vertex 0 of the cube is interpolated; the untagged corners keep
    the smooth limit point (-1/2, -1/2, 1/2) of vertex 4 = (-1, -1, 1):

    >>> c = cube()
    >>> T = LimitSurface(PolyMesh(c.vertices, c.faces.tolist(), corners={0: 10}))
    >>> T.evaluate([0, 1], [0.0, 0.0], [0.0, 0.0])["P"].round(12).tolist()
    [[-1.0, -1.0, -1.0], [-0.5, -0.5, 0.5]]
    """

    def __init__(self, mesh: QuadMesh | PolyMesh, *, progress=None, parameterizations=None):
        self.mesh = mesh
        self.parameterizations = dict(parameterizations or {})
        if isinstance(mesh, PolyMesh):
            from ccproof.evaluate.tagged import build_tagged

            keep: dict = {}  # the tagged step, kept for with_vertices
            b, top, self._hole_ptex, self._ptex_face = build_tagged(mesh, progress, keep)
            self._finish(b, top, self._hole_ptex, keep_job_base=False)
            self._moving = keep
            return
        if not isinstance(mesh, QuadMesh):
            raise CCProofError(f"LimitSurface takes a QuadMesh or a PolyMesh, not {type(mesh).__name__}")
        self._hole_ptex = self._ptex_face = None
        b = Builder(progress=progress)
        cx = mesh.halfedges  # the mesh's own topology (untagged, default options)
        base = ((0.0, 0.0), (1.0, 0.0), (0.0, 1.0))
        m = mesh.n_faces
        b.classify(cx, mesh.vertices, Jobs(np.arange(m), np.zeros(m, np.int64), np.arange(m), [base]),
                   vmap=np.arange(mesh.n_vertices))
        self._finish(b, np.repeat(np.arange(m, dtype=np.int64)[:, None], 4, axis=1), np.zeros(m, dtype=np.bool_))

    def _finish(self, b, top, refused, keep_job_base=True):
        """The patch table from a :class:`Builder` that has classified every job; ``top`` (P, 4) the
        job of each quadrant of every ptex face, ``refused`` (P,) the ptex faces evaluation refuses.
        The jobs' rings are the table's (:meth:`with_vertices` shares them);
        ``keep_job_base``: keep the base face of every job (the quad-mesh :meth:`vertex_normals`)."""
        self._table, self._groups = b.table(top, refused)
        self._schemes = [s for s, _ in b.schemes]
        self._job_base = np.frombuffer(b.job_base, dtype=np.int64).copy() if len(b.job_base) and keep_job_base \
            else np.zeros(0, np.int64)
        self._moving = {}  # shared by the surfaces with_vertices derives: the tagged step (build_tagged's keep)
        self._vmap = b.vmap
        self._corner_normal = {}
        T = self._table
        self.split_depth = T.split_depth
        self.patch_map = PatchMap(T)
        self.n_patches = self.patch_map.n_patches
        self.max_layers = self.patch_map.max_layers

    def __getstate__(self):
        """Pickled by value, with the C kernel's view of the table (:meth:`_c_table`: its corner nets and grid,
        computed once here) where that kernel is built: a worker of a cluster receives the table (or maps it
        from shared memory, :func:`ccproof.scale.share`) instead of building it and its view again."""
        from ccproof.evaluate._ckernel import load

        if load() is not None:
            self._c_table()
        return dict(self.__dict__)

    @property
    def table_bytes(self):
        """Bytes held by the patch table: the kernel's arrays (the jobs' rings, the positions they index
        unless they are the mesh's vertices), the jobs of every template, the operators;
        :attr:`configuration_bytes` of them are per configuration or template, the rest grows with the faces."""
        T = self._table
        n = sum(a.nbytes for a in T if isinstance(a, np.ndarray) and a is not T.points)
        vertices = getattr(self.mesh, "vertices", None)
        if not (isinstance(vertices, np.ndarray) and np.shares_memory(vertices, T.points)):
            n += T.points.nbytes  # (the mesh's own vertices are not counted)
        n += sum(jobs.nbytes for _, jobs, _ in self._groups)
        return n + self._job_base.nbytes + sum(t.R.nbytes + t.Q.nbytes + t.O.nbytes for t, _, _ in self._groups)

    @property
    def configuration_bytes(self):
        """Bytes of the table held once per configuration (layer operators) or template (leaf
        operators), shared by all faces of that configuration."""
        T = self._table
        n = sum(a.nbytes for a in (T.ops, T.op_start, T.op_size, T.n_layers, T.unit, T.kind, T.child, T.u0,
                                   T.v0, T.h, T.leaf, T.cfg, T.cu, T.cv, T.vop, T.vop_start, T.vn))
        return n + sum(t.R.nbytes + t.Q.nbytes + t.O.nbytes for t, _, _ in self._groups)

    @property
    def n_faces(self):
        """Number of (ptex) faces: the valid ``face`` ids of :meth:`evaluate`."""
        return self.mesh.n_ptex if self._ptex_face is not None else self.mesh.n_faces

    # ------------------------------------------------------------------ input checks
    def _check(self, face_ids, u, v):
        """Face ids and (u, v) as flat int64 / float64 arrays, checked (errors name the point)."""
        f, u, v = self._check_shapes(face_ids, u, v)
        self._check_values(f, u, v)
        return f, u, v

    def _refused_faces(self):
        """Per face id, whether evaluation refuses it (the ptex faces of holes)."""
        if self._hole_ptex is not None:
            return self._hole_ptex
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
        if self._hole_ptex is not None and self._hole_ptex.any():
            bad = np.flatnonzero(self._hole_ptex[f])
            if bad.size:
                i = int(bad[0])
                raise CCProofError(
                    f"point {i}: ptex face {int(f[i])} (face {int(self._ptex_face[f[i]])}) is a hole"
                )
        return f, u, v

    # ------------------------------------------------------------------ evaluation
    def locate(self, face_ids, u, v):
        """The patch of every point and the point's parameter in it.

        Returns
        -------
        patch : ndarray of int, shape (n,)
            A stored regular patch (``< n_patches``), or ``n_patches + 3 (max_layers c + n) + code``
            for patch ``code`` of layer ``n`` of corner face ``c`` (not stored: its net is the
            configuration's layer operator applied to the corner face's ring).
        s, t : ndarray, shape (n,)
            Parameter in the patch, in [0, 1]; exact (dyadic rescaling).
        scale : ndarray, shape (n,)
            ``1 / h``: d/du = scale * d/ds for a patch of side h (a power of 2).
        """
        f, u, v = self._check(face_ids, u, v)
        return self._locate(f, u, v)

    def _locate(self, f, u, v):
        loc = self.patch_map.locate(f, u, v)
        return loc.patch, loc.s, loc.t, loc.scale

    def evaluate(self, face_ids, u, v, derivatives=1, *, parameterization="natural", chunk=CHUNK, out=None,
                 backend=None, threads=None):
        """Positions and derivatives of the limit surface at points (face, u, v), in a parameterization.

        Parameters
        ----------
        face_ids : array_like of int, shape (n,)
        u, v : array_like of float, shape (n,)
            Face parameters in [0, 1] (corner i of the face at (0,0), (1,0), (1,1), (0,1)).
        derivatives : int, 0, 1 or 2
        parameterization : str or parameterization value
            ``"natural"`` (default: bmz04 section 2, the evaluator's own); a name recorded in
            :attr:`parameterizations` (``ccproof.limit_surface`` records ``"vanishing"`` and
            ``"characteristic"`` on quad meshes); or a value such as
            :class:`ccproof.reparam.Parameterization` (bmz04 section 4), which this method applies
            around its natural evaluation by calling ``parameterization.evaluate_on(self, face, u, v,
            derivatives, ...)`` with the checked points.
        chunk : int
            Points per chunk (memory beyond the outputs is about 1 kB per chunk point).
        out : dict of ndarray, optional
            Preallocated outputs (shape (n, 3) each) to fill.
        backend : {None, "c", "numba", "numpy"}
            ``None``: the environment variable ``CCPROOF_BACKEND`` if set, else the C kernel
            (``ccproof/evaluate/_clib.c``) where the install built it, else the numba kernel where
            numba is installed, else numpy. All compute the same sums in the same order (the same bits).
        threads : int, optional
            Threads for the compiled kernels (they release the GIL; the points are split into
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
            Face id out of range or not an integer, (u, v) outside [0, 1]^2 or NaN (names the point);
            a parameterization name this surface does not know.

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
        if not (isinstance(parameterization, str) and parameterization == "natural"):
            p = self._parameterization(parameterization)
            f, u, v = self._check(face_ids, u, v)
            return p.evaluate_on(self, f, u, v, derivatives, chunk=chunk, out=out, backend=backend, threads=threads)
        name, kernel = evaluation_kernel(backend)
        if kernel is None:
            f, u, v = self._check(face_ids, u, v)
        else:  # the compiled kernel checks the values itself, in the threads
            f, u, v = self._check_shapes(face_ids, u, v)
        n = f.size
        keys = _KEYS[derivatives]
        if out is None:
            out = {k: np.empty((n, 3)) for k in keys}
        if kernel is not None:
            return self._evaluate_compiled(name, kernel, f, u, v, derivatives, out, threads)
        for lo in range(0, n, chunk):
            hi = min(n, lo + chunk)
            self._eval_chunk(f[lo:hi], u[lo:hi], v[lo:hi], derivatives, {k: out[k][lo:hi] for k in keys})
        return out

    def _evaluate_compiled(self, name, kernel, f, u, v, derivatives, out, threads):
        """:meth:`evaluate` by the compiled kernel ``name`` (``"c"`` or ``"numba"``) into ``out``, in blocks;
        from :data:`SORT_MIN` points on, on a surface of at least :data:`SORT_FACES` ptex faces, unless the faces
        are in order already, batched by face (:meth:`_evaluate_by_face`)."""
        n = f.size
        if n >= SORT_MIN and self.n_faces >= SORT_FACES and (f[1:] < f[:-1]).any():
            return self._evaluate_by_face(name, kernel, f, u, v, derivatives, out, threads)
        block, back = evaluation_blocks(name, kernel, self._kernel_tables, f, u, v, derivatives, out)
        # few blocks: each kernel call computes the corner nets it meets once (a cache per call)
        bad = in_blocks(block, n, threads_for(threads, n), 32768, per_thread=4)
        if max(bad) >= 0:
            self._check_values(f, u, v)  # raises, naming the first bad point
            raise CCProofError("internal error: the compiled kernel refused a point the checks accept")
        for k, a in back:
            out[k][...] = a
        return out

    def _evaluate_by_face(self, name, kernel, f, u, v, derivatives, out, threads):
        """:meth:`_evaluate_compiled` on the points taken in the order of their faces (in runs of at most
        ``n_faces / 2^15`` faces (the C kernel: ``n_faces / 2^20``), in the caller's order within a run; the
        table's rows and the positions the nets are computed from are read in order, and points of one patch
        find its net in the kernel's cache). The C kernel reads each point from its row and writes its results
        there (:func:`ccproof.evaluate._ckernel.face_order`, ``ccp_evaluate_at``); numba's takes chunks of
        :data:`SORT_CHUNK` points gathered and written back to ``out`` in the caller's order. Every point gets
        the same bits as in any other order (its net is the same sums)."""
        keys = _KEYS[derivatives]
        if name == "c":
            from ccproof.evaluate._ckernel import face_order

            order = face_order(f, self.n_faces, max(0, int(self.n_faces - 1).bit_length() - 20))
            block, back = evaluation_blocks(name, kernel, self._kernel_tables, f, u, v, derivatives, out, order)
            if max(in_blocks(block, f.size, threads_for(threads, f.size), 32768, per_thread=4)) >= 0:
                self._check_values(f, u, v)  # raises, naming the first bad point
                raise CCProofError("internal error: the compiled kernel refused a point the checks accept")
            for k, a in back:
                out[k][...] = a
            return out
        shift = max(0, int(self.n_faces - 1).bit_length() - 16)  # (runs of 2^shift faces: a radix sort)
        order = np.argsort((f >> shift).astype(np.uint16), kind="stable")

        def block(lo, hi):
            for a in range(lo, hi, SORT_CHUNK):
                sel = order[a:min(hi, a + SORT_CHUNK)]
                fb, ub, vb = f[sel], u[sel], v[sel]
                tmp = {k: np.empty((sel.size, 3)) for k in keys}
                bad = evaluation_blocks(name, kernel, self._kernel_tables, fb, ub, vb, derivatives, tmp)[0](0, sel.size)
                if bad >= 0:
                    return bad
                for k in keys:
                    out[k][sel] = tmp[k]
            return -1

        bad = in_blocks(block, f.size, threads_for(threads, f.size), 32768, per_thread=4)
        if max(bad) >= 0:
            self._check_values(f, u, v)  # raises, naming the first bad point
            raise CCProofError("internal error: the compiled kernel refused a point the checks accept")
        return out

    def basis(self, face_ids, u, v, derivatives=0, *, parameterization="natural", threads=None):
        """Basis rows: the sparse linear map from the control points to points and derivatives.

        ``W = S.basis(f, u, v, d)`` holds, per point, the weights of the file's control vertices (the
        limit stencils of OpenSubdiv): ``W["P"] @ X`` equals ``S.evaluate(f, u, v, d)["P"]`` for the
        surface's control points X (to round-off), ``W["Du"] @ X`` its ``"Pu"``, and so on; the same
        rows serve any other control points (``S.with_vertices(Y)`` evaluates to ``W["P"] @ Y``) and any
        array framework that multiplies by a sparse matrix (differentiation through the surface).

        Parameters
        ----------
        face_ids, u, v : array_like, shape (n,)
            Points as :meth:`evaluate` takes them (checked the same way).
        derivatives : int, 0, 1 or 2
        parameterization : str or parameterization value
            ``"natural"`` (default), or a name of :attr:`parameterizations` or a value with a
            ``basis_on(surface, f, u, v, derivatives)`` method (:class:`ccproof.reparam.Parameterization`).
        threads : int, optional
            Threads of the compiled kernels (natural parameterization), as :meth:`evaluate` takes them.

        Returns
        -------
        dict of scipy.sparse.csr_matrix, shape (n, n_vertices)
            ``"P"``; with ``derivatives >= 1`` also ``"Du"``, ``"Dv"``; with 2 also ``"Duu"``, ``"Duv"``,
            ``"Dvv"`` (derivatives with respect to the face's own (u, v)). Columns: the vertices of
            :attr:`mesh` (a PolyMesh's own vertices; an unused vertex's column is empty). Rows sorted by
            column (canonical format); the matrices may share one pair of read-only index arrays (rows
            of the file's vertices themselves), so change one's structure in place (``eliminate_zeros``)
            only on a ``.copy()``.

        Examples
        --------
        The centre of the cube's top face: 68/81 (one step and the limit mask), as a weighted sum of
        the cube's 8 vertices:

        >>> from ccproof.mesh.examples import cube
        >>> S = natural_limit_surface(cube())
        >>> W = S.basis([1], [0.5], [0.5], 1)
        >>> sorted(W), W["P"].shape, round(float(W["P"].sum()), 12), round(float(abs(W["Du"].sum())), 12)
        (['Du', 'Dv', 'P'], (1, 8), 1.0, 0.0)
        >>> round(float((W["P"] @ np.asarray(cube().vertices))[0, 2] * 81), 12)
        68.0
        """
        if derivatives not in (0, 1, 2):
            raise CCProofError(f"derivatives must be 0, 1 or 2, got {derivatives!r}")
        f, u, v = self._check(face_ids, u, v)
        if not (isinstance(parameterization, str) and parameterization == "natural"):
            p = self._parameterization(parameterization)
            if not callable(getattr(p, "basis_on", None)):
                raise CCProofError(f"parameterization {parameterization!r} has no basis_on method")
            return p.basis_on(self, f, u, v, derivatives)
        from ccproof.evaluate._basis import basis_rows

        return basis_rows(self, f, u, v, derivatives, threads=threads)

    def _parameterization(self, p):
        """The parameterization value of ``evaluate(..., parameterization=p)``: a name looked up in
        :attr:`parameterizations`, or a value with an ``evaluate_on`` method."""
        if isinstance(p, str):
            if p not in self.parameterizations:
                known = ", ".join(["natural", *self.parameterizations])
                hint = ("" if self.parameterizations else
                        " (ccproof.limit_surface names vanishing and characteristic on quad meshes)")
                raise CCProofError(f"unknown parameterization {p!r} for this surface; use one of {known}{hint}")
            return self.parameterizations[p]
        if not callable(getattr(p, "evaluate_on", None)):
            raise CCProofError(f"parameterization must be a name or a value with an evaluate_on method "
                               f"(ccproof.reparam.Parameterization), got {p!r}")
        return p

    def _kernel_table(self):
        """The patch table as the compiled kernels take it (one :class:`PatchTable` argument)."""
        return self._table

    def _kernel_tables(self, name):
        """The patch table as the backend ``name`` reads it (:func:`ccproof.evaluate.backend.evaluation_blocks`)."""
        return self._c_table() if name == "c" else self._table

    def _c_table(self):
        """The patch table as the C kernel reads it (:class:`ccproof.evaluate._ckernel.CTable`, made
        once per table and kept)."""
        ct = self.__dict__.get("_ctable")
        if ct is None or ct.table is not self._table:
            from ccproof.evaluate._ckernel import CTable

            ct = self._ctable = CTable(self._table)
        return ct

    def _newton_kernel(self, backend=None):
        """The compiled Newton descent of the closest points on this surface (natural parameterization),
        or None: numpy backend."""
        return newton_kernel(backend)

    def _eval_chunk(self, f, u, v, d, out):
        evaluate_chunk(self._table, self.patch_map, f, u, v, d, out)

    # ------------------------------------------------------------------ corner faces
    def _corner_leaf(self, job, vf):
        """``(CornerScheme, C - C[0])`` of the corner face ``vf`` of ``job``: its configuration's
        scheme and its ring (Nc, 3) relative to the corner vertex."""
        T = self._table
        return self._schemes[int(T.cfg[vf])], corner_rings(T, np.array([job]), vf)[0]

    def _eigen_normal(self, job, vf):
        """Unit normal at the irregular corner of corner face ``vf`` of ``job`` from the exact tangent masks."""
        key = (int(job), int(vf))
        if key not in self._corner_normal:
            scheme, rel = self._corner_leaf(*key)
            T = scheme.tangent_masks
            nrm = None
            if T is not None:
                t1, t2 = T @ rel
                c = np.cross(t1, t2)
                if np.linalg.norm(c) > 0:
                    nrm = c / np.linalg.norm(c)
            self._corner_normal[key] = nrm
        return self._corner_normal[key]

    def _eigen_normals(self, jobs, vfs):
        """:meth:`_eigen_normal` of many corner faces at once, (k, 3), NaN where undetermined: one product of
        the tangent masks with the rings of all the jobs of each corner face ``vf`` (not cached)."""
        T = self._table
        out = np.full((jobs.size, 3), np.nan)
        for vf in np.unique(vfs).tolist():
            sel = np.flatnonzero(vfs == vf)
            M = self._schemes[int(T.cfg[vf])].tangent_masks
            if M is None:
                continue
            for lo in range(0, sel.size, _RING_BLOCK):  # blocks: the products' temporaries stay in cache
                part = sel[lo:lo + _RING_BLOCK]
                t = np.matmul(M, corner_rings(T, jobs[part], vf))  # (k, 2, 3): each ring's own product
                c = np.cross(t[:, 0], t[:, 1])
                n = np.sqrt(np.vecdot(c, c))  # the dot product of np.linalg.norm(c) row by row: the same bits
                ok = n > 0
                out[part[ok]] = c[ok] / n[ok, None]
        return out

    def closest_points(self, X, **options):
        """Globally nearest limit points to the rows of ``X`` (n, 3): face, u, v, P, distance, normal
        (see :func:`ccproof.evaluate.closest.closest_points`)."""
        from .closest import closest_points

        return closest_points(self, X, **options)


    def normals(self, face_ids, u, v):
        """Unit limit normals, shape (n, 3), oriented like ``Pu x Pv``.

        ``Pu x Pv`` normalized, except closer to an irregular corner than the innermost layer of its
        configuration (including the corner itself, where ``Pu x Pv`` degenerates): there the normal
        of the exact tangent plane at the vertex (left eigenvectors of the corner's exact subdivision
        matrix, :attr:`ccproof.evaluate.local.CornerScheme.tangent_masks`); it differs from
        ``Pu x Pv`` at the innermost layer by the decay of the third eigenvalue over some 50 layers
        (round-off). NaN where the tangent plane at such a corner is not determined by two
        eigenvectors.
        """
        f, u, v = self._check(face_ids, u, v)
        r = self.evaluate(f, u, v, 1)
        N = np.cross(r["Pu"], r["Pv"])
        job, vf, kind = self.patch_map.faces(f, u, v)
        idx = np.flatnonzero(kind == KIND_CORNER)
        if idx.size:
            T = self._table
            w = vf[idx]
            U0, V0, H = T.u0[w], T.v0[w], T.h[w]
            du = np.where(T.cu[w], (U0 + H) - u[idx], u[idx] - U0) / H
            dv = np.where(T.cv[w], (V0 + H) - v[idx], v[idx] - V0) / H
            mx = np.maximum(du, dv)
            inner = np.flatnonzero(mx < np.ldexp(1.0, -T.n_layers[T.cfg[w]]))
            if inner.size:
                # orientation: Pu x Pv at 2^-12 of the corner face's side inside it (at the corner
                # itself Pu x Pv vanishes, and its sign is round-off)
                wi = w[inner]
                d = 2.0**-12 * H[inner]
                ur = np.where(T.cu[wi], U0[inner] + H[inner] - d, U0[inner] + d)
                vr = np.where(T.cv[wi], V0[inner] + H[inner] - d, V0[inner] + d)
                rr = self.evaluate(f[idx[inner]], ur, vr, 1)
                ref = np.cross(rr["Pu"], rr["Pv"])
                e = self._eigen_normals(job[idx[inner]], wi)  # NaN where undetermined
                flip = np.einsum("ij,ij->i", e, ref) < 0
                N[idx[inner]] = np.where(flip[:, None], -e, e)
        with np.errstate(invalid="ignore", divide="ignore"):
            return N / np.linalg.norm(N, axis=1)[:, None]

    # ------------------------------------------------------------------ vertices
    def vertex_limits(self):
        """Exact limit positions of the control vertices, shape (n_vertices, 3).

        Quad meshes: the masks of :func:`ccproof.mesh.limit_positions`. Tagged meshes: evaluated at
        the ptex corner (0, 0) of a sub-face at the vertex, or at the quad corner (hole faces
        included: holes do not change the surface of the other faces), one corner per vertex, all in
        one batch as :meth:`evaluate` takes random points; NaN at unused vertices.
        """
        if self._ptex_face is None:
            return limit_positions(self.mesh)
        from ccproof.evaluate.tagged import vertex_corners

        out = np.full((self.mesh.n_vertices, 3), np.nan)
        f, u, v, verts = vertex_corners(self.mesh)
        # one corner per vertex, its last in the mesh's order; evaluated as any batch of points (the compiled
        # kernels: the same sums as the numpy path, the same bits)
        keep = _one_per_vertex(verts, last=True)
        hole = self._hole_ptex[f[keep]]  # (evaluate refuses a hole: its corners by the numpy path, as before)
        for sel, batched in ((keep[~hole], True), (keep[hole], False)):
            if batched:
                out[verts[sel]] = self.evaluate(f[sel], u[sel], v[sel], 0)["P"]
            elif sel.size:
                r = {"P": np.empty((sel.size, 3))}
                self._eval_chunk(f[sel], u[sel], v[sel], 0, r)
                out[verts[sel]] = r["P"]
        return out

    def _corners_of_vertices(self):
        """``(vertices, jobs, vfs)``, sorted by vertex: each mesh vertex that is the irregular corner of a corner
        face once, with the job and corner face (``vf``: of the first job of its template, the template's
        representative) of its first such face in the order of the templates and their jobs."""
        verts, jobs_of, vfs = [np.zeros(0, np.int64)], [np.zeros(0, np.int64)], [np.zeros(0, np.int64)]
        if self._vmap is None:
            return verts[0], jobs_of[0], vfs[0]
        T = self._table
        for t, jobs, rings in self._groups:
            if jobs is None or not jobs.size:
                continue
            for c, pos in enumerate(t.cor_vertex):
                if pos < 0:
                    continue
                corner = next(i for i, k in enumerate(t.kind) if k == KIND_CORNER and t.leaf[i] == c)
                verts.append(np.asarray(self._vmap[rings[:, pos]], dtype=np.int64))
                jobs_of.append(np.asarray(jobs, dtype=np.int64))
                vfs.append(np.full(jobs.size, int(T.job_root[jobs[0]]) + corner, dtype=np.int64))
        verts_all = np.concatenate(verts)
        first = np.unique(verts_all, return_index=True)[1]  # sorted vertices, the first occurrence of each
        return verts_all[first], np.concatenate(jobs_of)[first], np.concatenate(vfs)[first]

    def vertex_normals(self):
        """Unit limit normals at the control vertices, shape (n_vertices, 3).

        Eigen masks (:func:`ccproof.mesh.limit_normals`) at interior and regular boundary vertices;
        at other boundary vertices the tangent masks of the exact corner matrix
        (:attr:`ccproof.evaluate.local.CornerScheme.tangent_masks`), oriented like ``Pu x Pv``.
        NaN where the tangent plane is not determined by the dominant eigenvectors. Tagged meshes:
        each vertex takes the normal (:meth:`normals`) of its first face corner that is not on a
        hole (all in one batch; the tangent masks of a corner face applied to the rings of all its jobs at
        once); NaN where the tangent plane is not determined or the vertex has only hole faces.
        """
        if self._ptex_face is not None:
            from ccproof.evaluate.tagged import vertex_corners

            out = np.full((self.mesh.n_vertices, 3), np.nan)
            f, u, v, verts = vertex_corners(self.mesh)
            keep = np.flatnonzero(~self._hole_ptex[f])
            keep = keep[_one_per_vertex(verts[keep], last=False)]  # the first corner of a vertex not on a hole
            out[verts[keep]] = self.normals(f[keep], u[keep], v[keep])
            return out
        Nn = limit_normals(self.mesh)
        bad = np.flatnonzero(np.isnan(Nn).any(axis=1))
        if bad.size:
            self._boundary_normals(Nn, bad)
        return Nn

    def _boundary_normals(self, Nn, bad):
        """Fill ``Nn[bad]`` (vertices without a closed-form mask: irregular boundary vertices) from the tangent masks
        of one corner face at each, all at once: the masks times the rings of all the jobs of each corner face
        (:meth:`_eigen_normals`), oriented like ``Pu x Pv`` evaluated just inside those corner faces in one batch."""
        verts, jobs, vfs = self._corners_of_vertices()
        at = np.minimum(np.searchsorted(verts, bad), max(verts.size - 1, 0))
        found = verts.size > 0
        has = (verts[at] == bad) if found else np.zeros(bad.size, bool)
        if not has.any():
            return
        v, job, vf = bad[has], jobs[at[has]], vfs[at[has]]
        nrm = self._eigen_normals(job, vf)  # unit, NaN where the tangent plane is not determined
        ok = ~np.isnan(nrm).any(axis=1)
        if not ok.any():
            return
        v, job, vf, nrm = v[ok], job[ok], vf[ok], nrm[ok]
        # orientation: Pu x Pv at 2^-12 of the corner face's side inside it
        T = self._table
        U0, V0, H = T.u0[vf], T.v0[vf], T.h[vf]
        d = 2.0**-12 * H
        u = np.where(T.cu[vf], U0 + H - d, U0 + d)
        w = np.where(T.cv[vf], V0 + H - d, V0 + d)
        r = self.evaluate(self._job_base[job], u, w, 1)
        flip = np.einsum("ij,ij->i", nrm, np.cross(r["Pu"], r["Pv"])) < 0
        Nn[v] = np.where(flip[:, None], -nrm, nrm)

    # ------------------------------------------------------------------ moved control points
    def with_vertices(self, X):
        """The limit surface of the same mesh with the control points ``X`` (n_vertices, 3).

        Everything that depends only on the connectivity (classification, templates, configurations,
        the jobs' rings) is shared with ``self``; only the positions the rings index, the limit points of
        the corner faces and, on small tables, the precomputed nets are new. The result evaluates like a
        fresh build on the mesh with the new control points (the same operations on the same data; on
        PolyMesh surfaces tested bit for bit), at a fraction of its cost (for the moving surfaces of
        ccproof.apps.dynamics).

        A :class:`~ccproof.mesh.polymesh.PolyMesh` surface (tags, n-gons, holes, non-manifold): ``X``
        are the PolyMesh's own vertices. The rings index the vertices the builder classified: those
        of :attr:`PolyMesh.manifold <ccproof.mesh.polymesh.PolyMesh.manifold>` (``X[manifold_vertex_map]``)
        on an all-quad mesh, else its level-1 vertices, recomputed as the build computes them (the
        vectorized untagged step :func:`ccproof.mesh.step_fast.catmark_step`, or the tagged step that
        the build ran, kept by it as CSR arrays (:class:`ccproof.mesh.csr.PackedCSR`, 24 bytes per ptex
        face on a tagged triangle mesh, docs/evaluate.md; shared by the derived surfaces) and applied as
        :meth:`PolyMesh.refine` applies it: no move repeats the step).

        Parameters
        ----------
        X : array_like, shape (n_vertices, 3)
            Unused vertices may hold anything (they do not enter the surface).

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

        A cube with an infinitely sharp corner at vertex 0 (a PolyMesh), moved by 1 along x:

        >>> c = cube()
        >>> T = LimitSurface(PolyMesh(c.vertices, c.faces.tolist(), corners={0: 10}))
        >>> T.with_vertices(np.asarray(c.vertices) + [1, 0, 0]).evaluate([0], [0.0], [0.0])["P"].round(12).tolist()
        [[0.0, -1.0, -1.0]]
        """
        mesh = self.mesh.with_vertices(X)  # checks the shape and finiteness (MeshError); topology shared
        if self._ptex_face is not None:
            V = self._classified_positions(mesh)
        else:
            V = np.where(mesh.is_unused_vertex[:, None], 0.0, mesh.vertices)  # unused: any value, weight 0
        new = object.__new__(LimitSurface)
        new.__dict__.update(self.__dict__)
        new.mesh = mesh
        new.parameterizations = dict(self.parameterizations)
        T = self._table
        V = np.ascontiguousarray(V, dtype=np.float64)
        check_positions(V, T.rings)
        new._table = with_nets(T._replace(points=V, nets=T.nets[:0], hot=T.hot[:0], cor_ring=T.cor_ring[:0],
                                          ring=T.ring[:0]), self._groups)
        new._ctable = None
        new._corner_normal = {}
        return new

    def _classified_positions(self, mesh):
        """The positions (N, 3) of the vertices the jobs' rings of a PolyMesh surface index, for the
        PolyMesh ``mesh`` (this surface's mesh with new vertices), computed as
        :func:`ccproof.evaluate.tagged.build_tagged` computes them."""
        man = mesh.manifold
        if man.is_all_quads:  # the builder starts on the (split) base mesh
            return np.asarray(man.vertices, dtype=np.float64)
        step = catmark_step(man)  # untagged: the vectorized step (None: the tagged step below)
        if step is not None:
            return step[0]
        V1 = self._moving["step"].apply(man.vertices)  # the build's step, kept (build_tagged)
        V1[np.flatnonzero(man.is_unused_vertex)] = np.nan  # as PolyMesh.refine: an unused vertex has no vertex point
        return V1


def _one_per_vertex(verts, last):
    """Indices into ``verts`` of one entry per distinct vertex: its first or its last occurrence.

    >>> v = np.array([3, 1, 3, 2, 1])
    >>> _one_per_vertex(v, last=False).tolist(), _one_per_vertex(v, last=True).tolist()
    ([1, 3, 0], [4, 3, 2])
    """
    if not last:
        return np.unique(verts, return_index=True)[1]
    first_of_reversed = np.unique(verts[::-1], return_index=True)[1]
    return verts.size - 1 - first_of_reversed


def natural_limit_surface(mesh, *, progress=None, parameterizations=None):
    """Prepare the exact evaluation of the limit surface of ``mesh`` in its natural parameterization.

    The package-wide entry point is :func:`ccproof.limit_surface` (the same surfaces, plus the
    parameterizations of bmz04 on quad meshes); this one is the evaluator alone.

    Parameters
    ----------
    mesh : QuadMesh, PolyMesh, or str or os.PathLike
        A QuadMesh or a PolyMesh (tagged: ``face`` = ptex face index; on untagged all-quad meshes the
        same numbers as the QuadMesh to round-off). A path is read by
        :func:`ccproof.mesh.io.read_mesh` (OBJ with OpenSubdiv tags, OFF, or any meshio format): an
        untagged manifold all-quad file gives a LimitSurface on a QuadMesh, anything else (triangles,
        n-gons, creases, corners, holes, boundary modes, non-manifold edges and vertices) one on the
        PolyMesh.
    progress : bool, optional
        Show a progress bar (tqdm, on stderr) when the setup takes more than 2 s; default: when
        stderr is a terminal.
    parameterizations : dict of str -> parameterization value, optional
        Names :meth:`LimitSurface.evaluate` accepts besides ``"natural"`` (:attr:`LimitSurface.parameterizations`).

    Returns
    -------
    LimitSurface

    Examples
    --------
    >>> from ccproof.mesh.examples import torus
    >>> natural_limit_surface(torus()).evaluate([0], [0.5], [0.5])["P"].shape
    (1, 3)
    """
    if isinstance(mesh, (QuadMesh, PolyMesh)):
        return LimitSurface(mesh, progress=progress, parameterizations=parameterizations)
    from ccproof.mesh.io import read_mesh

    mesh = read_mesh(mesh)
    if mesh.is_plain_quads:
        # a file holding an untagged manifold all-quad mesh: the QuadMesh evaluator, as before (same
        # numbers as the tagged one to round-off; ``S.mesh`` is a QuadMesh)
        return LimitSurface(mesh.to_quad_mesh(), progress=progress, parameterizations=parameterizations)
    return LimitSurface(mesh, progress=progress, parameterizations=parameterizations)


#: former name, kept importable for ccproof/evaluate/cli.py, ccproof/reparam/cli.py and tests; the
#: package-wide ``limit_surface`` is :func:`ccproof.reparam.limit_surface` (= ``ccproof.limit_surface``)
limit_surface = natural_limit_surface
