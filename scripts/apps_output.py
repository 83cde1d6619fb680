"""What a user who takes the applications' output elsewhere gets: the numbers of docs/hsh10.md section 8 and
docs/qmv98.md section 4 ("Equilibrium"), printed, not estimated.

  python scripts/apps_output.py --arap [--osd]  # bunny, 16 charts: control UVs under the corners-only rule
                                                # (--osd: folds counted by OpenSubdiv itself too)
  python scripts/apps_output.py --arap --metric off   # without the minimax (ControlOptions(metric=False))
  python scripts/apps_output.py --fit      # bunny scan: fit steps, energy, criterion, two-sided error
  python scripts/apps_output.py --fit-table  # docs/qmv98.md section 4's tables: synthetic data and the bunny,
                                             # defaults and the regularization a = 1e-4, 1e-5, 1e-6 (b = a / 10)

--arap: for --refine 0 and the default, method (c) on the bunny's 16 normal-segmented charts; then the folds
(UV quads with a corner triangle of signed area <= 0) of the control UVs subdivided with the face-varying
"corners only" rule at levels 1-3, and the distortion of that texture at the metric level (the same samples as
the exact texture): first for the (c) control UVs as they were written before (the chart's own unknowns), then
for :func:`ccproof.apps.arap.fvar.export_control` (fit + polish under the rule, extra subdivisions), whose
control mesh is written to --out-dir. With --osd the written files are also subdivided by OpenSubdiv itself
(Far::PrimvarRefiner, FVAR_LINEAR_CORNERS_ONLY; the driver of tests/apps/arap/osd_fvar_driver.cpp, built
with g++ -losdCPU) and its folded quads at levels 1-3 are counted the same way.
--fit: ``fit_points`` with the defaults on the scan's 2,038 vertices, and an independent two-sided distance
(exact limit points of the fitted control mesh subdivided 4 times, scipy k-d trees both ways).
"""

from __future__ import annotations

import argparse
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

BUNNY = Path(__file__).resolve().parents[1] / "tests" / "data" / "meshes" / "bunny_quads.obj"


def _fmt(m):
    return f"E_angle {m.E_angle:.6f}  E_area {m.E_area:.6f}  E_stretch {m.E_stretch:.6f}"


def _build_osd():
    import shutil
    import subprocess
    import tempfile

    src = Path(__file__).resolve().parents[1] / "tests" / "apps" / "arap" / "osd_fvar_driver.cpp"
    if shutil.which("g++") is None or not Path("/usr/include/opensubdiv/far/primvarRefiner.h").exists():
        print("OpenSubdiv headers (apt-get install libosd-dev) or g++ missing: --osd skipped")
        return None
    exe = Path(tempfile.mkdtemp()) / "osd_fvar"
    r = subprocess.run(["g++", "-O2", "-std=c++14", str(src), "-o", str(exe), "-losdCPU"], capture_output=True,
                       text=True)
    if r.returncode != 0:
        print(f"building the OpenSubdiv driver failed: {r.stderr[-500:]}")
        return None
    return exe


