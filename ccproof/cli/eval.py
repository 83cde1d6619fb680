"""Evaluate the Catmull-Clark (or, with --scheme loop, the Loop) limit surface of a mesh (OBJ with OpenSubdiv
tags, OFF, PLY, STL, VTK or any other format meshio reads; non-manifold edges and vertices and unused vertices as
OpenSubdiv takes them) in one of the parameterizations of bmz04 (triangles, n-gons, tagged and
non-manifold meshes: natural only, ``face`` being the ptex face index): natural (Stam, section 2),
vanishing (F^alpha blend, section 4.2: derivatives tend to 0 at extraordinary vertices) or
characteristic (Phi^-1 blend, section 4.3: C1 with a Jacobian of rank 2 at extraordinary vertices).

Positions P and derivatives (Pu, Pv; Puu, Puv, Pvv) with respect to each face's own parameter
(u, v): corner i of the face's OBJ vertex list at (0,0), (1,0), (1,1), (0,1) for i = 0..3 (the ptex
convention of OpenSubdiv). The reparameterizations change (u, v) only in the quarter of a face at
an interior vertex of valence != 4; every parameterization covers the same surface.

Points come from a CSV file with the header ``face,u,v`` (0-based face index) or are drawn at
random (--samples N, uniform face and (u, v); faces in holes have no surface and are not drawn).
The output .npz holds the arrays P, Pu, Pv (and Puu, Puv, Pvv with --derivatives 2), each of shape
(n, 3) in the order of the points, and face, u, v.

Limits (checked before any work): every input file at most --max-input GB (default 2; regular files or a
pipe, read once); one .npz result must fit this machine's memory (96 bytes per point, 168 with --derivatives
2), shards (--out FOLDER/) the free disk; --scheduler local:N at most the cores and the chunks; outputs may
not replace an input.

Where the points run: in this process for one chunk (--chunk, default 10^6 points), and by default for several
chunks too when the compiled kernel is there (its threads use every core; a local Dask cluster would only add the
memory of its worker processes: the report says so); --scheduler local:N or ADDRESS starts or uses a cluster, whose
workers share the one table built here.

With --scheme loop: the exact Loop limit surface of a triangle mesh (OpenSubdiv's Sdc Loop rules: boundaries,
infinitely sharp creases and corners), ``face`` the triangle index, corner 0 of the triangle at (u, v) = (0, 0),
1 at (1, 0), 2 at (0, 1), u + v <= 1 (--samples draws uniformly in the triangles).

Examples:
  ccproof eval bunny.obj --samples 1000000 --out bunny.npz --plot ev.png
  ccproof eval mesh.obj --points points.csv --parameterization characteristic --derivatives 1 --out out.npz
  ccproof eval mesh.obj --samples 1000 --parameterization vanishing --alpha 2.5 --out out.npz
  ccproof eval triangles.obj --scheme loop --samples 100000 --derivatives 2 --out loop.npz
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

from ccproof.cli._eval_args import add_arguments as _add_evaluate_arguments
from ccproof.cli._eval_args import evaluable_ptex_faces, read_face_uv_csv
from ccproof.cli._progress import add_progress_argument, progress_enabled
from ccproof.errors import CCProofError


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
    from ccproof.scale.engine import add_scheduler_arguments

    add_scheduler_arguments(parser)
    add_progress_argument(parser)
    parser.add_argument("--threads", type=int, metavar="T",
                        help="evaluation threads per process (default: every core when the points are evaluated "
                        "in this process, 1 per task on a Dask cluster, whose local workers are one per core)")
    parser.add_argument("--chunk", type=int, default=1_000_000, metavar="M",
                        help="points per task (default 1000000); --out FOLDER/ writes one .npz shard per chunk and "
                        "--points FOLDER reads one (docs/scale-out.md)")


def _phases(read, setup, worker_setup, start=0.0):
    """The phases before the evaluation, as printed: read and setup seconds, then (workers) sharing the surface
    and starting them, and the longest a worker took to map or receive the surface.

    >>> _phases(1.5, 2.0, 0.0)
    'read in 1.50 s, setup 2.00 s'
    >>> _phases(1.5, 2.0, 0.25, 3.0)
    'read in 1.50 s, setup 2.00 s, workers ready in 3.00 s (surface taken in 0.25 s)'
    """
    text = f"read in {read:.2f} s, setup {setup:.2f} s"
    if start >= 0.005 or worker_setup >= 0.005:
        text += f", workers ready in {start:.2f} s (surface taken in {worker_setup:.2f} s)"
    return text


def build_surface(mesh, tagged, alpha=None, progress=False, scheme="catmark"):
    """The surface ``ccproof eval`` evaluates (module level, so a Dask worker can rebuild it by name):
    the tagged evaluator's natural parameterization for a tagged or non-quad :class:`PolyMesh`, else the
    reparameterizable surface of an all-quad :class:`QuadMesh`; with ``scheme="loop"`` the Loop surface of a
    triangle mesh. ``progress``: a bar for the setup, where the constructor draws one (never on a worker)."""
    if scheme != "catmark":
        from ccproof.reparam.surface import limit_surface

        return limit_surface(mesh, scheme=scheme)
    if tagged:
        from ccproof.evaluate import limit_surface as natural_surface

        return natural_surface(mesh, progress=progress)
    from ccproof.reparam.surface import limit_surface

    return limit_surface(mesh, alpha=alpha, progress=progress)


def _checked_points(path, n_faces, evaluable=None):
    """The (face, u, v) of a CSV file, each point checked (face in range and not in a hole, u and v in
    [0, 1]) with its line number: the evaluator checks them too, but only chunk by chunk and after the
    setup. ``evaluable``: the ptex faces outside holes (None: all)."""
    import numpy as np

    face, u, v = read_face_uv_csv(path)
    inside = (face >= 0) & (face < n_faces)
    hole = inside & ~np.isin(face, evaluable) if evaluable is not None else np.zeros(face.shape, bool)
    for bad, what in (
        (~inside, lambda i: f"face id {int(face[i])} out of range [0, {n_faces})"),
        (hole, lambda i: f"face id {int(face[i])} lies in a hole of the mesh (it has no limit surface)"),
        (~((u >= 0) & (u <= 1)), lambda i: f"u = {float(u[i])!r} is outside [0, 1]"),  # NaN too
        (~((v >= 0) & (v <= 1)), lambda i: f"v = {float(v[i])!r} is outside [0, 1]"),
    ):
        i = np.flatnonzero(bad)
        if i.size:
            raise CCProofError(f"{path}:{int(i[0]) + 2}: point {int(i[0])}: {what(int(i[0]))}")
    return face, u, v


def check_result_size(n, derivatives, out_path, shards, what=""):
    """Refuse, before any work, a result that cannot be held: one ``.npz`` file is built in memory (at most
    the machine's physical memory), shards are streamed to disk (at most the free space of their folder).

    >>> from pathlib import Path
    >>> check_result_size(10**15, 1, Path("o.npz"), False, "--samples 1000000000000000: ")
    Traceback (most recent call last):
    ...
    ccproof.errors.CCProofError: --samples 1000000000000000: the result takes 96 PB (96 bytes per point), more ...
    """
    import os
    import shutil

    per_point = 8 * (3 + 3 * (1, 3, 6)[derivatives])  # face, u, v and P (Pu, Pv; Puu, Puv, Pvv)
    need = n * per_point
    if shards:
        folder = Path(out_path)
        while not folder.exists() and folder != folder.parent:
            folder = folder.parent
        have, where = shutil.disk_usage(folder).free, f"the free space of {folder}"
        hint = "free some space or write elsewhere"
    else:
        try:
            have = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
        except (ValueError, OSError, AttributeError):
            return
        where, hint = "this machine's memory", "write shards with --out FOLDER/ (one .npz per --chunk points)"
    if need > have:
        raise CCProofError(f"{what}the result takes {_size(need)} ({per_point} bytes per point), more than {where} "
                           f"({_size(have)}); {hint}, or evaluate fewer points")


def _size(b):
    for unit in ("bytes", "kB", "MB", "GB", "TB", "PB"):
        if b < 1000 or unit == "PB":
            return f"{b:.0f} {unit}" if unit == "bytes" else f"{b:.3g} {unit}"
        b /= 1000


def run(args) -> int:
    from pathlib import Path

    out_path, shards = _check_outputs_and_options(args)
    from ccproof.mesh.io import read_mesh
    from ccproof.scale import scheduler_from_args

    points = None if args.points is None else Path(args.points).resolve()
    sched = scheduler_from_args(args)  # --scheduler checked before any work
    from ccproof.cli._progress import phase

    progress = progress_enabled(args)
    t0 = time.perf_counter()
    with phase(f"read {Path(args.mesh).name}", progress):
        poly = read_mesh(args.mesh)  # OBJ with OpenSubdiv tags, OFF, or any meshio format
    t_read = time.perf_counter() - t0
    mesh, tagged, n_faces, kwargs, evaluable = _mesh_to_evaluate(args, poly)
    del poly  # (``mesh`` is the same object, or its QuadMesh)
    # the points before the surface's setup (seconds on large meshes): a bad point is reported at once
    sources = _point_sources(args, points, n_faces, evaluable, out_path, shards)
    from ccproof.cli._notice import compile_notice

    compile_notice("eval")  # after the input checks: an error stays one line
    sched, note = _default_in_process(args, sched, len(sources))
    held = [mesh]  # handed over: once shared, the surface's copy is the only one
    del mesh
    n, names, sweep, surface, times = _evaluate_sources(args, held, tagged, kwargs, sources, out_path, sched,
                                                        progress)
    mesh = surface.mesh
    setup, worker_setup, t_start, t_write = times
    for line in sweep.report([f"chunk {i}" for i in range(len(sources))]):  # retried or lost tasks
        print(line)
    out = dict.fromkeys(names)
    what = (str(mesh) if tagged else f"{mesh.n_vertices} vertices, {mesh.n_faces} faces, "
            f"{mesh.extraordinary_vertices.size} extraordinary vertices")
    print(f"{args.mesh}: {what}; {_phases(t_read, setup, worker_setup, t_start)}")
    evaluation = max(sweep.seconds - worker_setup, 0.0)  # the workers take the surface at the same time, first
    scheme = "" if args.scheme == "catmark" else f"{args.scheme} scheme, "
    print(f"evaluated {n} points ({scheme}{args.parameterization} parameterization, derivatives {args.derivatives}) "
          f"in {_evaluation_phases(n, evaluation, t_write)}")
    if note:
        print(note)
    print(f"wrote {args.out}: {', '.join(['face', 'u', 'v', *out])}")
    if args.plot:
        _plot(args, mesh, surface)
    sys.stdout.flush()
    return 0


def _default_in_process(args, sched, n_chunks):
    """(scheduler, note): the default scheduler (no --scheduler, --jobs or --serial) evaluates several chunks of a
    Catmull-Clark surface in this process when the compiled kernel is there: it runs every core as threads, so a
    local Dask cluster would add only its worker processes and their copies of the chunks' results (measured on
    81,920 triangles, 2 x 10^6 points: 1.37 x the memory of --serial, 3.5 x its time,
    scripts/bench_eval_scheduler.py).
    The note says so in the report; ``--scheduler local:N`` still starts a cluster. The numpy kernel (one thread)
    and the Loop scheme keep the cluster: there it is the only way to use the cores."""
    if not (getattr(sched, "implicit", False) and sched.kind == "local" and n_chunks > 1 and args.scheme == "catmark"):
        return sched, ""
    from ccproof.evaluate.backend import evaluation_kernel
    from ccproof.scale import Scheduler

    name, kernel = evaluation_kernel(None)
    if kernel is None:
        return sched, ""
    threads = args.threads or sched.workers
    return Scheduler("serial"), (f"default scheduler: the {n_chunks} chunks evaluated in this process, {threads} "
                                 f"thread{'s' if threads > 1 else ''} of the {name} kernel (a local Dask cluster "
                                 "would add its worker processes' memory, not speed; --scheduler local:N starts one)")


def _check_outputs_and_options(args):
    """Every output checked before any work (even the imports), then the options; returns (out path, shards)."""
    from ccproof.cli._output import PLOT_SUFFIXES, OutputPlan, is_folder_request

    # distinct from the inputs (--points FOLDER may not be the --out folder); absolute paths (a Dask worker may
    # run elsewhere)
    plan = OutputPlan()
    plan.add_input("MESH", args.mesh)
    plan.add_input("--points", args.points)
    shards = is_folder_request(args.out)
    out_path = plan.add_folder("--out", args.out) if shards else \
        plan.add("--out", args.out, (".npz",), hint="(or FOLDER/ for shards)")
    if args.plot:
        plan.add("--plot", args.plot, PLOT_SUFFIXES)
    plan.check()
    if args.alpha is not None and args.parameterization != "vanishing":
        raise CCProofError(f"--alpha is the exponent of --parameterization vanishing, not of {args.parameterization}")
    if args.threads is not None and args.threads < 1:
        raise CCProofError(f"--threads must be >= 1, got {args.threads}")
    if args.seed < 0:  # numpy's generators take non-negative seeds (the tasks failed one by one after the setup)
        raise CCProofError(f"--seed must be an integer >= 0, got {args.seed}")
    return out_path, shards


def _mesh_to_evaluate(args, poly):
    """(mesh, tagged, number of faces, evaluate's keywords, evaluable ptex faces or None) of the mesh read."""
    if args.scheme == "loop":
        return _loop_mesh(args, poly)
    tagged = not poly.is_plain_quads
    if tagged:
        # triangles, n-gons, creases, corners, holes, boundary modes: the natural parameterization
        # of the tagged evaluator, by ptex face (equal to the face index on all-quad meshes)
        if args.parameterization != "natural":
            raise CCProofError(
                f"{args.mesh}: the {args.parameterization} parameterization needs an untagged all-quad mesh "
                "(this one has non-quad faces, OpenSubdiv tags or non-manifold edges or vertices); use "
                "--parameterization natural"
            )
        if args.plot:
            raise CCProofError(f"{args.mesh}: --plot needs an untagged all-quad mesh")
        evaluable = evaluable_ptex_faces(poly)  # holes (tagged, or boundary mode none) have no surface
        if evaluable is not None and evaluable.size == 0:
            raise CCProofError(f"{args.mesh}: every face is a hole: there is no limit surface to evaluate")
        return poly, tagged, poly.n_ptex, {}, evaluable
    mesh = poly.to_quad_mesh()
    if args.plot and args.plot_vertex is not None and not 0 <= args.plot_vertex < mesh.n_vertices:
        raise CCProofError(f"--plot-vertex {args.plot_vertex} out of range [0, {mesh.n_vertices})")
    return mesh, tagged, mesh.n_faces, {"parameterization": args.parameterization}, None


def _loop_mesh(args, poly):
    """--scheme loop: the triangle mesh (checked before any work), its faces, no keywords."""
    import numpy as np

    if args.parameterization != "natural":
        raise CCProofError(f"--parameterization {args.parameterization} is Catmull-Clark's (bmz04); --scheme loop "
                           "has the natural parameterization only")
    if args.plot:
        raise CCProofError("--plot draws Catmull-Clark isoparameter lines; it does not apply to --scheme loop")
    bad = np.flatnonzero(poly.sizes != 3)
    if bad.size:
        f = int(bad[0])
        raise CCProofError(f"{args.mesh}: --scheme loop takes triangles only: face {f} has {int(poly.sizes[f])} "
                           "vertices")
    evaluable = np.flatnonzero(~poly.is_hole).astype(np.int64) if poly.is_hole.any() else None
    if evaluable is not None and evaluable.size == 0:
        raise CCProofError(f"{args.mesh}: every face is a hole: there is no limit surface to evaluate")
    return poly, True, poly.n_faces, {}, evaluable


def _check_in_triangles(path, face, u, v):
    """--scheme loop: every point of a CSV file in its triangle (u + v <= 1), else the line named."""
    import numpy as np

    i = np.flatnonzero(~(u + v <= 1))
    if i.size:
        k = int(i[0])
        raise CCProofError(f"{path}:{k + 2}: point {k}: u + v = {float(u[k] + v[k])!r} > 1 is outside triangle "
                           f"{int(face[k])} (--scheme loop: u, v >= 0, u + v <= 1)")


def _loop_samples(args, n_faces, evaluable):
    """--samples for --scheme loop: uniform triangle (outside holes), uniform (u, v) in it (u + v <= 1)."""
    import numpy as np

    from ccproof.scale import point_chunks

    rng = np.random.default_rng(args.seed)
    face = rng.integers(0, n_faces, args.samples) if evaluable is None else \
        evaluable[rng.integers(0, evaluable.size, args.samples)]
    u, v = rng.random(args.samples), rng.random(args.samples)
    flip = u + v > 1
    u[flip], v[flip] = 1 - u[flip], 1 - v[flip]
    return point_chunks(args.chunk, arrays=(face, u, v))


def _point_sources(args, points, n_faces, evaluable, out_path, shards):
    """The chunks of points to evaluate (--points FILE or FOLDER, or --samples), checked before the setup."""
    from ccproof.scale import point_chunks

    if points is not None and points.is_dir():
        from ccproof.mesh.inputs import check_regular_file

        check_regular_file(points / "index.json")  # (a link to /dev/zero refused before it is read)
        return point_chunks(args.chunk, shards=points)
    if points is not None:
        arrays = _checked_points(args.points, n_faces, evaluable)
        if args.scheme == "loop":
            _check_in_triangles(args.points, *arrays)
        check_result_size(arrays[0].size, args.derivatives, out_path, shards, f"{args.points}: ")
        return point_chunks(args.chunk, arrays=arrays)
    if args.samples < 0:
        raise CCProofError(f"--samples must be >= 0, got {args.samples}")
    check_result_size(args.samples, args.derivatives, out_path, shards, f"--samples {args.samples}: ")
    if args.scheme == "loop":
        return _loop_samples(args, n_faces, evaluable)
    return point_chunks(args.chunk, samples=args.samples, seed=args.seed,
                        n_faces=n_faces if evaluable is None else evaluable)


def _evaluate_sources(args, held, tagged, kwargs, sources, out_path, sched, progress):
    """Evaluate the chunks on the scheduler and write --out; returns (points, names, sweep, surface, times)
    with times = (setup here, the workers' setup, sharing the surface and starting the workers, gathering and
    writing).

    The surface is built once, here, before any worker starts, from the mesh in the list ``held`` (emptied:
    the surface keeps the mesh); the workers of this machine map its arrays from shared memory, those of a
    remote cluster receive it by value, once per worker (never rebuilt). ``progress``: a bar for every phase
    (the setup, the sharing and the workers' start, the evaluation, the writing)."""
    import contextlib

    from ccproof.cli._progress import phase
    from ccproof.scale import open_scheduler, release_freed_memory, runs_in_process, share

    t1 = time.perf_counter()
    with phase("setup", progress):  # (the patch table's own bar below it, where the build is long)
        surface = build_surface(held.pop(), tagged, args.alpha, progress, args.scheme)
    setup = time.perf_counter() - t1
    in_process = runs_in_process(sched, len(sources))
    where = "here" if in_process else "anywhere" if sched.kind == "address" else "machine"
    t_start = time.perf_counter()
    with contextlib.ExitStack() as stack:
        with phase("share the surface with the workers and start them", progress and not in_process):
            if where == "machine":
                release_freed_memory()  # the build's temporaries, before the shared copy is written
            shipped, surface = stack.enter_context(share(surface, where))
            if where == "machine":
                release_freed_memory()  # the surface as built (its shared copy replaces it here)
            sched = stack.enter_context(open_scheduler(sched, len(sources)))
        t_start = 0.0 if in_process else time.perf_counter() - t_start
        if args.threads is not None:
            kwargs["threads"] = args.threads
        elif not in_process:
            kwargs["threads"] = 1  # one worker per core already: no second level of threads
        # the file (or each shard and the index) is written under a temporary name, then renamed
        t_tasks = time.perf_counter()
        with phase(f"evaluate {sum(_count(s) for s in sources)} points", progress and len(sources) == 1):
            n, names, sweep, worker_setup = evaluate_points_of(shipped, sources, args, kwargs, out_path, sched,
                                                               surface, progress)
        t_write = time.perf_counter() - t_tasks - sweep.seconds  # gathering and writing the output
    return n, names, sweep, surface, (setup, worker_setup, t_start, t_write)


def _count(source):
    """Points of a chunk source (of :func:`ccproof.scale.point_chunks`; a shard: unknown here, 0)."""
    return int(source[3]) if source[0] == "samples" else len(source[1]) if source[0] == "arrays" else 0


def evaluate_points_of(shipped, sources, args, kwargs, out_path, sched, surface, progress):
    """:func:`ccproof.scale.evaluate_points` with the options of ``args``."""
    from ccproof.scale import evaluate_points

    return evaluate_points(shipped, sources, args.derivatives, kwargs, str(out_path), sched, local=surface,
                           progress=progress)


def _evaluation_phases(n, evaluation, write):
    """The evaluation's seconds and rate (of the evaluation alone), then the gathering and writing.

    >>> _evaluation_phases(10**6, 0.5, 0.25)
    '0.500 s (2,000,000 points/s, evaluation alone); gathering and writing 0.25 s'
    """
    rate = n / evaluation if evaluation > 0 and n else float("nan")
    return f"{evaluation:.3f} s ({rate:,.0f} points/s, evaluation alone); gathering and writing {write:.2f} s"


def _plot(args, mesh, surface):
    """--plot: the isoparameter lines around --plot-vertex (default: the extraordinary vertex of highest valence)."""
    import numpy as np

    from ccproof.cli._output import atomic
    from ccproof.reparam.plot import plot_isoparameter_lines

    vtx = args.plot_vertex
    if vtx is None:
        ev = mesh.extraordinary_vertices
        vtx = int(ev[np.argmax(mesh.valence[ev])]) if ev.size else 0
    with atomic(Path(args.plot).resolve()) as tmp:
        plot_isoparameter_lines(surface, vtx, tmp, parameterization=args.parameterization)
    print(f"wrote {args.plot}: isoparameter lines around vertex {vtx} (valence {int(mesh.valence[vtx])})")
