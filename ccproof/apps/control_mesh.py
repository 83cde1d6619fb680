"""The control mesh of the applications: every mesh ``ccproof eval`` reads, as an all-quad mesh.

ARAP (hsh10) and the dynamic surfaces (qmv98) work on all-quad Catmull-Clark control meshes. A mesh with
triangles or n-gons (any format of :func:`ccproof.mesh.io.read_mesh`: OBJ, PLY, OFF, STL, VTK, ...) is
subdivided once with the Catmull-Clark rules first: every n-gon becomes n quads and the limit surface is
unchanged (it is the step every Catmull-Clark evaluator takes on such a mesh anyway). Vertices that no face
uses (common in scans) are dropped, the others keep their order. Meshes with OpenSubdiv tags (creases,
corners, holes, boundary modes) are refused: the applications use the untagged rules; so are non-manifold
meshes (OpenSubdiv makes their non-manifold edges and vertices infinitely sharp, which the untagged rules
of an all-quad control mesh cannot express; ``ccproof eval`` evaluates them).
"""

from __future__ import annotations

import os

import numpy as np

from ccproof.errors import MeshError
from ccproof.mesh import QuadMesh

__all__ = ["read_control_mesh", "children_labels"]


def read_control_mesh(path: str | os.PathLike[str]) -> tuple[QuadMesh, np.ndarray | None]:
    """Read a polygon mesh and make it all quads (module docstring).

    Parameters
    ----------
    path : str or os.PathLike
        Any file :func:`ccproof.mesh.io.read_mesh` reads.

    Returns
    -------
    mesh : QuadMesh
        The mesh itself when it is all quads, else the mesh subdivided once (the same limit surface);
        without unused vertices.
    sizes : ndarray of int64, shape (n_faces_of_the_file,), or None
        None when the file's faces are kept; else the corner count of every face of the file: face ``f``
        became the quads ``sum(sizes[:f]) .. sum(sizes[:f + 1]) - 1`` (:func:`children_labels`).

    Raises
    ------
    MeshError
        What :func:`~ccproof.mesh.io.read_mesh` raises, a mesh with OpenSubdiv tags, or a non-manifold mesh.

    Examples
    --------
    A square pyramid (one quad, four triangles) as ASCII PLY: 5 + 8 + 5 = 18 vertices and 4 + 4 * 3 = 16
    quads after one step:

    >>> import os, tempfile
    >>> tmp = tempfile.TemporaryDirectory()          # removed when the example ends
    >>> p = os.path.join(tmp.name, "pyramid.ply")
    >>> with open(p, "w") as fh:
    ...     _ = fh.write("ply\\nformat ascii 1.0\\nelement vertex 5\\nproperty float x\\nproperty float y\\n"
    ...                  "property float z\\nelement face 5\\nproperty list uchar int vertex_indices\\nend_header\\n"
    ...                  "0 0 0\\n1 0 0\\n1 1 0\\n0 1 0\\n0.5 0.5 1\\n"
    ...                  "4 0 3 2 1\\n3 0 1 4\\n3 1 2 4\\n3 2 3 4\\n3 3 0 4\\n")
    >>> mesh, sizes = read_control_mesh(p)
    >>> mesh.n_vertices, mesh.n_faces, sizes.tolist()
    (18, 16, [4, 3, 3, 3, 3])

    An unused vertex (the sixth) is dropped:

    >>> with open(p, "w") as fh:
    ...     _ = fh.write("ply\\nformat ascii 1.0\\nelement vertex 6\\nproperty float x\\nproperty float y\\n"
    ...                  "property float z\\nelement face 1\\nproperty list uchar int vertex_indices\\nend_header\\n"
    ...                  "0 0 0\\n1 0 0\\n1 1 0\\n0 1 0\\n0.5 0.5 1\\n9 9 9\\n4 0 1 2 3\\n")
    >>> mesh, sizes = read_control_mesh(p)
    >>> mesh.n_vertices, mesh.n_faces, sizes
    (4, 1, None)
    """
    from ccproof.mesh.io import read_mesh

    poly = read_mesh(path)
    if poly.has_tags:
        raise MeshError(f"{os.fspath(path)}: OpenSubdiv tags (creases, corners, holes or boundary modes) are not "
                        "supported here: the applications use the untagged Catmull-Clark rules")
    if not poly.is_manifold:
        e, v = poly.nonmanifold_edges, np.flatnonzero(poly.is_nonmanifold_vertex)
        what = f"non-manifold edge ({e[0, 0]}, {e[0, 1]})" if len(e) else f"non-manifold vertex {int(v[0])}"
        raise MeshError(f"{os.fspath(path)}: {what}: non-manifold meshes are not supported here (OpenSubdiv makes "
                        "them infinitely sharp, which the applications' untagged rules cannot express); "
                        "`ccproof eval` evaluates them")
    sizes = np.asarray(poly.sizes, dtype=np.int64)
    idx = np.asarray(poly.indices, dtype=np.int64)
    used = np.unique(idx)
    if used.size < poly.n_vertices:  # unused vertices (a subdivision step cannot even place them): dropped
        from ccproof.mesh.polymesh import PolyMesh

        new = np.full(poly.n_vertices, -1, dtype=np.int64)
        new[used] = np.arange(used.size)
        poly = PolyMesh(np.asarray(poly.vertices)[used], new[idx], sizes=sizes)
    if poly.is_all_quads:
        return QuadMesh(poly.vertices, poly.indices.reshape(-1, 4)), None
    fine, _ = poly.refine(operator=False)
    V, F = np.asarray(fine.vertices, dtype=np.float64), fine.indices.reshape(-1, 4)
    return QuadMesh(V, F), sizes


def children_labels(labels, sizes):
    """Per-face labels of the file's faces carried to the quads of :func:`read_control_mesh`.

    Parameters
    ----------
    labels : array_like of int, shape (n,)
    sizes : array_like of int, shape (n,), or None

    Returns
    -------
    ndarray of int64

    Examples
    --------
    >>> children_labels([7, 8], [3, 4]).tolist(), children_labels([7, 8], None).tolist()
    ([7, 7, 7, 8, 8, 8, 8], [7, 8])
    """
    labels = np.asarray(labels, dtype=np.int64)
    return labels if sizes is None else np.repeat(labels, np.asarray(sizes, dtype=np.int64))
