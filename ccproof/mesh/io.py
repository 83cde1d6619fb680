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

import numpy as np

from ccproof.errors import MeshError
from ccproof.mesh.quadmesh import QuadMesh

__all__ = ["read_obj", "read_obj_polygons", "write_obj"]


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


def read_obj(path):
    """Read an all-quad OBJ file into a validated :class:`QuadMesh`.

    Face ``f`` of the mesh is the ``f``-th ``f`` statement of the file and keeps its vertex order
    (corner ``i`` of the face sits at (0,0), (1,0), (1,1), (0,1) for ``i = 0..3``).

    Raises
    ------
    MeshError
        If the file is malformed, a face is not a quad (the message gives its number and source
        line), or the mesh fails any check of :class:`QuadMesh`.
    """
    V, polys, lines = read_obj_polygons(path)
    try:
        return QuadMesh.from_polygons(V, polys, lines=lines)
    except MeshError as exc:
        raise MeshError(f"{path}: {exc}") from None


def write_obj(path, mesh, *, comment=None):
    """Write a :class:`QuadMesh` (or ``(vertices, faces)``) as OBJ with 17 significant digits.

    Reading the file back with :func:`read_obj` gives the same arrays bit for bit.
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
