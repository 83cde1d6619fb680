"""Exact Loop limit evaluation (the second subdivision scheme): :class:`LoopSurface`.

One concept per module: :mod:`.box_spline` (the regular patch), :mod:`.complex` (local triangle
complexes and one exact Loop step), :mod:`.plan` (per-configuration exact data: regular nets,
self-similar layers, local splits), :mod:`.surface` (setup and batched evaluation).
"""

from ccproof.evaluate.loop.surface import LoopSurface, loop_limit_surface

__all__ = ["LoopSurface", "loop_limit_surface"]
