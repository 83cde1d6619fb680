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
>>> z = TaylorForm((2, 1), [0, 1], 64)                   # z on [-1, 1]
>>> f = (x * z + 1) * (x * z - 1)                        # x^2 z^2 - 1
>>> f.shape, f.truncate(1).shape
((3, 3), (2, 3))
>>> t = f.truncate(1).coeffs
>>> t[0].str(3), t[1].str(3), bool(t[2].contains(-2)), bool(t[2].contains(0)), bool(t[2].rad() < 1 + arb("1e-6"))
('-1.00', '-1.00', True, True, True)

The last ball is -1 + [-1, 1]: the dropped x^2 z^2 (Bernstein coefficient 1 on B_2 = x^2) bounded by [-1, 1].
"""

import flint
from flint import arb

from . import tensor as T
from .bernstein import BernsteinForm, unit_box

ZBOX = (T.exact_scalar(-1), T.exact_scalar(1))


class TaylorForm(BernsteinForm):
    """Polynomial in ``z`` in [-1, 1] (axis 0, power basis) with Bernstein coefficients in ``x`` in
    [0, 1]^d (axes 1..d), all coefficients ``arb`` balls at ``prec`` bits (see the module docstring): a
    :class:`BernsteinForm` on [-1, 1] x [0, 1]^d whose axis 0 is in the power basis (:attr:`POWER_AXES`), so
    that sums, products and derivatives in x are the Bernstein ones (zeros appended and plain convolution
    along z), :meth:`truncate` drops powers of z and :meth:`bernstein` converts z.

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

    >>> f = TaylorForm((2, 3, 2), [0, 0, 0, 0, 1, 1, 0, 1, 0, 1, 0, 1], 53)
    >>> f.truncate(0).shape
    (1, 3, 2)
    """

    __slots__ = ()
    POWER_AXES = 1

    def __init__(self, shape, coeffs, prec):
        shape = tuple(shape)
        if T.check_prec(prec) is None or len(shape) < 2:
            raise ValueError(f"a TaylorForm holds balls (pass prec=...) in 2..4 variables, got {shape!r}, {prec!r}")
        super().__init__(shape, coeffs, _box(len(shape)), prec)

    @classmethod
    def constant(cls, c, nx, prec):
        """The constant ``c`` as a form in ``nx`` variables x (degree 0)."""
        with flint.ctx.workprec(prec):
            return cls.from_raw((1,) * (nx + 1), [T.to_kind(T.scalar(c), prec)], _box(nx + 1), prec)

    @classmethod
    def variable(cls, axis, nx, prec):
        """The variable ``x_axis`` (1 <= axis <= nx), Bernstein coefficients (0, 1)."""
        if isinstance(axis, bool) or not isinstance(axis, int) or not 1 <= axis <= nx:
            raise ValueError(f"axis {axis!r} out of range 1..{nx}")
        return cls.from_raw((1,) + tuple(2 if i == axis else 1 for i in range(1, nx + 1)), [arb(0), arb(1)],
                            _box(nx + 1), prec)

    def truncate(self, degree):
        """Keep z^0 .. z^degree; each dropped coefficient c of z^e B_k (e > degree) is added as
        [-|c|, |c|] to the coefficient of z^0 B_k (|z| <= 1 and B_k >= 0)."""
        if isinstance(degree, bool) or not isinstance(degree, int) or degree < 0:
            raise ValueError(f"degree must be a non-negative int, got {degree!r}")
        if self.shape[0] <= degree + 1:
            return self
        c, shape = T.truncate(self.coeffs, self.shape, 0, degree, self.prec)
        return self.from_raw(shape, c, self.box, self.prec)


def _box(nvars):
    return (ZBOX,) + unit_box(nvars - 1)
