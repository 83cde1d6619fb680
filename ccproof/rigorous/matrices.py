"""The exact basis-change matrices of Bernstein forms and Taylor shifts (``fmpq_mat``, cached; internal).

Each maps the coefficient vector of a polynomial along one axis: power basis to Bernstein basis on [0, 1]
(with degree elevation), elevation, de Casteljau split and restriction, derivative, and the Taylor shift
p(x) -> p(a + h x). :mod:`.tensor` applies them along an axis, exactly or enclosed in ``arb_mat``.
"""

from math import comb

from flint import fmpq, fmpq_mat, fmpz

_CACHE = {}


def _cached(key, build):
    mat = _CACHE.get(key)
    if mat is None:
        mat = build()
        if len(_CACHE) > 8192:
            _CACHE.clear()
        _CACHE[key] = mat
    return mat


def _matrix(rows, cols, entry):
    return fmpq_mat(rows, cols, [fmpq(entry(i, j)) for i in range(rows) for j in range(cols)])


def _C(n, k):
    """Binomial coefficient, zero outside 0 <= k <= n."""
    return comb(n, k) if 0 <= k <= n else 0


def binomials(n):
    """[C(n, 0), ..., C(n, n)] (fmpz): the scaling of degree-n Bernstein coefficients."""
    return [fmpz(comb(n, i)) for i in range(n + 1)]


def power_to_bernstein_matrix(n, d):
    """(d+1) x (n+1) ``fmpq_mat``: power coefficients of degree n -> Bernstein ones of degree d >= n on [0,1].

    b_k = sum_i C(k, i) / C(d, i) a_i.

    Examples
    --------
    >>> (power_to_bernstein_matrix(1, 2) * fmpq_mat(2, 1, [0, 1])).entries()   # x in degree 2
    [0, 1/2, 1]
    """
    return _cached(("p2b", n, d), lambda: _matrix(d + 1, n + 1, lambda k, i: fmpq(_C(k, i), comb(d, i))))


def elevation_matrix(n, d):
    """(d+1) x (n+1) ``fmpq_mat``: Bernstein degree elevation n -> d: b'_k = sum_i C(n,i) C(d-n,k-i) / C(d,k) b_i.

    Examples
    --------
    >>> (elevation_matrix(1, 3) * fmpq_mat(2, 1, [0, 1])).entries()   # x in degree 3
    [0, 1/3, 2/3, 1]
    """

    def entry(k, i):
        return fmpq(_C(n, i) * _C(d - n, k - i), comb(d, k))

    return _cached(("elev", n, d), lambda: _matrix(d + 1, n + 1, entry))


def split_matrix(n, t, side):
    """De Casteljau at ``t``: side 0 gives the coefficients on [0, t], side 1 on [t, 1].

    side 0: b'_i = sum_{j <= i} C(i, j) t^j (1-t)^(i-j) b_j;
    side 1: b'_i = sum_{j >= i} C(n-i, j-i) t^(j-i) (1-t)^(n-j) b_j.  Exact (n+1) x (n+1) ``fmpq_mat``.

    Examples
    --------
    >>> (split_matrix(2, fmpq(1, 2), 0) * fmpq_mat(3, 1, [0, 0, 1])).entries()   # x^2 on [0, 1/2]
    [0, 0, 1/4]
    """
    s = 1 - t

    def left(i, j):
        return _C(i, j) * t**j * s ** (i - j) if j <= i else 0

    def right(i, j):
        return _C(n - i, j - i) * t ** (j - i) * s ** (n - j) if j >= i else 0

    return _cached(("split", n, t, side), lambda: _matrix(n + 1, n + 1, right if side else left))


def restrict_matrix(n, a, b):
    """(n+1) x (n+1) ``fmpq_mat``: Bernstein coefficients of degree n on [0,1] -> on [a, b] (0 <= a < b <= 1).

    Examples
    --------
    >>> (restrict_matrix(1, fmpq(1, 4), fmpq(1, 2)) * fmpq_mat(2, 1, [0, 1])).entries()   # x
    [1/4, 1/2]
    """

    def build():
        mat = split_matrix(n, b, 0) if b < 1 else None
        if a > 0:
            right = split_matrix(n, a / b, 1)
            mat = right if mat is None else right * mat
        return mat if mat is not None else _matrix(n + 1, n + 1, lambda i, j: int(i == j))

    return _cached(("restrict", n, a, b), build)


def derivative_matrix(n, h):
    """n x (n+1) ``fmpq_mat`` (1 x 1 zero when n = 0): Bernstein coefficients of f' for an interval of width h.

    Examples
    --------
    >>> (derivative_matrix(2, fmpq(1, 2)) * fmpq_mat(3, 1, [0, 0, 1])).entries()   # 4 x^2 on [0, 1/2]
    [0, 4]
    """
    if n == 0:
        return _cached(("diff", 0), lambda: fmpq_mat(1, 1, [0]))
    return _cached(
        ("diff", n, h),
        lambda: _matrix(n, n + 1, lambda i, j: n / h if j == i + 1 else -n / h if j == i else 0),
    )


def taylor_shift_matrix(n, a, h):
    """Exact matrix sending the coefficients of p(x) (degree n) to those of p(a + h x).

    Parameters
    ----------
    n : int
    a, h : fmpq

    Returns
    -------
    fmpq_mat, shape (n + 1, n + 1)
        Entry (j, i) is ``C(i, j) a^(i-j) h^j``; the Taylor shift to a box before the Bernstein
        conversion (docs/rigorous.md "API").

    Examples
    --------
    x^2 becomes (1 + 2 x)^2 = 1 + 4 x + 4 x^2:

    >>> taylor_shift_matrix(2, fmpq(1), fmpq(2)) * fmpq_mat(3, 1, [0, 0, 1])
    [1]
    [4]
    [4]
    """
    def build():
        return fmpq_mat(n + 1, n + 1, [fmpq(comb(i, j)) * a ** (i - j) * h**j if i >= j else fmpq(0)
                                       for j in range(n + 1) for i in range(n + 1)])

    return _cached(("shift", n, a, h), build)


def conversion_matrix(n, d, lo, hi):
    """Power coefficients of degree n on [lo, hi] -> Bernstein ones of degree d >= n (cached)."""
    if (lo, hi) == (0, 1):
        return power_to_bernstein_matrix(n, d)
    return _cached(
        ("conv", n, d, lo, hi),
        lambda: power_to_bernstein_matrix(n, d) * taylor_shift_matrix(n, lo, hi - lo),
    )
