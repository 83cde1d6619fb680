"""The regular Loop patch: the quartic three-direction box spline on its 12 control points.

A triangle whose three vertices are regular (smooth, valence 6, untagged one-ring) is a polynomial
patch of total degree 4 on the 12 vertices of its one-ring (Loop 1987; Stam 1998), listed by their
lattice position :data:`NET` in the triangle's frame: P(0,0) = v0, P(1,0) = v1, P(0,1) = v2, edges
along (1, 0), (0, 1) and (-1, 1)::

            (-1,2)  (0,2)
        (-1,1)  v2=(0,1)  (1,1)
    (-1,0)  v0=(0,0)  v1=(1,0)  (2,0)
        (0,-1)  (1,-1)  (2,-1)

The 12 basis polynomials are not typed in: :func:`basis_coefficients` derives them exactly from the
Loop rules of :data:`ccproof.mesh.scheme.LOOP` (the box spline B is the limit of a delta on the regular
lattice: two exact Loop steps, then the limit mask, give B on the quarter lattice; the 15 values in the
triangle determine each quartic). :func:`basis` evaluates them and their derivatives.
"""

from __future__ import annotations

import functools

import numpy as np

from ccproof.mesh.scheme import LOOP

__all__ = ["NET", "DIRS", "basis_coefficients", "basis", "MONOMIALS"]

#: the six lattice directions counter-clockwise (the one-ring of a regular vertex)
DIRS = ((1, 0), (0, 1), (-1, 1), (-1, 0), (0, -1), (1, -1))
#: lattice positions of the 12 control points of a regular patch, in net order
NET = ((0, 0), (1, 0), (0, 1), (-1, 0), (0, -1), (1, -1), (2, -1), (2, 0), (1, 1), (0, 2), (-1, 2), (-1, 1))
#: exponents (p, q) of the monomials u^p v^q of degree <= 4
MONOMIALS = tuple((p, d - p) for d in range(5) for p in range(d, -1, -1))


def _loop_step_lattice(c):
    """One Loop step of coefficients ``c`` (dict lattice point -> flint.fmpq) on the regular lattice."""
    import flint

    one = flint.fmpq(1)
    wV, we = LOOP.vertex_point(6, one)
    ev, eo = LOOP.edge_point(one)
    pts = set()
    for (i, j) in c:
        for di, dj in ((0, 0),) + DIRS:
            pts.add((i + di, j + dj))
    out = {}
    for (i, j) in pts:
        s = wV * c.get((i, j), 0) + we * sum(c.get((i + a, j + b), 0) for a, b in DIRS)
        if s:
            out[(2 * i, 2 * j)] = s
        for n in range(3):  # edges (i, j) -> (i, j) + DIRS[n]
            (a, b), (p, q), (r, s2) = DIRS[n], DIRS[n + 1], DIRS[n - 1]
            e = ev * (c.get((i, j), 0) + c.get((i + a, j + b), 0)) + eo * (c.get((i + p, j + q), 0) +
                                                                           c.get((i + r, j + s2), 0))
            if e:
                out[(2 * i + a, 2 * j + b)] = e
    return out


@functools.lru_cache(maxsize=1)
def basis_coefficients():
    """Exact coefficients of the 12 basis polynomials: ``K[m][i]`` is the coefficient of monomial
    ``MONOMIALS[m]`` in the basis function of control point ``NET[i]``.

    Examples
    --------
    The basis is a partition of unity: the constant terms sum to 1, every other monomial's to 0; the
    patch interpolates nothing but reproduces the limit point ``(v0 / 2 + sum of its neighbours / 12)``
    at (0, 0):

    >>> K = basis_coefficients()
    >>> [sum(row) for row in K] == [1] + [0] * 14, [str(x) for x in K[0][:3]]
    (True, ['1/2', '1/12', '1/12'])
    """
    import flint

    one = flint.fmpq(1)
    c = {(0, 0): one}
    for _ in range(2):
        c = _loop_step_lattice(c)
    lV, le = LOOP.limit(6, one)

    def box(x):  # B at the quarter-lattice point x / 4
        return lV * c.get(x, 0) + le * sum(c.get((x[0] + a, x[1] + b), 0) for a, b in DIRS)

    samples = [(a, b) for a in range(5) for b in range(5 - a)]
    V = flint.fmpq_mat(15, 15, [flint.fmpq(a**p * b**q, 4 ** (p + q)) for a, b in samples for p, q in MONOMIALS])
    rhs = flint.fmpq_mat(15, 12, [box((a - 4 * du, b - 4 * dv)) for a, b in samples for du, dv in NET])
    X = V.solve(rhs)
    return tuple(tuple(X[m, i] for i in range(12)) for m in range(15))


@functools.lru_cache(maxsize=1)
def _coefficient_arrays():
    """Float coefficient matrices of the basis and of its five derivatives, each (15, 12)."""
    K = np.array([[int(x.p) / int(x.q) for x in row] for row in basis_coefficients()])
    idx = {e: m for m, e in enumerate(MONOMIALS)}

    def diff(C, du, dv):
        out = np.zeros_like(C)
        for m, (p, q) in enumerate(MONOMIALS):
            if p >= du and q >= dv:
                f = np.prod(range(p - du + 1, p + 1)) * np.prod(range(q - dv + 1, q + 1))
                out[idx[(p - du, q - dv)]] += f * C[m]
        return out

    return {(0, 0): K, (1, 0): diff(K, 1, 0), (0, 1): diff(K, 0, 1), (2, 0): diff(K, 2, 0),
            (1, 1): diff(K, 1, 1), (0, 2): diff(K, 0, 2)}


def basis(u, v, derivatives=0):
    """Weights of the 12 control points at (u, v), shape (n, 12), and their derivatives.

    Returns a dict with keys ``(0, 0)`` and, for ``derivatives >= 1``, ``(1, 0)``, ``(0, 1)``
    (d/du, d/dv), for ``derivatives == 2`` also ``(2, 0)``, ``(1, 1)``, ``(0, 2)``.

    Examples
    --------
    >>> w = basis(np.array([0.25]), np.array([0.5]), 1)
    >>> round(float(w[(0, 0)].sum()), 14), abs(round(float(w[(1, 0)].sum()), 14))
    (1.0, 0.0)
    """
    u = np.asarray(u, dtype=np.float64)
    v = np.asarray(v, dtype=np.float64)
    up = [np.ones_like(u), u, u * u, u * u * u, (u * u) * (u * u)]
    vp = [np.ones_like(v), v, v * v, v * v * v, (v * v) * (v * v)]
    Mono = np.stack([up[p] * vp[q] for p, q in MONOMIALS], axis=-1)
    C = _coefficient_arrays()
    keys = [(0, 0)] + ([(1, 0), (0, 1)] if derivatives >= 1 else []) + \
        ([(2, 0), (1, 1), (0, 2)] if derivatives >= 2 else [])
    return {k: Mono @ C[k] for k in keys}
