"""R for every dart K >= K0: det J_Phi of the family's nets as Taylor models in h (trusted).

Three regions of quadrants q (docs/tagged_c1.md, item 6, "Dividing by h exactly"): the bulk s = q/K in
[s0, 1/2] (K det J_Phi), the middle (K^3 det J_Phi/q^2 as a function of s and w = 1/q) and the layer
quadrants 0..T-1 (K^3 det J_Phi). The Taylor coefficients come from acb_series arithmetic, the remainders
from Cauchy's estimate on the complex h-square [-r, r]^2 (:func:`disc_bounds`, :func:`layer_disc`); the
coefficients that vanish exactly (:mod:`.dart_zeros`) are dropped.
"""

from __future__ import annotations

from flint import acb, acb_mat, arb, ctx, fmpq

from .dart_family import (
    PIECES,
    XB,
    YB,
    Family,
    _ball,
    _coeffs,
    _hvar,
    _parts,
    basis_nets,
    det_series,
    layer_nets,
    series_cap,
)


def taylor_dets(sigma, n, prec=128, **control):
    """The Taylor coefficients in h of D_ij = D(X_i, Y_j) for the basis parts X_i (X+, X-) and Y_j (Y0, Y+, Y-):
    {(i, j, piece): [coefficient list (acb) of h^m, m = 0..n]}. D is bilinear, so the coefficient of h^m is
    sum_(k + l = m) D(X_i,k, Y_j,l) of the nets' own Taylor coefficients (acb_series, rigorous)."""
    with ctx.workprec(prec), series_cap(n):
        fam = Family(_hvar(n), sigma, **control)
        nets = basis_nets(fam)
        series = {(name, piece): [[[_coeffs(z, n + 1)[m] for z in row] for row in net] for m in range(n + 1)]
                  for name, pn in nets.items() for piece, net in pn.items()}
        return {(i, j, piece): det_series(series[(i, piece)], series[(j, piece)], n)
                for i in XB for j in YB for piece in PIECES}


def disc_bounds(sigma, r, grid=4, prec=128, **control):
    """M with |D_ij(h)| <= M[(i, j, piece)] (every Bernstein coefficient) for every complex h in the square
    [-r, r]^2 (grid x grid acb boxes; every system on each box proved regular by arb, so D_ij is analytic
    on the disc |h| <= r). Raises ZeroDivisionError where a box decides nothing."""
    M = {}
    with ctx.workprec(prec):
        for a in range(grid):
            for b in range(grid):
                re = _ball(-r + 2 * r * fmpq(a, grid), -r + 2 * r * fmpq(a + 1, grid))
                im = _ball(-r + 2 * r * fmpq(b, grid), -r + 2 * r * fmpq(b + 1, grid))
                fam = Family(acb(re, im), sigma, **control)
                nets = basis_nets(fam)
                forms = {(name, piece): [[[acb(z) for z in row] for row in net]]
                         for name, pn in nets.items() for piece, net in pn.items()}
                for i in XB:
                    for j in YB:
                        for piece in PIECES:
                            d = det_series(forms[(i, piece)], forms[(j, piece)], 0)[0]
                            bound = max((abs(z).upper() for z in d), key=lambda x: x)
                            if not bound.is_finite():
                                raise ZeroDivisionError(f"disc box {a}, {b}: no bound")
                            key = (i, j, piece)
                            M[key] = bound if key not in M or bound > M[key] else M[key]
    return M


def kdet_matrices(T, n):
    """{piece: [D_1, ..., D_n]}, D_m an acb_mat with d_ijm at row c (the Bernstein coefficient), column ij (in the
    order of XB x YB): Horner's rule in h runs on all of them at once (:func:`kdet_box`)."""
    ijs = [(i, j) for i in XB for j in YB]
    return {piece: [acb_mat([[T[(i, j, piece)][m][c] for (i, j) in ijs]
                             for c in range(len(T[(XB[0], YB[0], piece)][1]))]) for m in range(1, n + 1)]
            for piece in _parts(T)}


