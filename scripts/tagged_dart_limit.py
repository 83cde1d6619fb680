#!/usr/bin/env python
"""Explore ``dart:K`` for every large K at once (not trusted; no certificate is written).

A C1 certificate for every K >= K0 needs (docs/tagged_c1.md, "A plan for every dart K >= 101"):

(a) the spectrum for all K: lam1 = lam(cos(2 pi/K)) (odd mode 1, closed form) and lam2, the
    leading root of the even one-ring block S_in below 1, with lam1 > lam2 > |every other|;
(b) the characteristic map (x, y) regular and injective uniformly in K.

The even one-ring block is the smooth even operator S0 with ONE row changed (ray 0's (1,0): the sharp
edge midpoint (C + e_0)/2 instead of the smooth edge rule), so S_in = S0 + e_0 d^T and every eigenvalue
of S_in that is none of S0 solves F(lam) = d^T (lam - S0)^-1 e_0 = 1. Through the Fourier modes of S0,

    F(lam) = (1/K) [ (K - 1) + n*/(4 lam) (sum_j 1/(c* - c_j) - 1/(c* - 1)) + g0(lam, K) ],

c_j = cos(2 pi j/K), c* = (16 lam^2 - 10 lam + 1)/(2 lam) (so lam = lam(c*)), n* = 4 (1 - c*)(lam - 1/4)
- (1 + c*), g0 the mode-0 term (a 3 x 3 resolvent), and the classical sum over the K-th roots of unity
sum_{j=0}^{K-1} 1/(cos phi - c_j) = -K cot(K phi/2)/sin phi (c* = cos phi). With phi = 2 sigma/K,
h = 1/K, the equation F = 1 becomes G(sigma, h) = 0,

    G = -sigma cot(sigma)/sinc(phi) + 1/sinc(phi/2)^2 + 2 sigma^2 h^2 (g0 - 1) 4 lam/n*,

analytic in (sigma, h) near h = 0, with the limit tan(sigma) = sigma: lam2 = lam(cos(2 sigma/K)) with
sigma -> 4.4934 (between pi and 2 pi, i.e. lam(cos(4 pi/K)) < lam2 < lam(cos(2 pi/K)) = lam1).

The script prints, one block per item:

A. the closed form of F against the exact resolvent d^T (lam - S0)^-1 e_0 (fmpq, one-ring matrices
   built here from the rules, independently of the trusted base) at rational lam, K = 5..30;
B. sigma(K), lam1, lam2, lam(cos(4 pi/K)) and the scaled gaps for K = 101 .. 10^6 and the limit;
C. a bracket of sigma for every K >= K0 at once: G(sigma_lo, h) and G(sigma_hi, h) of certain opposite
   signs on arb boxes covering h in [0, 1/K0];
D. the winding number of 1 - F along the circle |lam| = r (r between lam(cos(4 pi/K)) and lam2): 0
   means lam2 is the only eigenvalue of S_in of modulus > r besides 1 (floats, adaptive; a measurement);
D'. the same for every K >= K0 at once: Re(1 - F) > 0 on the whole circle, on arb/acb boxes in three
   regions of variables that include h = 1/K = 0 (see the comment above :func:`region_n`), and mode 0's
   second and third eigenvalues below r;
E. the characteristic map at K = 101, 202, 404, 808 (x the odd mode-1 vector, y the even vector of lam2 by
   inverse iteration on the sparse S): K times the least Bernstein coefficient of det J_Phi per piece
   and of the transversality forms, and where along the ring the minimum sits; its convergence is what
   a uniform-in-K map certificate must exploit;
F. the same map from closed forms (x the mode-1 vector; y = y_C u(p) + Re(beta (v^(p) e^(i phi (t - K/2)) + its
   mirror image in ray K/2)), exact on every point: |S y - lam2 y| is printed) at K = 1000, 4000, 16000:
   the quadrants next to the sharp ray (K^3 min det J, and over (2 pi q)^2) against the bulk (K min det J
   over theta^2), which must match for a two-regime argument.

  python scripts/tagged_dart_limit.py [--k0 101] [--skip-map]   (about 60 s, 0.94 GB: K = 16000 in F)
"""

from __future__ import annotations

import argparse
import cmath
import math

from flint import acb, arb, ctx, fmpq, fmpq_mat

_HALF, _EIGHTH = fmpq(1, 2), fmpq(1, 8)


# --- A. the one-ring matrices from the rules (C, e_0..e_{K-1}, f_0..f_{K-1}) --------------------------

