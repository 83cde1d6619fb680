"""Matplotlib figures of dynamic Catmull-Clark surfaces (the paper's colour code: normal elements yellow,
special elements green). matplotlib is imported lazily.
"""

from __future__ import annotations

import numpy as np

__all__ = ["limit_grid", "draw_surface", "set_equal_axes"]

NORMAL_COLOR = np.array([0.98, 0.85, 0.25])
SPECIAL_COLOR = np.array([0.35, 0.75, 0.35])


def limit_grid(model, P, per_edge=6):
    """Limit-surface points on a ``(per_edge + 1)^2`` grid of every face with a patch.

    Returns ``faces (F,), grid (F, per_edge + 1, per_edge + 1, 3)``.

    Parameters
    ----------
    model : DynamicSurface
    P : ndarray, shape (n_vertices, 3) float64
        The state.
    per_edge : int, optional

    Returns
    -------
    faces : ndarray, shape (F,) int64
    grid : ndarray, shape (F, per_edge + 1, per_edge + 1, 3) float64

    Examples
    --------
    >>> from ccproof.apps.dynamics.meshes import torus_32
    >>> from ccproof.apps.dynamics.model import DynamicSurface
    >>> m = DynamicSurface(torus_32())
    >>> f, G = limit_grid(m, m.vertices, 2)
    >>> f.shape, G.shape
    ((32,), (32, 3, 3, 3))
    """
    faces = np.flatnonzero(model.layout.face_kind > 0)
    g = np.linspace(0.0, 1.0, per_edge + 1)
    uu, vv = np.meshgrid(g, g, indexing="ij")
    F = np.repeat(faces, uu.size)
    U = np.tile(uu.reshape(-1), faces.size)
    V = np.tile(vv.reshape(-1), faces.size)
    pts = model.evaluate(F, U, V, 0, P)["P"]
    return faces, pts.reshape(faces.size, per_edge + 1, per_edge + 1, 3)


def draw_surface(ax, model, P, per_edge=5, light=(0.3, -0.5, 0.8), alpha=1.0, edgecolor="none"):
    """Add the limit surface of state P to a 3D axes as shaded quads (yellow normal, green special).

    The figures of qmv98 section 4 (scripts/qmv98_examples.py).

    Parameters
    ----------
    ax : mpl_toolkits.mplot3d.Axes3D
    model : DynamicSurface
    P : ndarray, shape (n_vertices, 3) float64
    per_edge : int, optional
    light : tuple of 3 float, optional
        Light direction of the shading.
    alpha : float, optional
    edgecolor : str, optional

    Returns
    -------
    None

    Examples
    --------
    Drawing takes seconds (matplotlib), so this example is not run:

    >>> import matplotlib.pyplot as plt  # doctest: +SKIP
    >>> from ccproof.apps.dynamics.meshes import torus_32  # doctest: +SKIP
    >>> from ccproof.apps.dynamics.model import DynamicSurface  # doctest: +SKIP
    >>> m = DynamicSurface(torus_32())  # doctest: +SKIP
    >>> ax = plt.figure().add_subplot(projection="3d")                 # doctest: +SKIP
    >>> draw_surface(ax, m, m.vertices)                                 # doctest: +SKIP
    """
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    faces, G = limit_grid(model, P, per_edge)
    q = np.stack([G[:, :-1, :-1], G[:, 1:, :-1], G[:, 1:, 1:], G[:, :-1, 1:]], axis=3)  # (F, e, e, 4, 3)
    kind = model.layout.face_kind[faces]
    base = np.where((kind == 2)[:, None], SPECIAL_COLOR, NORMAL_COLOR)
    nrm = np.cross(q[..., 2, :] - q[..., 0, :], q[..., 3, :] - q[..., 1, :])
    nrm /= np.maximum(np.linalg.norm(nrm, axis=-1, keepdims=True), 1e-300)
    L = np.asarray(light, dtype=float)
    L /= np.linalg.norm(L)
    shade = 0.35 + 0.65 * np.abs(nrm @ L)
    col = (base[:, None, None, :] * shade[..., None]).reshape(-1, 3)
    polys = q.reshape(-1, 4, 3)
    pc = Poly3DCollection(polys, facecolors=np.c_[col, np.full(len(col), alpha)], edgecolors=edgecolor,
                          linewidths=0.1)
    ax.add_collection3d(pc)
    return polys.reshape(-1, 3)


def set_equal_axes(ax, pts, margin=0.05):
    """Equal aspect ratio around the points; no axes drawn.

    Parameters
    ----------
    ax : mpl_toolkits.mplot3d.Axes3D
    pts : ndarray, shape (n, 3) float64
    margin : float, optional
        Relative margin around the bounding cube.

    Returns
    -------
    None

    Examples
    --------
    Needs matplotlib (seconds to import), so this example is not run:

    >>> import numpy as np  # doctest: +SKIP
    >>> import matplotlib.pyplot as plt  # doctest: +SKIP
    >>> ax = plt.figure().add_subplot(projection="3d")                 # doctest: +SKIP
    >>> set_equal_axes(ax, np.array([[0, 0, 0], [2, 1, 1.0]]))        # doctest: +SKIP
    """
    pts = np.asarray(pts)
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    c = 0.5 * (lo + hi)
    r = 0.5 * float((hi - lo).max()) * (1 + margin)
    ax.set_xlim(c[0] - r, c[0] + r)
    ax.set_ylim(c[1] - r, c[1] + r)
    ax.set_zlim(c[2] - r, c[2] + r)
    try:
        ax.set_box_aspect((1, 1, 1))
    except AttributeError:  # pragma: no cover
        pass
    ax.set_axis_off()
