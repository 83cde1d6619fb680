"""Shape recovery from range data with a dynamic Catmull-Clark surface (qmv98 sections 3.4, 4.2; docs/qmv98.md B6, Q9).

Pipeline (:func:`fit_points`):

1. normalize the data: centre and diameter of the minimal enclosing sphere (Welzl,
   :func:`minimal_enclosing_sphere`), so that every parameter below is dimensionless;
2. initial model: the paper's 98-vertex model (the cube subdivided twice) placed inside the data
   (centred at the centroid, control cube half-extents ``init_scale`` times the data's half-extents),
   or a user mesh;
3. evolve with the massless scheme (32) (default) or (31) under data springs: every data point pulls
   its nearest limit-surface point (the global closest point, :mod:`ccproof.evaluate.closest`;
   re-projected every step; at most ``spring_points`` of them, a fixed random subset of a denser
   cloud), until equilibrium: the total energy (elastic + springs) changes by less
   than ``tol`` (relative) between steps t - dt and t + dt (the paper's criterion, section 3.4; two
   steps because (32) advances two interleaved sequences) *and* so does the mean data -> surface
   distance (relative to itself, or to the data spacing of :func:`data_spacing` once it is smaller; the
   ICP-like tail, tangential sliding, lowers the energy slowly while the error still
   creeps: both must have settled), or ``max_steps`` (default 1000, a safety cap: the bunny scan needs
   about 200 + 100 steps); a level that stops otherwise says why (:attr:`FitLevel.reason`, and a
   warning naming the criterion that failed, the values reached and whether the energy rose);
   then the springs act both ways: surface -> data springs
   (:class:`~ccproof.apps.dynamics.forces.SurfaceToDataSprings`, total ``surface_spring_total``) pull
   the fixed samples of the surface that are farther than the stray distance (step 6) from every data
   point toward their nearest data points, to within that distance, so that surface no data point is
   near (a membrane spanning a concavity of the data) is drawn to the data; on the first level they are
   switched on once the data springs alone have reached equilibrium (from the small start cube they
   would pull the surface onto the nearest data, inner walls of a concavity included) and the
   evolution goes on to the equilibrium of both; on the later levels they act from the start;
4. subdivide globally and rebuild the model (densities rescaled, :meth:`Material.refined`), refit;
   repeat ``levels`` times;
5. report the paper's fit error: the largest distance of a data point to the limit surface, in % of the
   diameter of the minimal enclosing sphere, and the mean distance;
6. and the other direction (:func:`surface_to_data`), which the paper's error cannot see: the limit
   surface sampled at a level (exact limit points of the subdivided control mesh) and, per sample, the
   distance to the nearest data point (scipy cKDTree). A sample *strays* when it is farther than
   ``stray_distance`` (default 3 times the data's median nearest-neighbour spacing: a covered surface is
   within about one spacing of the data everywhere) from every data point; the area fraction of stray
   samples, their largest distance, and the two-sided (Hausdorff) error ``max(data -> surface,
   surface -> data)`` are reported. :class:`FitResult` ``.warnings`` says when more than
   ``stray_fraction`` of the surface strays (a surface spanning a torus' hole, an unseen side filled in)
   or a level stopped at the step cap.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ccproof.apps.control_mesh import TaggedQuadMesh
from ccproof.apps.dynamics.cloud import (
    check_cloud,
    data_spacing,
    fit_error,
    limit_surface_mesh,
    minimal_enclosing_sphere,
    surface_to_data,
)
from ccproof.apps.dynamics.fit_options import Evolution, FitSprings, SurfaceCheck
from ccproof.apps.dynamics.forces import ModelClosestPoints, Springs, SurfaceToDataSprings
from ccproof.apps.dynamics.integrate import ImplicitIntegrator
from ccproof.apps.dynamics.meshes import paper_initial_model
from ccproof.apps.dynamics.model import DynamicSurface, Material
from ccproof.errors import CCProofError
from ccproof.mesh import QuadMesh
from ccproof.mesh.points import read_points

__all__ = [
    "read_points",
    "FitSprings",
    "Evolution",
    "SurfaceCheck",
    "FitLevel",
    "FitResult",
    "fit_points",
    "DEFAULT_FIT_MATERIAL",
]

#: material of the shape-recovery runs, in units where the data's enclosing sphere has diameter 1
#: and the data springs sum to 1 (``spring_total``): massless, weak tension, weak rigidity
DEFAULT_FIT_MATERIAL = Material(mu=0.0, gamma=1.0, a11=1e-5, a22=1e-5, b11=1e-6, b12=2e-6, b22=1e-6)


@dataclass
class FitLevel:
    """One level of the multilevel fit (qmv98 section 4.2; docs/qmv98.md B6).

    Parameters
    ----------
    n_vertices, n_faces : int
    steps : int
        Implicit steps taken.
    converged : bool
    max_error_percent, mean_error_percent : float
    seconds : float
    cg_iterations : int
    energy : float
        Total energy (elastic + springs, normalized units) after the last step.
    energy_change, error_change : float
        Relative changes of the total energy and of the mean data -> surface distance between the last
        step and the one two steps before (the equilibrium criterion of :func:`fit_points`).
    reason : str
        Why the level stopped, in words.

    Examples
    --------
    >>> lev = FitLevel(98, 96, 10, True, 0.5, 0.1, 1.0, 40)
    >>> lev.n_faces, lev.converged
    (96, True)
    """

    n_vertices: int
    n_faces: int
    steps: int
    converged: bool
    max_error_percent: float
    mean_error_percent: float
    seconds: float
    cg_iterations: int
    energy: float = math.nan
    energy_change: float = math.nan
    error_change: float = math.nan
    reason: str = ""


@dataclass
class FitResult:
    """Outcome of :func:`fit_points`; ``mesh`` is in the data's coordinates.

    Parameters
    ----------
    mesh : QuadMesh or None
        The fitted control mesh (data units). From a non-manifold start mesh: the split mesh, its
        ``file_vertex`` labelling the copies of one vertex (which the fit keeps at one point;
        :func:`ccproof.apps.control_file.write_control_obj` writes it merged, in the file's numbering).
    model : DynamicSurface or None
    levels : list of FitLevel
    center : ndarray, shape (3,), optional
    diameter : float
        Diameter of the minimal enclosing sphere of the data.
    parameters : dict
    data_distances : ndarray, shape (m,), optional
        Data -> surface distances at the final level (data units).
    surface : QuadMesh, optional
        The limit surface sampled at ``sample_level`` (data units); ``surface_report`` its
        :func:`surface_to_data`.
    sample_level : int
    surface_report : dict
    spacing, stray_distance : float
        :func:`data_spacing`, and the distance beyond which surface points count as stray.
    warnings : list of str
    normalized_state : ndarray, shape (n, 3), optional
        Final control points in the normalized units of the fit (centre 0, diameter 1).

    Examples
    --------
    Fitting takes seconds, so this example is not run (docs/qmv98.md shows measured fits):

    >>> from ccproof.apps.dynamics.shapes import synthetic_range_data
    >>> res = fit_points(synthetic_range_data("ellipsoid"))                   # doctest: +SKIP
    >>> res.mesh, res.levels, res.two_sided_error_percent                      # doctest: +SKIP
    """

    mesh: QuadMesh | None
    model: DynamicSurface | None
    levels: list = field(default_factory=list)
    center: np.ndarray | None = None
    diameter: float = 0.0
    parameters: dict = field(default_factory=dict)
    #: data -> surface distances of the data points (data units), at the final level
    data_distances: np.ndarray | None = None
    #: the limit surface sampled at ``sample_level`` (QuadMesh, data units) and surface -> data report
    surface: QuadMesh | None = None
    sample_level: int = 0
    surface_report: dict = field(default_factory=dict)
    #: data spacing, stray distance (data units)
    spacing: float = 0.0
    stray_distance: float = 0.0
    warnings: list = field(default_factory=list)
    #: the final control points in the normalized units of the fit (centre 0, enclosing-sphere diameter 1)
    normalized_state: np.ndarray | None = None

    @property
    def two_sided_error_percent(self):
        """max(data -> surface, surface -> data) in % of the enclosing-sphere diameter (Hausdorff)."""
        if self.data_distances is None:
            raise CCProofError("no data distances: this FitResult was not filled by fit_points")
        return 100.0 * max(float(self.data_distances.max()), self.surface_report["max"]) / self.diameter

    @property
    def data_rms_percent(self):
        """Root mean square of the data -> surface distances, in % of the enclosing-sphere diameter."""
        if self.data_distances is None:
            raise CCProofError("no data distances: this FitResult was not filled by fit_points")
        return 100.0 * float(np.sqrt(np.mean(self.data_distances**2))) / self.diameter

    @property
    def surface_rms_percent(self):
        """Area-weighted root mean square of the surface -> data distances, in % of the diameter."""
        return 100.0 * self.surface_report["rms"] / self.diameter

    @property
    def surface_max_percent(self):
        return 100.0 * self.surface_report["max"] / self.diameter

    @property
    def stray_distance_percent(self):
        return 100.0 * self.stray_distance / self.diameter

    @property
    def max_error_percent(self):
        return self.levels[-1].max_error_percent

    @property
    def mean_error_percent(self):
        return self.levels[-1].mean_error_percent


def _initial_mesh(init, Xn, init_scale):
    if isinstance(init, str):
        if init != "cube":
            raise CCProofError(f"unknown initial model {init!r} (use 'cube' or a mesh)")
        lo, hi = Xn.min(axis=0), Xn.max(axis=0)
        centroid = Xn.mean(axis=0)
        half = init_scale * 0.5 * (hi - lo)
        return paper_initial_model(center=centroid, half_extent=half)
    if not isinstance(init, QuadMesh):
        raise CCProofError("init must be 'cube' or a QuadMesh (normalized with the data, see fit_points)")
    return init


def fit_points(X: ArrayLike, init: Literal["cube"] | QuadMesh = "cube", levels: int = 1,
               material: Material | None = None, springs: FitSprings | None = None,
               evolution: Evolution | None = None, check: SurfaceCheck | None = None, init_scale: float = 0.5,
               progress: bool = False, callback: Callable[[int, int, DynamicSurface, NDArray[np.float64]], object]
               | None = None) -> FitResult:
    """Recover a closed surface from range data (module docstring).

    Parameters
    ----------
    X : array_like (m, 3)
        Data points (at least 4, finite).
    init : "cube" or QuadMesh
        Initial control mesh; a QuadMesh is given in the data's coordinates.
    levels : int >= 0
        Global subdivisions after the first equilibrium (paper: 1, 98 -> 386 vertices).
    material : Material, optional
        Densities in normalized units (default :data:`DEFAULT_FIT_MATERIAL`), for the initial level;
        rescaled at each subdivision (:meth:`Material.refined`).
    springs, evolution, check : FitSprings, Evolution, SurfaceCheck, optional
        The data and surface -> data springs, the evolution of each level (scheme, time step, step cap,
        tolerance), the surface -> data report (sampling level, stray criterion); default: their defaults.
    init_scale : float in (0, 1]
        Size of the initial control cube relative to the data's bounding box.
    progress : bool
        Show a tqdm progress bar over the time steps.
    callback : callable, optional
        ``callback(level, step, model, P_normalized)`` after every step.

    Returns
    -------
    FitResult
        ``mesh``: the fitted control mesh (data coordinates; 98 vertices from the cube, x4 faces per level),
        ``max_error_percent`` / ``mean_error_percent``: the paper's fit error (data -> limit surface, % of the
        enclosing-sphere diameter), ``surface``, ``surface_report`` and ``warnings`` (surface -> data).

    Examples
    --------
    500 points on the unit sphere, fitted from the paper's 98-vertex cube model without subdividing; the
    limit surface (checked independently: the radii of its samples) hugs the sphere:

    >>> import numpy as np
    >>> X = np.random.default_rng(0).normal(size=(500, 3))
    >>> X /= np.linalg.norm(X, axis=1, keepdims=True)
    >>> fit = fit_points(X, levels=0)
    >>> r = np.linalg.norm(fit.surface.vertices, axis=1)
    >>> fit.mesh.n_vertices, fit.max_error_percent < 0.5, bool(0.98 < r.min() and r.max() < 1.01), fit.warnings
    (98, True, True, [])
    """
    springs = FitSprings() if springs is None else springs
    evolution = Evolution() if evolution is None else evolution
    check = SurfaceCheck() if check is None else check
    pts = check_cloud(X)  # (m, 3) float64
    _check_fit_numbers(levels, springs.total, springs.surface_total, init_scale)
    material = DEFAULT_FIT_MATERIAL if material is None else material
    centre, radius = minimal_enclosing_sphere(pts)
    if not (diameter := 2.0 * radius) > 0:
        raise CCProofError("the data points all coincide")
    Xn = (pts - centre) / diameter
    mesh0 = _start_mesh(init, Xn, init_scale, centre, diameter)
    Xs = _spring_subset(Xn, springs.points)
    result = FitResult(mesh=None, model=None, center=centre, diameter=diameter,
                       parameters=_parameters(material, springs, evolution, init_scale, levels, Xs.shape[0]))
    spacing_n = max(data_spacing(Xn), 1e-300)
    # the stray distance (normalized): the surface -> data springs pull the samples farther than it back to it
    stray_n = 3.0 * spacing_n if check.stray_distance_percent is None else float(check.stray_distance_percent) / 100
    fit = _FitState(DynamicSurface(mesh0, material, levels=evolution.truncation), mesh0, result, spacing_n)
    bar = _progress_bar((levels + 1) * evolution.max_steps) if progress else None
    try:
        for level in range(levels + 1):
            fit.relax(level, (Xn, Xs, springs, stray_n), evolution, (bar, callback))
            if level < levels:
                fit.refine()
    finally:
        if bar is not None:
            bar.close()
    fit.finish(pts, check)
    return result


def _parameters(material, springs, evolution, init_scale, levels, spring_points):
    """The parameters a :class:`FitResult` records (dt resolved, the count of points carrying springs)."""
    return {"material": material, "spring_total": springs.total, "dt": evolution.time_step(),
            "scheme": evolution.scheme, "max_steps": evolution.max_steps, "tol": evolution.tol,
            "init_scale": init_scale, "truncation": evolution.truncation, "levels": levels,
            "surface_spring_total": springs.surface_total, "spring_points": spring_points}


def _progress_bar(total):
    from tqdm import tqdm

    return tqdm(total=total, desc="fit", unit="step")


class _FitState:
    """The state of :func:`fit_points` from level to level: the model, its control points ``P`` (normalized),
    the copies of one file vertex (a non-manifold start: one free point, docs/qmv98.md)."""

    def __init__(self, model, mesh0, result, spacing_n):
        self.model, self.result, self.spacing_n = model, result, spacing_n
        self.P = np.array(mesh0.vertices)
        self.copies = getattr(mesh0, "file_vertex", None)
        self.err: dict = {}

    def relax(self, level, data, evolution, hooks):
        """Integrate ``level`` to equilibrium (or the step cap) and record its :class:`FitLevel`."""
        Xn, Xs, springs, stray_n = data
        t0 = time.perf_counter()
        model, result = self.model, self.result
        finder = ModelClosestPoints(model)
        integ = ImplicitIntegrator(model, result.parameters["dt"], P=self.P, scheme=evolution.scheme, tol=1e-9,
                                   copies=self.copies)
        reverse = (SurfaceToDataSprings(model, Xn, springs.surface_total, slack=stray_n)
                   if springs.surface_total > 0 else None)
        k = np.full(Xs.shape[0], springs.total / Xs.shape[0])
        run = _relax_level(model, finder, integ, (Xs, k, reverse), level, result.parameters, self.spacing_n, hooks)
        step, converged, cg, energies, change, err_change, reason = run
        bar = hooks[0]
        if bar is not None and step < evolution.max_steps:
            bar.update(evolution.max_steps - step)
        self.P = integ.P
        self.err = err = fit_error(model, self.P, Xn, finder=finder, diameter=1.0)
        result.levels.append(FitLevel(model.n_vertices, model.mesh.n_faces, step, converged, err["max_percent"],
                                      err["mean_percent"], time.perf_counter() - t0, cg,
                                      energies[-1] if energies else math.nan, change, err_change, reason))

    def refine(self):
        """Subdivide the model globally (densities rescaled) and carry the control points over."""
        self.model, A = self.model.refine(self.P)
        self.P = np.asarray(A @ self.P)
        if self.copies is not None:  # the children of the copies that are one point of the refined file
            self.copies = self.model.mesh.file_vertex  # (subdivide_control: copy_labels)

    def finish(self, pts, check):
        """The fitted mesh in data units, the data distances, the warnings and the surface -> data report."""
        result, diameter = self.result, self.result.diameter
        result.model = self.model
        result.mesh = mesh = self.model.mesh.with_vertices(self.P * diameter + result.center)
        if self.copies is not None:
            mesh.file_vertex = self.copies
        result.normalized_state = self.P
        result.data_distances = self.err["distances"] * diameter
        for i, lev in enumerate(result.levels):
            if not lev.converged:
                result.warnings.append(f"level {i} {lev.reason}")
        _report_surface(result, pts, check.sample_level, check.stray_distance_percent, check.stray_fraction)


def _spring_subset(Xn, spring_points):
    """The data points that carry data springs: all, or a fixed random subset (seed 0) of ``spring_points``."""
    if spring_points is not None and (int(spring_points) != spring_points or spring_points < 4):
        raise CCProofError(f"spring_points must be an integer >= 4 or None, got {spring_points!r}")
    if spring_points is None or Xn.shape[0] <= spring_points:
        return Xn
    keep = np.sort(np.random.default_rng(0).choice(Xn.shape[0], size=int(spring_points), replace=False))
    return Xn[keep]


def _check_fit_numbers(levels, spring_total, surface_spring_total, init_scale):
    """Refuse, naming the option, a bad number of levels, spring totals or initial scale of :func:`fit_points`."""
    if int(levels) != levels or levels < 0:
        raise CCProofError(f"levels must be an integer >= 0, got {levels!r}")
    if not (spring_total > 0 and math.isfinite(spring_total)):
        raise CCProofError(f"spring_total must be finite and > 0, got {spring_total!r}")
    if not (surface_spring_total >= 0 and math.isfinite(surface_spring_total)):
        raise CCProofError(f"surface_spring_total must be finite and >= 0, got {surface_spring_total!r}")
    if not (0 < init_scale <= 1):
        raise CCProofError(f"init_scale must be in (0, 1], got {init_scale!r}")


def _start_mesh(init, Xn, init_scale, centre, diameter):
    """The start mesh of :func:`fit_points` in the normalized frame (extraordinary vertices isolated where the
    elements need it)."""
    if isinstance(init, str):
        mesh0 = _initial_mesh(init, Xn, init_scale)
    else:
        mesh0 = _initial_mesh(init, Xn, init_scale)
        mesh0 = mesh0.with_vertices((np.asarray(mesh0.vertices) - centre) / diameter)
    from ccproof.apps.dynamics.elements import isolate_extraordinary

    if not isinstance(mesh0, TaggedQuadMesh):  # tagged elements take any face (docs/qmv98.md)
        mesh0, _ = isolate_extraordinary(mesh0)
    return mesh0


def _relax_level(model, finder, integ, data, level, params, spacing_n, hooks):
    """Integrate one level of :func:`fit_points` with ``integ`` to equilibrium or to the step cap.
    ``data`` = (Xn, k, reverse springs or None), ``params`` the fit's parameters, ``hooks`` = (bar, callback).
    Returns (steps, converged, CG iterations, energies, change, error change, reason)."""
    Xn, k, reverse = data
    bar, callback = hooks
    max_steps, tol = params["max_steps"], params["tol"]
    converged = False
    cg = 0
    step = 0
    energies, errors = [], []
    change = err_change = math.inf
    two_way = reverse is not None and level > 0
    one_way_steps = 0
    for step in range(1, max_steps + 1):
        f, u, v, _, dist = finder.query(integ.P, Xn)
        errors.append(float(np.mean(dist)))  # of the state before this step
        springs = Springs(model, f, u, v, Xn, k)
        if two_way and reverse is not None:  # and from the surface to the data (two-way forces)
            pull = reverse.springs(integ.P)[0].pulling()
            springs = springs if pull is None else Springs.stacked(springs, pull)
        info = integ.step(springs=springs)
        cg += info.iterations
        energies.append(model.energy(integ.P) + springs.energy(integ.P))
        change = abs(energies[-1] - energies[-3]) / abs(energies[-1]) if len(energies) >= 3 else math.inf
        # relative to the mean error, or to the data spacing once the error is below it (changes
        # finer than the data's resolution are not progress)
        err_change = (abs(errors[-1] - errors[-3]) / max(abs(errors[-1]), spacing_n)
                      if len(errors) >= 3 else math.inf)
        if bar is not None:
            bar.update(1)
            bar.set_postfix(level=level, dE=f"{change:.1e}", dErr=f"{err_change:.1e}")
        if callback is not None:
            callback(level, step, model, integ.P)
        if change <= tol and err_change <= tol:
            if reverse is not None and not two_way:  # the first level's data-spring equilibrium
                two_way, energies, errors, one_way_steps = True, [], [], step
                continue
            converged = True
            break
    reason = _level_reason(converged, step, one_way_steps, (change, err_change), energies, (max_steps, tol))
    return step, converged, cg, energies, change, err_change, reason


def _level_reason(converged, step, one_way_steps, changes, energies, caps):
    """Why a level of :func:`fit_points` stopped (equilibrium, or the step cap and what had not settled)."""
    change, err_change = changes
    max_steps, tol = caps
    rises = sum(b > a for a, b in zip(energies[-11:-1], energies[-10:]))
    if converged:
        first = f" (data springs alone for the first {one_way_steps})" if one_way_steps else ""
        reason = (f"equilibrium after {step} steps{first}: relative energy change {change:.2g} and mean-error "
                  f"change {err_change:.2g} over two steps, both <= tol {tol:g}")
    else:
        failed = [w for w, c in (("energy", change), ("mean data error", err_change)) if not c <= tol]
        reason = (f"stopped at the step cap ({max_steps} steps, --max-steps) before equilibrium: relative "
                  f"{' and '.join(failed)} change over two steps {change:.2g} / {err_change:.2g} > tol {tol:g}"
                  + (f"; the energy rose at {rises} of the last 10 steps (lower --dt)" if rises else
                     "; the energy was still falling (raise --max-steps)"))
    return reason


def _report_surface(result, pts, sample_level, stray_distance_percent, stray_fraction):
    """The fitted limit surface of ``result``, its sampling level, the data spacing, and how far it strays from
    the data (a warning beyond ``stray_fraction``)."""
    mesh, diameter = result.mesh, result.diameter
    if sample_level is None:
        nf = mesh.n_faces
        sample_level = next((k for k in (1, 2, 3) if nf * 4**k >= 4 * pts.shape[0]), 3)
    result.sample_level = int(sample_level)
    result.surface = limit_surface_mesh(result.mesh, sample_level)
    result.spacing = data_spacing(pts)
    result.stray_distance = (3.0 * result.spacing if stray_distance_percent is None
                             else float(stray_distance_percent) * diameter / 100.0)
    rep = surface_to_data(result.surface, pts, result.stray_distance)
    result.surface_report = rep
    if rep["stray_fraction"] > stray_fraction:
        # both directions: a web across a concavity leaves the data -> surface error (the headline) small
        data_max = 100.0 * float(result.data_distances.max()) / diameter
        result.warnings.append(
            f"the fitted surface strays from the data: surface -> data, {100 * rep['stray_fraction']:.1f} % of its "
            f"area is farther than {result.stray_distance_percent:.2f} % of the diameter from every data point, "
            f"up to {result.surface_max_percent:.2f} %{_where_stray(result)}, while data -> surface every point "
            f"is within {data_max:.2f} % (RMS {result.data_rms_percent:.3f} %): the fit error does not show it; "
            f"the surface spans a concavity of the data (a web; raise --surface-spring or --levels), the data may "
            f"not cover the surface (an unseen side), or the start mesh's topology may not match the data's (e.g. "
            f"a genus-0 start for a torus: give --init)")


def _where_stray(result, most=12):
    """Where the stray part of ``result.surface`` lies: the fitted control faces whose sampled faces have stray corners
    (the ``most`` with the most of them, in that order), and the centroid of the stray samples (data units); '' for
    a tagged mesh (its sampled faces leave the holes out, so they are not numbered by their control face)."""
    rep, surface, mesh = result.surface_report, result.surface, result.mesh
    stray = rep["distances"] > result.stray_distance
    if isinstance(mesh, TaggedQuadMesh) or surface.n_faces != mesh.n_faces * 4**result.sample_level:
        return ""
    # child 4 f + i of face f at every subdivision: sampled face q lies in control face q // 4^level; the faces
    # with the most stray sample corners first
    weight = np.bincount(np.arange(surface.n_faces) // 4**result.sample_level,
                         weights=stray[surface.faces].sum(axis=1), minlength=mesh.n_faces)
    faces = np.flatnonzero(weight > 0)
    faces = faces[np.argsort(-weight[faces], kind="stable")]
    c = np.asarray(surface.vertices)[stray].mean(axis=0)
    listed = ", ".join(str(f) for f in faces[:most]) + (", ..." if faces.size > most else "")
    return (f", on {faces.size} of the {mesh.n_faces} fitted control faces (most: {listed}) around "
            f"({c[0]:.4g}, {c[1]:.4g}, {c[2]:.4g})")
