"""The spectrum and the eigenvectors of ``dart:K`` for every K >= K0 at once (trusted): only 1, lam1 and one even
eigenvalue lie outside |lam| = lam(cos(2 sigma_r/K)), and the family of :mod:`.dart_family` at sigma* is its
eigenvector (docs/tagged_c1.md, "Every dart K >= 101", items 3 and 7: "The spectral step", "The eigenvector lemma")."""

from __future__ import annotations

from functools import cache
from math import isqrt

from flint import acb, arb, ctx, fmpq, fmpq_mat, fmpq_mpoly_ctx, fmpq_poly

from ccproof.rigorous.analytic import ball

from .dart_family import B_AT_1, N_POLYS, Family, adjugate, kappa, l0, u_denominator
from .errors import CertificateError
from .rules import TWO_RING
from .statement import lam_of
from .tagged import WINDOW, labels, sector_rows, window_classes
from .tagged_modes import RING_INDEX, charpoly_roots, check_dart, check_ring, off_cut, ring_block, ring_stencil

_C = ("C",)
_E, _F = (1, 0), (1, 1)  # the one-ring positions
_E10, _E20, _E11 = RING_INDEX[_E], RING_INDEX[(2, 0)], RING_INDEX[_F]
_HALF, _QUARTER = fmpq(1, 2), fmpq(1, 4)
_X = fmpq_poly([0, 1])
T_PI = fmpq(355, 113)  # > pi: region F's end (boxes beyond pi are harmless: the circle continues)
W_DEN = 1024  # w1 = m/W_DEN, the least m with m^2 tau1 >= W_DEN^2
W_POINTS = 33  # the remainders of check_crease_row: w^-16 times polynomials of degree <= 32 in w
#: (a ray's row?, reading a ray?) -> the sectors delta it may read (the eigenvector lemma's windows)
_REACH = {(True, True): (-1, 0, 1), (True, False): (-1, 0), (False, True): (0, 1), (False, False): (0,)}


def _centre_ok(k):
    weight = {_E: fmpq(3, 2 * k * k), _F: fmpq(1, 4 * k * k)}  # per ray's (1,0), per quadrant's (1,1)
    want = {0: 1 - fmpq(7, 4 * k)} | {j: weight[p[2:]] for j, p in enumerate(labels("dart", k)) if p[2:] in weight}
    return sector_rows("dart", k)[0] == want


@cache
def check_construction():
    """Raise unless S is built alike for every K >= 7 (docs/tagged_c1.md, "The spectral step" (1)); returns (d,
    bound): d = ray 0's sharp midpoint row minus the smooth edge row, {("C",) or (kind, delta, position):
    weight}, and the outer even rows' bound.

    >>> d, bound = check_construction()
    >>> d[("C",)], d[("r", 0, 1, 0)], d[("q", -1, 1, 1)], bound
    (1/8, 1/8, -1/16, 15/64)
    """
    classes = window_classes("dart")
    if not all(_centre_ok(k) for k in range(7, 13)):
        raise CertificateError("dart: the centre row is not (1 - 7h/4, 3h^2/2 per ray, h^2/4 per quadrant)")
    if any(x < 0 for k in WINDOW for row in sector_rows("dart", k) for x in row.values()):
        raise CertificateError("dart: a negative weight (the outer bound assumes none)")
    bound = fmpq(0)
    for k in WINDOW:  # check_dart checks the ring (check_ring) first
        _, _, blocks, _, _, b = check_dart(k)
        bound = max(bound, b)
        if not all(abs(z) < _HALF for M in blocks for z, _ in charpoly_roots(M)):
            raise CertificateError(f"dart:{k}: an odd block of the modes +-1 has an eigenvalue >= 1/2")
    if bound > fmpq(15, 64):
        raise CertificateError(f"dart: the outer even rows bound {bound} > 15/64")
    return _sharp_difference(classes[("r", 0, 3) + _E]), bound


