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
    parser.add_argument("mesh", help="mesh file: OBJ (OpenSubdiv tag lines allowed) or any meshio format")
    src = parser.add_mutually_exclusive_group(required=True)
    src.add_argument("--points", metavar="CSV", help="CSV file with header face,u,v (face: ptex face index)")
    src.add_argument("--samples", metavar="N", type=int, help="evaluate at N random points")
    parser.add_argument("--derivatives", type=int, choices=(0, 1, 2), default=1, help="derivative order (default 1)")
    parser.add_argument("--out", metavar="FILE.npz", required=True, help="output file (numpy .npz)")
    parser.add_argument("--seed", type=int, default=0, help="random seed for --samples (default 0)")
    parser.add_argument(
        "--plot", metavar="FILE.png", help="draw isoparameter lines of the faces around an extraordinary vertex"
    )
    parser.add_argument(
        "--plot-vertex",
        metavar="V",
        type=int,
        help="vertex for --plot (default: the interior extraordinary vertex of highest valence, else 0)",
    )


def read_face_uv_csv(path):
    """Read a ``face,u,v`` CSV file; returns (face int64 (n,), u (n,), v (n,))."""
    import numpy as np

    with open(path, encoding="utf-8") as fh:
        header = fh.readline()
        names = [h.strip().lower() for h in header.strip().split(",")]
        if names != ["face", "u", "v"]:
            raise CCProofError(f"{path}: the first line must be the header 'face,u,v', got {header.strip()!r}")
        faces, us, vs = [], [], []
        for no, line in enumerate(fh, start=2):
            if not line.strip():
                continue
            parts = line.split(",")
            if len(parts) != 3:
                raise CCProofError(f"{path}:{no}: expected 3 comma-separated values, got {line.strip()!r}")
            try:
                f = int(parts[0])
                u, v = float(parts[1]), float(parts[2])
            except ValueError:
                raise CCProofError(f"{path}:{no}: bad value in {line.strip()!r}") from None
            faces.append(f)
            us.append(u)
            vs.append(v)
    return np.array(faces, dtype=np.int64), np.array(us), np.array(vs)
