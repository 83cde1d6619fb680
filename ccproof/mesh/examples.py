"""Small example quad meshes (for tests, figures and benchmarks).

>>> k_regular_disk(5, rings=2)
QuadMesh(31 vertices, 20 faces, 20 boundary edges, 1 extraordinary vertices)
"""

from __future__ import annotations

import numpy as np

from ccproof.errors import CCProofError
from ccproof.mesh.quadmesh import QuadMesh

__all__ = ["k_regular_disk", "grid", "cube", "torus", "l_shape"]


def k_regular_disk(k, rings=3, height=None):
    """Planar k-regular complex R_k (bmz04 section 3): k parallelogram sectors of rings x rings quads.

    Sector j is spanned by e_j = (cos 2 pi j/k, sin 2 pi j/k) and e_{j+1}; its vertex (a, b)
    (``1 <= a <= rings``, ``0 <= b <= rings``) sits at ``a e_j + b e_{j+1}``, the centre (vertex 0)
    at the origin. Vertex index of (j, a, b): ``1 + (j * rings + a - 1) * (rings + 1) + b``. Face
    ``(j * rings + a) * rings + b`` has corners (a, b), (a+1, b), (a+1, b+1), (a, b+1); the faces
    at the centre (a = b = 0) are ``j * rings * rings`` with corner 0 at the centre.

    Parameters
    ----------
    k : int >= 3
    rings : int >= 1
    height : callable, optional
        ``z = height(x, y)`` (vectorized); default 0.

    Returns
    -------
    QuadMesh
        ``1 + k rings (rings + 1)`` vertices ``(n, 3) float64``, ``k rings^2`` faces.

    Examples
    --------
    Vertex (j, a, b) = (1, 1, 0) sits at e_1 = (cos 2 pi/k, sin 2 pi/k):

    >>> import numpy as np
    >>> m = k_regular_disk(6, rings=2)
    >>> m.n_vertices, m.n_faces, bool(np.allclose(m.vertices[1 + 2 * 3], [0.5, np.sqrt(3) / 2, 0]))
    (37, 24, True)
    """
    if int(k) != k or k < 3 or rings < 1:
        raise CCProofError(f"k_regular_disk needs k >= 3 and rings >= 1, got k={k}, rings={rings}")
    k, R = int(k), int(rings)

    def vid(j, a, b):
        j %= k
        if a == 0 and b == 0:
            return 0
        if a == 0:
            return vid(j + 1, b, 0)
        return 1 + (j * R + a - 1) * (R + 1) + b

    n = 1 + k * R * (R + 1)
    V = np.zeros((n, 3))
    for j in range(k):
        ej = np.array([np.cos(2 * np.pi * j / k), np.sin(2 * np.pi * j / k)])
        ej1 = np.array([np.cos(2 * np.pi * (j + 1) / k), np.sin(2 * np.pi * (j + 1) / k)])
        for a in range(1, R + 1):
            for b in range(R + 1):
                V[vid(j, a, b), :2] = a * ej + b * ej1
    F = []
    for j in range(k):
        for a in range(R):
            for b in range(R):
                F.append([vid(j, a, b), vid(j, a + 1, b), vid(j, a + 1, b + 1), vid(j, a, b + 1)])
    if height is not None:
        V[:, 2] = height(V[:, 0], V[:, 1])
    return QuadMesh(V, F)


def grid(nx, ny, height=None):
    """Open ``nx x ny`` grid of unit quads in the plane (vertex ``i + (nx + 1) j`` at (i, j)).

    Parameters
    ----------
    nx, ny : int >= 1
    height : callable, optional
        ``z = height(x, y)`` (vectorized); default 0.

    Returns
    -------
    QuadMesh
        ``(nx + 1)(ny + 1)`` vertices, ``nx ny`` faces; face ``i + nx j`` is
        ``(v(i, j), v(i+1, j), v(i+1, j+1), v(i, j+1))`` (counter-clockwise, normal +z).

    Examples
    --------
    >>> m = grid(2, 3, height=lambda x, y: x * y)
    >>> m.n_vertices, m.n_faces, m.faces[0].tolist(), m.vertices[5].tolist()
    (12, 6, [0, 1, 4, 3], [2.0, 1.0, 2.0])
    """
    xs, ys = np.meshgrid(np.arange(nx + 1.0), np.arange(ny + 1.0))
    V = np.stack([xs.ravel(), ys.ravel(), np.zeros(xs.size)], axis=1)
    if height is not None:
        V[:, 2] = height(V[:, 0], V[:, 1])
    idx = np.arange((nx + 1) * (ny + 1)).reshape(ny + 1, nx + 1)
    F = np.stack([idx[:-1, :-1], idx[:-1, 1:], idx[1:, 1:], idx[1:, :-1]], axis=-1).reshape(-1, 4)
    return QuadMesh(V, F)


