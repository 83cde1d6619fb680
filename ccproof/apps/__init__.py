"""ccproof.apps (layer of docs/architecture.md): ARAP parameterization (``arap``), dynamic surfaces (``dynamics``),
isogeometric analysis on limit surfaces (``iga``: quadrature, assembly, graded spaces; docs/iga.md),
and the control mesh both read (``control_mesh``: any mesh ``ccproof eval`` reads, as quads; tagged and
non-manifold ones as a ``TaggedQuadMesh``, which ``arap`` subdivides with OpenSubdiv's rules and ``fit``
refuses by name)."""
