"""Rigorous kernels: Bernstein forms on boxes and Taylor models over ``fmpq`` (exact) or ``arb`` (balls); no float.

Exact inputs give exact outputs; ball inputs give balls enclosing the exact result for every choice in the input
balls (computed inside ``flint.ctx.workprec``, the global precision never changed). The guarantees and the API:
docs/rigorous.md; an example: :mod:`.bernstein`."""

from .bernstein import BernsteinForm, jacobian_determinant, range_enclosure, unit_box
from .matrices import conversion_matrix
from .taylor import TaylorForm
from .tensor import exact_fmpq

__all__ = ["BernsteinForm", "TaylorForm", "conversion_matrix", "exact_fmpq", "jacobian_determinant", "range_enclosure",
           "unit_box"]
