"""ARAP parameterization of a Catmull-Clark subdivision surface (He, Schaefer, Hormann 2010).

Optimizes the texture control points of every chart so that the subdivided texture maps the LIMIT
surface as rigidly as possible (hsh10 Eq. 3), with a multi-resolution schedule over the levels
start..K, either with extended charts (hsh10 (c), default) or with boundary rules (b). Charts are
per-face integer labels (--charts FILE, one per face in OBJ order; negative = no chart) or a simple
segmentation (--segment normals: six charts by the dominant axis of the face normal, or with --normal-angle DEG
charts whose normals lie within DEG degrees of their first face's; then split into disks); without either the
whole mesh must be a topological disk, and a single chart that folds says so with the fix (segment into charts).

Prints E_angle, E_area, E_stretch (hsh10 section 4, at --eval-level, default 5), flipped texture
triangles of the control mesh and flipped samples at the evaluation level, seconds and iterations.
With --baselines also (a) ARAP on the triangulated control mesh, the other variant, and (d) ARAP on
the control mesh subdivided 3 times, all measured the same way.

Output for other tools (--out FILE): the limit surface sampled at --out-level (default 3) as a
triangle (or --cells quad) mesh whose per-vertex UVs are the parameterization evaluated exactly at
the limit points; charts packed into [0, 1]^2 without overlap (shelf packing, one common scale);
seams as duplicated vertices (one UV per chart). FILE.obj is written directly (v, vt, f i/i), any
other extension through meshio (point data "uv"; PLY: "s", "t"); FILE.json holds the metrics, the
packing scale and the written triangles' own distortion. The written triangles are judged first: where
their UVs fold (signed area <= 0) the default --refine/--out-level refine the control mesh further (up to 4,
within --max-memory) until none folds, saying which; an explicit --refine/--out-level that folds is refused
(exit 1, the count and the fix, nothing written) unless --allow-folds (written, with a warning).
--control-out FILE.obj writes a control mesh
with texture control points for the rule every subdivision tool has, OpenSubdiv's face-varying "corners
only" (FVAR_LINEAR_CORNERS_ONLY; its header says so): fitted to the exact texture and polished by the
same optimization under that rule, on the texture's control mesh subdivided 0..--control-extra more times
(the fewest that give no fold at levels 1-3 and every distortion excess within 5 % of the exact texture's,
at most --control-max-faces faces; where the last one allowed misses that, each chart takes the polish or a
minimization of the measured distortion, whichever makes the largest excess ratio smallest); it prints the
folds and the distortion such a tool will see.

Input: any mesh `ccproof eval` reads (OBJ, PLY, OFF, STL, VTK, ...), with the surface `ccproof eval`
evaluates. Triangles and n-gons are subdivided once with Catmull-Clark first (n quads per n-gon, the same
limit surface); --charts labels then name the file's faces, each label carried to its quads. Unused
vertices are dropped. OpenSubdiv tags (creases, corners, holes, boundary modes, semi-sharp edges and
vertices) and non-manifold edges and vertices (infinitely sharp, as OpenSubdiv makes them) follow
OpenSubdiv's rules on every level; with the Chaikin crease method a semi-sharp tag (sharpness s < 10) is
resolved by ceil(s) global Catmull-Clark steps first (refused by name beyond 200,000 faces); hole faces
belong to no chart. --control-out on such a mesh writes the control mesh the UVs belong to (the quads above,
subdivided as the UVs need, a non-manifold vertex's split copies written as one vertex: without a subdivision
the file's vertices in its numbering) with its creases, corners and holes as OpenSubdiv's
OBJ tag lines ('t crease 2/1/0 a b s', 't corner 1/1/0 v s', 't hole k/0/0 f ...'; 0-based, infinitely sharp
as 10): reading it back (ccproof eval, OpenSubdiv) gives the same tags and the same limit surface.

Scale: charts are processed one at a time; the peak memory is estimated first. The levels not given
(--out-level, --eval-level, then --levels) are lowered one at a time until the estimate fits --max-memory
(default 2 GB), and stderr says which were chosen; a run that still does not fit stops with an error naming
the options that lower it. --refine R (default:
the smallest R in 0..2 giving >= 1000 control faces per chart) subdivides the control mesh before
optimizing (b)/(c), which lets (c) reach (d)'s E_area on small charts; --accel (default 5) is the
Anderson acceleration of the local/global iteration. --preview FILE.png renders checkerboard and
distortion maps.

Inputs (the mesh, --charts) at most --max-input GB (default 2; regular files or a pipe). Outputs: every
file a run writes (--out and FILE.json, --control-out and UV.obj.json, --labels-out, --preview) is checked
before any work: distinct from each other and from the inputs (other spellings and links included),
writable, within the file system's name limits; they are renamed into place together when all are
written, so a failure (a full disk) leaves none of them. --out-level, --control-extra, --levels and the
other counts must be >= 0, --max-memory and --tol finite.

Example:  ccproof arap bunny_quads.obj --segment normals --baselines --out bunny_uv.obj --preview bunny.png
"""

