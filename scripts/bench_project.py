"""Benchmark of closest points on the bunny's limit surface (ccproof.evaluate.closest).

Random points uniform in the bounding box of the limit surface enlarged by 5 % on each side.
Ours: ClosestPointFinder (sampled cell cylinders, BVH, best-first projected Newton). Baseline: scipy
cKDTree over a dense limit sampling ((2^L + 1)^2 samples per face), the nearest sample refined by the
same projected Newton (to the same accuracy; not global: it keeps the nearest sample's face).
Prints rates (points per second, preparation excluded and included), the ratio, the agreement of
the distances, and the certified mode's cost per point on a few points.

    python scripts/bench_project.py [--n 1000000] [--level 5] [--certify 5] [--baseline-n 100000] [--rounds 3]
    python scripts/bench_project.py --smoke          the torus, 200 points (the test suite's run)

With ``--memory`` it measures instead the search structure at scan size: noisy icosphere scans of
scripts/bench_memory.py (level L: 20 4^L triangles, 3 ptex faces each) and ``--points`` points in a
shell around them. Per level and per source tree (this one; with ``--old DIR`` also the package in DIR,
e.g. the previous commit: ``git archive HEAD~1 | tar -x -C DIR`` plus the compiled kernel copied in),
each in a fresh process: the bytes per ptex face the structure keeps after its build and the peak of
its build (tracemalloc: numpy arrays, not scipy's k-d tree nodes), the process's peak RSS through the
queries (1,000 points per call, as ``ccproof project``), the query time per point (the trees in turn,
round by round; the ratio per round), and the peak RSS of ``ccproof project`` itself (a fresh process)::

    python scripts/bench_project.py --memory --levels 3 4 5 6 --points 10000 --old /tmp/ccproof-old
"""

import argparse
import sys
import time
from pathlib import Path

import numpy as np
from scipy.spatial import cKDTree

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _bench import load, ratio_line  # noqa: E402

from ccproof.evaluate import limit_surface  # noqa: E402
from ccproof.evaluate.closest import ClosestPointFinder  # noqa: E402
from ccproof.evaluate.closest_cells import morton_order  # noqa: E402
from ccproof.evaluate.closest_certified import certify_closest  # noqa: E402
from ccproof.evaluate.newton import newton_descent  # noqa: E402
from ccproof.mesh.examples import torus  # noqa: E402

BUNNY = Path(__file__).resolve().parents[1] / "tests" / "data" / "meshes" / "bunny_quads.obj"
REPO = Path(__file__).resolve().parents[1]

