"""Exact evaluation of Catmull-Clark limit surfaces at (face, u, v) batches (natural parameterization).

Layer ``evaluate`` of docs/architecture.md; imports only :mod:`ccproof.mesh` and :mod:`ccproof.errors`.
See :mod:`ccproof.evaluate.surface` for the method and docs/evaluate.md for accuracy and speed.
The names are loaded lazily, so that ``ccproof --help`` does not import numpy.

>>> from ccproof.evaluate import natural_limit_surface
>>> from ccproof.mesh.examples import torus
>>> natural_limit_surface(torus()).evaluate([0], [0.5], [0.5])["P"].shape
(1, 3)

The public names: :class:`LimitSurface` (the evaluator), :func:`natural_limit_surface` (builds it),
:class:`PatchTable` (the arrays the kernels read: ``S.patch_map.table``) and :func:`available_backends`.
``limit_surface`` here is the former name of :func:`natural_limit_surface` (kept importable); the
package-wide ``limit_surface`` is :func:`ccproof.limit_surface`.
"""

from typing import TYPE_CHECKING

if TYPE_CHECKING:  # the lazy names below, as type checkers see them
    from ccproof.evaluate.backend import available_backends
    from ccproof.evaluate.patch_table import PatchTable
    from ccproof.evaluate.surface import LimitSurface, natural_limit_surface
    from ccproof.evaluate.surface import limit_surface as limit_surface  # the former name

#: lazily loaded public names -> defining module
_WHERE = {
    "LimitSurface": "ccproof.evaluate.surface",
    "PatchTable": "ccproof.evaluate.patch_table",
    "available_backends": "ccproof.evaluate.backend",
    "natural_limit_surface": "ccproof.evaluate.surface",
    "limit_surface": "ccproof.evaluate.surface",  # former name of natural_limit_surface
}

__all__ = ["LimitSurface", "PatchTable", "available_backends", "natural_limit_surface"]


def __getattr__(name: str) -> object:
    if name in _WHERE:
        from importlib import import_module

        return getattr(import_module(_WHERE[name]), name)
    raise AttributeError(f"module 'ccproof.evaluate' has no attribute {name!r}")
