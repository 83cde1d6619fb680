"""T and W for every dart K >= K0: the outer curves of the family's nets as Taylor models in h (trusted).

T: a1 X Y' - a2 Y X' along the four outer curves (a_i = -ln lam_i), in the bulk, middle and layer regions
of :mod:`.dart_regularity`. W: the signs of X and Y on the outer curves' Bezier points that, with T, make
the outer curve cross the half-axis {Y = 0, X > 0} exactly once (docs/tagged_c1.md, item 6, "Winding").
"""

from __future__ import annotations

from flint import acb, arb, ctx, fmpq

from .dart_family import (
    CURVES,
    PIECES,
    XB,
    YB,
    Family,
    _ball,
    _bprod,
    _coeffs,
    _hvar,
    _series_curves,
    _trans_series,
    basis_nets,
    curve_points,
    layer_nets,
    series_cap,
)
from .dart_regularity import kdet_box, layer_box, middle_box, middle_coeffs


def taylor_trans(sigma, n, prec=128, **control):
    """As :func:`taylor_dets` for T_ij = a1 X_i Y_j' - a2 Y_j X_i' along the outer curves (a_i = -ln lam_i):
    {(i, j, curve): [coefficient list of h^m, m = 0..n]}; T_ij(0) = 0 exactly (a1 = a2, both parts multiples
    of one real curve at h = 0)."""
    with ctx.workprec(prec), series_cap(n):
        fam = Family(_hvar(n), sigma, **control)
        nets = basis_nets(fam)
        A1, A2 = (_coeffs(-lam.log(), n + 1) for lam in (fam.lam1, fam.lam2))
        curves = {b: _series_curves(nets[b], n) for b in nets}
        return {(i, j, c): _trans_series(curves[i][c], curves[j][c], A1, A2, n)
                for i in XB for j in YB for c in CURVES}


def disc_trans(sigma, r, grid=12, prec=128, **control):
    """As :func:`disc_bounds` for the T_ij of :func:`taylor_trans`."""
    M = {}
    with ctx.workprec(prec):
        for a in range(grid):
            for b in range(grid):
                re = _ball(-r + 2 * r * fmpq(a, grid), -r + 2 * r * fmpq(a + 1, grid))
                im = _ball(-r + 2 * r * fmpq(b, grid), -r + 2 * r * fmpq(b + 1, grid))
                fam = Family(acb(re, im), sigma, **control)
                nets = basis_nets(fam)
                if not (acb(fam.lam1).real > 0 and acb(fam.lam2).real > 0):
                    raise ZeroDivisionError("log lam: not certainly off the branch cut")
                a1, a2 = -acb(fam.lam1).log(), -acb(fam.lam2).log()
                for i in XB:
                    for j in YB:
                        for c in CURVES:
                            X, Y = curve_points(nets[i], c), curve_points(nets[j], c)
                            t = [a1 * p - a2 * q for p, q in zip(_bprod(X, Y), _bprod(Y, X))]
                            bound = max((abs(z).upper() for z in t), key=lambda x: x)
                            if not bound.is_finite():
                                raise ZeroDivisionError(f"disc box {a}, {b}: no bound")
                            key = (i, j, c)
                            M[key] = bound if key not in M or bound > M[key] else M[key]
    return M


def layer_trans_taylor(q, sigma, n, prec=128):
    """{curve: [coefficients (arb) of h^m]} of a1 X Y' - a2 Y X' on layer quadrant q (h^0..h^2: 0 exactly)."""
    with ctx.workprec(prec), series_cap(n):
        fam = Family(_hvar(n), sigma)
        nets = layer_nets(fam, q)
        A1, A2 = ([z.real for z in _coeffs(-lam.log(), n + 1)] for lam in (fam.lam1, fam.lam2))
        xs = _series_curves({p: nets[p][0] for p in PIECES}, n)
        ys = _series_curves({p: nets[p][1] for p in PIECES}, n)
        real = {c: ([[z.real for z in pts] for pts in xs[c]], [[z.real for z in pts] for pts in ys[c]]) for c in CURVES}
        return {c: [[z.real for z in row] for row in _trans_series(real[c][0], real[c][1], A1, A2, n)] for c in CURVES}