def one_ring(k, dart):
    """The smooth one-ring operator (dart=False) or the dart's (ray 0 sharp), exact, 2k + 1 rows."""
    m = 2 * k + 1
    S = fmpq_mat(m, m)
    e, f = (lambda r: 1 + r % k), (lambda q: 1 + k + q % k)
    S[0, 0] = 1 - fmpq(7, 4 * k)
    for r in range(k):
        S[0, e(r)] += fmpq(3, 2 * k * k)
        S[0, f(r)] += fmpq(1, 4 * k * k)
        S[f(r), 0] += fmpq(1, 4)
        S[f(r), e(r)] += fmpq(1, 4)
        S[f(r), e(r + 1)] += fmpq(1, 4)
        S[f(r), f(r)] += fmpq(1, 4)
        if dart and r == 0:
            S[e(0), 0] += _HALF
            S[e(0), e(0)] += _HALF
            continue
        S[e(r), 0] += fmpq(3, 8)
        S[e(r), e(r)] += fmpq(3, 8)
        for j in (e(r - 1), e(r + 1), f(r - 1), f(r)):
            S[e(r), j] += fmpq(1, 16)
    return S


def g0(lam, h):
    """The mode-0 term d . (lam - B0)^-1 (0, 1, 0) (B0 on (C, E, F); h = 1/K may be a ball)."""
    B0 = [[1 - 7 * h / 4, 3 * h / 2, h / 4], [fmpq(3, 8), _HALF, _EIGHTH], [fmpq(1, 4), _HALF, fmpq(1, 4)]]
    # Cramer: u = (lam - B0)^-1 (0, 1, 0)
    M = [[(lam if i == j else 0) - B0[i][j] for j in range(3)] for i in range(3)]

    def det3(A):
        return (A[0][0] * (A[1][1] * A[2][2] - A[1][2] * A[2][1]) - A[0][1] * (A[1][0] * A[2][2] - A[1][2] * A[2][0])
                + A[0][2] * (A[1][0] * A[2][1] - A[1][1] * A[2][0]))
    D = det3(M)
    rhs = [0, 1, 0]
    u = [det3([[rhs[i] if j == c else M[i][j] for j in range(3)] for i in range(3)]) / D for c in range(3)]
    return u[0] / 8 - u[2] / 8


def cstar(lam):
    return (16 * lam * lam - 10 * lam + 1) / (2 * lam)


def f_closed(lam, k):
    """F(lam) for dart:k by the closed form (acb; lam complex allowed)."""
    lam = acb(lam)
    cs = cstar(lam)
    phi = cs.acos()
    n = 4 * (1 - cs) * (lam - fmpq(1, 4)) - (1 + cs)
    s = -k * (k * phi / 2).cot() / phi.sin()
    return ((k - 1) + n / (4 * lam) * (s - 1 / (cs - 1)) + g0(lam, fmpq(1, k))) / k


def f_exact(lam, k):
    """d^T (lam - S0)^-1 e_0 from the one-ring matrices (fmpq)."""
    S0, Sd = one_ring(k, False), one_ring(k, True)
    m = S0.nrows()
    d = [Sd[1, j] - S0[1, j] for j in range(m)]
    A = fmpq_mat([[(lam if i == j else 0) - S0[i, j] for j in range(m)] for i in range(m)])
    u = A.solve(fmpq_mat([[int(i == 1)] for i in range(m)]))
    return sum((d[j] * u[j, 0] for j in range(m)), fmpq(0))


def part_a():
    worst = arb(0)
    for k in range(5, 31):
        for lam in (fmpq(2, 5), fmpq(3, 5), fmpq(13, 20), fmpq(7, 10), fmpq(3, 2)):
            ex, cl = f_exact(lam, k), f_closed(lam, k)
            err = abs(cl - acb(ex))
            if not err < arb("1e-20"):
                print(f"A  MISMATCH K={k} lam={lam}: exact {ex}, closed {cl}")
                return
            worst = max(worst, err.mid())
    print(f"A  closed-form F = exact resolvent at lam in {{2/5, 3/5, 13/20, 7/10, 3/2}}, K = 5..30: "
          f"max |difference| {float(worst):.1e} (128 bits)")


# --- B, C. the scaled secular function G(sigma, h) ------------------------------------------------

def lam_of(c):
    return (5 + c + ((1 + c) * (9 + c)).sqrt()) / 16


def h2g0(sigma, h, lam):
    """h^2 g0(lam, h) at lam = lam(cos(2 sigma h)), analytic at h = 0.

    B0's mode-0 block has, at h = 0, the eigenvalue lam(1) of the limit: det(lam - B0) = det0 + h det(R) with
    det0 = (lam - 1)(lam^2 - 3 lam/4 + 1/16) = -(lam - 1) lam sigma^2 h^2 sinc(sigma h)^2/4 (lam = lam(c) solves
    lam^2 - (5 + c) lam/8 + 1/16 = 0), so det/h is regular; g0 = (u0 - u2)/8 by Cramer, u2 det = O(1).
    """
    q = fmpq(1, 4)
    R = [[fmpq(7, 4), fmpq(-3, 2), -q], [fmpq(-3, 8), lam - _HALF, -_EIGHTH], [-q, -_HALF, lam - q]]
    det_r = (R[0][0] * (R[1][1] * R[2][2] - R[1][2] * R[2][1]) - R[0][1] * (R[1][0] * R[2][2] - R[1][2] * R[2][0])
             + R[0][2] * (R[1][0] * R[2][1] - R[1][1] * R[2][0]))
    det_h = -(lam - 1) * lam * sigma ** 2 * h * (sigma * h).sinc() ** 2 / 4 + det_r
    m00, m01, m02, m20, m21, m22 = lam - 1 + 7 * h / 4, -3 * h / 2, -h / 4, -q, -_HALF, lam - q
    u0_det = -(m01 * m22 - m02 * m21)       # = O(h)
    u2_det = -(m00 * m21 - m01 * m20)
    return h * (u0_det - u2_det) / (8 * det_h)


