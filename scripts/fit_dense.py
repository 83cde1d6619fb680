"""`fit` on dense clouds sampled off a known surface, judged against that TRUE surface (not the data).

  python scripts/fit_dense.py                          10^4, 3 x 10^4, 10^5 points, exact and with 0.2 % noise,
                                                      levels 1 and 2 (minutes per 10^5 run)
  python scripts/fit_dense.py --n 10000 --levels 1     one size, one level
  python scripts/fit_dense.py --smoke                  a tiny run (what the default test suite executes)

The true surface is the Catmull-Clark limit surface of tests/data/meshes/bunny_quads.obj. Points are drawn
uniformly by area on it (a cell of a 16 x 16 split of a face chosen by its area, (u, v) in it by rejection on
|s_u x s_v|; every point is an exact limit point of ccproof's evaluator), optionally moved by isotropic Gaussian
noise of ``--noise`` % of the diameter. Each cloud is fitted with :func:`ccproof.apps.dynamics.fit.fit_points` at its
defaults, and the fitted limit surface (exact limit points at the centres of 6 x 6
cells of every face, weighted by their area) is compared with the true limit surface by the global closest points
of :mod:`ccproof.evaluate.closest`: the area fraction farther than 1 % and 2 % of the diameter (of the data's
enclosing sphere), the largest distance, and the true faces nearest to the far part (where the webs are). Also
printed: the fit's own figures (data -> surface max/mean, its stray fraction and warnings), time and peak memory
(tracemalloc; the machine may be loaded by other jobs).
"""

from __future__ import annotations

import argparse
import time
import tracemalloc
from pathlib import Path

import numpy as np

BUNNY = Path(__file__).resolve().parents[1] / "tests" / "data" / "meshes" / "bunny_quads.obj"


def true_surface(path=BUNNY):
    """The limit surface of the bunny control mesh and a closest-point search on it."""
    from ccproof.evaluate import LimitSurface
    from ccproof.evaluate.closest import ClosestPointFinder
    from ccproof.mesh import read_obj

    mesh = read_obj(path)
    S = LimitSurface(mesh)
    return mesh, S, ClosestPointFinder(S)


def _jacobians(S, f, u, v):
    r = S.evaluate(f, u, v, derivatives=1)
    return r["P"], np.linalg.norm(np.cross(r["Pu"], r["Pv"]), axis=1)


def sample_by_area(S, n_faces, n, seed=0, grid=16):
    """``n`` points distributed uniformly by area on the limit surface ``S`` (exact limit points): a cell of a
    ``grid`` x ``grid`` split of a face chosen by its area (|s_u x s_v| at its centre), (u, v) in it by rejection on
    |s_u x s_v| against twice the centre's value (capped there: near an extraordinary corner the density may
    exceed it, a small bias that is reported)."""
    rng = np.random.default_rng(seed)
    g = (np.arange(grid) + 0.5) / grid
    uu, vv = (a.ravel() for a in np.meshgrid(g, g, indexing="ij"))
    c = grid * grid
    f = np.repeat(np.arange(n_faces), c)
    cu, cv = np.tile(uu, n_faces), np.tile(vv, n_faces)
    _, J = _jacobians(S, f, cu, cv)
    p = J / J.sum()
    out, got, capped = [], 0, 0
    while got < n:
        k = 2 * (n - got) + 16
        cell = rng.choice(f.size, size=k, p=p)
        u = cu[cell] + (rng.random(k) - 0.5) / grid
        v = cv[cell] + (rng.random(k) - 0.5) / grid
        P, j = _jacobians(S, f[cell], u, v)
        bound = 2.0 * J[cell]
        capped += int((j > bound).sum())
        keep = rng.random(k) * bound < j
        out.append(P[keep])
        got += int(keep.sum())
    if capped:
        print(f"   (sampling: {capped} candidates above the rejection bound, accepted with probability 1)")
    return np.concatenate(out)[:n]


def fitted_samples(mesh, per_side):
    """Exact limit points of a fitted control mesh at the cell centres of each face, their areas and faces."""
    from ccproof.evaluate import LimitSurface

    S = LimitSurface(mesh)
    g = (np.arange(per_side) + 0.5) / per_side
    uu, vv = (a.ravel() for a in np.meshgrid(g, g, indexing="ij"))
    nf = mesh.n_faces
    f = np.repeat(np.arange(nf), per_side * per_side)
    P, J = _jacobians(S, f, np.tile(uu, nf), np.tile(vv, nf))
    return P, J / per_side**2, f


