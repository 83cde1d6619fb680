"""Synthetic range data standing in for the paper's scans (docs/qmv98.md Q9; the bulb, head and anvil scans of
qmv98 Figs. 7-9 are not available).

* ``"bulb"``: a surface of revolution, a unit sphere above the equator that narrows and stretches below
  it (a light-bulb profile), 1,000 points in the paper;
* ``"ellipsoid"``: semi-axes 1, 0.8, 1.25 (a head-sized blob), 1,779 points;
* ``"superquadric"``: exponent 0.5 (rounded box, an anvil-like block), semi-axes 1.4, 0.7, 0.8,
  2,031 points;
* ``"torus"``: radii 1 and 0.4 around the z axis (genus 1: a closed genus-0 start mesh cannot match
  it), 1,500 points;
* ``"half_ellipsoid"``: the ``"ellipsoid"`` points with z >= 0 only (a scan seen from one side),
  1,000 points.

Points are drawn area-uniformly (surfaces of revolution and ellipsoids) or as the image of uniform
points of the sphere (superquadric).

>>> X = synthetic_range_data("ellipsoid", 500)
>>> X.shape, bool(np.allclose((X[:, 0] / 1.0) ** 2 + (X[:, 1] / 0.8) ** 2 + (X[:, 2] / 1.25) ** 2, 1))
((500, 3), True)
"""

from __future__ import annotations

import numpy as np

from ccproof.errors import CCProofError

__all__ = ["SHAPES", "PAPER_SIZES", "synthetic_range_data"]

SHAPES = ("bulb", "ellipsoid", "superquadric", "torus", "half_ellipsoid")

#: the paper's data sizes (bulb, head, anvil)
PAPER_SIZES = {"bulb": 1000, "ellipsoid": 1779, "superquadric": 2031, "torus": 1500, "half_ellipsoid": 1000}


def _smoothstep(x):
    x = np.clip(x, 0.0, 1.0)
    return x * x * (3 - 2 * x)


def _bulb_profile(th):
    sig = _smoothstep((th - np.pi / 2) / (np.pi / 2))
    rho = np.sin(th) * (1 - 0.45 * sig)
    z = np.cos(th) * (1 + 0.7 * sig)
    return rho, z


def _revolution(profile, m, rng):
    th = np.linspace(0.0, np.pi, 4001)
    rho, z = profile(th)
    ds = np.hypot(np.gradient(rho, th), np.gradient(z, th))
    w = rho * ds
    cdf = np.concatenate([[0.0], np.cumsum(0.5 * (w[1:] + w[:-1]) * np.diff(th))])
    t = np.interp(rng.random(m) * cdf[-1], cdf, th)
    r, zz = profile(t)
    ph = rng.random(m) * 2 * np.pi
    return np.stack([r * np.cos(ph), r * np.sin(ph), zz], axis=1)


def _sphere(m, rng):
    n = rng.standard_normal((m, 3))
    return n / np.linalg.norm(n, axis=1, keepdims=True)


def synthetic_range_data(name, m=None, seed=0, noise=0.0):
    """``m`` points on the synthetic shape ``name`` (default: the paper's size), optional Gaussian noise
    of standard deviation ``noise`` (absolute units).

    The range data of the fitting examples of qmv98 section 4 (docs/qmv98.md B6).

    Parameters
    ----------
    name : str
        One of :data:`SHAPES`.
    m : int, optional
        Number of points (default :data:`PAPER_SIZES` of the shape).
    seed : int, optional
        Seed of ``numpy.random.default_rng``.
    noise : float, optional

    Returns
    -------
    ndarray, shape (m, 3) float64

    Examples
    --------
    Points of the ellipsoid with semi-axes 1, 0.8, 1.25 satisfy its equation:

    >>> import numpy as np
    >>> X = synthetic_range_data("ellipsoid", 50)
    >>> X.shape, bool(np.allclose((X / [1, 0.8, 1.25]) ** 2 @ np.ones(3), 1))
    ((50, 3), True)
    """
    if name not in SHAPES:
        raise CCProofError(f"unknown shape {name!r}; choose one of {', '.join(SHAPES)}")
    m = PAPER_SIZES[name] if m is None else int(m)
    if m < 1:
        raise CCProofError("m must be >= 1")
    rng = np.random.default_rng(seed)
    if name == "bulb":
        X = _revolution(_bulb_profile, m, rng)
    elif name == "ellipsoid":
        ax = np.array([1.0, 0.8, 1.25])
        # area-uniform by rejection: accept a sphere point with probability |grad| ratio
        out = []
        while sum(len(o) for o in out) < m:
            n = _sphere(4 * m, rng)
            g = np.linalg.norm(n / ax * np.prod(ax), axis=1)  # area element of x = ax * n
            keep = rng.random(n.shape[0]) < g / g.max() if g.max() > 0 else np.ones(n.shape[0], bool)
            out.append(n[keep] * ax)
        X = np.concatenate(out)[:m]
    elif name == "torus":
        R, r = 1.0, 0.4
        out = []
        while sum(len(o) for o in out) < m:  # area element (R + r cos v): rejection on v
            u, v = rng.random((2, 4 * m)) * 2 * np.pi
            keep = rng.random(4 * m) < (R + r * np.cos(v)) / (R + r)
            u, v = u[keep], v[keep]
            out.append(np.stack([(R + r * np.cos(v)) * np.cos(u), (R + r * np.cos(v)) * np.sin(u), r * np.sin(v)], 1))
        X = np.concatenate(out)[:m]
    elif name == "half_ellipsoid":
        E = synthetic_range_data("ellipsoid", 2 * m + 50, seed=seed)
        X = E[E[:, 2] >= 0][:m]
    else:
        ax = np.array([1.4, 0.7, 0.8])
        n = _sphere(m, rng)
        X = ax * np.sign(n) * np.abs(n) ** 0.5
    if noise:
        X = X + noise * rng.standard_normal(X.shape)
    return X
