"""Isoparameter lines of the three parameterizations around a vertex (bmz04 Figs. 2, 4, 5).

Matplotlib is imported inside the functions, so that importing this module stays cheap.
"""

from __future__ import annotations

import numpy as np

from ccproof.errors import CCProofError

__all__ = ["isoparameter_lines", "plot_isoparameter_lines"]

_CORNER_UV = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])


def isoparameter_lines(surface, vertex, parameterization="natural", n_lines=16, n_samples=257):
    """Polylines u = i/n_lines and v = j/n_lines of every face around ``vertex``, on the limit surface.

    Parameters
    ----------
    surface : LimitSurface
        A surface of an all-quad mesh (from ``ccproof.limit_surface`` for the names "vanishing" and
        "characteristic"; any quad mesh's surface takes a :class:`ccproof.reparam.Parameterization`).
    vertex : int
    parameterization : {"natural", "vanishing", "characteristic"}
        The parameterization whose lines u = const, v = const are drawn (bmz04 Figs. 2, 4, 5).
    n_lines : int
        Lines per direction and face (the face edges included).
    n_samples : int
        Points per line; they are denser near the vertex (quadratic spacing) so that the
        behaviour of bmz04 section 3 is visible.

    Returns
    -------
    lines : list of ndarray, shape (n_samples, 3)
        2 (n_lines + 1) lines per face around the vertex.
    is_edge : list of bool
        Whether the line is a face edge (u or v in {0, 1}).

    Examples
    --------
    >>> from ccproof.mesh.examples import k_regular_disk
    >>> from ccproof.reparam import limit_surface
    >>> S = limit_surface(k_regular_disk(5, 2))
    >>> lines, is_edge = isoparameter_lines(S, 0, "characteristic", n_lines=2, n_samples=5)
    >>> len(lines), lines[0].shape, sum(is_edge)        # 5 faces x 2 directions x 3 lines, 2 of 3 are edges
    (30, (5, 3), 20)
    """
    mesh = surface.mesh
    if not 0 <= int(vertex) < mesh.n_vertices:
        raise CCProofError(f"vertex {vertex} out of range [0, {mesh.n_vertices})")
    kw = {} if parameterization == "natural" else {"parameterization": parameterization}
    _, _, faces = mesh.one_ring(int(vertex))
    t = np.linspace(0.0, 1.0, n_samples) ** 2  # dense at the vertex end
    lines, is_edge = [], []
    for f in faces:
        i = int(np.flatnonzero(mesh.faces[f] == vertex)[0])
        c = _CORNER_UV[i]
        a = _CORNER_UV[(i + 1) % 4] - c
        b = _CORNER_UV[(i + 3) % 4] - c
        for k in range(n_lines + 1):
            s = k / n_lines
            for d0, d1 in ((a, b), (b, a)):
                uv = c + np.outer(t, d0) + s * d1
                uv = np.clip(uv, 0.0, 1.0)
                P = surface.evaluate(np.full(n_samples, f), uv[:, 0], uv[:, 1], 0, **kw)["P"]
                lines.append(P)
                is_edge.append(k in (0, n_lines))
    return lines, is_edge


def plot_isoparameter_lines(surface, vertex, path, parameterization="natural", n_lines=16, title=None):
    """Draw :func:`isoparameter_lines` projected on the tangent plane at the vertex; save to ``path``.

    The view is the limit tangent plane at the vertex (axes: the direction of the first edge
    neighbour and its normal complement), as in bmz04 Figs. 2, 4, 5 for planar k-regular meshes.
    ``title`` defaults to the parameterization, the vertex, its kind and valence.

    Parameters
    ----------
    surface : LimitSurface
    vertex : int
        The vertex whose neighbourhood is drawn.
    path : str or pathlib.Path
        Image file (any matplotlib format).
    parameterization : {"natural", "vanishing", "characteristic"}, optional
    n_lines : int, optional
        Isoparameter lines per direction and face.
    title : str, optional

    Returns
    -------
    None

    Examples
    --------
    Drawing takes seconds (matplotlib), so this example is not run:

    >>> from ccproof.mesh.examples import cube
    >>> from ccproof.reparam.surface import limit_surface
    >>> plot_isoparameter_lines(limit_surface(cube()), 0, "cube.png", "characteristic")   # doctest: +SKIP
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    lines, is_edge = isoparameter_lines(surface, vertex, parameterization, n_lines=n_lines)
    L = surface.vertex_limits()[vertex]
    nrm = surface.vertex_normals()[vertex]
    if not np.isfinite(nrm).all():
        nrm = np.array([0.0, 0.0, 1.0])
    e = surface.mesh.one_ring(int(vertex))[0][0]
    x = surface.mesh.vertices[e] - L
    x = x - (x @ nrm) * nrm
    if np.linalg.norm(x) < 1e-300:
        x = np.cross(nrm, [1.0, 0.0, 0.0])
    x /= np.linalg.norm(x)
    y = np.cross(nrm, x)
    fig, ax = plt.subplots(figsize=(6, 6), dpi=150)
    for P, edge in zip(lines, is_edge):
        q = P - L
        ax.plot(q @ x, q @ y, color="k" if edge else "tab:blue", lw=1.1 if edge else 0.45)
    ax.plot([0], [0], "o", color="tab:red", ms=4)
    ax.set_aspect("equal")
    ax.set_axis_off()
    k = int(surface.mesh.valence[vertex])
    kind = "boundary" if surface.mesh.is_boundary_vertex[vertex] else "interior"
    ax.set_title(title or f"{parameterization} parameterization near vertex {vertex} ({kind}, valence {k})",
                 fontsize=9)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
