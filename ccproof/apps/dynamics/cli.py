"""Fit a dynamic Catmull-Clark surface to a point cloud (shape recovery from range data, qmv98 section 4.2).

  ccproof fit POINTS.xyz --out fitted.obj                 cube x2 (98 vertices) -> equilibrium -> 386 vertices
  ccproof fit scan.ply --levels 2 --out fitted.obj        two global subdivisions after the first fit
  ccproof fit bunny.obj --init start.obj --out fit.obj    start from your own (closed, all-quad) control mesh

POINTS: .xyz (x y z per line), .ply (vertex x, y, z; ASCII or binary) or .obj (its vertices). The model
starts as the paper's 98-vertex mesh (the cube subdivided twice) inside the data, evolves under data
springs (every point pulls its nearest limit-surface point) with the massless implicit scheme (32) to
equilibrium, is subdivided once (386 vertices) and refitted. Printed per level: control vertices, time
steps, the paper's fit error (the largest distance of a data point to the limit surface, in % of the
diameter of the smallest enclosing sphere, Welzl) and the mean distance in the same unit. All material
parameters are in units where that diameter is 1 and the data springs sum to --spring.
"""

from __future__ import annotations


def add_arguments(p):
    p.add_argument("points", help="point cloud: .xyz, .ply or .obj")
    p.add_argument("--out", required=True, help="write the fitted control mesh (OBJ) here")
    p.add_argument("--init", default="cube", help="'cube' (the paper's 98-vertex model, default) or an OBJ mesh")
    p.add_argument("--levels", type=int, default=1, help="global subdivisions after the first fit (default 1)")
    p.add_argument("--scheme", choices=("massless", "inertial"), default="massless",
                   help="time integrator: eq. (32) massless (default) or eq. (31)")
    p.add_argument("--dt", type=float, default=None, help="time step (default 1000 massless, 10 inertial)")
    p.add_argument("--max-steps", type=int, default=60, help="time steps per level at most (default 60)")
    p.add_argument("--tol", type=float, default=1e-3,
                   help="equilibrium: relative energy change between steps (default 1e-3)")
    p.add_argument("--tension", type=float, default=1e-5, help="a11 = a22 (default 1e-5)")
    p.add_argument("--rigidity", type=float, default=1e-6, help="b11 = b22 = b12/2 (default 1e-6)")
    p.add_argument("--damping", type=float, default=1.0, help="gamma (default 1)")
    p.add_argument("--mass", type=float, default=0.0,
                   help="mu (default 0 with the massless scheme, 1 with --scheme inertial)")
    p.add_argument("--spring", type=float, default=1.0, help="sum of the data spring constants (default 1)")
    p.add_argument("--truncation", type=int, default=6, help="special-element stiffness level L (default 6)")
    p.add_argument("--init-scale", type=float, default=0.5, help="initial cube size / data box (default 0.5)")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")


def run(args) -> int:
    from pathlib import Path

    from ccproof.apps.dynamics.fit import fit_points, read_points
    from ccproof.apps.dynamics.model import Material
    from ccproof.errors import CCProofError
    from ccproof.mesh import read_obj, write_obj

    X = read_points(args.points)
    init = args.init
    if init != "cube":
        if not Path(init).exists():
            raise CCProofError(f"--init: {init}: no such file (use 'cube' or an OBJ mesh)")
        init = read_obj(init)
    mu = args.mass if args.scheme == "massless" or args.mass > 0 else 1.0
    material = Material(mu=mu, gamma=args.damping, a11=args.tension, a22=args.tension, b11=args.rigidity,
                        b12=2 * args.rigidity, b22=args.rigidity)
    res = fit_points(X, init=init, levels=args.levels, material=material, spring_total=args.spring, dt=args.dt,
                     scheme=args.scheme, max_steps=args.max_steps, tol=args.tol, init_scale=args.init_scale,
                     truncation=args.truncation, progress=not args.no_progress)
    print(f"data: {X.shape[0]} points from {args.points}; minimal enclosing sphere diameter {res.diameter:.6g}")
    print("level  vertices  faces  steps  equilibrium  max error %  mean error %  seconds")
    for i, lev in enumerate(res.levels):
        print(f"{i:5d}  {lev.n_vertices:8d}  {lev.n_faces:5d}  {lev.steps:5d}  {'yes' if lev.converged else 'no':>11}"
              f"  {lev.max_error_percent:11.3f}  {lev.mean_error_percent:12.4f}  {lev.seconds:7.1f}")
    print(f"fit error (max distance to the limit surface, % of the enclosing-sphere diameter): "
          f"{res.max_error_percent:.3f} %   mean: {res.mean_error_percent:.4f} %")
    write_obj(args.out, res.mesh, comment=(
        f"ccproof fit {Path(args.points).name}: {res.mesh.n_vertices} control vertices, max error "
        f"{res.max_error_percent:.3f} % of the enclosing-sphere diameter"))
    print(f"wrote {args.out}")
    return 0
