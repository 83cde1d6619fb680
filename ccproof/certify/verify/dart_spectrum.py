"""The spectrum of ``dart:K`` for every K >= K0 at once (trusted).

The statement (docs/tagged_c1.md, "A plan for every dart K >= 101", items 1 to 3): for every K >= K0,
1 is a simple eigenvalue of S, lam1 = lam(cos(2 pi/K)) (odd, mode 1) and lam2 are simple, and every
other eigenvalue has modulus below r = lam(cos(2 sigma_r/K)) < lam2 < lam1. lam2 = lam(cos(2 sigma*/K))
with sigma* in the record's bracket comes from the eigenvector lemma (:mod:`.dart_eigen`), which needs the
count shown here. The argument, with what is checked where:

1. **Construction for every K** (:func:`check_construction`, exact). Every row of S but the centre's is
   the translate of one row per window class (kind, min(t, 3), min(K - t, 3), position): the rows of
   ``dart:7`` and ``dart:8`` relative to their point are one row per class, the same in both, and every
   class of a K >= 7 occurs there. The centre row is the smooth rule with weights 1 - 7h/4, 3h^2/2 on each
   ray's (1,0) and h^2/4 on each quadrant's (1,1), h = 1/K (checked for K = 7..12). :func:`.tagged_modes.
   check_dart` at K = 7, 8 then holds for every K: S commutes with the reflection R in ray 0; S is the
   ring operator L on the odd vectors (modes w_j = e^(2 pi i j/K), 1 <= j < K/2, and the odd parts of
   w = 1, -1, whose blocks do not depend on K); the one-ring (C, every (1,0), every (1,1)) is closed;
   every weight is >= 0, so the outer even rows' absolute sums are the window classes' and bound the
   outer eigenvalues by 15/64 for every K.
2. **Odd part.** Mode j has 1/8, 1/16, 1/32, 1/64, lam(c_j) and 1/(16 lam(c_j)) <= 1/4 (the block
   polynomial, :func:`.tagged_modes.check_ring`), c_j = cos(2 pi j/K); lam is strictly increasing on
   [-1, 1], so lam(c_1) = lam1 is the only one >= r when pi < sigma_r < 2 pi. The odd blocks of w = +-1
   have every eigenvalue below 1/2 (exact characteristic polynomials, roots in arb); r > 1/2 because
   2 sigma_r/K0 < pi/2. So the odd part has lam1 once and nothing else of modulus >= r.
3. **The even one-ring: a secular equation.** On the one-ring of 2K + 1 points the dart's operator is the
   smooth one S0 plus e_0 d^T (d: ray 0's sharp midpoint row minus the smooth edge row, derived from the
   rows; R-invariant, so d^T vanishes on odd vectors), hence det(lam - S) = det(lam - S0)(1 - F(lam)),
   F = d^T (lam - S0)^-1 e_0. In the Fourier modes of S0 (mode j != 0: the 2 x 2 block B1(w) of the ring
   stencil on (1,0), (1,1), closed: checked; mode 0: the 3 x 3 block B0(h) on (C, E, F))

       F = (1/K) [ sum_{j=1}^{K-1} g(lam, c_j) + g0(lam, h) ],   g = d_e(w) e^ + d_f(w) f^ = 1 + n*/(4 lam (c* - c)),

   (e^, f^) = (lam - B1(w))^-1 (1, 0), d_e, d_f the sums of d's ray and quadrant weights times w^delta, g0 the
   same with B0 and (0, 1, 0), c* = 8 lam - 5 + 1/(2 lam), n* = 4 (1 - c*)(lam - 1/4) - (1 + c*)
   (:func:`check_secular`: the identity of g in Q(lam, w), exact with fmpq_mpoly), and by the classical
   partial fractions of K z^(K-1)/(z^K - 1) (a stated lemma) sum_{j=0}^{K-1} 1/(cos phi - c_j) =
   -K cot(K phi/2)/sin phi, c* = cos phi. So

       1 - F = h (1 - g0) + n*/(4 lam) (cot(K phi/2)/sin phi + h/(c* - 1)).

   det(lam - B0) = (lam - 1) P(lam) + h det R(lam), P = lam^2 - 3 lam/4 + 1/16 = -lam (1 - c*)/8 (exact):
   the mode-0 pole is divided out where h -> 0.
4. **The count.** S0's eigenvalues of modulus >= r: 1 (mode 0; simple: Q(1) > 0 below), lam(c_1) twice
   (modes 1 and K - 1, one even and one odd combination); modes j >= 2 lie below r, 1/(16 lam) <= 1/4 < r,
   and mode 0's other two, the roots of Q = det(x - B0)/(x - 1) = P + h l (l = det R/(x - 1), linear:
   exact), are real, positive and below r: disc(Q) > 0, Q(0) > 0 > Q'(0), Q(r)/h > 0 and Q'(r) > 0 on h-balls
   covering [0, 1/K0]
   (:func:`check_mode0_roots`). None lies on the circle. If Re(1 - F) > 0 on |lam| = r (the record's trees over
   the regions N, I, F below, for t = arg lam in [0, pi]; the lower half by conjugation), 1 - F does not
   wind, so the one-ring operators of S and S0 have equally many eigenvalues outside the circle: 3. The
   odd part is the same for both (lam1, once), so the even one-ring has exactly two: 1 and, by the
   eigenvector lemma, lam(cos(2 sigma*/K)) with sigma* < sigma_hi < sigma_r; both simple. With 1. and 2.
   this is the spectral part of the generalized Reif criterion for every K >= K0.

The regions (each includes h = 0, K = infinity), on lam = r e^(it), r = lam(cos(2 sigma_r h)):

* N, t = tau h^2, (tau, h) in [0, tau1] x [0, 1/K0]: h (1 - F), with D = (1 - c*)/h^2 analytic and
  sigma^2 = D A(h^2 D)/2, A(x) = (asin(s)/s)^2 at s^2 = x/2 (its series with the tail as a ball);
* I, t in [tau1 h^2, v0^2]: v = sqrt(t), w = h/v, (v, w) in [0, v0] x [0, w1] with w1^2 tau1 >= 1:
  v (1 - F), cot(K phi/2) = -i plus a ball of radius 2 e^(-2T)/(1 - e^(-2T)), T = Im(K phi/2);
* F, (t, h) in [v0^2, 355/113] x [0, 1/K0]: 1 - F, T >= Im(phi) K0/2.

Each evaluator returns an arb enclosing Re of its quantity on a box (the multiplier h or v is > 0 for
every finite K); the record's trees (:func:`.replay.read_tree`) bound it below by a positive number.
"""

