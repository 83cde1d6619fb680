"""Fit a dynamic Catmull-Clark surface to a point cloud (shape recovery from range data, qmv98 section 4.2).

  ccproof fit POINTS.xyz --out fitted.obj                 cube x2 (98 vertices) -> equilibrium -> 386 vertices
  ccproof fit scan.ply --levels 2 --out fitted.obj        two global subdivisions after the first fit
  ccproof fit bunny.obj --init start.ply --out fit.obj    start from your own closed control mesh

POINTS: .xyz (x y z per line), .ply (vertex x, y, z; ASCII or binary), .obj, .csv (header x,y,z; the formats
of `ccproof project`) or the vertices of any mesh file eval reads.
--init: any mesh eval reads; triangles and n-gons are subdivided once (Catmull-Clark) to quads
first (the same limit surface); unused vertices are dropped; OpenSubdiv tags (infinitely sharp and semi-sharp
creases and corners, holes, boundary modes) and non-manifold edges and vertices (infinitely sharp) are kept:
faces near them are tagged elements whose surface is the one `ccproof eval` evaluates (hole faces carry no
patch; the fitted OBJ keeps the tags as `t` lines); the copies of a non-manifold vertex (one per fan) move as
one point and are written as one vertex (an all-quad file at --levels 0: its own vertices and faces, in its
numbering). The model starts as the paper's 98-vertex mesh (the cube subdivided twice) inside the data,
evolves under data springs (every point pulls its nearest limit-surface point) with the massless implicit
scheme (32) to equilibrium (the relative changes of the total energy and of the mean data -> surface distance
over two steps both <= --tol; --max-steps is a safety cap), is subdivided once (386 vertices) and refitted.
Each level says why it stopped. Printed per level: control vertices, time steps, the paper's fit error (the
largest distance of a data point to the limit surface, in % of the diameter of the smallest enclosing sphere,
Welzl) and the mean distance in the same unit. All material parameters are in units where that diameter is 1
and the data springs sum to --spring.

The other direction is reported too: the limit surface sampled at --sample-level (written to
--surface-out, default OUT with "_limit" before the extension) and the distance of every sample to its
nearest data point: max, area-weighted mean and RMS, the area fraction farther than --stray-distance
(default 3 data spacings) and the two-sided (Hausdorff) error. Springs act both ways: besides the data
springs, once the first level has reached equilibrium, those of 4 x 4 samples per face that are farther
than --stray-distance from every data point are pulled toward their nearest data points, to within that
distance (constants in proportion to area, summing to --surface-spring, default 5; 0 turns them off), so
surface that no data point is near (a membrane across a concavity) is drawn to the data. A warning (stderr)
says when more than --stray-fraction of the surface strays (a torus' hole spanned, an unseen side filled in, a
concavity spanned) or a level stopped at --max-steps.
--errors FILE.csv writes x, y, z, distance and distance in % for every data point.

Limits: every time step re-projects every data point that carries a spring onto the limit surface (global
closest points), so the time grows with those points x steps: at most --spring-points of them (default 10^4, a
fixed random subset of a larger cloud; 0: all). On the bunny's limit surface (scripts/fit_dense.py) 10^4 points
take minutes (about 400 + 80 steps at --levels 1, a loaded 2-core machine); 10^5 points in about 6 minutes on
the default subset, while with all of them pulling (--spring-points 0) a step of the first level takes about 7 s
(an hour or more per fit). The surface -> data springs are what keep a dense fit from spanning a concavity (10^4
points: 6.9 % of the area more than 2 % of the diameter off the true surface with --surface- spring 0, 0.05 % at
the default); the stray warning's figures are distances to the data, within about one spacing of the distances
to the true surface on a dense cloud, and it names the faces where the surface strays.
Input files (POINTS, --init) at most --max-input GB (default 2; regular files or a pipe);
--sample-level at most 6. Outputs (--out, --surface-out or its derived name, --errors) are checked before
any work: distinct from each other and from the inputs (other spellings and links included), writable,
within the file system's name limits; they are renamed into place together when all are written, so a
failure leaves none of them.
"""

from __future__ import annotations

import sys


