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

Multi-resolution schedule: optimize at ``start_level`` until the relative energy decrease
per iteration is below ``tol``, then at the next level warm-started from the current ``T^0``, up
to ``levels``. The default start is level 1 (docs/hsh10.md A6 caution: at level 0 the masks miss the
odd-even modes of regular grids; level 0 is allowed and then regularized if singular).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any, Literal

import numpy as np
from numpy.typing import ArrayLike

from ccproof.apps.arap.charts import charts_from_labels, check_disk
from ccproof.apps.arap.hierarchy import ChartHierarchy
from ccproof.apps.arap.lscm import fit_area, lscm, lscm_extend, signed_areas, triangulate_quads
from ccproof.apps.arap.metrics import Metrics, sample_metrics
from ccproof.apps.arap.samples import build_samples
from ccproof.apps.arap.solver import LocalGlobal, iterate, system_from_samples, triangle_samples
from ccproof.errors import CCProofError

if TYPE_CHECKING:
    from ccproof.mesh import QuadMesh

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
    "refine_mesh",
    "auto_refine",
    "estimate_memory",
    "MemoryBudgetError",
    "run_memory",
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
        Per chart (P, UV, Q) limit samples at ``sample_level`` (see :func:`compare`).
    sample_level : int, optional

    Examples
    --------
    >>> from ccproof.mesh.examples import grid
    >>> res, _ = compare(grid(3, 3), methods=("c",), levels=1, eval_level=3)
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
    #: per chart (P, UV, Q) limit samples at ``sample_level`` (see :func:`compare`), or None
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
        The chart on :func:`refine_mesh` (mesh, labels, times).
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


