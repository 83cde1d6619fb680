"""Tensor-product Bernstein forms on boxes, de Casteljau subdivision and range enclosure.

A :class:`BernsteinForm` of degrees ``(n_0, ..., n_{d-1})`` on the box ``B = prod [lo_i, hi_i]``
(exact rational endpoints) stands for

    f(x) = sum_k b[k] prod_i C(n_i, k_i) t_i^k_i (1 - t_i)^(n_i - k_i),   t_i = (x_i - lo_i) / (hi_i - lo_i).

Since the basis functions are non-negative and sum to one on ``B``, ``min b <= f <= max b`` there
(:func:`range_enclosure`, :func:`certainly_positive`).  Coefficients are all ``fmpq`` (exact) or
all ``arb``; in the ball case every returned coefficient encloses the exact coefficient for every
choice of real inputs in the input balls.

>>> from ccproof.rigorous.poly import Poly
>>> x, y = Poly.variable(0, 2), Poly.variable(1, 2)
>>> f = bernstein_coefficients(x * y - x / 4 + 1, box=[(0, 1), (0, 1)])
>>> f.coeffs
[1, 1, 3/4, 7/4]
>>> left, right = f.split(0)
>>> left.box[0], left.coeffs
((0, 1/2), [1, 1, 7/8, 11/8])
>>> range_enclosure(f), certainly_positive(f)
((3/4, 7/4), True)
"""

from math import comb

import flint
from flint import arb, fmpq, fmpq_mat, fmpz

from . import _tensor as T
from .poly import Poly, check_box, taylor_shift_matrix

_HALF = fmpq(1, 2)


