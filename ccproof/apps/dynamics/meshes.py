"""The control meshes of qmv98 (Fig. 6 and the shape-recovery model of section 4.2; docs/qmv98.md B6, Q8).

The paper gives only their sizes; these generators reproduce the sizes (and the valences):

* :func:`paper_initial_model`: the cube subdivided twice, 98 vertices, 96 faces, 8 vertices of
  valence 3 (the initial model of every shape-recovery experiment); once more: 386 / 384;
* :func:`open_surface_valence5` (Fig. 6a): the 5-regular disk of 3 rings, 61 vertices, 45 faces, one
  interior vertex of valence 5;
* :func:`torus_32` (Fig. 6b): an 8 x 4 torus, 32 vertices, 32 faces, all regular;
* :func:`genus2_surface` (Fig. 6c): 542 vertices, 544 faces, eight interior vertices of valence 5
  (genus 2: V - E + F = -2). Two 24 x 12 tori, each with a 4 x 4 block of faces removed, glued along
  the two 16-vertex hole boundaries with a shift of two positions, so that every corner of one hole
  meets a side vertex of the other (3 + 2 = 5 faces) and the valence-5 vertices are isolated;
* :func:`flat_sheet` (Fig. 6d): a 9 x 9 grid of vertices, 64 faces (36 faces carry a patch).

>>> [(m.n_vertices, m.n_faces) for m in (paper_initial_model(), open_surface_valence5(), torus_32(), flat_sheet())]
[(98, 96), (61, 45), (32, 32), (81, 64)]
"""

from __future__ import annotations

import numpy as np

from ccproof.mesh import QuadMesh, subdivide
from ccproof.mesh.examples import cube, grid, k_regular_disk, torus

__all__ = [
    "paper_initial_model",
    "open_surface_valence5",
    "torus_32",
    "genus2_surface",
    "flat_sheet",
]


def paper_initial_model(center=(0.0, 0.0, 0.0), half_extent=1.0, subdivisions=2):
    """The cube ``center +- half_extent`` (scalar or per axis) subdivided ``subdivisions`` times.

    The initial model of the fitting examples of qmv98 section 4 (docs/qmv98.md B6).

    Parameters
    ----------
    center : array_like, shape (3,), optional
    half_extent : float or array_like, shape (3,), optional
    subdivisions : int, optional

    Returns
    -------
    QuadMesh

    Examples
    --------
    >>> m = paper_initial_model()
    >>> m.n_vertices, m.n_faces, int((m.valence == 3).sum())
    (98, 96, 8)
    """
    m = cube()
    V = np.asarray(m.vertices) * np.asarray(half_extent, dtype=np.float64) + np.asarray(center, dtype=np.float64)
    m = m.with_vertices(V)
    for _ in range(int(subdivisions)):
        m = subdivide(m)
    return m


def open_surface_valence5(height=0.0):
    """Fig. 6a of qmv98: 61 vertices, 45 faces, one interior vertex of valence 5 (a 5-regular disk of 3 rings).

    Parameters
    ----------
    height : float, optional
        z of the centre (the disk is planar for 0).

    Returns
    -------
    QuadMesh

    Examples
    --------
    >>> m = open_surface_valence5()
    >>> m.n_vertices, m.n_faces, int(m.valence[~m.is_boundary_vertex].max())
    (61, 45, 5)
    """
    h = None if not height else (lambda x, y: height * np.exp(-(x * x + y * y) / 4.0))
    m = k_regular_disk(5, rings=3, height=h)
    return m.with_vertices(np.asarray(m.vertices) / 3.0)


def torus_32(R=2.0, r=0.75):
    """Fig. 6b of qmv98: the 8 x 4 regular torus (32 vertices, 32 faces).

    Parameters
    ----------
    R, r : float, optional
        Major and minor radius.

    Returns
    -------
    QuadMesh

    Examples
    --------
    Closed and regular: every vertex has valence 4, Euler characteristic 0:

    >>> m = torus_32()
    >>> m.n_vertices, m.n_faces, set(m.valence.tolist()), m.n_vertices - m.n_edges + m.n_faces
    (32, 32, {4}, 0)
    """
    return torus(8, 4, R=R, r=r)


def flat_sheet(size=2.0):
    """Fig. 6d of qmv98: the 9 x 9 vertex sheet (8 x 8 faces) centred at the origin, side ``size``.

    Parameters
    ----------
    size : float, optional

    Returns
    -------
    QuadMesh

    Examples
    --------
    >>> m = flat_sheet()
    >>> m.n_vertices, m.n_faces, m.vertices.min(axis=0).tolist(), m.vertices.max(axis=0).tolist()
    (81, 64, [-1.0, -1.0, 0.0], [1.0, 1.0, 0.0])
    """
    m = grid(8, 8)
    V = np.asarray(m.vertices).copy()
    V[:, :2] = (V[:, :2] / 8.0 - 0.5) * size
    return m.with_vertices(V)


