"""Arguments and point reader of ``ccproof eval`` (the command itself is :mod:`ccproof.cli.eval`, which
adds the bmz04 parameterizations and the scheduler options).

Evaluate the Catmull-Clark limit surface of a mesh exactly (natural parameterization): all-quad, or
with triangles, n-gons, creases, corners, holes and boundary modes (OpenSubdiv tags in the OBJ),
``face`` being OpenSubdiv's ptex face index (the face index on all-quad meshes).

Positions P and derivatives (Pu, Pv; Puu, Puv, Pvv) with respect to each face's own parameter
(u, v): corner i of the face's OBJ vertex list at (0,0), (1,0), (1,1), (0,1) for i = 0..3 (the ptex
convention of OpenSubdiv). Regular faces are bicubic B-splines; faces at extraordinary vertices are
evaluated exactly by self-similarity (Stam 1998, bmz04 sections 2-3); boundaries follow the
OpenSubdiv VTX_BOUNDARY_EDGE_ONLY rules.

Points come from a CSV file with the header ``face,u,v`` (0-based face index) or are drawn at
random (--samples N, uniform face and (u, v)). The output .npz holds the arrays P, Pu, Pv (and
Puu, Puv, Pvv with --derivatives 2), each of shape (n, 3) in the order of the points, and face, u, v.

Example:
  ccproof eval bunny.obj --samples 1000000 --out bunny.npz --plot ev.png
"""

from __future__ import annotations

from ccproof.errors import CCProofError


def add_arguments(parser):
    parser.add_argument("mesh", help="mesh file: OBJ (OpenSubdiv tag lines allowed), OFF (any polygon size), or "
                        "any meshio format (PLY, STL, VTK, ...); non-manifold and unused vertices as OpenSubdiv")
    src = parser.add_mutually_exclusive_group(required=True)
    src.add_argument("--points", metavar="CSV", help="CSV file with header face,u,v (face: ptex face index)")
    src.add_argument("--samples", metavar="N", type=int, help="evaluate at N random points")
    parser.add_argument("--derivatives", type=int, choices=(0, 1, 2), default=1, help="derivative order (default 1)")
    parser.add_argument("--out", metavar="FILE.npz", required=True,
                        help="output file (numpy .npz), or FOLDER/ for one .npz shard per --chunk points")
    parser.add_argument("--seed", type=int, default=0, help="random seed for --samples (default 0)")
    parser.add_argument("--scheme", choices=("catmark", "loop"), default="catmark",
                        help="subdivision scheme: catmark (Catmull-Clark, default) or loop (Loop's scheme with "
                        "OpenSubdiv's Sdc rules, exact; triangle meshes only, face = triangle index, corner 0 at "
                        "(u, v) = (0, 0), 1 at (1, 0), 2 at (0, 1), u + v <= 1; natural parameterization only)")
    parser.add_argument(
        "--plot", metavar="FILE.png", help="draw isoparameter lines of the faces around an extraordinary vertex"
    )
    parser.add_argument(
        "--plot-vertex",
        metavar="V",
        type=int,
        help="vertex for --plot (default: the interior extraordinary vertex of highest valence, else 0)",
    )


def evaluable_ptex_faces(poly):
    """The ptex faces of a :class:`~ccproof.mesh.polymesh.PolyMesh` that have a limit surface (not in a
    hole face, tagged or implied by the boundary mode), int64 (m,); None when every ptex face has one.

    >>> from ccproof.mesh.polymesh import PolyMesh
    >>> m = PolyMesh([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [2, 0, 0]], [[0, 1, 2, 3], [1, 4, 2]],
    ...              holes=[0])
    >>> evaluable_ptex_faces(m).tolist()
    [1, 2, 3]
    """
    import numpy as np

    if not poly.is_hole.any():
        return None
    counts = np.diff(poly.ptex_start)
    return np.repeat(~poly.is_hole, counts).nonzero()[0].astype(np.int64)


def read_face_uv_csv(path):
    """Read a ``face,u,v`` CSV file; returns (face int64 (n,), u (n,), v (n,))."""
    import numpy as np

    from ccproof.mesh.points import read_csv_columns

    rows = read_csv_columns(path, ("face", "u", "v"))
    face = rows[:, 0]
    bad = np.flatnonzero(~np.isfinite(face) | (face != np.round(face)))
    if bad.size:
        raise CCProofError(f"{path}:{int(bad[0]) + 2}: face must be an integer, got {float(face[bad[0]])!r}")
    # beyond 2^53 a float is no exact integer, beyond 2^63 the int64 cast is undefined (-9223372036854775808)
    huge = np.flatnonzero(np.abs(face) >= FACE_LIMIT)
    if huge.size:
        raise CCProofError(f"{path}:{int(huge[0]) + 2}: face id {float(face[huge[0]]):g} is out of range "
                           "(beyond 2^53, no mesh has so many faces)")
    return face.astype(np.int64), rows[:, 1].copy(), rows[:, 2].copy()


#: face ids of a points file at least this large are refused before the int64 cast (2^53: floats stay exact)
FACE_LIMIT = 2.0**53
