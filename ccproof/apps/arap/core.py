"""hsh10 end to end: initialization, the multi-resolution optimization, the baselines, the metrics.

Methods (the rows of hsh10's comparison figures, docs/hsh10.md A10):

* ``"a"``: ARAP polygon parameterization (Liu et al. 2008) of the triangulated chart control mesh,
  texture then subdivided with the chart's boundary rules;
* ``"b"``: ours with boundary rules (:mod:`~ccproof.apps.arap.hierarchy`, rules ``"boundary"``);
* ``"c"``: ours with extended charts (rules ``"extended"``);
* ``"d"``: ARAP polygon parameterization of the chart control mesh subdivided 3 times (its
  level-3 control points), texture subdivided with boundary rules from level 3.

Every method is initialized by LSCM on its own triangulated control mesh (for (c): LSCM on the
chart, then the conformal extension to the ring). Every method is measured the same way:
:func:`texture_metrics` at evaluation level 5 (docs/hsh10.md A9), plus flipped triangles of the texture
control mesh (:func:`control_flips`).

Multi-resolution schedule (A7): optimize at ``start_level`` until the relative energy decrease
per iteration is below ``tol``, then at the next level warm-started from the current ``T^0``, up
to ``levels``. The default start is level 1 (docs/hsh10.md A6 caution: at level 0 the masks miss the
odd-even modes of regular grids; level 0 is allowed and then regularized if singular).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from ccproof.apps.arap.charts import charts_from_labels, check_disk
from ccproof.apps.arap.hierarchy import ChartHierarchy
from ccproof.apps.arap.lscm import fit_area, lscm, lscm_extend, signed_areas, triangulate_quads
from ccproof.apps.arap.metrics import Metrics, sample_metrics
from ccproof.apps.arap.samples import build_samples
from ccproof.apps.arap.solver import LocalGlobal, iterate, system_from_samples, triangle_samples
from ccproof.errors import CCProofError

__all__ = [
    "LevelStats",
    "ChartTexture",
    "MethodResult",
    "initial_texture",
    "optimize_chart",
    "polygon_arap",
    "run_method",
    "texture_metrics",
    "control_flips",
    "parameterize",
    "compare",
    "METHODS",
    "VARIANTS",
]

METHODS = ("a", "b", "c", "d")
#: --variant name -> method
VARIANTS = {"extended": "c", "boundary": "b"}
METHOD_NAMES = {
    "a": "(a) ARAP on control mesh",
    "b": "(b) ours, boundary rules",
    "c": "(c) ours, extended charts",
    "d": "(d) ARAP on control mesh x3",
}


@dataclass
class LevelStats:
    """What happened at one optimization level."""

    level: int
    samples: int
    build_seconds: float
    iterations: int
    seconds: float
    seconds_per_iteration: float
    energy_start: float
    energy_end: float
    converged: bool
    regularized: bool


@dataclass
class ChartTexture:
    """A chart's texture: level-``level`` values on ``E_level`` subdivided with ``rules``."""

    hierarchy: ChartHierarchy
    rules: str
    level: int
    values: np.ndarray
    #: texture unknowns (control level of the method), and the control-level triangles
    unknowns: np.ndarray = None


@dataclass
class MethodResult:
    """One method on all charts of a mesh."""

    method: str
    textures: list
    seconds: float
    iterations: int
    metrics: Metrics = None
    flips_control: int = 0
    triangles_control: int = 0
    levels: list = field(default_factory=list)

    @property
    def name(self):
        return METHOD_NAMES[self.method]


# --------------------------------------------------------------------------- initialization
def _chart_triangles(h: ChartHierarchy):
    """Level-0 chart triangles in unknown indices, and the positions of the unknowns."""
    L0 = h.level(0)
    orig = h.orig0
    Fc = orig[L0.chart_faces()]
    V = h.surface.vertices[h.unknown_vertices]
    return V, triangulate_quads(V, Fc)


def initial_texture(h: ChartHierarchy, rules):
    """LSCM of the triangulated chart control mesh at its natural scale (A6); for extended charts the
    ring unknowns are the conformal extension of it (A11.6). Shape (n_unknowns, 2)."""
    V, Tc = _chart_triangles(h)
    nc = h.n_chart_vertices
    UV = fit_area(lscm(V[:nc], Tc), V[:nc], Tc)
    if rules == "boundary" or h.unknown_vertices.size == nc:
        return UV
    L0 = h.level(0)
    orig = h.orig0
    Te = triangulate_quads(V, orig[L0.mesh.faces])
    return lscm_extend(V, Te, np.arange(nc), UV)