from __future__ import annotations

from functools import cache
from math import isqrt

from flint import acb, arb, fmpq, fmpq_mpoly_ctx, fmpq_poly

from ccproof.rigorous.analytic import ball

from .dart_family import kappa
from .errors import CertificateError
from .statement import lam_of
from .tagged import labels, sector_rows, window_rows
from .tagged_modes import RING_INDEX, charpoly_roots, check_dart, check_ring, ring_stencil

WINDOW = (7, 8)  # the window classes of every K >= 7 occur in both
_C = ("C",)
_E, _F = (1, 0), (1, 1)  # the one-ring positions
_HALF, _QUARTER, _EIGHTH = fmpq(1, 2), fmpq(1, 4), fmpq(1, 8)
T_PI = fmpq(355, 113)  # > pi: region F's end (boxes beyond pi are harmless: the circle continues)
W_DEN = 1024  # w1 = m/W_DEN, the least m with m^2 tau1 >= W_DEN^2


def _centre_ok(k):
    pts, row = labels("dart", k), sector_rows("dart", k)[0]
    want = {0: 1 - fmpq(7, 4 * k)}
    for j, p in enumerate(pts):
        if p[2:] == _E:
            want[j] = fmpq(3, 2 * k * k)
        elif p[0] == "q" and p[2:] == _F:
            want[j] = fmpq(1, 4 * k * k)
    return row == want