def osd_folds(exe, path, levels=(1, 2, 3)):
    """Folded UV quads (a corner triangle of signed area <= 0) of the textured faces of an OBJ with v/vt,
    subdivided by OpenSubdiv's face-varying corners-only rule (uniform refinement: the children of face f at
    level l are 4^l f .. 4^l f + 4^l - 1)."""
    import subprocess

    nv, F, FT, UV = 0, [], [], []
    for line in Path(path).read_text().splitlines():
        s = line.split()
        if not s:
            continue
        if s[0] == "v":
            nv += 1
        elif s[0] == "vt":
            UV.append(s[1] + " " + s[2])
        elif s[0] == "f":
            F.append([int(c.split("/")[0]) - 1 for c in s[1:]])
            FT.append([int(c.split("/")[1]) - 1 if "/" in c else -1 for c in s[1:]])
    ui, n = [], len(UV)
    for ft in FT:
        for k in ft:
            ui.append(k if k >= 0 else n)
            n += k < 0
    vals = UV + ["0 0"] * (n - len(UV))
    tex = np.array([f for f, ft in enumerate(FT) if ft[0] >= 0])
    out = []
    for lv in levels:
        inp = "\n".join([f"{nv} {len(F)} {n} {lv}", " ".join(str(len(f)) for f in F),
                         " ".join(str(v) for f in F for v in f), " ".join(map(str, ui)), "\n".join(vals)]) + "\n"
        res = subprocess.run([str(exe)], input=inp, capture_output=True, text=True, check=True).stdout
        lines = res.splitlines()
        m = int(lines[0])
        U = np.loadtxt(lines[1 : 1 + m]).reshape(-1, 2)
        Q = np.loadtxt(lines[2 + m :], dtype=np.int64).reshape(-1, 4)
        q = 4**lv
        Q = Q[(q * tex[:, None] + np.arange(q)).ravel()]
        bad = np.zeros(Q.shape[0], dtype=bool)
        for i in range(4):
            a, b, c = U[Q[:, i]], U[Q[:, (i + 1) % 4]], U[Q[:, (i + 3) % 4]]
            bad |= (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0]) <= 0
        out.append(int(bad.sum()))
    return out


def arap(eval_level, out_dir, use_osd, refines=("0", "auto"), metric="auto"):
    from ccproof.apps.arap.charts import segment_by_normals
    from ccproof.apps.arap.core import ChartTexture, Solver, texture_metrics
    from ccproof.apps.arap.fvar import FOLD_LEVELS, ControlOptions, export_control, subdivided_folds
    from ccproof.apps.arap.hierarchy import ChartHierarchy
    from ccproof.apps.arap.io import write_uv_obj
    from ccproof.apps.arap.meshes import LevelPlan, auto_refine, compare
    from ccproof.apps.arap.metrics import Metrics
    from ccproof.mesh import read_obj

    exe = _build_osd() if use_osd else None
    out_dir.mkdir(parents=True, exist_ok=True)

    mesh = read_obj(BUNNY)
    labels = segment_by_normals(mesh)
    print(f"bunny: {mesh.n_faces} faces, {labels.max() + 1} charts; metrics at level {eval_level} "
          f"(E_angle, E_area minimum 2, E_stretch minimum 1); folds at levels {FOLD_LEVELS}")
    for refine in [auto_refine(mesh, labels) if r == "auto" else int(r) for r in refines]:
        t0 = time.perf_counter()
        res, _ = compare(mesh, labels, ("c",), LevelPlan(levels=3, eval_level=eval_level, refine=refine),
                         Solver(accel=5), release=True)
        r = res["c"]
        t1 = time.perf_counter()
        print(f"\n--refine {refine}: exact texture (c)            {_fmt(r.metrics)}   ({t1 - t0:.1f} s)")
        folds, met = np.zeros(len(FOLD_LEVELS), dtype=np.int64), Metrics()
        for tex in r.textures:  # the former --control-out: the chart's (c) unknowns under the corners-only rule
            h = tex.hierarchy
            hc = ChartHierarchy(h.surface, h.chart_faces, surface_corners=True)
            Y = tex.unknowns[: hc.n_chart_vertices]
            folds += subdivided_folds(hc, Y)
            met = met + texture_metrics(ChartTexture(hc, "boundary", 0, hc.lift_unknowns(Y, "boundary"), Y),
                                        eval_level - refine)
            hc.release()
            h.release()
        print(f"  (c) control UVs as written before:      {_fmt(met)}   folds {folds.tolist()}")
        if exe is not None:
            old = out_dir / f"bunny_control_refine{refine}_before.obj"
            write_uv_obj(old, r.textures[0].hierarchy.surface, r)  # the former file: (c)'s own unknowns
            print(f"    OpenSubdiv's folds of that file: {osd_folds(exe, old)}")
        t2 = time.perf_counter()
        # the CLI's defaults (--metric on / off: the minimax on every refinement that misses the target / never)
        exp = export_control(r, eval_level, 3, ControlOptions(max_faces=150_000, metric=metric))
        t3 = time.perf_counter()
        ex = np.subtract(r.metrics.as_tuple(), (2.0, 2.0, 1.0))
        for extra, f, m in exp.tried:
            if extra == exp.extra and exp.arap_metrics is not None:
                a = exp.arap_metrics
                ratio = np.subtract(a.as_tuple(), (2.0, 2.0, 1.0)) / ex
                print(f"  corners-only UVs, {extra} extra subdivision(s), ARAP polish alone: {_fmt(a)}   excess / "
                      f"exact {ratio[0]:.3f} {ratio[1]:.3f} {ratio[2]:.3f}")
                print(f"    minimax per chart (None: ARAP polish, else metric_polish weights): {exp.chart_weights}")
            ratio = np.subtract(m.as_tuple(), (2.0, 2.0, 1.0)) / ex
            print(f"  corners-only UVs, {extra} extra subdivision(s): {_fmt(m)}   folds {f}   excess / exact "
                  f"{ratio[0]:.3f} {ratio[1]:.3f} {ratio[2]:.3f}")
        er = exp.excess_ratio()
        print(f"  written: {exp.extra} extra ({exp.mesh.n_faces} control faces), excess / exact "
              f"{er[0]:.3f} {er[1]:.3f} {er[2]:.3f}, within 5 %: {exp.accepted} ({t3 - t2:.1f} s)")
        path = out_dir / f"bunny_control_refine{refine}{'' if metric == 'auto' else '_metric_' + str(metric)}.obj"
        write_uv_obj(path, exp.mesh, replace(r, textures=exp.textures))
        print(f"  wrote {path}")
        if exe is not None:
            print(f"    OpenSubdiv's folds of that file: {osd_folds(exe, path)}")


