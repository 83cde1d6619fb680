"""Evaluate the Catmull-Clark limit surface of an all-quad OBJ mesh exactly (natural parameterization).

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

import sys
import time

from ccproof.errors import CCProofError


def add_arguments(parser):
    parser.add_argument("mesh", help="all-quad OBJ file")
    src = parser.add_mutually_exclusive_group(required=True)
    src.add_argument("--points", metavar="CSV", help="CSV file with header face,u,v")
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


def read_points(path):
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


def run(args) -> int:
    import numpy as np

    from ccproof.evaluate import limit_surface
    from ccproof.mesh import read_obj

    t0 = time.perf_counter()
    mesh = read_obj(args.mesh)
    surface = limit_surface(mesh)
    t1 = time.perf_counter()
    if args.points is not None:
        f, u, v = read_points(args.points)
    else:
        if args.samples < 0:
            raise CCProofError(f"--samples must be >= 0, got {args.samples}")
        rng = np.random.default_rng(args.seed)
        f = rng.integers(0, mesh.n_faces, args.samples)
        u, v = rng.random(args.samples), rng.random(args.samples)
    t2 = time.perf_counter()
    out = surface.evaluate(f, u, v, derivatives=args.derivatives)
    t3 = time.perf_counter()
    np.savez(args.out, face=f, u=u, v=v, **out)
    print(
        f"{args.mesh}: {mesh.n_vertices} vertices, {mesh.n_faces} faces, "
        f"{mesh.extraordinary_vertices.size} extraordinary vertices; prepared in {t1 - t0:.2f} s"
    )
    rate = f.size / (t3 - t2) if t3 > t2 and f.size else float("nan")
    print(f"evaluated {f.size} points (derivatives {args.derivatives}) in {t3 - t2:.3f} s ({rate:,.0f} points/s)")
    print(f"wrote {args.out}: {', '.join(['face', 'u', 'v', *out])}")
    if args.plot:
        from ccproof.evaluate.plot import plot_isoparameter_lines

        vtx = args.plot_vertex
        if vtx is None:
            ev = mesh.extraordinary_vertices
            vtx = int(ev[np.argmax(mesh.valence[ev])]) if ev.size else 0
        plot_isoparameter_lines(surface, vtx, args.plot)
        print(f"wrote {args.plot}: isoparameter lines around vertex {vtx} (valence {int(mesh.valence[vtx])})")
    sys.stdout.flush()
    return 0
