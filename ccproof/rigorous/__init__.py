"""Rigorous kernels: polynomials and Bernstein forms over ``fmpq`` (exact) and ``arb`` (balls).

No Python float is used or accepted anywhere in this package; every number is an ``fmpq``,
``fmpz`` or ``arb``.  Ball arithmetic runs at a precision carried by the objects (``prec``, bits)
inside ``flint.ctx.workprec``; the global flint precision is never changed.

Guarantees
----------
* Exact inputs (``prec is None``) give exact outputs: polynomial arithmetic, composition, affine
  change of variables, Bernstein conversion, degree elevation, de Casteljau subdivision and
  Bernstein products are computed in ``fmpq`` without rounding.
* Ball inputs give ball outputs that *enclose* the exact result for every choice of real numbers
  in the input balls (and for the exact rational basis-change matrices, which are enclosed in
  ``arb`` at the working precision when they are not dyadic).
* The Bernstein basis on a box is non-negative and a partition of unity, so
  ``range_enclosure(bernstein_coefficients(p, box))`` brackets ``p`` on the whole box and
  ``certainly_positive`` (every coefficient certainly > 0, finite) proves ``p > 0`` on it.

Main entry points: :class:`Poly`, :func:`jacobian_determinant` (of power, Bernstein or Taylor forms),
:func:`bernstein_coefficients`, :class:`BernsteinForm` (``split``, ``restrict``, ``elevate``, ``diff``, ``+ - *``),
:func:`range_enclosure`, :func:`certainly_positive`, :func:`ball_contains`,
:class:`TaylorForm` (a Taylor model in one parameter with
Bernstein coefficients in the other variables, ``truncate``, ``bernstein``).  See ``docs/rigorous.md``.
"""

from ._tensor import ball_contains, exact_fmpq
from .bernstein import (
    BernsteinForm,
    bernstein_coefficients,
    certainly_positive,
    range_enclosure,
    unit_box,
)
from .poly import Poly, jacobian_determinant
from .taylor import TaylorForm

__all__ = [
    "BernsteinForm",
    "Poly",
    "TaylorForm",
    "ball_contains",
    "bernstein_coefficients",
    "certainly_positive",
    "exact_fmpq",
    "jacobian_determinant",
    "range_enclosure",
    "unit_box",
]
