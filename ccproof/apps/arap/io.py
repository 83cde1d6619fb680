"""Writing the control-mesh texture: OBJ with per-corner texture coordinates, plus a JSON sidecar.

For other tools prefer :mod:`~ccproof.apps.arap.export` (the limit surface sampled at a level with
exact UVs). This file is for users who subdivide the control mesh themselves; the rule they must
use is written in the header (:data:`RULE_TEXT`).

The OBJ holds the control mesh (``v``), the texture control points of every chart (``vt``; packed
with the transforms of :func:`~ccproof.apps.arap.export.pack_charts` when given, else laid side by
side at their natural ARAP scale), the chart faces as ``f v/vt`` and, for a tagged control mesh
(:class:`~ccproof.apps.control_mesh.TaggedQuadMesh`), its creases, corners and holes as OpenSubdiv's
``t`` lines (:func:`ccproof.mesh.write.obj_tag_lines`: read back by :func:`ccproof.mesh.io.read_obj_tagged`,
the same tags and surface).
Faces in no chart are written without texture. For extended charts the texture of a chart also
has control points on the ring of faces around it (hsh10 section 3.2): they are written as extra
``vt`` lines that no face uses, and the JSON sidecar (``<out>.json``) lists, for every chart, the
global vertex of every texture control point, the subdivision rules and the metrics, so that the
texture can be subdivided with the surface (DeRose et al. 1998) exactly as it was optimized.
"""

from __future__ import annotations

import json
import os

import numpy as np

__all__ = ["write_uv_obj", "layout_offsets", "RULE_TEXT"]

#: the subdivision rule the written texture control points need, per texture rule set
RULE_TEXT = {
    "boundary": (
        "subdivision rule for these vt: Catmull-Clark with every chart boundary treated as a mesh boundary "
        "(edge points of chart boundary edges = midpoints, chart boundary vertices (e0 + 6 V + e1) / 8, "
        "vertices with one chart face kept), i.e. face-varying boundary interpolation 'corners only' "
        "(OpenSubdiv FVAR_LINEAR_CORNERS_ONLY, Blender UV Smooth 'Keep Corners')"
    ),
    "extended": (
        "subdivision rule for these vt: extended charts: subdivide every chart TOGETHER WITH its ring of "
        "neighbouring faces with the surface's own Catmull-Clark rules (the ring's texture points are the vt "
        "lines no face uses; the JSON sidecar lists the control vertex of every texture point). Standard "
        "face-varying subdivision of the chart faces alone does NOT reproduce this texture (it folds); use "
        "the sampled limit surface (ccproof arap --out) or --variant boundary for that"
    ),
}


def layout_offsets(uvs, gap=0.05):
    """Translations placing the charts' texture boxes left to right (gap relative to the width).

    Parameters
    ----------
    uvs : list of ndarray, shape (n_c, 2) float64
    gap : float, optional

    Returns
    -------
    list of ndarray, shape (2,) float64
        One translation per chart.

    Examples
    --------
    The second box (width 1) starts after the first one (width 1) and a gap of 0.5:

    >>> import numpy as np
    >>> offs = layout_offsets([np.array([[0, 0], [1, 1.0]]), np.array([[5, 5], [6, 7.0]])], gap=0.5)
    >>> [(np.round(o, 9) + 0.0).tolist() for o in offs]
    [[0.0, 0.0], [-3.5, -5.0]]
    """
    offs = []
    x = 0.0
    for uv in uvs:
        lo, hi = uv.min(axis=0), uv.max(axis=0)
        offs.append(np.array([x - lo[0], -lo[1]]))
        x += (hi[0] - lo[0]) * (1 + gap) + 1e-12
    return offs


def _texture_points(mesh, texs, transforms, scale):
    """The texture points of the charts (packed by ``transforms`` and ``scale``, or side by side without them),
    the texture point of every corner of every face (-1 outside the charts) and the sidecar's chart entries."""
    uvs = [np.asarray(t.unknowns, dtype=np.float64) for t in texs]
    if transforms is None:
        transforms, scale = [(np.eye(2), o) for o in layout_offsets(uvs)], 1.0
    F = mesh.faces
    face_vt = np.full((mesh.n_faces, 4), -1, dtype=np.int64)
    charts_json, lines_vt, base = [], [], 0
    for tex, uv, (R, off) in zip(texs, uvs, transforms):
        h = tex.hierarchy
        if tex.level != 0:
            raise ValueError("only level-0 textures can be written (method d is evaluation only)")
        uvo = scale * (uv @ np.asarray(R).T + off)
        lines_vt.extend(uvo.tolist())
        loc = np.full(mesh.n_vertices, -1, dtype=np.int64)
        nc = h.n_chart_vertices
        loc[h.unknown_vertices[:nc]] = np.arange(nc)
        face_vt[h.chart_faces] = base + loc[F[h.chart_faces]]
        charts_json.append({"faces": h.chart_faces.tolist(), "rules": tex.rules,
                            "vertices": h.unknown_vertices[: uv.shape[0]].tolist(), "n_chart_vertices": int(nc),
                            "vt_first": int(base), "uv": uvo.tolist()})
        base += uv.shape[0]
    return face_vt, lines_vt, charts_json


