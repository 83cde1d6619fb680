"""Taylor models in one parameter with Bernstein coefficients in the other variables.

A :class:`TaylorForm` of shape ``(m, n_1, ..., n_d)`` (row-major coefficient balls ``c``) stands for

    f(z, x) = sum_{e < m, k} c[e, k] z^e B_k(x),     z in [-1, 1],  x in [0, 1]^d,

with ``B_k(x) = prod_i C(n_i - 1, k_i) x_i^k_i (1 - x_i)^(n_i - 1 - k_i)`` the tensor Bernstein basis on
the unit box: a power series in the parameter ``z`` whose coefficients are Bernstein forms in ``x``.
Every operation returns balls enclosing the exact result for every choice of the inputs in their
balls, as :mod:`.bernstein` does. :meth:`TaylorForm.truncate` drops the powers ``z^e``, ``e > D``:
since ``|z| <= 1`` and ``B_k >= 0``, ``c z^e B_k`` lies in ``[-|c|, |c|] B_k``, so each dropped ball
is added (as ``[-|c|, |c|]``) to ``c[0, k]``. Keeping ``x`` in the Bernstein basis keeps those balls
of the size of the values (a power basis in ``x`` would add the absolute values of its coefficients,
which cancel heavily at high degree).

>>> from flint import arb
>>> x = TaylorForm.variable(1, 1, prec=64)               # x_1 on [0,1]
>>> z = TaylorForm.from_poly(Poly.variable(0, 2), 64)   # z on [-1, 1]
>>> f = (x * z + 1) * (x * z - 1)                        # x^2 z^2 - 1
>>> f.shape, f.truncate(1).shape
((3, 3), (2, 3))
>>> t = f.truncate(1).coeffs
>>> t[0].str(3), t[1].str(3), bool(t[2].contains(-2)), bool(t[2].contains(0)), bool(t[2].rad() < 1 + arb("1e-6"))
('-1.00', '-1.00', True, True, True)

The last ball is -1 + [-1, 1]: the dropped x^2 z^2 (Bernstein coefficient 1 on B_2 = x^2) bounded by [-1, 1].
"""

from math import prod

import flint
from flint import arb

from . import _tensor as T
from .bernstein import (
    BernsteinForm,
    binomials,
    conversion_matrix,
    derivative_matrix,
    elevation_matrix,
    power_to_bernstein_matrix,
)
from .poly import Poly

ZBOX = (T.exact_scalar(-1), T.exact_scalar(1))


