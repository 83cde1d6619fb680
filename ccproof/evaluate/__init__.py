"""Exact evaluation of Catmull-Clark limit surfaces at (face, u, v) batches (natural parameterization).

Layer ``evaluate`` of docs/architecture.md; imports only :mod:`ccproof.mesh` and :mod:`ccproof.errors`.
See :mod:`ccproof.evaluate.surface` for the method and docs/evaluate.md for accuracy and speed.
The names are loaded lazily, so that ``ccproof --help`` does not import numpy.

>>> from ccproof.evaluate import natural_limit_surface
>>> from ccproof.mesh.examples import torus
>>> natural_limit_surface(torus()).evaluate([0], [0.5], [0.5])["P"].shape
(1, 3)

``limit_surface`` here is the former name of :func:`natural_limit_surface` (kept importable); the
package-wide ``limit_surface`` is :func:`ccproof.limit_surface`.
"""

__all__ = ["LimitSurface", "natural_limit_surface"]


def __getattr__(name):
    if name in __all__ or name == "limit_surface":
        from ccproof.evaluate import surface

        return getattr(surface, name)
    raise AttributeError(f"module 'ccproof.evaluate' has no attribute {name!r}")
