"""Control UVs that a standard face-varying subdivision reproduces (OpenSubdiv "corners only").

A tool that subdivides a textured control mesh (OpenSubdiv, Blender, Maya, RenderMan, ...) subdivides the
UVs with a *face-varying* rule: every chart is a separate mesh of UV values, its boundary a crease.
OpenSubdiv's ``Sdc::Options::FVAR_LINEAR_CORNERS_ONLY`` (its ``Vtr::FVarLevel``, with the default
``VTX_BOUNDARY_EDGE_ONLY``) is: interior values follow the vertex's Catmull-Clark rules; a value on a
chart boundary whose span around its vertex has two or more faces is a smooth crease (edge points of
chart boundary edges are midpoints, the value becomes ``(e0 + 6 V + e1) / 8`` with ``e0, e1`` its two
chart-boundary neighbours; limit ``(e0 + 4 V + e1) / 6``); a value whose span is one face is a sharp
corner (``V' = V``), also at a one-face corner of an open surface. These are the boundary rules of
:class:`~ccproof.apps.arap.hierarchy.ChartHierarchy` with ``surface_corners=True``.

hsh10's extended charts (c) subdivide the texture with the *surface's* rules across the chart boundary
(chart plus ring, docs/hsh10.md A8): no standard rule reproduces them, and the control UVs of (c) fold
when a tool subdivides them with its own rule. :func:`export_control` therefore writes control UVs *for*
the corners-only rule. Per chart: the least-squares fit of the corners-only texture's limit UVs to the
exact texture's limit UVs at the level-``fit_level`` vertices of the chart (:func:`corners_only_texture`,
uniform weights, sparse normal equations), polished by hsh10's own optimization under the corners-only
rules (where that folds, the nearest blend towards the fit that does not). It counts the folds of the
subdivided UVs at levels 1..3 (what a tool renders, :func:`subdivided_folds`) and measures the texture
with the same samples as the exact one (:func:`~ccproof.apps.arap.core.texture_metrics`). When the UVs
on the texture's control mesh fold, or a distortion excess exceeds ``max_excess_ratio`` times the exact
texture's, the control mesh is subdivided once more (the same limit surface, 4x the faces and UVs) and
fitted again, up to ``max_extra`` times. Where even the last refinement allowed misses the ratio, the
distortion the metrics measure is minimized (:func:`metric_polish`) with a few weightings of the three excesses
(:data:`METRIC_WEIGHTS`), and every chart keeps the candidate (ARAP polish or one of these) that makes the
largest of the three global excess ratios smallest (a minimax over the charts' choices: one weighting only
trades E_angle against E_area and E_stretch, mixing them across charts balances the three).
The excess sits mostly at the chart boundary's concave corners (a value whose span has k of its vertex's n
faces, k / n > 1/2): the rule keeps the boundary a smooth crease there, a texture angle of pi where the
surface's is 2 pi k / n, which costs a fixed amount per corner in units of the local control faces' area.

The inner 3 x 3 faces of a flat 5 x 5 grid as one chart: the exact texture is an isometry, and so is the
corners-only one (on a uniform flat grid every rule reproduces affine functions at the same points):

>>> import numpy as np
>>> from ccproof.mesh.examples import grid
>>> from ccproof.apps.arap.meshes import LevelPlan, compare
>>> labels = -np.ones(25, dtype=int)
>>> labels[[6, 7, 8, 11, 12, 13, 16, 17, 18]] = 0
>>> res, _ = compare(grid(5, 5), labels, methods=("c",), plan=LevelPlan(levels=1, eval_level=3))
>>> exp = export_control(res["c"], eval_level=3)
>>> exp.extra, exp.folds, [round(x, 9) for x in exp.metrics.as_tuple()]
(0, [0, 0, 0], [2.0, 2.0, 1.0])
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.sparse.linalg as spla

from ccproof.apps.arap.hierarchy import ChartHierarchy
from ccproof.apps.arap.lscm import signed_areas
from ccproof.apps.arap.metrics import Metrics, excess_ratios, minimax_choice
from ccproof.apps.arap.samples import limit_operator
from ccproof.apps.arap.solver import lbfgs
from ccproof.errors import CCProofError

__all__ = ["corners_only_texture", "subdivided_folds", "metric_polish", "ControlExport", "ControlOptions",
           "export_control",
           "FOLD_LEVELS", "EXCESS_FLOOR", "METRIC_WEIGHTS"]

#: distortion excesses below this are not told apart (an isometric exact texture)
EXCESS_FLOOR = 1e-9
#: the subdivision levels at which the folds of the subdivided control UVs are counted
FOLD_LEVELS = (1, 2, 3)
#: the minimax candidates of :func:`export_control`: (E_angle, E_stretch) weights of :func:`metric_polish`, times
#: the reciprocal of the exact texture's excess (E_area's weight: its reciprocal). On the bunny (16 charts,
#: default refinement, 1 extra) these three and the ARAP polish, chosen per chart, gave a largest excess ratio
#: of 1.038 (written: 1.038, 1.038, 1.034); any single weighting for every chart at best 1.058
#: (docs/hsh10.md section 8.1).
METRIC_WEIGHTS = ((1.3, 1.0), (1.6, 1.0), (2.0, 2.0))


def _refined_chart(h: ChartHierarchy, times, mesh=None):
    """The chart of ``h`` on its control mesh subdivided ``times`` times (children 4^t f .. 4^t f + 4^t - 1)."""
    from ccproof.apps.arap.meshes import refine_mesh

    if mesh is None:
        mesh, _ = refine_mesh(h.surface, None, times)
    q = 4 ** int(times)
    faces = (q * h.chart_faces[:, None] + np.arange(q)).ravel()
    return ChartHierarchy(mesh, faces, surface_corners=True), mesh


def corners_only_texture(tex, times=0, fit_level=2, mesh=None):
    """Corners-only control UVs fitted to a chart texture (module docstring).

    Parameters
    ----------
    tex : :class:`~ccproof.apps.arap.core.ChartTexture`
        A level-0 texture (``rules`` "extended" or "boundary").
    times : int >= 0
        Subdivide the chart's control mesh this many times first.
    fit_level : int >= 1
        Level (of the subdivided control mesh) of the limit samples of the least-squares fit.
    mesh : QuadMesh, optional
        The control mesh subdivided ``times`` times, if already computed.

    Returns
    -------
    hierarchy : ChartHierarchy
        The chart on the subdivided control mesh (boundary rules with ``surface_corners=True``).
    Y : ndarray, shape (hierarchy.n_chart_vertices, 2) float64
        The control UVs of its chart vertices.

    Examples
    --------
    A texture that is affine on the chart is reproduced exactly (every rule preserves affine functions):

    >>> import numpy as np
    >>> from ccproof.mesh.examples import grid
    >>> from ccproof.apps.arap.core import ChartTexture
    >>> h = ChartHierarchy(grid(4, 4), [5, 6, 9, 10])
    >>> X = h.surface.vertices[h.unknown_vertices][:, :2] @ np.array([[2.0, 1], [0, 1]])
    >>> hc, Y = corners_only_texture(ChartTexture(h, "extended", 0, h.lift_unknowns(X, "extended"), X))
    >>> bool(np.abs(Y - X[: h.n_chart_vertices]).max() < 1e-12)
    True
    """
    if tex.level != 0:
        raise CCProofError(f"only level-0 textures have control UVs (this one lives at level {tex.level})")
    h = tex.hierarchy
    times, fit_level = int(times), int(fit_level)
    if times < 0 or fit_level < 1:
        raise CCProofError(f"times must be >= 0 and fit_level >= 1, got {times}, {fit_level}")
    from ccproof.apps.arap.core import lift_to_refined

    hc, _ = _refined_chart(h, times, mesh)
    X = lift_to_refined(h, tex.unknowns, tex.rules, hc, times) if times else tex.unknowns
    L = hc.level(fit_level)
    cv = np.flatnonzero(L.chart_vertex)
    U = (limit_operator(L, tex.rules) @ (hc.operator(fit_level, tex.rules) @ X))[cv]
    A = (limit_operator(L, "boundary") @ hc.operator(fit_level, "boundary")).tocsr()[cv]
    N = (A.T @ A).tocsc()
    Y = spla.splu(N).solve(np.asarray(A.T @ U))
    return hc, Y


def subdivided_folds(hierarchy: ChartHierarchy, Y, levels=FOLD_LEVELS):
    """Folded UV quads of the chart's corners-only subdivision at each of ``levels``.

    A quad folds when one of its four corner triangles has a signed UV area <= 0 (whatever diagonal a
    tool triangulates along, the quad then has a non-positive triangle or is not convex).

    Parameters
    ----------
    hierarchy : ChartHierarchy
    Y : ndarray, shape (hierarchy.n_chart_vertices, 2) float64
        Control UVs of the chart vertices.
    levels : sequence of int

    Returns
    -------
    list of int

    Examples
    --------
    >>> from ccproof.mesh.examples import grid
    >>> h = ChartHierarchy(grid(3, 3), range(9))
    >>> Y = h.surface.vertices[h.unknown_vertices][:, :2]
    >>> subdivided_folds(h, Y), subdivided_folds(h, Y[:, ::-1])          # mirrored: every quad folds
    ([0, 0, 0], [36, 144, 576])
    """
    out = []
    X0 = hierarchy.lift_unknowns(Y, "boundary")
    for lv in levels:
        X = hierarchy.subdivide_values(X0, "boundary", 0, lv)
        Q = hierarchy.level(lv).chart_faces()
        bad = np.zeros(Q.shape[0], dtype=bool)
        for i in range(4):
            T = Q[:, [i, (i + 1) % 4, (i + 3) % 4]]
            bad |= signed_areas(X, T) <= 0
        out.append(int(bad.sum()))
    return out


def _metric_system(hierarchy: ChartHierarchy, level):
    """Sparse ``B1, B2`` (s, n_c) with grad phi_j = (B1 Y, B2 Y)_j in the isometric frames of the level-``level``
    metric samples (the samples of :func:`~ccproof.apps.arap.core.texture_metrics`), and their weights."""
    import scipy.sparse as sp

    from ccproof.apps.arap.core import metric_samples
    from ccproof.apps.arap.samples import isometric_frames

    S = metric_samples(hierarchy, level, "boundary")
    ok = S.weight > 1e-14 * S.weight.max()
    A = hierarchy.operator(level, "boundary")
    G1 = (S.O1 @ A).tocsr()[ok]
    G2 = (S.O2 @ A).tocsr()[ok]
    a, b, c = isometric_frames(S.p1[ok], S.p2[ok])
    B1 = (sp.diags(1.0 / a) @ G1).tocsr()
    B2 = (sp.diags(1.0 / c) @ (G2 - sp.diags(b / a) @ G1)).tocsr()
    return B1, B2, S.weight[ok]


def _metric_energy(B1, B2, w, weights):
    """f(Y) and its gradient: the weighted distortion excess of the samples, +inf where a sample folds.

    With J = (B1 Y, B2 Y), F = |J|_F^2, D = det J: E_angle's integrand s1/s2 + s2/s1 = F / D, E_area's
    s1 s2 + 1/(s1 s2) = D + 1/D, E_stretch's (1/s1^2 + 1/s2^2) / 2 = F / (2 D^2); the chart's squared stretch
    (sum w F/(2D^2)) (sum w D) / A^2 (texture area element w D).
    f = wa sum w (F/D - 2) + wr sum w (D + 1/D - 2) + ws A (E_stretch^2 - 1) / 2.
    """
    wa, wr, ws = weights
    A = float(w.sum())

    def f(y):
        Y = y.reshape(-1, 2)
        P, Q = B1 @ Y, B2 @ Y  # columns of J: J = [[P0, Q0], [P1, Q1]]
        D = P[:, 0] * Q[:, 1] - Q[:, 0] * P[:, 1]
        if not np.all(D > 0):
            return np.inf, None
        F = (P * P).sum(1) + (Q * Q).sum(1)
        st = F / (2 * D * D)
        Ps, Ds = float(w @ st), float(w @ D)
        val = wa * float(w @ (F / D - 2)) + wr * float(w @ (D + 1 / D - 2)) + ws * (Ps * Ds / A - A) / 2
        # d/dJ: dF = 2 J, dD = cof J = [[Q1, -P1], [-Q0, P0]] (columns P, Q)
        cP = np.stack([Q[:, 1], -Q[:, 0]], 1)
        cQ = np.stack([-P[:, 1], P[:, 0]], 1)
        gF = wa * w / D + ws * (Ds / A) * w / (2 * D * D) / 2
        gD = (wa * w * (-F / D**2) + wr * w * (1 - 1 / D**2)
              + ws / 2 * ((Ds / A) * w * (-F / D**3) + (Ps / A) * w))
        gP = 2 * gF[:, None] * P + gD[:, None] * cP
        gQ = 2 * gF[:, None] * Q + gD[:, None] * cQ
        return val, np.asarray(B1.T @ gP + B2.T @ gQ).ravel()

    return f


def metric_polish(hierarchy: ChartHierarchy, Y, level, weights=(1.0, 1.0, 1.0), max_iter=300):
    """Control UVs that minimize the distortion excess of their corners-only texture at ``level``.

    The energy is the one :func:`~ccproof.apps.arap.core.texture_metrics` measures, on the same samples:
    ``wa (E_angle - 2) + wr (E_area - 2) + ws (E_stretch^2 - 1) / 2`` times the chart's area (hsh10 section 4),
    a barrier against folds at the samples (E_angle and E_area are infinite where det grad phi -> 0), minimized
    by L-BFGS from ``Y`` (which must not fold at the samples).

    Parameters
    ----------
    hierarchy : ChartHierarchy
        Corners-only rules (``surface_corners=True``).
    Y : ndarray, shape (hierarchy.n_chart_vertices, 2) float64
    level : int >= 1
    weights : (wa, wr, ws)
        E.g. the reciprocals of the exact texture's excesses.
    max_iter : int

    Returns
    -------
    ndarray, shape (hierarchy.n_chart_vertices, 2) float64
        ``Y`` itself where it folds at the samples.

    Examples
    --------
    A sheared texture of a flat grid (the whole surface one chart) ends with less angle distortion than even
    the identity's (whose corners-only texture is not an isometry near the surface's corners):

    >>> from ccproof.mesh.examples import grid
    >>> from ccproof.apps.arap.core import ChartTexture, texture_metrics
    >>> h = ChartHierarchy(grid(4, 4), range(16), surface_corners=True)
    >>> I = h.surface.vertices[h.unknown_vertices[: h.n_chart_vertices], :2]
    >>> X = I @ np.array([[1.0, 0.3], [0, 1]])
    >>> Y = metric_polish(h, X, 2)
    >>> tex = lambda Z: ChartTexture(h, "boundary", 0, h.lift_unknowns(Z, "boundary"), Z)
    >>> e_x, e_i, e_y = (texture_metrics(tex(Z), 2).E_angle for Z in (X, I, Y))
    >>> bool(e_y < e_i < e_x), round(e_x, 4), round(e_i, 4), round(e_y, 4)
    (True, 2.0986, 2.0083, 2.0036)
    """
    B1, B2, w = _metric_system(hierarchy, int(level))
    f = _metric_energy(B1, B2, w, weights)
    y0 = np.asarray(Y, dtype=np.float64).ravel()
    if not np.isfinite(f(y0)[0]):
        return np.asarray(Y, dtype=np.float64)
    y, _ = lbfgs(f, y0, max_iter=max_iter)
    return y.reshape(-1, 2)


@dataclass
class ControlExport:
    """Control UVs for the corners-only rule (:func:`export_control`).

    Attributes
    ----------
    mesh : QuadMesh
        The control mesh the UVs belong to (the texture's control mesh subdivided ``extra`` times).
    textures : list of ChartTexture
        Per chart: rules "boundary" (corners only), level 0, ``unknowns`` = the control UVs (n_c, 2).
    extra : int
        Subdivisions of the texture's control mesh.
    folds : list of int
        Folded UV quads at the levels :data:`FOLD_LEVELS` of the written control mesh, all charts.
    metrics : Metrics
        The corners-only texture measured like the exact one (same level, same samples).
    level : int
        The metric level, on the input mesh.
    exact : Metrics
        The exact texture at the same samples.
    tried : list of (extra, folds, metrics)
        Every refinement tried (its final UVs).
    accepted : bool
        Whether ``extra`` met the criterion (no fold, excess within the ratio) or is the best of those tried.
    chart_weights : list
        Per chart of the written UVs: None for the ARAP polish, else the :data:`METRIC_WEIGHTS` entry of the
        :func:`metric_polish` candidate the minimax chose.
    arap_metrics : Metrics or None
        Where the minimax ran on the written refinement: its ARAP polish alone (all charts), else None.
    """

    mesh: object
    textures: list
    extra: int
    folds: list
    metrics: Metrics
    exact: Metrics
    level: int = 0
    tried: list = field(default_factory=list)
    accepted: bool = False
    chart_weights: list = field(default_factory=list)
    arap_metrics: Metrics | None = None

    def excess_ratio(self):
        """(E_angle, E_area, E_stretch) excess of the corners-only texture over the exact texture's."""
        return excess_ratios(self.metrics, self.exact)


@dataclass(frozen=True)
class ControlOptions:
    """How :func:`export_control` fits, polishes and judges the control UVs of each refinement it tries.

    Parameters
    ----------
    max_extra : int
        Subdivide the texture's control mesh at most this many more times.
    max_faces : int, optional
        Do not subdivide the control mesh beyond this many faces.
    max_excess_ratio : float
        Accept the first refinement with no fold at :data:`FOLD_LEVELS` and every distortion excess
        (E_angle - 2, E_area - 2, E_stretch - 1) at most this times the exact texture's (or at most
        :data:`EXCESS_FLOOR` where the exact texture's excess is below it).
    fit_level : int
        Level of the fit's samples (:func:`corners_only_texture`).
    polish : bool
        Polish the fit with hsh10's optimization under the corners-only rules.
    accel : int
        Anderson acceleration of the polish.
    metric : "auto", True or False
        The minimax over :func:`metric_polish` candidates: "auto" on the last refinement allowed (by
        ``max_extra`` and ``max_faces``) when the ARAP polish misses the criterion there; True on every
        refinement whose ARAP polish misses it; False never. It costs ``len(METRIC_WEIGHTS)`` L-BFGS runs per
        chart (the bunny at its default refinement: 1,249 s against 198-514 s without it, on a loaded machine).
    metric_iter : int
        L-BFGS iterations of each candidate per chart.

    Examples
    --------
    >>> ControlOptions(max_extra=0).metric
    'auto'
    """

    max_extra: int = 2
    max_faces: int | None = None
    max_excess_ratio: float = 1.05
    fit_level: int = 2
    polish: bool = True
    accel: int = 5
    metric: str | bool = "auto"
    metric_iter: int = 300


def export_control(result, eval_level=5, levels=3, options=None, progress=False):
    """Corners-only control UVs for every chart of ``result`` (module docstring).

    Per chart: the least-squares fit of :func:`corners_only_texture`, then (``options.polish``) hsh10's
    local/global optimization with the corners-only rules (method (b) on the subdivided control mesh,
    :func:`~ccproof.apps.arap.core.optimize_chart`) started from it; the polished UVs are kept when their
    subdivision has no fold at :data:`FOLD_LEVELS`, else the first blend ``Y2 + t (Y_fit - Y2)``, t = 0.25,
    0.5, 0.75, that has none, else the fit's (or whichever folds least). Where that misses
    ``options.max_excess_ratio`` (see ``options.metric``): per chart the :func:`metric_polish` candidates of
    :data:`METRIC_WEIGHTS` (from the ARAP polish, or from the kept UVs where the polish folds at the samples),
    those without a fold at :data:`FOLD_LEVELS` kept, and per chart the candidate (ARAP included) that
    minimizes the largest of the three global excess ratios (coordinate descent over the charts' choices from
    every uniform start; never worse than the ARAP polish alone).

    Parameters
    ----------
    result : :class:`~ccproof.apps.arap.core.MethodResult`
        Method (b) or (c) (level-0 textures).
    eval_level : int
        Metric level on the input mesh (the texture's control mesh is the input refined
        ``result.refine`` times); raised to level 1 of the subdivided control mesh where it is below.
    levels : int
        Finest optimization level of the polish, counted on the input mesh (at least level 1 of the
        subdivided control mesh).
    options : ControlOptions, optional
        Refinements allowed, acceptance, fit, polish and minimax (default ``ControlOptions()``).
    progress : bool
        A tqdm progress bar over the charts of each refinement tried.

    Returns
    -------
    ControlExport
        The accepted refinement, or the best one tried (fewest folds, then smallest largest excess ratio).
    """
    from ccproof.apps.arap.meshes import refine_mesh

    opts = ControlOptions() if options is None else options
    if opts.metric not in ("auto", True, False):
        raise CCProofError(f"metric must be 'auto', True or False, got {opts.metric!r}")
    texs = result.textures
    if not texs or any(t.level != 0 for t in texs):
        raise CCProofError("control UVs need level-0 textures (methods b and c)")
    if int(opts.max_extra) < 0:
        raise CCProofError(f"max_extra must be >= 0, got {opts.max_extra}")
    ref = int(getattr(result, "refine", 0))
    tried, best, exacts, mesh, ok = [], None, {}, texs[0].hierarchy.surface, False
    for extra in range(int(opts.max_extra) + 1):
        if extra:
            if opts.max_faces is not None and 4 * mesh.n_faces > opts.max_faces:
                break
            mesh, _ = refine_mesh(mesh, None, 1)
        last = extra == int(opts.max_extra) or (opts.max_faces is not None and 4 * mesh.n_faces > opts.max_faces)
        # metric level on the input mesh: eval_level, at least level 1 of the subdivided control mesh
        e_in = max(int(eval_level), ref + extra + 1)
        if e_in not in exacts:
            exacts[e_in] = _exact_metrics(texs, e_in - ref)
        step = _Refinement(mesh, extra, e_in - ref - extra, exacts[e_in], opts)
        step.polish(texs, max(1, int(levels) - ref - extra), progress)
        if not step.accepted() and (opts.metric is True or (opts.metric == "auto" and last)):
            step.minimax(progress)
        ok = step.accepted()
        exp = step.export(e_in)
        tried.append((extra, exp.folds, exp.metrics))
        key = (sum(exp.folds), max(exp.excess_ratio()))
        if best is None or key < best[0] or ok:
            best = (key, exp)
        if ok:
            break
    exp = best[1]
    exp.tried = tried
    exp.accepted = bool(ok)
    return exp


def _exact_metrics(texs, ev):
    """The metrics of the exact textures at level ``ev`` of their control mesh (fine levels released)."""
    from ccproof.apps.arap.core import texture_metrics

    exact = Metrics()
    for tex in texs:
        exact = exact + texture_metrics(tex, ev)
        tex.hierarchy.release()
    return exact


def _bar(progress, total, desc):
    if not progress:
        return None
    from tqdm import tqdm

    return tqdm(total=total, desc=desc, unit="chart")


class _Refinement:
    """One refinement tried by :func:`export_control`: its charts' UVs, folds and metrics at level ``ev_x`` of
    the subdivided control mesh ``mesh``, judged against the exact textures' metrics ``exact``."""

    def __init__(self, mesh, extra, ev_x, exact, opts):
        self.mesh, self.extra, self.ev_x, self.exact, self.opts = mesh, extra, ev_x, exact, opts
        self.ex_e = np.subtract(exact.as_tuple(), (2.0, 2.0, 1.0))
        self.folds = np.zeros(len(FOLD_LEVELS), dtype=np.int64)
        self.met, self.out, self.charts = Metrics(), [], []
        self.weights, self.arap_met = [], None

    def measure(self, hc, Y):
        from ccproof.apps.arap.core import ChartTexture, texture_metrics

        ct = ChartTexture(hc, "boundary", 0, hc.lift_unknowns(Y, "boundary"), Y)
        return ct, texture_metrics(ct, self.ev_x)

    def accepted(self):
        ex_m = np.subtract(self.met.as_tuple(), (2.0, 2.0, 1.0))
        return sum(self.folds) == 0 and bool(np.all(
            ex_m <= np.maximum(self.opts.max_excess_ratio * self.ex_e, EXCESS_FLOOR)))

    def polish(self, texs, top, progress):
        """Per chart: the corners-only fit, polished (the polish or the nearest blend towards the fit that
        does not fold)."""
        from ccproof.apps.arap.core import optimize_chart

        bar = _bar(progress, len(texs), f"control UVs, {self.extra} extra")
        for tex in texs:
            hc, Y = corners_only_texture(tex, self.extra, self.opts.fit_level, self.mesh)
            fo = subdivided_folds(hc, Y)
            Y2 = Y
            if self.opts.polish:
                Y2, _, _ = optimize_chart(hc, "boundary", Y, levels=top, start_level=1, accel=self.opts.accel)
                for t in (0.0, 0.25, 0.5, 0.75):
                    Yt = Y2 + t * (Y - Y2)
                    fot = subdivided_folds(hc, Yt)
                    if sum(fot) == 0 or sum(fot) < sum(fo):
                        Y, fo = Yt, fot
                        if sum(fot) == 0:
                            break
            self.folds += fo
            ct, m = self.measure(hc, Y)
            self.met = self.met + m
            hc.release()
            tex.hierarchy.release()
            self.out.append(ct)
            self.charts.append((hc, Y, Y2, fo, m))
            if bar is not None:
                bar.update(1)
        if bar is not None:
            bar.close()
        self.weights = [None] * len(texs)

    def minimax(self, progress):
        """The minimax over metric-energy candidates (fold-free at FOLD_LEVELS), ARAP polish included."""
        cands, uvs = [], []
        bar = _bar(progress, len(self.charts), f"minimax, {self.extra} extra")
        for hc, Y, Y2, fo, m in self.charts:
            cm, cu = self._candidates(hc, Y, Y2, fo, m)
            hc.release()
            cands.append(cm)
            uvs.append(cu)
            if bar is not None:
                bar.update(1)
        if bar is not None:
            bar.close()
        choice = minimax_choice(self.exact, cands)
        if not any(choice):
            return
        from ccproof.apps.arap.core import ChartTexture

        self.arap_met = self.met
        self.met, self.out, self.folds = Metrics(), [], np.zeros(len(FOLD_LEVELS), dtype=np.int64)
        for i, ((hc, *_), cm, cu, j) in enumerate(zip(self.charts, cands, uvs, choice)):
            Z, fz, wts = cu[j]
            self.out.append(ChartTexture(hc, "boundary", 0, hc.lift_unknowns(Z, "boundary"), Z))
            self.met = self.met + cm[j]
            self.folds += fz
            self.weights[i] = wts

    def _candidates(self, hc, Y, Y2, fo, m):
        """One chart's candidates: (metrics list, (UVs, folds, weights) list), the kept UVs first."""
        cm, cu = [m], [(Y, fo, None)]
        if sum(fo):
            return cm, cu
        w0 = 1.0 / np.maximum(self.ex_e, EXCESS_FLOOR)
        # from the ARAP polish where the fold barrier admits it (its folds may lie between samples)
        f1 = _metric_energy(*_metric_system(hc, self.ev_x), (1.0, 1.0, 1.0))
        start = Y2 if np.isfinite(f1(np.asarray(Y2, dtype=np.float64).ravel())[0]) else Y
        for wa, ws in METRIC_WEIGHTS:
            Z = metric_polish(hc, start, self.ev_x, (wa * w0[0], w0[1], ws * w0[2]), max_iter=self.opts.metric_iter)
            fz = subdivided_folds(hc, Z)
            if sum(fz) == 0:
                cm.append(self.measure(hc, Z)[1])
                cu.append((Z, fz, (wa, ws)))
        return cm, cu

    def export(self, e_in):
        return ControlExport(self.mesh, self.out, self.extra, self.folds.tolist(), self.met, self.exact, e_in,
                             chart_weights=self.weights, arap_metrics=self.arap_met)