def write_uv_obj(path, mesh, result, comment=None, table=None, transforms=None, scale=1.0):
    """Write ``result`` (a :class:`~ccproof.apps.arap.core.MethodResult`) for ``mesh``.

    ``transforms`` (list of (R, t) per chart) and ``scale``: the packing of
    :func:`~ccproof.apps.arap.export.pack_charts` (texture point ``scale * (uv @ R.T + t)``).
    The OBJ of ``ccproof arap`` (docs/hsh10.md); a tagged mesh's tags as ``t`` lines; a non-manifold file's
    split copies of a vertex as one vertex (:func:`~ccproof.apps.control_file.merge_labels`; the sidecar's chart
    ``vertices`` in that numbering). Both files are written atomically (a temporary file in the same folder,
    then ``os.replace``).

    Parameters
    ----------
    path : str or os.PathLike
        The OBJ file.
    mesh : QuadMesh or TaggedQuadMesh
    result : MethodResult
    comment : str, optional
    table : str, optional
        Text written into the header.
    transforms : list of (ndarray (2, 2), ndarray (2,)), optional
    scale : float, optional

    Returns
    -------
    str
        The path of the JSON sidecar.

    Examples
    --------
    >>> import os, tempfile
    >>> from ccproof.mesh.examples import grid
    >>> from ccproof.apps.arap.meshes import LevelPlan, compare
    >>> res, _ = compare(grid(3, 3), methods=("c",), plan=LevelPlan(levels=1, eval_level=3))
    >>> tmp = tempfile.TemporaryDirectory()          # removed when the example ends
    >>> d = tmp.name
    >>> sidecar = write_uv_obj(os.path.join(d, "grid.obj"), grid(3, 3), res["c"])
    >>> sorted(os.listdir(d)), os.path.basename(sidecar)
    (['grid.obj', 'grid.obj.json'], 'grid.obj.json')
    """
    path = os.fspath(path)
    texs = result.textures
    face_vt, lines_vt, charts_json = _texture_points(mesh, texs, transforms, scale)
    if transforms is None:
        scale = 1.0
    from ccproof.apps.control_file import merge_labels, merged_copies
    from ccproof.mesh.write import atomic_path, obj_tag_lines

    V, F, tag_lines = mesh.vertices, mesh.faces, obj_tag_lines(mesh)
    lab = merge_labels(mesh)
    if lab is not None:  # a non-manifold file's split mesh: its copies written as one vertex (the file's numbering)
        V, F, tag_lines = merged_copies(mesh, lab)
        for ch in charts_json:
            ch["vertices"] = lab[np.asarray(ch["vertices"], dtype=np.int64)].tolist()
    with atomic_path(path) as tmp, open(tmp, "w", encoding="utf-8") as fh:
        for c in (comment or "").splitlines():
            fh.write(f"# {c}\n")
        for r in sorted({t.rules for t in texs}):
            fh.write(f"# {RULE_TEXT[r]}\n")
        fh.write(f"# {V.shape[0]} vertices, {F.shape[0]} faces, {len(texs)} charts, {len(lines_vt)} texture points\n")
        fh.writelines(f"v {x:.17g} {y:.17g} {z:.17g}\n" for x, y, z in V.tolist())
        fh.writelines(f"vt {u:.17g} {v:.17g}\n" for u, v in lines_vt)
        for f in range(F.shape[0]):
            if face_vt[f, 0] >= 0:
                fh.write("f " + " ".join(f"{a + 1}/{b + 1}" for a, b in zip(F[f], face_vt[f])) + "\n")
            else:
                fh.write("f " + " ".join(str(a + 1) for a in F[f]) + "\n")
        fh.writelines(tag_lines)
    side = path + ".json"
    with atomic_path(side) as tmp, open(tmp, "w", encoding="utf-8") as fh:
        json.dump({"method": result.method, "rules": {r: RULE_TEXT[r] for r in {t.rules for t in texs}},
                   "uv_scale": float(scale), "charts": charts_json, "table": table or {}}, fh)
    return side
