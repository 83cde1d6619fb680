"""The exact basis-change matrices (``fmpq_mat``, cached) along one axis: power to Bernstein basis on [0, 1] (with
degree elevation), elevation, de Casteljau split and restriction, derivative, the Taylor shift p(x) -> p(a + h x);
the formulas: docs/rigorous.md, "Basis changes". :mod:`.tensor` applies them, exactly or enclosed in ``arb_mat``.

>>> (power_to_bernstein_matrix(1, 2) * fmpq_mat(2, 1, [0, 1])).entries()   # x in degree 2
[0, 1/2, 1]
>>> (split_matrix(2, fmpq(1, 2), 0) * fmpq_mat(3, 1, [0, 0, 1])).entries()   # x^2 on [0, 1/2]
[0, 0, 1/4]
>>> (derivative_matrix(2, fmpq(1, 2)) * fmpq_mat(3, 1, [0, 0, 1])).entries()   # 4 x^2 on [0, 1/2]
[0, 4]
>>> (taylor_shift_matrix(2, fmpq(1), fmpq(2)) * fmpq_mat(3, 1, [0, 0, 1])).entries()   # (1 + 2x)^2
[1, 4, 4]
"""

from math import comb

from flint import fmpq, fmpq_mat

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


def power_to_bernstein_matrix(n, d):
    """Power coefficients of degree n -> Bernstein ones of degree d >= n on [0, 1]: b_k = sum_i C(k, i)/C(d, i) a_i."""
    return _cached(("p2b", n, d), lambda: _matrix(d + 1, n + 1, lambda k, i: fmpq(comb(k, i), comb(d, i))))


def elevation_matrix(n, d):
    """Bernstein degree n -> d: b'_k = sum_i C(n, i) C(d - n, k - i) / C(d, k) b_i."""
    return _cached(("elev", n, d), lambda: _matrix(d + 1, n + 1, lambda k, i: fmpq(
        comb(n, i) * comb(d - n, k - i) if k >= i else 0, comb(d, k))))


def split_matrix(n, t, side):
    """De Casteljau at ``t``: the coefficients on [0, t] (side 0) or on [t, 1] (side 1)."""
    s = 1 - t

    def left(i, j):
        return comb(i, j) * t**j * s ** (i - j) if j <= i else 0

    def right(i, j):
        return comb(n - i, j - i) * t ** (j - i) * s ** (n - j) if j >= i else 0

    return _cached(("split", n, t, side), lambda: _matrix(n + 1, n + 1, right if side else left))


def restrict_matrix(n, a, b):
    """Bernstein coefficients of degree n on [0, 1] -> on [a, b] (0 <= a < b <= 1): two splits."""

    def build():
        mat = split_matrix(n, b, 0) if b < 1 else _matrix(n + 1, n + 1, lambda i, j: int(i == j))
        return split_matrix(n, a / b, 1) * mat if a > 0 else mat

    return _cached(("restrict", n, a, b), build)


def derivative_matrix(n, h):
    """Bernstein coefficients of f' (degree n - 1) on an interval of width h; 1 x 1 zero when n = 0."""
    if n == 0:
        return _cached(("diff", 0), lambda: fmpq_mat(1, 1, [0]))
    return _cached(("diff", n, h), lambda: _matrix(n, n + 1, lambda i, j: n / h if j == i + 1 else -n / h if j == i
                                                     else 0))


def taylor_shift_matrix(n, a, h):
    """Coefficients of p(x) (degree n) -> those of p(a + h x): entry (j, i) is C(i, j) a^(i-j) h^j."""
    return _cached(("shift", n, a, h), lambda: fmpq_mat(n + 1, n + 1, [
        fmpq(comb(i, j)) * a ** (i - j) * h**j if i >= j else fmpq(0) for j in range(n + 1) for i in range(n + 1)]))


def conversion_matrix(n, d, lo, hi):
    """Power coefficients of degree n on [lo, hi] -> Bernstein ones of degree d >= n."""
    return _cached(("conv", n, d, lo, hi),
                   lambda: power_to_bernstein_matrix(n, d) * taylor_shift_matrix(n, lo, hi - lo))
