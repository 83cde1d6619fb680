"""Per-valence float64 data of the forward and inverse characteristic map (internal).

The one place where the float nets come from: :func:`float_nets` (the certified table of
:mod:`ccproof.tables` when it exists, otherwise the exact nets rounded once). Everything else in
this module is derived from those nets and from the exact implicit polynomials of
:mod:`ccproof.inverse.implicit`, once per valence (cached).

Conventions used by the kernels: by the symmetry Phi(v, u) = swap(Phi(u, v)) only points with
u >= v (face side) and x >= y (image side) are ever evaluated; those lie in P1 (patch index 0)
or P2 (index 1) of some layer. A point of the quadrant is written t = lam^n t0 with t0 in the
layer-0 image, and its preimage y = 2^-n y0 with y0 in layer 0 = [0,1]^2 minus [0,1/2)^2.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from math import comb

import numpy as np

from ccproof.errors import check_valence

#: powers lam^n are tabulated for |n| <= NMAX (as mantissa and binary exponent)
NMAX = 2200
#: total degree of the polynomial first guess of the inverse of P1 and P2
FIT_DEGREE = 5

# Bezier -> power basis: power[m] = sum_i BEZ2POW[i, m] * bezier[i]
BEZ2POW = np.array([[comb(3, i) * comb(3 - i, m - i) * (-1) ** (m - i) if m >= i else 0
                     for m in range(4)] for i in range(4)], dtype=float)


def float_nets(k):
    """(lam, Bezier nets (3, 4, 4, 2)) in float64 for valence k: the single source of the float
    data of this package (certified table when it exists, see :func:`ccproof.tables.numeric.
    characteristic_nets`)."""
    from ccproof.tables.numeric import characteristic_nets

    t = characteristic_nets(k)
    return float(t.lam), np.asarray(t.bezier, dtype=float)


def monomial_exponents(degree):
    """Exponents (a, b) of the monomials x^a y^b of total degree <= degree, in the order in which
    :func:`monomials` builds them (each from an earlier one by one multiplication)."""
    out = [(0, 0)]
    for d in range(1, degree + 1):
        out += [(d - b, b) for b in range(d + 1)]
    return out


def monomials(x, y, degree, out=None):
    """Rows x^a y^b (order of :func:`monomial_exponents`) as a (M, n) array."""
    exps = monomial_exponents(degree)
    n = x.shape[0]
    m = out if out is not None else np.empty((len(exps), n))
    m[0] = 1.0
    index = {(0, 0): 0}
    for r, (a, b) in enumerate(exps[1:], start=1):
        if a > 0:
            np.multiply(m[index[(a - 1, b)]], x, out=m[r])
        else:
            np.multiply(m[index[(a, b - 1)]], y, out=m[r])
        index[(a, b)] = r
    return m


@dataclass
class ValenceData:
    """Everything the float kernels need for one valence (see module docstring)."""

    k: int
    lam: float
    bezier: np.ndarray          # (3, 4, 4, 2) Bezier nets of P1, P2, P3
    power: np.ndarray           # (2, 2, 4, 4): [patch P1/P2, comp x/y, s power, t power]
    W: np.ndarray               # (2, 22, 4): rows of t-coefficients of q_i(t) (x: 0-3, y: 4-7),
                                # q_i'(t) (x: 8-11, y: 12-15), i q_i(t) (x: 16-18, y: 19-21)
    C6: np.ndarray              # (2, 6, 16): x, y, x_s, x_t, y_s, y_t on the monomials s^i t^j (4i+j)
    pow_mant: np.ndarray        # lam^n = pow_mant[n + NMAX] * 2**pow_exp[n + NMAX] (any n, exact range)
    pow_exp: np.ndarray
    pow_lam: np.ndarray         # lam^n as a double (0 / inf where out of range): the fast path
    pow_2lam: np.ndarray        # (2 lam)^n as a double (Jacobians)
    pow2: np.ndarray            # 2^n as a double
    inv_log_lam: float          # 1 / log(lam)
    log_a: float                # log(A): first guess puts max(t0) in (lam A, A]
    G: np.ndarray               # (5, 10) location rows on the cubic monomials of t0: g_Gamma(t0),
                                # g_Gamma(lam t0), g_C(t0 / lam), g_C(t0), g_C(lam t0)
    fit: np.ndarray             # (2, 2, M): first guess of (s, t) of P1 / P2, monomials of degree FIT_DEGREE (5)
    gamma_sign: int
    sep_sign: int


def _arb_pow_table(lam_arb):
    """lam^n = mant * 2^expo for |n| <= NMAX, mant in [1/2, 1) the correctly rounded double of
    the midpoint of an 80-bit ball (so no over- or underflow whatever n)."""
    from flint import arb, ctx

    mant = np.empty(2 * NMAX + 1)
    expo = np.empty(2 * NMAX + 1, dtype=np.int64)
    with ctx.workprec(96):
        lam = +lam_arb
        inv = 1 / lam
        for base, sign in ((lam, 1), (inv, -1)):
            p = arb(1)
            for n in range(NMAX + 1):
                man, e = p.mid().man_exp()
                man, e = int(man), int(e)
                L = man.bit_length()
                mant[sign * n + NMAX] = float(man) / 2.0**L if L <= 1000 else float(man >> (L - 60)) / 2.0**60
                expo[sign * n + NMAX] = e + L
                p = p * base
    return mant, expo


def _eval_power(C, s, t):
    S = np.stack([np.ones_like(s), s, s * s, s**3])
    T = np.stack([np.ones_like(t), t, t * t, t**3])
    return np.einsum("cmn,mp,np->cp", C, S, T)


@lru_cache(maxsize=64)
def valence_data(k):
    """The cached :class:`ValenceData` of valence k."""
    from ccproof.algebra.specialize import subdominant_eigenvalue
    from ccproof.inverse.implicit import implicit_polynomial, inside_sign

    k = check_valence(k)
    lam, bez = float_nets(k)
    power = np.einsum("im,jn,pijc->pcmn", BEZ2POW, BEZ2POW, bez[:2])
    W = np.zeros((2, 22, 4))
    for p in range(2):
        for c in range(2):
            for i in range(4):
                for j in range(4):
                    W[p, 4 * c + i, j] = power[p, c, i, j]
                    if j >= 1:
                        W[p, 8 + 4 * c + i, j - 1] = j * power[p, c, i, j]
                    if i >= 1:
                        W[p, 16 + 3 * c + i - 1, j] = i * power[p, c, i, j]
    C6 = np.zeros((2, 6, 16))
    for p in range(2):
        for i in range(4):
            for j in range(4):
                for c in range(2):
                    C6[p, c, 4 * i + j] = power[p, c, i, j]
                    if i < 3:
                        C6[p, 2 + 2 * c, 4 * i + j] = (i + 1) * power[p, c, i + 1, j]
                    if j < 3:
                        C6[p, 3 + 2 * c, 4 * i + j] = (j + 1) * power[p, c, i, j + 1]
    mant, expo = _arb_pow_table(subdominant_eigenvalue(k, "arb", 128))

    # location: Gamma = image of u = 1/2, 0 <= v <= 1/2 (edge s = 0 of P1), the inner boundary of
    # layer 0 on the side x >= y; Gamma / lam is its outer boundary. Separator C = edge t = 1 of P1.
    gam = implicit_polynomial(k, "P1:s=0", "float")
    sep = implicit_polynomial(k, "P1:t=1", "float")
    exps3 = monomial_exponents(3)
    col3 = {e: i for i, e in enumerate(exps3)}

    def row(poly, scale):
        r = np.zeros(len(exps3))
        for (a, b), x in poly.items():
            r[col3[(a, b)]] = x * scale ** (a + b)
        return r

    G = np.array([row(gam, 1.0), row(gam, lam), row(sep, 1 / lam), row(sep, 1.0), row(sep, lam)])

    # first guess: least-squares polynomial of total degree FIT_DEGREE in (x, y) for the local
    # (s, t) of P1 and of P2 (the part s >= t), fitted on a slightly enlarged domain.
    g = np.linspace(-0.03, 1.03, 90)
    ss, tt = (a.ravel() for a in np.meshgrid(g, g))
    fits = []
    for p in range(2):
        s, t = (ss, tt) if p == 0 else (ss[ss >= tt - 0.03], tt[ss >= tt - 0.03])
        xy = _eval_power(power[p], s, t)
        V = monomials(xy[0], xy[1], FIT_DEGREE).T
        coef, *_ = np.linalg.lstsq(V, np.stack([s, t], 1), rcond=None)
        fits.append(coef.T)  # (2, M)
    fit = np.array(fits)

    # first-guess normalization: the layer-0 image has max-norm in [xmin, xmax / lam] where
    # x ranges over Gamma; A = geometric middle of [xmax, xmin / lam^2]
    w = np.linspace(0, 1, 401)
    B = np.array([comb(3, j) * w**j * (1 - w) ** (3 - j) for j in range(4)])
    gx = B.T @ bez[0, 0, :, 0]
    xmin, xmax = gx.min(), gx.max()
    log_a = 0.5 * (np.log(xmax) + np.log(xmin) - 2 * np.log(lam))
    lam_arb = subdominant_eigenvalue(k, "arb", 128)
    m2, e2 = _arb_pow_table(2 * lam_arb)
    with np.errstate(over="ignore", under="ignore"):
        pow_lam = np.ldexp(mant, expo)
        pow_2lam = np.ldexp(m2, e2)
        pow2 = np.ldexp(1.0, np.arange(-NMAX, NMAX + 1))
    return ValenceData(k, lam, bez, power, W, C6, mant, expo, pow_lam, pow_2lam, pow2, 1.0 / np.log(lam),
                       float(log_a), G, fit, inside_sign(k, "P1:s=0"), inside_sign(k, "P1:t=1"))


#: points per block in the vectorized kernels (keeps the temporaries in cache)
CHUNK = 16384
#: OpenBLAS runs a product m x k times k x n single-threaded when m n k <= 4 * 65536; above that it
#: starts threads, which for these tiny products only costs time (and a lot on a loaded machine)
_GEMM_SINGLE = 4 * 65536


def matmul(A, B):
    """A @ B for a small A (m x k) and a wide B (k x n), in column blocks small enough for OpenBLAS
    to stay single-threaded."""
    m, k = A.shape
    n = B.shape[1]
    step = max(256, _GEMM_SINGLE // max(1, m * k))
    if n <= step:
        return A @ B
    out = np.empty((m, n))
    for i in range(0, n, step):
        np.matmul(A, B[:, i:i + step], out=out[:, i:i + step])
    return out
#: blocks whose points all have max(u, v) in [SAFE_LO, SAFE_HI] scale with the double tables
#: (plain products); others with mantissa/exponent tables and ldexp (exact range, 30x slower)
SAFE_LO = 2.0**-900
SAFE_HI = 2.0**900

_LN2 = float(np.log(2.0))
#: quadratic approximation of log(m) on [1/2, 1) (error < 1e-2), used by :func:`approx_log`
_LOG_Q = np.polyfit(np.linspace(0.5, 1.0, 200), np.log(np.linspace(0.5, 1.0, 200)), 2)


def approx_log(a):
    """log(a) to within 1e-2 (a > 0): frexp plus a quadratic; 3x cheaper than np.log."""
    m, e = np.frexp(a)
    c2, c1, c0 = _LOG_Q
    return (c2 * m + c1) * m + (c0 + _LN2 * e)


def patch_eval(Wp, s, t, jacobian=False):
    """P(s, t) of one piece (``Wp`` = ``ValenceData.W[p]``) at arrays s, t (local coordinates).

    Returns (x, y) or (x, y, x_s, x_t, y_s, y_t). The t-polynomials q_i(t) of both components
    (and their t- and s-derivative coefficients) come out of one small matrix product, then
    Horner in s.
    """
    n = s.shape[0]
    T = np.empty((4, n))
    T[0] = 1.0
    T[1] = t
    np.multiply(t, t, out=T[2])
    np.multiply(T[2], t, out=T[3])
    if not jacobian:
        Q = matmul(Wp[:8], T)
        return _horner3(Q, 0, s), _horner3(Q, 4, s)
    Q = matmul(Wp, T)
    return (_horner3(Q, 0, s), _horner3(Q, 4, s), _horner2(Q, 16, s), _horner3(Q, 8, s),
            _horner2(Q, 19, s), _horner3(Q, 12, s))


def patch_eval_jac(Cp, s, t):
    """(x, y, x_s, x_t, y_s, y_t) of one piece (``Cp`` = ``ValenceData.C6[p]``): all six are
    combinations of the 16 monomials s^i t^j (i, j <= 3), so one product (6 x 16) @ (16 x n) after
    12 multiplications; about 25% cheaper than :func:`patch_eval` with ``jacobian=True``."""
    n = s.shape[0]
    M = np.empty((16, n))
    M[0] = 1.0
    M[1] = t
    np.multiply(t, t, out=M[2])
    np.multiply(M[2], t, out=M[3])
    M[4] = s
    np.multiply(s, s, out=M[8])
    np.multiply(M[8], s, out=M[12])
    for i in (4, 8, 12):
        np.multiply(M[1:4], M[i], out=M[i + 1:i + 4])
    return matmul(Cp, M)


def _horner3(Q, i, s):
    acc = Q[i + 3] * s
    acc += Q[i + 2]
    acc *= s
    acc += Q[i + 1]
    acc *= s
    acc += Q[i]
    return acc


def _horner2(Q, i, s):
    acc = Q[i + 2] * s
    acc += Q[i + 1]
    acc *= s
    acc += Q[i]
    return acc


def chunks(n, size=CHUNK):
    """Slices covering range(n) in blocks of ``size``."""
    for i in range(0, n, size):
        yield slice(i, min(i + size, n))


def as_points(u, v, what="point"):
    """Broadcast two coordinate arrays to flat float64 arrays; reject NaN, inf and negatives.

    Returns (u, v, shape). Raises :class:`~ccproof.errors.CCProofError`.
    """
    from ccproof.errors import CCProofError

    try:
        u = np.asarray(u, dtype=np.float64)
        v = np.asarray(v, dtype=np.float64)
        u, v = np.broadcast_arrays(u, v)
    except (TypeError, ValueError) as exc:
        raise CCProofError(f"{what} coordinates must be real numbers or arrays of them: {exc}") from None
    shape = u.shape
    u = np.ascontiguousarray(u).ravel()
    v = np.ascontiguousarray(v).ravel()
    for name, a in (("first", u), ("second", v)):
        bad = ~np.isfinite(a)
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            raise CCProofError(f"{what} {name} coordinate is not finite (NaN or inf) at index {i}: {float(a[i])!r}")
        neg = a < 0
        if neg.any():
            i = int(np.flatnonzero(neg)[0])
            raise CCProofError(
                f"{what} {name} coordinate is negative at index {i}: {float(a[i])!r}; the characteristic map "
                "and its inverse are defined on the quadrant [0, inf)^2")
    return u, v, shape
