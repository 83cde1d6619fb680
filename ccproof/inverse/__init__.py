"""ccproof.inverse: the characteristic map, its inverse (bmz04 section 4.3, Algorithm 1) and the
implicit equations of its layer and patch boundaries (Definition 5). See ``docs/inverse.md``.

Public entry points: :func:`characteristic_map` (vectorized Phi with Jacobian),
:func:`inverse_characteristic_map` (vectorized Phi^-1 with a guaranteed fallback),
:mod:`ccproof.inverse.implicit` (exact Sylvester-resultant implicitization) and
:func:`certify_preimage` (arb interval-Newton certificate of one preimage).

The names are imported lazily (so that ``ccproof --help`` does not load numpy).
"""

from importlib import import_module

_WHERE = {
    "CertifiedPreimage": "ccproof.inverse.certified",
    "certify_preimage": "ccproof.inverse.certified",
    "InverseResult": "ccproof.inverse.algorithm",
    "inverse_characteristic_map": "ccproof.inverse.algorithm",
    "characteristic_map": "ccproof.inverse.forward",
}

__all__ = sorted(_WHERE)


def __getattr__(name):
    if name in _WHERE:
        value = getattr(import_module(_WHERE[name]), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'ccproof.inverse' has no attribute {name!r}")


def __dir__():
    return sorted(list(globals()) + __all__)