def big_g(sigma, h):
    """G(sigma, h) (arb balls allowed for both; h = 0 gives the limit 1 - sigma cot sigma)."""
    phi = 2 * sigma * h
    cs = phi.cos()
    lam = lam_of(cs)
    n = 4 * (1 - cs) * (lam - fmpq(1, 4)) - (1 + cs)
    return (-sigma / sigma.tan() / phi.sinc() + 1 / (phi / 2).sinc() ** 2
            + 2 * sigma ** 2 * (h2g0(sigma, h, lam) - h ** 2) * 4 * lam / n)


def sigma_of(h, lo=4.0, hi=4.6):
    a, b = arb(lo), arb(hi)
    ga = big_g(a, h)
    for _ in range(200):
        m = (a + b) / 2
        gm = big_g(m.mid(), h)
        if (gm > 0) == (ga > 0):
            a, ga = m.mid(), gm
        else:
            b = m.mid()
    return (a + b) / 2


def part_b(ks):
    print("B  K        sigma(K)        lam1            lam2            lam(cos 4pi/K)  "
          "K^2(lam1-lam2)  K^2(lam2-lam(c2))")
    for k in ks:
        h = arb(0) if k is None else arb(fmpq(1, k))
        s = sigma_of(h)
        if k is None:
            print(f"   limit    {s.str(12, radius=False)}  (root of tan s = s in (pi, 3 pi/2))")
            continue
        l1, l2s = lam_of((2 * arb.pi() * h).cos()), lam_of((4 * arb.pi() * h).cos())
        l2 = lam_of((2 * s * h).cos())
        print(f"   {k:<8} {s.str(12, radius=False)}  {l1.str(12, radius=False)}  {l2.str(12, radius=False)}  "
              f"{l2s.str(12, radius=False)}  {((l1 - l2) * k * k).str(8, radius=False)}      "
              f"{((l2 - l2s) * k * k).str(8, radius=False)}")


def part_c(k0, lo="4.45", hi="4.51", boxes=64, quiet=False):
    """G(lo, h) < 0 < G(hi, h) for every h in [0, 1/k0]: h-boxes as arb balls (untrusted demonstration);
    ``quiet``: return the number of boxes where both signs are certain instead of printing."""
    s_lo, s_hi = arb(lo), arb(hi)
    fails = 0
    for i in range(boxes):
        a, b = fmpq(i, boxes * k0), fmpq(i + 1, boxes * k0)
        h = arb((a + b) / 2, (b - a) / 2)
        gl, gh = big_g(s_lo, h), big_g(s_hi, h)
        if not (gl < 0 and gh > 0):
            fails += 1
            if not quiet:
                print(f"C  box {i}: G(lo) = {gl}, G(hi) = {gh}")
    if quiet:
        return boxes - fails
    print(f"C  sigma in ({lo}, {hi}) for every K >= {k0}: G(lo, h) < 0 < G(hi, h) certain on {boxes - fails}/{boxes} "
          f"h-boxes covering [0, 1/{k0}] (so lam2 = lam(cos(2 sigma/K)) lies strictly between lam(cos 4pi/K) and lam1)")


# --- D. the winding number of 1 - F on |lam| = r ----------------------------------------------------

def _cot(z):
    """cot z, stable for large |Im z|."""
    if z.imag > 0:
        e = cmath.exp(2j * z)
        return 1j * (1 + e) / (e - 1) if abs(e) > 0 else -1j
    e = cmath.exp(-2j * z)
    return -1j * (1 + e) / (e - 1)


def _f_float(lam, k):
    cs = (16 * lam * lam - 10 * lam + 1) / (2 * lam)
    phi = cmath.acos(cs)
    n = 4 * (1 - cs) * (lam - 0.25) - (1 + cs)
    h = 1 / k
    B0 = [[1 - 7 * h / 4, 3 * h / 2, h / 4], [3 / 8, 1 / 2, 1 / 8], [1 / 4, 1 / 2, 1 / 4]]
    M = [[(lam if i == j else 0) - B0[i][j] for j in range(3)] for i in range(3)]
    det = (M[0][0] * (M[1][1] * M[2][2] - M[1][2] * M[2][1]) - M[0][1] * (M[1][0] * M[2][2] - M[1][2] * M[2][0])
           + M[0][2] * (M[1][0] * M[2][1] - M[1][1] * M[2][0]))
    u0 = -(M[0][1] * M[2][2] - M[0][2] * M[2][1]) / det  # Cramer, column (0, 1, 0)
    u2 = -(M[0][0] * M[2][1] - M[0][1] * M[2][0]) / det
    gz = u0 / 8 - u2 / 8
    s = -k * _cot(k * phi / 2) / cmath.sin(phi)
    return ((k - 1) + n / (4 * lam) * (s - 1 / (cs - 1)) + gz) / k


