"""Mesh output: OBJ files with 17 significant digits and OpenSubdiv's tag lines, written atomically.

:func:`write_obj` writes what :func:`ccproof.mesh.io.read_obj` reads back bit for bit;
:func:`obj_tag_lines` the tag lines :func:`ccproof.mesh.io.read_obj_tagged` reads; :func:`atomic_path`
is how every writer of the library replaces a file (completely or not at all).
"""

from __future__ import annotations

import contextlib
import os

import numpy as np

from ccproof.mesh.quadmesh import QuadMesh

__all__ = ["write_obj", "atomic_path", "obj_tag_lines"]


def write_obj(path, mesh, *, comment=None):
    """Write a :class:`QuadMesh` (or ``(vertices, faces)``) as OBJ with 17 significant digits.

    Reading the file back with :func:`read_obj` gives the same arrays bit for bit. A mesh with tags (the
    applications' tagged control mesh: arrays ``edge_sharpness``, ``vertex_sharpness``, ``hole``) gets
    OpenSubdiv's tag lines (:func:`obj_tag_lines`). The file is written atomically (:func:`atomic_path`):
    an existing ``path`` is replaced only by a complete file.

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
    >>> from ccproof.mesh.io import read_obj
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
    with atomic_path(path) as tmp, open(tmp, "w", encoding="utf-8") as fh:
        if comment:
            for c in str(comment).splitlines():
                fh.write(f"# {c}\n")
        fh.write(f"# {V.shape[0]} vertices, {F.shape[0]} faces\n")
        fh.writelines(f"v {x:.17g} {y:.17g} {z:.17g}\n" for x, y, z in V.tolist())
        fh.writelines("f " + " ".join(str(i + 1) for i in row) + "\n" for row in F.tolist())
        fh.writelines(obj_tag_lines(mesh))


@contextlib.contextmanager
def atomic_path(path):
    """Yield a temporary path in the folder of ``path``; move it onto ``path`` (``os.replace``) when the
    block ends normally, remove it otherwise (``path`` is then left as it was). The library's writers use
    it; the commands' outputs go through ``ccproof.cli._output.atomic`` (the same, plus its checks).

    Examples
    --------
    >>> import os, tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     p = os.path.join(d, "a.txt")
    ...     with atomic_path(p) as tmp, open(tmp, "w") as fh:
    ...         _ = fh.write("done")
    ...     try:
    ...         with atomic_path(p) as tmp, open(tmp, "w") as fh:
    ...             raise KeyboardInterrupt
    ...     except KeyboardInterrupt:
    ...         pass
    ...     open(p).read(), os.listdir(d)
    ('done', ['a.txt'])
    """
    import uuid

    folder, name = os.path.split(os.path.abspath(os.fspath(path)))
    tmp = os.path.join(folder, f".tmp-{uuid.uuid4().hex[:8]}-{name}")  # created by the writer: the usual mode
    try:
        yield tmp
        os.replace(tmp, path)
    finally:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)


def obj_tag_lines(mesh):
    """OpenSubdiv's OBJ tag lines of a tagged control mesh, as :func:`read_obj_tagged` reads them.

    Parameters
    ----------
    mesh : QuadMesh
        With arrays ``edge_sharpness`` (over ``edges``), ``vertex_sharpness`` and ``hole`` (the applications'
        :class:`~ccproof.apps.control_mesh.TaggedQuadMesh`); none for a plain mesh.

    Returns
    -------
    list of str
        ``t crease 2/1/0 a b s`` per sharp edge, ``t corner 1/1/0 v s`` per sharp vertex (0-based vertices,
        the sharpness exactly (``repr``), infinite sharpness as 10), one ``t hole k/0/0 f ...`` line.
    """
    es = getattr(mesh, "edge_sharpness", None)
    if not isinstance(es, np.ndarray):
        return []
    out = []
    for e in np.flatnonzero(es > 0).tolist():
        a, b = mesh.edges[e].tolist()
        out.append(f"t crease 2/1/0 {a} {b} {min(float(es[e]), 10.0)!r}\n")
    vs = mesh.vertex_sharpness
    for v in np.flatnonzero(vs > 0).tolist():
        out.append(f"t corner 1/1/0 {v} {min(float(vs[v]), 10.0)!r}\n")
    holes = np.flatnonzero(mesh.hole).tolist()
    if holes:
        out.append(f"t hole {len(holes)}/0/0 " + " ".join(map(str, holes)) + "\n")
    return out
