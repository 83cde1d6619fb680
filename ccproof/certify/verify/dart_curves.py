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
    bezier_product,
    curve_trans_series,
    series_coeffs,
    series_curves,
)
from .dart_regularity import mode_factors, real_hull
from .maps import STAR_CURVES, curve_points


def _logs(fam):
    """(a1, a2) = (-ln lam1, -ln lam2) at an acb h (ZeroDivisionError unless certainly off the cut)."""
    if not (acb(fam.lam1).real > 0 and acb(fam.lam2).real > 0):
        raise ZeroDivisionError("log lam: not certainly off the branch cut")
    return -acb(fam.lam1).log(), -acb(fam.lam2).log()


def _trans(X, Y, a1, a2):
    return [a1 * p - a2 * q for p, q in zip(bezier_product(X, Y), bezier_product(Y, X))]


def trans_values(fam, nets):
    """{(i, j, curve): the 6 Bernstein coefficients of a1 X_i Y_j' - a2 Y_j X_i'} at one acb h."""
    a1, a2 = _logs(fam)
    return {(i, j, c): _trans(curve_points(nets[i], c, oriented=True), curve_points(nets[j], c, oriented=True),
                              a1, a2)
            for i in XB for j in YB for c in STAR_CURVES}


def layer_trans_values(fam, lnets):
    """{curve: the 6 Bernstein coefficients of a1 X Y' - a2 Y X'} of one layer quadrant at one acb h."""
    a1, a2 = _logs(fam)
    xs, ys = ({p: lnets[p][k] for p in PIECES} for k in (0, 1))
    return {c: _trans(curve_points(xs, c, oriented=True), curve_points(ys, c, oriented=True), a1, a2)
            for c in STAR_CURVES}


def coord_values(nets, coord):
    """{(basis part, curve): its 4 Bezier points} of x (coord "x") or y ("y") at one acb h."""
    return {(part, c): curve_points(nets[part], c, oriented=True)
            for part in (XB if coord == "x" else YB) for c in STAR_CURVES}


def layer_y_values(lnets):
    """{curve: 4 Bezier points of Y} of one layer quadrant at one acb h."""
    return {c: curve_points({p: lnets[p][1] for p in PIECES}, c, oriented=True) for c in STAR_CURVES}


def trans_series(fam, nets, n):
    """As :func:`trans_values` for the series family: {(i, j, curve): [coefficient list of h^m]};
    T_ij(0) = 0 exactly (a1 = a2, both parts multiples of one real curve at h = 0)."""
    A1, A2 = (series_coeffs(-lam.log(), n + 1) for lam in (fam.lam1, fam.lam2))
    curves = {b: series_curves(nets[b], n) for b in nets}
    return {(i, j, c): curve_trans_series(curves[i][c], curves[j][c], A1, A2, n)
            for i in XB for j in YB for c in STAR_CURVES}


def layer_trans_series(fam, lnets, n):
    """{curve: [coefficients (arb) of h^m]} of a1 X Y' - a2 Y X' on a layer quadrant (h^0..h^2: 0 exactly)."""
    A1, A2 = ([z.real for z in series_coeffs(-lam.log(), n + 1)] for lam in (fam.lam1, fam.lam2))
    xs, ys = (series_curves({p: lnets[p][k] for p in PIECES}, n) for k in (0, 1))
    real = {c: ([[z.real for z in pts] for pts in xs[c]], [[z.real for z in pts] for pts in ys[c]])
            for c in STAR_CURVES}
    return {c: [[z.real for z in row] for row in curve_trans_series(real[c][0], real[c][1], A1, A2, n)]
            for c in STAR_CURVES}


def layer_y_series(lnets, n):
    """{curve: [m: 4 arb]}: Taylor coefficients of Y's outer-curve points on a layer quadrant."""
    ys = series_curves({p: lnets[p][1] for p in PIECES}, n)
    return {c: [[z.real for z in pts] for pts in ys[c]] for c in STAR_CURVES}


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
