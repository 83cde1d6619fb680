"""Project 3-D points onto the Catmull-Clark limit surface of a mesh (globally nearest limit points).

For every point of POINTS (``.xyz``, ``.ply``, ``.obj`` vertices, or ``.csv`` with the header ``x,y,z``; the
same formats as ``ccproof fit``) the nearest point of the limit surface: its
parameter (face, u, v) (ptex face; corner i of the face at (0,0), (1,0), (1,1), (0,1)), the point
P, the distance |X - P| and the unit normal there. The search is global (bounding cylinders over
sampled cells, a bounding-volume hierarchy, best-first projected Newton descents), see
docs/closest.md. The output .npz holds the arrays face (n,), u (n,), v (n,), P (n, 3),
distance (n,), normal (n, 3) in the order of the points; with --certify (untagged all-quad meshes
only) also verdict (n,) of
strings ('certified', 'ambiguous', 'uncertified'), distance_lo, distance_hi (n,) (a rigorous
enclosure of the distance where certified) and parameter_radius (n,) (the nearest parameter
lies within this max-norm radius of (u, v) in the same face, where certified).

Limits (checked before any work): input files at most --max-input GB (default 2); the search structure,
about 250 bytes per ptex face plus a cell cache of at most 67 MB and 52 MB of samples evaluated at once
(more only if one face's (2 --cells + 1)^2 samples exceed that), at most --max-memory GB (default 2; the
evaluator's table is not counted); --out may not replace an input.

Example:
  ccproof project bunny.obj points.csv --out nearest.npz
"""

from __future__ import annotations


def add_arguments(parser):
    parser.add_argument("mesh", help="mesh file: OBJ (with OpenSubdiv tags), OFF, PLY, STL, VTK, ... (any mesh "
                        "'ccproof eval' reads)")
    parser.add_argument("points", help="point cloud: .xyz (x y z per line), .ply (vertex x, y, z), .obj (v lines), "
                        ".csv (header x,y,z), or the vertices of any mesh file")
    parser.add_argument("--out", metavar="FILE.npz", required=True, help="output file (numpy .npz)")
    parser.add_argument("--certify", action="store_true",
                        help="add interval-arithmetic verdicts (slow: per point; untagged all-quad meshes only)")
    parser.add_argument("--cells", type=int, default=None,
                        help="cells per face side of the search structure (default 8): the cells of a face "
                             "are computed when a query reaches it, from (2 cells + 1)^2 samples; the structure "
                             "keeps one bound per face")
    parser.add_argument("--max-memory", type=float, default=2.0, metavar="GB",
                        help="refuse a search structure whose estimated memory exceeds this (default 2 GB; "
                             "about 250 bytes per ptex face plus 0.12 GB)")
    from ccproof.cli._progress import add_progress_argument

    add_progress_argument(parser)


def check_search_memory(n_faces, cells, max_memory_gb):
    """Refuse, before any work, a search structure above ``--max-memory`` (the figure and the options named).

    >>> check_search_memory(2036, 100000, 2.0)
    Traceback (most recent call last):
    ...
    ccproof.errors.CCProofError: --cells 100000: the search structure of 2036 faces needs about 1.66e+04 GB, ...
    >>> check_search_memory(2_600_000, 8, 0.5)  # a 871k-triangle scan
    Traceback (most recent call last):
    ...
    ccproof.errors.CCProofError: --cells 8: the search structure of 2600000 faces needs about 0.77 GB, ...
    """
    from ccproof.errors import CCProofError
    from ccproof.evaluate.closest import BATCH_SAMPLES, CACHE_CELLS, search_memory

    if not (max_memory_gb > 0 and max_memory_gb < float("inf")):
        raise CCProofError(f"--max-memory must be a positive number of GB, got {max_memory_gb}")
    need = search_memory(n_faces, cells) / 1e9
    # --cells counts only where one face's samples or cells exceed what is evaluated or cached at once
    big = (2 * cells + 1) ** 2 > BATCH_SAMPLES or cells * cells > CACHE_CELLS
    fix = "lower --cells or raise --max-memory" if big else "raise --max-memory"
    if need > max_memory_gb:
        raise CCProofError(f"--cells {cells}: the search structure of {n_faces} faces needs about {need:.3g} GB, "
                           f"above --max-memory {max_memory_gb:g} GB; {fix}")


#: points per progress step of the float search (the certified mode steps point by point)
BATCH = 1000