def winding(k, sigma_r=5.4, max_step=0.3):
    """The winding number of 1 - F(lam) along |lam| = r = lam(cos(2 sigma_r/K)), adaptive in the angle."""
    c = math.cos(2 * sigma_r / k)
    r = (5 + c + math.sqrt((1 + c) * (9 + c))) / 16
    total, pts = 0.0, 0

    def val(t):
        return 1 - _f_float(r * cmath.exp(1j * t), k)
    ts = sorted({2 * math.pi * i / 256 for i in range(257)}
                | {t for i in range(1, int(2 * math.log2(k)) + 12) for t in (2 * math.pi * 2.0 ** -i,
                                                                              2 * math.pi * (1 - 2.0 ** -i))})
    vs = [val(t) for t in ts]
    stack = [(ts[i], vs[i], ts[i + 1], vs[i + 1]) for i in range(len(ts) - 1)]
    while stack:
        a, fa, b, fb = stack.pop()
        d = cmath.phase(fb / fa)
        if abs(d) > max_step and b - a > 1e-15:
            m = (a + b) / 2
            fm = val(m)
            stack += [(m, fm, b, fb), (a, fa, m, fm)]
            continue
        total += d
        pts += 1
    return r, total / (2 * math.pi), pts


def part_d(ks):
    for k in ks:
        r, w, pts = winding(k)
        print(f"D  K = {k:<8} r = {r:.12f}: winding number of 1 - F on |lam| = r: {w:+.6f} ({pts} arcs)")
    for k in ks[:2]:  # the same measurement must see lam2 once the circle passes inside it (sigma_r < sigma(K))
        r, w, pts = winding(k, sigma_r=4.0)
        print(f"D  control: K = {k:<5} r = lam(cos(8/K)) = {r:.12f} (between lam2 and lam1): winding {w:+.6f} "
              f"({pts} arcs; expected +1: S_in has no eigenvalue outside but 1, S0 has 1 and lam1)")


# --- D'. Re(1 - F) > 0 on |lam| = r for every K >= K0 at once (arb/acb boxes; untrusted) -------------
#
# 1 - F = h (1 - g0) + n*/(4 lam) (cot(K phi/2)/sin phi + h/(c* - 1)), c* = 8 lam - 5 + 1/(2 lam) = cos phi
# (even in phi), on lam = r e^(it), r = lam(cos(2 sigma_r h)), t in [0, pi] (the lower half by conjugation).
# If Re(1 - F) > 0 on the whole circle, its winding number is 0. Three regions, each analytic in its own
# variables over boxes that include h = 0 (K = infinity):
#   N  t = tau h^2, tau in [0, tau1]: h (1 - F) in (tau, h), sigma = K phi/2 from sigma^2 = D A(h^2 D)/2;
#   I  t in [tau1 h^2, t0]: v = sqrt(t), w = h/v in [0, 1/sqrt(tau1)]: v (1 - F) in (v, w), with
#      cot(K phi/2) = -i + a ball of radius 2 e^(-2T)/(1 - e^(-2T)), T = Im(K phi/2) >= Im(phi/v)/(2w);
#   F  t in [t0, pi]: 1 - F in (t, h), cot as in I with T >= Im(phi) K0/2.

_SIG_R = fmpq(27, 5)  # sigma_r = 5.4: between sigma(K) < 4.51 and 2 pi


def _e1(z):
    """(e^z - 1)/z = e^(z/2) sinc(i z/2) (acb, analytic at 0)."""
    return (z / 2).exp() * (acb(0, 1) * z / 2).sinc()


def _asin_ratio_sq(x, terms=40):
    """A(x) = (asin(s)/s)^2 with s^2 = x/2, by its series in y = x/2 (coefficients <= 1, so the tail is at
    most |y|^terms/(1 - |y|); |y| < 9/10 required)."""
    y = x / 2
    acc, c = acb(0), fmpq(1)
    for n in range(terms):
        acc += c / (2 * n + 1) * y ** n
        c = c * (2 * n + 1) / (2 * n + 2)
    tail = abs(y) ** terms / (1 - abs(y))
    if not abs(y) < fmpq(9, 10):
        raise ValueError("asin series: |x/2| >= 9/10")
    s = acc + acb(arb(0, tail.upper()), arb(0, tail.upper()))
    return s * s


def _det_r(lam):
    q = fmpq(1, 4)
    R = [[fmpq(7, 4), fmpq(-3, 2), -q], [fmpq(-3, 8), lam - _HALF, -_EIGHTH], [-q, -_HALF, lam - q]]
    return (R[0][0] * (R[1][1] * R[2][2] - R[1][2] * R[2][1]) - R[0][1] * (R[1][0] * R[2][2] - R[1][2] * R[2][0])
            + R[0][2] * (R[1][0] * R[2][1] - R[1][1] * R[2][0]))