class TaylorForm:
    """Polynomial in ``z`` in [-1, 1] (axis 0, power basis) with Bernstein coefficients in ``x`` in
    [0, 1]^d (axes 1..d), all coefficients ``arb`` balls at ``prec`` bits (see the module docstring).

    Parameters
    ----------
    shape : tuple of int, length 1 + d (2..4)
        ``(z degree + 1, x degrees + 1)``.
    coeffs : sequence of arb-convertible, length ``prod(shape)`` (row-major)
    prec : int
        Bits of the balls.

    Notes
    -----
    Taylor models in one parameter for every valence k >= k0 (docs/readings.md R10,
    docs/appendix_a.md).

    Examples
    --------
    x^2 + z y: z-degree 1, Bernstein coefficients in (x, y) of x^2 (0, 0, 1) and of y (0, 1):

    >>> z, x, y = (Poly.variable(i, 3) for i in range(3))
    >>> f = TaylorForm.from_poly(x * x + z * y, 53)
    >>> f.shape, [c.str(3, radius=False) for c in f.coeffs]
    ((2, 3, 2), ['0', '0', '0', '0', '1.00', '1.00', '0', '1.00', '0', '1.00', '0', '1.00'])
    """

    __slots__ = ("shape", "coeffs", "prec")

    def __init__(self, shape, coeffs, prec):
        shape = tuple(shape)
        if not 2 <= len(shape) <= T.MAX_VARS or any(isinstance(n, bool) or not isinstance(n, int) or n < 1
                                                     for n in shape):
            raise ValueError(f"bad shape {shape!r}")
        prec = T.check_prec(prec)
        if prec is None:
            raise ValueError("a TaylorForm holds balls: pass prec=...")
        coeffs = [T.scalar(c) for c in coeffs]
        if len(coeffs) != prod(shape):
            raise ValueError(f"{len(coeffs)} coefficients for shape {shape}")
        self.shape, self.coeffs, self.prec = shape, T.convert(coeffs, prec), prec

    @classmethod
    def from_raw(cls, shape, coeffs, prec):
        """From coefficients already of the form's kind and precision (no conversion, no checks)."""
        f = object.__new__(cls)
        f.shape, f.coeffs, f.prec = tuple(shape), coeffs, prec
        return f

    @classmethod
    def from_poly(cls, poly, prec):
        """The power-basis :class:`Poly` ``poly`` in (z, x_1, ..., x_d), x in the Bernstein basis on [0,1]^d."""
        if not isinstance(poly, Poly) or poly.nvars < 2:
            raise TypeError("expected a Poly in (z, x_1, ...), at least 2 variables")
        coeffs, shape = T.convert(poly.coeffs, prec), poly.shape
        for axis in range(1, len(shape)):
            coeffs, shape = T.apply_along_axis(coeffs, shape, axis,
                                               power_to_bernstein_matrix(shape[axis] - 1, shape[axis] - 1), prec)
        return cls.from_raw(shape, coeffs, prec)

    @classmethod
    def constant(cls, c, nx, prec):
        """The constant ``c`` as a form in ``nx`` variables x (degree 0)."""
        with flint.ctx.workprec(prec):
            return cls.from_raw((1,) * (nx + 1), [T.to_kind(T.scalar(c), prec)], prec)

    @classmethod
    def variable(cls, axis, nx, prec):
        """The variable ``x_axis`` (1 <= axis <= nx), Bernstein coefficients (0, 1)."""
        d = nx
        if isinstance(axis, bool) or not isinstance(axis, int) or not 1 <= axis <= d:
            raise ValueError(f"axis {axis!r} out of range 1..{d}")
        shape = (1,) + tuple(2 if i == axis else 1 for i in range(1, d + 1))
        return cls.from_raw(shape, [arb(0), arb(1)], prec)

    # ------------------------------------------------------------------ arithmetic

    def _aligned(self, other):
        """Both operands with the same shape: Bernstein axes elevated, the z axis zero-padded."""
        if other.prec != self.prec or len(other.shape) != len(self.shape):
            raise ValueError("TaylorForms of different precision or number of variables")
        out = []
        target = tuple(max(p, q) for p, q in zip(self.shape, other.shape))
        for f in (self, other):
            coeffs, shape = f.coeffs, f.shape
            for axis in range(1, len(shape)):
                if shape[axis] != target[axis]:
                    coeffs, shape = T.apply_along_axis(coeffs, shape, axis,
                                                       elevation_matrix(shape[axis] - 1, target[axis] - 1), f.prec)
            out.append(T.pad(coeffs, shape, target, f.prec))
        return out[0], out[1], target

    def _shift(self, c, sign):
        # a constant is c z^0 times the partition of unity: added to every coefficient of the z^0 block
        c = T.scalar(c)
        block = prod(self.shape[1:])
        with flint.ctx.workprec(self.prec):
            head = [x + c for x in self.coeffs[:block]] if sign > 0 else [x - c for x in self.coeffs[:block]]
        return TaylorForm.from_raw(self.shape, head + self.coeffs[block:], self.prec)

    def __add__(self, other):
        if not isinstance(other, TaylorForm):
            return self._shift(other, 1)
        a, b, shape = self._aligned(other)
        with flint.ctx.workprec(self.prec):
            return TaylorForm.from_raw(shape, [x + y for x, y in zip(a, b)], self.prec)

    __radd__ = __add__

    def __neg__(self):
        return TaylorForm.from_raw(self.shape, [-c for c in self.coeffs], self.prec)

    def __sub__(self, other):
        if not isinstance(other, TaylorForm):
            return self._shift(other, -1)
        a, b, shape = self._aligned(other)
        with flint.ctx.workprec(self.prec):
            return TaylorForm.from_raw(shape, [x - y for x, y in zip(a, b)], self.prec)

    def __rsub__(self, other):
        return (-self)._shift(other, 1)

    def __mul__(self, other):
        """Product: plain convolution in z, Bernstein product (binomially weighted convolution) in x."""
        if not isinstance(other, TaylorForm):
            c = T.scalar(other)
            with flint.ctx.workprec(self.prec):
                return TaylorForm.from_raw(self.shape, [x * c for x in self.coeffs], self.prec)
        if other.prec != self.prec or len(other.shape) != len(self.shape):
            raise ValueError("TaylorForms of different precision or number of variables")

        def weights(shape):
            return T.weights(shape, [[1] * shape[0]] + [binomials(n - 1) for n in shape[1:]])

        with flint.ctx.workprec(self.prec):
            a = [c * w for c, w in zip(self.coeffs, weights(self.shape))]
            b = [c * w for c, w in zip(other.coeffs, weights(other.shape))]
            c, shape = T.multiply(a, self.shape, b, other.shape, self.prec)
            c = [x / w for x, w in zip(c, weights(shape))]
        return TaylorForm.from_raw(shape, c, self.prec)

    __rmul__ = __mul__

    # ------------------------------------------------------------------ calculus, truncation, conversion

    def diff(self, axis):
        """Partial derivative with respect to ``x_axis`` (axis >= 1; Bernstein derivative, degree one less)."""
        if isinstance(axis, bool) or not isinstance(axis, int) or not 1 <= axis < len(self.shape):
            raise ValueError(f"axis {axis!r} is not an x axis")
        c, shape = T.apply_along_axis(self.coeffs, self.shape, axis,
                                      derivative_matrix(self.shape[axis] - 1, T.exact_scalar(1)), self.prec)
        return TaylorForm.from_raw(shape, c, self.prec)

    def truncate(self, degree):
        """Keep z^0 .. z^degree; each dropped coefficient c of z^e B_k (e > degree) is added as
        [-|c|, |c|] to the coefficient of z^0 B_k (|z| <= 1 and B_k >= 0)."""
        if isinstance(degree, bool) or not isinstance(degree, int) or degree < 0:
            raise ValueError(f"degree must be a non-negative int, got {degree!r}")
        if self.shape[0] <= degree + 1:
            return self
        c, shape = T.truncate(self.coeffs, self.shape, 0, degree, self.prec)
        return TaylorForm.from_raw(shape, c, self.prec)

    def bernstein(self):
        """The :class:`BernsteinForm` of the same polynomial on [-1, 1] x [0, 1]^d (z converted)."""
        n = self.shape[0] - 1
        c, shape = T.apply_along_axis(self.coeffs, self.shape, 0, conversion_matrix(n, n, *ZBOX), self.prec)
        box = (ZBOX,) + ((T.exact_scalar(0), T.exact_scalar(1)),) * (len(shape) - 1)
        return BernsteinForm.from_raw(shape, c, box, self.prec)