def kdet_box(T, M, s_lo, s_hi, h_lo, h_hi, sigma, r, n, prec=128, mats=None):
    """(lower, upper) bounds of K det J_Phi over the three pieces' Bernstein coefficients, for s in [s_lo, s_hi] and
    h in [h_lo, h_hi] (0 < h_hi < r): sum_ij a_i(s) b_j(s) (sum_(m=1..n) d_ijm h^(m-1) + rho_ij) with
    |rho_ij| <= M_ij h^n/(r^(n+1) (1 - h/r)) (Cauchy on |h| = r), the m = 0 terms being 0 exactly; Horner's
    rule runs on the matrices of :func:`kdet_matrices` (``mats`` when given), and the real part of a_i b_j rho_ij
    is at most (|Re a_i b_j| + |Im a_i b_j|) |rho_ij|."""
    with ctx.workprec(prec):
        mats = kdet_matrices(T, n) if mats is None else mats
        s, h = _ball(s_lo, s_hi), _ball(h_lo, h_hi)
        E, F = acb(0, 2 * arb.pi() * s).exp(), acb(0, sigma * (2 * s - 1)).exp()
        a, b = {"X+": E, "X-": 1 / E}, {"Y0": acb(1), "Y+": F, "Y-": 1 / F}
        hr = arb(fmpq(h_hi)) / r
        tail = arb(fmpq(h_hi)) ** n / (arb(r) ** (n + 1) * (1 - hr))
        ws = [(i, j, a[i] * b[j]) for i in XB for j in YB]
        low, high = None, None
        for piece, Ds in mats.items():
            rho = sum(((abs(w.real) + abs(w.imag)) * (M[(i, j, piece)] * tail) for i, j, w in ws), arb(0))
            acc = Ds[-1]
            for D in reversed(Ds[:-1]):
                acc = acc * acb(h) + D
            vals = [sum((acc[c, k] * w for k, (_, _, w) in enumerate(ws)), acb(0)).real + arb(0, rho.upper())
                    for c in range(acc.nrows())]
            lo = min((z.lower() for z in vals), key=lambda x: x)
            hi = max((z.upper() for z in vals), key=lambda x: x)
            low = lo if low is None or lo < low else low
            high = hi if high is None or hi > high else high
        return low, high


def _omegas(sigma):
    """a_i(s) b_j(s) = c_ij e^(i omega_ij s): {(i, j): (c_ij, omega_ij)} (acb, arb)."""
    tp, es = 2 * arb.pi(), acb(0, sigma).exp()
    a = {"X+": tp, "X-": -tp}
    b = {"Y0": (acb(1), arb(0)), "Y+": (1 / es, 2 * sigma), "Y-": (es, -2 * sigma)}
    return {(i, j): (b[j][0], a[i] + b[j][1]) for i in XB for j in YB}


def middle_coeffs(T, sigma, L=24):
    """e[(m, l)][piece] = sum_ij d_ijm c_ij (i omega_ij)^l/l! (Bernstein coefficient lists, acb): the
    coefficient of s^l h^(m-1) in K det J_Phi = sum_ij a_i(s) b_j(s) sum_m d_ijm h^(m-1), for m = 1, 2 and
    l <= L (the terms m >= 3 are evaluated directly)."""
    om = _omegas(sigma)
    out = {}
    for m in (1, 2):
        for l in range(L + 1):
            for piece in _parts(T):
                acc = None
                for (i, j), (c, w) in om.items():
                    f = c * (acb(0, w) ** l) / arb.fac_ui(l)
                    v = [f * z for z in T[(i, j, piece)][m]]
                    acc = v if acc is None else [x + y for x, y in zip(acc, v)]
                out[(m, l, piece)] = acc
    return out