def run(args):
    import time
    from pathlib import Path

    from ccproof.cli._output import OutputPlan, atomic

    plan = OutputPlan()  # before any work (even the imports)
    plan.add_input("MESH", args.mesh)
    plan.add_input("POINTS", args.points)
    out_path = plan.add("--out", args.out, (".npz",))
    plan.check()
    import numpy as np

    from ccproof.cli._progress import phase, progress_enabled
    from ccproof.errors import CCProofError
    from ccproof.evaluate.closest import CELLS, ClosestPointFinder
    from ccproof.evaluate.closest import check_query_points as check_points
    from ccproof.evaluate.surface import limit_surface
    from ccproof.mesh.points import read_points

    progress = progress_enabled(args)
    with phase(f"read {Path(args.points).name}", progress):
        X = read_points(args.points)  # file and line named for a bad or non-finite point
    try:  # huge coordinates: refused before the search structure is built
        check_points(X)
    except CCProofError as exc:
        raise CCProofError(f"{args.points}: {exc} (points counted from 0 in file order)") from None
    if args.cells is not None and args.cells < 1:
        raise CCProofError(f"--cells must be >= 1, got {args.cells}")
    if not (args.max_memory > 0 and args.max_memory < float("inf")):
        raise CCProofError(f"--max-memory must be a positive number of GB, got {args.max_memory}")
    from ccproof.cli._eval_args import evaluable_ptex_faces
    from ccproof.mesh.io import read_mesh

    t_read = time.perf_counter()
    with phase(f"read {Path(args.mesh).name}", progress):
        poly = read_mesh(args.mesh)
    t_read = time.perf_counter() - t_read
    if args.certify and not poly.is_plain_quads:  # before the search: certify_closest needs a QuadMesh
        raise CCProofError(f"{args.mesh}: --certify needs an untagged manifold all-quad mesh (this one has "
                           "non-quad faces, OpenSubdiv tags or non-manifold edges or vertices); drop --certify")
    evaluable = evaluable_ptex_faces(poly)  # holes (tagged, or boundary mode none) have no surface
    if evaluable is not None and evaluable.size == 0:
        raise CCProofError(f"{args.mesh}: every face is a hole: there is no limit surface to project onto")
    n_search = poly.n_ptex if evaluable is None else evaluable.size
    check_search_memory(n_search, CELLS if args.cells is None else args.cells, args.max_memory)  # before the setup
    t_setup = time.perf_counter()
    S = limit_surface(poly.to_quad_mesh() if poly.is_plain_quads else poly, progress=progress)  # a bar if long
    t_setup = time.perf_counter() - t_setup
    from ccproof.cli._notice import compile_notice

    compile_notice("project")  # after the input checks: an error stays one line
    t_build = time.perf_counter()
    finder = ClosestPointFinder(S, cells=CELLS if args.cells is None else args.cells, faces=evaluable,
                                progress=progress)  # a bar over the faces
    t0 = time.perf_counter()
    t_build = t0 - t_build
    starts = range(0, X.shape[0], BATCH)
    if progress and len(starts) > 1:
        from tqdm import tqdm

        starts = tqdm(starts, desc="project", unit="batch")
    from ccproof.evaluate.closest_cells import morton_order

    order = morton_order(X)  # nearby points in the same batch: the finder refines fewer faces
    parts = [finder.query(X[order[a:a + BATCH]]) for a in starts] or [finder.query(X)]  # (no points: empty arrays)
    out = {}
    for k in ("face", "u", "v", "P", "distance", "normal"):
        out[k] = np.empty_like(np.concatenate([getattr(r, k) for r in parts]))
        out[k][order] = np.concatenate([getattr(r, k) for r in parts])
    msg = (f"{args.mesh}: read in {t_read:.2f} s, setup {t_setup:.2f} s, search structure {t_build:.2f} s; "
           f"{X.shape[0]} points projected in {time.perf_counter() - t0:.2f} s")
    if args.certify:
        t1 = time.perf_counter()
        counts = _certify(S, X, out, progress)
        msg += f"; certified mode {time.perf_counter() - t1:.2f} s: {counts}"
    with atomic(out_path) as tmp:
        np.savez(tmp, **out)
    print(f"{msg}; wrote {args.out}")
    return 0


def _certify(S, X, out, progress):
    """Add the interval verdicts of --certify to ``out`` (verdict, distance_lo, distance_hi, parameter_radius);
    returns the count of each verdict."""
    import numpy as np

    from ccproof.evaluate.closest_certified import certify_closest

    points = range(X.shape[0])
    if progress:
        from tqdm import tqdm

        points = tqdm(points, desc="certify", unit="point")
    cert = [certify_closest(S, X[i], out["face"][i], out["u"][i], out["v"][i]) for i in points]
    out["verdict"] = np.array([c.verdict for c in cert])
    out["distance_lo"] = np.array([c.distance_lo for c in cert])
    out["distance_hi"] = np.array([c.distance_hi for c in cert])
    out["parameter_radius"] = np.array([c.parameter_radius for c in cert])
    return {k: int((out["verdict"] == k).sum()) for k in ("certified", "ambiguous", "uncertified")}
