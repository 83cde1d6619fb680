"""Spectrum of the Catmull-Clark subdivision matrix of valence k (bmz04 section 3; docs/readings.md R2).

The two-ring matrix S of Definition 2 is block-circulant over the k sectors. In Fourier mode m
(values z_p omega^(m j) on position p of sector j, omega = exp(2 pi i/k)) it becomes a 6x6 block
whose characteristic polynomial, computed symbolically once (see docs/readings.md, R2), is

    mode m != 0:  (8x-1)(16x-1)(32x-1)(64x-1) (16x^2 - 2(5 + c_m) x + 1),   c_m = cos(2 pi m/k)
    mode m == 0:  (x-1)(8x-1)(16x-1)(32x-1)(64x-1) (16k x^2 - (12k - 28) x + k - 3)   (7x7, with centre)

Hence det(x I - S) is the mode-0 factor times [(8x-1)(16x-1)(32x-1)(64x-1)]^(k-1) times
prod_{m=1}^{k-1} (16x^2 - 2(5 + c_m)x + 1), and with y = (16x^2 - 10x + 1)/(2x) the Chebyshev identity
prod_{m=1}^{k-1} (y - c_m) = 2^(1-k) (T_k(y) - 1)/(y - 1) makes the last product a rational polynomial,

which :func:`charpoly_product_formula` writes out and :func:`check_charpoly_factorization` compares
exactly (fmpq) with the characteristic polynomial of the exact matrix for a given k.

Ordering for every k >= 3 (:func:`spectral_conditions`): lam(c) = (5 + c + sqrt((1+c)(9+c)))/16 is
increasing in c, and c_1 = c_{k-1} = cos(2 pi/k) > c_m for 2 <= m <= k-2, so lam = lam(c_1) is the
largest mode-m (m != 0) eigenvalue, of multiplicity exactly 2 (one simple root in each of the modes
1 and k-1: the discriminant (1+c)(9+c) > 0 for k >= 3), hence non-defective. It beats the mode-0
root mu iff q0(lam) > 0 where q0(x)/k = 16x^2 - (12 - 28/k)x + 1 - 3/k, which reduces (using
16 lam^2 = 2(5+c) lam - 1) to

    (28 lam - 3)/k - 2 (1 - c) lam > 0,

true for all k >= 4 because 1 - c = 2 sin^2(pi/k) <= 2 pi^2/k^2 and 28 lam - 3 > 8, and checked
directly for k = 3. The constant eigenvalues 1/8, ..., 1/64 lie below lam(3) > 0.41.
"""

from __future__ import annotations

from ccproof.errors import check_valence
from ccproof.valence import lam_from_c


def _fmpq_poly(coeffs):
    from flint import fmpq_poly

    return fmpq_poly(coeffs)


def _chebyshev_t(n):
    """T_n as an ``fmpq_poly``."""
    from flint import fmpq_poly

    t0, t1 = fmpq_poly([1]), fmpq_poly([0, 1])
    if n == 0:
        return t0
    for _ in range(n - 1):
        t0, t1 = t1, 2 * fmpq_poly([0, 1]) * t1 - t0
    return t1


def charpoly_product_formula(k):
    """det(x I - S) of the (6k+1) two-ring matrix predicted by the Fourier block argument.

    Built only from the closed-form mode factors in the module docstring (no matrix is formed);
    the spectrum of the subdivision matrix (bmz04 section 3; docs/readings.md R2).

    Parameters
    ----------
    k : int
        Valence, k >= 3.

    Returns
    -------
    flint.fmpq_poly
        Monic, of degree 6k + 1.

    Examples
    --------
    For k = 4 (the regular grid) 1 and 1/2 are eigenvalues:

    >>> from flint import fmpq
    >>> p = charpoly_product_formula(4)
    >>> p.degree(), p(1), p(fmpq(1, 2))
    (25, 0, 0)
    """
    from flint import fmpq

    k = check_valence(k)
    X = _fmpq_poly([0, 1])
    small = (8 * X - 1) * (16 * X - 1) * (32 * X - 1) * (64 * X - 1)
    mode0 = (X - 1) * small * (16 * k * X * X - (12 * k - 28) * X + (k - 3))
    # prod_{m=1}^{k-1} (16x^2 - 10x + 1 - 2 c_m x) = (2x)^(k-1) prod (y - c_m)
    #   = (2x)^(k-1) 2^(1-k) (T_k(y) - 1)/(y - 1) = 2^(1-k) [(2x)^k (T_k(y) - 1)] / (16x^2 - 12x + 1)
    T = _chebyshev_t(k)
    num = _fmpq_poly([0])
    q = 16 * X * X - 10 * X + 1
    for i in range(k + 1):
        ci = T[i]
        if ci != 0:
            num += ci * q**i * (2 * X) ** (k - i)
    num -= (2 * X) ** k
    quot, rem = divmod(num, 16 * X * X - 12 * X + 1)
    if rem != 0:
        raise AssertionError("Chebyshev product is not divisible by (y - 1)")
    inner = quot * fmpq(1, 2 ** (k - 1))
    total = mode0 * small ** (k - 1) * inner
    return total / total[total.degree()]


