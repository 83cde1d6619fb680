"""ARAP parameterization of Catmull-Clark subdivision surfaces (He, Schaefer, Hormann 2010)."""