from __future__ import annotations

import json
import sys

__all__ = ["add_arguments", "run", "format_table"]


def add_arguments(parser):
    parser.add_argument("mesh", help="control mesh: any mesh eval reads (OpenSubdiv tags and non-manifold meshes "
                                     "too); triangles and n-gons are subdivided once (Catmull-Clark) to quads first")
    parser.add_argument("--charts", metavar="LABELS", help="chart label file: one integer per face of the file")
    parser.add_argument("--segment", choices=["normals"], help="segment into charts (when no --charts)")
    parser.add_argument("--normal-angle", type=float, default=None, metavar="DEG",
                        help="with --segment normals: a chart holds faces whose normals are within DEG degrees of "
                             "its first face's (larger: fewer charts; default: six charts by the dominant axis of "
                             "the normal, then split into disks)")
    parser.add_argument("--variant", choices=["extended", "boundary"], default="extended",
                        help="chart boundary treatment: extended charts (c) or boundary rules (b)")
    parser.add_argument("--levels", type=int, default=None, metavar="K",
                        help="finest optimization level (default 3, lowered while the estimated memory of the "
                             "largest chart exceeds --max-memory)")
    parser.add_argument("--start-level", type=int, default=1, help="coarsest optimization level (default 1)")
    parser.add_argument("--eval-level", type=int, default=None,
                        help="level of the metric samples (default: 5, lowered for large meshes so that all "
                             "charts have at most 4M samples and to fit --max-memory, at least 3 with --baselines)")
    parser.add_argument("--refine", default="auto",
                        help="subdivide the control mesh R times before optimizing (b)/(c): 0, 1, 2 or auto "
                             "(default: the smallest R in 0..2 giving >= 1000 control faces per chart)")
    parser.add_argument("--max-memory", type=float, default=2.0, metavar="GB",
                        help="the levels not given are lowered to fit this estimated peak memory; a run that still "
                             "exceeds it is refused (default 2 GB)")
    from ccproof.cli._progress import add_progress_argument

    add_progress_argument(parser)
    parser.add_argument("--accel", type=int, default=5, metavar="M",
                        help="Anderson acceleration history of (b)/(c), energy-safeguarded (default 5; 0: plain)")
    parser.add_argument("--tol", type=float, default=1e-6, help="relative energy decrease to stop a level")
    parser.add_argument("--max-iter", type=int, default=1000, help="iterations per level at most")
    parser.add_argument("--baselines", action="store_true", help="also run (a), the other variant and (d)")
    parser.add_argument("--engine", choices=["auto", "numpy", "igl"], default="auto",
                        help="triangle ARAP engine of the baselines (auto: libigl if installed)")
    parser.add_argument("--out", metavar="FILE",
                        help="write the limit surface sampled at --out-level with exact UVs (.obj, or any "
                             "meshio format such as .vtu .ply), plus FILE.json")
    parser.add_argument("--out-level", type=int, default=None,
                        help="sampling level of --out and --preview (default 3, lowered for large meshes to "
                             "at most 2M triangles)")
    parser.add_argument("--cells", choices=["triangle", "quad"], default="triangle", help="cells of --out")
    parser.add_argument("--control-out", metavar="UV.obj",
                        help="write a control mesh with texture control points for OpenSubdiv's face-varying "
                             "'corners only' rule (OBJ with vt, plus UV.obj.json; a tagged or non-manifold input's "
                             "tags as OpenSubdiv 't crease/corner/hole' lines; see above)")
    parser.add_argument("--control-extra", type=int, default=2, metavar="N",
                        help="--control-out may subdivide the texture's control mesh up to N more times (default 2), "
                             "not beyond --control-max-faces")
    parser.add_argument("--control-max-faces", type=int, default=150_000, metavar="F",
                        help="largest control mesh --control-out writes (default 150000 faces)")
    parser.add_argument("--allow-folds", action="store_true",
                        help="write --out even where its UV triangles fold (with a warning); without it such an "
                             "output is refined away at the default --refine/--out-level, else refused (exit 1)")
    parser.add_argument("--labels-out", metavar="FILE", help="write the chart labels used")
    parser.add_argument("--preview", metavar="FILE.png",
                        help="render a checkerboard through the UVs and the per-triangle distortion (matplotlib), "
                             "one row per method")


