"""The hemispherical shell with an 18-degree hole (MacNeal and Harder 1985): a shell with curved free edges.

A hemisphere of radius R = 10 (t = 0.04, E = 6.825e7, nu = 0.3) open at the top, where a hole of 18 degrees
around the pole is cut out, and free along the equator: both boundaries are circles (curved) and free, so
the problem has no displacement condition at all. Four radial point forces of magnitude 2 on the equator,
90 degrees apart and alternating in sign (outward along x, inward along y), are self-equilibrated; w is the
radial displacement under a force, published 0.094 (MacNeal and Harder 1985, who computed it for a
hemisphere without the hole) and 0.0924 for the shell with the hole (converged values of Reissner-Mindlin
and Kirchhoff-Love discretizations, e.g. Belytschko et al. 1985, Kiendl et al. 2009).

The whole hemisphere is modelled, without symmetry conditions: a ghost-ring grid closed around (``4 n``
faces around, ``n`` between the equator and the hole, one ghost row of faces beyond each boundary, on the
sphere too), so that every face of the region is a regular bicubic patch and the free edges are knot lines
inside the mesh (the full spline space up to them, docs/iga.md). The control points are solved for so that
the limit surface passes through the sphere at every vertex
(:func:`~ccproof.apps.iga.shell_benchmarks.interpolating_control_points`). The six rigid motions are
removed by the constraint ``R^T c = 0`` on the coefficients (Lagrange multipliers), which the solution
satisfies anyway: the mesh and the loads are symmetric under the reflections ``x -> -x`` and ``y -> -y``
and under the quarter turn about z with the loads' signs flipped, so the symmetric solution has no
component along any rigid motion.

>>> r = hemisphere_with_hole(4)
>>> r["dofs"], round(r["w"], 3)
(330, 0.028)
"""

from __future__ import annotations

import math

import numpy as np
import scipy.sparse as sp

from ccproof.errors import CCProofError

__all__ = ["HEMISPHERE_REFERENCE", "HEMISPHERE_HOLE_REFERENCE", "hemisphere_grid", "hemisphere_with_hole",
           "hemisphere_ev_grid", "hemisphere_ev", "solve_free_shell"]

#: radial displacement under a force, MacNeal and Harder 1985 (computed for the hemisphere without a hole)
HEMISPHERE_REFERENCE = 0.094

#: the same for the hemisphere with the 18-degree hole, converged (Belytschko et al. 1985; Kiendl et al. 2009)
HEMISPHERE_HOLE_REFERENCE = 0.0924


def hemisphere_grid(n, radius=10.0, hole=18.0):
    """The ghost-ring grid of the hemisphere with a hole: ``4 n`` faces around, ``n`` from the equator to
    the hole's edge, one ghost row of faces beyond each.

    Returns
    -------
    mesh : QuadMesh
        Vertex ``i + 4 n j`` at longitude ``2 pi i / (4 n)`` and latitude ``(j - 1) dphi`` (j = 0 .. n + 2;
        rows 1 and n + 1 the equator and the hole's edge), face ``i + 4 n j`` between rows j and j + 1; the
        control points interpolate the sphere at every vertex.
    region : bool (n_faces,)
        The faces of the shell (rows 1 .. n).
    """
    from ccproof.apps.iga.shell_benchmarks import interpolating_control_points
    from ccproof.mesh import QuadMesh

    n = int(n)
    if n < 1:
        raise CCProofError(f"the hemisphere needs n >= 1 faces between the equator and the hole, got {n!r}")
    m = 4 * n
    dphi = math.radians(90.0 - hole) / n
    lam = 2.0 * math.pi * np.arange(m) / m
    phi = dphi * (np.arange(n + 3) - 1.0)
    Lam, Phi = np.meshgrid(lam, phi)  # row j: latitude phi_j
    targets = radius * np.stack([np.cos(Phi) * np.cos(Lam), np.cos(Phi) * np.sin(Lam), np.sin(Phi)], -1)
    targets = targets.reshape(-1, 3)
    idx = np.arange(targets.shape[0]).reshape(n + 3, m)
    nxt = np.roll(idx, -1, axis=1)
    faces = np.stack([idx[:-1], nxt[:-1], nxt[1:], idx[1:]], -1).reshape(-1, 4)
    mesh = QuadMesh(targets, faces)
    mesh = QuadMesh(interpolating_control_points(mesh, targets), faces)
    rows = np.repeat(np.arange(n + 2), m)
    return mesh, (rows >= 1) & (rows <= n)