def middle_box(T, E, M, s_lo, s_hi, w_lo, w_hi, sigma, r, n, L=24, prec=128):
    """(lower, upper) bounds of G = K det J_Phi/s^2 (= K^3 det J_Phi/q^2 at s = q h) on s in [s_lo, s_hi],
    w = h/s in [w_lo, w_hi] (s_lo >= 0): the m = 1 part sum_(l >= 2) e_1l s^(l-2), the m = 2 part
    w sum_(l >= 1) e_2l s^(l-1) (the coefficients e_10, e_11, e_20 being 0 exactly), the m >= 3 parts
    a_i(s) b_j(s) d_ijm s^(m-3) w^(m-1), the tails of the exponential series (|omega s|^(L+1)/(L+1)!, with
    the factor 1/(1 - |omega s|/(L + 2))) and the Cauchy remainder M_ij s^(n-2) w^n/(r^(n+1) (1 - h/r))."""
    with ctx.workprec(prec):
        s, w = _ball(s_lo, s_hi), _ball(w_lo, w_hi)
        om = _omegas(sigma)
        wmax = max((abs(x[1]).upper() for x in om.values()), key=lambda x: x)
        z = wmax * arb(fmpq(s_hi))
        if not z < L + 2:
            raise ValueError("s too large for the exponential series")
        # the tails of the exponential series, divided by s^2 (m = 1) and s (m = 2): |c_ij| = 1 and
        # sum_(l > L) |omega s|^l/l! <= |omega s|^(L+1)/(L+1)!/(1 - |omega s|/(L + 2))
        geo = z ** (L - 1) / arb.fac_ui(L + 1) / (1 - z / (L + 2))
        h_hi = arb(fmpq(s_hi)) * arb(fmpq(w_hi))
        ctail = arb(fmpq(s_hi)) ** (n - 2) * arb(fmpq(w_hi)) ** n / (arb(r) ** (n + 1) * (1 - h_hi / r))
        ab = {k: c * acb(0, w_ * s).exp() for k, (c, w_) in om.items()}
        low, high = None, None
        for piece in _parts(T):
            ncoef = len(T[("X+", "Y0", piece)][1])  # the pieces' (or curves') Bernstein coefficients
            dmax = {m: max((abs(c).upper() for key in T if key[2] == piece for c in T[key][m]), key=lambda x: x)
                    for m in (1, 2)}
            rad1 = 6 * dmax[1] * wmax ** 2 * geo
            rad2 = 6 * dmax[2] * wmax * geo * z * arb(fmpq(w_hi))
            rem = sum((M[(i, j, piece)] * ctail for i in XB for j in YB), arb(0))
            rad = (rad1 + rad2 + rem).upper()
            for c in range(ncoef):
                g1 = acb(0)
                for l in range(L, 1, -1):
                    g1 = g1 * s + E[(1, l, piece)][c]
                g2 = acb(0)
                for l in range(L, 0, -1):
                    g2 = g2 * s + E[(2, l, piece)][c]
                g = g1 + w * g2
                for m in range(3, n + 1):
                    g += sum((ab[k] * T[k + (piece,)][m][c] for k in ab), acb(0)) * s ** (m - 3) * w ** (m - 1)
                v = g.real + arb(0, rad)
                low = v.lower() if low is None or v.lower() < low else low
                high = v.upper() if high is None or v.upper() > high else high
        return low, high


def layer_taylor(q, sigma, n, prec=128):
    """{piece: [Bernstein coefficients (arb) of det J_Phi's h^m, m = 0..n]} of layer quadrant q (real parts:
    the values are real for real h)."""
    with ctx.workprec(prec), series_cap(n):
        fam = Family(_hvar(n), sigma)
        out = {}
        for piece, (X, Y) in layer_nets(fam, q).items():
            fx, fy = ([[[acb(_coeffs(Z[i][j], n + 1)[m].real) for j in range(4)] for i in range(4)]
                       for m in range(n + 1)] for Z in (X, Y))
            out[piece] = [[z.real for z in c] for c in det_series(fx, fy, n)]
        return out


def layer_disc(q, sigma, r, grid=12, prec=128):
    """{piece: M} with |det J_Phi(h)| <= M (every Bernstein coefficient) for complex h in [-r, r]^2."""
    M = {}
    with ctx.workprec(prec):
        for a in range(grid):
            for b in range(grid):
                re = _ball(-r + 2 * r * fmpq(a, grid), -r + 2 * r * fmpq(a + 1, grid))
                im = _ball(-r + 2 * r * fmpq(b, grid), -r + 2 * r * fmpq(b + 1, grid))
                fam = Family(acb(re, im), sigma)
                for piece, (X, Y) in layer_nets(fam, q).items():
                    d = det_series([[[acb(z) for z in row] for row in X]], [[[acb(z) for z in row] for row in Y]], 0)[0]
                    bound = max((abs(z).upper() for z in d), key=lambda x: x)
                    if not bound.is_finite():
                        raise ZeroDivisionError(f"layer disc box {a}, {b}: no bound")
                    M[piece] = bound if piece not in M or bound > M[piece] else M[piece]
    return M


def layer_box(T, M, h_lo, h_hi, r, n, order=3, prec=128):
    """(lower, upper) bounds of K^order det J_Phi on h in [h_lo, h_hi] from the Taylor model (the
    coefficients of h^0 .. h^(order-1) being 0 exactly)."""
    with ctx.workprec(prec):
        h = _ball(h_lo, h_hi)
        tail = arb(fmpq(h_hi)) ** (n + 1 - order) / (arb(r) ** (n + 1) * (1 - arb(fmpq(h_hi)) / r))
        low, high = None, None
        for piece, coeffs in T.items():
            rad = (M[piece] * tail).upper()
            for c in range(len(coeffs[0])):
                acc = arb(0)
                for m in range(n, order - 1, -1):
                    acc = acc * h + coeffs[m][c]
                acc += arb(0, rad)
                low = acc.lower() if low is None or acc.lower() < low else low
                high = acc.upper() if high is None or acc.upper() > high else high
        return low, high


# --- the evaluators a dart:>=K0 record's leaves are replayed on ------------------------------------------