def layer_trans_disc(q, sigma, r, grid=12, prec=128):
    """{curve: M} with |a1 X Y' - a2 Y X'| <= M on complex h in [-r, r]^2 for layer quadrant q."""
    M = {}
    with ctx.workprec(prec):
        for a in range(grid):
            for b in range(grid):
                re = _ball(-r + 2 * r * fmpq(a, grid), -r + 2 * r * fmpq(a + 1, grid))
                im = _ball(-r + 2 * r * fmpq(b, grid), -r + 2 * r * fmpq(b + 1, grid))
                fam = Family(acb(re, im), sigma)
                nets = layer_nets(fam, q)
                if not (acb(fam.lam1).real > 0 and acb(fam.lam2).real > 0):
                    raise ZeroDivisionError("log lam: not certainly off the branch cut")
                a1, a2 = -acb(fam.lam1).log(), -acb(fam.lam2).log()
                for c in CURVES:
                    X = curve_points({p: nets[p][0] for p in PIECES}, c)
                    Y = curve_points({p: nets[p][1] for p in PIECES}, c)
                    t = [a1 * p - a2 * q_ for p, q_ in zip(_bprod(X, Y), _bprod(Y, X))]
                    bound = max((abs(z).upper() for z in t), key=lambda x: x)
                    if not bound.is_finite():
                        raise ZeroDivisionError(f"layer disc box {a}, {b}: no bound")
                    M[c] = bound if c not in M or bound > M[c] else M[c]
    return M


def coord_taylor(sigma, n, coord, prec=128):
    """{(basis part, curve): [order m: 4 acb]}: Taylor coefficients in h of the outer curves' Bezier points of
    the basis parts of x (coord "x": X+, X-) or y ("y": Y0, Y+, Y-)."""
    with ctx.workprec(prec), series_cap(n):
        fam = Family(_hvar(n), sigma)
        nets = basis_nets(fam)
        return {(b, c): pts for b in (XB if coord == "x" else YB) for c, pts in _series_curves(nets[b], n).items()}


def coord_disc(sigma, r, coord, grid=12, prec=128):
    """{(basis part, curve): M}, |Bezier point| <= M on complex h in [-r, r]^2."""
    M = {}
    with ctx.workprec(prec):
        for a in range(grid):
            for b in range(grid):
                re = _ball(-r + 2 * r * fmpq(a, grid), -r + 2 * r * fmpq(a + 1, grid))
                im = _ball(-r + 2 * r * fmpq(b, grid), -r + 2 * r * fmpq(b + 1, grid))
                nets = basis_nets(Family(acb(re, im), sigma))
                for part in (XB if coord == "x" else YB):
                    for c in CURVES:
                        bound = max((abs(acb(z)).upper() for z in curve_points(nets[part], c)), key=lambda x: x)
                        if not bound.is_finite():
                            raise ZeroDivisionError(f"disc box {a}, {b}: no bound")
                        key = (part, c)
                        M[key] = bound if key not in M or bound > M[key] else M[key]
    return M


def _coord_factors(coord, s, sigma):
    if coord == "x":
        E = acb(0, 2 * arb.pi() * s).exp()
        return {"X+": E, "X-": 1 / E}
    F = acb(0, sigma * (2 * s - 1)).exp()
    return {"Y0": acb(1), "Y+": F, "Y-": 1 / F}