def hemisphere_ev_grid(level, n=4, radius=10.0, hole=18.0):
    """The hemisphere's grid (:func:`hemisphere_grid`, ``4 n x n`` faces) with an o-grid block centred at each
    load point (:func:`~ccproof.apps.iga.shell_benchmarks.ogrid_block_faces`: per block four vertices of
    valence 3, two in the shell and two in the ghost row below the equator, 0.4 faces from the load point,
    and two of valence 5 at its upper corners, one face above the equator; its lower corners lie on the
    mesh's boundary, beyond the ghost row), subdivided ``level``
    times in the parameter plane and mapped onto the sphere, the control points interpolating it at every
    vertex. The equator (the free edge) runs along mesh edges through the blocks, every vertex on it
    regular; the patches of the extraordinary vertices touch it at level 0.

    The parameter plane is embedded on a cylinder of circumference ``4 n`` (one unit per face around and
    per face row up) so that the blocks across the seam at longitude 0 are built and subdivided without
    wrapping; a vertex's longitude and latitude are its angle and height there.

    Returns
    -------
    mesh : QuadMesh
    region : bool (n_faces,)
        The faces between the equator and the hole's edge.
    loads : ndarray (4,)
        The vertices at longitudes 0, 90, 180, 270 degrees on the equator (the blocks' centres).
    """
    from ccproof.apps.iga.shell_benchmarks import interpolating_control_points, ogrid_block_faces
    from ccproof.mesh import QuadMesh, subdivide

    n = int(n)
    if n < 2:
        raise CCProofError(f"the hemisphere with o-grid blocks needs n >= 2, got {n!r}")
    m = 4 * n
    rho = m / (2.0 * math.pi)
    lam = 2.0 * math.pi * np.arange(m) / m
    Lam, T = np.meshgrid(lam, np.arange(n + 3) - 1.0)
    V = list(np.stack([rho * np.cos(Lam), rho * np.sin(Lam), T], -1).reshape(-1, 3))
    idx = np.arange(len(V)).reshape(n + 3, m)
    nxt = np.roll(idx, -1, axis=1)
    faces = np.stack([idx[:-1], nxt[:-1], nxt[1:], idx[1:]], -1).reshape(-1, 4).tolist()
    centres = [int(idx[1, k * n]) for k in range(4)]
    F = [f for f in faces if not set(f) & set(centres)]
    for k, c in enumerate(centres):
        i = k * n
        B = [idx[0, i - 1], idx[0, (i + 1) % m], idx[2, (i + 1) % m], idx[2, i - 1]]
        M = [idx[0, i], idx[1, (i + 1) % m], idx[2, i], idx[1, i - 1]]
        F += ogrid_block_faces(V, [int(b) for b in B], [int(x) for x in M], c)
    mesh = QuadMesh(np.asarray(V), F)
    for _ in range(int(level)):
        mesh = subdivide(mesh)
    X = np.asarray(mesh.vertices)
    lon, t = np.arctan2(X[:, 1], X[:, 0]), X[:, 2]
    phi = t * math.radians(90.0 - hole) / n
    targets = radius * np.stack([np.cos(phi) * np.cos(lon), np.cos(phi) * np.sin(lon), np.sin(phi)], -1)
    faces = np.asarray(mesh.faces)
    tc = t[faces].mean(axis=1)
    region = (tc > 0.0) & (tc < n)
    loads = [int(np.argmin(np.abs(t) + np.abs(np.angle(np.exp(1j * (lon - a)))))) for a in np.pi / 2 * np.arange(4)]
    return QuadMesh(interpolating_control_points(mesh, targets), faces), region, np.array(loads)


def solve_free_shell(K, b, R):
    """The displacement coefficients c (3 n,) of ``K c = b`` with ``R^T c = 0`` (R (3 n, 6) the rigid motions;
    b must be orthogonal to them: a self-equilibrated load), by a sparse LU of the saddle-point system.

    Raises
    ------
    CCProofError
        If the load is not self-equilibrated (``|R^T b|`` above 1e-10 of ``|R| |b|``) or the system is
        singular (a zero-energy mode besides the rigid motions).
    """
    from scipy.sparse.linalg import splu

    R = np.asarray(R, dtype=np.float64)
    if np.abs(R.T @ b).max() > 1e-10 * np.abs(R).max() * np.abs(b).max() * R.shape[0]:
        raise CCProofError("the load is not self-equilibrated (it does work on a rigid motion)")
    Rs = sp.csr_matrix(R)
    A = sp.bmat([[K, Rs], [Rs.T, None]], format="csc")
    rhs = np.concatenate([b, np.zeros(R.shape[1])])
    try:
        lu = splu(A)
    except RuntimeError as exc:
        raise CCProofError(f"the free shell's stiffness is singular beyond the rigid motions ({exc})") from exc
    y = lu.solve(rhs)
    y += lu.solve(rhs - A @ y)  # one step of iterative refinement (thin shells: condition numbers ~1e12)
    res = np.linalg.norm(A @ y - rhs) / np.linalg.norm(rhs) if np.isfinite(y).all() else np.inf
    if not res <= 1e-8:
        raise CCProofError(f"the free shell's stiffness is singular beyond the rigid motions (residual {res:.3g})")
    return y[:K.shape[0]]