def format_table(results, eval_level=5):
    """The comparison table as text (one row per method)."""
    head = (f"{'method':<30} {'E_angle':>9} {'E_area':>9} {'E_stretch':>9} {'flips T0':>11} "
            f"{'flips L' + str(eval_level):>9} {'seconds':>8} {'iters':>6}")
    rows = [head, "-" * len(head)]
    for r in results.values():
        m = r.metrics
        rows.append(
            f"{r.name:<30} {m.E_angle:9.6f} {m.E_area:9.6f} {m.E_stretch:9.6f} "
            f"{f'{r.flips_control}/{r.triangles_control}':>11} {m.flips:>9d} {r.seconds:8.2f} {r.iterations:6d}"
        )
    return "\n".join(rows)


#: at most this many triangles in the default --out
MAX_DEFAULT_OUT_TRIANGLES = 2_000_000
#: at most this many metric samples (faces of E_k over all charts) for the default --eval-level
MAX_DEFAULT_SAMPLES = 4_000_000


def default_eval_level(mesh, labels, levels, with_d):
    """5 (hsh10's level), lowered while the charts' E_k hold more than MAX_DEFAULT_SAMPLES faces, but not
    below the optimization level, nor below 3 when (d) is measured (its texture lives at level 3)."""
    import numpy as np

    from ccproof.apps.arap.meshes import mesh_charts

    F = mesh.faces
    n = 0
    for fc in mesh_charts(mesh, labels):  # faces of E_0: the chart and its ring
        isc = np.zeros(mesh.n_vertices, dtype=bool)
        isc[F[fc]] = True
        n += int(isc[F].any(axis=1).sum())
    k = 5
    while k > 0 and n * 4**k > MAX_DEFAULT_SAMPLES:
        k -= 1
    return max(k, levels, 3 if with_d else 0)


def _default_out_level(mesh, labels):
    """3, lowered while --out would hold more than MAX_DEFAULT_OUT_TRIANGLES triangles."""
    n = mesh.n_faces if labels is None else int((labels >= 0).sum())
    out_level = 3
    while out_level > 0 and 2 * n * 4**out_level > MAX_DEFAULT_OUT_TRIANGLES:
        out_level -= 1
    return out_level


def _sample_level(args, out_level):
    """The level the outputs sample (--out, --control-out, --preview), None when none is written."""
    return out_level if (args.out or args.control_out or args.preview) else None


