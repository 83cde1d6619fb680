"""What to do with one tagged ring configuration, computed once per configuration (exact, then rounded).

:func:`plan` maps the key of a triangle's one-ring (:func:`~ccproof.evaluate.loop.complex.canonical_triangle_ring`)
to one of

* :class:`Regular`: the three corners are regular: the box-spline patch on 12 ring points;
* :class:`Corner`: corner 0 alone is irregular and the ring is self-similar (the ring of the child
  at corner 0 has the same key): Stam's layers. With ``A`` the exact subdivision matrix from the
  ring to the ring of the corner child, layer n (the corner child of level n minus its own corner
  child) consists of the three regular children of level n + 1 whose nets are ``M_j A^n C``; stored
  as the deviations ``M_j A^n - 1 l^T`` from the limit point (l: the exact limit mask), until they
  fall below 2^-60 (as :func:`ccproof.evaluate.local.power_layers` does for Catmull-Clark);
* :class:`Split`: anything else: one exact local Loop step; four child rings (stencil matrices from
  this ring), each planned in turn.

The weights of Loop's rules lie in Q(cos(2 pi / k)); they are computed as balls (``flint.arb``) of
:data:`PRECISION` bits, and every stored float is the ball's midpoint (correctly rounded), the radius
checked below 2^-120 times max(1, |value|): the deviations kept reach down to 2^-60, so each keeps a
relative accuracy of 2^-60 before its rounding to float64, the only error that matters.
"""

from __future__ import annotations

import contextlib
from dataclasses import dataclass

import numpy as np

from ccproof.errors import MeshError
from ccproof.evaluate.loop.box_spline import basis_coefficients
from ccproof.evaluate.loop.complex import (
    SMOOTH,
    canonical_triangle_ring,
    key_complex,
    limit_stencil,
    loop_step,
    regular_triangle_net,
)

__all__ = ["Regular", "Corner", "Split", "plan", "oriented_ring", "PRECISION", "MAX_DEPTH", "LAYER_TOLERANCE"]

#: bits of the balls in which the exact data are computed
PRECISION = 192
#: smallest deviation kept in a layer table (beyond it the layer equals the limit point in float64)
LAYER_TOLERANCE = 2.0**-60
#: most local subdivisions of one configuration before its children are regular or self-similar
MAX_DEPTH = 12
_MAX_LAYERS = 400


@dataclass(frozen=True, eq=False)
class Regular:
    """Box-spline patch: ``net`` (12, N): its control points (box_spline.NET order) from the ring."""
    net: np.ndarray


@dataclass(frozen=True, eq=False)
class Corner:
    """Self-similar layers at irregular corner 0: ``limit_mask`` (N,), ``layers`` (n_layers, 3, 12, N), and
    ``poly_layers`` (n_layers, 3, N, 15): the same in monomial form (the box spline's coefficients times each
    layer's nets: ring point q's weight in the coefficient of monomial m of child j of layer n)."""
    size: int
    limit_mask: np.ndarray
    layers: np.ndarray
    poly_layers: np.ndarray


@dataclass(frozen=True, eq=False)
class Split:
    """One local step: per child (rotation r, rows (N_child, N), child key) in loop_step's child order."""
    children: tuple


@contextlib.contextmanager
def _precision():
    import flint

    old = flint.ctx.prec
    flint.ctx.prec = PRECISION
    try:
        yield flint.arb(1)
    finally:
        flint.ctx.prec = old


def _to_float(x):
    if isinstance(x, (int, float)):
        return float(x)
    if float(x.rad()) > 2.0**-120 * max(1.0, abs(float(x.mid()))):
        raise MeshError(f"internal: a weight lost its precision ({x})")  # pragma: no cover
    return float(x.mid())


def _dense(rows, ncols):
    """Float matrix of stencils (dict column -> ball)."""
    M = np.zeros((len(rows), ncols))
    for i, s in enumerate(rows):
        for j, w in s.items():
            M[i, j] = _to_float(w)
    return M


def irregular_corners(cx, tri):
    return [i for i in range(3) if not cx.is_regular(tri[i], tri[(i + 1) % 3])]


def oriented_ring(cx, tri, irr=None):
    """(rotation r, ring labels, key) of a triangle: read from its irregular corner when it has one alone.

    Rotation r lists the triangle from its corner r (the parameter turns accordingly,
    :data:`ccproof.evaluate.loop.surface.ROTATIONS`). ``irr``: the irregular corners when known.
    """
    if irr is None:
        irr = irregular_corners(cx, tri)
    r = irr[0] if len(irr) == 1 else 0
    ring, key = canonical_triangle_ring(cx, tri[r:] + tri[:r])
    return r, ring, key


_PLANS: dict = {}


def plan(key, depth=0):
    """The :class:`Regular`, :class:`Corner` or :class:`Split` of a ring key (cached per key)."""
    if key in _PLANS:
        return _PLANS[key]
    if depth > MAX_DEPTH:
        raise MeshError(f"a triangle configuration is neither regular nor self-similar after {MAX_DEPTH} "
                        "local Loop steps")
    cx = key_complex(key)
    irr = irregular_corners(cx, (0, 1, 2))
    net = regular_triangle_net(cx, (0, 1, 2)) if not irr else None
    out = Regular(_dense(net, cx.n_vertices)) if net is not None else None
    if out is None and irr == [0]:
        out = _corner(cx, key)
    if out is None:
        out = _split(cx, key, depth)
    _PLANS[key] = out
    return out