def band(eval_level, chart, weights):
    """docs/hsh10.md section 8.1, "Where the excess sits": one chart of the bunny at the default refinement, its
    corners-only UVs on the control mesh subdivided once more (fit + ARAP polish, as export_control): per metric
    sample, matched to the exact texture's by position, the excess over the exact texture's by graph distance
    to the chart boundary and by the nearest chart-boundary vertex's type (k chart faces of its n); then the
    chart's three excess ratios after metric_polish with E_angle's weight times each of ``weights``."""
    import scipy.sparse as sp
    from scipy.sparse.csgraph import dijkstra
    from scipy.spatial import cKDTree

    from ccproof.apps.arap.charts import segment_by_normals
    from ccproof.apps.arap.core import ChartTexture, Solver, optimize_chart, texture_metrics
    from ccproof.apps.arap.fvar import corners_only_texture, metric_polish
    from ccproof.apps.arap.meshes import LevelPlan, auto_refine, compare, refine_mesh
    from ccproof.mesh import read_obj

    mesh = read_obj(BUNNY)
    labels = segment_by_normals(mesh)
    ref = auto_refine(mesh, labels)
    res, _ = compare(mesh, labels, ("c",), LevelPlan(levels=3, eval_level=eval_level, refine=ref), Solver(accel=5),
                     release=True)
    tex = res["c"].textures[chart]
    h = tex.hierarchy
    ev, evx = eval_level - ref, eval_level - ref - 1
    hc, Y = corners_only_texture(tex, 1, 2, refine_mesh(h.surface, None, 1)[0])
    Yp, _, _ = optimize_chart(hc, "boundary", Y, levels=max(1, 3 - ref - 1), start_level=1, accel=5)

    def samples(hh, lev, rules, X):
        m, d = texture_metrics(ChartTexture(hh, rules, 0, hh.lift_unknowns(X, rules), X), lev, per_sample=True)
        s1, s2, w = d["s1"], d["s2"], d["weight"]
        ex = np.stack([w * (s1 / s2 + s2 / s1 - 2), w * (d["area_distortion"] - 2)], 1)
        return m, hh.level(lev).mesh.vertices[d["vertex"]], ex, w

    me, Pe, exe, we = samples(h, ev, "extended", tex.unknowns)
    mp, Pp, exp_, _ = samples(hc, evx, "boundary", Yp)
    E = np.subtract(me.as_tuple(), (2.0, 2.0, 1.0))
    print(f"chart {chart}: {h.chart_faces.size} faces at --refine {ref}, {hc.chart_faces.size} with 1 extra; ARAP "
          f"polish excess / exact {np.round(np.subtract(mp.as_tuple(), (2.0, 2.0, 1.0)) / E, 3)}")
    L = h.level(ev)
    e, n = L.mesh.edges, L.mesh.n_vertices
    G = sp.coo_matrix((np.ones(len(e)), (e[:, 0], e[:, 1])), shape=(n, n)).tocsr()
    dist = dijkstra(G, directed=False, indices=np.flatnonzero(L.chart_boundary), min_only=True, unweighted=True)
    dist /= 2**ev  # in faces of the texture's control mesh
    tree = cKDTree(L.mesh.vertices)
    de, dp = dist[tree.query(Pe)[1]], dist[tree.query(Pp)[1]]
    A = me.area
    print("  distance to the chart boundary (control faces): share of the area; (corners-only - exact) E_angle, "
          "E_area excess / the chart's exact excess")
    edges = [0, 0.01, 0.3, 0.6, 1.1, 2.1, 5.1, np.inf]
    for lo, hi in zip(edges[:-1], edges[1:]):
        se, sp_ = (de >= lo) & (de < hi), (dp >= lo) & (dp < hi)
        diff = (exp_[sp_].sum(0) - exe[se].sum(0)) / A / E[:2]
        print(f"    [{lo:4.2f}, {hi:4.2f}): area {we[se].sum() / A:.3f}  {np.round(diff, 4)}")
    L0 = h.level(0)
    bv = np.flatnonzero(L0.chart_boundary)
    typ = np.array([f"{a} of {b}" for a, b in zip(L0.chart_face_count[bv], L0.mesh.face_count[bv])])
    tb = cKDTree(L0.mesh.vertices[bv])
    ne, np_ = tb.query(Pe)[1], tb.query(Pp)[1]
    print("  nearest chart-boundary vertex (k chart faces of n), samples within 1 face: count, (corners-only - "
          "exact) E_angle, E_area excess in 1e-6 of the chart's area and / the chart's exact excess")
    for t in sorted(set(typ)):
        sel = np.flatnonzero(typ == t)
        d = (exp_[np.isin(np_, sel) & (dp <= 1.01)].sum(0) - exe[np.isin(ne, sel) & (de <= 1.01)].sum(0)) / A
        print(f"    {t}: {sel.size:4d}  {np.round(d * 1e6, 2)}  {np.round(d / E[:2], 4)}")
    for wa in weights:
        Z = metric_polish(hc, Yp, evx, (wa / E[0], 1 / E[1], 1 / E[2]))
        m = texture_metrics(ChartTexture(hc, "boundary", 0, hc.lift_unknowns(Z, "boundary"), Z), evx)
        print(f"  metric_polish, E_angle weight x {wa}: excess / exact "
              f"{np.round(np.subtract(m.as_tuple(), (2.0, 2.0, 1.0)) / E, 3)}")


