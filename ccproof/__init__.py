"""ccproof: Catmull-Clark subdivision surfaces as certified parametric surfaces.

Layers (docs/architecture.md), each importing only from the ones before it:
``algebra`` (exact) -> ``rigorous`` (arb/fmpq Bernstein kernels) -> ``tables`` (certified
per-valence tables) -> ``mesh`` -> ``evaluate`` -> ``inverse`` -> ``reparam`` -> ``certify`` -> ``apps``.
"""

__version__ = "0.1.0"


def __getattr__(name):
    """Lazy top-level shortcut: ``ccproof.limit_surface`` is :func:`ccproof.reparam.limit_surface`."""
    if name == "limit_surface":
        from ccproof.reparam.surface import limit_surface

        return limit_surface
    raise AttributeError(f"module 'ccproof' has no attribute {name!r}")
