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

Main entry points: :class:`BernsteinForm` (``split``, ``restrict``, ``elevate``, ``diff``, ``+ - *``),
:func:`range_enclosure`, :func:`certainly_positive`, :func:`ball_contains`,
:class:`TaylorForm` (a Taylor model in one parameter with
Bernstein coefficients in the other variables, ``truncate``, ``bernstein``), :func:`jacobian_determinant` (of
Bernstein or Taylor forms, or of polynomials).  :class:`Poly` (polynomials in the power basis) and
:func:`bernstein_coefficients` (their Bernstein forms) are the exact reference of the tests; the
verifier uses neither, so they are loaded only when named.  See ``docs/rigorous.md``.
"""

from ._tensor import ball_contains, exact_fmpq
from .bernstein import (
    BernsteinForm,
    certainly_positive,
    jacobian_determinant,
    range_enclosure,
    unit_box,
)
from .matrices import conversion_matrix
from .taylor import TaylorForm


def __getattr__(name):
    """:class:`Poly` and :func:`bernstein_coefficients` (module :mod:`.poly`), imported when first named."""
    if name in ("Poly", "bernstein_coefficients"):
        from . import poly

        return getattr(poly, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


__all__ = [
    "BernsteinForm",
    "Poly",
    "TaylorForm",
    "ball_contains",
    "bernstein_coefficients",
    "certainly_positive",
    "conversion_matrix",
    "exact_fmpq",
    "jacobian_determinant",
    "range_enclosure",
    "unit_box",
]
