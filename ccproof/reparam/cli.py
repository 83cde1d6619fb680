"""Evaluate the Catmull-Clark limit surface of a mesh (OBJ with OpenSubdiv tags, or any meshio
format) in one of the parameterizations of bmz04 (triangles, n-gons and tagged meshes: natural only,
``face`` being the ptex face index): natural (Stam, section 2), vanishing (F^alpha blend,
section 4.2: derivatives tend to 0 at extraordinary vertices) or characteristic (Phi^-1 blend,
section 4.3: C1 with a Jacobian of rank 2 at extraordinary vertices).

Positions P and derivatives (Pu, Pv; Puu, Puv, Pvv) with respect to each face's own parameter
(u, v): corner i of the face's OBJ vertex list at (0,0), (1,0), (1,1), (0,1) for i = 0..3 (the ptex
convention of OpenSubdiv). The reparameterizations change (u, v) only in the quarter of a face at
an interior vertex of valence != 4; every parameterization covers the same surface.

Points come from a CSV file with the header ``face,u,v`` (0-based face index) or are drawn at
random (--samples N, uniform face and (u, v)). The output .npz holds the arrays P, Pu, Pv (and
Puu, Puv, Pvv with --derivatives 2), each of shape (n, 3) in the order of the points, and face, u, v.

Examples:
  ccproof eval bunny.obj --samples 1000000 --out bunny.npz --plot ev.png
  ccproof eval mesh.obj --points points.csv --parameterization characteristic --derivatives 1 --out out.npz
  ccproof eval mesh.obj --samples 1000 --parameterization vanishing --alpha 2.5 --out out.npz
"""

from __future__ import annotations

import sys
import time

from ccproof.errors import CCProofError
from ccproof.evaluate.cli import add_arguments as _add_evaluate_arguments
from ccproof.evaluate.cli import read_points


def add_arguments(parser):
    _add_evaluate_arguments(parser)
    parser.add_argument(
        "--parameterization",
        choices=("natural", "vanishing", "characteristic"),
        default="natural",
        help="natural (default; bmz04 section 2), vanishing (section 4.2) or characteristic (section 4.3)",
    )
    parser.add_argument(
        "--alpha",
        type=float,
        metavar="A",
        help="exponent of F^alpha for --parameterization vanishing (must exceed -log 2 / log lam of every "
        "extraordinary valence; default: twice that bound, per valence)",
    )


def run(args) -> int:
    import numpy as np

    from ccproof.mesh import QuadMesh
    from ccproof.mesh.io import read_mesh
    from ccproof.reparam.surface import limit_surface

    t0 = time.perf_counter()
    poly = read_mesh(args.mesh)  # OBJ with OpenSubdiv tags, or any meshio format
    tagged = not poly.is_all_quads or poly.has_tags
    if tagged:
        # triangles, n-gons, creases, corners, holes, boundary modes: the natural parameterization
        # of the tagged evaluator, by ptex face (equal to the face index on all-quad meshes)
        from ccproof.evaluate import limit_surface as natural_surface

        if args.parameterization != "natural":
            raise CCProofError(
                f"{args.mesh}: the {args.parameterization} parameterization needs an untagged all-quad mesh "
                "(this one has non-quad faces or OpenSubdiv tags); use --parameterization natural"
            )
        if args.plot:
            raise CCProofError(f"{args.mesh}: --plot needs an untagged all-quad mesh")
        mesh = poly
        natural = natural_surface(poly)
    else:
        mesh = QuadMesh(poly.vertices, np.array(poly.polygons, dtype=np.int64).reshape(-1, 4))
        surface = limit_surface(mesh, alpha=args.alpha)
    t1 = time.perf_counter()
    if args.points is not None:
        f, u, v = read_points(args.points)
    else:
        if args.samples < 0:
            raise CCProofError(f"--samples must be >= 0, got {args.samples}")
        rng = np.random.default_rng(args.seed)
        f = rng.integers(0, natural.n_faces if tagged else mesh.n_faces, args.samples)
        u, v = rng.random(args.samples), rng.random(args.samples)
    t2 = time.perf_counter()
    if tagged:
        out = natural.evaluate(f, u, v, derivatives=args.derivatives)
    else:
        out = surface.evaluate(f, u, v, derivatives=args.derivatives, parameterization=args.parameterization)
    t3 = time.perf_counter()
    np.savez(args.out, face=f, u=u, v=v, **out)
    if tagged:
        print(f"{args.mesh}: {mesh}; prepared in {t1 - t0:.2f} s")
    else:
        print(
            f"{args.mesh}: {mesh.n_vertices} vertices, {mesh.n_faces} faces, "
            f"{mesh.extraordinary_vertices.size} extraordinary vertices; prepared in {t1 - t0:.2f} s"
        )
    rate = f.size / (t3 - t2) if t3 > t2 and f.size else float("nan")
    print(
        f"evaluated {f.size} points ({args.parameterization} parameterization, derivatives {args.derivatives}) "
        f"in {t3 - t2:.3f} s ({rate:,.0f} points/s)"
    )
    print(f"wrote {args.out}: {', '.join(['face', 'u', 'v', *out])}")
    if args.plot:
        from ccproof.reparam.plot import plot_isoparameter_lines

        vtx = args.plot_vertex
        if vtx is None:
            ev = mesh.extraordinary_vertices
            vtx = int(ev[np.argmax(mesh.valence[ev])]) if ev.size else 0
        plot_isoparameter_lines(surface, vtx, args.plot, parameterization=args.parameterization)
        print(f"wrote {args.plot}: isoparameter lines around vertex {vtx} (valence {int(mesh.valence[vtx])})")
    sys.stdout.flush()
    return 0
