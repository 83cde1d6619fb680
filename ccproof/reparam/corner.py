"""Limit of the derivatives of the characteristic parameterization at an extraordinary vertex.

At an interior vertex of valence k != 4 the natural parameterization f of a face has derivatives
0 (k = 3) or infinite (k >= 5) at the corner, but f o Phi^-1 (bmz04 section 4.3) is differentiable
there. Its derivative at the corner, in the corner's local frame (s along the face edge to the
face's next vertex, t along the edge to its previous vertex), is

    D (f o Phi^-1)(0) = [ f_lam(1, 0), f_lam(0, 1) ],

where f_lam is the lam-eigencomponent of f (docs/readings.md R2). Derivation: write
``f(y) = x0 + sum_a (l_a . C) g_a(y) + (eigencomponents of smaller eigenvalues)`` with
``l_1, l_2`` a basis of left eigenvectors of lam (they live on the vertex's 1-ring), ``g_a`` the
limit functions of the dual right eigenvectors (``l_a . r_b = delta_ab``) and C the control points.
Phi is in the same eigenspace, so ``Phi = M g`` for a 2 x 2 matrix M, and the normalization
Phi(1, 0) = (1, 0), Phi(0, 1) = (0, 1) (R3; the second by the swap symmetry) gives
``M^-1 = [g(1, 0), g(0, 1)] =: G``. Hence ``f o Phi^-1 (t) = x0 + (l . C)^T G t + o(|t|)`` (the
other eigencomponents decay like |t|^(log mu / log lam) with exponent > 1).

The 1-ring left eigenvectors are the closed-form tangent masks of :mod:`ccproof.mesh.masks`
(``A cos(2 pi j/k)`` on e_j, ``cos(2 pi j/k) + cos(2 pi (j+1)/k)`` on d_j, A = 16 lam - 4; and the
same with sines); G depends only on k and is computed once per valence from the exact
subdivision matrix of the evaluator's self-similar corner (:func:`ccproof.evaluate.local.
corner_scheme`): its right lam-eigenvectors (SVD null space of A - lam I in float64, normalized
against the masks), evaluated at the two edge neighbours with the exact limit-position masks
(regular vertices). The mask ``T_k = G^T L`` (shape (2, 2k+1)) then gives the two tangents of any
face corner of valence k directly from the vertex's 1-ring, whatever the rest of the mesh.
"""

from __future__ import annotations

import functools

import numpy as np

from ccproof.errors import CCProofError, check_valence

__all__ = ["corner_ring", "characteristic_tangent_masks", "corner_tangents"]


def corner_ring(mesh, face, corner):
    """The 1-ring of corner ``corner`` of ``face`` in the order [V, e_0..e_{k-1}, d_0..d_{k-1}].

    ``e_0`` is the face's next vertex (local s axis), ``e_1`` its previous vertex (local t axis),
    then counter-clockwise; ``d_j`` is the vertex opposite V in the face between e_j and e_{j+1}
    (``d_0`` is the face's opposite vertex). The ring of the tangent masks of docs/reparam.md
    (bmz04 section 4.3, the characteristic parameterization at a corner).

    Parameters
    ----------
    mesh : QuadMesh
    face : int
    corner : int
        0..3, the corner of ``face`` at the vertex V (an interior vertex).

    Returns
    -------
    ndarray of int, shape (2k + 1,)

    Raises
    ------
    CCProofError
        If V is a boundary vertex.

    Examples
    --------
    >>> from ccproof.mesh.examples import cube
    >>> m = cube()
    >>> ring, f = corner_ring(m, 0, 0), m.faces[0]
    >>> ring.size, [int(ring[i]) for i in (0, 1, 2, 4)] == [int(f[i]) for i in (0, 1, 3, 2)]
    (7, True)
    """
    F = mesh.faces
    v = int(F[face, corner])
    if mesh.is_boundary_vertex[v]:
        raise CCProofError(f"vertex {v} is a boundary vertex: no characteristic-map tangents")
    e, d, fs = mesh.one_ring(v)
    j = int(np.flatnonzero(fs == face)[0])
    e, d = np.roll(e, -j), np.roll(d, -j)
    if e[0] != F[face, (corner + 1) % 4] or e[1] != F[face, (corner + 3) % 4]:  # pragma: no cover
        raise CCProofError(f"face {face}: the 1-ring of vertex {v} is not consistently oriented")
    return np.concatenate([[v], e, d]).astype(np.int64)