def _sharp_difference(sharp):
    """d = ``sharp`` minus the smooth edge row, raising unless the one-ring is closed in the ring stencil and d
    reads the one-ring window only, invariant under the reflection in ray 0."""
    if any(q not in (_E, _F) for pos in (_E, _F) for _, q in ring_stencil()[RING_INDEX[pos]]):
        raise CertificateError("the ring rows of the one-ring leave it")
    smooth = {("r" if q[1] == 0 else "q", dlt) + q: x for (dlt, q), x in ring_stencil()[_E10].items()}
    smooth[_C] = kappa()[_E10]
    d = {key: sharp.get(key, 0) - smooth.get(key, 0) for key in set(sharp) | set(smooth)}
    d = {key: x for key, x in d.items() if x != 0}
    for key in d:
        if key != _C and (key[2:] not in (_E, _F) or not -1 <= key[1] <= 1):
            raise CertificateError(f"dart: d reads {key} outside the one-ring window")
        mirror = key if key == _C else (key[0], -key[1] if key[2:] == _E else -key[1] - 1) + key[2:]
        if d.get(mirror, 0) != d[key]:
            raise CertificateError("dart: d is not invariant under the reflection in ray 0")
    return d


def _b1w(w, zero):
    """w B1(w), B1 the ring stencil's 2 x 2 block on (1,0), (1,1) (w an fmpq or a polynomial generator)."""
    out = [[zero, zero], [zero, zero]]
    for i, pos in enumerate((_E, _F)):
        for (dlt, q), x in ring_stencil()[RING_INDEX[pos]].items():
            out[i][(_E, _F).index(q)] = out[i][(_E, _F).index(q)] + x * w ** (dlt + 1)
    return out


def _dw(w, zero):
    """(d_C, w d_e(w), w d_f(w)): d in the mode w (d_e sums d's rays' weights times w^delta, d_f its quadrants')."""
    d = check_construction()[0]
    de, df = (sum((x * w ** (key[1] + 1) for key, x in d.items() if key[2:] == pos), zero) for pos in (_E, _F))
    return d.get(_C, fmpq(0)), de, df


def b0(lam, h):
    """lam - B0(h), the mode-0 block on (C, E, F) (3 x 3 of lam's type)."""
    kap, B = kappa(), _b1w(fmpq(1), fmpq(0))  # B1(1)
    rows = [[1 - fmpq(7, 4) * h, fmpq(3, 2) * h, _QUARTER * h], [kap[_E10], *B[0]], [kap[_E11], *B[1]]]
    return [[(lam if i == j else 0) - rows[i][j] for j in range(3)] for i in range(3)]


def _det3(A):
    return (A[0][0] * (A[1][1] * A[2][2] - A[1][2] * A[2][1]) - A[0][1] * (A[1][0] * A[2][2] - A[1][2] * A[2][0])
            + A[0][2] * (A[1][0] * A[2][1] - A[1][1] * A[2][0]))


def mode0_parts(lam, h):
    """(num, det R): g0 = num/det(lam - B0) (Cramer's numerators of (lam - B0)^-1 (0, 1, 0) weighed by d's mode-0
    part) and det R, the h-coefficient of det(lam - B0) (only B0's first row depends on h, affinely)."""
    M = b0(lam, h)
    num = sum((wt * _det3([[(int(i == 1) if j == c else M[i][j]) for j in range(3)] for i in range(3)])
               for c, wt in enumerate(_dw(fmpq(1), fmpq(0)))), 0 * lam)
    return num, _det3([[fmpq(7, 4), fmpq(-3, 2), -_QUARTER]] + b0(lam, 0)[1:])