@cache
def check_construction():
    """Raise unless S is built the same way for every K >= 7 (item 1 of the module docstring); returns
    (d, bound): d as {("C",) or (kind, delta, position): weight} relative to ray 0 (the sharp midpoint row
    minus the smooth edge row) and the bound on the outer even rows.

    Examples
    --------
    >>> d, bound = check_construction()
    >>> d[("C",)], d[("r", 0, 1, 0)], d[("q", -1, 1, 1)], bound
    (1/8, 1/8, -1/16, 15/64)
    """
    sharp = _check_rows()
    bound = _outer_bound()
    _check_one_ring_closed()
    return _check_d(_construction_d(sharp)), bound


def _check_rows():
    """Raise unless the window classes agree, the centre row is the rule's and no weight is negative; returns
    the sharp midpoint row of ray 0."""
    check_ring()
    classes = [window_rows("dart", k) for k in WINDOW]
    if classes[0] != classes[1]:
        raise CertificateError(f"dart: the window classes of dart:{WINDOW[0]} and dart:{WINDOW[1]} differ")
    if not all(_centre_ok(k) for k in range(7, 13)):
        raise CertificateError("dart: the centre row is not (1 - 7h/4, 3h^2/2 per ray, h^2/4 per quadrant)")
    if any(x < 0 for k in WINDOW for row in sector_rows("dart", k) for x in row.values()):
        raise CertificateError("dart: a negative weight (the outer bound assumes none)")
    return classes[0][("r", 0, 3) + _E]


def _outer_bound():
    """The bound on the outer even rows over the window (raise if over 15/64, or if an odd block of the modes
    +-1 has an eigenvalue >= 1/2)."""
    bound = fmpq(0)
    for k in WINDOW:
        _, _, blocks, _, _, b = check_dart(k)
        bound = max(bound, b)
        for M in blocks:
            if not all(abs(z) < _HALF for z, _ in charpoly_roots(M)):
                raise CertificateError(f"dart:{k}: an odd block of the modes +-1 has an eigenvalue >= 1/2")
    if bound > fmpq(15, 64):
        raise CertificateError(f"dart: the outer even rows bound {bound} > 15/64")
    return bound


def _check_one_ring_closed():
    for pos in (_E, _F):  # the one-ring is closed in the ring stencil
        if any(q not in (_E, _F) for _, q in ring_stencil()[RING_INDEX[pos]]):
            raise CertificateError(f"the ring row of {pos} leaves the one-ring")


def _construction_d(sharp):
    """The sharp midpoint row minus the smooth edge row, zero weights dropped."""
    smooth = {("r" if q[1] == 0 else "q", dlt) + q: x for (dlt, q), x in ring_stencil()[RING_INDEX[_E]].items()}
    smooth[_C] = kappa()[RING_INDEX[_E]]
    d = {key: sharp.get(key, 0) - smooth.get(key, 0) for key in set(sharp) | set(smooth)}
    return {key: x for key, x in d.items() if x != 0}


def _check_d(d):
    """Raise unless d reads only the one-ring window and is invariant under the reflection in ray 0."""
    for key in d:
        if key != _C and (key[2:] not in (_E, _F) or not -1 <= key[1] <= 1):
            raise CertificateError(f"dart: d reads {key} outside the one-ring window")
        mirror = key if key == _C else (key[0], -key[1] if key[2:] == _E else -key[1] - 1) + key[2:]
        if d.get(mirror, 0) != d[key]:
            raise CertificateError("dart: d is not invariant under the reflection in ray 0")
    return d


def _b1w(w, zero):
    """w B1(w), B1 the ring stencil's 2 x 2 block on (1,0), (1,1) (no negative power of w: w an fmpq or a
    polynomial generator; ``zero`` of its ring)."""
    out = [[zero, zero], [zero, zero]]
    for i, pos in enumerate((_E, _F)):
        for (dlt, q), x in ring_stencil()[RING_INDEX[pos]].items():
            out[i][(_E, _F).index(q)] = out[i][(_E, _F).index(q)] + x * w ** (dlt + 1)
    return out