def add_arguments(p):
    p.add_argument("points", help="point cloud: .xyz, .ply, .obj or .csv (header x,y,z)")
    p.add_argument("--out", required=True, help="write the fitted control mesh (OBJ) here")
    p.add_argument("--init", default="cube",
                   help="'cube' (the paper's 98-vertex model, default) or a mesh (any format eval reads, with "
                        "OpenSubdiv tags and non-manifold edges and vertices; triangles and n-gons are subdivided "
                        "once to quads)")
    p.add_argument("--levels", type=int, default=1, help="global subdivisions after the first fit (default 1)")
    p.add_argument("--scheme", choices=("massless", "inertial"), default="massless",
                   help="time integrator: eq. (32) massless (default) or eq. (31)")
    p.add_argument("--dt", type=float, default=None, help="time step (default 1000 massless, 10 inertial)")
    p.add_argument("--max-steps", type=int, default=1000,
                   help="time steps per level at most, a safety cap (default 1000)")
    p.add_argument("--tol", type=float, default=1e-3,
                   help="equilibrium: relative changes of the energy and of the mean data error over two steps "
                        "(default 1e-3)")
    p.add_argument("--tension", type=float, default=1e-5, help="a11 = a22 (default 1e-5)")
    p.add_argument("--rigidity", type=float, default=1e-6, help="b11 = b22 = b12/2 (default 1e-6)")
    p.add_argument("--damping", type=float, default=1.0, help="gamma (default 1)")
    p.add_argument("--mass", type=float, default=0.0,
                   help="mu (default 0 with the massless scheme, 1 with --scheme inertial)")
    p.add_argument("--spring", type=float, default=1.0, help="sum of the data spring constants (default 1)")
    p.add_argument("--truncation", type=int, default=6, help="special-element stiffness level L (default 6)")
    p.add_argument("--init-scale", type=float, default=0.5, help="initial cube size / data box (default 0.5)")
    from ccproof.cli._progress import add_progress_argument

    add_progress_argument(p)
    p.add_argument("--surface-out", default=None,
                   help="write the fitted limit surface sampled at --sample-level (.obj or any meshio format; "
                        "default OUT with _limit before the extension)")
    p.add_argument("--sample-level", type=int, default=None,
                   help="subdivision level of the sampled limit surface (default: 1..3, >= 4 samples per point; "
                        "at most 6)")
    p.add_argument("--stray-distance", type=float, default=None,
                   help="surface samples farther than this (%% of the diameter) from every data point stray "
                        "(default 3 data spacings)")
    p.add_argument("--stray-fraction", type=float, default=0.01,
                   help="warn when more than this area fraction of the surface strays (default 0.01)")
    p.add_argument("--surface-spring", type=float, default=5.0,
                   help="sum of the surface -> data spring constants (4 x 4 samples per face, in proportion to "
                        "area): samples farther than --stray-distance from every data point are pulled toward their "
                        "nearest data point, from the first level's data-spring equilibrium on, so that surface no "
                        "data point is near (a membrane across a concavity) is pulled to the data; 0: data springs "
                        "only, as in the paper (default 5)")
    p.add_argument("--spring-points", type=int, default=10_000,
                   help="at most this many data points carry data springs (a fixed random subset of a larger cloud; "
                        "errors, stray report and surface -> data springs use every point); 0: all (default 10000)")
    p.add_argument("--errors", default=None, metavar="FILE.csv", help="write the per-point errors here")


