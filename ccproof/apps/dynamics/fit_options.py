"""The options of :func:`~ccproof.apps.dynamics.fit.fit_points`, one frozen value per concept: the springs
between data and surface, the evolution of each level, and the check of the surface against the data."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

__all__ = ["FitSprings", "Evolution", "SurfaceCheck"]


@dataclass(frozen=True)
class FitSprings:
    """The springs of :func:`fit_points` between the data and the surface (normalized units).

    Parameters
    ----------
    total : float > 0
        Sum of the data-spring constants (each carrying point gets ``total / count``).
    surface_total : float >= 0
        Sum of the constants of the surface -> data springs
        (:class:`~ccproof.apps.dynamics.forces.SurfaceToDataSprings`: 4 x 4 samples per patch face, in
        proportion to area; a sample farther than the stray distance from every data point is pulled
        toward its nearest data point, to within the stray distance), which pull the parts of the surface
        that no data point is near (a membrane across a concavity) to the data; 0 turns them off (the
        paper's one-way data springs only).
    points : int >= 4 or None
        At most this many data points carry data springs (a fixed random subset, seed 0, when the cloud is
        larger): every step re-projects them all, so the time grows with their number, while a few points per
        spacing of the final surface pin it as well (docs/qmv98.md, dense clouds). The errors, the stray report
        and the surface -> data springs use every point. None: all.

    Examples
    --------
    >>> FitSprings(surface_total=0.0).points
    10000
    """

    total: float = 1.0
    surface_total: float = 5.0
    points: int | None = 10_000


@dataclass(frozen=True)
class Evolution:
    """How :func:`fit_points` integrates each level to equilibrium (qmv98 eqs. 31, 32).

    Parameters
    ----------
    scheme : "massless" (eq. 32) or "inertial" (eq. 31)
    dt : float > 0, optional
        Time step (normalized units); default 1000 (massless: nearly quasi-static steps) or 10 (inertial).
    max_steps : int
        Time steps per level at most (a safety cap, not the usual stop).
    tol : float
        Equilibrium: relative changes of the total energy and of the mean data -> surface distance (the
        latter relative to max(mean distance, data spacing)) between steps t - dt and t + dt both at most
        ``tol``.
    truncation : int
        Truncation level L of the special-element stiffness.

    Examples
    --------
    >>> Evolution(scheme="inertial").time_step()
    10.0
    """

    scheme: Literal["massless", "inertial"] = "massless"
    dt: float | None = None
    max_steps: int = 1000
    tol: float = 1e-3
    truncation: int = 6

    def time_step(self) -> float:
        """``dt``, or the scheme's default."""
        if self.dt is not None:
            return float(self.dt)
        return 1000.0 if self.scheme == "massless" else 10.0


@dataclass(frozen=True)
class SurfaceCheck:
    """How :func:`fit_points` judges the fitted surface from the other side (surface -> data).

    Parameters
    ----------
    sample_level : int, optional
        Level of the sampled limit surface (default: the smallest level in 1..3 with at least 4 samples per
        data point).
    stray_distance_percent : float, optional
        Surface -> data distance above which a surface sample strays, in % of the enclosing-sphere diameter
        (default 3 times :func:`~ccproof.apps.dynamics.cloud.data_spacing`); the surface -> data springs pull
        to within it.
    stray_fraction : float
        Warn when more than this area fraction of the surface strays.

    Examples
    --------
    >>> SurfaceCheck().stray_fraction
    0.01
    """

    sample_level: int | None = None
    stray_distance_percent: float | None = None
    stray_fraction: float = 0.01