def _levels_within_budget(args, mesh, labels, hierarchies, methods, refine):
    """(levels, eval level, out level): the options given, the others at their defaults, lowered one level at a
    time (the metrics' or the output's sampling level first, then the optimization's) while the estimated peak
    memory exceeds --max-memory; says on stderr what was lowered. When nothing given can be lowered enough, the
    run refuses later by name (:class:`~ccproof.apps.arap.meshes.MemoryBudgetError`)."""
    from ccproof.apps.arap.meshes import run_memory

    budget = args.max_memory * 1e9
    levels = 3 if args.levels is None else args.levels
    ev = args.eval_level if args.eval_level is not None else default_eval_level(mesh, labels, levels, "d" in methods)
    out = args.out_level if args.out_level is not None else _default_out_level(mesh, labels)
    first = (levels, ev, out)

    def need(levels, ev, out):
        return run_memory(hierarchies, methods, levels, ev, _sample_level(args, out), refine, release=True)[0]

    floor = max(refine, 3 if "d" in methods else 0)
    while need(levels, ev, out) > budget:
        samples = _sample_level(args, out)
        if args.out_level is None and samples is not None and out > 0 and out >= ev:
            out -= 1
        elif args.eval_level is None and ev > max(floor, levels):
            ev -= 1
        elif args.levels is None and levels > max(args.start_level, 1):
            levels -= 1
        else:
            break
    if (levels, ev, out) != first:
        names = ("levels", "metrics level", "output level")
        what = ", ".join(f"{n} {a} -> {b}" for n, a, b in zip(names, first, (levels, ev, out)) if a != b)
        print(f"ccproof arap: chosen to fit --max-memory {args.max_memory:g} GB: {what} (estimated peak "
              f"{need(levels, ev, out) / 1e9:.2f} GB)", file=sys.stderr)
    return levels, ev, out


def run(args) -> int:
    plan = _output_plan(args)  # every file written, and the options among themselves: before any work
    from ccproof.apps.arap.hierarchy import ChartHierarchy
    from ccproof.apps.arap.meshes import auto_refine, mesh_charts
    from ccproof.errors import CCProofError

    refine = _check_options(args)
    mesh, labels = _read_input(args)
    ours, methods, engine = _methods(args)
    refine = auto_refine(mesh, labels) if refine is None else refine
    hierarchies = [ChartHierarchy(mesh, fc) for fc in mesh_charts(mesh, labels)]
    levels, eval_level, out_level = _levels_within_budget(args, mesh, labels, hierarchies, methods, refine)
    args.levels = levels
    if eval_level < refine:
        raise CCProofError(f"--refine {refine} is above the metrics' level {eval_level} (the default "
                           "--eval-level); give --eval-level >= --refine")
    sample_level = _sample_level(args, out_level)

    def optimize(refine):
        return _optimize(args, mesh, labels, methods, engine, refine, eval_level, sample_level, hierarchies)

    results = optimize(refine)
    judged = _judge_folds(args, results, ours, out_level, refine, optimize,
                          lambda r: _fits(args, hierarchies, methods, eval_level, sample_level, r))
    if judged is None:
        return 1  # a negative verdict: folded UV triangles, nothing written
    results, refine = judged
    print(f"{args.mesh}: {mesh.n_vertices} vertices, {mesh.n_faces} faces, {len(results[ours].textures)} chart(s); "
          f"levels {args.start_level}..{args.levels}, refine {refine}, metrics at level {eval_level}, "
          f"baseline engine {engine}")
    _print_results(args, results, ours, eval_level)
    table = {
        m: {"E_angle": r.metrics.E_angle, "E_area": r.metrics.E_area, "E_stretch": r.metrics.E_stretch,
            "flips_control": r.flips_control, "flips_eval": r.metrics.flips, "seconds": r.seconds,
            "iterations": r.iterations}
        for m, r in results.items()
    }
    comment = f"ccproof arap {args.mesh}: {results[ours].name}, levels {args.start_level}..{args.levels}"
    if labels is None:  # without --charts or --segment the whole mesh is chart 0 (--labels-out)
        import numpy as np

        labels = np.zeros(mesh.n_faces, dtype=np.int64)
    with plan:  # all outputs or none
        _write_outputs(args, plan, results, ours, labels, out_level, eval_level, comment, table)
    sys.stdout.flush()
    return 0


