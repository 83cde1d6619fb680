"""Tensor-product Bernstein forms on boxes: de Casteljau subdivision, range enclosure, det J (docs/rigorous.md).

A form of degrees n on the box [lo, hi] stands for sum_k b[k] prod_i C(n_i, k_i) t_i^k_i (1 - t_i)^(n_i - k_i),
t_i = (x_i - lo_i) / (hi_i - lo_i); the basis is non-negative and sums to one, so min b <= f <= max b on the box.

>>> f = BernsteinForm((2, 2), [1, 1, fmpq(3, 4), fmpq(7, 4)])   # x y - x/4 + 1 on [0, 1]^2
>>> left, right = f.split(0)
>>> left.box[0], left.coeffs
((0, 1/2), [1, 1, 7/8, 11/8])
>>> range_enclosure(f)
(3/4, 7/4)
"""

from math import comb

import flint
from flint import arb, fmpq, fmpz

from . import tensor as T
from .matrices import conversion_matrix, derivative_matrix, elevation_matrix, restrict_matrix, split_matrix

_HALF = fmpq(1, 2)


class BernsteinForm:
    """Bernstein coefficients ``coeffs`` (row-major, ``shape`` = degrees + 1, 1 to 4 axes) of a polynomial on the
    exact ``box`` (default [0, 1]^d), exact (``prec`` None) or arb balls at ``prec`` bits; no basis conversion.

    >>> b = BernsteinForm((3,), [0, 0, 1])   # x^2
    >>> b.degrees, b.box
    ((2,), ((0, 1),))
    """

    __slots__ = ("shape", "coeffs", "box", "prec")
    #: leading axes in the power basis (a :class:`~ccproof.rigorous.TaylorForm`'s parameter z: 1), the others Bernstein
    POWER_AXES = 0

    def __init__(self, shape, coeffs, box=None, prec=None):
        shape, coeffs, prec = tuple(shape), [T.scalar(c) for c in coeffs], T.check_prec(prec)
        if not 1 <= len(shape) <= T.MAX_VARS or any(isinstance(n, bool) or not isinstance(n, int) or n < 1
                                                    for n in shape):
            raise ValueError(f"bad shape {shape!r}")
        if len(coeffs) != T.size(shape):
            raise ValueError(f"{len(coeffs)} coefficients for shape {shape}")
        self.shape, self.coeffs, self.prec = shape, T.convert(coeffs, prec), prec  # arb with prec None: TypeError
        self.box = unit_box(len(shape)) if box is None else check_box(box, len(shape))

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

    def split(self, axis, t=_HALF):
        """De Casteljau: the forms ``(low, high)`` on the two parts of the box cut along ``axis`` at fraction ``t``."""
        axis = self._axis(axis)
        t = T.exact_scalar(t)
        if not 0 < t < 1:
            raise ValueError(f"split fraction must lie in (0, 1), got {t}")
        n = self.shape[axis] - 1
        lo, hi = self.box[axis]
        mid = lo + (hi - lo) * t
        return self._along(axis, split_matrix(n, t, 0), (lo, mid)), self._along(axis, split_matrix(n, t, 1), (mid, hi))

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
        axis = self._axis(axis)
        lo, hi = self.box[axis]
        return self._along(axis, derivative_matrix(self.shape[axis] - 1, hi - lo), self.box[axis])

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

    def _axis(self, axis):
        if isinstance(axis, bool) or not isinstance(axis, int) or not 0 <= axis < self.nvars:
            raise ValueError(f"axis {axis!r} out of range for {self.nvars} variables")
        if axis < self.POWER_AXES:
            raise ValueError(f"axis {axis!r} is in the power basis (not an x axis)")
        return axis

    def _common(self, other):
        """The precision of a result of ``self`` and ``other``: forms of one type on one box (or a scalar)."""
        if not isinstance(other, BernsteinForm):
            return self.prec
        if type(other) is not type(self):
            raise TypeError(f"expected a {type(self).__name__}, got {type(other).__name__}")
        if other.box != self.box:
            raise ValueError(f"Bernstein forms on different boxes: {self.box} and {other.box}")
        return T.join_prec(self.prec, other.prec)

    def _scalar(self, c):
        c = T.scalar(c)
        if isinstance(c, arb) and self.prec is None:
            raise TypeError("arb scalar with an exact Bernstein form: convert it with .to_arb(prec)")
        return c

    def __add__(self, other):
        return self._add(other, 1)

    __radd__ = __add__

    def __sub__(self, other):
        return self._add(other, -1)

    def __rsub__(self, other):
        return (-self)._add(other, 1)

    def __neg__(self):
        return self.from_raw(self.shape, [-c for c in self.coeffs], self.box, self.prec)

    def _add(self, other, sign):
        prec = self._common(other)
        if isinstance(other, BernsteinForm):
            degrees = tuple(max(p, q) - 1 for p, q in zip(self.shape, other.shape))
            a, b = (T.convert(f.elevate(degrees).coeffs, prec) for f in (self, other))
            shape = tuple(d + 1 for d in degrees)
        else:  # a constant: added to every coefficient (partition of unity) of the power axes' degree 0
            n = T.size(self.shape[self.POWER_AXES:])
            a, b, shape = self.coeffs[:n], [self._scalar(other)] * n, self.shape
        with flint.ctx.workprec(prec or flint.ctx.prec):
            out = [x + y for x, y in zip(a, b)] if sign > 0 else [x - y for x, y in zip(a, b)]
        return self.from_raw(shape, out + self.coeffs[len(out):], self.box, prec)  # the rest: a constant's

    def __mul__(self, other):
        """Product on the same box (degree m + n): the convolution of the coefficients scaled by C(m, i) and C(n, j),
        divided by C(m + n, k); along a power axis a plain convolution."""
        prec = self._common(other)
        if not isinstance(other, BernsteinForm):
            c = self._scalar(other)
            with flint.ctx.workprec(prec or flint.ctx.prec):
                return self.from_raw(self.shape, [x * c for x in self.coeffs], self.box, prec)
        with flint.ctx.workprec(prec or flint.ctx.prec):
            a, b = ([c * w for c, w in zip(T.convert(f.coeffs, prec), self._weights(f.shape))] for f in (self, other))
            c, shape = T.multiply(a, self.shape, b, other.shape, prec)
            return self.from_raw(shape, [x / w for x, w in zip(c, self._weights(shape))], self.box, prec)

    __rmul__ = __mul__

    def _weights(self, shape):
        """Per axis 1 (power) or the binomials C(n, i) scaling Bernstein coefficients of degree n."""
        return T.weights(shape, [[1] * n if a < self.POWER_AXES else [comb(n - 1, i) for i in range(n)]
                                 for a, n in enumerate(shape)])