def _g0_num(lam, h):
    """u0 det - u2 det (Cramer numerators of the mode-0 resolvent column, g0 = (that)/(8 det))."""
    q = fmpq(1, 4)
    m00, m01, m02, m20, m21, m22 = lam - 1 + 7 * h / 4, -3 * h / 2, -h / 4, -q, -_HALF, lam - q
    return -(m01 * m22 - m02 * m21) + (m00 * m21 - m01 * m20)


def _cot_far(T):
    """cot z for Im z >= T > 0: -i plus a ball."""
    e = (-2 * T).exp()
    rad = (2 * e / (1 - e)).upper()
    return acb(arb(0, rad), arb(-1, rad))


def _ball(lo, hi):
    lo, hi = fmpq(lo), fmpq(hi)
    return arb((lo + hi) / 2, (hi - lo) / 2)


def region_n(tau, h):
    """Re of h (1 - F) on the box (tau, h) (arb balls)."""
    r = lam_of((2 * _SIG_R * h).cos())
    e = acb(0, 1) * tau * h * h
    lam = r * e.exp()
    D = (2 * _SIG_R ** 2 * (_SIG_R * h).sinc() ** 2 - 8 * r * acb(0, 1) * tau * _e1(e)
         + acb(0, 1) * tau * _e1(-e) / (2 * r))
    sig = (D * _asin_ratio_sq(h * h * D) / 2).sqrt()
    n = 4 * h * h * D * (lam - fmpq(1, 4)) - (2 - h * h * D)
    h2g0 = h * _g0_num(lam, h) / (8 * (-(lam - 1) * lam * h * D / 8 + _det_r(lam)))
    val = h * h - h2g0 + n / (4 * lam) * (sig.cot() / (2 * sig * (2 * sig * h).sinc()) - 1 / D)
    return val.real


def region_i(v, w):
    """Re of v (1 - F) on the box (v, w) (arb balls, v, w >= 0)."""
    h = v * w
    r = lam_of((2 * _SIG_R * h).cos())
    e = acb(0, 1) * v * v
    lam = r * e.exp()
    D = (2 * _SIG_R ** 2 * w * w * (_SIG_R * h).sinc() ** 2 - 8 * r * acb(0, 1) * _e1(e)
         + acb(0, 1) * _e1(-e) / (2 * r))
    psi = (2 * D * _asin_ratio_sq(v * v * D)).sqrt()
    if not psi.imag > 0:
        psi = -psi
    if not psi.imag > 0:
        return arb(0, 1)  # undecided
    T = psi.imag.lower() / (2 * arb(w.upper()))
    cot = _cot_far(T) if w.upper() > 0 else acb(0, -1)
    n = 4 * v * v * D * (lam - fmpq(1, 4)) - (2 - v * v * D)
    # v h g0 = v w num/(8 (a v + b w)), a = -(lam - 1) lam D/8, b = det R; bound it where v, w touch 0
    a, b, num = -(lam - 1) * lam * D / 8, _det_r(lam), _g0_num(lam, h)
    if v.lower() > 0 or w.lower() > 0:
        vhg0 = v * w * num / (8 * (a * v + b * w))
    else:  # |a v + b w| >= max(al v - be w, ga w - de v) >= m (v + ...) : |v w/(a v + b w)| <= v_hi/m
        al, be, ga, de = abs(a.imag).lower(), abs(b.imag).upper(), abs(b.real).lower(), abs(a.real).upper()
        m = (al * ga - be * de) / (al + de)
        if not m > 0:
            return arb(0, 1)
        bound = (arb(v.upper()) / m * abs(num) / 8).upper()
        vhg0 = acb(arb(0, bound), arb(0, bound))
    val = v * h - vhg0 + n / (4 * lam) * (cot / (psi * (v * psi).sinc()) - w / D)
    return val.real


def region_f(t, h, k0):
    """Re of 1 - F on the box (t, h), h in [0, 1/k0]."""
    r = lam_of((2 * _SIG_R * h).cos())
    lam = r * (acb(0, 1) * t).exp()
    cs = 8 * lam - 5 + 1 / (2 * lam)
    # any root of cos phi = c* will do (the expression is even and 2 pi-periodic in phi for integer K);
    # off the real axis phi = i acosh(c*) (acosh's cut is the real (-inf, 1]); near lam = -r, c* is close
    # to the real (-inf, -1]: phi = pi + i acosh(-c*) there
    if cs.imag > 0 or cs.imag < 0:
        phi = acb(0, 1) * cs.acosh()
    else:
        phi = acb.pi() + acb(0, 1) * (-cs).acosh() if cs.real < -1 else cs.acos()
    if not phi.imag > 0:
        phi = -phi
    if not phi.imag > 0:
        return arb(0, 1)
    cot = _cot_far(phi.imag.lower() * k0 / 2)
    n = 4 * (1 - cs) * (lam - fmpq(1, 4)) - (1 + cs)
    val = h * (1 - g0(lam, h)) + n / (4 * lam) * (cot / phi.sin() + h / (cs - 1))
    return val.real