class BernsteinForm:
    """Bernstein coefficients ``coeffs`` (row-major, shape ``degrees + 1``) of a polynomial on ``box``.

    Build one with :func:`bernstein_coefficients`, or directly from Bezier control values (for
    example the 4 x 4 net of a bicubic patch, row-major, ``shape=(4, 4)``) with this constructor,
    which does no basis conversion; :meth:`to_poly` gives the power form in the box variables.

    Parameters
    ----------
    shape : tuple of d int (1 <= d <= 4): ``degrees + 1`` per variable (Farin's tensor Bernstein basis)
    coeffs : sequence of fmpq-convertible or arb, length ``prod(shape)``
    box : sequence of d exact pairs (lo, hi), optional: default [0, 1]^d
    prec : int, optional: bits of the arb balls; None (default) for exact coefficients

    Examples
    --------
    >>> b = BernsteinForm((3,), [0, 0, 1])
    >>> b.to_poly() == Poly.variable(0, 1) ** 2, b.degrees, b.box
    (True, (2,), ((0, 1),))
    """

    __slots__ = ("shape", "coeffs", "box", "prec")
    #: leading axes in the power basis (a :class:`~ccproof.rigorous.TaylorForm`'s parameter z: 1), the others Bernstein
    POWER_AXES = 0

    def __init__(self, shape, coeffs, box=None, prec=None):
        shape = tuple(shape)
        if not 1 <= len(shape) <= T.MAX_VARS or any(
            isinstance(n, bool) or not isinstance(n, int) or n < 1 for n in shape
        ):
            raise ValueError(f"bad shape {shape!r}")
        coeffs = list(coeffs)
        if len(coeffs) != T.size(shape):
            raise ValueError(f"{len(coeffs)} coefficients for shape {shape}")
        prec = T.check_prec(prec)
        coeffs = [T.scalar(c) for c in coeffs]
        if prec is None and any(isinstance(c, arb) for c in coeffs):
            raise TypeError("arb coefficient in an exact Bernstein form: pass prec=...")
        self.shape = shape
        self.coeffs = T.convert(coeffs, prec)
        self.box = unit_box(len(shape)) if box is None else check_box(box, len(shape))
        self.prec = prec

    @classmethod
    def from_raw(cls, shape, coeffs, box, prec):
        """From coefficients already of the form's kind and precision (no conversion, no checks)."""
        f = object.__new__(cls)
        f.shape, f.coeffs, f.box, f.prec = tuple(shape), coeffs, box, prec
        return f

    @property
    def nvars(self):
        return len(self.shape)

    @property
    def degrees(self):
        return tuple(n - 1 for n in self.shape)

    @property
    def is_exact(self):
        return self.prec is None

    def __repr__(self):
        kind = "exact" if self.prec is None else f"arb {self.prec} bits"
        box = " x ".join(f"[{lo}, {hi}]" for lo, hi in self.box)
        return f"BernsteinForm({kind}, degrees={self.degrees}, box={box})"

    def to_arb(self, prec):
        """Ball version at ``prec`` bits."""
        if T.check_prec(prec) is None:
            raise ValueError("to_arb needs a precision in bits")
        return self.from_raw(self.shape, T.convert(self.coeffs, prec), self.box, prec)

    # ------------------------------------------------------------------ subdivision

    def split(self, axis, t=_HALF):
        """De Casteljau split of ``box`` along ``axis`` at fraction ``t`` (default 1/2): ``(low, high)``.

        With the default ``t = 1/2`` the sub-boxes of a dyadic box are dyadic and the matrices are
        dyadic (exact in ``arb``); the result is exact for exact input.
        """
        axis = self._axis(axis, bernstein=True)
        t = T.exact_scalar(t)
        if not 0 < t < 1:
            raise ValueError(f"split fraction must lie in (0, 1), got {t}")
        n = self.shape[axis] - 1
        lo, hi = self.box[axis]
        mid = lo + (hi - lo) * t
        low = self._along(axis, split_matrix(n, t, 0), (lo, mid))
        high = self._along(axis, split_matrix(n, t, 1), (mid, hi))
        return low, high

    def restrict(self, box):
        """Bernstein form of the same polynomial on a sub-box ``box`` of ``self.box``."""
        box = check_box(box, self.nvars)
        f = self
        for axis, ((lo, hi), (a, b)) in enumerate(zip(self.box, box)):
            if (a, b) == (lo, hi):
                continue
            if a < lo or b > hi or axis < self.POWER_AXES:
                raise ValueError(f"[{a}, {b}] is not inside [{lo}, {hi}] (axis {axis})")
            h = hi - lo
            f = f._along(axis, restrict_matrix(f.shape[axis] - 1, (a - lo) / h, (b - lo) / h), (a, b))
        return f

    def elevate(self, degrees):
        """Same polynomial in the Bernstein basis of higher ``degrees`` (per variable)."""
        degrees = tuple(degrees)
        if len(degrees) != self.nvars or any(d < n - 1 for d, n in zip(degrees, self.shape)):
            raise ValueError(f"cannot elevate degrees {self.degrees} to {degrees}")
        f = self
        for axis, d in enumerate(degrees[self.POWER_AXES:], self.POWER_AXES):
            if d != f.shape[axis] - 1:
                f = f._along(axis, elevation_matrix(f.shape[axis] - 1, d), self.box[axis])
        shape = tuple(d + 1 for d in degrees[:self.POWER_AXES]) + f.shape[self.POWER_AXES:]  # power axes: zeros
        return f if shape == f.shape else f.from_raw(shape, T.pad(f.coeffs, f.shape, shape, f.prec), f.box, f.prec)

    def diff(self, axis):
        """Bernstein form (degree one less along ``axis``) of the partial derivative on the box."""
        axis = self._axis(axis, bernstein=True)
        n = self.shape[axis] - 1
        lo, hi = self.box[axis]
        return self._along(axis, derivative_matrix(n, hi - lo), self.box[axis])

    def to_poly(self):
        """The polynomial in the original (box) variables, in the power basis."""
        f = self.bernstein()
        mats = [bernstein_to_power_matrix(n - 1) for n in f.shape]
        c, shape = T.apply_all_axes(f.coeffs, f.shape, mats, f.prec)
        p = Poly.from_raw(shape, c, self.prec)
        for axis, (lo, hi) in enumerate(f.box):
            if (lo, hi) != (0, 1):
                h = hi - lo
                p = p.affine(axis, -lo / h, (1 - lo) / h)  # t = (x - lo) / h
        return p

    def bernstein(self):
        """The form with every axis in the Bernstein basis on its box (the power axes converted; else itself)."""
        f = self
        for axis in range(self.POWER_AXES):
            n = f.shape[axis] - 1
            c, shape = T.apply_along_axis(f.coeffs, f.shape, axis, conversion_matrix(n, n, *f.box[axis]), f.prec)
            f = BernsteinForm.from_raw(shape, c, f.box, f.prec)
        return f

    def _along(self, axis, mat, interval):
        c, shape = T.apply_along_axis(self.coeffs, self.shape, axis, mat, self.prec)
        box = self.box[:axis] + (interval,) + self.box[axis + 1 :]
        return self.from_raw(shape, c, box, self.prec)

    def _axis(self, axis, bernstein=False):
        if isinstance(axis, bool) or not isinstance(axis, int) or not 0 <= axis < self.nvars:
            raise ValueError(f"axis {axis!r} out of range for {self.nvars} variables")
        if bernstein and axis < self.POWER_AXES:
            raise ValueError(f"axis {axis!r} is in the power basis (not an x axis)")
        return axis

    # ------------------------------------------------------------------ arithmetic (same box)

    def _common(self, other):
        if type(other) is not type(self):
            raise TypeError(f"expected a {type(self).__name__}, got {type(other).__name__}")
        if other.box != self.box:
            raise ValueError(f"Bernstein forms on different boxes: {self.box} and {other.box}")
        prec = T.join_prec(self.prec, other.prec)
        degrees = tuple(max(p, q) - 1 for p, q in zip(self.shape, other.shape))
        a, b = self.elevate(degrees), other.elevate(degrees)
        return T.convert(a.coeffs, prec), T.convert(b.coeffs, prec), a.shape, prec

    def __add__(self, other):
        if not isinstance(other, BernsteinForm):
            return self._shift(T.scalar(other), 1)
        a, b, shape, prec = self._common(other)
        with flint.ctx.workprec(prec or flint.ctx.prec):
            return self.from_raw(shape, [x + y for x, y in zip(a, b)], self.box, prec)

    __radd__ = __add__

    def __sub__(self, other):
        if not isinstance(other, BernsteinForm):
            return self._shift(T.scalar(other), -1)
        a, b, shape, prec = self._common(other)
        with flint.ctx.workprec(prec or flint.ctx.prec):
            return self.from_raw(shape, [x - y for x, y in zip(a, b)], self.box, prec)

    def __rsub__(self, other):
        return (-self)._shift(T.scalar(other), 1)

    def __neg__(self):
        return self.from_raw(self.shape, [-c for c in self.coeffs], self.box, self.prec)

    def _shift(self, c, sign):
        # a constant is added to every coefficient (partition of unity) of the power axes' degree 0
        self._check_scalar_kind(c)
        n = T.size(self.shape[self.POWER_AXES:])
        with flint.ctx.workprec(self.prec or flint.ctx.prec):
            out = [x + c for x in self.coeffs[:n]] if sign > 0 else [x - c for x in self.coeffs[:n]]
        return self.from_raw(self.shape, out + self.coeffs[n:], self.box, self.prec)

    def _check_scalar_kind(self, c):
        if isinstance(c, arb) and self.prec is None:
            raise TypeError("arb scalar with an exact Bernstein form: convert it with .to_arb(prec)")

    def __mul__(self, other):
        """Product on the same box, of degree ``m + n``, computed in Bernstein form.

        With ``a~_i = C(m, i) a_i`` (coefficients in the basis t^i (1-t)^(m-i)), the product's
        scaled coefficients are the plain convolution of ``a~`` and ``b~``; divide by C(m+n, k). Along a power
        axis the weights are 1 (a plain convolution).
        """
        if not isinstance(other, BernsteinForm):
            c = T.scalar(other)
            self._check_scalar_kind(c)
            with flint.ctx.workprec(self.prec or flint.ctx.prec):
                return self.from_raw(self.shape, [x * c for x in self.coeffs], self.box, self.prec)
        if type(other) is not type(self) or other.box != self.box:
            raise ValueError(f"forms on different boxes or bases: {self.box} and {other.box}")
        prec = T.join_prec(self.prec, other.prec)
        wa, wb = self._weights(self.shape), self._weights(other.shape)
        with flint.ctx.workprec(prec or flint.ctx.prec):
            a = [c * w for c, w in zip(T.convert(self.coeffs, prec), wa)]
            b = [c * w for c, w in zip(T.convert(other.coeffs, prec), wb)]
        c, shape = T.multiply(a, self.shape, b, other.shape, prec)
        wc = self._weights(shape)
        with flint.ctx.workprec(prec or flint.ctx.prec):
            c = [x / w for x, w in zip(c, wc)]
        return self.from_raw(shape, c, self.box, prec)

    __rmul__ = __mul__

    def _weights(self, shape):
        return T.weights(shape, [[1] * n if a < self.POWER_AXES else binomials(n - 1) for a, n in enumerate(shape)])

    def __truediv__(self, c):
        """Division by a non-zero scalar."""
        c = T.scalar(c)
        self._check_scalar_kind(c)
        if isinstance(c, fmpq):
            if c == 0:
                raise ZeroDivisionError("Bernstein form divided by zero")
            return self * (1 / c)
        with flint.ctx.workprec(self.prec):
            return self.from_raw(self.shape, [x / c for x in self.coeffs], self.box, self.prec)