def _left_masks(k):
    from ccproof.reparam.quadrant import subdominant_lambda

    lam = subdominant_lambda(k)
    A = 16 * lam - 4
    th = 2 * np.pi * np.arange(k) / k
    L = np.zeros((2, 2 * k + 1))
    L[0, 1 : k + 1] = A * np.cos(th)
    L[0, k + 1 :] = np.cos(th) + np.cos(th + 2 * np.pi / k)
    L[1, 1 : k + 1] = A * np.sin(th)
    L[1, k + 1 :] = np.sin(th) + np.sin(th + 2 * np.pi / k)
    return lam, L


@functools.lru_cache(maxsize=256)
def characteristic_tangent_masks(k):
    """Mask T_k, shape (2, 2k+1), with ``T_k @ X[corner_ring(...)]`` = the two limit derivatives
    d(f o Phi^-1)/ds, d/dt at a corner of valence k (module docstring).

    Parameters
    ----------
    k : int
        Valence, k >= 3 (interior corner).

    Returns
    -------
    ndarray, shape (2, 2k + 1) float64
        Rows d/ds, d/dt; columns in the order of :func:`corner_ring`.

    Examples
    --------
    >>> T = characteristic_tangent_masks(5)
    >>> T.shape, bool(abs(T.sum(axis=1)).max() < 1e-14)      # derivatives of a constant vanish
    ((2, 11), True)
    """
    from ccproof.evaluate.local import corner_scheme, quad_ring
    from ccproof.mesh import limit_positions
    from ccproof.mesh.examples import k_regular_disk

    k = check_valence(k)
    if k == 4:
        raise CCProofError("valence 4 is regular: the characteristic parameterization is the natural one there")
    disk = k_regular_disk(k, rings=3)
    ring, key = quad_ring(disk.faces, 0, 0)
    scheme = corner_scheme(key)
    N = len(ring)
    A = np.array([[int(x.p) / int(x.q) for x in row] for row in scheme.A.tolist()])
    order = corner_ring(disk, 0, 0)
    pos = {int(v): i for i, v in enumerate(ring)}
    idx = np.array([pos[int(v)] for v in order])
    lam, L1 = _left_masks(k)
    L = np.zeros((2, N))
    L[:, idx] = L1
    if np.abs(L @ A - lam * L).max() > 1e-12 * np.abs(L).max():  # pragma: no cover - closed form check
        raise CCProofError(f"valence {k}: the tangent masks are not left eigenvectors of the corner matrix")
    _, sv, Vt = np.linalg.svd(A - lam * np.eye(N))
    if not (sv[-2] < 1e-12 < 1e-6 < sv[-3]):  # pragma: no cover - lam is a double, isolated eigenvalue
        raise CCProofError(f"valence {k}: lam is not an isolated double eigenvalue ({sv[-3:]})")
    R = Vt[-2:].T
    R = R @ np.linalg.inv(L @ R)  # dual basis: L R = I
    vals = np.zeros((disk.n_vertices, 3))
    vals[np.asarray(ring), :2] = R
    lim = limit_positions(disk, vals)
    G = np.array([lim[order[1], :2], lim[order[2], :2]]).T  # G[a, col] = g_a(edge neighbour col)
    T = G.T @ L1
    T.setflags(write=False)
    return T


def corner_tangents(mesh, face, corner):
    """d(f o Phi^-1)/ds and d/dt at corner ``corner`` of ``face`` (local corner frame), shape (2, 3).

    The vertex must be interior with valence != 4: :func:`characteristic_tangent_masks` applied to
    :func:`corner_ring` (docs/reparam.md; bmz04 section 4.3).

    Parameters
    ----------
    mesh : QuadMesh
    face : int
    corner : int
        0..3.

    Returns
    -------
    ndarray, shape (2, 3) float64

    Examples
    --------
    At a corner of the cube with corners (+-1, +-1, +-1) the tangent plane is orthogonal to the
    diagonal (1, 1, 1), by symmetry:

    >>> from ccproof.mesh.examples import cube
    >>> T = corner_tangents(cube(), 0, 0)
    >>> T.shape, bool(np.abs(T @ np.ones(3)).max() < 1e-14), bool(np.linalg.matrix_rank(T) == 2)
    ((2, 3), True, True)
    """
    ring = corner_ring(mesh, face, corner)
    k = (ring.size - 1) // 2
    return characteristic_tangent_masks(k) @ mesh.vertices[ring]