def _cover(fn, xs, ys, depth=8):
    """Bisect the boxes [x0, x1] x [y0, y1] (fmpq ends) until fn is certainly > 0 on each; returns
    (boxes, least lower bound) or raises with the first box that fails at the depth limit."""
    stack = [(x0, x1, y0, y1, 0) for x0, x1 in zip(xs, xs[1:]) for y0, y1 in zip(ys, ys[1:])]
    count, worst = 0, None
    while stack:
        x0, x1, y0, y1, d = stack.pop()
        val = fn(_ball(x0, x1), _ball(y0, y1))
        if val > 0:
            count += 1
            worst = val.lower() if worst is None or val.lower() < worst else worst
            continue
        if d >= depth:
            raise ValueError(f"box [{x0}, {x1}] x [{y0}, {y1}] undecided: {val}")
        xm, ym = (x0 + x1) / 2, (y0 + y1) / 2
        if d % 2 == 0:
            stack += [(x0, xm, y0, y1, d + 1), (xm, x1, y0, y1, d + 1)]
        else:
            stack += [(x0, x1, y0, ym, d + 1), (x0, x1, ym, y1, d + 1)]
    return count, worst


def part_d_uniform(k0=101, tau1=50, v0=None, nx=40, ny=4):
    """Print D' (raises ValueError where a box stays undecided). Regions: N for t <= tau1 h^2, I for
    tau1 h^2 <= t <= v0^2 (v0 = 2/5 by default), F for t >= v0^2."""
    v0 = fmpq(2, 5) if v0 is None else v0
    h0 = fmpq(1, k0)
    w1 = fmpq(math.ceil(10 ** 4 / math.sqrt(tau1)) + 1, 10 ** 4)  # w <= w1 covers every t >= tau1 h^2
    assert w1 * w1 * tau1 >= 1
    t_pi = fmpq(355, 113)  # > pi; boxes beyond pi are harmless (the circle continues)
    grid = (lambda a, b, n: [a + (b - a) * fmpq(i, n) for i in range(n + 1)])
    res = {}
    res["N"] = _cover(region_n, grid(fmpq(0), fmpq(tau1), nx), grid(fmpq(0), h0, ny))
    res["I"] = _cover(region_i, grid(fmpq(0), v0, nx), grid(fmpq(0), w1, ny))
    res["F"] = _cover(lambda t, h: region_f(t, h, k0), grid(v0 * v0, t_pi, nx), grid(fmpq(0), h0, ny))
    for name, (count, worst) in res.items():
        print(f"D' region {name}: Re > 0 certain on {count} boxes, least lower bound {worst}")
    # S0's even eigenvalues outside the circle: 1 and lam(cos(2 pi/K)) only. Modes j >= 2 give lam(cos(2 pi j/K))
    # <= lam(cos(4 pi/K)) < r (sigma_r < 2 pi) and 1/(16 lam) <= 1/4; mode 0's block has det(x - B0) =
    # (x - 1) Q(x), Q(x) = x^2 - 3x/4 + 1/16 + h l(x) (det R = (x - 1) l(x)); both roots of Q lie below r when
    # Q(r) > 0 and Q'(r) > 0, and Q(r)/h = l(r) - (r/4) sigma_r^2 h sinc(sigma_r h)^2 on r = lam(cos(2 sigma_r h))
    if not _det_r(fmpq(1)) == 0:
        raise ValueError("det R does not vanish at 1")

    def ell(z):  # det R is quadratic in x with the root 1: l = det R/(x - 1) is linear
        return _det_r(z) / (z - 1)
    ok = 0
    for i in range(ny * 4):
        h = _ball(h0 * i / (ny * 4), h0 * (i + 1) / (ny * 4))
        r = lam_of((2 * _SIG_R * h).cos())
        q_over_h = ell(r) - r / 4 * _SIG_R ** 2 * h * (_SIG_R * h).sinc() ** 2
        dq = 2 * r - fmpq(3, 4) + h * (ell(r + 1) - ell(r))  # l is linear: l' = l(r + 1) - l(r)
        ok += bool(q_over_h > 0 and dq > 0)
    print(f"D' mode 0: both roots of Q below r on {ok}/{ny * 4} h-boxes (so S0 has exactly 1 and lam(cos(2 pi/K)) "
          "outside the circle among its even eigenvalues)")
    print(f"D' so Re(1 - F) > 0 on |lam| = lam(cos(2 x 5.4/K)) for every K >= {k0}: the winding number is 0, and "
          "S_in has no eigenvalue outside that circle but 1 and lam2")


# --- E. the characteristic map at large K -----------------------------------------------------------

