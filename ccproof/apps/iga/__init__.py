"""Isogeometric analysis on Catmull-Clark limit surfaces: quadrature that knows the extraordinary vertices
(:mod:`~ccproof.apps.iga.quadrature`), the mass, stiffness and load of scalar problems with the surface
metric (:mod:`~ccproof.apps.iga.assembly`), and a linear Kirchhoff-Love thin shell
(:mod:`~ccproof.apps.iga.shell`, benchmarks in :mod:`~ccproof.apps.iga.shell_benchmarks`), on the basis rows
of :meth:`ccproof.evaluate.surface.LimitSurface.basis`. docs/iga.md."""