#: the child process of --memory: mesh, points, then one JSON line
_JOB = r"""
import json, resource, sys, time, tracemalloc
import numpy as np
import ccproof
assert not sys.argv[3] or ccproof.__file__.startswith(sys.argv[3]), (ccproof.__file__, sys.argv[3])
from ccproof.evaluate import limit_surface
from ccproof.evaluate.closest import ClosestPointFinder, parameter_faces
S = limit_surface(sys.argv[1], progress=False)
X = np.loadtxt(sys.argv[2], delimiter=",", skiprows=1)
ClosestPointFinder(S, cells=1).query(X[:3])  # compiled kernels loaded, the table's lazy parts built
rss_table = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
nf = parameter_faces(S)
tracemalloc.start()
t0 = time.perf_counter()
F = ClosestPointFinder(S)
t_build = time.perf_counter() - t0
kept, peak = tracemalloc.get_traced_memory()
tracemalloc.stop()
F.query(X[:10])
t0 = time.perf_counter()
d = np.concatenate([F.query(X[a:a + 1000]).distance for a in range(0, X.shape[0], 1000)])
np.save(sys.argv[4], d)
t_query = time.perf_counter() - t0
print(json.dumps(dict(faces=nf, kept=kept / nf, peak=peak / nf, build=t_build, query=t_query / X.shape[0],
                      rss_table=rss_table, rss=resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024,
                      )))
"""


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("--n", type=int, default=1_000_000)
    ap.add_argument("--level", type=int, default=5, help="baseline sampling: 2^level intervals per face side")
    ap.add_argument("--certify", type=int, default=5, help="points for the certified mode")
    ap.add_argument("--baseline-n", type=int, default=100_000,
                    help="the baseline runs on the first N points only (its rate is per point)")
    ap.add_argument("--rounds", type=int, default=3, help="interleaved rounds of ours and the baseline")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--memory", action="store_true", help="the search structure's memory at scan size (see above)")
    ap.add_argument("--levels", type=int, nargs="+", default=[3, 4, 5], help="--memory: icosphere levels")
    ap.add_argument("--points", type=int, default=10_000, help="--memory: points per mesh")
    ap.add_argument("--old", metavar="DIR", help="--memory: a source tree of the package to compare with")
    ap.add_argument("--cli", action="store_true", help="--memory: also the peak RSS of `ccproof project`")
    ap.add_argument("--smoke", action="store_true",
                    help="the torus of ccproof.mesh.examples, 200 points, 2 rounds (the test suite's run)")
    a = ap.parse_args(argv)
    if a.memory:
        return memory(a)
    if a.smoke:
        a.n, a.level, a.certify, a.baseline_n, a.rounds = 200, 2, 0, 200, 2
    S = limit_surface(torus() if a.smoke else BUNNY)
    t0 = time.perf_counter()
    F = ClosestPointFinder(S)
    t_prep = time.perf_counter() - t0
    L = 2**a.level
    t0 = time.perf_counter()
    nf = S.mesh.n_faces
    t = np.arange(L + 1) / L
    U, V = np.meshgrid(t, t, indexing="ij")
    fu = np.repeat(np.arange(nf), (L + 1) ** 2)
    uu, vv = np.tile(U.ravel(), nf), np.tile(V.ravel(), nf)
    samples = S.evaluate(fu, uu, vv, 0)["P"]
    T = cKDTree(samples)
    t_bprep = time.perf_counter() - t0
    lo, hi = samples.min(0), samples.max(0)  # the bounding box of the limit surface (sampled)
    ext = hi - lo
    X = lo - 0.05 * ext + np.random.default_rng(a.seed).random((a.n, 3)) * 1.1 * ext
    nb = min(a.n, a.baseline_n)
    F.query(X[:10])  # warm-up (compiled kernels)
    ours, base, loads = [], [], []
    for r in range(a.rounds):  # ours and the baseline in turn, round by round, per point
        loads.append(load())
        for who in ("ours", "base") if r % 2 == 0 else ("base", "ours"):
            t0 = time.perf_counter()
            if who == "ours":
                res = F.query(X)
                ours.append((time.perf_counter() - t0) / a.n)
            else:
                _, j = T.query(X[:nb], k=1)
                bu, bv, bE = newton_descent(S, X[:nb], fu[j], uu[j], vv[j])
                base.append((time.perf_counter() - t0) / nb)
    t_ours, t_base = min(ours) * a.n, min(base) * a.n  # for all n points at the measured rate
    print(f"ours: preparation {t_prep:.2f} s, {a.n} points in {t_ours:.2f} s: {a.n / t_ours:,.0f} points/s "
          f"({a.n / (t_ours + t_prep):,.0f} with preparation); descents per point {res.descents.mean():.2f}")
    db = np.sqrt(2 * bE)
    print(f"baseline (cKDTree over {fu.size:,} samples + Newton, measured on {nb} points): preparation "
          f"{t_bprep:.2f} s, {a.n / t_base:,.0f} points/s ({a.n / (t_base + t_bprep):,.0f} with preparation)")
    print(f"ratio ours / baseline: {t_base / t_ours:.2f} (queries, best rounds), "
          f"{(t_base + t_bprep) / (t_ours + t_prep):.2f} (with preparation)")
    print(ratio_line("time per point ours/baseline:", [x / y for x, y in zip(ours, base)], loads))
    res_d = res.distance[:nb]
    rel = (db - res_d) / res_d
    diag = float(np.linalg.norm(ext))
    worse = np.flatnonzero(rel < -1e-12)
    real = worse[(res_d[worse] - db[worse]) > 1e-15 * diag]
    print(f"baseline farther than ours (relative > 1e-12) at {(rel > 1e-12).sum()} points (max {rel.max():.3g}); "
          f"ours farther than baseline at {worse.size} points (max relative {-rel.min():.3g}), of which "
          f"{real.size} by more than 1e-15 of the diagonal (the rest: round-off at distances "
          f"<= {res_d[worse].max() / diag if worse.size else 0:.2g} of the diagonal)")
    if a.certify:
        verdicts = {}
        t0 = time.perf_counter()
        for i in range(a.certify):
            c = certify_closest(S, X[i], res.face[i], res.u[i], res.v[i])
            verdicts[c.verdict] = verdicts.get(c.verdict, 0) + 1
        dt = (time.perf_counter() - t0) / a.certify
        print(f"certified mode: {dt:.2f} s per point; verdicts {verdicts}")