def part_e(ks):
    import numpy as np
    import scipy.sparse as sp
    import scipy.sparse.linalg as spl

    from ccproof.certify.verify.maps import STAR_CURVES, regularity_form
    from ccproof.certify.verify.tagged import labels, sector_rows
    from ccproof.certify.verify.tagged_map import PIECES, quadrant_nets, transversal_form
    from ccproof.rigorous import range_enclosure

    for k in ks:
        h = arb(fmpq(1, k))
        s = sigma_of(h)
        l1, l2 = lam_of((2 * arb.pi() * h).cos()), lam_of((2 * s * h).cos())
        pts, rows = labels("dart", k), sector_rows("dart", k)
        m = len(pts)
        ij = ([i for i, row in enumerate(rows) for _ in row], [j for row in rows for j in row])
        S = sp.csr_matrix(([float(w) for row in rows for w in row.values()], ij), shape=(m, m))
        vecs = []
        for lam, parity in ((float(l1.mid()), -1), (float(l2.mid()), 1)):
            # inverse iteration from a vector of the right parity under the reflection in ray 0
            v = np.array([math.sin(2 * math.pi * p[1] / k) if parity < 0 and p[0] != "C" else 1.0 for p in pts])
            lu = spl.splu((S - (lam + 1e-12) * sp.identity(m)).tocsc())
            for _ in range(6):
                v = lu.solve(v)
                v /= np.abs(v).max()
            res = np.abs(S @ v - lam * v).max()
            # x = 1 at ray K/4's (1,0) (sin theta = 1 there), y = 1 at ray K/2's (1,0) (theta = pi)
            v /= v[pts.index(("r", round(k / (4 if parity < 0 else 2)), 1, 0))]
            vecs.append(v)
        sig = float(s.mid())
        prof = [(f, vecs[1][pts.index(("r", round(f * k), 1, 0))],
                 (math.cos(sig * (1 - 2 * round(f * k) / k)) / math.cos(sig) - 1) / (1 / math.cos(sig) - 1))
                for f in (0.0, 0.05, 0.1, 0.25, 0.4)]
        print(f"E  K = {k:<4} y at ray r's (1,0) against the limit profile (cos(sigma (1 - theta/pi))/cos sigma - 1), "
              "scaled to 1 at theta = pi: " + "; ".join(f"theta/2pi {f:.2f}: {a:.5f} vs {b:.5f}" for f, a, b in prof))
        x, y = ([arb(float(z)) for z in v] for v in vecs)
        a1, a2 = -l1.log(), -l2.log()
        with ctx.workprec(64):
            nets = [quadrant_nets("dart", k, x, y, q, 64) for q in range(k)]
            reg = [(min(range_enclosure(regularity_form(nets[q], p, 64))[0] for p in PIECES), q) for q in range(k)]
            sign = 1 if max(reg)[0] > 0 else -1
            reg = [(v * sign, q) for v, q in reg]
            tra = [(min(range_enclosure(transversal_form(nets[q], c, a1, a2, 64))[0] for c in STAR_CURVES) * sign, q)
                   for q in range(k)]
        near = {0, 1, 2, k - 1, k - 2, k - 3}
        for title, vals in (("det J_Phi", reg), ("transversality", tra)):
            inner = min((v, q) for v, q in vals if q not in near)
            edge = {q: v for v, q in vals if q in near}
            prof = " ".join(f"{f:.2f}:{float((vals[round(f * k)][0] * k).mid()):.5f}" for f in (0.1, 0.25, 0.4, 0.5))
            print(f"E  K = {k:<4} {title:<14} K*min over quadrants 3..K-4: {float((inner[0] * k).mid()):.6f} "
                  f"(theta/2pi = {inner[1] / k:.3f}); K^3*min at quadrants 0, 1, 2: "
                  + " ".join(f"{float((edge[q] * k ** 3).mid()):.4f}" for q in (0, 1, 2))
                  + f"; K*min at theta/2pi {prof}; not positive: {sum(1 for v, _ in vals if not v > 0)}")
        print(f"E  K = {k:<4} |S v - lam v| <= {res:.1e}, orientation {sign:+d}")