@cache
def check_secular():
    """Raise unless the secular identities hold exactly (fmpq_mpoly): det(lam - B1(w)), g = 1 + n*/(4 lam (c* - c)),
    P = -lam (1 - c*)/8, det(lam - B0) = (lam - 1) P + h det R, det R = (lam - 1) l, l linear.

    >>> check_secular()
    True
    """
    lam, w, h = fmpq_mpoly_ctx.get(("l", "w", "h"), "lex").gens()
    zero = 0 * lam  # everything below is multiplied by w^2 (B1 and d reach w^-1)
    B = _b1w(w, zero)
    c2 = (w * w + 1) * w / 2  # w^2 c
    det2 = (lam * w - B[0][0]) * (lam * w - B[1][1]) - B[0][1] * B[1][0]  # w^2 det(lam - B1)
    if det2 != w * w * lam * lam - (5 * w * w + c2) * lam / 8 + w * w / 16:
        raise CertificateError("the 2 x 2 one-ring block has another characteristic polynomial")
    dc, de, df = _dw(w, zero)
    g_num = (lam * w - B[1][1]) * de + B[1][0] * df  # w^2 det(lam - B1) g
    lc = 16 * lam * lam - 10 * lam + 1  # 2 lam c*
    n2 = 4 * (2 * lam - lc) * (lam - _QUARTER) - (2 * lam + lc)  # 2 lam n*
    if 64 * lam * g_num != 64 * lam * det2 + n2 * w * w:  # g det = det + n*/32 (c* - c = 8 det/lam)
        raise CertificateError("the mode term g(lam, c) is not 1 + n*/(4 lam (c* - c))")
    P = lam * lam - 3 * lam / 4 + fmpq(1, 16)
    if 8 * P * 2 != -(2 * lam - lc):
        raise CertificateError("P is not -lam (1 - c*)/8")
    if _det3(b0(lam, h)) != (lam - 1) * P + h * mode0_parts(lam, h)[1]:
        raise CertificateError("det(lam - B0) is not (lam - 1) P + h det R")
    _ell()
    return True


def _ell():
    """l = det R/(lam - 1), raising unless det R (in Q[lam]) is (lam - 1) times a polynomial of degree <= 1."""
    ell, rem = divmod(mode0_parts(_X, 0)[1], _X - 1)
    if rem != 0 or ell.degree() > 1:
        raise CertificateError("det R is not (lam - 1) times a linear polynomial")
    return ell


def check_mode0_roots(sig_r, k0, balls):
    """Raise unless on ``balls`` h-balls covering [0, 1/k0] Q's roots are real, positive and below r and
    Q(1) > 0 (1 simple); returns the least Q(r)/h.

    >>> check_mode0_roots(fmpq(27, 5), 101, 16) > 0
    True
    """
    ell = _ell()
    l0_, l1, sr, least = ell[0], ell[1], arb(sig_r), None
    for i in range(balls):
        h = ball(fmpq(i, balls * k0), fmpq(i + 1, balls * k0))
        r = lam_of((2 * sr * h).cos())  # the circle's radius (2 sigma_r h < pi/2: check_ranges)
        q_over_h = l0_ + l1 * r - r / 4 * sr ** 2 * h * (sr * h).sinc() ** 2  # P(r) = -r sigma_r^2 h^2 sinc^2/4
        b, c = -fmpq(3, 4) + h * l1, fmpq(1, 16) + h * l0_
        if not (b * b - 4 * c > 0 and c > 0 and b < 0 and q_over_h > 0 and 2 * r + b > 0 and 1 + b + c > 0):
            raise CertificateError(f"mode 0: h-ball {i}: Q's roots are not certainly real and below r, or Q(1) = 0")
        least = q_over_h.lower() if least is None else min(least, q_over_h.lower())
    return least


def _e1(z):
    """(e^z - 1)/z, analytic at 0."""
    return (z / 2).exp() * (acb(0, 1) * z / 2).sinc()


def _asin_ratio_sq(x, terms=40):
    """A(x) = (asin(s)/s)^2, s^2 = x/2: sum c_n y^n/(2n + 1), y = x/2, c_n <= 1, tail <= |y|^terms/(1 - |y|)."""
    y = x / 2
    if not abs(y) < fmpq(9, 10):
        raise ValueError("asin series: |x/2| is not certainly below 9/10")
    acc, c = acb(0), fmpq(1)
    for n in range(terms):
        acc += c / (2 * n + 1) * y ** n
        c = c * (2 * n + 1) / (2 * n + 2)
    tail = (abs(y) ** terms / (1 - abs(y))).upper()
    s = acc + acb(arb(0, tail), arb(0, tail))
    return s * s