def _span(low, high):
    """The arb ball [low, high] (both arb points or balls: their hull)."""
    return arb(low).union(arb(high))


def _sigma_edges(sig_lo, sig_hi, boxes):
    return [fmpq(sig_lo) + (fmpq(sig_hi) - fmpq(sig_lo)) * fmpq(i, boxes) for i in range(boxes + 1)]


class RegularityModels:
    """R's Taylor models for every K >= K0: the disc bounds over the whole sigma bracket, and one
    :class:`RegularityBox` per sigma box.

    Parameters
    ----------
    sig_lo, sig_hi : fmpq
        The bracket of sigma(K) (shown by the spectrum and the eigenvector lemma).
    hints : TaylorHints
    layer : int
        T: the layer quadrants are 0..T-1.
    prec : int

    Examples
    --------
    >>> from flint import fmpq
    >>> from ccproof.certify.verify.dart_family import TaylorHints
    >>> hints = TaylorHints(r=fmpq(1, 32), disc_grid=6, sigma_boxes=10, order=12, layer_order=14, exp_order=24)
    >>> box = RegularityModels(fmpq(4484, 1000), fmpq(44935, 10000), hints, 0, 128).sigma_box(0)
    >>> box.bulk([(fmpq(1, 4), fmpq(26, 100)), (fmpq(0), fmpq(1, 101))]) > 0  # K det J_Phi, every K >= 101
    True
    """

    def __init__(self, sig_lo, sig_hi, hints, layer, prec):
        self.hints, self.layer, self.prec = hints, layer, prec
        self.edges = _sigma_edges(sig_lo, sig_hi, hints.sigma_boxes)
        with ctx.workprec(prec):
            sig_all = _ball(sig_lo, sig_hi)
            self.M = disc_bounds(sig_all, hints.r, grid=hints.disc_grid, prec=prec)
            self.ML = {q: layer_disc(q, sig_all, hints.r, grid=hints.disc_grid, prec=prec) for q in range(layer)}
        self._boxes = {}

    def sigma_box(self, i):
        """The models on sigma box i of ``hints.sigma_boxes`` equal boxes of the bracket (cached)."""
        if not 0 <= i < self.hints.sigma_boxes:
            raise IndexError(f"sigma box {i} of {self.hints.sigma_boxes}")
        if i not in self._boxes:
            self._boxes[i] = RegularityBox(self, i)
        return self._boxes[i]


class RegularityBox:
    """The Taylor coefficients on one sigma box; each evaluator returns one arb containing every Bernstein
    coefficient of the three pieces of the region's scaled det J_Phi on the box (a list of (lo, hi) fmpq)."""

    def __init__(self, models, i):
        self.m, hints, prec = models, models.hints, models.prec
        with ctx.workprec(prec):
            self.sigma = _ball(models.edges[i], models.edges[i + 1])
            self.T = taylor_dets(self.sigma, hints.order, prec=prec)
            self.mats = kdet_matrices(self.T, hints.order)
            self.E = middle_coeffs(self.T, self.sigma, L=hints.exp_order)
            self.TL = {q: layer_taylor(q, self.sigma, hints.layer_order, prec=prec) for q in range(models.layer)}

    def _h_ok(self, h_hi):
        if not (h_hi >= 0 and h_hi < self.m.hints.r):
            raise ZeroDivisionError(f"h up to {h_hi} is not inside the Cauchy disc of radius {self.m.hints.r}")

    def bulk(self, box):
        """K det J_Phi on (s, h) in the box (the bulk, s in [s0, 1/2])."""
        (s_lo, s_hi), (h_lo, h_hi) = box
        self._h_ok(h_hi)
        hn = self.m.hints
        return _span(*kdet_box(self.T, self.m.M, s_lo, s_hi, h_lo, h_hi, self.sigma, hn.r, hn.order,
                               prec=self.m.prec, mats=self.mats))

    def middle(self, box):
        """K^3 det J_Phi/q^2 as a function of (s, w = 1/q) in the box (the middle)."""
        (s_lo, s_hi), (w_lo, w_hi) = box
        self._h_ok(s_hi * w_hi)
        hn = self.m.hints
        return _span(*middle_box(self.T, self.E, self.m.M, s_lo, s_hi, w_lo, w_hi, self.sigma, hn.r, hn.order,
                                 L=hn.exp_order, prec=self.m.prec))

    def layer(self, q, box):
        """K^3 det J_Phi of layer quadrant q on h in the box."""
        ((h_lo, h_hi),) = box
        self._h_ok(h_hi)
        hn = self.m.hints
        return _span(*layer_box(self.TL[q], self.m.ML[q], h_lo, h_hi, hn.r, hn.layer_order, prec=self.m.prec))