def judge(res, finder, per_side=6):
    """The fitted surface against the true one: area fractions beyond 1 % / 2 % of the diameter, the max (% of
    the diameter), and the true faces / fitted faces where it is beyond 2 %."""
    P, a, f = fitted_samples(res.mesh, per_side)
    r = finder.query(P)
    d = 100.0 * r.distance / res.diameter
    A = float(a.sum())
    far = d > 2.0
    return {"over1": float(a[d > 1.0].sum()) / A, "over2": float(a[far].sum()) / A, "max": float(d.max()),
            "rms": float(np.sqrt(a @ d**2 / A)), "true_faces": np.unique(r.face[far]),
            "fit_faces": np.unique(f[far]), "far_points": P[far]}


def run_case(S, n_faces, finder, n, noise, levels, seed=0, **fit_kw):
    from ccproof.apps.dynamics.fit import fit_points

    X = sample_by_area(S, n_faces, n, seed=seed)
    if noise > 0:
        from ccproof.apps.dynamics.cloud import minimal_enclosing_sphere

        rng = np.random.default_rng(seed + 1)
        diam = 2.0 * minimal_enclosing_sphere(X)[1]
        X = X + rng.normal(scale=noise / 100.0 * diam, size=X.shape)
    tracemalloc.start()
    t0 = time.perf_counter()
    res = fit_points(X, levels=levels, **fit_kw)
    secs = time.perf_counter() - t0
    peak = tracemalloc.get_traced_memory()[1] / 2**20
    tracemalloc.stop()
    return res, judge(res, finder), secs, peak


def line(n, noise, levels, res, q, secs, peak):
    steps = "+".join(str(lev.steps) for lev in res.levels)
    return (f"n={n:>6} noise={noise:.1f}% levels={levels}: true surface: >1% {100 * q['over1']:5.2f} % of area, "
            f">2% {100 * q['over2']:5.2f} %, max {q['max']:5.2f} %, rms {q['rms']:.3f} % | data->fit max "
            f"{res.max_error_percent:.2f} % mean {res.mean_error_percent:.3f} % | fit's stray "
            f"{100 * res.surface_report['stray_fraction']:.2f} % | steps {steps} | {secs:.0f} s, peak "
            f"{peak:.0f} MiB | warnings {len(res.warnings)}")


def main(argv=None):
    from ccproof.apps.dynamics.fit import Evolution, FitSprings, SurfaceCheck

    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--n", type=int, nargs="*", default=[10_000, 30_000, 100_000])
    ap.add_argument("--noise", type=float, nargs="*", default=[0.0, 0.2], help="in %% of the diameter")
    ap.add_argument("--levels", type=int, nargs="*", default=[1, 2])
    ap.add_argument("--surface-spring", type=float, default=None, help="FitSprings.surface_total of fit_points")
    ap.add_argument("--stray-distance", type=float, default=None,
                    help="SurfaceCheck.stray_distance_percent of fit_points (%% of the diameter; default 3 spacings)")
    ap.add_argument("--max-steps", type=int, default=None, help="Evolution.max_steps of fit_points (default: its own)")
    ap.add_argument("--smoke", action="store_true", help="one tiny run (1,000 points, level 0, 5 steps)")
    ap.add_argument("--where", action="store_true", help="print the true faces nearest to the far part")
    args = ap.parse_args(argv)
    mesh, S, finder = true_surface()
    kw = {} if args.surface_spring is None else {"springs": FitSprings(surface_total=args.surface_spring)}
    if args.smoke:
        args.n, args.noise, args.levels, args.max_steps = [1000], [0.0], [0], 5
    if args.stray_distance is not None:
        kw["check"] = SurfaceCheck(stray_distance_percent=args.stray_distance)
    if args.max_steps is not None:
        kw["evolution"] = Evolution(max_steps=args.max_steps)
    print("(timings on a machine shared with other jobs)")
    for n in args.n:
        for noise in args.noise:
            for levels in args.levels:
                res, q, secs, peak = run_case(S, mesh.n_faces, finder, n, noise, levels, **kw)
                print(line(n, noise, levels, res, q, secs, peak), flush=True)
                for w in res.warnings:
                    print("   warning:", w)
                if args.where and q["true_faces"].size:
                    lo, hi = q["far_points"].min(axis=0), q["far_points"].max(axis=0)
                    print(f"   beyond 2 %: {q['true_faces'].size} true faces {q['true_faces'][:40].tolist()}; "
                          f"{q['fit_faces'].size} fitted faces; box {np.round(lo, 3).tolist()} .. "
                          f"{np.round(hi, 3).tolist()}")


if __name__ == "__main__":
    main()