# ---------------------------------------------------------------------------- conversion


def unit_box(nvars):
    """The box [0, 1]^nvars with exact endpoints.

    Parameters
    ----------
    nvars : int

    Returns
    -------
    tuple of nvars (fmpq, fmpq)

    Examples
    --------
    >>> unit_box(2)
    ((0, 1), (0, 1))
    """
    return ((fmpq(0), fmpq(1)),) * nvars


def bernstein_coefficients(poly, box=None, degrees=None):
    """Bernstein form of ``poly`` on ``box`` (default [0,1]^n) of ``degrees`` (default ``poly.degrees``).

    Per variable, one exact matrix (Taylor shift to the box, then power -> Bernstein basis with
    degree elevation) is applied along the axis; exact input gives exact ``fmpq`` coefficients,
    ball input gives balls at ``poly.prec``.  For tight balls on small sub-boxes prefer converting
    once on a large box and then using :meth:`BernsteinForm.split` / :meth:`BernsteinForm.restrict`
    (both numerically stable) over re-expanding the power form on each sub-box.

    Parameters
    ----------
    poly : Poly
    box : sequence of nvars pairs (lo, hi), optional
    degrees : tuple of int, optional: at least ``poly.degrees`` (higher ones elevate the degree)

    Returns
    -------
    BernsteinForm of shape ``degrees + 1``

    Examples
    --------
    x^2 on [1, 3] is (1 + 2t)^2 = (1 - t)^2 + 3 * 2t(1 - t) + 9 t^2:

    >>> x = Poly.variable(0, 1)
    >>> bernstein_coefficients(x**2, box=[(1, 3)]).coeffs, bernstein_coefficients(x, degrees=(2,)).coeffs
    ([1, 3, 9], [0, 1/2, 1])
    """
    if not isinstance(poly, Poly):
        raise TypeError(f"expected a Poly, got {type(poly).__name__}")
    box = unit_box(poly.nvars) if box is None else check_box(box, poly.nvars)
    degrees = poly.degrees if degrees is None else tuple(degrees)
    if len(degrees) != poly.nvars or any(
        isinstance(d, bool) or not isinstance(d, int) or d < n for d, n in zip(degrees, poly.degrees)
    ):
        raise ValueError(f"Bernstein degrees {degrees} below the polynomial's degrees {poly.degrees}")
    mats = [conversion_matrix(n - 1, d, lo, hi) for n, d, (lo, hi) in zip(poly.shape, degrees, box)]
    c, shape = T.apply_all_axes(poly.coeffs, poly.shape, mats, poly.prec)
    return BernsteinForm.from_raw(shape, c, box, poly.prec)