def check_charpoly_factorization(k):
    """Exact check that the characteristic polynomial of the exact (6k+1) x (6k+1) two-ring matrix
    equals :func:`charpoly_product_formula` (k).

    Cost grows like k^4 (exact charpoly); intended for k up to about 40 (docs/readings.md R2).

    Parameters
    ----------
    k : int
        Valence, k >= 3.

    Returns
    -------
    bool
        True.

    Raises
    ------
    AssertionError
        If the two polynomials differ.

    Examples
    --------
    >>> check_charpoly_factorization(5)
    True
    """
    from ccproof.algebra.subdivision import subdivision_matrix_fmpq

    k = check_valence(k)
    S = subdivision_matrix_fmpq(k)
    cp = S.charpoly()
    pred = charpoly_product_formula(k)
    if cp != pred:
        raise AssertionError(f"characteristic polynomial of S(k={k}) differs from the Fourier product")
    return True


def spectral_conditions(k, prec=128):
    """Certify 1 = lam_0 > lam_1 = lam_2 = lam(k) > |lam_3| for valence k (arb, outward rounded).

    The eigenvalue conditions of bmz04 section 3 (Definition 4; docs/readings.md R2). The eigenvalue
    list is complete by the Fourier block argument (:func:`check_charpoly_factorization`).

    Parameters
    ----------
    k : int
        Valence, k >= 3.
    prec : int, optional
        Bits of precision (default 128).

    Returns
    -------
    dict
        ``k``; the balls ``lam`` (subdominant), ``mu`` (largest mode-0 eigenvalue below 1),
        ``lam_mode2`` (largest eigenvalue of the other modes m != 0, +-1; None for k = 3), the certified
        ``gap`` lower bound of lam - max(|other eigenvalues|); and ``ok`` (True only when every
        inequality is certain).

    Examples
    --------
    For k = 4 the spectrum is that of bicubic B-spline subdivision, 1, 1/2, 1/2, 1/4, ...:

    >>> s = spectral_conditions(4)
    >>> s["ok"], s["lam"].contains(0.5), s["mu"].contains(0.25), s["gap"].contains(0.25)
    (True, True, True, True)
    """
    from flint import arb, ctx, fmpq

    from ccproof.algebra.specialize import subdominant_eigenvalue

    k = check_valence(k)
    with ctx.workprec(prec):
        c1 = arb(fmpq(2, k)).cos_pi()
        lam = subdominant_eigenvalue(k, "arb", prec)
        disc1 = (1 + c1) * (9 + c1)
        # mode 0: larger root of 16k x^2 - (12k-28) x + (k-3)
        b = arb(12 * k - 28)
        d0 = b * b - 64 * k * (k - 3)
        mu = (b + d0.sqrt()) / (32 * k)
        others = [mu, arb(fmpq(1, 8))]
        lam2 = None
        if k >= 4:
            # next largest cos(2 pi m/k), m = 2 (or the mode m = k/2 ... all below c_1)
            c2 = arb(fmpq(4, k)).cos_pi()
            lam2 = lam_from_c(c2, arb.sqrt)
            others.append(lam2)
        gap = min((lam - o for o in others), key=lambda z: z.lower())
        ok = bool(disc1 > 0) and bool(lam < 1) and bool(gap > 0)
        # the smaller roots are positive (product 1/16 > 0, sum > 0), so |.| = value
    return {"k": k, "lam": lam, "mu": mu, "lam_mode2": lam2, "gap": gap, "ok": ok}
