"""R for every dart K >= K0: det J_Phi of the family's nets as Taylor models in h (trusted).

Three regions of quadrants q (docs/tagged_c1.md, item 6, "Dividing by h exactly"): the bulk s = q/K in
[s0, 1/2] (K det J_Phi), the middle (K^3 det J_Phi/q^2 as a function of s and w = 1/q) and the layer
quadrants 0..T-1 (K^3 det J_Phi). The Taylor coefficients come from acb_series arithmetic, the remainders
from Cauchy's estimate on the complex h-square [-r, r]^2 (:mod:`ccproof.rigorous.analytic`: one disc bound,
one model); the coefficients that vanish exactly (:mod:`.dart_zeros`) are dropped.
"""

from __future__ import annotations

from flint import acb, acb_mat, arb, ctx, fmpq

from ccproof.rigorous.analytic import AnalyticModel, ball, cauchy_factor, hull

from .dart_family import PIECES, XB, YB, det_series, packed_partials, series_coeffs

IJ = [(i, j) for i in XB for j in YB]  # the columns of the bulk models


def _flat(nets):
    return {(name, piece): net for name, pn in nets.items() for piece, net in pn.items()}


def coefficient_nets(net, n, real=False):
    """[the 4 x 4 net of the h^m Taylor coefficients (acb), m = 0..n] of a net of series or of values
    (``real``: as :func:`.dart_family.series_coeffs`)."""
    cs = [[series_coeffs(z, n + 1, real) for z in row] for row in net]
    return [[[c[m] for c in row] for row in cs] for m in range(n + 1)]


def dets_series(nets, n):
    """{(i, j, piece): [the 36 Bernstein coefficients of D(X_i, Y_j)'s h^m, m = 0..n]} of the basis nets (of
    acb_series; of acb values with n = 0: the values at one h)."""
    series = {key: packed_partials(coefficient_nets(net, n)) for key, net in _flat(nets).items()}
    return {(i, j, p): det_series(series[(i, p)], series[(j, p)], n) for i, j in IJ for p in PIECES}


def bulk_models(T, M, r):
    """{piece: AnalyticModel} of the D_ij: row c the Bernstein coefficient, column ij (in the order of IJ)."""
    return {p: AnalyticModel.from_columns([T[ij + (p,)] for ij in IJ], [M[ij + (p,)] for ij in IJ], r)
            for p in sorted({key[2] for key in T})}


def mode_factors(s, sigma):
    """([a_i(s)] in the order of XB, [b_j(s)] in the order of YB): E = e^(2 pi i s), 1/E; 1, F, 1/F,
    F = e^(i sigma (2 s - 1))."""
    E, F = acb(0, 2 * arb.pi() * s).exp(), acb(0, sigma * (2 * s - 1)).exp()
    return [E, 1 / E], [acb(1), F, 1 / F]


def real_hull(models, weights, h_lo, h_hi, low, prec):
    """An arb holding Re sum_k weights[k] f_k(h)/h^low, every row of every model, h in [h_lo, h_hi]."""
    with ctx.workprec(prec):
        return hull(v for model in models.values() for v in model.real_part(weights, h_lo, h_hi, low=low))


def kdet_box(models, s_lo, s_hi, h_lo, h_hi, sigma, prec=128):
    """An arb holding K det J_Phi's Bernstein coefficients (every piece) for s in [s_lo, s_hi] and h in
    [h_lo, h_hi] (0 <= h_hi < r): Re sum_ij a_i(s) b_j(s) D_ij(h)/h from the models of :func:`bulk_models`
    (the h^0 terms 0 exactly)."""
    with ctx.workprec(prec):
        a, b = mode_factors(ball(s_lo, s_hi), sigma)
        return real_hull(models, [x * y for x in a for y in b], h_lo, h_hi, 1, prec)


def y_omegas(sigma):
    """b_j(s) = c_j e^(i omega_j s): [(c_j, omega_j)] in the order of YB (Y0, Y+, Y-)."""
    es = acb(0, sigma).exp()
    return [(acb(1), arb(0)), (1 / es, 2 * sigma), (es, -2 * sigma)]


def omegas(sigma):
    """a_i(s) b_j(s) = c_ij e^(i omega_ij s): [(c_ij, omega_ij)] (acb, arb) in the order of IJ."""
    tp = 2 * arb.pi()
    return [(c, a + w) for a in (tp, -tp) for c, w in y_omegas(sigma)]


