"""hsh10 on whole meshes: charts from labels, refinement to a chart size, the memory budget checked before
work (:class:`MemoryBudgetError`), the comparison of the methods (:func:`compare`) and the one-call
:func:`parameterize`. Per chart: :mod:`~ccproof.apps.arap.core`.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Literal

import numpy as np
from numpy.typing import ArrayLike

from ccproof.apps.arap.charts import charts_from_labels, check_disk
from ccproof.apps.arap.core import (
    METHODS,
    VARIANTS,
    MethodResult,
    Solver,
    control_flips,
    lift_to_refined,
    run_method,
    texture_metrics,
)
from ccproof.apps.arap.hierarchy import ChartHierarchy
from ccproof.apps.arap.metrics import Metrics
from ccproof.errors import CCProofError

if TYPE_CHECKING:
    from ccproof.mesh import QuadMesh

__all__ = ["mesh_charts", "refine_mesh", "auto_refine", "estimate_memory", "MemoryBudgetError", "run_memory",
           "LevelPlan", "compare", "parameterize"]


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


@dataclass(frozen=True)
class LevelPlan:
    """The subdivision levels of :func:`compare`, counted on the input mesh.

    Parameters
    ----------
    levels, start_level : int
        Last and first optimization level.
    eval_level : int
        Level of the metric samples (the same for every method).
    refine : int >= 0
        Subdivide the control mesh ``refine`` times before optimizing (b) and (c) (more texture unknowns,
        the same surface and the same metric samples); their optimization levels are then
        ``max(start_level, refine + 1) .. max(levels, refine + 1)`` on the input mesh, i.e. from level 1
        of the refined mesh (level 0 misses odd-even modes), warm-started from the input mesh's
        optimization at levels ``start_level .. refine`` (:func:`lift_to_refined`: the same texture
        on the refined unknowns). (a) and (d) use the input mesh.
    sample_level : int, optional
        Also keep every chart's limit samples at this level (:func:`~ccproof.apps.arap.export.sample_chart`)
        in ``MethodResult.samples``.

    Examples
    --------
    >>> LevelPlan(levels=1, eval_level=3)
    LevelPlan(levels=1, start_level=1, eval_level=3, refine=0, sample_level=None)
    """

    levels: int = 3
    start_level: int = 1
    eval_level: int = 5
    refine: int = 0
    sample_level: int | None = None


def compare(mesh, labels=None, methods=METHODS, plan=LevelPlan(), solver=None, hierarchies=None, release=False,
            max_memory=None, progress=False):
    """Run ``methods`` on every chart and measure them the same way.

    Parameters
    ----------
    plan : LevelPlan
        Optimization, metric, refinement and sample levels.
    solver : Solver, optional
        Tolerance, iterations, acceleration (the CLI uses 5) and the baselines' engine and level (default
        ``Solver()``).
    hierarchies : list of ChartHierarchy, optional
        Those of the input mesh, when already built (returned for reuse).
    release : bool
        Process the charts one at a time and drop their fine levels afterwards (peak memory of the
        largest chart instead of the sum); the samples of ``plan.sample_level`` are taken before.
    max_memory : float, optional
        Bytes; raise :class:`MemoryBudgetError` before allocating when :func:`estimate_memory` exceeds it.
    progress : bool
        A tqdm progress bar over (chart, method).

    Returns
    -------
    dict method -> MethodResult, and the list of ChartHierarchy of the input mesh (reusable)

    Examples
    --------
    A flat grid has an isometric texture, E_angle = E_area = 2, E_stretch = 1 (their minima):

    >>> from ccproof.mesh.examples import grid
    >>> res, hierarchies = compare(grid(3, 3), methods=("b", "c"), plan=LevelPlan(levels=1, eval_level=3))
    >>> [[round(x, 9) for x in res[m].metrics.as_tuple()] for m in "bc"], len(hierarchies)
    ([[2.0, 2.0, 1.0], [2.0, 2.0, 1.0]], 1)
    """
    if hierarchies is None:
        hierarchies = [ChartHierarchy(mesh, fc) for fc in mesh_charts(mesh, labels)]
    solver = Solver() if solver is None else solver
    plan = replace(plan, refine=int(plan.refine))
    if plan.refine < 0:
        raise CCProofError(f"refine must be >= 0, got {plan.refine}")
    fine = _refined_charts(mesh, labels, methods, plan)
    _check_budget(hierarchies, methods, plan, solver, release, max_memory)
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=len(hierarchies) * len(methods), desc="arap", unit="chart")
    acc = {m: _Tally() for m in methods}
    try:
        for i, h in enumerate(hierarchies):
            for m in methods:
                if bar is not None:
                    bar.set_postfix(method=m, chart=i)
                hm = fine["hierarchies"][i] if fine and m in ("b", "c") else h
                acc[m].add(_chart_method(h, hm, m, plan, solver), plan, release)
                if bar is not None:
                    bar.update(1)
            if release:
                h.release()
    finally:
        if bar is not None:
            bar.close()
    return {m: acc[m].result(m, plan.refine if fine and m in ("b", "c") else 0, plan) for m in methods}, hierarchies


def _refined_charts(mesh, labels, methods, plan):
    """The charts of the mesh refined ``plan.refine`` times, when (b) or (c) optimize on it ({} otherwise)."""
    if not (plan.refine and any(m in ("b", "c") for m in methods)):
        return {}
    rmesh, rlab = refine_mesh(mesh, labels, plan.refine)
    return {"hierarchies": [ChartHierarchy(rmesh, fc) for fc in mesh_charts(rmesh, rlab)]}


def _check_budget(hierarchies, methods, plan, solver, release, max_memory):
    """Raise :class:`MemoryBudgetError` when the estimated peak exceeds ``max_memory`` (bytes; None: no budget)."""
    need, deepest, opt = run_memory(hierarchies, methods, plan.levels, plan.eval_level, plan.sample_level,
                                    plan.refine, solver.baseline_level, release)
    if max_memory is not None and need > max_memory:
        big = int(np.argmax([h.n_faces(0) for h in hierarchies]))
        raise MemoryBudgetError(
            f"estimated peak memory {need / 1e9:.2f} GB exceeds the budget {max_memory / 1e9:.2f} GB "
            f"(--max-memory): chart {big} has {hierarchies[big].n_faces(max(deepest, opt or 0)):,} faces at level "
            f"{max(deepest, opt or 0)}; lower --eval-level / --levels / --out-level (each level less divides it "
            f"by 4), or use smaller charts")


def _chart_method(h, hm, m, plan, solver):
    """Method ``m`` on chart ``h`` (on ``hm``, its refined chart, when that is not ``h``): (texture, seconds,
    iterations, level stats with levels on the input mesh, metric level on hm, hm)."""
    refine, X0, sec0, it0, st0 = plan.refine, None, 0.0, 0, []
    if hm is not h:
        st = max(plan.start_level, refine + 1) - refine
        lv, ev = max(plan.levels, refine + 1) - refine, plan.eval_level - refine
        if plan.start_level <= refine:  # multi-resolution: the input mesh's levels below the refined ones
            t0 = time.perf_counter()
            texc, _, it0, st0 = run_method(h, m, refine, plan.start_level, replace(solver, trace=False))
            X0 = lift_to_refined(h, texc.unknowns, texc.rules, hm, refine)
            sec0 = time.perf_counter() - t0
    else:
        st, lv, ev = plan.start_level, plan.levels, plan.eval_level
    if ev < 0:
        raise CCProofError(f"eval_level {plan.eval_level} is below refine {refine}")
    tex, sec, it, stt = run_method(hm, m, lv, st, solver, X0=X0)
    if hm is not h:  # level numbers on the input mesh
        stt = [replace(x, level=x.level + refine) for x in stt]
    return tex, sec + sec0, it + it0, st0 + stt, ev, hm, h


class _Tally:
    """What :func:`compare` gathers of one method over the charts."""

    def __init__(self):
        self.texs, self.secs, self.its, self.lv, self.met = [], 0.0, 0, [], Metrics()
        self.flips, self.total, self.samples, self.sample_level = 0, 0, [], None

    def add(self, run, plan, release):
        """Add one chart's ``run`` (:func:`_chart_method`)."""
        tex, sec, it, stats, ev, hm, h = run
        self.texs.append(tex)
        self.secs += sec
        self.its += it
        self.lv.append(stats)
        self.met = self.met + texture_metrics(tex, ev)
        f, t = control_flips(tex)
        self.flips += f
        self.total += t
        if plan.sample_level is not None:
            from ccproof.apps.arap.export import sample_chart

            off = plan.refine if hm is not h else 0
            sl = max(plan.sample_level - off, tex.level)  # (d) lives at level 3
            self.samples.append(sample_chart(tex, sl))
            self.sample_level = sl + off
        if release and hm is not h:
            hm.release()

    def result(self, m, refine, plan):
        r = MethodResult(m, self.texs, self.secs, self.its, levels=self.lv)
        r.metrics, r.flips_control, r.triangles_control = self.met, self.flips, self.total
        r.refine = refine
        r.samples = self.samples if plan.sample_level is not None else None
        r.sample_level = self.sample_level if self.sample_level is not None else plan.sample_level
        return r


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
    res, hs = compare(mesh, labels, (VARIANTS[variant],), LevelPlan(levels, start_level, eval_level),
                      Solver(tol=tol, max_iter=max_iter))
    return res[VARIANTS[variant]]
