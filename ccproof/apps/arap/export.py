"""Parameterizations other tools can read: the limit surface sampled at a level, with exact UVs.

What is written (:func:`sampled_surface`, :func:`write_surface`):

* **points**: the limit positions of the level-k vertices of every chart (Catmull-Clark limit
  masks, exact: interior ``(n^2 V + 4 sum e + sum f) / (n (n + 5))``, crease ``(e0 + 4 V + e1) / 6``);
* **UVs**: the limit of the chart's texture at the same vertices, with the texture's own rules
  (surface rules on the extended chart for (c), chart boundary rules for (a), (b), (d)): the
  parameterization evaluated exactly at those parameter points, not a re-subdivision of UVs;
* **cells**: the level-k chart faces, as quads or split into two triangles along the shorter 3D
  diagonal;
* **seams**: every chart has its own copy of its vertices, so a vertex on a chart boundary appears
  once per chart (same position, one UV per chart). Points and UVs have the same index, which is
  what meshio's OBJ reader and per-vertex formats (PLY, VTK, ...) need.

Packing (:func:`pack_charts`, a documented simple packer): every chart keeps the natural scale of
its ARAP texture (texel density is the same on all charts up to ARAP's area distortion), is rotated
by the principal axes of its UVs (a rotation: no distortion, no change of orientation), its
bounding box padded by ``gap`` (relative to the square root of the total box area) and the boxes are
shelf-packed (tallest first, rows of a width chosen among 32 candidates to make the layout the most
square). One common scale ``s`` then maps the layout into ``[0, 1]^2``. Boxes do not overlap, so
charts do not. ``s`` is written to the file header and the JSON sidecar: E_angle and E_stretch are
scale invariant, E_area of the file's UVs is that of the parameterization after dividing them by
``s``.

>>> import numpy as np
>>> uvs = [np.array([[0.0, 0], [2, 0], [2, 1], [0, 1]]), np.array([[0.0, 0], [1, 0], [0, 1]])]
>>> T, s = pack_charts(uvs)
>>> packed = [s * (uv @ R.T + t) for uv, (R, t) in zip(uvs, T)]
>>> all(p.min() >= 0 and p.max() <= 1 for p in packed)
True
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Literal

import numpy as np

from ccproof.apps.arap.lscm import signed_areas, triangulate_quads
from ccproof.apps.arap.metrics import triangle_metrics
from ccproof.apps.arap.samples import limit_operator
from ccproof.errors import CCProofError

if TYPE_CHECKING:
    from ccproof.apps.arap.core import MethodResult

__all__ = ["SampledSurface", "sample_chart", "pack_charts", "sampled_surface", "write_surface", "read_surface",
           "write_uv_mesh"]


@dataclass
class SampledSurface:
    """The limit surface of the charts sampled at ``level``, with UVs (see the module docstring).

    Attributes
    ----------
    points : (n, 3) limit positions (chart vertices duplicated per chart)
    uv : (n, 2) packed UVs in [0, 1]^2 (``scale * (uv_raw @ R_c^T + t_c)`` per chart)
    uv_raw : (n, 2) the parameterization's UVs (natural scale, unpacked)
    cells : (m, 3) or (m, 4) int, counter-clockwise as the control faces
    cell_type : "triangle" or "quad"
    chart : (n,) chart of every point; cell_chart : (m,) chart of every cell
    scale : float, the packing scale s
    transforms : list of (R (2, 2), t (2,)) per chart

    Examples
    --------
    >>> from ccproof.mesh.examples import grid
    >>> from ccproof.apps.arap.meshes import LevelPlan, compare
    >>> res, _ = compare(grid(3, 3), methods=("c",), plan=LevelPlan(levels=1, eval_level=3))
    >>> S = sampled_surface(res["c"], level=1)
    >>> S.points.shape, S.cells.shape, S.cell_type, bool(0 <= S.uv.min() and S.uv.max() <= 1)
    ((49, 3), (72, 3), 'triangle', True)
    """

    points: np.ndarray
    uv: np.ndarray
    uv_raw: np.ndarray
    cells: np.ndarray
    cell_type: str
    chart: np.ndarray
    cell_chart: np.ndarray
    level: int
    scale: float
    transforms: list = field(default_factory=list)

    def triangles(self):
        """Triangles (m', 3): the cells, quads split along the shorter 3D diagonal."""
        if self.cell_type == "triangle":
            return self.cells
        return triangulate_quads(self.points, self.cells)

    def metrics(self, raw=True, per_triangle=False):
        """:func:`~ccproof.apps.arap.metrics.triangle_metrics` of the written triangles (``raw``:
        on the unpacked UVs, i.e. the parameterization's scale)."""
        return triangle_metrics(self.points, self.uv_raw if raw else self.uv, self.triangles(), per_triangle)

    def folds(self):
        """Number of triangles with signed UV area <= 0."""
        return int((signed_areas(self.uv, self.triangles()) <= 0).sum())


def sample_chart(tex, level):
    """Limit positions, limit UVs and level-``level`` chart quads of one chart texture.

    Parameters
    ----------
    tex : :class:`~ccproof.apps.arap.core.ChartTexture`
    level : int, >= ``tex.level``

    Returns
    -------
    P : (n, 3), UV : (n, 2), Q : int (m, 4) in local indices (the chart vertices of ``E_level``)

    Examples
    --------
    Level 1 of a 3 x 3 grid has 6 x 6 quads on 7 x 7 vertices:

    >>> from ccproof.mesh.examples import grid
    >>> from ccproof.apps.arap.meshes import LevelPlan, compare
    >>> res, _ = compare(grid(3, 3), methods=("c",), plan=LevelPlan(levels=1, eval_level=3))
    >>> P, UV, Q = sample_chart(res["c"].textures[0], 1)
    >>> P.shape, UV.shape, Q.shape
    ((49, 3), (49, 2), (36, 4))
    """
    if level < tex.level:
        raise CCProofError(f"output level {level} is below the texture's level {tex.level} (method (d) needs >= 3)")
    h = tex.hierarchy
    L = h.level(level)
    X = h.subdivide_values(tex.values, tex.rules, tex.level, level)
    cv = np.flatnonzero(L.chart_vertex)
    loc = np.full(L.n_vertices, -1, dtype=np.int64)
    loc[cv] = np.arange(cv.size)
    UV = (limit_operator(L, tex.rules) @ X)[cv]
    P = (limit_operator(L, "extended") @ L.mesh.vertices)[cv]
    return P, UV, loc[L.chart_faces()]


def _principal_rotation(uv):
    """Rotation (det +1) taking the principal axes of the points to x (longer) and y."""
    c = uv - uv.mean(axis=0)
    w, V = np.linalg.eigh(c.T @ c)
    R = V[:, ::-1].T  # rows: major axis, minor axis
    if np.linalg.det(R) < 0:
        R[1] *= -1
    return R


def pack_charts(uvs, gap=0.02, rotate=True):
    """Shelf packing of the charts' bounding boxes into [0, 1]^2 (module docstring).

    Parameters
    ----------
    uvs : list of (n_c, 2) arrays, the charts' UVs (natural scale)
    gap : float, padding around every box relative to ``sqrt(total box area)``

    Returns
    -------
    transforms : list of (R (2, 2), t (2,)), scale : float
        The packed UVs of chart c are ``scale * (uv_c @ R.T + t)``, inside [0, 1]^2, boxes disjoint.

    Examples
    --------
    >>> import numpy as np
    >>> uvs = [np.array([[0, 0], [2, 1.0]]), np.array([[5, 5], [6, 8.0]])]
    >>> transforms, scale = pack_charts(uvs)
    >>> packed = [scale * (uv @ R.T + t) for uv, (R, t) in zip(uvs, transforms)]
    >>> all(0 <= p.min() and p.max() <= 1 for p in packed)
    True
    """
    if not uvs:
        return [], 1.0
    Rs, lo, size = [], [], []
    for uv in uvs:
        uv = np.asarray(uv, dtype=np.float64)
        R = _principal_rotation(uv) if rotate and uv.shape[0] >= 3 else np.eye(2)
        r = uv @ R.T
        a, b = r.min(axis=0), r.max(axis=0)
        if b[1] - a[1] > b[0] - a[0]:  # landscape boxes pack better on shelves
            R = np.array([[0.0, 1.0], [-1.0, 0.0]]) @ R
            r = uv @ R.T
            a, b = r.min(axis=0), r.max(axis=0)
        Rs.append(R)
        lo.append(a)
        size.append(b - a)
    sizes = np.array(size)
    pad = gap * np.sqrt(max(float(np.prod(sizes, axis=1).sum()), 1e-300))
    box = sizes + 2 * pad
    order = np.argsort(-box[:, 1], kind="stable")

    def shelves(width):
        pos = np.zeros((len(uvs), 2))
        x = y = row_h = 0.0
        used_w = 0.0
        for i in order:
            if x > 0 and x + box[i, 0] > width:
                y += row_h
                x = row_h = 0.0
            pos[i] = (x, y)
            x += box[i, 0]
            used_w = max(used_w, x)
            row_h = max(row_h, box[i, 1])
        return pos, max(used_w, 1e-300), y + row_h

    best: tuple[float, np.ndarray] | None = None
    for width in np.linspace(box[:, 0].max(), box[:, 0].sum(), 32):
        pos, W, H = shelves(width)
        side = max(W, H)
        if best is None or side < best[0]:
            best = (side, pos)
    assert best is not None  # 32 widths were tried
    side, pos = best
    scale = 1.0 / side
    transforms = [(R, p + pad - a) for R, p, a in zip(Rs, pos, lo)]
    return transforms, float(scale)


def sampled_surface(result, level=3, cells="triangle", gap=0.02):
    """The charts of ``result`` (a :class:`~ccproof.apps.arap.core.MethodResult`) as one sampled mesh.

    Parameters
    ----------
    result : MethodResult
    level : int, optional
        Subdivision level of the samples.
    cells : {"triangle", "quad"}, optional
    gap : float, optional
        Padding of :func:`pack_charts`.

    Returns
    -------
    SampledSurface

    Examples
    --------
    >>> from ccproof.mesh.examples import grid
    >>> from ccproof.apps.arap.meshes import LevelPlan, compare
    >>> res, _ = compare(grid(3, 3), methods=("c",), plan=LevelPlan(levels=1, eval_level=3))
    >>> sampled_surface(res["c"], level=1, cells="quad").cells.shape
    (36, 4)
    """
    if cells not in ("triangle", "quad"):
        raise CCProofError(f"cells must be 'triangle' or 'quad', got {cells!r}")
    if getattr(result, "samples", None) is not None and result.sample_level == level:
        parts = result.samples  # computed by compare before the charts' fine levels were released
    else:
        off = getattr(result, "refine", 0)
        parts = [sample_chart(tex, level - off) for tex in result.textures]
    transforms, scale = pack_charts([uv for _, uv, _ in parts], gap)
    pts, raw, packed, cl, chart, cchart = [], [], [], [], [], []
    base = 0
    for c, ((P, UV, Q), (R, t)) in enumerate(zip(parts, transforms)):
        pts.append(P)
        raw.append(UV)
        packed.append(scale * (UV @ R.T + t))
        C = triangulate_quads(P, Q) if cells == "triangle" else Q
        cl.append(C + base)
        chart.append(np.full(P.shape[0], c))
        cchart.append(np.full(C.shape[0], c))
        base += P.shape[0]
    return SampledSurface(
        np.concatenate(pts), np.clip(np.concatenate(packed), 0.0, 1.0), np.concatenate(raw), np.concatenate(cl),
        cells, np.concatenate(chart), np.concatenate(cchart), int(level), scale, transforms,
    )


_CHUNK = 50_000


def _write_rows(fh, tag, A, fmt):
    line = tag + (" " + fmt) * A.shape[1] + "\n"
    for i in range(0, A.shape[0], _CHUNK):
        fh.write("".join(line % tuple(r) for r in A[i : i + _CHUNK].tolist()))


def write_surface(path: str | os.PathLike[str], surf: SampledSurface, comment: str | None = None) -> str:
    """Write a :class:`SampledSurface`.

    ``.obj`` (``v``, ``vt``, ``f i/i ...``; full precision) by this function, any other extension
    through meshio (point data ``uv`` and ``chart``; for PLY, which has scalar vertex properties only,
    ``s`` and ``t``). docs/hsh10.md.

    Parameters
    ----------
    path : str or os.PathLike
    surf : SampledSurface
    comment : str, optional
        A header comment (OBJ).

    Returns
    -------
    str
        ``path``.

    Examples
    --------
    >>> import os, tempfile
    >>> import numpy as np
    >>> from ccproof.mesh.examples import grid
    >>> from ccproof.apps.arap.meshes import LevelPlan, compare
    >>> res, _ = compare(grid(3, 3), methods=("c",), plan=LevelPlan(levels=1, eval_level=3))
    >>> S = sampled_surface(res["c"], level=1)
    >>> tmp = tempfile.TemporaryDirectory()          # removed when the example ends
    >>> path = os.path.join(tmp.name, "surface.obj")
    >>> _ = write_surface(path, S)
    >>> points, uv, cells = read_surface(path)
    >>> bool(np.array_equal(points, S.points) and np.array_equal(uv, S.uv)), cells.shape
    (True, (72, 3))
    """
    path = os.fspath(path)
    if path.lower().endswith(".obj"):
        ch = surf.cell_chart
        with open(path, "w", encoding="utf-8") as fh:
            for line in (comment or "").splitlines():
                fh.write(f"# {line}\n")
            fh.write(f"# limit surface sampled at level {surf.level}: {surf.points.shape[0]} vertices "
                     f"(duplicated per chart at seams), {surf.cells.shape[0]} {surf.cell_type}s, "
                     f"{int(surf.chart.max(initial=-1)) + 1} charts; uv packing scale {surf.scale:.17g}\n")
            _write_rows(fh, "v", surf.points, "%.17g")
            _write_rows(fh, "vt", surf.uv, "%.17g")
            k = surf.cells.shape[1]
            fmt = "f " + " ".join(["%d/%d"] * k) + "\n"
            for c in range(int(ch.max(initial=-1)) + 1):
                fh.write(f"g chart{c}\n")
                C = surf.cells[ch == c] + 1
                for i in range(0, C.shape[0], _CHUNK):  # chunks: memory of the output, not of Python objects
                    B = np.repeat(C[i : i + _CHUNK], 2, axis=1)
                    fh.write("".join(fmt % tuple(r) for r in B.tolist()))
        return path
    try:
        import meshio
    except ImportError as exc:  # pragma: no cover - meshio is a dependency
        raise CCProofError("writing non-OBJ formats needs meshio") from exc
    pdata = {"uv": surf.uv, "chart": surf.chart.astype(np.int32)}
    if path.lower().endswith(".ply"):  # PLY has scalar vertex properties only: s, t (read by Blender, MeshLab)
        pdata = {"s": surf.uv[:, 0].copy(), "t": surf.uv[:, 1].copy(), "chart": pdata["chart"]}
    mesh = meshio.Mesh(
        surf.points, [(surf.cell_type, surf.cells.astype(np.int32))], point_data=pdata,
        cell_data={"chart": [surf.cell_chart.astype(np.int32)]},
    )
    try:
        meshio.write(path, mesh)
    except Exception as exc:
        raise CCProofError(f"meshio cannot write {path!r}: {exc}") from exc
    return path


def read_surface(path):
    """Read a written surface back with meshio: (points (n, 3), uv (n, 2), cells (m, k)).

    Parameters
    ----------
    path : str or os.PathLike
        A file of :func:`write_surface` (OBJ, PLY or any meshio format).

    Returns
    -------
    points : ndarray, shape (n, 3) float64
    uv : ndarray, shape (n, 2) float64
    cells : ndarray, shape (m, 3) or (m, 4) int

    Examples
    --------
    >>> import os, tempfile
    >>> import numpy as np
    >>> from ccproof.mesh.examples import grid
    >>> from ccproof.apps.arap.meshes import LevelPlan, compare
    >>> res, _ = compare(grid(3, 3), methods=("c",), plan=LevelPlan(levels=1, eval_level=3))
    >>> S = sampled_surface(res["c"], level=1, cells="quad")
    >>> tmp = tempfile.TemporaryDirectory()          # removed when the example ends
    >>> path = os.path.join(tmp.name, "surface.ply")
    >>> _ = write_surface(path, S)
    >>> points, uv, cells = read_surface(path)
    >>> bool(np.abs(uv - S.uv).max() < 1e-12), cells.shape
    (True, (36, 4))
    """
    import meshio

    m = meshio.read(os.fspath(path))
    pd = m.point_data
    uv = pd.get("obj:vt", pd.get("uv"))
    if uv is None and "s" in pd and "t" in pd:
        uv = np.column_stack([pd["s"], pd["t"]])
    if uv is None:
        raise CCProofError(f"{path}: no texture coordinates (obj:vt or uv point data)")
    cells = np.concatenate([c.data for c in m.cells])
    return np.asarray(m.points, dtype=np.float64), np.asarray(uv, dtype=np.float64)[:, :2], cells



def write_uv_mesh(path: str | os.PathLike[str], result: MethodResult, level: int = 3,
                  cells: Literal["triangle", "quad"] = "triangle", comment: str | None = None) -> SampledSurface:
    """Write an ARAP parameterization for other tools: the limit surface with its exact UVs.

    The file ``ccproof arap --out`` writes (docs/hsh10.md section 8): the limit positions of the level-``level``
    vertices of every chart, the parameterization's exact limit UVs there (hsh10's texture rules, not a
    re-subdivision), charts packed into [0, 1]^2 (:func:`pack_charts`), seams as duplicated vertices. ``.obj``
    is written directly (``v``, ``vt``, ``f i/i``, 17 significant digits), any other extension through meshio
    (point data ``uv``; PLY: ``s``, ``t``).

    Parameters
    ----------
    path : str or os.PathLike
    result : MethodResult
        Of :func:`~ccproof.apps.arap.meshes.parameterize` (or one method of ``compare``).
    level : int
        Subdivision level of the samples (4^level triangles pairs per control face).
    cells : {"triangle", "quad"}
    comment : str, optional
        Header comment (OBJ).

    Returns
    -------
    SampledSurface
        What was written: ``points`` (n, 3), ``uv`` (n, 2) packed, ``uv_raw`` (n, 2), ``cells`` (m, 3 or 4),
        ``scale`` (the packing scale), ``metrics()`` of the written triangles, ``folds()``.

    Examples
    --------
    >>> import os, tempfile
    >>> import numpy as np
    >>> import ccproof
    >>> from ccproof.mesh.examples import grid
    >>> res = ccproof.parameterize(grid(3, 3), levels=1, eval_level=2)
    >>> tmp = tempfile.TemporaryDirectory()          # removed when the example ends
    >>> S = ccproof.write_uv_mesh(os.path.join(tmp.name, "uv.obj"), res, level=2)
    >>> points, uv, tris = read_surface(os.path.join(tmp.name, "uv.obj"))
    >>> tris.shape, S.folds(), bool(np.array_equal(uv, S.uv))
    ((288, 3), 0, True)
    """
    surf = sampled_surface(result, int(level), cells)
    write_surface(path, surf, comment)
    return surf