def _dw(w, zero):
    """(d_C, w d_e(w), w d_f(w)): d in the mode w (d_e = sum over rays delta of d w^delta, d_f over quadrants;
    w and ``zero`` as :func:`_b1w`)."""
    d, _ = check_construction()
    de, df = zero, zero
    for key, x in d.items():
        if key != _C:
            t = x * w ** (key[1] + 1)
            de, df = (de + t, df) if key[2:] == _E else (de, df + t)
    return d.get(_C, fmpq(0)), de, df


def b0(lam, h):
    """lam - B0(h), the mode-0 block on (C, E, F) (3 x 3 of lam's type)."""
    kap, B = kappa(), _b1w(fmpq(1), fmpq(0))  # B1(1)
    rows = [[1 - fmpq(7, 4) * h, fmpq(3, 2) * h, _QUARTER * h], [kap[RING_INDEX[_E]], B[0][0], B[0][1]],
            [kap[RING_INDEX[_F]], B[1][0], B[1][1]]]
    return [[(lam if i == j else 0) - rows[i][j] for j in range(3)] for i in range(3)]


def _det3(A):
    return (A[0][0] * (A[1][1] * A[2][2] - A[1][2] * A[2][1]) - A[0][1] * (A[1][0] * A[2][2] - A[1][2] * A[2][0])
            + A[0][2] * (A[1][0] * A[2][1] - A[1][1] * A[2][0]))


def mode0_parts(lam, h):
    """(num, det R): g0 = num/(8 det(lam - B0))... precisely g0 = num/det(lam - B0), num = the Cramer
    numerators of (lam - B0)^-1 (0, 1, 0) weighed by d's mode-0 part; det R = the h-coefficient of
    det(lam - B0) (only B0's first row depends on h, affinely)."""
    M = b0(lam, h)
    dc, de, df = _dw(fmpq(1), fmpq(0))
    num = 0 * lam
    for c, wt in enumerate((dc, de, df)):
        num += wt * _det3([[(int(i == 1) if j == c else M[i][j]) for j in range(3)] for i in range(3)])
    R = [[fmpq(7, 4), fmpq(-3, 2), -_QUARTER]] + b0(lam, 0)[1:]
    return num, _det3(R)


@cache
def check_secular():
    """Raise unless the identities of item 3 hold exactly: det(lam - B1(w)) = lam^2 - (5 + c) lam/8 + 1/16,
    g = 1 + n*/(4 lam (c* - c)) in Q(lam, w), P = -lam (1 - c*)/8, det(lam - B0) = (lam - 1) P + h det R,
    and det R = (lam - 1) l with l linear.

    Examples
    --------
    >>> check_secular()
    True
    """
    ctx = fmpq_mpoly_ctx.get(("l", "w", "h"), "lex")
    lam, w, h = ctx.gens()
    # clear w's negative powers: everything below is multiplied by w^2 (B1 reaches w^-1, d reaches w^-1)
    B = _b1w(w, ctx.from_dict({}))
    c2 = (w * w + 1) * w / 2  # w^2 c
    det2 = (lam * w - B[0][0]) * (lam * w - B[1][1]) - B[0][1] * B[1][0]  # w^2 det(lam - B1)
    if det2 != w * w * lam * lam - (5 * w * w + c2) * lam / 8 + w * w / 16:
        raise CertificateError("the 2 x 2 one-ring block has another characteristic polynomial")
    dc, de, df = _dw(w, ctx.from_dict({}))  # w d_e(w), w d_f(w)
    g_num = (lam * w - B[1][1]) * de + B[1][0] * df  # w^2 det(lam - B1) g
    # c* = 8 lam - 5 + 1/(2 lam); 2 lam n* = 4 (2 lam - 2 lam c*)(lam - 1/4) - (2 lam + 2 lam c*)
    lc = 16 * lam * lam - 10 * lam + 1  # 2 lam c*
    n2 = 4 * (2 * lam - lc) * (lam - _QUARTER) - (2 * lam + lc)  # 2 lam n*
    # g det = det + n*/32 (c* - c = 8 det/lam), times 64 lam w^2
    if 64 * lam * g_num != 64 * lam * det2 + n2 * w * w:
        raise CertificateError("the mode term g(lam, c) is not 1 + n*/(4 lam (c* - c))")
    P = lam * lam - 3 * lam / 4 + fmpq(1, 16)
    if 8 * P * 2 != -(2 * lam - lc):  # 8 P = -lam (1 - c*), times 2
        raise CertificateError("P is not -lam (1 - c*)/8")
    _, detR = mode0_parts(lam, h)
    if _det3(b0(lam, h)) != (lam - 1) * P + h * detR:
        raise CertificateError("det(lam - B0) is not (lam - 1) P + h det R")
    _ell()
    return True