def coord_box(T, M, s_lo, s_hi, h_lo, h_hi, sigma, r, n, coord, prec=128):
    """(lower, upper) bounds of X or Y on every outer curve's Bezier points, s in [s_lo, s_hi], h in
    [h_lo, h_hi] (a bulk quadrant)."""
    with ctx.workprec(prec):
        s, h = _ball(s_lo, s_hi), _ball(h_lo, h_hi)
        fac = _coord_factors(coord, s, sigma)
        hr = arb(fmpq(h_hi)) / r
        tail = hr ** (n + 1) / (1 - hr)
        low, high = None, None
        for c in CURVES:
            for p in range(4):
                tot = acb(0)
                for part, f in fac.items():
                    acc = acb(0)
                    for m in range(n, -1, -1):
                        acc = acc * h + T[(part, c)][m][p]
                    rad = (M[(part, c)] * tail).upper()
                    tot += f * (acc + acb(arb(0, rad), arb(0, rad)))
                v = tot.real
                low = v.lower() if low is None or v.lower() < low else low
                high = v.upper() if high is None or v.upper() > high else high
        return low, high


def ymid_box(T, M, s_lo, s_hi, w_lo, w_hi, sigma, r, n, L=24, prec=128):
    """(lower, upper) bounds of Y/s on every outer curve point, s in [s_lo, s_hi], w = h/s in [w_lo, w_hi]:
    the h^0 part sum_j b_j(s) Y_j0 = sum_(l >= 1) (...) s^l (its s^0 coefficient is y at K = infinity and s = 0:
    0 exactly) divided by s termwise, the parts h^m, m >= 1, as b_j(s) Y_jm s^(m-1) w^m, and the tails."""
    with ctx.workprec(prec):
        s, w = _ball(s_lo, s_hi), _ball(w_lo, w_hi)
        es = acb(0, sigma).exp()
        om = {"Y0": (acb(1), arb(0)), "Y+": (1 / es, 2 * sigma), "Y-": (es, -2 * sigma)}
        fac = _coord_factors("y", s, sigma)
        z = 2 * abs(sigma).upper() * arb(fmpq(s_hi))
        if not z < L + 2:
            raise ValueError("s too large for the exponential series")
        geo = z ** L / arb.fac_ui(L + 1) / (1 - z / (L + 2)) * 2 * abs(sigma).upper()
        h_hi = arb(fmpq(s_hi)) * arb(fmpq(w_hi))
        ctail = arb(fmpq(s_hi)) ** n * arb(fmpq(w_hi)) ** (n + 1) / (arb(r) ** (n + 1) * (1 - h_hi / r))
        low, high = None, None
        for c in CURVES:
            y0max = max((abs(T[(j, c)][0][p]).upper() for j in YB for p in range(4)), key=lambda x: x)
            rad = (3 * y0max * geo + sum((M[(j, c)] * ctail for j in YB), arb(0))).upper()
            for p in range(4):
                g = acb(0)
                for l in range(L, 0, -1):
                    coef = sum((cj * acb(0, wj) ** l / arb.fac_ui(l) * T[(j, c)][0][p] for j, (cj, wj) in om.items()),
                               acb(0))
                    g = g * s + coef
                for m in range(1, n + 1):
                    g += sum((fac[j] * T[(j, c)][m][p] for j in YB), acb(0)) * s ** (m - 1) * w ** m
                v = g.real + arb(0, rad)
                low = v.lower() if low is None or v.lower() < low else low
                high = v.upper() if high is None or v.upper() > high else high
        return low, high




def layer_coord(q, sigma, n, r, grid=12, prec=128):
    """(Taylor coefficients {curve: [m: 4 arb]}, disc bounds {curve: M}) of Y on layer quadrant q's outer curves."""
    with ctx.workprec(prec), series_cap(n):
        fam = Family(_hvar(n), sigma)
        nets = layer_nets(fam, q)
        ys = _series_curves({p: nets[p][1] for p in PIECES}, n)
        T = {c: [[z.real for z in pts] for pts in ys[c]] for c in CURVES}
        M = {}
        for a in range(grid):
            for b in range(grid):
                re = _ball(-r + 2 * r * fmpq(a, grid), -r + 2 * r * fmpq(a + 1, grid))
                im = _ball(-r + 2 * r * fmpq(b, grid), -r + 2 * r * fmpq(b + 1, grid))
                nets = layer_nets(Family(acb(re, im), sigma), q)
                for c in CURVES:
                    bound = max((abs(acb(z)).upper() for z in curve_points({p: nets[p][1] for p in PIECES}, c)),
                                key=lambda x: x)
                    if not bound.is_finite():
                        raise ZeroDivisionError(f"layer disc box {a}, {b}: no bound")
                    M[c] = bound if c not in M or bound > M[c] else M[c]
        return T, M