def hemisphere_with_hole(n, order=4, material=None, force=2.0, radius=10.0, hole=18.0):
    """The hemisphere with a hole at ``n`` faces from the equator to the hole (``4 n`` around).

    Returns
    -------
    dict
        ``w``: the outward radial displacement under the outward force at longitude 0 (reference
        :data:`HEMISPHERE_HOLE_REFERENCE`); ``w_all``: the radial displacements under the four forces
        (longitudes 0, 90, 180, 270 degrees; outward positive), ``dofs`` (coefficients less the six rigid
        motions), ``c`` (3 n_vertices,), ``n``.
    """
    from ccproof.apps.iga.quadrature import surface_quadrature
    from ccproof.apps.iga.shell import ShellFields, ShellMaterial, point_load, restrict_rule, rigid_motions
    from ccproof.evaluate import natural_limit_surface

    material = material or ShellMaterial(6.825e7, 0.3, 0.04)
    mesh, region = hemisphere_grid(n, radius, hole)
    S = natural_limit_surface(mesh)
    F = ShellFields(S, restrict_rule(surface_quadrature(S, order, "plain"), region))
    m = 4 * int(n)
    faces = m + np.arange(4) * (m // 4)  # equator row, faces with corner (0, 0) at longitudes 0, 90, 180, 270
    radial = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]])
    sign = np.array([1.0, -1.0, 1.0, -1.0])  # outward, inward, outward, inward
    zero = np.zeros(4)
    b = point_load(S, faces, zero, zero, force * sign[:, None] * radial)
    c = solve_free_shell(F.stiffness(material), b, rigid_motions(mesh.vertices))
    P = S.basis(faces, zero, zero, 0)["P"]
    nv = mesh.n_vertices
    u = np.stack([P @ c[k * nv:(k + 1) * nv] for k in range(3)], 1)
    w_all = np.einsum("ij,ij->i", u, radial)
    return {"w": float(w_all[0]), "w_all": w_all, "dofs": 3 * nv - 6, "c": c, "n": int(n)}


def hemisphere_ev(level, n=4, order=4, depth=4, material=None, force=2.0, radius=10.0, hole=18.0):
    """The hemisphere with a hole on :func:`hemisphere_ev_grid` at ``level`` (``4 n 2^level`` faces around),
    the adaptive rule (``depth`` rings) on the region; the loads and the result as
    :func:`hemisphere_with_hole` (``w``, ``w_all``, ``dofs``, ``c``, ``level``)."""
    from ccproof.apps.iga.quadrature import surface_quadrature
    from ccproof.apps.iga.shell import ShellFields, ShellMaterial, point_load, restrict_rule, rigid_motions
    from ccproof.evaluate import natural_limit_surface

    material = material or ShellMaterial(6.825e7, 0.3, 0.04)
    mesh, region, loads = hemisphere_ev_grid(level, n, radius, hole)
    S = natural_limit_surface(mesh)
    F = ShellFields(S, restrict_rule(surface_quadrature(S, order, "adaptive", depth), region))
    faces = np.asarray(mesh.faces)
    at = [np.argwhere((faces == v) & region[:, None])[0] for v in loads]  # (face, corner) in the shell
    uv = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])[[c for _, c in at]]
    f = np.array([a for a, _ in at])
    radial = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]])
    sign = np.array([1.0, -1.0, 1.0, -1.0])
    b = point_load(S, f, uv[:, 0], uv[:, 1], force * sign[:, None] * radial)
    nv = mesh.n_vertices
    # the ghost row's vertices of the blocks whose functions vanish on the shell: no coefficient
    keep = np.flatnonzero(np.tile(F.fields.W["P"].getnnz(axis=0) > 0, 3))
    K = F.stiffness(material)[keep][:, keep]
    c = np.zeros(3 * nv)
    c[keep] = solve_free_shell(K, b[keep], rigid_motions(mesh.vertices)[keep])
    P = S.basis(f, uv[:, 0], uv[:, 1], 0)["P"]
    u = np.stack([P @ c[k * nv:(k + 1) * nv] for k in range(3)], 1)
    w_all = np.einsum("ij,ij->i", u, radial)
    return {"w": float(w_all[0]), "w_all": w_all, "dofs": int(keep.size) - 6, "c": c, "level": int(level)}
