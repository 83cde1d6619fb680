"""A look at a parameterization instead of a table: checkerboard through the UVs and distortion maps.

:func:`render_preview` draws, for every method (one row each), the sampled limit surface
(:class:`~ccproof.apps.arap.export.SampledSurface`) seen along its smallest principal axis (back
faces culled, painter's order, Lambert shading), three times:

1. a checkerboard texture through the packed UVs (``checks`` squares across [0, 1]), flat per
   triangle (the colour of the triangle's UV centroid), with its number of folded triangles;
2. the area distortion ``log2(s1 s2)`` of every triangle (natural UV scale; 0 = area preserved; a
   diverging map with limits shared by all rows);
3. the stretch ``sqrt((1/s1^2 + 1/s2^2) / 2)`` of every triangle (1 = no stretch, shared limits).

``s1 >= s2`` are the singular values of the triangle's map to the plane
(:func:`~ccproof.apps.arap.metrics.triangle_metrics`). matplotlib, Agg backend.
"""

from __future__ import annotations

import numpy as np

__all__ = ["render_preview", "project"]


def project(points, view=None):
    """Orthographic projection along ``view`` (default: the smallest principal axis of the points).

    Parameters
    ----------
    points : ndarray, shape (n, 3) float64
    view : array_like, shape (3,), optional

    Returns
    -------
    xy : ndarray, shape (n, 2) float64
    depth : ndarray, shape (n,) float64
        Larger depth is nearer the viewer.
    view : ndarray, shape (3,) float64

    Examples
    --------
    Points of the plane z = 0 are seen along the z axis, all at the same depth:

    >>> import numpy as np
    >>> from ccproof.mesh.examples import grid
    >>> xy, depth, view = project(grid(3, 3).vertices)
    >>> np.abs(view).round(12).tolist(), float(np.ptp(depth)), xy.shape
    ([0.0, 0.0, 1.0], 0.0, (16, 2))
    """
    P = np.asarray(points, dtype=np.float64)
    c = P - P.mean(axis=0)
    if view is None:
        w, V = np.linalg.eigh(c.T @ c)
        view = V[:, 0]
        if view[np.argmax(np.abs(view))] < 0:
            view = -view
    view = np.asarray(view, dtype=np.float64)
    view = view / np.linalg.norm(view)
    up = np.array([0.0, 1.0, 0.0]) if abs(view[1]) < 0.9 else np.array([1.0, 0.0, 0.0])
    x = np.cross(up, view)
    x /= np.linalg.norm(x)
    y = np.cross(view, x)
    return np.stack([c @ x, c @ y], axis=1), c @ view, view


def _draw(ax, xy, depth, T, colors, normals, view):
    from matplotlib.collections import PolyCollection

    facing = normals @ view
    keep = np.flatnonzero(facing > 0)
    order = keep[np.argsort(depth[T[keep]].mean(axis=1))]
    shade = (0.35 + 0.65 * facing[order] / np.linalg.norm(normals[order], axis=1))[:, None]
    col = np.clip(colors[order, :3] * shade, 0, 1)
    pc = PolyCollection(xy[T[order]], facecolors=col, edgecolors="none", antialiased=False)
    ax.add_collection(pc)
    ax.set_xlim(xy[:, 0].min(), xy[:, 0].max())
    ax.set_ylim(xy[:, 1].min(), xy[:, 1].max())
    ax.set_aspect("equal")
    ax.set_xticks([])
    ax.set_yticks([])


def render_preview(path, surfaces, names=None, title=None, checks=None, view=None, dpi=110):
    """Write a PNG with one row per method: checkerboard, area distortion, stretch (module docstring).

    Parameters
    ----------
    path : str, the PNG file
    surfaces : dict method -> SampledSurface
    names : dict method -> row title, optional
    checks : int, optional
        Checkerboard squares across [0, 1] (default: about 5 triangles per square side on the coarsest
        surface, 4 to 24).

    Examples
    --------
    Rendering takes seconds (matplotlib), so this example is not run:

    >>> from ccproof.mesh.examples import grid
    >>> from ccproof.apps.arap.meshes import LevelPlan, compare
    >>> from ccproof.apps.arap.export import sampled_surface
    >>> res, _ = compare(grid(3, 3), methods=("c",), plan=LevelPlan(levels=1, eval_level=3))
    >>> render_preview("preview.png", {"c": sampled_surface(res["c"], level=2)})   # doctest: +SKIP
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib import cm
    from matplotlib.colors import Normalize

    names = names or {}
    data = {}
    for m, s in surfaces.items():
        T = s.triangles()
        met, per = s.metrics(per_triangle=True)
        P = s.points
        nrm = np.cross(P[T[:, 1]] - P[T[:, 0]], P[T[:, 2]] - P[T[:, 0]])
        data[m] = (T, per, nrm, met)
    allp = np.concatenate([s.points for s in surfaces.values()])
    _, _, view = project(allp, view)
    la = np.concatenate([np.log2(np.abs(d[1]["s1"] * d[1]["s2"])) for d in data.values()])
    st = np.concatenate([d[1]["stretch"] for d in data.values()])
    amax = float(np.nanpercentile(np.abs(la), 99)) or 1e-6
    smax = float(np.nanpercentile(st, 99))
    smax = smax if smax > 1 + 1e-9 else 1 + 1e-6
    if checks is None:
        n = min(d[0].shape[0] for d in data.values())
        checks = int(np.clip(np.sqrt(n / 2) / 5, 4, 24))
    rows = len(surfaces)
    fig, axes = plt.subplots(rows, 3, figsize=(13, 4.2 * rows), squeeze=False, layout="constrained")
    anorm, snorm = Normalize(-amax, amax), Normalize(1.0, smax)
    for r, (m, s) in enumerate(surfaces.items()):
        T, per, nrm, met = data[m]
        xy, depth, _ = project(s.points, view)
        c = s.uv[T].mean(axis=1)
        chk = ((np.floor(c[:, 0] * checks) + np.floor(c[:, 1] * checks)) % 2).astype(bool)
        ccol = np.where(chk[:, None], [0.92, 0.92, 0.92], [0.85, 0.25, 0.2])
        acol = cm.coolwarm(anorm(np.nan_to_num(np.log2(np.abs(per["s1"] * per["s2"])))))
        scol = cm.viridis(snorm(np.nan_to_num(per["stretch"], nan=1.0)))
        label = names.get(m, m)
        for ax, col, sub in (
            (axes[r, 0], ccol, f"{label}\nlevel {s.level}, {T.shape[0]:,} triangles, {s.folds()} folded"),
            (axes[r, 1], acol, f"area distortion log2(s1 s2); E_area {met.E_area:.6f}"),
            (axes[r, 2], scol, f"stretch; E_stretch {met.E_stretch:.6f}"),
        ):
            _draw(ax, xy, depth, T, np.asarray(col, dtype=np.float64), nrm, view)
            ax.set_title(sub, fontsize=9)
    fig.colorbar(cm.ScalarMappable(anorm, cm.coolwarm), ax=axes[:, 1].tolist(), shrink=0.5, label="log2(s1 s2)")
    fig.colorbar(cm.ScalarMappable(snorm, cm.viridis), ax=axes[:, 2].tolist(), shrink=0.5, label="stretch")
    if title:
        fig.suptitle(title, fontsize=10)
    fig.savefig(path, dpi=dpi)
    plt.close(fig)
    return path