def _children(cx, key, one):
    """(child complex, stencils, the four children of triangle (0, 1, 2))."""
    child, st = loop_step(cx, one)
    i = key[0].index((0, 1, 2))
    return child, st, child.triangles[4 * i:4 * i + 4]


def _split(cx, key, depth):
    with _precision() as one:
        child, st, kids = _children(cx, key, one)
        out = []
        for t in kids:
            r, ring, ckey = oriented_ring(child, t)
            rows = [st[x] for x in ring]
            if any(s is None for s in rows):
                raise MeshError("internal: a child ring needs triangles outside its parent's ring")
            out.append((r, _dense(rows, cx.n_vertices), ckey))
    return Split(tuple((r, rows, ckey, plan(ckey, depth + 1)) for r, rows, ckey in out))


def _corner(cx, key):

    with _precision() as one:
        child, st, kids = _children(cx, key, one)
        ring0, key0 = canonical_triangle_ring(child, kids[0])
        if key0 != key or any(irregular_corners(child, t) for t in kids[1:]):
            return None
        rows = [st[x] for x in ring0]
        nets = [regular_triangle_net(child, t) for t in kids[1:]]
        if any(n is None for n in nets) or any(s is None for s in rows):
            return None
        nets = [_compose(r, st) for n in nets for r in n]
        if any(s is None for s in nets):
            return None
        N = cx.n_vertices
        A, M = _arb_mat(rows, N), _arb_mat(nets, N)
        l_row = _limit_row(cx, A, N, one)
        layers = power_layers(M, A, l_row)
        return Corner(N, np.array([_to_float(l_row[0, j]) for j in range(N)]), layers, _monomial_form(layers))


def _monomial_form(layers):
    """(n_layers, 3, N, 15): the layers' nets (n_layers, 3, 12, N) times the box spline's coefficient matrix."""
    K = np.array([[int(x.p) / int(x.q) for x in row] for row in basis_coefficients()])  # (15, 12)
    return np.ascontiguousarray(np.matmul(K, layers).transpose(0, 1, 3, 2))


def _limit_row(cx, A, N, one):
    """The limit mask of corner 0 as a (1, N) ball matrix: Sdc's closed forms, and at a dart (smooth rule,
    one sharp edge, whose edge point is a midpoint) the left eigenvector of ``A`` for 1, solved exactly."""
    import flint

    rule, fan = cx.rule(0)
    if rule != SMOOTH or not any(cx.is_sharp(0, w) for w in fan):
        lmask = limit_stencil(cx, 0, one)
        return flint.arb_mat(1, N, [lmask.get(j, 0) for j in range(N)])
    B = (A - flint.arb_mat(N, N, [int(i == j) for i in range(N) for j in range(N)])).transpose()
    for j in range(N):
        B[N - 1, j] = 1
    x = B.solve(flint.arb_mat(N, 1, [0] * (N - 1) + [1]))
    return flint.arb_mat(1, N, [x[i, 0] for i in range(N)])


def _compose(row, stencils):
    """A stencil of child labels composed with the children's stencils (None where one is missing)."""
    out = {}
    for v, w in row.items():
        if stencils[v] is None:
            return None
        for x, y in stencils[v].items():
            out[x] = out.get(x, 0) + w * y
    return out


def _arb_mat(rows, ncols):
    import flint

    M = flint.arb_mat(len(rows), ncols)
    for i, s in enumerate(rows):
        for j, w in s.items():
            M[i, j] = w
    return M


def power_layers(M, A, l_row):
    """Rounded deviations ``M A^n - 1 l^T`` (balls), n = 0, 1, ... until below ``LAYER_TOLERANCE``.

    Returns ndarray (n_layers, 3, 12, N).

    Examples
    --------
    Point 1 moves halfway to point 0 at each step: the deviation of layer n is ``(-2^-n, 2^-n)``:

    >>> import flint
    >>> A = flint.arb_mat(2, 2, [1, 0, 0.5, 0.5])
    >>> D = power_layers(flint.arb_mat(36, 2, [0, 1] * 36), A, flint.arb_mat(1, 2, [1, 0]))
    >>> D.shape, D[3, 0, 0].tolist()
    ((62, 3, 12, 2), [-0.125, 0.125])
    """
    with _precision():
        return _power_layers(M, A, l_row)


def _power_layers(M, A, l_row):
    import flint

    rows, N = M.nrows(), A.nrows()
    L = flint.arb_mat(rows, N, [l_row[0, j] for _ in range(rows) for j in range(N)])
    R, layers = M, []
    for _ in range(_MAX_LAYERS):
        E = (R - L).entries()
        D = np.array([float(x) for x in E]).reshape(3, 12, N)  # the midpoints, correctly rounded
        layers.append(D)
        if np.abs(D).max() < LAYER_TOLERANCE:
            for x in E:  # the radii grow with n: checked on the last layer
                _to_float(x)
            return np.array(layers)
        R = R * A
    raise MeshError(f"corner configuration of {N} vertices does not converge to its limit point")