def fit():
    from scipy.spatial import cKDTree

    from ccproof.apps.dynamics.fit import fit_points, read_points
    from ccproof.mesh import subdivide
    from ccproof.mesh.masks import limit_positions

    X = read_points(BUNNY)
    t0 = time.perf_counter()
    res = fit_points(X, levels=1)
    t1 = time.perf_counter()
    print(f"bunny scan: {X.shape[0]} points, defaults (tol {res.parameters['tol']:g}, cap "
          f"{res.parameters['max_steps']} steps), {t1 - t0:.1f} s")
    for i, lev in enumerate(res.levels):
        print(f"  level {i}: {lev.n_vertices} vertices, {lev.steps} steps, energy {lev.energy:.6g}, energy change "
              f"{lev.energy_change:.2g}, mean-error change {lev.error_change:.2g}, max / mean error "
              f"{lev.max_error_percent:.3f} / {lev.mean_error_percent:.4f} %: {lev.reason}")
    print(f"  reported: data -> surface {res.max_error_percent:.3f} %, surface -> data "
          f"{res.surface_max_percent:.3f} %, two-sided {res.two_sided_error_percent:.3f} % "
          f"(of the enclosing-sphere diameter)")
    m = res.mesh
    for _ in range(4):
        m = subdivide(m)
    S = limit_positions(m)
    h = float(np.max(np.linalg.norm(S[m.faces[:, 0]] - S[m.faces[:, 2]], axis=1)))
    d1 = cKDTree(S).query(X)[0].max()
    d2 = cKDTree(X).query(S)[0].max()
    D = res.diameter
    print(f"  independent ({S.shape[0]} limit points, spacing <= {100 * h / D:.3f} %): data -> surface "
          f"{100 * d1 / D:.3f} %, surface -> data {100 * d2 / D:.3f} %, two-sided {100 * max(d1, d2) / D:.3f} %")
    print(f"  warnings: {res.warnings or 'none'}")


