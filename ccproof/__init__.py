"""ccproof: Catmull-Clark subdivision surfaces as certified parametric surfaces.

Layers (DESIGN.md section 1), each importing only from the ones before it:
``algebra`` (exact) -> ``rigorous`` (arb/fmpq Bernstein kernels) -> ``tables`` (certified
per-valence tables) -> ``mesh`` -> ``evaluate`` -> ``inverse`` -> ``reparam`` -> ``certify`` -> ``apps``.
"""

__version__ = "0.1.0"