def range_enclosure(form):
    """``(lo, hi)`` with ``lo <= f <= hi`` on the box: min and max of the coefficients.

    Exact forms give ``fmpq``; ball forms give zero-radius ``arb`` endpoints rounded outward
    (``lo`` = min of the balls' lower endpoints, ``hi`` = max of upper endpoints); a NaN
    coefficient gives ``(-inf, +inf)``.  Also accepts a plain list of coefficients.

    Parameters
    ----------
    form : BernsteinForm or sequence of fmpq / arb

    Returns
    -------
    (lo, hi) : fmpq or arb, the range enclosure of the module docstring (docs/rigorous.md "Guarantees")

    Examples
    --------
    x (1 - x) has range [0, 1/4] on [0, 1]; its coefficients (0, 1/2, 0) enclose it:

    >>> x = Poly.variable(0, 1)
    >>> range_enclosure(bernstein_coefficients(x * (1 - x)))
    (0, 1/2)
    """
    coeffs = _coefficients(form)
    if not coeffs:
        raise ValueError("no coefficients")
    if all(isinstance(c, fmpq) for c in coeffs):
        return min(coeffs), max(coeffs)
    balls = [c if isinstance(c, arb) else None for c in coeffs]
    if any(b is None for b in balls):
        raise TypeError("mixed exact and ball coefficients")
    if any(b.is_nan() for b in balls):
        return arb.neg_inf(), arb.pos_inf()
    prec = max(form.prec if isinstance(form, BernsteinForm) and form.prec else 0, flint.ctx.prec)
    with flint.ctx.workprec(prec):  # endpoints rounded outward at (at least) the form's precision
        lows = [b.lower() for b in balls]
        highs = [b.upper() for b in balls]
    # endpoints are exact (radius 0), so ``<`` is a total order on them (including +-inf)
    lo = lows[0]
    for x in lows[1:]:
        if x < lo:
            lo = x
    hi = highs[0]
    for x in highs[1:]:
        if x > hi:
            hi = x
    return lo, hi


