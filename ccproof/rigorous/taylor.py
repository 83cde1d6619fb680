"""Taylor models in one parameter z in [-1, 1] with Bernstein coefficients in x in [0, 1]^d (docs/rigorous.md,
"Taylor models"): f(z, x) = sum_(e, k) c[e, k] z^e B_k(x), balls enclosing the exact result as in :mod:`.bernstein`.

>>> from flint import arb
>>> x = TaylorForm.variable(1, 1, prec=64)               # x_1 on [0,1]
>>> z = TaylorForm((2, 1), [0, 1], 64)                   # z on [-1, 1]
>>> f = (x * z + 1) * (x * z - 1)                        # x^2 z^2 - 1
>>> f.shape, f.truncate(1).shape
((3, 3), (2, 3))
>>> t = f.truncate(1).coeffs                             # x^2 z^2 (coefficient 1 on B_2 = x^2) -> [-1, 1] on B_2
>>> t[0].str(3), t[1].str(3), bool(t[2].contains(-2)), bool(t[2].contains(0)), bool(t[2].rad() < 1 + arb("1e-6"))
('-1.00', '-1.00', True, True, True)
"""

import flint
from flint import arb

from . import tensor as T
from .bernstein import BernsteinForm, unit_box

ZBOX = (T.exact_scalar(-1), T.exact_scalar(1))


class TaylorForm(BernsteinForm):
    """A :class:`BernsteinForm` of arb balls on [-1, 1] x [0, 1]^d (``shape``: z degree + 1, then x degrees + 1)
    whose axis 0 is in the power basis (:attr:`POWER_AXES`): sums, products and x derivatives are the Bernstein ones,
    :meth:`truncate` drops powers of z, :meth:`bernstein` converts z."""

    __slots__ = ()
    POWER_AXES = 1

    def __init__(self, shape, coeffs, prec):
        shape = tuple(shape)
        if T.check_prec(prec) is None or len(shape) < 2:
            raise ValueError(f"a TaylorForm holds balls (pass prec=...) in 2..4 variables, got {shape!r}, {prec!r}")
        super().__init__(shape, coeffs, _box(len(shape) - 1), prec)

    @classmethod
    def constant(cls, c, nx, prec):
        """The constant ``c`` as a form in ``nx`` variables x (degree 0)."""
        with flint.ctx.workprec(prec):
            return cls.from_raw((1,) * (nx + 1), [T.to_kind(T.scalar(c), prec)], _box(nx), prec)

    @classmethod
    def variable(cls, axis, nx, prec):
        """The variable ``x_axis`` (1 <= axis <= nx), Bernstein coefficients (0, 1)."""
        if isinstance(axis, bool) or not isinstance(axis, int) or not 1 <= axis <= nx:
            raise ValueError(f"axis {axis!r} out of range 1..{nx}")
        return cls.from_raw((1,) + tuple(2 if i == axis else 1 for i in range(1, nx + 1)), [arb(0), arb(1)], _box(nx),
                            prec)

    def truncate(self, degree):
        """Keep z^0 .. z^degree; each dropped c of z^e B_k is added as [-|c|, |c|] to the one of z^0 B_k."""
        if isinstance(degree, bool) or not isinstance(degree, int) or degree < 0:
            raise ValueError(f"degree must be a non-negative int, got {degree!r}")
        if self.shape[0] <= degree + 1:
            return self
        c, shape = T.truncate(self.coeffs, self.shape, 0, degree, self.prec)
        return self.from_raw(shape, c, self.box, self.prec)


def _box(nx):  # [-1, 1] x [0, 1]^nx
    return (ZBOX,) + unit_box(nx)