def _read_input(args):
    """The control mesh (all quads: a mesh with other faces or semi-sharp tags subdivided, said on stderr) and
    its chart labels (--charts, --segment; None: one chart)."""
    from ccproof.apps.arap.charts import read_labels, segment_by_normals
    from ccproof.apps.control_file import children_labels, read_control_mesh
    from ccproof.cli._progress import phase, progress_enabled

    with phase(f"read {args.mesh}", progress_enabled(args)):
        mesh, origin = read_control_mesh(args.mesh)
    n_file = mesh.n_faces if origin is None else int(origin.max()) + 1
    if origin is not None:
        steps = getattr(mesh, "global_steps", 1)
        what = ("not all quads: subdivided once" if steps == 1 else
                f"semi-sharp Chaikin tags: subdivided {steps} times")
        print(f"{args.mesh}: {n_file} faces, {what} (Catmull-Clark) to {mesh.n_faces} quads, the same limit "
              f"surface", file=sys.stderr)
    if args.charts:
        return mesh, children_labels(read_labels(args.charts, n_file), origin)
    if args.segment == "normals":
        return mesh, segment_by_normals(mesh, max_angle=args.normal_angle)
    return mesh, None


def _methods(args):
    """(our method, the methods run, the baselines' ARAP engine) of --variant, --baselines and --engine."""
    from ccproof.apps.arap.core import VARIANTS

    ours = VARIANTS[args.variant]
    if not args.baselines:
        return ours, [ours], "numpy" if args.engine == "auto" else args.engine
    other = "b" if ours == "c" else "c"
    methods = sorted({"a", other, ours, "d"}, key="abcd".index)
    engine = args.engine
    if engine == "auto":
        try:
            import igl  # noqa: F401

            engine = "igl"
        except ImportError:
            engine = "numpy"
    return ours, methods, engine


def _print_results(args, results, ours, eval_level):
    """The table of the methods, a warning for flipped samples, and our method's levels."""
    nch = len(results[ours].textures)
    print(format_table(results, eval_level))
    flips = results[ours].metrics.flips
    if flips:
        print(f"ccproof arap: warning: {results[ours].name}: {flips} flipped samples at level {eval_level} (the "
              f"texture folds there; E_stretch {results[ours].metrics.E_stretch:.3g}); {_finer(args, nch)}",
              file=sys.stderr)
    lv = results[ours].levels
    for k in range(len(lv[0]) if lv and lv[0] else 0):
        its = sum(c[k].iterations for c in lv)
        spi = sum(c[k].seconds for c in lv) / max(its, 1)
        e0 = sum(c[k].energy_start for c in lv)
        e1 = sum(c[k].energy_end for c in lv)
        print(f"  {results[ours].name}: level {lv[0][k].level}: {its} iterations, "
              f"{1e3 * spi:.2f} ms per chart iteration, energy {e0:.6g} -> {e1:.6g}, "
              f"converged: {all(c[k].converged for c in lv)}")


#: the finest --refine the default tries against folded --out triangles
MAX_FOLD_REFINE = 4


def _optimize(args, mesh, labels, methods, engine, refine, eval_level, sample_level, hierarchies):
    """The methods' results at ``refine`` (compare, with the memory errors named)."""
    from ccproof.apps.arap.core import Solver
    from ccproof.apps.arap.meshes import LevelPlan, MemoryBudgetError, compare
    from ccproof.cli._progress import progress_enabled
    from ccproof.errors import CCProofError

    try:
        plan = LevelPlan(args.levels, args.start_level, eval_level, refine, sample_level)
        solver = Solver(tol=args.tol, max_iter=args.max_iter, accel=args.accel, engine=engine)
        results, _ = compare(mesh, labels, methods, plan, solver, release=True, hierarchies=hierarchies,
                             max_memory=args.max_memory * 1e9, progress=progress_enabled(args))
    except MemoryBudgetError:
        raise
    except MemoryError as exc:
        raise CCProofError(f"out of memory ({exc}); lower --eval-level, --levels or --out-level (each level "
                           f"less needs 4x less memory) or lower --max-memory so that the estimate refuses "
                           f"earlier") from None
    return results


