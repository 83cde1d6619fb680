"""Distortion metrics of hsh10 section 4 (docs/hsh10.md A9) and flip counts.

For every sample j with singular values s1 >= s2 of grad phi_j = (t1 t2)(p^1 p^2)^-1, surface area
element A_j and texture area element A_T,j:

    E_angle   = sum A_j (s1/s2 + s2/s1)     / sum A_j                     (>= 2)
    E_area    = sum A_j (s1 s2 + 1/(s1 s2)) / sum A_j                     (>= 2)
    E_stretch = sqrt(sum A_j (1/s1^2 + 1/s2^2)/2 / sum A_j) sqrt(sum A_T,j / sum A_j)   (>= 1)

E_area is not scale invariant (it is meant for maps with their natural scale, as ARAP produces);
:meth:`Metrics.rescaled` gives the value after scaling the texture to the surface area. A sample
is *flipped* when det grad phi <= 0. Several charts are combined by summing the area-weighted
sums (docs/hsh10.md A11.4).

>>> import numpy as np
>>> J = np.array([[[2.0, 0.0], [0.0, 0.5]]])
>>> [float(x) for x in np.concatenate(singular_values(J))]
[2.0, 0.5, 1.0]
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ccproof.apps.arap.samples import SampleSet, isometric_frames

__all__ = ["singular_values", "jacobians", "Metrics", "sample_metrics", "triangle_metrics", "excess_ratios",
           "minimax_choice"]


def singular_values(J):
    """Singular values s1 >= s2 >= 0 and the determinant of 2x2 matrices J (s, 2, 2).

    Closed form (the rotation/reflection split of hsh10 Appendix), used by the metrics of section 4.

    Parameters
    ----------
    J : ndarray, shape (s, 2, 2) float64

    Returns
    -------
    s1, s2, det : ndarray, shape (s,) float64

    Examples
    --------
    >>> import numpy as np
    >>> s1, s2, det = singular_values(np.array([[[2.0, 0], [0, 1]], [[0, -3.0], [3, 0]]]))
    >>> s1.tolist(), s2.tolist(), det.tolist()
    ([2.0, 3.0], [1.0, 3.0], [2.0, 9.0])
    """
    a, b, c, d = J[:, 0, 0], J[:, 0, 1], J[:, 1, 0], J[:, 1, 1]
    Q = np.hypot(0.5 * (a + d), 0.5 * (c - b))
    R = np.hypot(0.5 * (a - d), 0.5 * (c + b))
    return Q + R, np.abs(Q - R), a * d - b * c


def jacobians(p1, p2, t1, t2):
    """grad phi = (t1 t2)(p^1 p^2)^-1 in the isometric frame of (p1, p2), shape (s, 2, 2).

    The Jacobian of the texture map at a sample (hsh10 section 3; docs/hsh10.md A2).

    Parameters
    ----------
    p1, p2 : ndarray, shape (s, 3) float64
        Surface tangents.
    t1, t2 : ndarray, shape (s, 2) float64
        Texture tangents.

    Returns
    -------
    ndarray, shape (s, 2, 2) float64

    Examples
    --------
    >>> import numpy as np
    >>> jacobians(np.array([[1.0, 0, 0]]), np.array([[0, 1.0, 0]]), np.array([[2.0, 0]]), np.array([[0, 3.0]])).tolist()
    [[[2.0, 0.0], [0.0, 3.0]]]
    """
    a, b, c = isometric_frames(p1, p2)
    J = np.empty((a.size, 2, 2))
    J[:, :, 0] = t1 / a[:, None]
    J[:, :, 1] = (t2 - t1 * (b / a)[:, None]) / c[:, None]
    return J


@dataclass
class Metrics:
    """Accumulated area-weighted sums of the metrics of hsh10 section 4; combine charts with ``+``.

    Parameters
    ----------
    area, angle_sum, area_sum, stretch_sum, texture_area : float, optional
    det_sum, invdet_sum : float, optional
        Sum A_j s1 s2 and sum A_j / (s1 s2): for the rescaled E_area.
    samples, flips : int, optional
    arap_sum : float, optional
        Sum A_j min_R ||grad phi_j - R||^2: the quadrature of hsh10 Eq. 1.

    Examples
    --------
    A triangle textured by a similarity of scale 2 keeps its angles (E_angle = 2, the minimum) and
    distorts the area by s1 s2 + 1/(s1 s2) = 4 + 1/4:

    >>> import numpy as np
    >>> V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0.0]])
    >>> m = triangle_metrics(V, 2 * V[:, :2], np.array([[0, 1, 2]]))
    >>> [round(x, 9) for x in m.as_tuple()[:2]], (m + m).samples
    ([2.0, 4.25], 2)
    """

    area: float = 0.0
    angle_sum: float = 0.0
    area_sum: float = 0.0
    stretch_sum: float = 0.0
    texture_area: float = 0.0
    #: sum A_j s1 s2 and sum A_j / (s1 s2): for the rescaled E_area
    det_sum: float = 0.0
    invdet_sum: float = 0.0
    samples: int = 0
    flips: int = 0
    #: sum A_j min_R ||grad phi_j - R||^2: the quadrature of hsh10 Eq. 1
    arap_sum: float = 0.0

    def __add__(self, other):
        return Metrics(
            self.area + other.area,
            self.angle_sum + other.angle_sum,
            self.area_sum + other.area_sum,
            self.stretch_sum + other.stretch_sum,
            self.texture_area + other.texture_area,
            self.det_sum + other.det_sum,
            self.invdet_sum + other.invdet_sum,
            self.samples + other.samples,
            self.flips + other.flips,
            self.arap_sum + other.arap_sum,
        )

    @property
    def E_angle(self):
        return self.angle_sum / self.area

    @property
    def E_area(self):
        return self.area_sum / self.area

    @property
    def E_arap(self):
        """Area-weighted mean of min_R ||grad phi - R||_F^2 (hsh10 Eq. 1 divided by the area)."""
        return self.arap_sum / self.area

    @property
    def E_stretch(self):
        return float(np.sqrt(self.stretch_sum / self.area) * np.sqrt(self.texture_area / self.area))

    def rescaled(self):
        """(E_angle, E_area, E_stretch) after scaling the texture so that sum A_T = sum A."""
        s2 = self.area / self.texture_area  # texture scale^2 to apply
        e_area = (s2 * self.det_sum + self.invdet_sum / s2) / self.area
        return self.E_angle, e_area, self.E_stretch

    def as_tuple(self):
        return self.E_angle, self.E_area, self.E_stretch

    def __repr__(self):
        return (
            f"Metrics(E_angle={self.E_angle:.6f}, E_area={self.E_area:.6f}, E_stretch={self.E_stretch:.6f}, "
            f"flips={self.flips}, samples={self.samples})"
        )


def sample_metrics(samples: SampleSet, T, per_sample=False):
    """Metrics of the level-k texture values ``T`` (n_k, 2) on the samples ``samples``.

    Parameters
    ----------
    samples : SampleSet
        Samples of one level (:func:`~ccproof.apps.arap.samples.build_samples`, purpose "metric").
    T : ndarray, shape (n_k, 2) float64
    per_sample : bool, optional

    Returns
    -------
    Metrics, and with ``per_sample=True`` also a dict of per-sample arrays (s1, s2, det, weight,
    area distortion s1 s2 + 1/(s1 s2)).

    Examples
    --------
    The identity texture of a flat grid is an isometry:

    >>> from ccproof.mesh.examples import grid
    >>> from ccproof.apps.arap.hierarchy import ChartHierarchy
    >>> from ccproof.apps.arap.samples import build_samples
    >>> L = ChartHierarchy(grid(3, 3), range(9)).level(1)
    >>> m = sample_metrics(build_samples(L, "extended", "metric"), L.mesh.vertices[:, :2])
    >>> [round(x, 9) for x in m.as_tuple()]
    [2.0, 2.0, 1.0]
    """
    t1, t2 = samples.texture_tangents(T)
    # samples with a degenerate surface frame (zero area element) carry no weight: leave them out
    ok = samples.weight > 1e-14 * samples.weight.max()
    p1, p2, t1, t2 = samples.p1[ok], samples.p2[ok], t1[ok], t2[ok]
    J = jacobians(p1, p2, t1, t2)
    s1, s2, det = singular_values(J)
    w = samples.weight[ok]
    with np.errstate(divide="ignore", invalid="ignore"):
        ang = s1 / s2 + s2 / s1
        pr = s1 * s2
        are = pr + 1.0 / pr
        st = 0.5 * (1.0 / s1**2 + 1.0 / s2**2)
    at = np.abs(t1[:, 0] * t2[:, 1] - t1[:, 1] * t2[:, 0]) * samples.area_factor[ok]
    m = Metrics(
        area=float(w.sum()),
        angle_sum=float(w @ ang),
        area_sum=float(w @ are),
        stretch_sum=float(w @ st),
        texture_area=float(at.sum()),
        det_sum=float(w @ pr),
        invdet_sum=float(w @ (1.0 / pr)),
        samples=int(w.size),
        flips=int((det <= 0).sum()),
        arap_sum=float(w @ ((s1 - 1) ** 2 + (s2 - np.sign(det)) ** 2)),
    )
    if per_sample:
        return m, {"s1": s1, "s2": s2, "det": det, "weight": w, "area_distortion": are,
                   "vertex": samples.vertex[ok]}
    return m


def triangle_metrics(P, UV, T, per_triangle=False):
    """The section-4 metrics of a piecewise-linear map: triangles ``T`` of positions ``P`` to ``UV``.

    Every triangle is one sample with tangents = its edge vectors ``p1 = P[b] - P[a]``,
    ``p2 = P[c] - P[a]`` (and the same for UV), weight = its 3D area, texture area = its UV area.
    This is how other tools see a written mesh (:mod:`~ccproof.apps.arap.export`).

    Parameters
    ----------
    P : (n, 3), UV : (n, 2), T : int (m, 3)

    Returns
    -------
    Metrics, and with ``per_triangle`` a dict of (m,) arrays s1, s2, det, weight, area_distortion
    (``s1 s2 + 1/(s1 s2)``) and stretch (``sqrt((1/s1^2 + 1/s2^2) / 2)``).

    Examples
    --------
    >>> import numpy as np
    >>> V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0.0]])
    >>> m, d = triangle_metrics(V, np.array([[0, 0], [2, 0], [0, 1.0]]), np.array([[0, 1, 2]]), per_triangle=True)
    >>> d["s1"].tolist(), d["s2"].tolist(), d["area_distortion"].tolist()
    ([2.0], [1.0], [2.5])
    """
    P = np.asarray(P, dtype=np.float64)
    UV = np.asarray(UV, dtype=np.float64)
    T = np.asarray(T, dtype=np.int64)
    p1, p2 = P[T[:, 1]] - P[T[:, 0]], P[T[:, 2]] - P[T[:, 0]]
    t1, t2 = UV[T[:, 1]] - UV[T[:, 0]], UV[T[:, 2]] - UV[T[:, 0]]
    w = 0.5 * np.linalg.norm(np.cross(p1, p2), axis=1)
    ok = w > 1e-14 * w.max()
    J = jacobians(p1[ok], p2[ok], t1[ok], t2[ok])
    s1, s2, det = singular_values(J)
    wk = w[ok]
    with np.errstate(divide="ignore", invalid="ignore"):
        ang = s1 / s2 + s2 / s1
        pr = s1 * s2
        are = pr + 1.0 / pr
        st = 0.5 * (1.0 / s1**2 + 1.0 / s2**2)
    at = 0.5 * np.abs(t1[ok, 0] * t2[ok, 1] - t1[ok, 1] * t2[ok, 0])
    m = Metrics(
        area=float(wk.sum()), angle_sum=float(wk @ ang), area_sum=float(wk @ are), stretch_sum=float(wk @ st),
        texture_area=float(at.sum()), det_sum=float(wk @ pr), invdet_sum=float(wk @ (1.0 / pr)),
        samples=int(wk.size), flips=int((det <= 0).sum()),
        arap_sum=float(wk @ ((s1 - 1) ** 2 + (s2 - np.sign(det)) ** 2)),
    )
    if not per_triangle:
        return m

    def full(x, fill=np.nan):
        out = np.full(T.shape[0], fill)
        out[ok] = x
        return out

    return m, {"s1": full(s1), "s2": full(s2), "det": full(det), "weight": w, "area_distortion": full(are),
               "stretch": full(np.sqrt(st))}


def excess_ratios(metrics: Metrics, exact: Metrics):
    """(E_angle, E_area, E_stretch) excess of ``metrics`` over ``exact``'s (1 where both are 0).

    >>> import numpy as np
    >>> V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0.0]])
    >>> m2, m3 = (triangle_metrics(V, s * V[:, :2], np.array([[0, 1, 2]])) for s in (2, 3))
    >>> [round(x, 6) for x in excess_ratios(m3, m2)]  # E_area: (9 + 1/9 - 2) / (4 + 1/4 - 2); no angle or stretch
    [1.0, 3.160494, 1.0]
    """
    m, e = metrics.as_tuple(), exact.as_tuple()
    return tuple((a - z) / (b - z) if b - z > 0 else (1.0 if a - z <= 0 else float("inf"))
                 for a, b, z in zip(m, e, (2.0, 2.0, 1.0)))


def minimax_choice(exact: Metrics, candidates):
    """Per chart, the candidate that makes the largest global excess ratio smallest.

    ``candidates[c]`` is chart c's list of Metrics (index 0: the default). Coordinate descent (one chart's choice
    at a time, while the largest ratio falls) from every uniform start (all charts on candidate j, or on 0 where
    they have fewer), the best end kept: never worse than the all-default choice or any uniform one, and no single
    chart's change lowers the result.

    Returns
    -------
    list of int
        The chosen index per chart.
    """
    def worst(choice):
        tot = Metrics()
        for c, j in zip(candidates, choice):
            tot = tot + c[j]
        return max(excess_ratios(tot, exact))

    best = None
    for start in range(max(len(c) for c in candidates)):
        choice = [start if start < len(c) else 0 for c in candidates]
        cur = worst(choice)
        improved = True
        while improved:
            improved = False
            for i, c in enumerate(candidates):
                for j in range(len(c)):
                    if j == choice[i]:
                        continue
                    trial = choice[:i] + [j] + choice[i + 1:]
                    v = worst(trial)
                    if v < cur:
                        cur, choice, improved = v, trial, True
        if best is None or cur < best[0]:
            best = (cur, choice)
    return best[1]
