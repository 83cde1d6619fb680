"""ARAP parameterization of Catmull-Clark subdivision surfaces (He, Schaefer, Hormann 2010; docs/hsh10.md).

* :mod:`~ccproof.apps.arap.charts`: charts from per-face labels (topological disks), segmentations;
* :mod:`~ccproof.apps.arap.hierarchy`: per-chart subdivision hierarchy with the extended-chart and
  the boundary-rule texture operators (OpenSubdiv's tags carried level by level,
  :mod:`ccproof.apps.control_mesh`);
* :mod:`~ccproof.apps.arap.samples`: limit tangent masks (hsh10 Eq. 2) and the samples of Eq. 3;
* :mod:`~ccproof.apps.arap.solver`: closed-form local step (Appendix), global step factorized once
  per level, the local/global iteration;
* :mod:`~ccproof.apps.arap.lscm`: triangulation and LSCM initialization (numpy/scipy);
* :mod:`~ccproof.apps.arap.metrics`: E_angle, E_area, E_stretch (section 4), flips;
* :mod:`~ccproof.apps.arap.core`: the methods (a)-(d), multi-resolution schedule, ``compare``;
* :mod:`~ccproof.apps.arap.export`: the limit surface with exact UVs for other tools (``write_uv_mesh``);
* :mod:`~ccproof.apps.arap.fvar`: control UVs for OpenSubdiv's face-varying "corners only" rule;
* :mod:`~ccproof.cli.arap`: ``ccproof arap``.

The names below are loaded lazily (``ccproof --help`` does not import numpy).

>>> from ccproof.apps.arap import LevelPlan, compare
>>> from ccproof.mesh.examples import grid
>>> res, _ = compare(grid(3, 3), methods=("c",), plan=LevelPlan(levels=1, eval_level=3))
>>> [round(x, 9) for x in res["c"].metrics.as_tuple()]
[2.0, 2.0, 1.0]
"""

__all__ = [
    "compare",
    "LevelPlan",
    "Solver",
    "parameterize",
    "charts_from_labels",
    "read_labels",
    "segment_by_normals",
    "ChartHierarchy",
    "texture_metrics",
    "ChartError",
]

_WHERE = {
    "compare": "meshes",
    "LevelPlan": "meshes",
    "Solver": "core",
    "parameterize": "meshes",
    "texture_metrics": "core",
    "charts_from_labels": "charts",
    "read_labels": "charts",
    "segment_by_normals": "charts",
    "ChartError": "charts",
    "ChartHierarchy": "hierarchy",
}


def __getattr__(name):
    if name in _WHERE:
        import importlib

        return getattr(importlib.import_module(f"ccproof.apps.arap.{_WHERE[name]}"), name)
    raise AttributeError(f"module 'ccproof.apps.arap' has no attribute {name!r}")
