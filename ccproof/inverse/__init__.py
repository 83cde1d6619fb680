"""ccproof.inverse: the characteristic map, its inverse (bmz04 section 4.3, Algorithm 1) and the
implicit equations of its layer and patch boundaries (Definition 5). See ``docs/inverse.md``.

Public entry points: :func:`characteristic_map` (vectorized Phi with Jacobian),
:func:`inverse_characteristic_map` (vectorized Phi^-1 with a guaranteed fallback),
:mod:`ccproof.inverse.implicit` (exact Sylvester-resultant implicitization) and
:func:`certify_preimage` (arb interval-Newton certificate of one preimage).
"""

from ccproof.inverse.algorithm import InverseResult, inverse_characteristic_map
from ccproof.inverse.forward import characteristic_map

__all__ = ["InverseResult", "characteristic_map", "inverse_characteristic_map"]