def middle_coeffs(model, om, m0, q, L=24):
    """{(m, l): e_ml = D_m (c_k (i omega_k)^l/l!)_k} (acb_mat, a row per value) for m0 <= m < m0 + q and
    l <= L: the coefficient of s^l h^m in F = sum_k c_k e^(i omega_k s) sum_m D_km h^m (``om``: the (c_k,
    omega_k) of the model's columns, |c_k| = 1)."""
    return {(m, l): model.coeffs[m] * acb_mat([[c * acb(0, w) ** l / arb.fac_ui(l)] for c, w in om])
            for m in range(m0, m0 + q) for l in range(L + 1)}


def middle_box(models, E, om, s_lo, s_hi, w_lo, w_hi, m0, q, L=24, prec=128):
    """An arb holding Re F/(h^m0 s^q) (F of :func:`middle_coeffs`, every model's rows) on s in [s_lo, s_hi],
    w = h/s in [w_lo, w_hi], s_lo >= 0, where F's coefficients of h^m s^l with l + m - m0 < q are 0 exactly:
    the orders m < m0 + q expanded in s, sum_l e_ml s^(l + m - m0 - q) w^(m - m0), the tails of those
    exponential series (|omega s|^l/l! summed past L: at most z^(L+1)/(L+1)!/(1 - z/(L + 2)), z = |omega| s)
    and the rest direct, (c e^(i omega s) . D_m) s^(m - m0 - q) w^(m - m0), with the Cauchy remainder
    sum_k M_k s^(n+1-m0-q) w^(n+1-m0)/(r^(n+1) (1 - h/r)). K det J_Phi/s^2 is m0 = 1, q = 2; Y/s is m0 = 0,
    q = 1."""
    with ctx.workprec(prec):
        s, w = acb(ball(s_lo, s_hi)), acb(ball(w_lo, w_hi))
        wmax = max((abs(x[1]).upper() for x in om), key=lambda x: x)
        z, sh, wh = wmax * arb(fmpq(s_hi)), arb(fmpq(s_hi)), arb(fmpq(w_hi))
        if not z < L + 2:
            raise ValueError("s too large for the exponential series")
        geo = 1 / (arb.fac_ui(L + 1) * (1 - z / (L + 2)))
        ab = acb_mat([[c * (w_ * s * acb(0, 1)).exp()] for c, w_ in om])
        vals = []
        for key, model in models.items():
            n, D = model.order, model.coeffs
            rad = sum(model.M, arb(0)) * sh ** (n + 1 - m0 - q) * wh ** (n + 1 - m0) * cauchy_factor(
                model.r, n, fmpq(s_hi) * fmpq(w_hi))
            g = None
            for j in range(q):
                e = E[key]
                dmax = max((abs(D[m0 + j][c, k]).upper() for c in range(D[m0 + j].nrows()) for k in range(len(om))),
                           key=lambda x: x)
                rad += len(om) * dmax * wh ** j * wmax ** (q - j) * z ** (L + 1 + j - q) * geo
                acc = e[(m0 + j, L)]
                for l in range(L - 1, q - j - 1, -1):
                    acc = acc * s + e[(m0 + j, l)]
                g = acc * w ** j if g is None else g + acc * w ** j
            for m in range(m0 + q, n + 1):
                g = g + (D[m] * ab) * (s ** (m - m0 - q) * w ** (m - m0))
            vals += [g[c, 0].real + arb(0, rad.upper()) for c in range(g.nrows())]
        return hull(vals)


def layer_dets_series(lnets, n, real=False):
    """{piece: [Bernstein coefficients of det J_Phi's h^m, m = 0..n]} of one layer quadrant's nets (series, or
    values with n = 0; ``real``: of the real parts, the nets being real for real h)."""
    return {p: det_series(coefficient_nets(X, n, real), coefficient_nets(Y, n, real), n) for p, (X, Y) in lnets.items()}


def column_models(T, M, r):
    """{key: AnalyticModel} with one column: the coefficient lists T[key][m] (rows) and the bound M[key]."""
    return {key: AnalyticModel.from_columns([coeffs], [M[key]], r) for key, coeffs in T.items()}


def layer_box(models, h_lo, h_hi, order=3, prec=128):
    """An arb holding K^order det J_Phi on h in [h_lo, h_hi] from the models of :func:`column_models` (the
    coefficients of h^0 .. h^(order-1) being 0 exactly)."""
    return real_hull(models, [1], h_lo, h_hi, order, prec)
