"""hsh10 per chart: initialization, the multi-resolution optimization, the baselines, the metrics
(whole meshes, their memory budget and the comparison of the methods: :mod:`~ccproof.apps.arap.meshes`).

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

Multi-resolution schedule: optimize at ``start_level`` until the relative energy decrease
per iteration is below ``tol``, then at the next level warm-started from the current ``T^0``, up
to ``levels``. The default start is level 1 (docs/hsh10.md A6 caution: at level 0 the masks miss the
odd-even modes of regular grids; level 0 is allowed and then regularized if singular).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from ccproof.apps.arap.hierarchy import ChartHierarchy
from ccproof.apps.arap.lscm import fit_area, lscm, lscm_extend, signed_areas, triangulate_quads
from ccproof.apps.arap.metrics import Metrics, sample_metrics
from ccproof.apps.arap.samples import build_samples
from ccproof.apps.arap.solver import LocalGlobal, iterate, system_from_samples, triangle_samples
from ccproof.errors import CCProofError

if TYPE_CHECKING:
    pass

__all__ = [
    "Solver",
    "LevelStats",
    "ChartTexture",
    "MethodResult",
    "initial_texture",
    "optimize_chart",
    "polygon_arap",
    "run_method",
    "texture_metrics",
    "control_flips",
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
    """What happened at one optimization level (the multi-resolution schedule of hsh10 section 3).

    Parameters
    ----------
    level : int
    samples : int
        Number of samples of hsh10 Eq. 3 at this level.
    build_seconds, seconds, seconds_per_iteration : float
    iterations : int
    energy_start, energy_end : float
        ARAP energy before and after.
    converged : bool
    regularized : bool
        Whether the global step needed a regularization.

    Examples
    --------
    >>> from ccproof.mesh.examples import grid
    >>> from ccproof.apps.arap.hierarchy import ChartHierarchy
    >>> tex, seconds, iterations, stats = run_method(ChartHierarchy(grid(3, 3), range(9)), "c", levels=1)
    >>> [(s.level, s.converged, s.energy_end < 1e-20) for s in stats]       # a flat grid: isometric
    [(1, True, True)]
    """

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
    """A chart's texture: level-``level`` values on ``E_level`` subdivided with ``rules``.

    Parameters
    ----------
    hierarchy : ChartHierarchy
    rules : {"boundary", "extended"}
        Subdivision rules of the texture (hsh10 section 3; docs/hsh10.md).
    level : int
    values : ndarray, shape (n, 2) float64
        Texture coordinates of the level-``level`` vertices.
    unknowns : ndarray, shape (n_unknowns, 2) float64, optional
        Texture unknowns (control level of the method).

    Examples
    --------
    >>> from ccproof.mesh.examples import grid
    >>> from ccproof.apps.arap.hierarchy import ChartHierarchy
    >>> tex = run_method(ChartHierarchy(grid(3, 3), range(9)), "c", levels=1)[0]
    >>> tex.rules, tex.level, tex.values.shape[1]
    ('extended', 0, 2)
    """

    hierarchy: ChartHierarchy
    rules: str
    level: int
    values: np.ndarray
    #: texture unknowns (control level of the method), and the control-level triangles
    unknowns: np.ndarray | None = None


@dataclass
class MethodResult:
    """One method on all charts of a mesh (a row of the comparison of hsh10 section 4).

    Parameters
    ----------
    method : {"a", "b", "c", "d"}
    textures : list of ChartTexture
    seconds : float
    iterations : int
    metrics : Metrics, optional
    flips_control, triangles_control : int, optional
    levels : list of LevelStats, optional
    refine : int, optional
        Times the control mesh was subdivided before optimizing (b, c).
    samples : list, optional
        Per chart (P, UV, Q) limit samples at ``sample_level`` (see :func:`~ccproof.apps.arap.meshes.compare`).
    sample_level : int, optional

    Examples
    --------
    >>> from ccproof.mesh.examples import grid
    >>> from ccproof.apps.arap.meshes import LevelPlan, compare
    >>> res, _ = compare(grid(3, 3), methods=("c",), plan=LevelPlan(levels=1, eval_level=3))
    >>> r = res["c"]
    >>> r.method, len(r.textures), r.metrics.flips
    ('c', 1, 0)
    """

    method: str
    textures: list
    seconds: float
    iterations: int
    metrics: Metrics | None = None
    flips_control: int = 0
    triangles_control: int = 0
    levels: list = field(default_factory=list)
    #: times the control mesh was subdivided before optimizing (b, c)
    refine: int = 0
    #: per chart (P, UV, Q) limit samples at ``sample_level`` (see :func:`~ccproof.apps.arap.meshes.compare`), or None
    samples: list | None = None
    sample_level: int | None = None

    @property
    def name(self):
        return METHOD_NAMES[self.method] + (f", refined x{self.refine}" if self.refine else "")


# --------------------------------------------------------------------------- initialization
def _chart_triangles(h: ChartHierarchy):
    """Level-0 chart triangles in unknown indices, and the positions of the unknowns."""
    L0 = h.level(0)
    orig = h.orig0
    Fc = orig[L0.chart_faces()]
    V = h.surface.vertices[h.unknown_vertices]
    return V, triangulate_quads(V, Fc)


def initial_texture(h: ChartHierarchy, rules):
    """LSCM of the triangulated chart control mesh at its natural scale.

    For extended charts the ring unknowns are the conformal extension of it (the initialization of
    hsh10 section 3; docs/hsh10.md).

    Parameters
    ----------
    h : ChartHierarchy
    rules : {"boundary", "extended"}

    Returns
    -------
    ndarray, shape (n_unknowns, 2) float64

    Examples
    --------
    A flat grid is developed isometrically (up to a rigid motion): the side lengths stay 3:

    >>> import numpy as np
    >>> from ccproof.mesh.examples import grid
    >>> from ccproof.apps.arap.hierarchy import ChartHierarchy
    >>> h = ChartHierarchy(grid(3, 3), range(9))
    >>> X = initial_texture(h, "boundary")
    >>> X.shape, round(float(np.linalg.norm(X[3] - X[0])), 9)
    ((16, 2), 3.0)
    """
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
@dataclass(frozen=True)
class Solver:
    """How the methods iterate (:func:`run_method`, :func:`~ccproof.apps.arap.meshes.compare`).

    Parameters
    ----------
    tol : float
        Stop a level when the relative energy decrease per iteration is below it.
    max_iter : int
        Iterations per level at most.
    accel : int
        Anderson acceleration history of (b) and (c) (0: the plain local/global iteration; the CLI uses 5);
        (a) and (d) are never accelerated (they are the baselines as published).
    engine : {"numpy", "igl"}
        ARAP engine of the polygon baselines (a) and (d).
    baseline_level : int
        Level of the control points that (d) parameterizes.
    baseline_max_iter : int
        Iterations of the polygon baselines at most.
    trace : bool
        Record the energy of every iteration (:class:`LevelStats`).

    Examples
    --------
    >>> Solver(tol=1e-8).max_iter
    1000
    """

    tol: float = 1e-6
    max_iter: int = 1000
    accel: int = 0
    engine: str = "numpy"
    baseline_level: int = 3
    baseline_max_iter: int = 2000
    trace: bool = False


def optimize_chart(h: ChartHierarchy, rules, X0, levels=3, start_level=1, tol=1e-6, max_iter=1000, trace=False,
                   accel=0):
    """Multi-resolution local/global optimization of one chart (hsh10 sections 3.1-3.3).

    ``accel``: Anderson acceleration history of :func:`~ccproof.apps.arap.solver.iterate` (0: plain).

    Parameters
    ----------
    h : ChartHierarchy
    rules : {"boundary", "extended"}
    X0 : ndarray, shape (n_unknowns, 2) float64
        Initial texture unknowns (:func:`initial_texture`).
    levels, start_level : int, optional
        The multi-resolution schedule: sample levels ``start_level .. start_level + levels - 1``.
    tol : float, optional
    max_iter : int, optional
    trace : bool, optional
    accel : int, optional

    Returns
    -------
    X : ndarray, shape (n_unknowns, 2) float64
    stats : list of LevelStats
    runs : list of IterationResult

    Examples
    --------
    >>> from ccproof.mesh.examples import grid
    >>> from ccproof.apps.arap.hierarchy import ChartHierarchy
    >>> h = ChartHierarchy(grid(3, 3), range(9))
    >>> X, stats, runs = optimize_chart(h, "extended", initial_texture(h, "extended"), levels=2)
    >>> X.shape, [s.level for s in stats], all(s.converged for s in stats)
    ((16, 2), [1, 2], True)
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
        res = iterate(sysk, X, tol=tol, max_iter=max_iter, trace=trace, accel=accel)
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
    The method (a) baseline of docs/hsh10.md.

    Parameters
    ----------
    V : ndarray, shape (n, 3) float64
    T : ndarray, shape (t, 3) int64
    UV0 : ndarray, shape (n, 2) float64
        Initial texture.
    engine : {"numpy", "igl"}, optional
    tol : float, optional
    max_iter : int, optional

    Returns
    -------
    UV : ndarray, shape (n, 2) float64
    iterations : int
    converged : bool

    Examples
    --------
    A unit square started 1.3 times too large comes back to its true size:

    >>> import numpy as np
    >>> from ccproof.apps.arap.lscm import triangulate_quads
    >>> V = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0.0]])
    >>> UV, it, ok = polygon_arap(V, triangulate_quads(V, [[0, 1, 2, 3]]), 1.3 * V[:, :2])
    >>> np.round(UV, 9).tolist(), ok
    ([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]], True)
    """
    if engine == "igl":
        return _triangle_arap_igl(V, T, UV0, tol, max_iter)
    if engine != "numpy":
        raise CCProofError(f"unknown ARAP engine {engine!r} (numpy or igl)")
    return _triangle_arap_numpy(V, T, UV0, tol, max_iter)


def lift_to_refined(h: ChartHierarchy, X, rules, fine: ChartHierarchy, times):
    """Texture unknowns of the chart of the ``times`` times refined mesh (``fine``) that give ``X``.

    The level-``times`` values of ``h`` (its ``E_times`` is the refined chart's ``E_0``), matched by
    position: the same texture on the same limit surface (docs/hsh10.md, "(c) and (d)").

    Parameters
    ----------
    h : ChartHierarchy
    X : ndarray, shape (h.n_unknowns(rules), 2) float64
    rules : {"boundary", "extended"}
    fine : ChartHierarchy
        The chart on :func:`~ccproof.apps.arap.meshes.refine_mesh` (mesh, labels, times).
    times : int

    Returns
    -------
    ndarray, shape (fine.n_unknowns(rules), 2) float64

    Examples
    --------
    >>> import numpy as np
    >>> from ccproof.mesh.examples import grid
    >>> from ccproof.apps.arap.hierarchy import ChartHierarchy
    >>> h = ChartHierarchy(grid(3, 3), range(9))
    >>> from ccproof.apps.arap.meshes import refine_mesh
    >>> fm, _ = refine_mesh(grid(3, 3), None, 1)
    >>> fine = ChartHierarchy(fm, range(fm.n_faces))
    >>> X = h.surface.vertices[h.unknown_vertices][:, :2]                     # the identity texture
    >>> Y = lift_to_refined(h, X, "boundary", fine, 1)
    >>> bool(np.abs(Y - fine.surface.vertices[fine.unknown_vertices][:, :2]).max() < 1e-12)
    True
    """
    from scipy.spatial import cKDTree

    L = h.level(times)
    vals = h.subdivide_values(h.lift_unknowns(X, rules), rules, 0, times)
    P = fine.surface.vertices[fine.unknown_vertices[: fine.n_unknowns(rules)]]
    d, idx = cKDTree(L.mesh.vertices).query(P)
    scale = float(np.ptp(P, axis=0).max()) or 1.0
    if d.max() > 1e-9 * scale:
        raise CCProofError("refined chart does not match the subdivided chart (internal error)")
    return vals[idx]


def run_method(h: ChartHierarchy, method, levels=3, start_level=1, solver=Solver(), X0=None):
    """Run one method of hsh10 section 4 on one chart (docs/hsh10.md).

    Parameters
    ----------
    h : ChartHierarchy
    method : {"a", "b", "c", "d"}
    levels, start_level : int, optional
        The multi-resolution schedule of (b) and (c).
    solver : Solver, optional
        Tolerance, iterations, acceleration and the baselines' engine and level.
    X0 : ndarray, shape (n_unknowns, 2), optional
        Initial texture unknowns of (b) / (c) (default: :func:`initial_texture`).

    Returns
    -------
    texture : ChartTexture
    seconds : float
    iterations : int
    stats : list of LevelStats

    Examples
    --------
    >>> from ccproof.mesh.examples import grid
    >>> from ccproof.apps.arap.hierarchy import ChartHierarchy
    >>> tex, seconds, iterations, stats = run_method(ChartHierarchy(grid(3, 3), range(9)), "c", levels=1)
    >>> [round(x, 9) for x in texture_metrics(tex, eval_level=3).as_tuple()]
    [2.0, 2.0, 1.0]
    """
    t0 = time.perf_counter()
    if method in ("b", "c"):
        rules = "boundary" if method == "b" else "extended"
        X0 = initial_texture(h, rules) if X0 is None else X0
        X, stats, _ = optimize_chart(h, rules, X0, levels, start_level, solver.tol, solver.max_iter, solver.trace,
                                     solver.accel)
        tex = ChartTexture(h, rules, 0, h.lift_unknowns(X, rules), X)
        return tex, time.perf_counter() - t0, sum(s.iterations for s in stats), stats
    if method == "a":
        V, T = _chart_triangles(h)
        V = V[:h.n_chart_vertices]
        X, it = _baseline_arap(V, T, solver)
        tex = ChartTexture(h, "boundary", 0, h.lift_unknowns(X, "boundary"), X)
        return tex, time.perf_counter() - t0, it, []
    if method == "d":
        k = int(solver.baseline_level)
        L = h.level(k)
        cv = np.flatnonzero(L.chart_vertex)
        loc = np.full(L.n_vertices, -1, dtype=np.int64)
        loc[cv] = np.arange(cv.size)
        V = L.mesh.vertices[cv]
        X, it = _baseline_arap(V, triangulate_quads(V, loc[L.chart_faces()]), solver)
        vals = np.zeros((L.n_vertices, 2))
        vals[cv] = X
        return ChartTexture(h, "boundary", k, vals, X), time.perf_counter() - t0, it, []
    raise CCProofError(f"unknown method {method!r}; expected one of {METHODS}")


def _baseline_arap(V, T, solver):
    """The polygon baselines: LSCM scaled to the area, then ARAP of the triangles; (UVs, iterations)."""
    UV0 = fit_area(lscm(V, T), V, T)
    X, it, _ = polygon_arap(V, T, UV0, solver.engine, solver.tol, solver.baseline_max_iter)
    return X, it


# --------------------------------------------------------------------------- measuring
def metric_samples(h: ChartHierarchy, level, rules):
    """The metric samples of level ``level`` of ``h`` for ``rules`` (built once, kept on ``h``)."""
    cache = h.__dict__.setdefault("_metric_samples", {})
    key = (level, rules)
    if key not in cache:
        cache[key] = build_samples(h.level(level), rules, "metric")
    return cache[key]


def texture_metrics(tex: ChartTexture, eval_level=5, per_sample=False):
    """The metrics of a chart texture at ``eval_level`` (same samples for every method).

    E_angle, E_area, E_stretch of hsh10 section 4 (docs/hsh10.md); an isometry gives 2, 2, 1.

    Parameters
    ----------
    tex : ChartTexture
    eval_level : int, optional
        Subdivision level of the samples (>= the texture's level).
    per_sample : bool, optional
        Also return the per-sample values.

    Returns
    -------
    Metrics

    Examples
    --------
    >>> from ccproof.mesh.examples import grid
    >>> from ccproof.apps.arap.hierarchy import ChartHierarchy
    >>> tex = run_method(ChartHierarchy(grid(3, 3), range(9)), "c", levels=1)[0]
    >>> m = texture_metrics(tex, eval_level=3)
    >>> [round(x, 9) for x in m.as_tuple()], m.flips
    ([2.0, 2.0, 1.0], 0)
    """
    if eval_level < tex.level:
        raise CCProofError(f"evaluation level {eval_level} is below the texture's level {tex.level}")
    X = tex.hierarchy.subdivide_values(tex.values, tex.rules, tex.level, eval_level)
    S = metric_samples(tex.hierarchy, eval_level, tex.rules)
    return sample_metrics(S, X, per_sample=per_sample)


def control_flips(tex: ChartTexture):
    """(flipped, total) triangles of the texture's control mesh.

    Chart faces at its level, split along the shorter 3D diagonal; flipped = signed texture area <= 0
    (hsh10 section 4).

    Parameters
    ----------
    tex : ChartTexture

    Returns
    -------
    flipped, total : int

    Examples
    --------
    >>> from ccproof.mesh.examples import grid
    >>> from ccproof.apps.arap.hierarchy import ChartHierarchy
    >>> control_flips(run_method(ChartHierarchy(grid(3, 3), range(9)), "c", levels=1)[0])   # 9 quads, 2 triangles each
    (0, 18)
    """
    L = tex.hierarchy.level(tex.level)
    T = triangulate_quads(L.mesh.vertices, L.chart_faces())
    a = signed_areas(tex.values, T)
    return int((a <= 0).sum()), int(T.shape[0])

