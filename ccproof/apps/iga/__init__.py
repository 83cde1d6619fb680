"""Isogeometric analysis on Catmull-Clark limit surfaces: quadrature that knows the extraordinary vertices
(:mod:`~ccproof.apps.iga.quadrature`), and the mass, stiffness and load of scalar problems with the surface
metric (:mod:`~ccproof.apps.iga.assembly`), on the basis rows of
:meth:`ccproof.evaluate.surface.LimitSurface.basis`. docs/iga.md."""