def run_method(h: ChartHierarchy, method, levels=3, start_level=1, tol=1e-6, max_iter=1000, engine="numpy",
               baseline_level=3, baseline_max_iter=2000, trace=False, X0=None, accel=0):
    """Run one method of hsh10 section 4 on one chart.

    ``X0``: initial texture unknowns of (b) / (c) (default: :func:`initial_texture`); ``accel``:
    Anderson acceleration of (b) / (c) (:func:`~ccproof.apps.arap.solver.iterate`). docs/hsh10.md.

    Parameters
    ----------
    h : ChartHierarchy
    method : {"a", "b", "c", "d"}
    levels, start_level : int, optional
        The multi-resolution schedule.
    tol : float, optional
    max_iter : int, optional
    engine : {"numpy", "igl"}, optional
        ARAP engine of method (a).
    baseline_level, baseline_max_iter : int, optional
        Level and iterations of the polygon baselines (a), (d).
    trace : bool, optional
    X0 : ndarray, shape (n_unknowns, 2), optional
    accel : int, optional

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
        X, stats, _ = optimize_chart(h, rules, X0, levels, start_level, tol, max_iter, trace, accel)
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


# --------------------------------------------------------------------------- whole meshes
def mesh_charts(mesh, labels):
    """Face index arrays of the charts (per-face ``labels``, None: one chart), hole faces left out."""
    hole = getattr(mesh, "hole", None)
    if hole is not None and hole.any():  # hole faces are not part of the surface: in no chart
        if labels is None:
            faces = np.flatnonzero(~hole)
            check_disk(mesh, faces, "the mesh without its holes (one chart; give --charts for a closed or "
                                    "non-disk mesh)")
            return [faces]
        labels = np.where(hole, -1, np.asarray(labels))
    if labels is None:
        faces = np.arange(mesh.n_faces)
        check_disk(mesh, faces, "the mesh (one chart; give --charts for a closed or non-disk mesh)")
        return [faces]
    return charts_from_labels(mesh, labels)


#: measured peak bytes per face of the metric / output level ``E_k`` of one chart (hierarchy, samples,
#: subdivision operators; bunny charts, levels 3-5: 0.9-1.1 kB), with a margin
BYTES_PER_FACE = 1400
#: measured peak bytes per face of the finest optimization level of one chart (samples composed with the
#: unknowns-to-level operator, the normal matrix and its factor; bunny x2 with refine 1: 3.9 kB before
#: the transposed operator stopped being stored), with a margin
OPT_BYTES_PER_FACE = 4000
#: memory of the interpreter and the libraries (numpy, scipy) before any chart
BASE_BYTES = 150e6


def refine_mesh(mesh, labels, times):
    """The control mesh subdivided ``times`` times (the same limit surface) and the children's labels.

    Child ``4 f + i`` of face ``f`` keeps its label.

    Parameters
    ----------
    mesh : QuadMesh
    labels : array_like of int, shape (n_faces,), or None
    times : int

    Returns
    -------
    mesh : QuadMesh or TaggedQuadMesh
        With 4**times as many faces (tags carried: :func:`~ccproof.apps.control_mesh.subdivide_control`).
    labels : ndarray of int64 or None

    Examples
    --------
    >>> from ccproof.mesh.examples import grid
    >>> m, lab = refine_mesh(grid(3, 3), range(9), 1)
    >>> m.n_faces, lab[:8].tolist()
    (36, [0, 0, 0, 0, 1, 1, 1, 1])
    """
    from ccproof.apps.control_mesh import subdivide_control

    lab = None if labels is None else np.asarray(labels)
    for _ in range(int(times)):
        mesh = subdivide_control(mesh)  # tags carried (a TaggedQuadMesh stays one)
        if lab is not None:
            lab = np.repeat(lab, 4)
    return mesh, lab


def auto_refine(mesh, labels, faces_per_chart=1000):
    """The measured default of ``refine``: the smallest r in 0..2 with at least ``faces_per_chart``
    control faces per chart after r subdivisions (docs/hsh10.md, "(c) and (d)").

    Parameters
    ----------
    mesh : QuadMesh
    labels : array_like of int or None
    faces_per_chart : int, optional

    Returns
    -------
    int

    Examples
    --------
    9 faces: 36 after one subdivision, 144 after two (the most):

    >>> from ccproof.mesh.examples import grid
    >>> auto_refine(grid(3, 3), None, 10), auto_refine(grid(3, 3), None, 100), auto_refine(grid(3, 3), None, 10**6)
    (1, 2, 2)
    """
    n_charts = len(mesh_charts(mesh, labels))
    per = mesh.n_faces / max(n_charts, 1) if labels is None else (np.asarray(labels) >= 0).sum() / max(n_charts, 1)
    r = 0
    while r < 2 and per * 4**r < faces_per_chart:
        r += 1
    return r


def estimate_memory(hierarchies, deepest_level, release=True, opt_level=None):
    """Estimated peak bytes of a run (linear in the faces).

    :data:`BYTES_PER_FACE` per face of ``E_deepest`` (metrics, output) and :data:`OPT_BYTES_PER_FACE` per
    face of ``E_opt_level`` (optimization), for the largest chart (``release``: charts are processed one
    at a time) or all charts, plus :data:`BASE_BYTES`.

    Parameters
    ----------
    hierarchies : list of ChartHierarchy
    deepest_level : int
    release : bool, optional
    opt_level : int, optional

    Returns
    -------
    float
        Bytes.

    Examples
    --------
    >>> from ccproof.mesh.examples import grid
    >>> from ccproof.apps.arap.hierarchy import ChartHierarchy
    >>> h = ChartHierarchy(grid(3, 3), range(9))
    >>> estimate_memory([h], 3) == BASE_BYTES + BYTES_PER_FACE * h.n_faces(3)
    True
    """
    def need(k, per):
        if k is None:
            return 0.0
        faces = [h.n_faces(k) for h in hierarchies]
        return per * (max(faces) if release else sum(faces))

    return BASE_BYTES + max(need(deepest_level, BYTES_PER_FACE), need(opt_level, OPT_BYTES_PER_FACE))


def run_memory(hierarchies, methods, levels, eval_level, sample_level=None, refine=0, baseline_level=3,
               release=True):
    """(bytes, deepest level, optimization level) of :func:`compare` with these options: the estimate it checks
    against ``max_memory`` before allocating (:func:`estimate_memory`), and the levels it counts.

    >>> from ccproof.mesh.examples import grid
    >>> from ccproof.apps.arap.hierarchy import ChartHierarchy
    >>> h = ChartHierarchy(grid(3, 3), range(9))
    >>> need, deepest, opt = run_memory([h], ("c",), 2, 4, refine=1)
    >>> (deepest, opt), need == estimate_memory([h], 4, True, 2)
    ((4, 2), True)
    """
    deepest = max([eval_level] + ([sample_level] if sample_level is not None else [])
                  + ([baseline_level] if "d" in methods else []))
    opt = None
    if any(m in ("b", "c") for m in methods):
        opt = max(levels, int(refine) + 1) if refine else levels
    return estimate_memory(hierarchies, deepest, release, opt), deepest, opt


class MemoryBudgetError(CCProofError):
    """The estimated memory of a run exceeds the budget (raised before allocating).

    Parameters
    ----------
    message : str
        The estimate and the budget.

    Examples
    --------
    >>> issubclass(MemoryBudgetError, CCProofError)
    True
    """


def compare(mesh, labels=None, methods=METHODS, levels=3, start_level=1, eval_level=5, tol=1e-6, max_iter=1000,
            engine="numpy", baseline_level=3, baseline_max_iter=2000, hierarchies=None, trace=False,
            refine=0, sample_level=None, release=False, max_memory=None, progress=False, accel=0):
    """Run ``methods`` on every chart and measure them the same way.

    Parameters
    ----------
    levels, start_level, eval_level : int
        Optimization and metric levels, counted on the input mesh.
    refine : int >= 0
        Subdivide the control mesh ``refine`` times before optimizing (b) and (c) (more texture unknowns,
        the same surface and the same metric samples); their optimization levels are then
        ``max(start_level, refine + 1) .. max(levels, refine + 1)`` on the input mesh, i.e. from level 1
        of the refined mesh (level 0 misses odd-even modes), warm-started from the input mesh's
        optimization at levels ``start_level .. refine`` (:func:`lift_to_refined`: the same texture
        on the refined unknowns). (a) and (d) use the input mesh.
    sample_level : int, optional
        Also keep every chart's limit samples at this level (:func:`~ccproof.apps.arap.export.sample_chart`)
        in ``MethodResult.samples`` (computed before ``release``).
    release : bool
        Process the charts one at a time and drop their fine levels afterwards (peak memory of the
        largest chart instead of the sum).
    max_memory : float, optional
        Bytes; raise :class:`MemoryBudgetError` before allocating when :func:`estimate_memory` exceeds it.
    progress : bool
        A tqdm progress bar over (chart, method).
    accel : int
        Anderson acceleration history for (b) and (c) (0: the plain local/global iteration; the CLI
        uses 5). (a) and (d) are never accelerated (they are the baselines as published).

    Returns
    -------
    dict method -> MethodResult, and the list of ChartHierarchy of the input mesh (reusable)

    Examples
    --------
    A flat grid has an isometric texture, E_angle = E_area = 2, E_stretch = 1 (their minima):

    >>> from ccproof.mesh.examples import grid
    >>> res, hierarchies = compare(grid(3, 3), methods=("b", "c"), levels=1, eval_level=3)
    >>> [[round(x, 9) for x in res[m].metrics.as_tuple()] for m in "bc"], len(hierarchies)
    ([[2.0, 2.0, 1.0], [2.0, 2.0, 1.0]], 1)
    """
    charts = mesh_charts(mesh, labels)
    if hierarchies is None:
        hierarchies = [ChartHierarchy(mesh, fc) for fc in charts]
    refine = int(refine)
    if refine < 0:
        raise CCProofError(f"refine must be >= 0, got {refine}")
    fine = {}
    if refine and any(m in ("b", "c") for m in methods):
        rmesh, rlab = refine_mesh(mesh, labels, refine)
        fine = {"hierarchies": [ChartHierarchy(rmesh, fc) for fc in mesh_charts(rmesh, rlab)],
                "start": max(start_level, refine + 1) - refine, "levels": max(levels, refine + 1) - refine}
    need, deepest, opt = run_memory(hierarchies, methods, levels, eval_level, sample_level, refine,
                                    baseline_level, release)
    if max_memory is not None and need > max_memory:
        big = int(np.argmax([h.n_faces(0) for h in hierarchies]))
        raise MemoryBudgetError(
            f"estimated peak memory {need / 1e9:.2f} GB exceeds the budget {max_memory / 1e9:.2f} GB "
            f"(--max-memory): chart {big} has {hierarchies[big].n_faces(max(deepest, opt or 0)):,} faces at level "
            f"{max(deepest, opt or 0)}; lower --eval-level / --levels / --out-level (each level less divides it "
            f"by 4), or use smaller charts")
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=len(hierarchies) * len(methods), desc="arap", unit="chart")
    acc: dict[str, dict[str, Any]] = {
        m: {"texs": [], "secs": 0.0, "its": 0, "lv": [], "met": Metrics(), "fl": 0, "tot": 0, "samples": []}
        for m in methods}
    try:
        for i, h in enumerate(hierarchies):
            for m in methods:
                if bar is not None:
                    bar.set_postfix(method=m, chart=i)
                X0, sec0, it0, st0 = None, 0.0, 0, []
                if fine and m in ("b", "c"):
                    hm, st, lv, ev = fine["hierarchies"][i], fine["start"], fine["levels"], eval_level - refine
                    if start_level <= refine:  # multi-resolution: the input mesh's levels below the refined ones
                        t0 = time.perf_counter()
                        texc, _, it0, st0 = run_method(h, m, refine, start_level, tol, max_iter, engine,
                                                       accel=accel)
                        X0 = lift_to_refined(h, texc.unknowns, texc.rules, hm, refine)
                        sec0 = time.perf_counter() - t0
                else:
                    hm, st, lv, ev = h, start_level, levels, eval_level
                if ev < 0:
                    raise CCProofError(f"eval_level {eval_level} is below refine {refine}")
                tex, sec, it, stt = run_method(hm, m, lv, st, tol, max_iter, engine, baseline_level,
                                               baseline_max_iter, trace, X0=X0, accel=accel)
                if hm is not h:  # level numbers on the input mesh
                    stt = [replace(x, level=x.level + refine) for x in stt]
                sec, it, stt = sec + sec0, it + it0, st0 + stt
                a = acc[m]
                a["texs"].append(tex)
                a["secs"] += sec
                a["its"] += it
                a["lv"].append(stt)
                a["met"] = a["met"] + texture_metrics(tex, ev)
                f, t = control_flips(tex)
                a["fl"] += f
                a["tot"] += t
                if sample_level is not None:
                    from ccproof.apps.arap.export import sample_chart

                    off = refine if hm is not h else 0
                    sl = max(sample_level - off, tex.level)  # (d) lives at level 3
                    a["samples"].append(sample_chart(tex, sl))
                    a["sample_level"] = sl + off
                if release and hm is not h:
                    hm.release()
                if bar is not None:
                    bar.update(1)
            if release:
                h.release()
    finally:
        if bar is not None:
            bar.close()
    out = {}
    for m in methods:
        a = acc[m]
        r = MethodResult(m, a["texs"], a["secs"], a["its"], levels=a["lv"])
        r.metrics, r.flips_control, r.triangles_control = a["met"], a["fl"], a["tot"]
        r.refine = refine if (fine and m in ("b", "c")) else 0
        r.samples = a["samples"] if sample_level is not None else None
        r.sample_level = a.get("sample_level", sample_level)
        out[m] = r
    return out, hierarchies


def parameterize(mesh: QuadMesh, labels: ArrayLike | None = None, variant: Literal["extended", "boundary"] = "extended",
                 levels: int = 3, start_level: int = 1, eval_level: int = 5, tol: float = 1e-6, max_iter: int = 1000
                 ) -> MethodResult:
    """hsh10 parameterization of every chart: variant "extended" (c) or "boundary" (b).

    The texture minimizing the ARAP energy of the limit surface (hsh10 Eq. 1), optimized level by level
    (module docstring) and measured with :func:`texture_metrics`; the methods "a", "d" and the
    comparison are :func:`compare`.

    Parameters
    ----------
    mesh : QuadMesh
        The control mesh; without ``labels`` it must be a disk (one chart).
    labels : array_like of int, shape (n_faces,), optional
        Chart label of every face (negative: in no chart); every chart must be a disk.
    variant : {"extended", "boundary"}
        hsh10's extended charts (method "c") or boundary rules (method "b").
    levels, start_level, eval_level : int
        Last and first optimization level, and the level of the metric samples (docs/hsh10.md A9).
    tol : float
        Relative energy decrease per iteration below which a level stops.
    max_iter : int
        Iterations per level at most.

    Returns
    -------
    MethodResult
        ``textures``: one :class:`ChartTexture` per chart (``values`` of shape (n_unknowns, 2), the texture
        coordinates of the chart's control points at level ``level``), ``metrics``: E_angle, E_area,
        E_stretch (hsh10 section 6), ``iterations``, ``seconds``, flipped control triangles.

    Examples
    --------
    A planar grid is developable: its parameterization is an isometry, where E_angle and E_area reach
    their minimum 2 and E_stretch its minimum 1 (docs/hsh10.md A9):

    >>> from ccproof.mesh.examples import grid
    >>> res = parameterize(grid(3, 3), levels=1, eval_level=2)
    >>> res.textures[0].values.shape, [round(e, 6) for e in res.metrics.as_tuple()], res.metrics.flips
    ((16, 2), [2.0, 2.0, 1.0], 0)
    """
    if variant not in VARIANTS:
        raise CCProofError(f"unknown variant {variant!r}; expected one of {tuple(VARIANTS)}")
    res, hs = compare(mesh, labels, (VARIANTS[variant],), levels, start_level, eval_level, tol, max_iter)
    return res[VARIANTS[variant]]
