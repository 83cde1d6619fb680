"""LSCM initialization and the triangle-ARAP baselines (a)/(d).

Expected values: a planar mesh is mapped by a similarity (checked against its own coordinates);
libigl's ``lscm`` and ``arap`` (when installed) as independent implementations.
"""

import importlib.util
import pathlib

import numpy as np
import pytest

from ccproof.apps.arap.core import polygon_arap
from ccproof.apps.arap.lscm import fit_area, lscm, lscm_extend, signed_areas, triangulate_quads
from ccproof.mesh.examples import k_regular_disk

_spec = importlib.util.spec_from_file_location("arap_meshes", pathlib.Path(__file__).with_name("_arap_meshes.py"))
M = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(M)


def _similarity_residual(A, B):
    """Smallest ||s R A + t - B|| over similarities (complex least squares)."""
    a = (A[:, 0] + 1j * A[:, 1]) - (A[:, 0] + 1j * A[:, 1]).mean()
    b = (B[:, 0] + 1j * B[:, 1]) - (B[:, 0] + 1j * B[:, 1]).mean()
    z = np.vdot(a, b) / np.vdot(a, a)
    return np.abs(z * a - b).max() / np.abs(b).max(), abs(z)


def test_lscm_reproduces_a_planar_mesh_up_to_similarity():
    m = k_regular_disk(5, rings=3)
    th = 0.4
    R = np.array([[np.cos(th), 0, -np.sin(th)], [0, 1, 0], [np.sin(th), 0, np.cos(th)]])
    V = m.vertices @ R.T + 2.0  # planar, but not in the xy plane
    T = triangulate_quads(V, m.faces)
    UV = lscm(V, T)
    res, _ = _similarity_residual(m.vertices[:, :2], UV)
    assert res < 1e-10
    assert (signed_areas(UV, T) > 0).all()  # orientation preserving
    UVs = fit_area(UV, V, T)
    _, scale = _similarity_residual(m.vertices[:, :2], UVs)
    assert abs(scale - 1) < 1e-10


def test_lscm_extension_keeps_fixed_points_and_extends_conformally():
    m = k_regular_disk(5, rings=3)
    V = m.vertices
    T = triangulate_quads(V, m.faces)
    fixed = np.flatnonzero(np.linalg.norm(V, axis=1) < 1.5)
    UV = lscm_extend(V, T, fixed, 3.0 * V[fixed, :2], reg=0.0)
    assert np.abs(UV - 3.0 * V[:, :2]).max() < 1e-9


def test_lscm_triangulation_uses_shorter_diagonal():
    V = np.array([[0, 0, 0], [3, 0, 0], [3, 1, 0], [0, 1, 0.0]])
    V2 = np.array([[0, 0, 0], [1, 0, 0], [1.2, 1, 0], [0, 0.2, 0.0]])
    T = triangulate_quads(V, [[0, 1, 2, 3]])
    assert sorted(map(sorted, T.tolist())) == [[0, 1, 2], [0, 2, 3]]  # both diagonals equal: 0-2
    T2 = triangulate_quads(V2, [[0, 1, 2, 3]])
    assert sorted(map(sorted, T2.tolist())) == [[0, 1, 3], [1, 2, 3]]


def test_lscm_matches_libigl():
    igl = pytest.importorskip("igl", reason="libigl not installed (optional extra ccproof[bench])")
    m, _ = M.curved_ev_mesh()
    V = m.vertices
    T = triangulate_quads(V, m.faces)
    UV = lscm(V, T, pins=(1, 60))
    b = np.array([1, 60])
    ref = igl.lscm(V, T, b, UV[b])[0]
    assert np.abs(ref - UV).max() < 1e-8 * np.abs(UV).max()


def test_numpy_triangle_arap_matches_libigl():
    pytest.importorskip("igl", reason="libigl not installed (optional extra ccproof[bench])")
    m, _ = M.curved_ev_mesh()
    V = m.vertices
    T = triangulate_quads(V, m.faces)
    UV0 = fit_area(lscm(V, T), V, T)
    a, ita, _ = polygon_arap(V, T, UV0, "numpy", tol=1e-12, max_iter=5000)
    b, itb, _ = polygon_arap(V, T, UV0, "igl", tol=1e-12, max_iter=5000)
    assert np.abs(a - b).max() < 1e-6 * np.ptp(a)
    # one step from the same start agrees to round-off (same energy, same pin, same local step)
    a1, _, _ = polygon_arap(V, T, UV0, "numpy", tol=0.0, max_iter=1)
    b1, _, _ = polygon_arap(V, T, UV0, "igl", tol=0.0, max_iter=1)
    assert np.abs(a1 - b1).max() < 1e-9 * np.ptp(a1)
