"""Per-valence data of the forward and inverse characteristic map, derived from the certified tables.

:func:`valence_data` is the one place where the float data of :mod:`ccproof.inverse` and
:mod:`ccproof.reparam` comes from. Everything is derived once per valence (cached in memory, a few
tens of milliseconds, ``scripts/bench_reparam.py``) from the balls of
:func:`ccproof.tables.numeric.characteristic_arb` (the certified table of k, or for a valence
without one the exact nets the tables hold, evaluated in arb):

* the float Bezier nets (:func:`_float_nets`) and their power-basis coefficients;
* the tables of lam^n (from the ball of lam);
* the implicit equations of the boundaries Gamma (``P1:s=0``) and C (``P1:t=1``) used to locate
  a point: the Sylvester determinant of Definition 5 (bmz04), evaluated in arb at the 10 points of
  a unisolvent lattice and interpolated exactly (:func:`implicit_boundary`), with the side of the
  piece decided in arb (:func:`inside_sign`). :mod:`ccproof.inverse.implicit` computes the same
  polynomials symbolically; it is the independent cross-check in the tests, never used here.

No symbolic computation and no sympy happen here (tests/inverse/test_data.py runs an evaluation in
a fresh interpreter and checks that sympy is never imported).

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


def _float_nets(k):
    """(lam, Bezier nets (3, 4, 4, 2)) in float64 for valence k: the single source of the float
    nets of :mod:`ccproof.inverse` (certified table when it exists, see
    :func:`ccproof.tables.numeric.characteristic_nets`).

    >>> lam, bez = _float_nets(4)
    >>> lam, bez.shape
    (0.5, (3, 4, 4, 2))
    """
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
    """Rows x^a y^b (order of :func:`monomial_exponents`: by total degree, then by the power of y).

    The basis of the fitted first guess of bmz04 Algorithm 1 (docs/inverse.md).

    Parameters
    ----------
    x, y : ndarray, shape (n,) float64
    degree : int
        Total degree.
    out : ndarray, shape (M, n), optional
        Filled in place, M = (degree + 1)(degree + 2)/2.

    Returns
    -------
    ndarray, shape (M, n) float64

    Examples
    --------
    >>> import numpy as np
    >>> monomials(np.array([2.0]), np.array([3.0]), 2).ravel().tolist()    # 1, x, y, x^2, xy, y^2
    [1.0, 2.0, 3.0, 4.0, 6.0, 9.0]
    """
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
    """Everything the float kernels need for one valence (see module docstring), made by :func:`valence_data`.

    bmz04 Algorithm 1 (docs/readings.md R11; docs/inverse.md). Fields (shapes float64 unless noted):

    Attributes
    ----------
    k : int
    lam : float
    bezier : ndarray, shape (3, 4, 4, 2)
        Bezier nets of P1, P2, P3.
    power : ndarray, shape (2, 2, 4, 4)
        ``[patch P1/P2, component x/y, s power, t power]``.
    W : ndarray, shape (2, 22, 4)
        Rows of t-coefficients of q_i(t) (x: 0-3, y: 4-7), q_i'(t) (x: 8-11, y: 12-15),
        i q_i(t) (x: 16-18, y: 19-21).
    C6 : ndarray, shape (2, 6, 16)
        x, y, x_s, x_t, y_s, y_t on the monomials s^i t^j (index 4i + j).
    pow_mant, pow_exp : ndarray
        lam^n = pow_mant[n + NMAX] * 2**pow_exp[n + NMAX] (any n, exact range).
    pow_lam, pow_2lam, pow2 : ndarray
        lam^n, (2 lam)^n and 2^n as doubles (0 / inf where out of range).
    inv_log_lam, log_a : float
        1 / log(lam); log(A) (the first guess puts max(t0) in (lam A, A]).
    G : ndarray, shape (5, 10)
        Location rows on the cubic monomials of t0: g_Gamma(t0), g_Gamma(lam t0), g_C(t0 / lam),
        g_C(t0), g_C(lam t0).
    fit : ndarray, shape (2, 2, M)
        First guess of (s, t) of P1 / P2 on the monomials of degree ``FIT_DEGREE``.
    gamma_sign, sep_sign : int

    Examples
    --------
    >>> D = valence_data(4)
    >>> D.lam, D.C6.shape, D.bezier[1, 3, 3].tolist()        # k = 4: Phi is the identity
    (0.5, (2, 6, 16), [1.0, 1.0])
    """

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


def _lstsq_tall(V, B, block=512):
    """Least-squares solution X (n, r) of V X ~ B for a tall V (m, n), m >> n: corrected semi-normal
    equations (Gram matrix, then one step of refinement on the residual; Bjorck, *Numerical Methods
    for Least Squares Problems*, 1996, section 2.2.5), all products in row blocks small enough for
    OpenBLAS to stay single-threaded. ``np.linalg.lstsq`` on the same (8100, 21) system starts BLAS
    threads and costs 50x more on a loaded machine; for the first-guess fits here (condition numbers
    up to 1e7, fit errors ~1e-4) the fitted values of the two agree to 1e-9 (tests/inverse/test_data.py).

    >>> V = np.vander(np.linspace(0, 1, 50), 3)
    >>> np.allclose(_lstsq_tall(V, V @ np.array([[1.0], [2.0], [3.0]])), [[1], [2], [3]])
    True
    """
    m = V.shape[0]
    G = sum(V[i:i + block].T @ V[i:i + block] for i in range(0, m, block))
    X = np.linalg.solve(G, sum(V[i:i + block].T @ B[i:i + block] for i in range(0, m, block)))
    R = B - np.vstack([V[i:i + block] @ X for i in range(0, m, block)])
    return X + np.linalg.solve(G, sum(V[i:i + block].T @ R[i:i + block] for i in range(0, m, block)))


def _eval_power(C, s, t):
    S = np.stack([np.ones_like(s), s, s * s, s**3])
    T = np.stack([np.ones_like(t), t, t * t, t**3])
    return np.einsum("cmn,mp,np->cp", C, S, T)


#: the boundary edges used to locate a point: name -> (patch, axis (0: s fixed, 1: t fixed), value)
BOUNDARY_EDGES = {"P1:s=0": ("P1", 0, 0), "P1:t=1": ("P1", 1, 1)}
#: the lattice {(a, b): a + b <= 3} on which g is interpolated (unisolvent for total degree 3)
_LATTICE = monomial_exponents(3)


def _edge_points(net, axis, value):
    a = 3 * value
    return [net[a][j] for j in range(4)] if axis == 0 else [net[i][a] for i in range(4)]


def bezier_to_power(b):
    """Power-basis coefficients (constant first) of the cubic with Bezier coefficients b0..b3
    (any ring: floats, ``arb``, ``Fraction``, sympy numbers).

    Parameters
    ----------
    b : sequence of 4 scalars
        Bezier coefficients b0..b3 of a cubic on [0, 1].

    Returns
    -------
    list of 4 scalars
        Power-basis coefficients, constant first (same arithmetic as ``b``).

    Examples
    --------
    >>> bezier_to_power([0, 1, 2, 3])
    [0, 3, 0, 0]
    >>> bezier_to_power([1, 1, 1, 1])          # partition of unity
    [1, 0, 0, 0]
    """
    b0, b1, b2, b3 = b
    return [b0, (b1 - b0) * 3, (b2 - b1 * 2 + b0) * 3, b3 - b2 * 3 + b1 * 3 - b0]


@lru_cache(maxsize=1)
def _lattice_inverse():
    from flint import arb_mat, fmpq_mat

    V = fmpq_mat([[u**a * v**b for (a, b) in _LATTICE] for (u, v) in _LATTICE])
    return arb_mat(V.inv())


def implicit_boundary(k, edge):
    """Implicit equation g(u, v) = sum g_ab u^a v^b of a boundary edge, as balls (bmz04 Definition 5).

    g(u, v) = det S(x(w) - u, y(w) - v), the Sylvester determinant of the edge's cubic (x(w), y(w))
    in the power basis of w, with the formal degree lowered while both leading coefficients are
    balls containing 0 (k = 4, where every boundary is a straight line). g has total degree 3; it is
    evaluated in arb at the 10 lattice points (a, b), a + b <= 3, and interpolated with the exact
    inverse of that lattice's Vandermonde matrix, so the balls contain the exact coefficients.

    Parameters
    ----------
    k : int
        Valence >= 3.
    edge : str
        ``"P1:s=0"`` (Gamma, the inner boundary of layer 0) or ``"P1:t=1"`` (C, between P1 and P2).

    Returns
    -------
    dict
        ``{(a, b): arb}`` for a + b <= 3.

    Examples
    --------
    >>> g = implicit_boundary(4, "P1:s=0")     # k = 4: the line u = 1/2
    >>> sorted((ab, float(x.mid()) / float(g[(1, 0)].mid())) for ab, x in g.items() if not x.contains(0))
    [((0, 0), -0.5), ((1, 0), 1.0)]
    """
    from flint import arb_mat, ctx

    from ccproof.tables.numeric import characteristic_arb

    k = check_valence(k)
    try:
        patch, axis, value = BOUNDARY_EDGES[edge]
    except KeyError:
        raise ValueError(f"unknown boundary edge {edge!r}; choose one of {', '.join(BOUNDARY_EDGES)}") from None
    data = characteristic_arb(k)
    pts = _edge_points(data.bezier[patch], axis, value)
    with ctx.workprec(data.prec + 64):
        x = bezier_to_power([p[0] for p in pts])
        y = bezier_to_power([p[1] for p in pts])
        while len(x) > 2 and x[-1].contains(0) and y[-1].contains(0):
            x, y = x[:-1], y[:-1]
        d = len(x) - 1
        vals = []
        for u, v in _LATTICE:
            q = [x[0] - u] + x[1:]
            r = [y[0] - v] + y[1:]
            S = [[0] * (2 * d) for _ in range(2 * d)]
            for i in range(d):
                for j in range(d + 1):
                    S[i][i + j] = q[j]
                    S[d + i][i + j] = r[j]
            vals.append([arb_mat(S).det()])
        coeffs = _lattice_inverse() * arb_mat(vals)
        return {ab: +coeffs[i, 0] for i, ab in enumerate(_LATTICE)}


def _bern(i, t):
    return comb(3, i) * t**i * (1 - t) ** (3 - i)


def _bern_d(i, t):
    d = 0
    if i > 0:
        d += i * t ** (i - 1) * (1 - t) ** (3 - i)
    if i < 3:
        d -= (3 - i) * t**i * (1 - t) ** (2 - i)
    return comb(3, i) * d


def inside_sign(k, edge, g=None):
    """Sign (+1 or -1) of :func:`implicit_boundary` g on the side of ``edge`` where its piece lies.

    At w = 0.1, ..., 0.9 along the edge the derivative of g(P(s, t)) in the direction into the
    piece's domain is enclosed in a ball; all nine must exclude 0 and agree (else ``ValueError``).

    Parameters
    ----------
    k : int
        Valence, k >= 3.
    edge : str
        A boundary edge name of :data:`BOUNDARY_EDGES` (``"P1:s=0"``, ...; docs/inverse.md).
    g : dict, optional
        The balls of :func:`implicit_boundary` (computed when omitted).

    Returns
    -------
    int
        +1 or -1.

    Examples
    --------
    >>> inside_sign(4, "P1:s=0") * float(implicit_boundary(4, "P1:s=0")[(1, 0)].mid()) > 0   # u > 1/2 inside
    True
    """
    from flint import arb, ctx, fmpq

    from ccproof.tables.numeric import characteristic_arb

    k = check_valence(k)
    patch, axis, value = BOUNDARY_EDGES[edge]
    g = implicit_boundary(k, edge) if g is None else g
    data = characteristic_arb(k)
    net = data.bezier[patch]
    step = -1 if value == 1 else 1
    signs = set()
    with ctx.workprec(data.prec + 64):
        for n in range(1, 10):
            w = arb(fmpq(n, 10))
            s, t = (arb(value), w) if axis == 0 else (w, arb(value))
            X = Y = DX = DY = arb(0)
            for i in range(4):
                for j in range(4):
                    px, py = net[i][j]
                    bi, bj = _bern(i, s), _bern(j, t)
                    dd = (_bern_d(i, s) * bj if axis == 0 else bi * _bern_d(j, t)) * step
                    X, Y = X + px * bi * bj, Y + py * bi * bj
                    DX, DY = DX + px * dd, DY + py * dd
            gu = gv = arb(0)
            for (a, b), cval in g.items():
                if a:
                    gu += cval * a * X ** (a - 1) * Y**b
                if b:
                    gv += cval * b * X**a * Y ** (b - 1)
            der = gu * DX + gv * DY
            signs.add(1 if der > 0 else (-1 if der < 0 else 0))
    if len(signs) != 1 or 0 in signs:
        raise ValueError(f"the sign of g on the inside of {edge} is not decided for k = {k}")
    return signs.pop()


def _normalized_float(g):
    m = max(abs(float(x.mid())) for x in g.values())
    return {ab: float(x.mid()) / m for ab, x in g.items()}


@lru_cache(maxsize=64)
def valence_data(k):
    """The cached :class:`ValenceData` of valence k, derived from the certified tables (module docstring).

    Parameters
    ----------
    k : int
        Valence >= 3 (any: a valence without its own table uses the exact nets of the tables).

    Returns
    -------
    ValenceData

    Examples
    --------
    >>> D = valence_data(5)
    >>> D.bezier.shape, D.fit.shape, round(D.lam, 6)
    ((3, 4, 4, 2), (2, 2, 21), 0.549988)
    """
    from ccproof.tables.numeric import characteristic_arb

    k = check_valence(k)
    lam, bez = _float_nets(k)
    power = np.einsum("im,jn,pijc->pcmn", BEZ2POW, BEZ2POW, bez[:2])
    W, C6 = _derivative_tables(power)
    lam_arb = characteristic_arb(k).lam
    mant, expo = _arb_pow_table(lam_arb)

    # location: Gamma = image of u = 1/2, 0 <= v <= 1/2 (edge s = 0 of P1), the inner boundary of
    # layer 0 on the side x >= y; Gamma / lam is its outer boundary. Separator C = edge t = 1 of P1.
    gam_arb = implicit_boundary(k, "P1:s=0")
    sep_arb = implicit_boundary(k, "P1:t=1")
    gam, sep = _normalized_float(gam_arb), _normalized_float(sep_arb)
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
        coef = _lstsq_tall(V, np.stack([s, t], 1))
        fits.append(coef.T)  # (2, M)
    fit = np.array(fits)

    # first-guess normalization: the layer-0 image has max-norm in [xmin, xmax / lam] where
    # x ranges over Gamma; A = geometric middle of [xmax, xmin / lam^2]
    w = np.linspace(0, 1, 401)
    B = np.array([comb(3, j) * w**j * (1 - w) ** (3 - j) for j in range(4)])
    gx = B.T @ bez[0, 0, :, 0]
    xmin, xmax = gx.min(), gx.max()
    log_a = 0.5 * (np.log(xmax) + np.log(xmin) - 2 * np.log(lam))
    m2, e2 = _arb_pow_table(2 * lam_arb)
    with np.errstate(over="ignore", under="ignore"):
        pow_lam = np.ldexp(mant, expo)
        pow_2lam = np.ldexp(m2, e2)
        pow2 = np.ldexp(1.0, np.arange(-NMAX, NMAX + 1))
    return ValenceData(k, lam, bez, power, W, C6, mant, expo, pow_lam, pow_2lam, pow2, 1.0 / np.log(lam),
                       float(log_a), G, fit, inside_sign(k, "P1:s=0", gam_arb),
                       inside_sign(k, "P1:t=1", sep_arb))


def _derivative_tables(power):
    """(W, C6) of :func:`valence_data` from the power-basis coefficients ``power`` (p, c, i, j) of the two
    patches: W (2, 22, 4) the values and first derivatives by rows, C6 (2, 6, 16) the values and first
    derivatives as flattened bicubic coefficient rows."""
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
    return W, C6