# --- the evaluators a dart:>=K0 record's leaves are replayed on ------------------------------------------

def _span(low, high):
    return arb(low).union(arb(high))


def layer_y_bounds(T, M, q, h_lo, h_hi, r, n, prec=128):
    """(lower, upper) bounds of K Y over layer quadrant q's outer-curve points (K^2 Y at ray 0's end point of
    quadrant 0), h in [h_lo, h_hi]; the coefficients below h^order are dropped (0 exactly: y = O(h), and O(h^2) at ray
    0's end point where x, hence y's first order, vanishes)."""
    with ctx.workprec(prec):
        h = _ball(h_lo, h_hi)
        hr = arb(fmpq(h_hi)) / r
        low = high = None
        for c in CURVES:
            for p in range(4):
                order = 2 if (q == 0 and c == "P1s1" and p == 0) else 1
                acc = arb(0)
                for m in range(n, order - 1, -1):
                    acc = acc * h + T[c][m][p]
                acc += arb(0, (M[c] * hr ** (n + 1) / (1 - hr) / arb(fmpq(h_hi)) ** order).upper())
                low = acc.lower() if low is None or acc.lower() < low else low
                high = acc.upper() if high is None or acc.upper() > high else high
        return low, high


class CurveModels:
    """T's and W's Taylor models for every K >= K0: disc bounds over the whole sigma bracket, one
    :class:`CurveBox` per sigma box (the parameters as :class:`.dart_regularity.RegularityModels`).

    Examples
    --------
    >>> from flint import fmpq
    >>> from ccproof.certify.verify.dart_family import TaylorHints
    >>> hints = TaylorHints(r=fmpq(1, 32), disc_grid=6, sigma_boxes=10, order=12, layer_order=14, exp_order=24)
    >>> box = CurveModels(fmpq(4484, 1000), fmpq(44935, 10000), hints, 0, 128).sigma_box(0)
    >>> box.x_bulk([(fmpq(1, 4), fmpq(26, 100)), (fmpq(0), fmpq(1, 101))]) > 0  # X > 0 there, every K >= 101
    True
    """

    def __init__(self, sig_lo, sig_hi, hints, layer, prec):
        self.hints, self.layer, self.prec = hints, layer, prec
        self.edges = [fmpq(sig_lo) + (fmpq(sig_hi) - fmpq(sig_lo)) * fmpq(i, hints.sigma_boxes)
                      for i in range(hints.sigma_boxes + 1)]
        r, g = hints.r, hints.disc_grid
        with ctx.workprec(prec):
            sig_all = _ball(sig_lo, sig_hi)
            self.MT = disc_trans(sig_all, r, grid=g, prec=prec)
            self.MX, self.MY = coord_disc(sig_all, r, "x", grid=g, prec=prec), coord_disc(sig_all, r, "y", grid=g,
                                                                                        prec=prec)
            self.MTL = {q: layer_trans_disc(q, sig_all, r, grid=g, prec=prec) for q in range(layer)}
            self.MYL = {q: layer_coord(q, sig_all, hints.layer_order, r, grid=g, prec=prec)[1] for q in range(layer)}
        self._boxes = {}

    def sigma_box(self, i):
        """The models on sigma box i (cached)."""
        if not 0 <= i < self.hints.sigma_boxes:
            raise IndexError(f"sigma box {i} of {self.hints.sigma_boxes}")
        if i not in self._boxes:
            self._boxes[i] = CurveBox(self, i)
        return self._boxes[i]


