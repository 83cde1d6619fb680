"""Exact evaluation of Catmull-Clark limit surfaces at (face, u, v) batches (natural parameterization).

Layer ``evaluate`` of docs/architecture.md; imports only :mod:`ccproof.mesh` and :mod:`ccproof.errors`.
See :mod:`ccproof.evaluate.surface` for the method and docs/evaluate.md for accuracy and speed.
The names are loaded lazily, so that ``ccproof --help`` does not import numpy.

>>> from ccproof.evaluate import limit_surface
>>> from ccproof.mesh.examples import torus
>>> limit_surface(torus()).evaluate([0], [0.5], [0.5])["P"].shape
(1, 3)
"""

__all__ = ["LimitSurface", "limit_surface"]


def __getattr__(name):
    if name in __all__:
        from ccproof.evaluate import surface

        return getattr(surface, name)
    raise AttributeError(f"module 'ccproof.evaluate' has no attribute {name!r}")