def run(args) -> int:
    from pathlib import Path

    _check_options(args)
    plan = _output_plan(args)  # before any work
    import numpy as np

    from ccproof.apps.control_file import merge_labels, read_control_mesh, write_control_obj
    from ccproof.apps.dynamics.fit import Evolution, FitSprings, SurfaceCheck, fit_points
    from ccproof.apps.dynamics.model import Material
    from ccproof.cli._notice import compile_notice
    from ccproof.cli._progress import progress_enabled
    from ccproof.errors import CCProofError
    from ccproof.mesh.points import read_points

    X = read_points(args.points)
    init = args.init
    if init != "cube":
        if not Path(init).exists():
            raise CCProofError(f"--init: {init}: no such file (use 'cube' or a mesh file)")
        init, origin = read_control_mesh(init)
        if getattr(init, "hole", np.zeros(1, dtype=bool)).all():
            raise CCProofError(f"--init {args.init}: every face is a hole (no surface to fit)")
        if origin is not None:
            steps = getattr(init, "global_steps", 1)
            what = ("not all quads: subdivided once" if steps == 1 else
                    f"semi-sharp Chaikin tags: subdivided {steps} times")
            print(f"--init {args.init}: {what} (Catmull-Clark) to {init.n_faces} quads", file=sys.stderr)
    compile_notice("fit")
    mu = args.mass if args.scheme == "massless" or args.mass > 0 else 1.0
    material = Material(mu=mu, gamma=args.damping, a11=args.tension, a22=args.tension, b11=args.rigidity,
                        b12=2 * args.rigidity, b22=args.rigidity)
    springs = FitSprings(total=args.spring, surface_total=args.surface_spring, points=args.spring_points or None)
    evolution = Evolution(scheme=args.scheme, dt=args.dt, max_steps=args.max_steps, tol=args.tol,
                          truncation=args.truncation)
    check = SurfaceCheck(sample_level=args.sample_level, stray_distance_percent=args.stray_distance,
                         stray_fraction=args.stray_fraction)
    res = fit_points(X, init=init, levels=args.levels, material=material, springs=springs, evolution=evolution,
                     check=check, init_scale=args.init_scale, progress=progress_enabled(args))
    print(f"data: {X.shape[0]} points from {args.points}; minimal enclosing sphere diameter {res.diameter:.6g}")
    print("level  vertices  faces  steps  equilibrium  max error %  mean error %  seconds")
    for i, lev in enumerate(res.levels):
        print(f"{i:5d}  {lev.n_vertices:8d}  {lev.n_faces:5d}  {lev.steps:5d}  {'yes' if lev.converged else 'no':>11}"
              f"  {lev.max_error_percent:11.3f}  {lev.mean_error_percent:12.4f}  {lev.seconds:7.1f}")
    for i, lev in enumerate(res.levels):
        print(f"level {i}: {lev.reason}; energy {lev.energy:.6g}")
    print(f"fit error (max distance to the limit surface, % of the enclosing-sphere diameter): "
          f"{res.max_error_percent:.3f} %   mean: {res.mean_error_percent:.4f} %")
    print(f"data -> surface ({X.shape[0]} points): max {res.max_error_percent:.3f} %, RMS "
          f"{res.data_rms_percent:.4f} %")
    rep = res.surface_report
    print(f"surface -> data (limit surface at level {res.sample_level}, {res.surface.n_vertices} samples): max "
          f"{res.surface_max_percent:.3f} %, area-weighted mean {100 * rep['mean'] / res.diameter:.4f} %, RMS "
          f"{res.surface_rms_percent:.4f} %, {100 * rep['stray_fraction']:.2f} % of the area farther than "
          f"{res.stray_distance_percent:.3f} % (data spacing {100 * res.spacing / res.diameter:.3f} %)")
    print(f"two-sided (Hausdorff) error: {res.two_sided_error_percent:.3f} % of the enclosing-sphere diameter")
    for w in res.warnings:
        print(f"ccproof fit: warning: {w}", file=sys.stderr)
    fv = merge_labels(res.mesh)  # a non-manifold --init: its copies written as one vertex
    n_written = res.mesh.n_vertices if fv is None else int(fv.max()) + 1
    comment = (f"ccproof fit {Path(args.points).name}: {n_written} control vertices, max error "
               f"{res.max_error_percent:.3f} %, two-sided {res.two_sided_error_percent:.3f} % of the "
               f"enclosing-sphere diameter")
    with plan:  # all outputs or none
        with plan.write(args.out) as tmp:  # a non-manifold --init: the copies merged, the file's numbering
            write_control_obj(tmp, res.mesh, comment=comment)
        with plan.write(args.surface_out) as tmp:
            _write_surface(tmp, res, comment)
        if args.errors:
            d = res.data_distances
            with plan.write(args.errors) as tmp:
                np.savetxt(tmp, np.column_stack([X, d, 100 * d / res.diameter]), delimiter=",",
                           header="x,y,z,distance,distance_percent_of_diameter", comments="", fmt="%.9g")
    print(f"wrote {args.out} (control mesh) and {args.surface_out} (limit surface at level {res.sample_level})")
    if args.errors:
        print(f"wrote {args.errors} (per-point data -> surface distances)")
    return 0