def _cot_far(T):
    """cot z for Im z >= T > 0: -i plus a ball of radius 2 e^(-2T)/(1 - e^(-2T))."""
    if not T > 0:
        raise ValueError("cot: Im z is not certainly positive")
    e = (-2 * T).exp()
    rad = (2 * e / (1 - e)).upper()
    return acb(arb(0, rad), arb(-1, rad))


def _nstar(one_minus_c, lam):
    return 4 * one_minus_c * (lam - _QUARTER) - (2 - one_minus_c)


class SpectralRegions:
    """The evaluators of Re h (1 - F), Re v (1 - F), Re (1 - F) on boxes of the regions N, I, F (the circle
    |lam| = lam(cos(2 sigma_r/K))).

    >>> reg = SpectralRegions(fmpq(27, 5), 101)
    >>> bool(reg.n([(fmpq(0), fmpq(5, 4)), (fmpq(0), fmpq(1, 404))]) > 0)
    True
    """

    def __init__(self, sig_r, k0):
        check_secular()
        self.sig_r, self.k0 = arb(sig_r), k0

    def n(self, box):
        tau, h = (ball(*iv) for iv in box)
        sr = self.sig_r
        r = lam_of((2 * sr * h).cos())
        e = acb(0, 1) * tau * h * h
        lam = r * e.exp()
        D = 2 * sr ** 2 * (sr * h).sinc() ** 2 - 8 * r * acb(0, 1) * tau * _e1(e) + acb(0, 1) * tau * _e1(-e) / (2 * r)
        sig = (D * _asin_ratio_sq(h * h * D) / 2).sqrt()
        num, detR = mode0_parts(lam, h)
        h2g0 = h * num / (-(lam - 1) * lam * h * D / 8 + detR)
        val = h * h - h2g0 + _nstar(h * h * D, lam) / (4 * lam) * (sig.cot() / (2 * sig * (2 * sig * h).sinc()) - 1 / D)
        return val.real

    def i(self, box):
        v, w = (ball(*iv) for iv in box)
        sr = self.sig_r
        h = v * w
        r = lam_of((2 * sr * h).cos())
        e = acb(0, 1) * v * v
        lam = r * e.exp()
        D = 2 * sr ** 2 * w * w * (sr * h).sinc() ** 2 - 8 * r * acb(0, 1) * _e1(e) + acb(0, 1) * _e1(-e) / (2 * r)
        psi = (2 * D * _asin_ratio_sq(v * v * D)).sqrt()
        if not psi.imag > 0:
            psi = -psi
        cot = _cot_far(psi.imag.lower() / (2 * arb(w.upper())))
        a = -(lam - 1) * lam * D / 8
        num, b = mode0_parts(lam, h)
        if v.lower() > 0 or w.lower() > 0:
            vhg0 = v * w * num / (a * v + b * w)
        else:  # |a v + b w| >= m w, m = (al ga - be de)/(al + de): |v w/(a v + b w)| <= v_hi/m
            al, be, ga, de = abs(a.imag).lower(), abs(b.imag).upper(), abs(b.real).lower(), abs(a.real).upper()
            m = (al * ga - be * de) / (al + de)
            if not m > 0:
                raise ValueError("region I: the mode-0 term is not bounded at v = w = 0")
            bound = (arb(v.upper()) / m * abs(num)).upper()
            vhg0 = acb(arb(0, bound), arb(0, bound))
        val = v * h - vhg0 + _nstar(v * v * D, lam) / (4 * lam) * (cot / (psi * (v * psi).sinc()) - w / D)
        return val.real

    def f(self, box):
        t, h = (ball(*iv) for iv in box)
        r = lam_of((2 * self.sig_r * h).cos())
        lam = r * (acb(0, 1) * t).exp()
        cs = 8 * lam - 5 + 1 / (2 * lam)
        # any root of cos phi = c* will do (the expression is even and 2 pi-periodic in phi for integer K)
        if cs.imag > 0 or cs.imag < 0:
            phi = acb(0, 1) * cs.acosh()
        elif cs.real < -1:
            phi = acb.pi() + acb(0, 1) * (-cs).acosh()
        else:
            phi = cs.acos()
        if not phi.imag > 0:
            phi = -phi
        cot = _cot_far(phi.imag.lower() * self.k0 / 2)
        num, detR = mode0_parts(lam, h)
        g0 = num / _det3(b0(lam, h))
        val = h * (1 - g0) + _nstar(1 - cs, lam) / (4 * lam) * (cot / phi.sin() + h / (cs - 1))
        return val.real


