"""The hemispherical shell with an 18-degree hole: a Kirchhoff-Love shell with curved free edges, on a
regular grid and with extraordinary vertices (valence 3 and 5) beside the free edge at the loads.

Independent references: the sphere itself (the limit passes through it at every vertex, evaluated by
``evaluate``, not by the rows the interpolation solved with), rigid motions (zero energy, and no other
zero-energy mode with two free edges), the symmetry of the problem (equal and opposite radial
displacements under the four forces) and the published displacement under a force (0.0924 with the hole,
0.094 MacNeal and Harder).
"""

import numpy as np
import pytest

from ccproof.apps.iga.quadrature import surface_quadrature
from ccproof.apps.iga.shell import ShellFields, ShellMaterial, point_load, restrict_rule, rigid_motions
from ccproof.apps.iga.shell_hemisphere import (
    HEMISPHERE_HOLE_REFERENCE,
    HEMISPHERE_REFERENCE,
    hemisphere_ev,
    hemisphere_ev_grid,
    hemisphere_grid,
    hemisphere_with_hole,
    solve_free_shell,
)
from ccproof.errors import CCProofError
from ccproof.evaluate import natural_limit_surface

MAT = ShellMaterial(6.825e7, 0.3, 0.04)


def test_grid_interpolates_the_sphere():
    """The limit at every vertex is on the sphere of radius 10 (to 1e-12); between them, on the region's
    quadrature points, within 0.02 of it at 16 x 4 faces and about four times closer at 32 x 8 (measured
    0.0116, 0.0031: O(h^2), the interpolation's end condition at the mesh's boundary rows one row beyond
    the free edges); the region spans latitudes 0 to 72 degrees."""
    dev = []
    for n in (4, 8):
        mesh, region = hemisphere_grid(n)
        S = natural_limit_surface(mesh)
        F = np.asarray(mesh.faces)
        corners = S.evaluate(np.arange(F.shape[0]), np.zeros(F.shape[0]), np.zeros(F.shape[0]))["P"]
        assert np.abs(np.linalg.norm(corners, axis=1) - 10.0).max() < 1e-12
        rule = restrict_rule(surface_quadrature(S, 4, "plain"), region)
        P = S.evaluate(rule.face, rule.u, rule.v)["P"]
        dev.append(np.abs(np.linalg.norm(P, axis=1) - 10.0).max())
        lat = np.degrees(np.arcsin(P[:, 2] / np.linalg.norm(P, axis=1)))
        assert lat.min() > -1e-9 and lat.max() < 72.0 + 1e-6
    assert dev[0] < 0.02 and dev[1] < dev[0] / 3, dev


def test_free_hemisphere_has_exactly_the_rigid_motions():
    """Both edges free: the stiffness has the six rigid motions as null space (K @ R = 0) and no other
    zero-energy mode (the seventh eigenvalue well away from zero)."""
    mesh, region = hemisphere_grid(2)
    S = natural_limit_surface(mesh)
    K = ShellFields(S, restrict_rule(surface_quadrature(S, 4, "plain"), region)).stiffness(MAT)
    R = rigid_motions(mesh.vertices)
    assert abs(K @ R).max() < 1e-12 * abs(K).max() * abs(R).max()
    ev = np.linalg.eigvalsh(K.toarray())
    assert ev[5] < 1e-10 * ev[-1] and ev[6] > 1e-9 * ev[-1], ev[:8] / ev[-1]


def test_loads_symmetric_and_equilibrated():
    """Equal and opposite radial displacements under the four forces; a load that does work on a rigid
    motion (one force alone) is refused."""
    r = hemisphere_with_hole(4)
    w = r["w_all"]
    assert np.allclose(w, r["w"] * np.array([1, -1, 1, -1]), rtol=1e-9, atol=0)
    mesh, region = hemisphere_grid(2)
    S = natural_limit_surface(mesh)
    K = ShellFields(S, restrict_rule(surface_quadrature(S, 4, "plain"), region)).stiffness(MAT)
    b = point_load(S, [8], [0.0], [0.0], [[2.0, 0.0, 0.0]])
    with pytest.raises(CCProofError, match="self-equilibrated"):
        solve_free_shell(K, b, rigid_motions(mesh.vertices))