def _check_options(args):
    """The options the library checks only later (or never: NaN compares false), before any work."""
    from math import isfinite

    from ccproof.errors import CCProofError

    if args.max_steps < 1:
        raise CCProofError(f"--max-steps must be >= 1, got {args.max_steps}")
    if args.sample_level is not None and not 0 <= args.sample_level <= MAX_SAMPLE_LEVEL:
        raise CCProofError(f"--sample-level must be 0..{MAX_SAMPLE_LEVEL} (each level has 4 times the samples), "
                           f"got {args.sample_level}")
    if not (isfinite(args.tol) and args.tol >= 0):
        raise CCProofError(f"--tol must be a finite number >= 0, got {args.tol}")
    if not 0 <= args.stray_fraction <= 1:  # NaN too
        raise CCProofError(f"--stray-fraction must be in [0, 1], got {args.stray_fraction}")
    if not (isfinite(args.surface_spring) and args.surface_spring >= 0):
        raise CCProofError(f"--surface-spring must be a finite number >= 0, got {args.surface_spring}")
    if args.spring_points != 0 and args.spring_points < 4:
        raise CCProofError(f"--spring-points must be 0 (all) or at least 4, got {args.spring_points}")
    if args.stray_distance is not None and not (isfinite(args.stray_distance) and args.stray_distance > 0):
        raise CCProofError(f"--stray-distance must be a finite number > 0 (% of the diameter), got "
                           f"{args.stray_distance}")
    _check_model_options(args)


def _check_model_options(args):
    """The model's numbers by their option names (the library named its parameters: a11, gamma, spring_total)."""
    from math import isfinite

    from ccproof.errors import CCProofError

    for option, value in (("--tension", args.tension), ("--rigidity", args.rigidity), ("--damping", args.damping),
                          ("--mass", args.mass)):
        if not (isfinite(value) and value >= 0):
            raise CCProofError(f"{option} must be a finite number >= 0, got {value}")
    for option, value in (("--spring", args.spring), ("--dt", args.dt)):
        if value is not None and not (isfinite(value) and value > 0):
            raise CCProofError(f"{option} must be a finite number > 0, got {value}")
    if not 0 < args.init_scale <= 1:  # NaN too
        raise CCProofError(f"--init-scale must be in (0, 1], got {args.init_scale}")
    if args.levels < 0:
        raise CCProofError(f"--levels must be >= 0, got {args.levels}")
    if args.truncation < 1:
        raise CCProofError(f"--truncation must be >= 1, got {args.truncation}")


#: the finest --sample-level (the 386-vertex model at level 6 is 1.6 million samples)
MAX_SAMPLE_LEVEL = 6


def _output_plan(args):
    """Every file ``fit`` writes (the derived ``OUT_limit`` name too), checked together before any work."""
    from pathlib import Path

    from ccproof.cli._output import OutputPlan, meshio_suffixes

    plan = OutputPlan()
    plan.add_input("POINTS", args.points)
    if args.init != "cube":
        plan.add_input("--init", args.init)
    plan.add("--out", args.out, (".obj",))
    if args.surface_out is None:
        o = Path(args.out)
        args.surface_out = str(o.with_name(o.stem + "_limit" + (o.suffix or ".obj")))
        plan.add("--surface-out (default: derived from --out)", args.surface_out, (".obj",))
    else:
        plan.add("--surface-out", args.surface_out, (".obj", *meshio_suffixes()))
    if args.errors:
        plan.add("--errors", args.errors, (".csv",))
    plan.check()
    return plan


def _write_surface(path, res, comment):
    import numpy as np

    from ccproof.errors import CCProofError
    from ccproof.mesh import write_obj

    if path.lower().endswith(".obj"):
        write_obj(path, res.surface, comment=comment + f"; limit surface sampled at level {res.sample_level}")
        return
    import meshio

    try:
        meshio.write(path, meshio.Mesh(np.asarray(res.surface.vertices), [("quad", res.surface.faces)],
                                       point_data={"distance_to_data": res.surface_report["distances"]}))
    except Exception as exc:
        raise CCProofError(f"cannot write {path!r}: {exc}") from exc
