"""Rigorous mode: an arb certificate that a box contains the preimage Phi^-1(t) (Krawczyk test).

Given t = (x, y) (floats, taken as exact rationals) and an approximate preimage, we build a small
box X around the approximation refined in arb, and evaluate the Krawczyk operator

    K(X) = m - Y (Phi(m) - t) + (I - Y J(X)) (X - m),

where m is the (exact) centre of X, Y any 2 x 2 matrix (the inverse of the midpoint of J(X)),
Phi(m) is enclosed with arb by the polynomial piece containing m, and J(X) is the *hull of the
enclosures of the Jacobians of every piece that meets X* (layers n, pieces P1, P2, P3 whose dyadic
domain 2^-n D_j intersects X, each on its intersection with X). Phi is C^1 on X (the pieces of a
bicubic spline join C^2, across layers too, away from the extraordinary vertex, which X avoids),
so the mean value theorem gives Phi(z) - Phi(m) in J(X) (z - m) for z in X. If K(X) lies in the
interior of X, then X contains exactly one zero of Phi - t (Krawczyk 1969; Moore 1977), i.e. the
preimage, and K(X) is a tighter enclosure of it: that is the box returned.

Special cases: t = 0 (exact answer 0), points on an axis (y = 0 forces s = 0 because Phi maps
each axis onto itself and is injective; a one-dimensional Krawczyk test on r), and the symmetry
Phi(v, u) = swap(Phi(u, v)) (exact) to work with x >= y. The arb nets come from
:func:`ccproof.algebra.specialize.characteristic_map_patches` (balls containing the exact nets).
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
from functools import lru_cache

from ccproof.errors import CCProofError, check_valence


@dataclass
class CertifiedPreimage:
    """A box ``(r, s)`` of arb balls that contains Phi^-1(x, y) (when ``certified``).

    The Krawczyk (interval Newton) certificate of one preimage (docs/inverse.md, bmz04 section 4.3).

    Parameters
    ----------
    r, s : flint.arb
        The box.
    certified : bool
        Whether the Krawczyk test proved that the box contains the preimage.
    pieces : tuple
        The (layer, patch) pieces that meet the box.
    width : float
        The largest radius.

    Examples
    --------
    For k = 4 Phi is the identity:

    >>> c = certify_preimage(4, 0.25, 0.75, 0.25, 0.75)
    >>> c.certified, c.r.contains(0.25), c.s.contains(0.75), c.width < 1e-30
    (True, True, True, True)
    """

    r: object
    s: object
    certified: bool
    pieces: tuple
    width: float

    def contains(self, r, s):
        """Whether the float point (r, s) lies in the box."""
        from flint import arb

        return bool(self.r.contains(arb(float(r)))) and bool(self.s.contains(arb(float(s))))

    def distance(self, r, s):
        """An upper bound (float) on the distance (max norm) from (r, s) to the true preimage."""
        from flint import arb

        d = max(abs(self.r - arb(float(r))).upper(), abs(self.s - arb(float(s))).upper())
        return float(d.mid()) * (1 + 2**-50)


@lru_cache(maxsize=64)
def _power_nets(k, prec):
    """Power-basis coefficients (arb) of P1, P2, P3: ``[patch][comp][i][j]`` of s^i t^j."""
    from flint import arb, ctx

    from ccproof.inverse.data import bezier_to_power
    from ccproof.tables.numeric import characteristic_arb

    data = characteristic_arb(k, prec + 20)
    nets = data.bezier
    out = []
    with ctx.workprec(prec + 20):
        for name in ("P1", "P2", "P3"):
            net = nets[name]
            comps = []
            for c in range(2):
                rows = [bezier_to_power([net[i][j][c] for j in range(4)]) for i in range(4)]
                cols = [bezier_to_power([rows[i][j] for i in range(4)]) for j in range(4)]
                comps.append([[cols[j][i] for j in range(4)] for i in range(4)])
            out.append(comps)
        lam = +data.lam
    return out, lam, arb


def _poly(C, s, t):
    """sum C[i][j] s^i t^j and its partial derivatives, arb in, arb out (interval Horner)."""
    val = ds = dt = None
    for i in range(3, -1, -1):
        q = ((C[i][3] * t + C[i][2]) * t + C[i][1]) * t + C[i][0]
        qt = (C[i][3] * 3 * t + C[i][2] * 2) * t + C[i][1]
        val = q if val is None else val * s + q
        dt = qt if dt is None else dt * s + qt
        if i >= 1:
            qs = q * i
            ds = qs if ds is None else ds * s + qs
    return val, ds, dt


_DOMAINS = {  # (u range, v range) of the layer-0 domains, and the local affine maps
    0: ((Fraction(1, 2), Fraction(1)), (Fraction(0), Fraction(1, 2))),
    1: ((Fraction(1, 2), Fraction(1)), (Fraction(1, 2), Fraction(1))),
    2: ((Fraction(0), Fraction(1, 2)), (Fraction(1, 2), Fraction(1))),
}


def _pieces(rlo, rhi, slo, shi):
    """(n, j, (r0, r1), (s0, s1)) for every piece meeting the box (exact Fractions)."""
    top = max(rhi, shi)
    bot = max(rlo, slo)
    if bot <= 0:
        raise CCProofError("the box contains the extraordinary vertex")
    n_lo = 0
    while Fraction(2) ** (-n_lo) < top:
        n_lo -= 1
    while Fraction(2) ** (-n_lo - 1) >= top:
        n_lo += 1
    out = []
    n = n_lo
    while Fraction(2) ** (-n) >= bot:
        sc = Fraction(2) ** (-n)
        for j, ((u0, u1), (v0, v1)) in _DOMAINS.items():
            a0, a1 = max(rlo, u0 * sc), min(rhi, u1 * sc)
            b0, b1 = max(slo, v0 * sc), min(shi, v1 * sc)
            if a0 <= a1 and b0 <= b1:
                out.append((n, j, (a0, a1), (b0, b1)))
        n += 1
    return out


def _fq(x):
    from flint import fmpq

    x = Fraction(x)
    return fmpq(x.numerator, x.denominator)


def _interval(lo, hi):
    from flint import arb

    return arb(_fq(lo)).union(arb(_fq(hi)))


def _piece_eval(data, n, j, r, s):
    """Phi and its Jacobian on piece (n, j) at arb (r, s) (balls or intervals)."""
    from flint import arb

    C, lam, _ = data
    sc = arb(2) ** n
    sl = 2 * sc * r - (1 if j in (0, 1) else 0)
    tl = 2 * sc * s - (0 if j == 0 else 1)
    ln = lam**n
    f = ln * sc * 2
    x, xs, xt = _poly(C[j][0], sl, tl)
    y, ys, yt = _poly(C[j][1], sl, tl)
    return (ln * x, ln * y), ((f * xs, f * xt), (f * ys, f * yt))


def certify_preimage(k, x, y, r, s, prec=128):
    """Certify that Phi^-1(x, y) lies in a small arb box around the approximation (r, s).

    Returns a :class:`CertifiedPreimage`; ``certified`` is False if the Krawczyk test failed for
    every box size tried (not observed; reported, never hidden).

    Parameters
    ----------
    k : int
        Valence, k >= 3.
    x, y : float
        The image point, in the quadrant [0, inf)^2.
    r, s : float
        An approximation of the preimage (e.g. from :func:`~ccproof.inverse.inverse_characteristic_map`).
    prec : int, optional
        Bits of precision of the arb arithmetic (default 128).

    Returns
    -------
    CertifiedPreimage

    Examples
    --------
    >>> c = certify_preimage(5, 1.0, 0.0, 1.0, 0.0)
    >>> c.certified, c.contains(1.0, 0.0)
    (True, True)
    >>> c = certify_preimage(3, 0.5, 0.25, 0.4, 0.2)   # a poor approximation is fine
    >>> c.certified, c.width < 1e-30, c.distance(0.4, 0.2) > 0.01
    (True, True, True)
    """
    from flint import arb, ctx

    k = check_valence(k)
    X, Y = Fraction(float(x)), Fraction(float(y))
    if X < 0 or Y < 0:
        raise CCProofError("the point must lie in the quadrant [0, inf)^2")
    if X == 0 and Y == 0:
        z = arb(0)
        return CertifiedPreimage(z, z, True, (), 0.0)
    swap = Y > X
    if swap:
        X, Y = Y, X
        r, s = s, r
    data = _power_nets(k, prec)
    with ctx.workprec(prec):
        if Y == 0:
            res = _certify_axis(data, X, float(r), prec)
        else:
            res = _certify_2d(data, X, Y, float(r), float(s), prec)
    if swap:
        res = CertifiedPreimage(res.s, res.r, res.certified, tuple((n, (2 if j == 0 else 0 if j == 2 else 1))
                                                                  for n, j in res.pieces), res.width)
    return res


def _mid_fraction(a):
    man, e = a.mid().man_exp()
    return Fraction(int(man)) * Fraction(2) ** int(e)


def _refine(data, X, Y, r, s, axis, steps=8):
    """Newton in arb midpoints (no rigour needed here): a better centre for the box."""
    from flint import arb

    rm, sm = arb(r), arb(s)
    for _ in range(steps):
        rf, sf = _mid_fraction(rm), _mid_fraction(sm)
        if rf <= 0 and sf <= 0:
            break
        n, j = _piece_of(rf, sf)
        (px, py), ((a, b), (c, d)) = _piece_eval(data, n, j, arb(_fq(rf)), arb(_fq(sf)))
        fx, fy = px - arb(_fq(X)), py - arb(_fq(Y))
        if axis:
            rm = arb(rm.mid()) - fx / a
            continue
        det = a * d - b * c
        rm = arb(rm.mid()) - (d * fx - b * fy) / det
        sm = arb(sm.mid()) - (a * fy - c * fx) / det
        if not (rm.is_finite() and sm.is_finite()):
            return arb(r), arb(s)
    return arb(rm.mid()), arb(0 if axis else sm.mid())


def _piece_of(r, s):
    """A piece (n, j) whose closed domain contains the exact point (r, s) != 0."""
    top = max(r, s)
    n = 0
    while Fraction(2) ** (-n) < top:
        n -= 1
    while Fraction(2) ** (-n - 1) >= top:
        n += 1
    sc = Fraction(2) ** n
    u, v = r * sc, s * sc
    if u >= Fraction(1, 2):
        return n, (0 if v <= Fraction(1, 2) else 1)
    return n, 2


def _certify_2d(data, X, Y, r, s, prec):
    from flint import arb

    rm, sm = _refine(data, X, Y, r, s, axis=False)
    rc, scn = _mid_fraction(rm), _mid_fraction(sm)
    scale = max(abs(rc), abs(scn), Fraction(1, 2**1000))
    for e in (prec // 2, prec // 3, prec // 4, 2 * prec // 3, 20):
        rho = scale * Fraction(1, 2**e)
        rlo, rhi, slo, shi = rc - rho, rc + rho, scn - rho, scn + rho
        if slo < 0 or rlo <= 0:
            rho = min(rho, scn / 2, rc / 2)
            if rho <= 0:
                continue
            rlo, rhi, slo, shi = rc - rho, rc + rho, scn - rho, scn + rho
        try:
            pieces = _pieces(rlo, rhi, slo, shi)
        except CCProofError:
            continue
        J = None
        for n, j, (a0, a1), (b0, b1) in pieces:
            _, Jp = _piece_eval(data, n, j, _interval(a0, a1), _interval(b0, b1))
            J = Jp if J is None else tuple(tuple(J[i][q].union(Jp[i][q]) for q in range(2)) for i in range(2))
        n, j = _piece_of(rc, scn)
        (px, py), _ = _piece_eval(data, n, j, arb(_fq(rc)), arb(_fq(scn)))
        fx, fy = px - arb(_fq(X)), py - arb(_fq(Y))
        a, b, c, d = (arb(J[0][0].mid()), arb(J[0][1].mid()), arb(J[1][0].mid()), arb(J[1][1].mid()))
        det = a * d - b * c
        if det == 0:
            continue
        Y00, Y01, Y10, Y11 = d / det, -b / det, -c / det, a / det
        dr = _interval(-rho, rho)
        ds = dr
        M00 = 1 - (Y00 * J[0][0] + Y01 * J[1][0])
        M01 = -(Y00 * J[0][1] + Y01 * J[1][1])
        M10 = -(Y10 * J[0][0] + Y11 * J[1][0])
        M11 = 1 - (Y10 * J[0][1] + Y11 * J[1][1])
        Kr = arb(_fq(rc)) - (Y00 * fx + Y01 * fy) + M00 * dr + M01 * ds
        Ks = arb(_fq(scn)) - (Y10 * fx + Y11 * fy) + M10 * dr + M11 * ds
        if (Kr.lower() > arb(_fq(rlo)) and Kr.upper() < arb(_fq(rhi))
                and Ks.lower() > arb(_fq(slo)) and Ks.upper() < arb(_fq(shi))):
            width = float(max(Kr.rad(), Ks.rad()))
            return CertifiedPreimage(Kr, Ks, True, tuple((n, j) for n, j, _, _ in pieces), width)
    return CertifiedPreimage(arb(r), arb(s), False, (), float("inf"))


def _certify_axis(data, X, r, prec):
    from flint import arb

    rm, _ = _refine(data, X, Fraction(0), r, 0.0, axis=True)
    rc = _mid_fraction(rm)
    for e in (prec // 2, prec // 3, prec // 4, 20):
        rho = abs(rc) * Fraction(1, 2**e)
        rlo, rhi = rc - rho, rc + rho
        if rlo <= 0:
            continue
        pieces = [(n, j, rr, ss) for n, j, rr, ss in _pieces(rlo, rhi, Fraction(0), Fraction(0)) if j == 0]
        J = None
        for n, j, (a0, a1), _ in pieces:
            _, Jp = _piece_eval(data, n, j, _interval(a0, a1), arb(0))
            J = Jp[0][0] if J is None else J.union(Jp[0][0])
        n, j = _piece_of(rc, Fraction(0))
        (px, _), _ = _piece_eval(data, n, j, arb(_fq(rc)), arb(0))
        a = arb(J.mid())
        if a == 0:
            continue
        Kr = arb(_fq(rc)) - (px - arb(_fq(X))) / a + (1 - J / a) * _interval(-rho, rho)
        if Kr.lower() > arb(_fq(rlo)) and Kr.upper() < arb(_fq(rhi)):
            return CertifiedPreimage(Kr, arb(0), True, tuple((n, j) for n, j, _, _ in pieces),
                                     float(Kr.rad()))
    return CertifiedPreimage(arb(r), arb(0), False, (), float("inf"))