# --------------------------------------------------------------------------- optimization
def optimize_chart(h: ChartHierarchy, rules, X0, levels=3, start_level=1, tol=1e-6, max_iter=1000, trace=False):
    """Multi-resolution local/global optimization of one chart (A4-A7).

    Returns
    -------
    X : (n_unknowns, 2), stats : list of LevelStats, runs : list of IterationResult
    """
    if start_level < 0 or levels < start_level:
        raise CCProofError(f"need 0 <= start_level <= levels, got start_level={start_level}, levels={levels}")
    X = np.asarray(X0, dtype=np.float64)
    stats, runs = [], []
    for k in range(start_level, levels + 1):
        t0 = time.perf_counter()
        L = h.level(k)
        S = build_samples(L, rules, "optimize")
        sysk = system_from_samples(S, h.operator(k, rules), pin=0)
        tb = time.perf_counter() - t0
        res = iterate(sysk, X, tol=tol, max_iter=max_iter, trace=trace)
        X = res.X
        stats.append(
            LevelStats(
                k, sysk.n_samples, tb, res.iterations, res.seconds, res.seconds_per_iteration,
                res.energies[0], res.energies[-1], res.converged, sysk.regularized,
            )
        )
        runs.append(res)
    return X, stats, runs


def _triangle_arap_numpy(V, T, UV0, tol, max_iter):
    p1, p2, G1, G2, w = triangle_samples(V, T)
    sysm = LocalGlobal(p1, p2, G1, G2, w, pin=int(T[0, 0]))
    res = iterate(sysm, UV0, tol=tol, max_iter=max_iter)
    return res.X, res.iterations, res.converged


def _triangle_arap_igl(V, T, UV0, tol, max_iter):
    try:
        import igl
    except ImportError as exc:  # pragma: no cover - depends on the environment
        raise CCProofError("engine 'igl' needs libigl (pip install libigl)") from exc
    p1, p2, G1, G2, w = triangle_samples(V, T)
    ev = LocalGlobal(p1, p2, G1, G2, w, factor=False)
    from ccproof.apps.arap.solver import closest_rotations

    def energy(X):
        J = ev.jacobians(X)
        return ev.energy(J, closest_rotations(J))

    data = igl.ARAPData()
    data.max_iter = 1
    b = np.array([int(T[0, 0])], dtype=np.int32)
    igl.arap_precomputation(np.ascontiguousarray(V), np.ascontiguousarray(T, dtype=np.int64), 2, b, data)
    bc = np.ascontiguousarray(UV0[b])
    X = np.ascontiguousarray(UV0, dtype=np.float64)
    E = energy(X)
    it, conv = 0, False
    while it < max_iter:
        X = igl.arap_solve(bc, data, X)
        it += 1
        En = energy(X)
        if (E - En) <= tol * E:
            conv = True
            break
        E = En
    return X, it, conv


def polygon_arap(V, T, UV0, engine="numpy", tol=1e-6, max_iter=500):
    """Liu et al. 2008 ARAP of a triangle mesh from ``UV0`` (one pinned vertex).

    engine "numpy": this package's local/global solver on triangle samples (exactly Liu's energy);
    engine "igl": libigl ``arap_precomputation(dim=2)`` + ``arap_solve`` one iteration at a time.
    Returns (UV, iterations, converged).
    """
    if engine == "igl":
        return _triangle_arap_igl(V, T, UV0, tol, max_iter)
    if engine != "numpy":
        raise CCProofError(f"unknown ARAP engine {engine!r} (numpy or igl)")
    return _triangle_arap_numpy(V, T, UV0, tol, max_iter)