def certainly_positive(form):
    """True only when every coefficient is certainly > 0 (so the polynomial is > 0 on the box).

    Exact ``fmpq`` coefficients are compared exactly; ``arb`` balls with arb's ``>`` (True only when
    the whole ball is > 0) and must be finite.

    Parameters
    ----------
    form : BernsteinForm, sequence of fmpq / arb, or one number

    Returns
    -------
    bool

    Examples
    --------
    >>> certainly_positive([arb(1), arb("0 +/- 0.1")]), certainly_positive(arb("nan"))
    (False, False)
    """
    coeffs = _coefficients(form)
    for c in coeffs:
        if isinstance(c, arb):
            if not (c.is_finite() and c > 0):
                return False
        elif not T.exact_scalar(c) > 0:
            return False
    return bool(coeffs)


def _coefficients(form):
    if isinstance(form, BernsteinForm):
        return form.bernstein().coeffs
    if isinstance(form, (arb, fmpq, fmpz, int)) and not isinstance(form, bool):
        return [form]
    return list(form)


# ---------------------------------------------------------------------------- exact matrices

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


def bernstein_to_power_matrix(n):
    """(n+1) x (n+1) ``fmpq_mat``: Bernstein coefficients of degree n on [0,1] -> power coefficients.

    a_i = sum_k (-1)^(i-k) C(n, i) C(i, k) b_k (the inverse of :func:`power_to_bernstein_matrix` ``(n, n)``).

    Examples
    --------
    >>> (bernstein_to_power_matrix(2) * fmpq_mat(3, 1, [0, 1, 0])).entries()   # 2 x (1 - x)
    [0, 2, -2]
    """

    def entry(i, k):
        return (-1) ** ((i - k) % 2) * _C(n, i) * _C(i, k)

    return _cached(("b2p", n), lambda: _matrix(n + 1, n + 1, entry))


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


def conversion_matrix(n, d, lo, hi):
    """Power coefficients of degree n on [lo, hi] -> Bernstein ones of degree d >= n (cached)."""
    if (lo, hi) == (0, 1):
        return power_to_bernstein_matrix(n, d)
    return _cached(
        ("conv", n, d, lo, hi),
        lambda: power_to_bernstein_matrix(n, d) * taylor_shift_matrix(n, lo, hi - lo),
    )