def _ell():
    """l = det R/(lam - 1), raising unless det R (in Q[lam]) is (lam - 1) times a polynomial of degree <= 1."""
    x = fmpq_poly([0, 1])
    ell, rem = divmod(mode0_parts(x, 0)[1], x - 1)
    if rem != 0 or ell.degree() > 1:
        raise CertificateError("det R is not (lam - 1) times a linear polynomial")
    return ell


def check_mode0_roots(sig_r, k0, balls):
    """Raise unless on ``balls`` h-balls covering [0, 1/k0]: disc(Q) > 0, Q(0) > 0 and Q'(0) < 0 (both roots
    real and positive), Q(r)/h > 0, Q'(r) > 0 (both below r) and Q(1) > 0 (1 simple). Returns the least Q(r)/h.

    Examples
    --------
    >>> from flint import fmpq
    >>> check_mode0_roots(fmpq(27, 5), 101, 16) > 0
    True
    """
    ell = _ell()
    l0, l1 = ell[0], ell[1]
    sr = arb(sig_r)
    least = None
    for i in range(balls):
        h = ball(fmpq(i, balls * k0), fmpq(i + 1, balls * k0))
        r = lam_of((2 * sr * h).cos())  # the circle's radius (2 sigma_r h < pi/2: check_ranges)
        q_over_h = l0 + l1 * r - r / 4 * sr ** 2 * h * (sr * h).sinc() ** 2  # P(r) = -r sigma_r^2 h^2 sinc^2/4
        b, c = -fmpq(3, 4) + h * l1, fmpq(1, 16) + h * l0
        ok = (b * b - 4 * c > 0 and c > 0 and b < 0 and q_over_h > 0 and 2 * r + b > 0 and 1 + b + c > 0)
        if not ok:
            raise CertificateError(f"mode 0: h-ball {i}: Q's roots are not certainly real and below r, or Q(1) = 0")
        least = q_over_h.lower() if least is None else min(least, q_over_h.lower())
    return least


def _e1(z):
    """(e^z - 1)/z, analytic at 0."""
    return (z / 2).exp() * (acb(0, 1) * z / 2).sinc()


def _asin_ratio_sq(x, terms=40):
    """A(x) = (asin(s)/s)^2, s^2 = x/2: the series sum c_n y^n/(2n + 1), y = x/2, c_n <= 1, tail <=
    |y|^terms/(1 - |y|); raises ValueError unless |y| < 9/10."""
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
    """The evaluators of Re h (1 - F), Re v (1 - F), Re (1 - F) on the boxes of regions N, I, F.

    Parameters
    ----------
    sig_r : fmpq
        The circle |lam| = lam(cos(2 sigma_r/K)).
    k0 : int

    Examples
    --------
    >>> from flint import fmpq
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
    """w1 = m/W_DEN with m the least integer such that w1^2 tau1 >= 1 (exact: m^2 >= c, c the least integer
    >= W_DEN^2/tau1).

    >>> from flint import fmpq
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

    >>> from flint import fmpq
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


__all__ = ["SpectralRegions", "T_PI", "WINDOW", "b0", "check_construction", "check_mode0_roots", "check_ranges",
           "check_secular", "mode0_parts", "region_roots", "w1_of"]