def run_method(h: ChartHierarchy, method, levels=3, start_level=1, tol=1e-6, max_iter=1000, engine="numpy",
               baseline_level=3, baseline_max_iter=2000, trace=False):
    """Run one method on one chart. Returns (ChartTexture, seconds, iterations, level stats)."""
    t0 = time.perf_counter()
    if method in ("b", "c"):
        rules = "boundary" if method == "b" else "extended"
        X0 = initial_texture(h, rules)
        X, stats, _ = optimize_chart(h, rules, X0, levels, start_level, tol, max_iter, trace)
        tex = ChartTexture(h, rules, 0, h.lift_unknowns(X, rules), X)
        return tex, time.perf_counter() - t0, sum(s.iterations for s in stats), stats
    if method == "a":
        V, T = _chart_triangles(h)
        nc = h.n_chart_vertices
        V = V[:nc]
        UV0 = fit_area(lscm(V, T), V, T)
        X, it, _ = polygon_arap(V, T, UV0, engine, tol, baseline_max_iter)
        tex = ChartTexture(h, "boundary", 0, h.lift_unknowns(X, "boundary"), X)
        return tex, time.perf_counter() - t0, it, []
    if method == "d":
        k = int(baseline_level)
        L = h.level(k)
        cv = np.flatnonzero(L.chart_vertex)
        loc = np.full(L.n_vertices, -1, dtype=np.int64)
        loc[cv] = np.arange(cv.size)
        V = L.mesh.vertices[cv]
        T = triangulate_quads(V, loc[L.chart_faces()])
        UV0 = fit_area(lscm(V, T), V, T)
        X, it, _ = polygon_arap(V, T, UV0, engine, tol, baseline_max_iter)
        vals = np.zeros((L.n_vertices, 2))
        vals[cv] = X
        return ChartTexture(h, "boundary", k, vals, X), time.perf_counter() - t0, it, []
    raise CCProofError(f"unknown method {method!r}; expected one of {METHODS}")


# --------------------------------------------------------------------------- measuring
def _metric_samples(h: ChartHierarchy, level, rules):
    cache = h.__dict__.setdefault("_metric_samples", {})
    key = (level, rules)
    if key not in cache:
        cache[key] = build_samples(h.level(level), rules, "metric")
    return cache[key]


def texture_metrics(tex: ChartTexture, eval_level=5, per_sample=False):
    """A9 metrics of a chart texture at ``eval_level`` (same samples for every method)."""
    if eval_level < tex.level:
        raise CCProofError(f"evaluation level {eval_level} is below the texture's level {tex.level}")
    X = tex.hierarchy.subdivide_values(tex.values, tex.rules, tex.level, eval_level)
    S = _metric_samples(tex.hierarchy, eval_level, tex.rules)
    return sample_metrics(S, X, per_sample=per_sample)


def control_flips(tex: ChartTexture):
    """(flipped, total) triangles of the texture's control mesh (chart faces at its level, split
    along the shorter 3D diagonal); flipped = signed texture area <= 0."""
    L = tex.hierarchy.level(tex.level)
    T = triangulate_quads(L.mesh.vertices, L.chart_faces())
    a = signed_areas(tex.values, T)
    return int((a <= 0).sum()), int(T.shape[0])


# --------------------------------------------------------------------------- whole meshes
def _charts(mesh, labels):
    if labels is None:
        faces = np.arange(mesh.n_faces)
        check_disk(mesh, faces, "the mesh (one chart; give --charts for a closed or non-disk mesh)")
        return [faces]
    return charts_from_labels(mesh, labels)


def compare(mesh, labels=None, methods=METHODS, levels=3, start_level=1, eval_level=5, tol=1e-6, max_iter=1000,
            engine="numpy", baseline_level=3, baseline_max_iter=2000, hierarchies=None, trace=False):
    """Run ``methods`` on every chart and measure them the same way.

    Returns
    -------
    dict method -> MethodResult, and the list of ChartHierarchy (reusable)
    """
    charts = _charts(mesh, labels)
    if hierarchies is None:
        hierarchies = [ChartHierarchy(mesh, fc) for fc in charts]
    out = {}
    for m in methods:
        texs, secs, its, lv = [], 0.0, 0, []
        for h in hierarchies:
            tex, s, it, st = run_method(h, m, levels, start_level, tol, max_iter, engine, baseline_level,
                                        baseline_max_iter, trace)
            texs.append(tex)
            secs += s
            its += it
            lv.append(st)
        out[m] = MethodResult(m, texs, secs, its, levels=lv)
    for r in out.values():
        met = Metrics()
        fl = tot = 0
        for tex in r.textures:
            met = met + texture_metrics(tex, eval_level)
            f, t = control_flips(tex)
            fl += f
            tot += t
        r.metrics, r.flips_control, r.triangles_control = met, fl, tot
    return out, hierarchies


def parameterize(mesh, labels=None, variant="extended", levels=3, start_level=1, eval_level=5, tol=1e-6,
                 max_iter=1000):
    """hsh10 parameterization of every chart: variant "extended" (c) or "boundary" (b)."""
    if variant not in VARIANTS:
        raise CCProofError(f"unknown variant {variant!r}; expected one of {tuple(VARIANTS)}")
    res, hs = compare(mesh, labels, (VARIANTS[variant],), levels, start_level, eval_level, tol, max_iter)
    return res[VARIANTS[variant]]
