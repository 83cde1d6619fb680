"""Quadrature on Catmull-Clark limit surfaces: per-face Gauss rules that know the extraordinary vertices.

A rule is a set of points ``(face, u, v)`` of the face parameter domains with weights ``w`` such that
``sum w g(face, u, v)`` approximates ``sum_faces int_[0,1]^2 g du dv``; surface integrals multiply g by the
area element ``|Pu x Pv|`` of the parameterization the points are evaluated in
(:class:`ccproof.apps.iga.assembly.SurfaceFields`). Three kinds:

``"plain"``
    ``order x order`` Gauss-Legendre points on every face.
``"adaptive"`` (natural parameterization)
    The same on faces without an irregular corner; a face with an irregular vertex (interior valence
    != 4, or a boundary vertex with other than two faces: :func:`irregular_corners`) at corner c gets,
    in its quadrant at c, the dyadic rings of the natural parameterization (layer n: the three squares
    of side ``2^-(n+1)`` where ``max(du, dv)`` lies in ``[2^-(n+1), 2^-n)``, du, dv the distances to the
    corner), ``depth`` of them, and a Gauss rule on the innermost square; its other quadrants a Gauss
    rule each. Every square of a ring is one bicubic polynomial patch of the surface (bmz04 Fig. 3), so
    the basis functions are polynomials on every cell.
``"split"`` (characteristic parameterization)
    Cells cut at the blend's breakpoints 1/6, 1/3, 1/2 (distance to every extraordinary corner of the
    face, along u and v), a Gauss rule per cell: the blend ``b(s) b(t)`` is C2 but not C3 there.

Error model. On a cell where the integrand is smooth with bounded derivatives of order 2q, a q-point
Gauss rule errs by ``O(h^(2q))`` (h the cell's side) times those derivatives. In the natural
parameterization the basis functions near an extraordinary vertex of valence k are smooth on each ring
square, with derivatives of order r growing like ``(2^r lam)^n`` in ring n (lam the subdominant
eigenvalue); the area element vanishes or blows up like ``(4 lam^2)^n``: the ring cells, of side ``2^-n``,
scale them back to ``O(lam^(2n))`` per cell, and the innermost square (area ``4^-(depth + 1)`` of the
face) is integrated with the integrand's own local size, so the rule's error is a geometric sum in the
ring index, dominated by the coarse rings, plus ``O((4 lam^2)^depth)`` from the inner square. Without
rings (``"plain"``) the face's Gauss rule samples a function that is only C1 (and piecewise polynomial
on a dyadic grid that the points do not resolve) at the corner: errors of the order of the face size
to a low power, which is the loss of rate measured in docs/iga.md.

>>> from ccproof.mesh.examples import cube
>>> from ccproof.evaluate import natural_limit_surface
>>> Q = surface_quadrature(natural_limit_surface(cube()), order=2, kind="adaptive", depth=3)
>>> round(float(Q.weight.sum()), 12)          # the six unit parameter squares
6.0
>>> Q.face.size                               # 6 faces x 4 quadrants x (3 squares x 3 rings + 1) x 2 x 2
960
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ccproof.errors import CCProofError

__all__ = ["QuadratureRule", "surface_quadrature", "quadrature_cells", "cells_rule", "extraordinary_corners",
           "irregular_corners", "RULE_KINDS"]

RULE_KINDS = ("plain", "adaptive", "split")

#: breakpoints of the characteristic parameterization's blend, as distances to the corner
BLEND_BREAKPOINTS = (1.0 / 6.0, 1.0 / 3.0, 0.5)


class QuadratureRule(NamedTuple):
    """Points ``(face, u, v)`` with parameter-domain weights ``weight`` (all shape (n,))."""

    face: np.ndarray
    u: np.ndarray
    v: np.ndarray
    weight: np.ndarray


def extraordinary_corners(mesh):
    """Per face and corner, whether the corner is an interior vertex of valence != 4, shape (m, 4) bool.

    >>> from ccproof.mesh.examples import cube, torus
    >>> bool(extraordinary_corners(cube()).all()), bool(extraordinary_corners(torus()).any())
    (True, False)
    """
    val = np.asarray(mesh.valence)
    ev = (val != 4) & ~np.asarray(mesh.is_boundary_vertex)
    return ev[np.asarray(mesh.faces)]


def irregular_corners(mesh):
    """Per face and corner, whether the corner is irregular: an extraordinary vertex, or a boundary vertex
    with a number of faces other than 2 (a corner of an open mesh; the limit is piecewise polynomial on
    dyadic rings there too, and its metric degenerates at the vertex), shape (m, 4) bool.

    >>> from ccproof.mesh.examples import grid
    >>> irregular_corners(grid(2, 1)).astype(int).tolist()
    [[1, 0, 0, 1], [0, 1, 1, 0]]
    """
    val = np.asarray(mesh.valence)
    bnd = np.asarray(mesh.is_boundary_vertex)
    irr = np.where(bnd, np.asarray(mesh.face_count) != 2, val != 4)
    return irr[np.asarray(mesh.faces)]


def _gauss(order):
    x, w = np.polynomial.legendre.leggauss(order)
    return 0.5 * (x + 1.0), 0.5 * w


def cells_rule(cells, order):
    """The ``order x order`` Gauss-Legendre rule on cells ``(face, u0, v0, hu, hv)`` (arrays).

    >>> import numpy as np
    >>> Q = cells_rule((np.array([3]), np.array([0.5]), np.array([0.0]), np.array([0.5]), np.array([0.25])), 2)
    >>> Q.face.tolist(), round(float(Q.weight.sum()), 15)
    ([3, 3, 3, 3], 0.125)
    """
    f, u0, v0, hu, hv = (np.asarray(a) for a in cells)
    x, w = _gauss(order)
    X, Y = np.meshgrid(x, x, indexing="ij")
    WW = np.outer(w, w).ravel()
    u = u0[:, None] + hu[:, None] * X.ravel()[None, :]
    v = v0[:, None] + hv[:, None] * Y.ravel()[None, :]
    wt = (hu * hv)[:, None] * WW[None, :]
    return QuadratureRule(np.repeat(f, x.size**2), u.ravel(), v.ravel(), wt.ravel())


#: corner c of a face at (cu, cv): (0,0), (1,0), (1,1), (0,1)
_CORNER_AT = ((0, 0), (1, 0), (1, 1), (0, 1))


def _ring_cells(depth):
    """Squares ``(s0, t0, h)`` covering [0, 1/2]^2 toward the corner (0, 0): ``depth`` dyadic rings of
    three squares and the innermost square."""
    out = []
    for n in range(1, depth + 1):
        a = 2.0 ** -(n + 1)
        out += [(a, 0.0, a), (a, a, a), (0.0, a, a)]
    a = 2.0 ** -(depth + 1)
    out.append((0.0, 0.0, a))
    return np.array(out)


def _adaptive_cells(ev, depth):
    """Cells of the adaptive rule for faces with the corner flags ``ev`` (m, 4)."""
    plain = np.flatnonzero(~ev.any(axis=1))
    cells = [(plain, np.zeros(plain.size), np.zeros(plain.size), np.ones(plain.size), np.ones(plain.size))]
    rings = _ring_cells(depth)
    for c, (cu, cv) in enumerate(_CORNER_AT):
        q0u, q0v = 0.5 * cu, 0.5 * cv  # the quadrant at corner c
        has = np.flatnonzero(ev[:, c])
        other = np.flatnonzero(ev.any(axis=1) & ~ev[:, c])
        half = np.full(other.size, 0.5)
        cells.append((other, np.full(other.size, q0u), np.full(other.size, q0v), half, half))
        if has.size:
            s0, t0, h = rings[:, 0], rings[:, 1], rings[:, 2]
            u0 = (1.0 - s0 - h) if cu else s0  # mirrored toward a corner at 1
            v0 = (1.0 - t0 - h) if cv else t0
            k = rings.shape[0]
            cells.append((np.repeat(has, k), np.tile(u0, has.size), np.tile(v0, has.size), np.tile(h, has.size),
                          np.tile(h, has.size)))
    return [np.concatenate(parts) for parts in zip(*cells)]


def _split_cells(ev):
    """Cells of the split rule: every face cut at the blend's breakpoints from each extraordinary corner."""
    parts = []
    for f in range(ev.shape[0]):
        bu, bv = {0.0, 1.0}, {0.0, 1.0}
        for c, (cu, cv) in enumerate(_CORNER_AT):
            if ev[f, c]:
                bu |= {1.0 - b if cu else b for b in BLEND_BREAKPOINTS}
                bv |= {1.0 - b if cv else b for b in BLEND_BREAKPOINTS}
        su, sv = np.array(sorted(bu)), np.array(sorted(bv))
        U0, V0 = np.meshgrid(su[:-1], sv[:-1], indexing="ij")
        HU, HV = np.meshgrid(np.diff(su), np.diff(sv), indexing="ij")
        parts.append((np.full(U0.size, f), U0.ravel(), V0.ravel(), HU.ravel(), HV.ravel()))
    return [np.concatenate(p) for p in zip(*parts)]