def test_converges_toward_the_published_displacement():
    """w at 8, 16, 32 faces around: the error against 0.0924 falls at every level and is below 4 % at
    32 x 8 (measured 0.0277, 0.0890)."""
    ws = [hemisphere_with_hole(n)["w"] for n in (2, 4, 8)]
    err = [abs(w / HEMISPHERE_HOLE_REFERENCE - 1) for w in ws]
    assert err[0] > err[1] > err[2] and err[2] < 0.04, ws


def test_ev_grid_has_its_extraordinary_vertices_beside_the_free_edge():
    """Four o-grid blocks: 16 interior vertices of valence 3 (8 of them in the shell) and 8 of valence 5 (the
    blocks' lower corners lie on the mesh's boundary, in the ghost row); the load
    points on the equator, regular, on the sphere at longitudes 0, 90, 180, 270 degrees; every shell face
    with a valence-3 corner touches the equator at level 0."""
    mesh, region, loads = hemisphere_ev_grid(0)
    S = natural_limit_surface(mesh)
    faces = np.asarray(mesh.faces)
    val = np.asarray(mesh.valence)
    interior = ~np.asarray(mesh.is_boundary_vertex)
    assert np.count_nonzero(interior & (val == 3)) == 16 and np.count_nonzero(interior & (val == 5)) == 8
    shell = np.unique(faces[region])
    ev3 = shell[val[shell] == 3]
    assert ev3.size == 8 and (val[loads] == 4).all()
    at = [np.argwhere(faces == v)[0] for v in loads]
    uv = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])[[c for _, c in at]]
    P = S.evaluate([f for f, _ in at], uv[:, 0], uv[:, 1])["P"]
    assert np.allclose(P, 10.0 * np.array([[1, 0, 0], [0, 1, 0], [-1, 0, 0], [0, -1, 0]]), rtol=0, atol=1e-12)
    equator = set(faces[region & np.isin(faces, loads).any(axis=1)].ravel().tolist())
    for v in ev3:  # the valence-3 vertex's shell faces: one of them reaches the load point's block edge
        assert any(set(f) & equator for f in faces[region & (faces == v).any(axis=1)].tolist())


def test_ev_hemisphere_converges_toward_the_published_displacement():
    """With the blocks, levels 0 and 1: symmetric displacements, and the error against 0.0924 falls to
    below 10 % (measured 0.00538, 0.0851; level 2 in the slow test)."""
    r0, r1 = hemisphere_ev(0), hemisphere_ev(1)
    for r in (r0, r1):
        assert np.allclose(r["w_all"], r["w"] * np.array([1, -1, 1, -1]), rtol=1e-9, atol=0)
    e0, e1 = (abs(r["w"] / HEMISPHERE_HOLE_REFERENCE - 1) for r in (r0, r1))
    assert e1 < e0 and e1 < 0.1, (r0["w"], r1["w"])


@pytest.mark.slow
def test_hemisphere_fine_slow():
    """64 x 16 and 128 x 32 faces: within 1.5 % of 0.0924 and 1 % of 0.094, and the last change below
    5e-4 (measured 0.093368, 0.093535)."""
    ws = [hemisphere_with_hole(n)["w"] for n in (16, 32)]
    for w in ws:
        assert abs(w / HEMISPHERE_HOLE_REFERENCE - 1) < 0.015 and abs(w / HEMISPHERE_REFERENCE - 1) < 0.01, ws
    assert abs(ws[1] - ws[0]) < 5e-4
    w2 = hemisphere_ev(2)["w"]  # with the blocks, 5,466 dofs: measured 0.093297
    assert abs(w2 / HEMISPHERE_HOLE_REFERENCE - 1) < 0.015 and abs(w2 - ws[1]) < 5e-4