def cube():
    """The cube [-1, 1]^3 with outward-facing quads (eight vertices of valence 3).

    Returns
    -------
    QuadMesh
        8 vertices ``(8, 3) float64`` (vertex 0 at (-1, -1, -1), 6 at (1, 1, 1)), 6 faces
        (face 1 is the top, z = 1).

    Examples
    --------
    Its corner limit point (9 V + 4 sum e + sum d) / 24 (bmz04 Fig. 1 masks) is (-1/2, -1/2, -1/2):

    >>> from ccproof.mesh import limit_positions
    >>> c = cube()
    >>> c.vertices[0].tolist(), limit_positions(c)[0].tolist(), c.faces[1].tolist()
    ([-1.0, -1.0, -1.0], [-0.5, -0.5, -0.5], [4, 5, 6, 7])
    """
    V = [[-1, -1, -1], [1, -1, -1], [1, 1, -1], [-1, 1, -1], [-1, -1, 1], [1, -1, 1], [1, 1, 1], [-1, 1, 1]]
    F = [[0, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7]]
    return QuadMesh(V, F)


def torus(n_major=8, n_minor=6, R=2.0, r=0.75):
    """A closed regular torus of ``n_major x n_minor`` quads (every vertex of valence 4).

    Parameters
    ----------
    n_major, n_minor : int >= 3
        Quads around the axis and around the tube.
    R, r : float
        Major and minor radius: vertex ``n_minor i + j`` sits at angle ``2 pi i / n_major`` around the
        z axis and ``2 pi j / n_minor`` around the tube.

    Returns
    -------
    QuadMesh
        ``n_major n_minor`` vertices ``(n, 3) float64`` and as many faces.

    Examples
    --------
    >>> t = torus()
    >>> t.n_vertices, t.n_faces, bool((t.valence == 4).all()), t.vertices[0].tolist()
    (48, 48, True, [2.75, 0.0, 0.0])
    """
    i, j = np.meshgrid(np.arange(n_major), np.arange(n_minor), indexing="ij")
    a, b = 2 * np.pi * i / n_major, 2 * np.pi * j / n_minor
    V = np.stack([(R + r * np.cos(b)) * np.cos(a), (R + r * np.cos(b)) * np.sin(a), r * np.sin(b)], -1)
    idx = np.arange(n_major * n_minor).reshape(n_major, n_minor)
    F = np.stack([idx, np.roll(idx, -1, 0), np.roll(np.roll(idx, -1, 0), -1, 1), np.roll(idx, -1, 1)], -1)
    return QuadMesh(V.reshape(-1, 3), F.reshape(-1, 4))


def l_shape(seed=0, noise=0.15):
    """A 4 x 4 grid minus its top-right 2 x 2 block, randomly perturbed.

    It has a concave boundary vertex with three faces, boundary vertices with one face (the
    convex corners) and regular boundary vertices.

    Parameters
    ----------
    seed : int
        Seed of ``numpy.random.default_rng`` for the perturbation.
    noise : float
        Standard deviation of the Gaussian perturbation of every coordinate.

    Returns
    -------
    QuadMesh
        21 vertices ``(21, 3) float64``, 12 faces.

    Examples
    --------
    >>> m = l_shape()
    >>> m.n_faces, int((m.is_boundary_vertex & (m.face_count == 3)).sum())
    (12, 1)
    """
    rng = np.random.default_rng(seed)
    g = grid(4, 4)
    keep = [f for f in range(16) if not (f % 4 >= 2 and f // 4 >= 2)]
    F = g.faces[keep]
    used = np.unique(F)
    remap = -np.ones(25, dtype=np.int64)
    remap[used] = np.arange(used.size)
    V = g.vertices[used] + noise * rng.normal(size=(used.size, 3))
    return QuadMesh(V, remap[F])