def _fits(args, hierarchies, methods, eval_level, sample_level, refine):
    """Whether ``refine`` keeps the estimated peak memory within --max-memory (and the metrics level above it)."""
    from ccproof.apps.arap.meshes import run_memory

    if refine > eval_level:
        return False
    need = run_memory(hierarchies, methods, args.levels, eval_level, sample_level, refine, release=True)[0]
    return need <= args.max_memory * 1e9


def _out_folds(args, result, out_level):
    """(folded, total) triangles of the --out surface to be written; (0, 0) without --out."""
    from ccproof.apps.arap.export import sampled_surface

    if not args.out:
        return 0, 0
    surf = sampled_surface(result, out_level, args.cells)
    return surf.folds(), surf.triangles().shape[0]


def _judge_folds(args, results, ours, out_level, refine, optimize, fits):
    """Judge the --out UVs before writing: (results, refine) to write, or None after a one-line refusal.

    With the default --refine and --out-level a folding output is optimized again on a finer control mesh
    (refine + 1, ... up to MAX_FOLD_REFINE, within --max-memory) until no written triangle folds, and stderr says
    what was chosen; with an explicit --refine or --out-level, or when no refinement within the budget unfolds it,
    the run refuses (exit 1) naming the count and the options, unless --allow-folds (then a warning at the write).
    """
    folded, total = _out_folds(args, results[ours], out_level)
    if not folded or args.allow_folds:
        return results, refine
    first, first_refine = folded, refine
    if args.refine == "auto" and args.out_level is None:
        while folded and refine < MAX_FOLD_REFINE and fits(refine + 1):
            refine += 1
            results = optimize(refine)
            folded, total = _out_folds(args, results[ours], out_level)
            if not folded:
                print(f"ccproof arap: --out {args.out}: {first} of {total} triangles folded in UV at refine "
                      f"{first_refine}; chosen refine {refine} (none folds)", file=sys.stderr)
                return results, refine
    if args.refine != "auto" or args.out_level is not None:
        given = f"--refine {args.refine}" if args.refine != "auto" else f"--out-level {args.out_level}"
        fix = "a higher --refine (or the defaults, which refine until none folds)"
    else:
        given = f"refine {refine} (the finest within --max-memory, --eval-level and {MAX_FOLD_REFINE})"
        fix = "more charts (--segment normals --normal-angle DEG, --charts), more --max-memory"
    print(f"ccproof arap: refused: --out {args.out}: {folded} of {total} triangles are folded in UV at {given}, "
          f"output level {out_level}; nothing written; give {fix}, or --allow-folds to write them anyway",
          file=sys.stderr)
    return None


def _finer(args, n_charts):
    """What to try against folds: charts when there is a single one, and a finer control mesh for the optimization."""
    one = ("a single chart, which folds: segment the mesh into charts (--segment normals [--normal-angle DEG], or "
           "--charts LABELS); or " if n_charts == 1 else "")
    if args.refine == "auto":
        return one + "give --refine 1 or 2 (a finer control mesh for the optimization)"
    return (one + f"--refine {args.refine} was given: raise it, or leave it to the default (auto: >= 1000 control "
            f"faces per chart)")


def _check_options(args):
    """The options among themselves, before any work; returns --refine as an int (None: auto)."""
    from ccproof.errors import CCProofError

    refine = None
    if args.refine != "auto":
        try:
            refine = int(args.refine)
        except ValueError:
            refine = -1
        if refine < 0:
            raise CCProofError(f"--refine must be auto or an integer >= 0, got {args.refine!r}")
    for name in ("start_level", "levels", "eval_level", "out_level", "control_extra", "accel", "max_iter"):
        value = getattr(args, name)
        if value is not None and value < 0:
            raise CCProofError(f"--{name.replace('_', '-')} must be >= 0, got {value}")
    if args.control_max_faces < 1:
        raise CCProofError(f"--control-max-faces must be >= 1, got {args.control_max_faces}")
    if not (args.max_memory > 0 and args.max_memory < float("inf")):  # NaN too
        raise CCProofError(f"--max-memory must be a positive number of GB, got {args.max_memory}")
    if not (args.tol >= 0 and args.tol < float("inf")):
        raise CCProofError(f"--tol must be a finite number >= 0, got {args.tol}")
    if args.normal_angle is not None and (args.segment != "normals" or args.charts):
        raise CCProofError("--normal-angle is a setting of --segment normals (without --charts)")
    if args.normal_angle is not None and not 0 < args.normal_angle <= 180:
        raise CCProofError(f"--normal-angle must be in (0, 180] degrees, got {args.normal_angle}")
    if args.levels is not None and args.levels < args.start_level:
        raise CCProofError(f"--levels {args.levels} is below --start-level {args.start_level}")
    if args.eval_level is not None and refine is not None and args.eval_level < refine:
        raise CCProofError(f"--eval-level {args.eval_level} is below --refine {refine} (the metrics are sampled "
                           "on the refined mesh)")
    return refine


