"""ccproof.reparam: the differentiable parameterizations of bmz04 section 4 (docs/readings.md R5-R7).

Weights b, w (:mod:`~ccproof.reparam.weights`), quadrant maps F^alpha and Phi^-1
(:mod:`~ccproof.reparam.quadrant`), the blend F_b of eq. (4) (:mod:`~ccproof.reparam.blend`), the
limit derivatives at an extraordinary vertex (:mod:`~ccproof.reparam.corner`) and the composition
with the evaluator (:func:`limit_surface`, :mod:`~ccproof.reparam.surface`). See docs/reparam.md.
Names are loaded lazily (``ccproof --help`` stays numpy-free).

>>> from ccproof.reparam import limit_surface
>>> from ccproof.mesh.examples import k_regular_disk
>>> S = limit_surface(k_regular_disk(5, 2))
>>> sorted(S.evaluate([0], [0.1], [0.2], parameterization="characteristic"))
['P', 'Pu', 'Pv']
"""

from importlib import import_module

_WHERE = {
    "Parameterization": "ccproof.reparam.surface",
    "corner_valence": "ccproof.reparam.surface",
    "limit_surface": "ccproof.reparam.surface",
    "face_map": "ccproof.reparam.blend",
    "PARAMETERIZATIONS": "ccproof.reparam.blend",
    "bump": "ccproof.reparam.weights",
    "weight_radial": "ccproof.reparam.weights",
    "weight_tensor": "ccproof.reparam.weights",
    "alpha_bound": "ccproof.reparam.quadrant",
    "default_alpha": "ccproof.reparam.quadrant",
    "vanishing_map": "ccproof.reparam.quadrant",
    "inverse_characteristic_map_derivatives": "ccproof.reparam.quadrant",
    "characteristic_tangent_masks": "ccproof.reparam.corner",
    "corner_tangents": "ccproof.reparam.corner",
}

__all__ = sorted(_WHERE)


def __getattr__(name):
    if name in _WHERE:
        value = getattr(import_module(_WHERE[name]), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'ccproof.reparam' has no attribute {name!r}")


def __dir__():
    return sorted(list(globals()) + __all__)