def _hole_loop(mesh):
    """The single boundary loop of ``mesh`` as an ordered vertex list (face on the left)."""
    be = mesh.boundary_edges
    nxt = {int(a): int(b) for a, b in be}
    start = int(be[0, 0])
    loop = [start]
    while nxt[loop[-1]] != start:
        loop.append(nxt[loop[-1]])
    return loop


def genus2_surface(R=1.6, r=0.9, shift=2, smooth=12):
    """Fig. 6c: a genus-2 quad mesh with 542 vertices, 544 faces and 8 isolated valence-5 vertices.

    Parameters
    ----------
    R, r : float
        Radii of the two 24 x 12 tori.
    shift : int
        Offset of the identification of the two 16-vertex hole loops (2: all eight glued corners
        get valence 5 and no face has two of them; 0 would give four valence-6 vertices).
    smooth : int
        Umbrella-smoothing sweeps applied to the vertices within three rings of the seam.

    >>> m = genus2_surface()
    >>> m.n_vertices, m.n_faces, m.n_vertices - m.n_edges + m.n_faces
    (542, 544, -2)
    >>> m.valence[m.extraordinary_vertices].tolist()
    [5, 5, 5, 5, 5, 5, 5, 5]
    """
    nM, nm = 24, 12
    T = torus(nM, nm, R=R, r=r)
    V = np.asarray(T.vertices) - np.array([R + r, 0.0, 0.0])  # outer equator point (i, j) = (0, 0) at x = 0
    F = np.asarray(T.faces)
    hole_i = np.arange(-2, 2) % nM
    hole_j = np.arange(-2, 2) % nm
    hole_faces = (hole_i[:, None] * nm + hole_j[None, :]).reshape(-1)
    inner_i = np.arange(-1, 2) % nM
    inner_j = np.arange(-1, 2) % nm
    inner_v = (inner_i[:, None] * nm + inner_j[None, :]).reshape(-1)
    keep_f = np.setdiff1d(np.arange(F.shape[0]), hole_faces)
    keep_v = np.setdiff1d(np.arange(V.shape[0]), inner_v)
    new_id = np.full(V.shape[0], -1, dtype=np.int64)
    new_id[keep_v] = np.arange(keep_v.size)
    VA = V[keep_v]
    FA = new_id[F[keep_f]]
    A = QuadMesh(VA, FA)
    loop = _hole_loop(A)
    if len(loop) != 16:
        raise AssertionError("hole loop must have 16 vertices")  # pragma: no cover
    # corner of the hole first (a loop vertex with three faces)
    corners = [k for k, v in enumerate(loop) if A.face_count[v] == 3]
    loop = loop[corners[0]:] + loop[: corners[0]]
    nA = VA.shape[0]
    # B: the mirror image x -> -x, faces reversed (same outward orientation); its own vertex ids = A's
    VB = VA * np.array([-1.0, 1.0, 1.0])
    FB = FA[:, ::-1]
    # partner(loop[k]) = B's vertex loop[k - shift]: map B's loop vertex loop[m] -> A's loop[m + shift]
    b_to_c = np.full(nA, -1, dtype=np.int64)
    is_loop = np.zeros(nA, dtype=bool)
    is_loop[loop] = True
    rest = np.flatnonzero(~is_loop)
    b_to_c[rest] = nA + np.arange(rest.size)
    for m_, v in enumerate(loop):
        b_to_c[v] = loop[(m_ + shift) % 16]
    Vc = np.concatenate([VA, VB[rest]])
    for m_, v in enumerate(loop):
        c = loop[(m_ + shift) % 16]
        Vc[c] = 0.5 * (VA[c] + VB[v])
    Fc = np.concatenate([FA, b_to_c[FB]])
    mesh = QuadMesh(Vc, Fc)
    if smooth:
        # relax the seam: umbrella smoothing of the vertices within three rings of the glued loop
        nbr = [[] for _ in range(mesh.n_vertices)]
        for a, b in mesh.edges:
            nbr[a].append(b)
            nbr[b].append(a)
        near = set(loop)
        for _ in range(3):
            near |= {w for v in near for w in nbr[v]}
        near = np.array(sorted(near))
        P = np.array(mesh.vertices)
        for _ in range(int(smooth)):
            P[near] = 0.5 * P[near] + 0.5 * np.array([P[nbr[v]].mean(axis=0) for v in near])
        mesh = mesh.with_vertices(P)
    return mesh
