"""Wavefront OBJ input and output for quad meshes.

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
from ccproof.mesh.quadmesh import QuadMesh

if TYPE_CHECKING:
    from ccproof.mesh.polymesh import PolyMesh

__all__ = ["read_obj", "read_obj_polygons", "read_obj_tagged", "read_mesh", "write_obj"]


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
    with open(os.fspath(path), encoding="utf-8", errors="replace") as fh:
        text = fh.read()
    verts, polys, lines = [], [], []
    for no, line in _logical_lines(text):
        s = line.split("#", 1)[0].split()
        if not s:
            continue
        tag = s[0]
        if tag == "v":
            if len(s) < 4:
                raise MeshError(f"{path}:{no}: vertex statement needs 3 coordinates: {line.strip()!r}")
            try:
                verts.append([float(x) for x in s[1:4]])
            except ValueError:
                raise MeshError(f"{path}:{no}: bad vertex coordinate in {line.strip()!r}") from None
        elif tag == "f":
            idx = []
            for tok in s[1:]:
                try:
                    i = int(tok.split("/", 1)[0])
                except ValueError:
                    raise MeshError(f"{path}:{no}: bad face index {tok!r}") from None
                if i == 0:
                    raise MeshError(f"{path}:{no}: OBJ indices are 1-based, got 0")
                idx.append(i - 1 if i > 0 else len(verts) + i)
            polys.append(idx)
            lines.append(no)
    n = len(verts)
    for f, (poly, no) in enumerate(zip(polys, lines)):
        for i in poly:
            if not 0 <= i < n:
                raise MeshError(f"{path}:{no}: face {f} refers to vertex {i + 1} (1-based) of {n}")
    V = np.array(verts, dtype=np.float64).reshape(-1, 3)
    return V, polys, lines


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

    V, polys, lines = read_obj_polygons(path)
    with open(os.fspath(path), encoding="utf-8", errors="replace") as fh:
        tags = _parse_tags(path, fh.read())
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
        elif name == "interpolateboundary":
            modes = {0: "none", 1: "edge_and_corner", 2: "edge_only"}
            if len(ints) != 1 or ints[0] not in modes:
                raise MeshError(f"{where}: expected one of 0, 1, 2, got {ints}")
            opts["boundary"] = modes[ints[0]]
        elif name == "creasemethod":
            m = {"normal": "uniform", "chaikin": "chaikin"}
            if len(strings) != 1 or strings[0] not in m:
                raise MeshError(f"{where}: expected 'normal' or 'chaikin', got {strings}")
            opts["crease_method"] = m[strings[0]]
        elif name == "smoothtriangles":
            m = {"catmark": "catmark", "smooth": "smooth"}
            if len(strings) != 1 or strings[0] not in m:
                raise MeshError(f"{where}: expected 'catmark' or 'smooth', got {strings}")
            opts["triangle_subdivision"] = m[strings[0]]
        elif name in ("facevaryinginterpolateboundary", "facevaryingpropagatecorners"):
            continue  # face-varying data only
        else:
            raise MeshError(f"{where}: not supported (hierarchical edits and unknown tags are refused)")
    try:
        return PolyMesh(V, polys, creases=creases or None, corners=corners or None, holes=holes or None,
                        options=Options(**opts))
    except MeshError as exc:
        raise MeshError(f"{path}: {exc}") from None


def read_mesh(path: str | os.PathLike[str]) -> PolyMesh:
    r"""Read any polygon mesh: OBJ (with OpenSubdiv tags) directly, other formats through meshio.

    Parameters
    ----------
    path : str or os.PathLike
        ``.obj`` (read by :func:`read_obj_tagged`: triangles, n-gons, creases, corners, holes, boundary
        modes) or any polygon format meshio reads (``.off``, ``.ply``, ``.stl``, ``.vtk``, ...).

    Returns
    -------
    PolyMesh
        Vertices of shape (n, 3) (2-D points get z = 0); meshio cells of type triangle, quad and
        polygon are kept in file order (by cell block); other cell types (lines, vertices, volumes)
        raise a MeshError naming the block.

    Raises
    ------
    MeshError
        A malformed file (its path and line), a cell block that is not polygons, or a mesh that fails
        the checks of :class:`~ccproof.mesh.polymesh.PolyMesh`.

    Examples
    --------
    A square pyramid (a quad and four triangles) as ASCII PLY (through meshio), and an OBJ cube
    with one crease:

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
    >>> from ccproof.mesh.examples import cube
    >>> obj = os.path.join(d, "cube.obj")
    >>> write_obj(obj, cube())
    >>> with open(obj, "a") as fh:
    ...     _ = fh.write("t crease 2/1/0 0 1 2.5\n")
    >>> read_mesh(obj).edge_sharpness
    {(0, 1): 2.5}
    >>> import shutil; shutil.rmtree(d)
    """
    from ccproof.mesh.polymesh import PolyMesh

    p = os.fspath(path)
    if p.lower().endswith(".obj"):
        return read_obj_tagged(p)
    import meshio

    try:
        mesh = meshio.read(p)
    except Exception as exc:  # meshio raises many types
        raise MeshError(f"{p}: meshio cannot read it: {exc}") from None
    polys = []
    for b, block in enumerate(mesh.cells):
        if block.type in ("triangle", "quad") or block.type.startswith("polygon"):
            polys.extend(np.asarray(block.data).tolist())
        else:
            raise MeshError(f"{p}: cell block {b} has type {block.type!r}: only polygon faces are supported")
    pts = np.asarray(mesh.points, dtype=np.float64)
    if pts.shape[1] == 2:
        pts = np.c_[pts, np.zeros(len(pts))]
    try:
        return PolyMesh(pts, polys)
    except MeshError as exc:
        raise MeshError(f"{p}: {exc}") from None


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
    V, polys, lines = read_obj_polygons(path)
    with open(os.fspath(path), encoding="utf-8", errors="replace") as fh:
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


def write_obj(path, mesh, *, comment=None):
    """Write a :class:`QuadMesh` (or ``(vertices, faces)``) as OBJ with 17 significant digits.

    Reading the file back with :func:`read_obj` gives the same arrays bit for bit.

    Parameters
    ----------
    path : str or os.PathLike
    mesh : QuadMesh or (vertices, faces)
        ``vertices (n, 3) float64``, ``faces (m, 4) int`` (0-based; written 1-based).
    comment : str, optional
        Written as ``#`` lines at the top.

    Returns
    -------
    None

    Examples
    --------
    >>> import os, tempfile
    >>> import numpy as np
    >>> from ccproof.mesh.examples import torus
    >>> with tempfile.TemporaryDirectory() as d:
    ...     path = os.path.join(d, "torus.obj")
    ...     write_obj(path, torus(), comment="a torus")
    ...     back = read_obj(path)
    >>> np.array_equal(back.vertices, torus().vertices), np.array_equal(back.faces, torus().faces)
    (True, True)
    """
    if isinstance(mesh, QuadMesh):
        V, F = mesh.vertices, mesh.faces
    else:
        V, F = np.asarray(mesh[0], dtype=np.float64), np.asarray(mesh[1], dtype=np.int64)
    with open(os.fspath(path), "w", encoding="utf-8") as fh:
        if comment:
            for c in str(comment).splitlines():
                fh.write(f"# {c}\n")
        fh.write(f"# {V.shape[0]} vertices, {F.shape[0]} faces\n")
        fh.writelines(f"v {x:.17g} {y:.17g} {z:.17g}\n" for x, y, z in V.tolist())
        fh.writelines("f " + " ".join(str(i + 1) for i in row) + "\n" for row in F.tolist())