class CurveBox:
    """The Taylor coefficients of T and of X, Y on one sigma box; each evaluator returns one arb containing
    every value of the region's scaled quantity (every curve's Bernstein coefficient, or every outer-curve
    Bezier point) on the box."""

    def __init__(self, models, i):
        self.m, hn, prec = models, models.hints, models.prec
        with ctx.workprec(prec):
            self.sigma = _ball(models.edges[i], models.edges[i + 1])
            self.T = taylor_trans(self.sigma, hn.order, prec=prec)
            self.E = middle_coeffs(self.T, self.sigma, L=hn.exp_order)
            self.TX = coord_taylor(self.sigma, hn.order, "x", prec=prec)
            self.TY = coord_taylor(self.sigma, hn.order, "y", prec=prec)
            self.TL = {q: layer_trans_taylor(q, self.sigma, hn.layer_order, prec=prec) for q in range(models.layer)}
            self.YL = {q: layer_coord(q, self.sigma, hn.layer_order, hn.r, grid=0, prec=prec)[0]
                       for q in range(models.layer)}

    def _h_ok(self, h_hi):
        if not (h_hi >= 0 and h_hi < self.m.hints.r):
            raise ZeroDivisionError(f"h up to {h_hi} is not inside the Cauchy disc of radius {self.m.hints.r}")

    def transversal_bulk(self, box):
        """K (a1 X Y' - a2 Y X') on the four outer curves, (s, h) in the box."""
        (s_lo, s_hi), (h_lo, h_hi) = box
        self._h_ok(h_hi)
        hn = self.m.hints
        return _span(*kdet_box(self.T, self.m.MT, s_lo, s_hi, h_lo, h_hi, self.sigma, hn.r, hn.order,
                               prec=self.m.prec))

    def transversal_middle(self, box):
        """K^3 (a1 X Y' - a2 Y X')/q^2 as a function of (s, w = 1/q) in the box."""
        (s_lo, s_hi), (w_lo, w_hi) = box
        self._h_ok(s_hi * w_hi)
        hn = self.m.hints
        return _span(*middle_box(self.T, self.E, self.m.MT, s_lo, s_hi, w_lo, w_hi, self.sigma, hn.r, hn.order,
                                 L=hn.exp_order, prec=self.m.prec))

    def transversal_layer(self, q, box):
        """K^3 (a1 X Y' - a2 Y X') on layer quadrant q's outer curves, h in the box."""
        ((h_lo, h_hi),) = box
        self._h_ok(h_hi)
        hn = self.m.hints
        return _span(*layer_box(self.TL[q], self.m.MTL[q], h_lo, h_hi, hn.r, hn.layer_order, prec=self.m.prec))

    def _coord(self, box, coord):
        (s_lo, s_hi), (h_lo, h_hi) = box
        self._h_ok(h_hi)
        hn = self.m.hints
        T, M = (self.TX, self.m.MX) if coord == "x" else (self.TY, self.m.MY)
        return _span(*coord_box(T, M, s_lo, s_hi, h_lo, h_hi, self.sigma, hn.r, hn.order, coord,
                                prec=self.m.prec))

    def x_bulk(self, box):
        """X on every outer-curve Bezier point, (s, h) in the box."""
        return self._coord(box, "x")

    def y_bulk(self, box):
        """Y on every outer-curve Bezier point, (s, h) in the box."""
        return self._coord(box, "y")

    def y_middle(self, box):
        """Y/s on every outer-curve Bezier point, (s, w) in the box."""
        (s_lo, s_hi), (w_lo, w_hi) = box
        self._h_ok(s_hi * w_hi)
        hn = self.m.hints
        return _span(*ymid_box(self.TY, self.m.MY, s_lo, s_hi, w_lo, w_hi, self.sigma, hn.r, hn.order,
                               L=hn.exp_order, prec=self.m.prec))

    def y_layer(self, q, box):
        """K Y on layer quadrant q's outer-curve points (K^2 Y at ray 0's end point of quadrant 0), h in the box."""
        ((h_lo, h_hi),) = box
        self._h_ok(h_hi)
        hn = self.m.hints
        return _span(*layer_y_bounds(self.YL[q], self.m.MYL[q], q, h_lo, h_hi, hn.r, hn.layer_order,
                                     prec=self.m.prec))