def _output_plan(args):
    """Every file ``arap`` writes (sidecars ``.json`` too), checked together before any work."""
    from ccproof.cli._output import PLOT_SUFFIXES, OutputPlan, meshio_suffixes

    plan = OutputPlan()
    plan.add_input("MESH", args.mesh)
    plan.add_input("--charts", args.charts)
    if args.out:
        plan.add("--out", args.out, (".obj", *meshio_suffixes()))
        plan.add("--out (its metrics sidecar)", args.out + ".json")
    if args.control_out:
        plan.add("--control-out", args.control_out, (".obj",))
        plan.add("--control-out (its sidecar)", args.control_out + ".json")
    if args.labels_out:
        plan.add("--labels-out", args.labels_out)
    if args.preview:
        plan.add("--preview", args.preview, PLOT_SUFFIXES)
    plan.check()
    return plan


def _write_outputs(args, plan, results, ours, labels, out_level, eval_level, comment, table):
    """Write every requested output through ``plan`` (renamed onto their names only when all are written)."""
    from ccproof.apps.arap.charts import write_labels
    from ccproof.apps.arap.export import sampled_surface, write_surface
    from ccproof.apps.arap.io import write_uv_obj

    if args.labels_out:
        with plan.write(args.labels_out) as tmp:
            write_labels(tmp, labels)
    surf = None
    if args.out or args.control_out:
        surf = sampled_surface(results[ours], out_level, args.cells)
    if args.preview:
        from ccproof.apps.arap.preview import render_preview

        surfs = {m: sampled_surface(r, r.sample_level) for m, r in results.items()}
        with plan.write(args.preview) as tmp:
            render_preview(tmp, surfs, {m: r.name for m, r in results.items()}, title=args.mesh)
        print(f"wrote {args.preview}")
    if args.out:
        with plan.write(args.out) as tmp:
            write_surface(tmp, surf, comment)
        wm = surf.metrics()
        info = {"method": ours, "level": surf.level, "cells": surf.cell_type, "uv_scale": surf.scale,
                "folds": surf.folds(), "seams": "vertices duplicated per chart",
                "written_triangles": {"E_angle": wm.E_angle, "E_area": wm.E_area, "E_stretch": wm.E_stretch,
                                      "note": "E_area at the natural UV scale: divide the file's UVs by uv_scale"},
                "table": table}
        plan.write_text(args.out + ".json", json.dumps(info, indent=1))
        print(f"wrote {args.out} (level {surf.level}: {surf.points.shape[0]} vertices, {surf.cells.shape[0]} "
              f"{surf.cell_type}s, {surf.folds()} folded; written triangles E_angle {wm.E_angle:.6f} "
              f"E_area {wm.E_area:.6f} E_stretch {wm.E_stretch:.6f}) and {args.out}.json")
        if surf.folds():
            hint = _finer(args, len(results[ours].textures))
            print(f"ccproof arap: warning: --out {args.out}: {surf.folds()} of {surf.cells.shape[0]} {surf.cell_type}s "
                  f"are folded in UV (E_stretch {wm.E_stretch:.3g}), written as --allow-folds asks; {hint}",
                  file=sys.stderr)
    if args.control_out:
        _write_control(args, plan, results[ours], surf, eval_level, comment, table, write_uv_obj)