def quadrature_cells(surface, kind="adaptive", depth=12):
    """The cells of a rule: ``(face, u0, v0, hu, hv)`` arrays, cell ``[u0, u0 + hu] x [v0, v0 + hv]`` of ``face``.

    >>> from ccproof.mesh.examples import cube
    >>> from ccproof.evaluate import natural_limit_surface
    >>> f, u0, v0, hu, hv = quadrature_cells(natural_limit_surface(cube()), "split")
    >>> f.size, sorted(set(u0[f == 0].tolist()))    # cut at 1/6, 1/3, 1/2 from both corners of each face
    (216, [0.0, 0.16666666666666666, 0.3333333333333333, 0.5, 0.6666666666666667, 0.8333333333333334])
    """
    from ccproof.mesh import QuadMesh

    if kind not in RULE_KINDS:
        raise CCProofError(f"unknown quadrature kind {kind!r}; use one of {', '.join(RULE_KINDS)}")
    if int(depth) < 1:
        raise CCProofError(f"depth must be >= 1, got {depth!r}")
    if not isinstance(surface.mesh, QuadMesh):
        raise CCProofError(f"the quadrature needs a surface on a QuadMesh, not a {type(surface.mesh).__name__}")
    ev = irregular_corners(surface.mesh)
    m = ev.shape[0]
    if kind == "plain":
        one = np.ones(m)
        return np.arange(m), np.zeros(m), np.zeros(m), one, one
    if kind == "adaptive":
        return tuple(_adaptive_cells(ev, int(depth)))
    return tuple(_split_cells(ev))


def surface_quadrature(surface, order=4, kind="adaptive", depth=12):
    """A quadrature rule on the faces of ``surface`` (module docstring): ``order x order`` Gauss-Legendre
    points on every cell of :func:`quadrature_cells`, sorted face by face.

    Parameters
    ----------
    surface : LimitSurface
        On a QuadMesh (its faces are the rule's faces).
    order : int
        Gauss-Legendre points per direction and cell.
    kind : {"plain", "adaptive", "split"}
    depth : int
        Dyadic rings toward every extraordinary corner (``"adaptive"``).

    Returns
    -------
    QuadratureRule

    Raises
    ------
    CCProofError
        An unknown kind, an order or depth below 1, a surface not on a QuadMesh.
    """
    if int(order) < 1:
        raise CCProofError(f"order and depth must be >= 1, got order={order!r}, depth={depth!r}")
    Q = cells_rule(quadrature_cells(surface, kind, depth), int(order))
    order_ = np.lexsort((Q.v, Q.u, Q.face))  # face by face
    return QuadratureRule(*(a[order_] for a in Q))
