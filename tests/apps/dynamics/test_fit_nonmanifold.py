"""Non-manifold start meshes in ``fit_points`` / ``ccproof fit``: the copies of one file vertex (the split
mesh's, one per fan) are one degree of freedom, and the written control mesh is in the file's numbering."""

from pathlib import Path

import numpy as np
import pytest

from ccproof.apps.control_file import read_control_mesh, write_control_obj
from ccproof.apps.dynamics.cloud import limit_surface_mesh
from ccproof.apps.dynamics.fit import Evolution, fit_points
from ccproof.apps.dynamics.integrate import ImplicitIntegrator, MatrixSystem
from ccproof.mesh.io import read_obj_polygons

MESHES = Path(__file__).resolve().parents[2] / "data" / "osd_nonmanifold" / "meshes"


def _cloud(V, seed=1, m=300):
    rng = np.random.default_rng(seed)
    return V[rng.integers(0, len(V), m)] + 0.3 * rng.normal(size=(m, 3))


def _file_edges(polygons):
    return {tuple(sorted((f[i], f[(i + 1) % len(f)]))) for f in polygons for i in range(len(f))}


def test_integrator_copies_closed_form():
    # massless step (D + 2 dt K) p = 2 dt f + D p_prev with rows 0 and 1 tied: one unknown y,
    # (d0 + d1 + 2 dt (k0 + k1)) y = 2 dt (f0 + f1) + d0 p0 + d1 p1 (the tied system pulled back by E^T)
    dt = 0.5
    sysm = MatrixSystem(M=np.zeros((3, 3)), D=np.diag([1.0, 2.0, 1.0]), K=np.diag([1.0, 3.0, 2.0]))
    P0 = np.array([[1.0], [1.0], [4.0]])
    integ = ImplicitIntegrator(sysm, dt, P=P0, scheme="massless", copies=[0, 0, 1])
    integ.step(force=np.array([[1.0], [-3.0], [2.0]]))
    y = (2 * dt * (1.0 - 3.0) + 1.0 * 1.0 + 2.0 * 1.0) / (1.0 + 2.0 + 2 * dt * (1.0 + 3.0))
    z = (2 * dt * 2.0 + 1.0 * 4.0) / (1.0 + 2 * dt * 2.0)
    assert integ.P[:, 0].tolist() == pytest.approx([y, y, z], rel=1e-12)


@pytest.mark.parametrize("name", ["bowtie", "book4"])
def test_fit_copies_stay_together(name):
    path = MESHES / f"{name}.obj"
    V, polygons, _ = read_obj_polygons(path)
    mesh, origin = read_control_mesh(path)
    assert origin is None and mesh.n_vertices > len(V)  # split: copies exist
    fv = mesh.file_vertex
    # every control vertex sits where its file vertex is, and every file vertex has a copy
    assert np.array_equal(np.asarray(mesh.vertices), V[fv]) and sorted(set(fv.tolist())) == list(range(len(V)))
    res = fit_points(_cloud(V), init=mesh, levels=0, evolution=Evolution(max_steps=5))
    P = np.asarray(res.mesh.vertices)
    assert np.abs(P - V[fv]).max() > 0.1  # the fit moved the control points
    for k in range(len(V)):  # the copies of one file vertex end at one point, bit for bit
        assert (P[fv == k] == P[fv == k][0]).all(), k
    assert np.array_equal(res.mesh.file_vertex, fv)


def test_fit_copies_refined_level():
    # bowtie refined: 17 file vertices + 24 file edges + 8 faces = 49 vertices of the file's refined mesh
    path = MESHES / "bowtie.obj"
    V, polygons, _ = read_obj_polygons(path)
    mesh, _ = read_control_mesh(path)
    res = fit_points(_cloud(V), init=mesh, levels=1, evolution=Evolution(max_steps=3))
    fv = res.mesh.file_vertex
    n_file = len(V) + len(_file_edges(polygons)) + len(polygons)
    assert n_file == 49 and res.mesh.n_vertices == 50 and int(fv.max()) + 1 == n_file
    P = np.asarray(res.mesh.vertices)
    for k in range(n_file):
        assert (P[fv == k] == P[fv == k][0]).all(), k


def test_fit_written_in_file_numbering(tmp_path):
    path = MESHES / "book4.obj"
    V, polygons, _ = read_obj_polygons(path)
    mesh, _ = read_control_mesh(path)
    res = fit_points(_cloud(V), init=mesh, levels=0, evolution=Evolution(max_steps=3))
    out = tmp_path / "fit.obj"
    write_control_obj(out, res.mesh)
    W, wpolys, _ = read_obj_polygons(out)
    assert W.shape == V.shape and wpolys == polygons  # the file's vertices and faces, in its numbering
    fv = res.mesh.file_vertex
    assert np.array_equal(W[fv], np.asarray(res.mesh.vertices))
    # read back, it is the same control mesh and limit surface
    back, _ = read_control_mesh(out)
    assert np.array_equal(np.asarray(back.vertices), np.asarray(res.mesh.vertices))
    assert np.array_equal(back.faces, res.mesh.faces)
    s0, s1 = limit_surface_mesh(res.mesh, 2), limit_surface_mesh(back, 2)
    assert np.array_equal(np.asarray(s0.vertices), np.asarray(s1.vertices))


def test_cli_fit_nonmanifold(tmp_path):
    from ccproof.cli import main

    path = MESHES / "bowtie.obj"
    V, polygons, _ = read_obj_polygons(path)
    pts = tmp_path / "pts.xyz"
    np.savetxt(pts, _cloud(V))
    out = tmp_path / "fit.obj"
    rc = main(["fit", str(pts), "--init", str(path), "--levels", "0", "--max-steps", "3", "--out", str(out),
               "--no-progress"])
    W, wpolys, _ = read_obj_polygons(out)
    assert rc == 0 and W.shape == V.shape and wpolys == polygons
    assert "17 control vertices" in out.read_text().splitlines()[0]


@pytest.mark.parametrize("name", ["book4", "book4_tags", "bowtie", "dupface", "flipped", "two_cubes",
                                  "two_cubes_creases", "collapsed"])
def test_written_control_mesh_reads_back(tmp_path, name):
    """``write_control_obj`` of the split control mesh: the copies merged (the file's vertex count), except for
    collapsed (degenerate faces: written split); read back, the same split mesh size and limit surface."""
    from ccproof.apps.control_file import merge_labels

    path = MESHES / f"{name}.obj"
    V, _, _ = read_obj_polygons(path)
    mesh, _ = read_control_mesh(path)
    out = tmp_path / "m.obj"
    write_control_obj(out, mesh)
    W, _, _ = read_obj_polygons(out)
    if name == "collapsed":  # a global step first; its merged faces would repeat a vertex
        assert merge_labels(mesh) is None and len(W) == mesh.n_vertices
    else:
        assert len(W) == len(V) < mesh.n_vertices
    back, _ = read_control_mesh(out)
    assert back.n_vertices == mesh.n_vertices and back.n_faces == mesh.n_faces
    s0 = np.asarray(limit_surface_mesh(mesh, 1).vertices)
    s1 = np.asarray(limit_surface_mesh(back, 1).vertices)
    assert s0.shape == s1.shape
    assert np.abs(np.sort(s0, axis=0) - np.sort(s1, axis=0)).max() <= 1e-15 * np.ptp(V, axis=0).max()