def w1_of(tau1):
    """w1 = m/W_DEN, m the least integer with w1^2 tau1 >= 1 (exact).

    >>> w1_of(fmpq(50))
    145/1024
    """
    if not tau1 > 0:
        raise CertificateError("spectrum: tau1 must be > 0")
    tau1 = fmpq(tau1)
    c = -(-(W_DEN * W_DEN * int(tau1.q)) // int(tau1.p))
    return fmpq(isqrt(c - 1) + 1, W_DEN)


def region_roots(k0, tau1, v0):
    """The root boxes of the regions N, I, F (fixed by K0, tau1, v0).

    >>> region_roots(101, fmpq(50), fmpq(2, 5))["I"]
    [(0, 2/5), (0, 145/1024)]
    """
    h0 = fmpq(1, k0)
    return {"N": [(fmpq(0), tau1), (fmpq(0), h0)], "I": [(fmpq(0), v0), (fmpq(0), w1_of(tau1))],
            "F": [(v0 * v0, T_PI), (fmpq(0), h0)]}


def check_ranges(k0, sig_lo, sig_hi, sig_r, tau1, v0):
    """Raise unless pi < sig_lo < sig_hi < sig_r < 2 pi, 2 sig_r/k0 < pi/2, tau1 > 0 and 0 < v0^2 < pi."""
    pi = arb.pi()
    if not (pi < arb(sig_lo) and sig_lo < sig_hi < sig_r and arb(sig_r) < 2 * pi):
        raise CertificateError("spectrum: need pi < sigma_lo < sigma_hi < sigma_r < 2 pi")
    if not 4 * arb(sig_r) < pi * k0:
        raise CertificateError("spectrum: need 2 sigma_r/K0 < pi/2 (so that r > 1/2)")
    if not (tau1 > 0 and v0 > 0 and arb(v0 * v0) < pi):
        raise CertificateError("spectrum: need tau1 > 0 and 0 < v0^2 < pi")


def check_reach():
    """Raise unless a ray's ring row reads rays d = -1..1 and quadrants d = -1, 0, a quadrant's rays d = 0, 1 and
    its own quadrant (the lemma's windows).

    >>> check_reach()
    True
    """
    for pos, row in zip(TWO_RING, ring_stencil()):
        for d, q in row:
            if d not in _REACH[(pos[1] == 0, q[1] == 0)]:
                raise CertificateError(f"the ring row of {pos} reads {q} of sector +{d}: "
                                       "beyond the windows of the lemma")
    return True


def check_mode0():
    """Raise unless (x - B(1)) N(x) = det(x - B(1)) kappa for U's numerator N (exact in Q[x]).

    >>> check_mode0()
    True
    """
    p, kap = B_AT_1.charpoly(), kappa()
    N = [fmpq_poly(c) for c in N_POLYS]
    if any(_X * N[i] - sum((B_AT_1[i, k] * N[k] for k in range(6)), fmpq_poly(0)) != p * kap[i] for i in range(6)):
        raise CertificateError("U's numerator is not adj(x - B(1)) kappa: the mode-0 part misses its rows")
    return True


def check_crease_row(points=W_POINTS):
    """Raise unless a1 b2 = a2 b1 on the curve lam = lam(c) (exact at w = 1..points): ray 0's crease vertex row
    holds wherever its sharp midpoint's does.

    >>> check_crease_row()
    True
    """
    if points < W_POINTS:
        raise CertificateError(f"{points} values of w cannot show an identity of degree {W_POINTS - 1}")
    p = B_AT_1.charpoly()  # the product of check_ring's block polynomial at w = 1
    N = [fmpq_poly(c) for c in N_POLYS]
    if any(n.degree() > 5 for n in N):
        raise CertificateError("U's numerator has degree > 5: the degree bound of the identity fails")
    a1 = (_X - _HALF) * N[_E10] - p / 2
    a2 = (_X - fmpq(1, 8)) * N[_E20] - fmpq(3, 4) * N[_E10] - p / 8
    psi = [fmpq_poly(0)] * 6
    psi[_E20] = a1 * (_X - fmpq(1, 8))
    psi[_E10] = -fmpq(3, 4) * a1 - a2 * (_X - _HALF)
    for w in range(1, points + 1):
        q = _X * _X - (5 + (fmpq(w) + fmpq(1, w)) / 2) / 8 * _X + fmpq(1, 16)
        adj = adjugate(fmpq_mat(ring_block(fmpq(w))))
        if any(sum((psi[i] * adj[i][j] for i in range(6)), fmpq_poly(0)) % q != 0 for j in range(6)):
            raise CertificateError(f"a1 b2 != a2 b1 at w = {w}: the crease vertex row of ray 0 fails")
    return True


def _nonzero(z, what):
    if not (z.is_finite() and abs(z) > 0):
        raise ZeroDivisionError(f"{what} is not certainly non-zero")


def scaled_centre_residual(fam):
    """r/h, the centre row's residual of S y - lam y over h, of a Family at an acb ball h (0 allowed) and an arb
    sigma; ZeroDivisionError unless U's denominator, alpha's a1, lam - 1/2 and every division are regular.

    >>> r = scaled_centre_residual(Family(acb(fmpq(1, 101)), arb("4.484")))
    >>> r.real > 0, abs(r.imag) < 1e-10, abs(r.real - 0.0013118) < 1e-6
    (True, True, True)
    """
    h, sigma, lam, (L0, L1) = fam.h, fam.sigma, fam.lam2, l0()
    _nonzero(u_denominator(lam, L1), "U's denominator")
    _nonzero((lam - _HALF) * fam.U[_E10] - (lam - L0) / 2, "alpha's denominator a1")
    _nonzero(lam - _HALF, "lam - 1/2")
    if not all(z.is_finite() for z in list(fam.U) + list(fam.vy) + list(fam.vx)):
        raise ZeroDivisionError("U or a bordered solution is not finite")
    sh, sinc = h * sigma, (h * sigma).sinc()
    _nonzero(sinc, "sinc(sigma h)")
    c = (2 * sh).cos()
    root = ((1 + c) * (9 + off_cut(c))).sqrt()  # the principal root, analytic off the cut
    _nonzero(root + arb(20).sqrt(), "sqrt((1 + c)(9 + c)) + sqrt 20")
    dl = -(sigma * sigma * h * sinc * sinc / 8) * (1 + (c + 11) / (root + arb(20).sqrt()))  # (lam - L0)/h
    w = (2 * acb(0, 1) * sh).exp()
    quot = (-acb(0, 1) * sh).exp() / (2 * acb(0, 1) * sigma * sinc)  # h/(w - 1)
    U, v, alpha = fam.U, fam.vy, fam.alpha
    out = ((1 - 7 * h / 4 - lam) * alpha * dl + alpha * (3 * U[_E10] / 2 + U[_E11] / 4)
           + acb(0, 1) * sigma.sin() * quot * (3 * v[_E10] * (1 + w) / 2 + v[_E11] / 2))
    if not out.is_finite():
        raise ZeroDivisionError("r/h is not finite")
    return out


def _guard(fam, tol):
    """Raise unless the Family computes the lemma's formula here: v^(1,0) = 1, y(C) = alpha (lam - L0), ray 0's
    two sharp rows and the ring rows of sector 1 (balls containing 0, radii below tol: identities)."""
    lam, y, yc, kap = fam.lam2, fam.layer_level0()[1], fam.yc, kappa()
    res = [fam.vy[_E10] - 1, yc - fam.alpha * (lam - l0()[0]), (lam - _HALF) * y(0, _E) - yc / 2,
           (lam - fmpq(1, 8)) * y(0, (2, 0)) - fmpq(3, 4) * y(0, _E) - yc / 8]
    res += [kap[i] * yc - lam * y(1, pos) + sum((x * y(1 + d, q) for (d, q), x in ring_stencil()[i].items()), 0 * yc)
            for i, pos in enumerate(TWO_RING)]
    for k, z in enumerate(res):
        if not (z.contains(0) and abs(z) < tol):
            raise CertificateError(f"the family misses identity {k} of the eigenvector lemma "
                                   "(pivot, centre value, sharp midpoint, crease vertex, ring rows of sector 1)")


def check_eigenvector(sig_lo, sig_hi, k0, prec, balls=64, family=Family):
    """Show that for every K >= k0 the family member at sigma(K) in (sig_lo, sig_hi) is the eigenvector of lam2
    (and x that of lam1), on ``balls`` h-balls covering [0, 1/k0]; one line, or CertificateError with the reason.
    ``family(h, sigma)``: tests pass perturbed families.

    >>> check_eigenvector(fmpq(4484, 1000), fmpq(44935, 10000), 101, 128).split(":")[0]
    'eigenvector lemma for every K >= 101'
    """
    sig_lo, sig_hi = fmpq(sig_lo), fmpq(sig_hi)
    if k0 < 7 or balls < 1:
        raise CertificateError(f"eigenvector lemma: K0 = {k0} < 7 or no h-balls")
    with ctx.workprec(prec):
        if not (arb(sig_lo) > arb.pi() and arb(sig_hi) < 2 * arb.pi() and sig_lo < sig_hi):
            raise CertificateError("eigenvector lemma: the bracket is not inside (pi, 2 pi)")
        for exact in (check_ring, check_reach, check_mode0, check_crease_row):
            exact()
        box = ball(sig_lo, sig_hi)
        if not box.cos() < 0:
            raise CertificateError("eigenvector lemma: cos(sigma) is not certainly < 0 on the bracket (alpha != 0)")
        tol = arb(2) ** (-(prec // 2))
        for i in range(balls):
            h = acb(ball(fmpq(i, balls * k0), fmpq(i + 1, balls * k0)))
            try:
                _guard(family(acb(fmpq(2 * i + 1, 2 * balls * k0)), arb(sig_lo)), tol)  # at the ball's centre
                vals = [scaled_centre_residual(family(h, s)) for s in (arb(sig_lo), arb(sig_hi), box)]
            except ZeroDivisionError as exc:
                raise CertificateError(f"eigenvector lemma: h-ball {i}: {exc}") from None
            lo, hi = vals[0].real, vals[1].real
            if not (lo > 0 > hi or lo < 0 < hi):
                raise CertificateError(f"eigenvector lemma: h-ball {i}: the centre residual r/h has no certain sign "
                                       f"change over the bracket (at sig_lo {lo.str(3)}, at sig_hi {hi.str(3)})")
        return (f"eigenvector lemma for every K >= {k0}: ring rows and ray 0's rows identically (exact: reach, "
                f"mode 0, crease row at {W_POINTS} w), centre residual changes sign on ({sig_lo}, {sig_hi}) on "
                f"{balls} h-balls, the family (x's and y's bordered systems, U, alpha) regular on the whole bracket")