def _child(tree, code, *args, cwd):
    """Run ``python -c code args`` in ``cwd`` (not a source tree) with the package of ``tree`` first on the
    path; its stdout."""
    import os
    import subprocess

    env = dict(os.environ, PYTHONPATH=str(tree))
    r = subprocess.run([sys.executable, "-c", code, *map(str, args)], env=env, capture_output=True, text=True,
                       cwd=cwd)
    if r.returncode != 0:
        raise SystemExit(f"{tree}: the job failed:\n{r.stderr[-3000:]}")
    return r.stdout


_CLI = ("import resource, subprocess, sys; subprocess.run([sys.executable, '-m', 'ccproof.cli', 'project', "
        "*sys.argv[1:]], check=True, capture_output=True); "
        "print(resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss * 1024)")


def memory(a):
    """--memory: per level, the structure's bytes per ptex face and peak RSS, this tree against --old."""
    import json
    import tempfile

    from bench_memory import icosphere, write_obj

    trees = {"new": REPO} if a.old is None else {"new": REPO, "old": Path(a.old)}
    rng = np.random.default_rng(a.seed)
    X = rng.standard_normal((a.points, 3))
    X *= (1 + 0.1 * rng.standard_normal((a.points, 1))) / np.linalg.norm(X, axis=1)[:, None]
    X = X[morton_order(X)]  # as `ccproof project` orders them (both trees get the same order)
    with tempfile.TemporaryDirectory() as tmp:
        pts = Path(tmp) / "points.csv"
        np.savetxt(pts, X, delimiter=",", header="x,y,z", comments="")
        for L in a.levels:
            mesh = Path(tmp) / f"icosphere{L}.obj"
            write_obj(mesh, *icosphere(L))
            rows, ratios, loads = {k: [] for k in trees}, [], []
            for r in range(a.rounds):  # the trees in turn, the order alternating
                loads.append(load())
                for k in (list(trees) if r % 2 == 0 else list(trees)[::-1]):
                    job = _child(trees[k], _JOB, mesh, pts, trees[k], Path(tmp) / f"{k}.npy", cwd=tmp)
                    rows[k].append(json.loads(job.strip().splitlines()[-1]))
                if "old" in trees:
                    ratios.append(rows["new"][-1]["query"] / rows["old"][-1]["query"])
            for k, rr in rows.items():
                x = rr[0]
                cli = ""
                if a.cli:
                    out = Path(tmp) / "out.npz"
                    rss = int(_child(trees[k], _CLI, mesh, pts, "--out", out, "--max-memory", 1000, "--no-progress",
                                     cwd=tmp))
                    cli = f"; `ccproof project` peak RSS {rss / 1e9:.3f} GB"
                print(f"level {L} ({20 * 4 ** L} triangles, {x['faces']} ptex faces) {k}: structure kept "
                      f"{x['kept']:,.0f} B/face, build peak {x['peak']:,.0f} B/face, build {x['build']:.2f} s; "
                      f"peak RSS {x['rss'] / 1e9:.3f} GB (table {x['rss_table'] / 1e9:.3f} GB); query "
                      f"{min(y['query'] for y in rr) * 1e3:.3f} ms/point{cli}", flush=True)
            if ratios:
                dn, do = np.load(Path(tmp) / "new.npy"), np.load(Path(tmp) / "old.npy")
                print(ratio_line(f"level {L} query time per point new/old:", ratios, loads)
                      + f" (machine shared with other jobs); distances new - old: max {(dn - do).max():.2e}, "
                      f"min {(dn - do).min():.2e}, identical at {np.mean(dn == do):.1%} of the points", flush=True)
    return 0


if __name__ == "__main__":
    main()