def fit_table(names, scales):
    """The rows of docs/qmv98.md section 4: max / mean data -> surface error in % of the enclosing-sphere
    diameter at 98 and 386 control vertices, and the steps of each level, for ``fit_points`` with the defaults
    and with the regularization scaled (a = s, b = s / 10)."""
    from dataclasses import replace as dc_replace

    from ccproof.apps.dynamics.fit import DEFAULT_FIT_MATERIAL, fit_points, read_points
    from ccproof.apps.dynamics.shapes import synthetic_range_data

    for name in names:
        X = read_points(BUNNY) if name == "bunny" else synthetic_range_data(name)
        for a in scales:
            mat = dc_replace(DEFAULT_FIT_MATERIAL, a11=a, a22=a, b11=a / 10, b12=a / 5, b22=a / 10)
            t0 = time.perf_counter()
            res = fit_points(X, levels=1, material=mat)
            dt = time.perf_counter() - t0
            print(f"{name} ({X.shape[0]} points), a = {a:g}, b = {a / 10:g}: " + " | ".join(
                f"{lev.n_vertices} vertices {lev.max_error_percent:.2f} / {lev.mean_error_percent:.3f} "
                f"({lev.steps}{'*' if lev.steps >= res.parameters['max_steps'] else ''})" for lev in res.levels)
                + f"   {dt:.1f} s", flush=True)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--arap", action="store_true")
    ap.add_argument("--fit", action="store_true")
    ap.add_argument("--band", type=int, metavar="CHART", help="where the corners-only excess sits, on that chart")
    ap.add_argument("--band-weights", default="1,1.3,1.45,1.6,2,3", help="--band: E_angle weights of metric_polish")
    ap.add_argument("--fit-table", action="store_true", help="the tables of docs/qmv98.md section 4")
    ap.add_argument("--shapes", default="bulb,ellipsoid,superquadric,bunny", help="--fit-table: data sets")
    ap.add_argument("--scales", default="1e-5,1e-4,1e-6", help="--fit-table: values of a (b = a / 10)")
    ap.add_argument("--eval-level", type=int, default=4, help="metric level of --arap (default 4)")
    ap.add_argument("--osd", action="store_true", help="--arap: also count folds with OpenSubdiv itself")
    ap.add_argument("--refines", default="0,auto", help="--arap: the --refine values (default 0,auto)")
    ap.add_argument("--metric", choices=("auto", "on", "off"), default="auto",
                    help="--arap: ControlOptions(metric=...) of export_control: the minimax over metric-energy "
                         "candidates on the last refinement allowed where the ARAP polish misses the target (auto, "
                         "default), on every refinement that misses it (on), never (off)")
    ap.add_argument("--out-dir", type=Path, default=Path("out/apps_output"), help="control meshes of --arap")
    a = ap.parse_args(argv)
    if not (a.arap or a.fit or a.fit_table or a.band is not None):
        ap.error("give --arap, --band, --fit and/or --fit-table")
    if a.band is not None:
        band(a.eval_level, a.band, [float(x) for x in a.band_weights.split(",")])
    if a.fit:
        fit()
    if a.fit_table:
        fit_table(a.shapes.split(","), [float(x) for x in a.scales.split(",")])
    if a.arap:
        arap(a.eval_level, a.out_dir, a.osd, a.refines.split(","), {"auto": "auto", "on": True, "off": False}[a.metric])


if __name__ == "__main__":
    main()
