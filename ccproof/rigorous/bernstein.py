"""Tensor-product Bernstein forms on boxes, de Casteljau subdivision and range enclosure.

A :class:`BernsteinForm` of degrees ``(n_0, ..., n_{d-1})`` on the box ``B = prod [lo_i, hi_i]``
(exact rational endpoints) stands for

    f(x) = sum_k b[k] prod_i C(n_i, k_i) t_i^k_i (1 - t_i)^(n_i - k_i),   t_i = (x_i - lo_i) / (hi_i - lo_i).

Since the basis functions are non-negative and sum to one on ``B``, ``min b <= f <= max b`` there
(:func:`range_enclosure`, :func:`certainly_positive`).  Coefficients are all ``fmpq`` (exact) or
all ``arb``; in the ball case every returned coefficient encloses the exact coefficient for every
choice of real inputs in the input balls.

>>> f = BernsteinForm((2, 2), [1, 1, fmpq(3, 4), fmpq(7, 4)])   # x y - x/4 + 1 on [0, 1]^2
>>> left, right = f.split(0)
>>> left.box[0], left.coeffs
((0, 1/2), [1, 1, 7/8, 11/8])
>>> range_enclosure(f), certainly_positive(f)
((3/4, 7/4), True)
"""


import flint
from flint import arb, fmpq, fmpz

from . import tensor as T
from .matrices import (
    binomials,
    conversion_matrix,
    derivative_matrix,
    elevation_matrix,
    restrict_matrix,
    split_matrix,
)

_HALF = fmpq(1, 2)


class BernsteinForm:
    """Bernstein coefficients ``coeffs`` (row-major, shape ``degrees + 1``) of a polynomial on ``box``.

    Build one with :func:`bernstein_coefficients`, or directly from Bezier control values (for
    example the 4 x 4 net of a bicubic patch, row-major, ``shape=(4, 4)``) with this constructor,
    which does no basis conversion.

    Parameters
    ----------
    shape : tuple of d int (1 <= d <= 4): ``degrees + 1`` per variable (Farin's tensor Bernstein basis)
    coeffs : sequence of fmpq-convertible or arb, length ``prod(shape)``
    box : sequence of d exact pairs (lo, hi), optional: default [0, 1]^d
    prec : int, optional: bits of the arb balls; None (default) for exact coefficients

    Examples
    --------
    >>> b = BernsteinForm((3,), [0, 0, 1])   # x^2
    >>> b.degrees, b.box
    ((2,), ((0, 1),))
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


def check_box(box, nvars):
    """``box`` as a tuple of ``nvars`` pairs ``(lo, hi)`` of fmpq with ``lo < hi``.

    Parameters
    ----------
    box : sequence of nvars pairs of exact numbers (int, fmpq, "p/q")
    nvars : int

    Returns
    -------
    tuple of nvars (fmpq, fmpq)

    Raises
    ------
    ValueError
        On a wrong number of intervals or an empty or degenerate one.

    Examples
    --------
    >>> check_box([(0, 1), ("1/2", 1)], 2)
    ((0, 1), (1/2, 1))
    >>> check_box([(1, 1)], 1)
    Traceback (most recent call last):
    ...
    ValueError: empty or degenerate interval [1, 1]
    """
    box = tuple(box)
    if len(box) != nvars:
        raise ValueError(f"box with {len(box)} intervals for {nvars} variables")
    out = []
    for iv in box:
        lo, hi = iv
        lo, hi = T.exact_scalar(lo), T.exact_scalar(hi)
        if not lo < hi:
            raise ValueError(f"empty or degenerate interval [{lo}, {hi}]")
        out.append((lo, hi))
    return tuple(out)


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

    >>> range_enclosure(BernsteinForm((3,), [0, fmpq(1, 2), 0]))
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


def jacobian_determinant(components, variables=None):
    """det of ``(d components[i] / d x_{variables[j]})`` for 1 to 4 components (Laplace expansion), in the
    components' own arithmetic: power form, Bernstein form on their common box, or Taylor model (z kept).

    ``variables`` defaults to ``0 .. len(components)-1``; extra variables act as parameters.

    Parameters
    ----------
    components : sequence of n Poly, BernsteinForm or TaylorForm (1 <= n <= 4), anything with ``diff``
    variables : tuple of n distinct int, optional (for a TaylorForm, x axes >= 1)

    Returns
    -------
    Poly, BernsteinForm or TaylorForm
        det J, whose sign decides local injectivity (docs/readings.md R7; e.g. det J_Phi of the
        characteristic map).

    Examples
    --------
    For z^2 = (x^2 - y^2, 2 x y) (Cauchy-Riemann: det J = |2 z|^2):

    >>> x, y = BernsteinForm((2, 1), [0, 1]), BernsteinForm((1, 2), [0, 1])
    >>> jacobian_determinant([x * x - y * y, 2 * x * y]).coeffs == (4 * x * x + 4 * y * y).coeffs
    True
    """
    components = list(components)
    n = len(components)
    if not 1 <= n <= T.MAX_VARS:
        raise ValueError(f"Jacobian of {n} components")
    variables = tuple(range(n)) if variables is None else tuple(variables)
    if len(variables) != n or len(set(variables)) != n:
        raise ValueError(f"need {n} distinct variables, got {variables!r}")
    jac = [[g.diff(v) for v in variables] for g in components]
    return _det(jac)


def _det(m):
    n = len(m)
    if n == 1:
        return m[0][0]
    if n == 2:
        return m[0][0] * m[1][1] - m[0][1] * m[1][0]
    total = None
    for j in range(n):
        minor = [row[:j] + row[j + 1 :] for row in m[1:]]
        term = m[0][j] * _det(minor)
        total = term if total is None else (total + term if j % 2 == 0 else total - term)
    return total