def _write_control(args, plan, r, surf, eval_level, comment, table, write_uv_obj):
    """--control-out: control UVs for the face-varying 'corners only' rule, and what a tool will see."""
    from dataclasses import replace

    from ccproof.apps.arap.fvar import FOLD_LEVELS, ControlOptions, export_control
    from ccproof.cli._progress import progress_enabled

    options = ControlOptions(max_extra=args.control_extra, max_faces=args.control_max_faces, accel=args.accel)
    exp = export_control(r, eval_level, args.levels, options, progress=progress_enabled(args))
    times = r.refine + exp.extra
    note = f"\ncontrol mesh: the input subdivided {times} times (Catmull-Clark)" if times else ""
    note += ("\ncontrol UVs: least-squares fit of the exact texture's limit UVs under the rule below, polished by "
             "hsh10's optimization under that rule")
    if exp.arap_metrics is not None:
        k = sum(w is not None for w in exp.chart_weights)
        note += (f"; in {k} of {len(exp.chart_weights)} charts then minimizing the measured distortion (weights "
                 "chosen per chart for the smallest largest excess ratio)")
    er = exp.excess_ratio()
    what = {"refine": r.refine, "extra_subdivisions": exp.extra, "fold_levels": list(FOLD_LEVELS),
            "folds": exp.folds, "metric_level": exp.level, "E_angle": exp.metrics.E_angle, "E_area": exp.metrics.E_area,
            "E_stretch": exp.metrics.E_stretch, "excess_ratio_to_exact": list(er), "accepted": exp.accepted,
            "tried": [{"extra": e, "folds": f, "E_angle": m.E_angle, "E_area": m.E_area, "E_stretch": m.E_stretch}
                      for e, f, m in exp.tried]}
    if exp.arap_metrics is not None:
        a = exp.arap_metrics
        what["minimax"] = {"chart_weights": [None if w is None else list(w) for w in exp.chart_weights],
                           "arap_polish_alone": {"E_angle": a.E_angle, "E_area": a.E_area, "E_stretch": a.E_stretch}}
    side = args.control_out + ".json"
    with plan.write(args.control_out) as tmp:
        plan.adopt(write_uv_obj(tmp, exp.mesh, replace(r, textures=exp.textures), comment=comment + note,
                                table=dict(table, control_out=what), transforms=surf.transforms, scale=surf.scale),
                   side)
    tags = ""
    if getattr(exp.mesh, "has_tags", False):
        m = exp.mesh
        tags = (f", tags as OpenSubdiv 't' lines: {int((m.edge_sharpness > 0).sum())} sharp edges, "
                f"{int((m.vertex_sharpness > 0).sum())} sharp vertices, {int(m.hole.sum())} holes")
    print(f"wrote {args.control_out} and {side}: control mesh = the input subdivided {times} times "
          f"({exp.mesh.n_faces} faces{tags}), UVs for OpenSubdiv's face-varying 'corners only' rule")
    print(f"  what a subdivision tool will see: folded UV quads at levels {', '.join(map(str, FOLD_LEVELS))}: "
          f"{', '.join(map(str, exp.folds))}; limit texture at level {exp.level}: E_angle {exp.metrics.E_angle:.6f} "
          f"E_area {exp.metrics.E_area:.6f} E_stretch {exp.metrics.E_stretch:.6f} (excess {er[0]:.3f}, {er[1]:.3f}, "
          f"{er[2]:.3f} x the exact texture's)")
    if not exp.accepted:
        last = len(exp.tried) - 1
        nxt = r.textures[0].hierarchy.surface.n_faces * 4 ** (last + 1)
        why = (f" (the next, {last + 1} extra, needs {nxt} faces > --control-max-faces {args.control_max_faces})"
               if last < args.control_extra and nxt > args.control_max_faces else "")
        print(f"ccproof arap: warning: --control-out: no subdivision of 0..{last} extra gave UVs without folds and "
              f"within 5 % of the exact texture's distortion excess{why}; wrote the best ({exp.extra} extra, "
              f"{sum(exp.folds)} folded quads); raise --control-extra / --control-max-faces, or use the sampled "
              f"surface (--out), which has the exact UVs", file=sys.stderr)