def unit_box(nvars):
    """The box [0, 1]^nvars (exact endpoints)."""
    return ((fmpq(0), fmpq(1)),) * nvars


def check_box(box, nvars):
    """``box`` as ``nvars`` exact pairs ``(lo, hi)`` with lo < hi, else ``ValueError``.

    >>> check_box([(0, 1), ("1/2", 1)], 2)
    ((0, 1), (1/2, 1))
    """
    box = tuple(box)
    if len(box) != nvars:
        raise ValueError(f"box with {len(box)} intervals for {nvars} variables")
    out = tuple((T.exact_scalar(lo), T.exact_scalar(hi)) for lo, hi in box)
    for lo, hi in out:
        if not lo < hi:
            raise ValueError(f"empty or degenerate interval [{lo}, {hi}]")
    return out


def range_enclosure(form):
    """``(lo, hi)`` with lo <= f <= hi on the box: the least and greatest coefficient (exact forms: fmpq; balls:
    zero-radius arb endpoints rounded outward, ``(-inf, +inf)`` for a NaN). Also takes a list of coefficients.

    >>> range_enclosure(BernsteinForm((3,), [0, fmpq(1, 2), 0]))
    (0, 1/2)
    """
    coeffs = _coefficients(form)
    if not coeffs:
        raise ValueError("no coefficients")
    if all(isinstance(c, fmpq) for c in coeffs):
        return min(coeffs), max(coeffs)
    if not all(isinstance(c, arb) for c in coeffs):
        raise TypeError("mixed exact and ball coefficients")
    if any(b.is_nan() for b in coeffs):
        return arb.neg_inf(), arb.pos_inf()
    prec = max(form.prec if isinstance(form, BernsteinForm) and form.prec else 0, flint.ctx.prec)
    with flint.ctx.workprec(prec):  # endpoints rounded outward at (at least) the form's precision
        lows, highs = [b.lower() for b in coeffs], [b.upper() for b in coeffs]
    return min(lows), max(highs)  # exact endpoints (radius 0): < and > are a total order on them, +-inf included


def _coefficients(form):
    if isinstance(form, BernsteinForm):
        return form.bernstein().coeffs
    if isinstance(form, (arb, fmpq, fmpz, int)) and not isinstance(form, bool):
        return [form]
    return list(form)


def jacobian_determinant(components, variables=None):
    """det (d components[i] / d x_variables[j]) of 1 to 4 components (default variables 0..n-1, the others
    parameters) in their own arithmetic (Bernstein forms on one box, Taylor models with z kept).

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
    return _det([[g.diff(v) for v in variables] for g in components])


def _det(m):
    if len(m) == 1:
        return m[0][0]
    total = None
    for j in range(len(m)):
        term = m[0][j] * _det([row[:j] + row[j + 1:] for row in m[1:]])
        total = term if total is None else (total + term if j % 2 == 0 else total - term)
    return total
