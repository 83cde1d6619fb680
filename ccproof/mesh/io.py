"""Mesh input: one reader, :func:`read_mesh`, for every command and format (output: :mod:`ccproof.mesh.write`).

A thin, faithful reader: it keeps the order of the faces and of the vertices inside each face
(the face parameterization depends on both) and the size of every polygon, so that a triangle or a
pentagon is reported with its face number and source line instead of being dropped or split.
Supported statements: ``v x y z [w]``, ``f i i/t i/t/n i//n ...`` (1-based or negative indices),
line continuations with ``\\``; every other statement (``vt``, ``vn``, ``g``, ``o``, ``s``,
``usemtl``, ``mtllib``, ``l``, ...) is ignored.
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING

import numpy as np

from ccproof.errors import MeshError
from ccproof.mesh.inputs import check_polygon_sizes, checked_input
from ccproof.mesh.quadmesh import QuadMesh

if TYPE_CHECKING:
    from ccproof.mesh.polymesh import PolyMesh

__all__ = ["read_obj", "read_obj_polygons", "read_obj_tagged", "read_off_polygons", "read_mesh"]


def _logical_lines(text):
    buf, start = "", None
    for no, line in enumerate(text.splitlines(), start=1):
        if start is None:
            start = no
        if line.endswith("\\"):
            buf += line[:-1] + " "
            continue
        yield start, buf + line
        buf, start = "", None
    if start is not None:
        yield start, buf


def read_obj_polygons(path):
    """Read the vertices and the polygons of an OBJ file, as they are.

    Parameters
    ----------
    path : str or os.PathLike

    Returns
    -------
    vertices : ndarray, shape (n, 3), float64
    polygons : list of list of int
        0-based vertex indices of each ``f`` statement, in file order.
    lines : list of int
        The (1-based) source line of each polygon.

    Raises
    ------
    MeshError
        On a malformed ``v`` or ``f`` statement or a vertex index out of range (message names the line).

    Examples
    --------
    >>> import os, tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     path = os.path.join(d, "m.obj")
    ...     with open(path, "w") as fh:
    ...         _ = fh.write("v 0 0 0\\nv 1 0 0\\nv 1 1 0\\nv 0 1 0\\nv 2 0 0\\n# two faces\\nf 1 2 3 4\\nf 2 5 3\\n")
    ...     V, polygons, lines = read_obj_polygons(path)
    >>> V.shape, polygons, lines
    ((5, 3), [[0, 1, 2, 3], [1, 4, 2]], [7, 8])
    """
    V, idx, sizes, lines, _ = _read_obj_arrays(path)
    off = np.r_[0, np.cumsum(sizes)].tolist()
    flat = idx.tolist()
    return V, [flat[a:b] for a, b in zip(off[:-1], off[1:])], lines.tolist()


def _read_obj_arrays(path, tags=False):
    """The vertices and polygons of an OBJ file as flat arrays (no Python object per face or vertex).

    Returns ``V`` (n, 3) float64, ``indices`` (sum of sizes,) int64 (0-based), ``sizes`` (m,) int64,
    ``lines`` (m,) int64 (the 1-based source line of each polygon) and, with ``tags``, the ``t`` lines
    (:func:`_parse_tags`) of the same text, else None.
    """
    from array import array

    with open(os.fspath(path), encoding="utf-8-sig", errors="replace") as fh:
        text = fh.read()
    verts, idx, sizes, lines = array("d"), array("q"), array("q"), array("q")
    nv = 0
    for no, line in _logical_lines(text):
        s = line.split("#", 1)[0].split()
        if not s:
            continue
        tag = s[0]
        if tag == "v":
            if len(s) < 4:
                raise MeshError(f"{path}:{no}: vertex statement needs 3 coordinates: {line.strip()!r}")
            try:
                verts.extend([float(s[1]), float(s[2]), float(s[3])])
            except ValueError:
                raise MeshError(f"{path}:{no}: bad vertex coordinate in {line.strip()!r}") from None
            nv += 1
        elif tag == "f":
            for tok in s[1:]:
                try:
                    i = int(tok.split("/", 1)[0])
                except ValueError:
                    raise MeshError(f"{path}:{no}: bad face index {tok!r}") from None
                if i == 0:
                    raise MeshError(f"{path}:{no}: OBJ indices are 1-based, got 0")
                idx.append(i - 1 if i > 0 else nv + i)
            sizes.append(len(s) - 1)
            lines.append(no)
    parsed = _parse_tags(path, text) if tags else None
    del text
    I = np.frombuffer(idx, dtype=np.int64).copy() if len(idx) else np.zeros(0, dtype=np.int64)
    del idx
    S = np.frombuffer(sizes, dtype=np.int64).copy() if len(sizes) else np.zeros(0, dtype=np.int64)
    L = np.frombuffer(lines, dtype=np.int64).copy() if len(lines) else np.zeros(0, dtype=np.int64)
    bad = np.flatnonzero((I < 0) | (I >= nv))
    if bad.size:
        f = int(np.searchsorted(np.cumsum(S), bad[0], side="right"))
        raise MeshError(f"{path}:{int(L[f])}: face {f} refers to vertex {int(I[bad[0]]) + 1} (1-based) of {nv}")
    V = np.frombuffer(verts, dtype=np.float64).copy().reshape(-1, 3) if nv else np.zeros((0, 3))
    return V, I, S, L, parsed


def _parse_tags(path, text):
    """The OpenSubdiv ``t`` lines of an OBJ text: list of (line, name, ints, floats, strings)."""
    out = []
    for no, line in _logical_lines(text):
        s = line.split("#", 1)[0].split()
        if not s or s[0] != "t":
            continue
        if len(s) < 3:
            raise MeshError(f"{path}:{no}: tag line needs a name and counts: {line.strip()!r}")
        name = s[1]
        try:
            ni, nf, ns = (int(x) for x in s[2].split("/"))
        except ValueError:
            raise MeshError(f"{path}:{no}: bad tag counts {s[2]!r} (expected nints/nfloats/nstrings)") from None
        rest = s[3:]
        if len(rest) < ni + nf + ns:
            raise MeshError(f"{path}:{no}: tag {name!r} announces {ni + nf + ns} values, has {len(rest)}")
        try:
            ints = [int(x) for x in rest[:ni]]
            floats = [float(x) for x in rest[ni : ni + nf]]
        except ValueError:
            raise MeshError(f"{path}:{no}: bad value in tag {name!r}: {line.strip()!r}") from None
        out.append((no, name, ints, floats, rest[ni + nf : ni + nf + ns]))
    return out


def read_obj_tagged(path):
    """Read an OBJ file with OpenSubdiv's tag lines into a :class:`~ccproof.mesh.polymesh.PolyMesh`.

    Tags (grammar of OpenSubdiv's ``regression/common/shape_utils.cpp``; indices 0-based):
    ``t crease n/1/0 a b [c d ...] s`` (pairs of vertices, one sharpness for all, or one float per
    pair), ``t corner n/1/0 v [...] s`` (or one float per vertex), ``t hole n/0/0 f ...``,
    ``t interpolateboundary 1/0/0 m`` (0 none, 1 edge and corner, 2 edge only; default edge only),
    ``t creasemethod 0/0/1 normal|chaikin``, ``t smoothtriangles 0/0/1 catmark|smooth``.
    Face-varying tags are ignored; any other tag is an error (never silently ignored). Negative
    sharpness is clamped to 0, as OpenSubdiv does, with the line in the error if it is NaN.

    Parameters
    ----------
    path : str or os.PathLike

    Returns
    -------
    PolyMesh
        Vertices ``(n, 3) float64``, the polygons in file order, and the tags (tests/data/osd_features
        describes the grammar; docs/evaluate.md "Tagged polygon meshes (OpenSubdiv's features)").

    Examples
    --------
    A quad (one ptex face) and a triangle (three) with an infinitely sharp crease (sharpness >= 10):

    >>> import os, tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     path = os.path.join(d, "m.obj")
    ...     with open(path, "w") as fh:
    ...         _ = fh.write("v 0 0 0\\nv 1 0 0\\nv 1 1 0\\nv 0 1 0\\nv 2 0 0\\nf 1 2 3 4\\nf 2 5 3\\n"
    ...                      "t crease 2/1/0 1 2 10\\n")
    ...     m = read_obj_tagged(path)
    >>> m.n_faces, m.n_ptex, m.edge_sharpness
    (2, 4, {(1, 2): inf})
    """
    from ccproof.mesh.polymesh import PolyMesh
    from ccproof.mesh.rules import Options

    V, indices, sizes, _, tags = _read_obj_arrays(path, tags=True)
    creases, corners, holes = {}, {}, []
    opts = {}
    for no, name, ints, floats, strings in tags:
        where = f"{path}:{no}: tag {name!r}"
        if name == "crease":
            if len(ints) % 2 or not floats:
                raise MeshError(f"{where}: needs vertex pairs and a sharpness")
            for j in range(0, len(ints), 2):
                s = floats[j] if len(floats) > 1 and j < len(floats) else floats[0]
                if s != s:
                    raise MeshError(f"{where}: sharpness is NaN on edge ({ints[j]}, {ints[j + 1]})")
                creases[(ints[j], ints[j + 1])] = max(s, 0.0)
        elif name == "corner":
            if not floats:
                raise MeshError(f"{where}: needs a sharpness")
            for j, v in enumerate(ints):
                s = floats[j] if len(floats) > 1 and j < len(floats) else floats[0]
                if s != s:
                    raise MeshError(f"{where}: sharpness is NaN on vertex {v}")
                corners[v] = max(s, 0.0)
        elif name == "hole":
            holes.extend(ints)
        elif name in ("interpolateboundary", "creasemethod", "smoothtriangles"):
            key, value = _option_tag(where, name, ints, strings)
            opts[key] = value
        elif name in ("facevaryinginterpolateboundary", "facevaryingpropagatecorners"):
            continue  # face-varying data only
        else:
            raise MeshError(f"{where}: not supported (hierarchical edits and unknown tags are refused)")
    try:
        return PolyMesh(V, indices, sizes=sizes, creases=creases or None, corners=corners or None,
                        holes=holes or None, options=Options(**opts))
    except MeshError as exc:
        raise MeshError(f"{path}: {exc}") from None


def _option_tag(where, name, ints, strings):
    """(Options field, value) of the OBJ option tag ``name`` (interpolateboundary, creasemethod,
    smoothtriangles); ``where`` names the file, line and tag in the error."""
    if name == "interpolateboundary":
        modes = {0: "none", 1: "edge_and_corner", 2: "edge_only"}
        if len(ints) != 1 or ints[0] not in modes:
            raise MeshError(f"{where}: expected one of 0, 1, 2, got {ints}")
        return "boundary", modes[ints[0]]
    if name == "creasemethod":
        m = {"normal": "uniform", "chaikin": "chaikin"}
        if len(strings) != 1 or strings[0] not in m:
            raise MeshError(f"{where}: expected 'normal' or 'chaikin', got {strings}")
        return "crease_method", m[strings[0]]
    m = {"catmark": "catmark", "smooth": "smooth"}
    if len(strings) != 1 or strings[0] not in m:
        raise MeshError(f"{where}: expected 'catmark' or 'smooth', got {strings}")
    return "triangle_subdivision", m[strings[0]]


_OFF_KEYWORDS = ("OFF", "COFF", "NOFF", "CNOFF", "STOFF", "STCOFF", "STNOFF", "STCNOFF")


def read_off_polygons(path):
    r"""Read the vertices and polygons of an ASCII OFF file (any polygon size).

    The Geomview OFF format: an optional keyword line (``OFF``, or ``COFF``/``NOFF``/``STOFF``/... whose
    vertex lines carry colours, normals or texture coordinates after x y z, ignored here), the counts
    ``nv nf ne`` (on the keyword line or the next), ``nv`` vertex lines ``x y z [...]``, ``nf`` face
    lines ``k i_1 .. i_k [colour]`` (0-based). ``#`` starts a comment. meshio's OFF reader takes
    triangles only; this one keeps quads and n-gons, in file order.

    Parameters
    ----------
    path : str or os.PathLike

    Returns
    -------
    vertices : ndarray, shape (n, 3), float64
    polygons : list of list of int
        0-based vertex indices of each face, in file order.
    lines : list of int
        The (1-based) source line of each face.

    Raises
    ------
    MeshError
        A binary or higher-dimensional OFF file, missing counts, a short or malformed vertex or face
        line, or an index out of range (message names the file and the line).

    Examples
    --------
    >>> import os, tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     path = os.path.join(d, "m.off")
    ...     with open(path, "w") as fh:
    ...         _ = fh.write("OFF\n# a quad and a triangle\n5 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n2 0 0\n"
    ...                      "4 0 1 2 3\n3 1 4 2\n")
    ...     V, polygons, lines = read_off_polygons(path)
    >>> V.shape, polygons, lines
    ((5, 3), [[0, 1, 2, 3], [1, 4, 2]], [9, 10])
    """
    p = os.fspath(path)
    with open(p, encoding="utf-8-sig", errors="replace") as fh:
        text = fh.read()
    rows = []
    for no, line in enumerate(text.splitlines(), start=1):
        tok = line.split("#", 1)[0].split()
        if tok:
            rows.append((no, tok))
    if not rows:
        raise MeshError(f"{p}: empty OFF file")
    k, nv, nf = _off_counts(p, rows)
    body = rows[k + 1 :]
    if len(body) < nv + nf:
        raise MeshError(f"{p}: the header announces {nv} vertices and {nf} faces, the file has {len(body)} data lines")
    verts = _off_vertices(p, body[:nv])
    polys, lines = _off_faces(p, body[nv : nv + nf], nv)
    return np.array(verts, dtype=np.float64).reshape(-1, 3), polys, lines


def _off_counts(p, rows):
    """(index of the counts' row, vertices, faces) of the OFF file ``p`` split into (line, tokens) ``rows``."""
    k = 0
    no, tok = rows[0]
    head = tok[0].upper()
    if head.endswith("OFF"):
        if head not in _OFF_KEYWORDS:
            raise MeshError(f"{p}:{no}: OFF variant {tok[0]!r} is not supported "
                            "(only 3-D ASCII OFF, COFF, NOFF, STOFF)")
        if len(tok) > 1 and tok[1].upper() == "BINARY":
            raise MeshError(f"{p}:{no}: binary OFF is not supported (ASCII only)")
        tok = tok[1:]
        if not tok:
            k = 1
            if len(rows) < 2:
                raise MeshError(f"{p}: no vertex and face counts after {head!r}")
            no, tok = rows[1]
    try:
        nv, nf = int(tok[0]), int(tok[1])
    except (ValueError, IndexError):
        raise MeshError(f"{p}:{no}: expected the counts 'vertices faces edges', got {' '.join(tok)!r}") from None
    if nv < 0 or nf < 0:
        raise MeshError(f"{p}:{no}: negative counts {nv} {nf}")
    return k, nv, nf


def _off_vertices(p, rows):
    """The x y z of each vertex row (line, tokens) of the OFF file ``p``."""
    verts = []
    for no, tok in rows:
        try:
            verts.append([float(x) for x in tok[:3]])
        except ValueError:
            raise MeshError(f"{p}:{no}: bad vertex coordinate in {' '.join(tok)!r}") from None
        if len(tok) < 3:
            raise MeshError(f"{p}:{no}: vertex line needs 3 coordinates: {' '.join(tok)!r}")
    return verts


def _off_faces(p, rows, nv):
    """(polygons, source lines) of the face rows (line, tokens) of the OFF file ``p`` with ``nv`` vertices."""
    polys, lines = [], []
    for f, (no, tok) in enumerate(rows):
        try:
            size = int(tok[0])
            idx = [int(x) for x in tok[1 : 1 + size]]
        except ValueError:
            raise MeshError(f"{p}:{no}: bad face line {' '.join(tok)!r}") from None
        if len(idx) != size:
            raise MeshError(f"{p}:{no}: face {f} announces {size} vertices, has {len(idx)}")
        for i in idx:
            if not 0 <= i < nv:
                raise MeshError(f"{p}:{no}: face {f} refers to vertex {i} of {nv} (0-based)")
        polys.append(idx)
        lines.append(no)
    return polys, lines


def _check_ply_header(p):
    """A PLY file starts with the line ``ply`` (lower case: the keywords of the PLY format are compared
    exactly by its reference reader, Turk's ply.c, and by VTK's); name the problem otherwise."""
    with open(p, "rb") as fh:
        first = fh.readline(64).strip()
    if first == b"ply":
        return
    if first.lower() == b"ply":
        raise MeshError(f"{p}: not a valid PLY file: the header is upper case ({first.decode(errors='replace')!r}); "
                        "PLY keywords are lower case ('ply', 'format', 'element', 'property', 'end_header')")
    raise MeshError(f"{p}: not a PLY file: it does not start with the line 'ply'")


def read_mesh(path: str | os.PathLike[str]) -> PolyMesh:
    r"""Read any polygon mesh: the one reader of every command.

    Parameters
    ----------
    path : str or os.PathLike
        ``.obj``: :func:`read_obj_tagged` (triangles, n-gons, OpenSubdiv tags: creases, corners, holes,
        boundary modes); ``.off``: :func:`read_off_polygons` (any polygon size; meshio's OFF reader
        takes triangles only); anything else through meshio (``.ply``, ``.stl``, ``.vtk``, ``.vtu``,
        ``.msh``, ...; a ``.ply`` must start with the line ``ply``).

    Returns
    -------
    PolyMesh
        Vertices of shape (n, 3) (2-D points get z = 0), all of them in file order (unused ones too,
        with any coordinates); faces in file order (meshio: by cell block, triangle, quad and
        polygon blocks); non-manifold edges and vertices as OpenSubdiv takes them.

    Raises
    ------
    MeshError
        Always naming the file: it does not exist or is a folder, a format no reader knows, a
        malformed file (with the line where we parse it), a cell block that is not polygons, or a
        mesh that fails the checks of :class:`~ccproof.mesh.polymesh.PolyMesh`.

    Examples
    --------
    A square pyramid (a quad and four triangles) as ASCII PLY (through meshio), the same as OFF
    (our reader), and an OBJ cube with one crease:

    >>> import os, tempfile
    >>> d = tempfile.mkdtemp()
    >>> ply = os.path.join(d, "pyramid.ply")
    >>> with open(ply, "w") as fh:
    ...     _ = fh.write("ply\nformat ascii 1.0\nelement vertex 5\nproperty float x\nproperty float y\n"
    ...                  "property float z\nelement face 5\nproperty list uchar int vertex_indices\nend_header\n"
    ...                  "0 0 0\n1 0 0\n1 1 0\n0 1 0\n0.5 0.5 1\n"
    ...                  "4 0 3 2 1\n3 0 1 4\n3 1 2 4\n3 2 3 4\n3 3 0 4\n")
    >>> m = read_mesh(ply)
    >>> m.n_vertices, m.n_faces, m.vertices.shape, [len(p) for p in m.polygons]
    (5, 5, (5, 3), [4, 3, 3, 3, 3])
    >>> off = os.path.join(d, "pyramid.off")
    >>> with open(off, "w") as fh:
    ...     _ = fh.write("OFF\n5 5 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n0.5 0.5 1\n"
    ...                  "4 0 3 2 1\n3 0 1 4\n3 1 2 4\n3 2 3 4\n3 3 0 4\n")
    >>> read_mesh(off).polygons == m.polygons
    True
    >>> from ccproof.mesh.examples import cube
    >>> from ccproof.mesh.write import write_obj
    >>> obj = os.path.join(d, "cube.obj")
    >>> write_obj(obj, cube())
    >>> with open(obj, "a") as fh:
    ...     _ = fh.write("t crease 2/1/0 0 1 2.5\n")
    >>> read_mesh(obj).edge_sharpness
    {(0, 1): 2.5}
    >>> read_mesh(os.path.join(d, "cube.xyz"))
    Traceback (most recent call last):
    ...
    ccproof.errors.MeshError: .../cube.xyz: no such file
    >>> import shutil; shutil.rmtree(d)
    """
    p = os.fspath(path)
    if os.path.isdir(p):
        raise MeshError(f"{p}: is a folder, not a mesh file")
    with checked_input(p, MeshError) as q:  # a regular file or a pipe, at most --max-input bytes
        mesh = _read_mesh(p, q)
    _check_magnitudes(mesh, p)
    check_polygon_sizes(mesh.polygons, p, MeshError)
    return mesh


#: largest coordinate of a vertex a face uses (as for the points of ccproof project): beyond it the
#: differences, derivatives and squared distances of the evaluators overflow
MAX_COORDINATE = 1e150


def _check_magnitudes(mesh: PolyMesh, p: str) -> None:
    """MeshError naming the file and the first used vertex with a coordinate beyond :data:`MAX_COORDINATE`."""
    V = np.asarray(mesh.vertices)
    big = np.flatnonzero((np.abs(V) > MAX_COORDINATE).any(axis=1))
    if big.size:
        used = np.zeros(V.shape[0], dtype=bool)
        used[np.concatenate([np.asarray(f, dtype=np.int64) for f in mesh.polygons])] = True
        hit = big[used[big]]
        if hit.size:
            v = int(hit[0])
            raise MeshError(f"{p}: vertex {v} (0-based) has coordinates {V[v].tolist()} beyond {MAX_COORDINATE:g} in "
                            "magnitude: the surface's differences and derivatives would overflow; scale the mesh")


def _read_mesh(p: str, q: str) -> PolyMesh:
    """:func:`read_mesh` of the file ``p``, read from ``q`` (``p`` itself, or a pipe's copy)."""
    from ccproof.mesh.polymesh import PolyMesh

    ext = os.path.splitext(p)[1].lower()
    if ext == ".obj":
        return read_obj_tagged(q)
    if ext == ".off":
        V, polys, _ = read_off_polygons(q)
        try:
            return PolyMesh(V, polys)
        except MeshError as exc:
            raise MeshError(f"{p}: {exc}") from None
    if ext == ".ply":
        _check_ply_header(q)
    mesh = _meshio_read(q, ext)
    polys = []
    for b, block in enumerate(mesh.cells):
        if block.type in ("triangle", "quad") or block.type.startswith("polygon"):
            polys.extend(np.asarray(block.data).tolist())
        else:
            raise MeshError(f"{p}: cell block {b} has type {block.type!r}: only polygon faces are supported")
    pts = np.asarray(mesh.points, dtype=np.float64)
    if pts.size == 0:
        raise MeshError(f"{p}: the file has no vertices (an empty mesh)")
    if pts.ndim != 2 or pts.shape[1] not in (2, 3):
        raise MeshError(f"{p}: points of shape {pts.shape}: expected 2-D or 3-D points")
    if pts.shape[1] == 2:
        pts = np.c_[pts, np.zeros(len(pts))]
    try:
        return PolyMesh(pts, polys)
    except MeshError as exc:
        raise MeshError(f"{p}: {exc}") from None


def _meshio_read(p, ext):
    """meshio's reader of the file's suffix, its failures turned into a MeshError naming the file and
    the reason. (``meshio.read`` prints its reader's error and calls ``sys.exit(1)``: both are caught
    here, the printed text becomes the reason; library code neither prints nor exits.)"""
    import contextlib
    import io

    import meshio

    fmts = meshio.extension_to_filetypes.get(ext, [])
    if not fmts:
        raise MeshError(f"{p}: unknown mesh format {ext or '(no suffix)'!r}: ccproof reads .obj, .off and the "
                        f"formats of meshio ({', '.join(sorted(meshio.extension_to_filetypes))})")
    reasons = []
    for fmt in fmts:
        buf = io.StringIO()
        try:
            with contextlib.redirect_stdout(buf), contextlib.redirect_stderr(buf):
                return meshio.read(p, file_format=fmt)
        except SystemExit:
            text = buf.getvalue().strip()
            reasons.append(text.splitlines()[0] if text else "meshio gave up")
        except meshio.ReadError as exc:
            reasons.append(str(exc).strip() or "meshio.ReadError")
        except (ValueError, IndexError, KeyError, TypeError, UnicodeDecodeError, EOFError, AssertionError) as exc:
            # meshio's parsers fail on malformed files with these (its own error type is not used throughout)
            first = str(exc).strip().splitlines()[0] if str(exc).strip() else ""
            reasons.append(f"{type(exc).__name__}: {first}" if first else type(exc).__name__)
    raise MeshError(f"{p}: not a valid {' or '.join(f.upper() for f in fmts)} file: {'; '.join(reasons)}")


def read_obj(path: str | os.PathLike[str]) -> QuadMesh:
    r"""Read an all-quad OBJ file into a validated :class:`QuadMesh`.

    Face ``f`` of the mesh is the ``f``-th ``f`` statement of the file and keeps its vertex order
    (corner ``i`` of the face sits at (0,0), (1,0), (1,1), (0,1) for ``i = 0..3``).

    Parameters
    ----------
    path : str or os.PathLike

    Returns
    -------
    QuadMesh
        ``vertices`` of shape (n, 3) float64 and ``faces`` of shape (m, 4) int64 (0-based), in file order.

    Raises
    ------
    MeshError
        If the file is malformed, a face is not a quad (the message gives its number and source
        line), it has OpenSubdiv tag lines (creases, corners, holes, boundary modes: never
        ignored; use :func:`read_mesh`), or the mesh fails any check of :class:`QuadMesh`.

    Examples
    --------
    >>> import os, tempfile
    >>> from ccproof.mesh.examples import cube
    >>> from ccproof.mesh.write import write_obj
    >>> d = tempfile.mkdtemp()
    >>> path = os.path.join(d, "cube.obj")
    >>> write_obj(path, cube())
    >>> m = read_obj(path)
    >>> m.vertices.shape, m.faces.shape, bool((m.vertices == cube().vertices).all())
    ((8, 3), (6, 4), True)
    >>> with open(path, "a") as fh:
    ...     _ = fh.write("f 1 2 3\n")
    >>> read_obj(path)
    Traceback (most recent call last):
    ...
    ccproof.errors.MeshError: .../cube.obj: face 6 (line 16) has 3 vertices, not 4: ccproof needs an all-quad mesh
    >>> import shutil; shutil.rmtree(d)
    """
    with checked_input(path, MeshError) as q:  # a regular file or a pipe, at most --max-input bytes
        V, polys, lines = read_obj_polygons(q)
        with open(q, encoding="utf-8-sig", errors="replace") as fh:
            for no, name, *_ in _parse_tags(path, fh.read()):
                if name not in ("facevaryinginterpolateboundary", "facevaryingpropagatecorners"):
                    raise MeshError(
                        f"{path}:{no}: OpenSubdiv tag {name!r}: a QuadMesh has no creases, corners, holes or "
                        "boundary modes; read the file with read_mesh / read_obj_tagged (PolyMesh) instead"
                    )
    try:
        return QuadMesh.from_polygons(V, polys, lines=lines)
    except MeshError as exc:
        raise MeshError(f"{path}: {exc}") from None
