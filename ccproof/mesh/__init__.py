"""Mesh input/output, validated topology (quad meshes; tagged polygon meshes with OpenSubdiv's
creases, corners, holes and boundary modes), the Catmull-Clark rules and vertex masks.

Layer ``mesh`` of docs/architecture.md: imports nothing from ccproof but :mod:`ccproof.errors`.

>>> from ccproof.mesh import QuadMesh, subdivide, subdivision_matrix
>>> m = QuadMesh([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], [[0, 1, 2, 3]])
>>> bool(abs(subdivision_matrix(m) @ m.vertices - subdivide(m).vertices).max() == 0)
True
"""

from ccproof.mesh.io import read_mesh, read_obj, read_obj_polygons, read_obj_tagged
from ccproof.mesh.masks import limit_normals, limit_positions, limit_tangents
from ccproof.mesh.polymesh import PolyMesh
from ccproof.mesh.quadmesh import QuadMesh
from ccproof.mesh.rules import Options
from ccproof.mesh.subdivision import child_faces, subdivide, subdivision_matrix
from ccproof.mesh.write import write_obj

__all__ = [
    "QuadMesh",
    "PolyMesh",
    "Options",
    "read_mesh",
    "read_obj_tagged",
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
