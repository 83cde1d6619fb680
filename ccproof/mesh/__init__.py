"""Quad-mesh input/output, validated topology, one reference Catmull-Clark step and vertex masks.

Layer ``mesh`` of docs/architecture.md: imports nothing from ccproof but :mod:`ccproof.errors`.

>>> from ccproof.mesh import QuadMesh, subdivide, subdivision_matrix
>>> m = QuadMesh([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], [[0, 1, 2, 3]])
>>> bool(abs(subdivision_matrix(m) @ m.vertices - subdivide(m).vertices).max() == 0)
True
"""

from ccproof.mesh.io import read_obj, read_obj_polygons, write_obj
from ccproof.mesh.masks import limit_normals, limit_positions, limit_tangents
from ccproof.mesh.quadmesh import QuadMesh
from ccproof.mesh.subdivision import child_faces, subdivide, subdivision_matrix

__all__ = [
    "QuadMesh",
    "read_obj",
    "read_obj_polygons",
    "write_obj",
    "subdivide",
    "subdivision_matrix",
    "child_faces",
    "limit_positions",
    "limit_tangents",
    "limit_normals",
]
