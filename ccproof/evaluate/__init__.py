"""Exact evaluation of Catmull-Clark limit surfaces at (face, u, v) batches (natural parameterization).

Layer ``evaluate`` of DESIGN.md section 1; imports only :mod:`ccproof.mesh` and :mod:`ccproof.errors`.
See :mod:`ccproof.evaluate.surface` for the method and docs/evaluate.md for accuracy and speed.
"""

from ccproof.evaluate.surface import LimitSurface, limit_surface

__all__ = ["LimitSurface", "limit_surface"]