def closed_form_vectors(k):
    """x and y of dart:k in closed form (floats), with |S y - lam2 y|.

    x is the odd mode-1 vector f = v - v o R (:func:`.tagged_modes.mode_vector`). y is, on every point
    but the centre, y_C u(p) + Re(beta (v^(p) e^(i phi (t - K/2)) + v^(p') e^(i phi (t' - K/2)))): u = (lam2 -
    B(1))^-1 kappa (kappa the centre's weights in the ring rows), v^ the eigenvector of lam2 in the 6 x 6
    block B(e^(i phi)), (t', p') the mirror image of (t, p) in ray K/2 (ray K - t; quadrant K - 1 - t with
    (a, b) swapped), phi = 2 sigma/K. The three real unknowns (y_C, Re beta, Im beta) are the null vector
    of S - lam2 on these three columns; the residual says whether the form is exact.
    """
    import numpy as np
    import scipy.sparse as sp

    from ccproof.certify.verify.tagged import labels, sector_rows
    from ccproof.certify.verify.tagged_modes import RING_INDEX, mode_vector, ring_block, ring_stencil

    def cv(z):
        return complex(float(z.real.mid()), float(z.imag.mid())) if isinstance(z, acb) else complex(float(z))

    h = arb(fmpq(1, k))
    s = sigma_of(h)
    l1, l2 = lam_of((2 * arb.pi() * h).cos()), lam_of((2 * s * h).cos())
    lam, phi = float(l2.mid()), float((2 * s * h).mid())
    pts, rows = labels("dart", k), sector_rows("dart", k)
    m = len(pts)
    kappa = np.array([1 - sum(float(w) for w in ring_stencil()[i].values()) for i in range(6)])
    u = np.linalg.solve(lam * np.eye(6) - np.array([[cv(z).real for z in r] for r in ring_block(fmpq(1))]), kappa)
    Bw = np.array([[cv(z) for z in r] for r in ring_block(acb(math.cos(phi), math.sin(phi)))])
    ev, V = np.linalg.eig(Bw)
    vh = V[:, int(np.argmin(abs(ev - lam)))]
    cols = np.zeros((m, 3))
    cols[0, 0] = 1
    for i, p in enumerate(pts[1:], 1):
        t, pos = p[1], p[2:]
        tm, pm = (k - t if t else k, pos) if pos[1] == 0 else (k - 1 - t, (pos[1], pos[0]))
        a = (vh[RING_INDEX[pos]] * cmath.exp(1j * phi * (t - k / 2))
             + vh[RING_INDEX[pm]] * cmath.exp(1j * phi * (tm - k / 2)))
        cols[i] = (u[RING_INDEX[pos]], a.real, a.imag)
    ij = ([i for i, row in enumerate(rows) for _ in row], [j for row in rows for j in row])
    S = sp.csr_matrix(([float(w) for row in rows for w in row.values()], ij), shape=(m, m))
    R = S @ cols - lam * cols
    _, sv, vt = np.linalg.svd(R, full_matrices=False)
    y = cols @ vt[-1]
    y /= y[pts.index(("r", round(k / 2), 1, 0))]
    res = float(np.abs(S @ y - lam * y).max())
    f = mode_vector("dart", k, 1, l1)
    piv = f[pts.index(("r", round(k / 4), 1, 0))]
    x = [0.0 if isinstance(z, fmpq) else float((z / piv).real.mid()) for z in f]
    return x, [float(z) for z in y], l1, l2, res


def part_f(ks, bulk=(0.01, 0.02, 0.05, 0.1, 0.25, 0.5), layer=6):
    """The three regimes of det J_Phi at large K from the closed forms: the quadrants q < ``layer`` next to
    the sharp ray (K^3 min), the bulk at theta/2pi in ``bulk`` (K min and K min/theta^2)."""
    from ccproof.certify.verify.maps import regularity_form
    from ccproof.certify.verify.tagged_map import PIECES, quadrant_nets
    from ccproof.rigorous import range_enclosure

    for k in ks:
        x, y, l1, l2, res = closed_form_vectors(k)
        xs, ys = [arb(z) for z in x], [arb(z) for z in y]
        with ctx.workprec(64):
            def low(q, k=k, xs=xs, ys=ys):
                nets = quadrant_nets("dart", k, xs, ys, q, 64)
                return float(min(range_enclosure(regularity_form(nets, p, 64))[0] for p in PIECES).mid())
            near = [low(q) * k ** 3 for q in range(layer)]
            far = [(f, low(round(f * k)) * k, round(f * k) / k) for f in bulk]
        print(f"F  K = {k:<6} closed-form y: |S y - lam2 y| <= {res:.1e}; det J_Phi: K^3 min at quadrants "
              f"0..{layer - 1}: "
              + " ".join(f"{v:.3f}" for v in near) + "; K^3 min/(2 pi q)^2 (q >= 1): "
              + " ".join(f"{v / (2 * math.pi * q) ** 2:.4f}" for q, v in enumerate(near) if q)
              + "; bulk K min at theta/2pi (K min/theta^2): "
              + " ".join(f"{f}: {v:.4f} ({v / (2 * math.pi * g) ** 2:.4f})" for f, v, g in far))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--k0", type=int, default=101)
    ap.add_argument("--skip-map", action="store_true")
    args = ap.parse_args(argv)
    ctx.prec = 128
    part_a()
    part_b([101, 200, 1000, 10 ** 4, 10 ** 6, None])
    part_c(args.k0)
    part_d([101, 1000, 10 ** 4, 10 ** 6])
    part_d_uniform(args.k0)
    if not args.skip_map:
        part_e([101, 202, 404, 808])
        part_f([1000, 4000, 16000], bulk=(0.002, 0.005, 0.01, 0.02, 0.05, 0.1, 0.25, 0.5), layer=8)


if __name__ == "__main__":
    main()
