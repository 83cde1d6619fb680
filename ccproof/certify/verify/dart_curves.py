"""T and W for every dart K >= K0: the outer curves of the family's nets as Taylor models in h (trusted).

T: a1 X Y' - a2 Y X' along the four outer curves (a_i = -ln lam_i), in the bulk, middle and layer regions
of :mod:`.dart_regularity`. W: the signs of X and Y on the outer curves' Bezier points that, with T, make
the outer curve cross the half-axis {Y = 0, X > 0} exactly once (docs/tagged_c1.md, item 6, "Winding").
The models and the disc bounds are those of :mod:`ccproof.rigorous.analytic`.
"""

from __future__ import annotations

from flint import acb, ctx

from ccproof.rigorous.analytic import AnalyticModel, ball, hull

from .dart_family import (
    PIECES,
    XB,
    YB,
    curve_trans_series,
    series_coeffs,
    series_curves,
)
from .dart_regularity import mode_factors, real_hull
from .maps import STAR_CURVES


def _log_coeffs(fam, n, real=False):
    """The Taylor coefficients of (a1, a2) = (-ln lam1, -ln lam2) (at an acb h, the values: ZeroDivisionError
    unless certainly off the branch cut)."""
    if isinstance(fam.lam1, acb) and not (acb(fam.lam1).real > 0 and acb(fam.lam2).real > 0):
        raise ZeroDivisionError("log lam: not certainly off the branch cut")
    return [series_coeffs(-lam.log(), n + 1, real) for lam in (fam.lam1, fam.lam2)]


def trans_series(fam, nets, n):
    """{(i, j, curve): [the 6 Bernstein coefficients of a1 X_i Y_j' - a2 Y_j X_i' of h^m, m = 0..n]} (series;
    values with n = 0); T_ij(0) = 0 exactly (a1 = a2, both parts multiples of one real curve at h = 0)."""
    A1, A2 = _log_coeffs(fam, n)
    curves = {b: series_curves(nets[b], n) for b in nets}
    return {(i, j, c): curve_trans_series(curves[i][c], curves[j][c], A1, A2, n)
            for i in XB for j in YB for c in STAR_CURVES}


def layer_trans_series(fam, lnets, n, real=False):
    """{curve: [coefficients of h^m]} of a1 X Y' - a2 Y X' on a layer quadrant (h^0..h^2: 0 exactly; ``real``:
    of the real parts)."""
    A1, A2 = _log_coeffs(fam, n, real)
    xs, ys = (series_curves({p: lnets[p][k] for p in PIECES}, n, real) for k in (0, 1))
    return {c: curve_trans_series(xs[c], ys[c], A1, A2, n) for c in STAR_CURVES}


def layer_y_series(lnets, n, real=False):
    """{curve: [m: 4 acb]}: Taylor coefficients of Y's outer-curve points on a layer quadrant."""
    return series_curves({p: lnets[p][1] for p in PIECES}, n, real)


def curve_models(T, M, r, parts):
    """{curve: AnalyticModel}: row p the Bezier point, column the basis part (in the order of ``parts``)."""
    return {c: AnalyticModel.from_columns([T[(b, c)] for b in parts], [M[(b, c)] for b in parts], r)
            for c in STAR_CURVES}


def coord_box(models, s_lo, s_hi, h_lo, h_hi, sigma, coord, prec=128):
    """An arb holding X or Y on every outer curve's Bezier points, s in [s_lo, s_hi], h in [h_lo, h_hi] (a
    bulk quadrant), from the models of :func:`curve_models`."""
    with ctx.workprec(prec):
        fac = mode_factors(ball(s_lo, s_hi), sigma)[0 if coord == "x" else 1]
        return real_hull(models, fac, h_lo, h_hi, 0, prec)


def layer_y_box(models, q, h_lo, h_hi, prec=128):
    """An arb holding K Y over layer quadrant q's outer-curve points (K^2 Y at ray 0's end point of quadrant 0),
    h in [h_lo, h_hi], from one-column models (:func:`.dart_regularity.column_models`); the coefficients below
    h^order are dropped (0 exactly: y = O(h), and O(h^2) at ray 0's end point where x, hence y's first order,
    vanishes)."""
    with ctx.workprec(prec):
        vals = []
        for c, model in models.items():
            ky, k2y = (model.real_part([1], h_lo, h_hi, low=order) for order in (1, 2))
            vals += [k2y[p] if (q == 0 and c == "P1s1" and p == 0) else ky[p] for p in range(4)]
        return hull(vals)
