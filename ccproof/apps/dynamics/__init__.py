"""Dynamic Catmull-Clark subdivision surfaces (Qin, Mandal & Vemuri 1998; qmv98): FEM, time integration,
shape recovery from range data.

Modules: :mod:`~ccproof.apps.dynamics.basis` (B-spline basis, analytic element Grams),
:mod:`~ccproof.apps.dynamics.elements` (normal/special elements, local subdivision recursion),
:mod:`~ccproof.apps.dynamics.model` (generalized coordinates, global matrices, limit evaluation),
:mod:`~ccproof.apps.dynamics.integrate` (implicit schemes (31), (32), preconditioned CG),
:mod:`~ccproof.apps.dynamics.forces` (springs to the nearest limit point, data forces),
:mod:`~ccproof.apps.dynamics.fit` (multilevel shape recovery, fit error, minimal enclosing sphere),
:mod:`~ccproof.apps.dynamics.meshes` (the paper's meshes), :mod:`~ccproof.apps.dynamics.shapes` (synthetic range
data), :mod:`~ccproof.apps.dynamics.plot` (figures), :mod:`~ccproof.cli.fit` (``ccproof fit``).
See docs/qmv98.md.
"""
