"""The sampled limit surface with UVs that other tools read (ccproof.apps.arap.export).

Independent cross-checks: the file is re-read with meshio (and libigl's readOBJ when the `bench`
extra is installed); UVs are compared with Catmull-Clark limit masks of the mesh layer
(ccproof.mesh.subdivide + limit_positions) applied to the texture as if it were a surface; the
distortion of the file's triangles is recomputed here with numpy's SVD in a local 3D frame.
"""

import importlib.util
import json
import pathlib

import numpy as np
import pytest
from scipy.spatial import cKDTree

from ccproof.apps.arap.core import Solver
from ccproof.apps.arap.export import pack_charts, read_surface, sampled_surface, write_surface
from ccproof.apps.arap.meshes import LevelPlan, compare
from ccproof.cli import main
from ccproof.mesh import QuadMesh, limit_positions, subdivide, write_obj

_spec = importlib.util.spec_from_file_location("arap_meshes", pathlib.Path(__file__).with_name("_arap_meshes.py"))
M = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(M)


@pytest.fixture(scope="module")
def tube_case():
    """Open cylinder cut into two half-tube charts (a seam along two lines), (b) and (c) optimized."""
    m = M.tube(12, 6)
    lab = np.array([0 if (f // 6) < 6 else 1 for f in range(m.n_faces)])
    res, hs = compare(m, lab, ("b", "c"), LevelPlan(levels=2, eval_level=2))
    return m, lab, res


@pytest.fixture(scope="module")
def ev_case():
    m, chart = M.curved_ev_mesh()
    lab = -np.ones(m.n_faces, dtype=int)
    lab[chart] = 0
    res, hs = compare(m, lab, ("b", "c"), LevelPlan(levels=2, eval_level=2))
    return m, lab, res


def _independent_triangle_metrics(P, UV, T):
    """E_angle, E_area, E_stretch of a PL map, from numpy's SVD in an orthonormal frame of each triangle."""
    a, b, c = P[T[:, 0]], P[T[:, 1]], P[T[:, 2]]
    e1 = b - a
    n = np.cross(b - a, c - a)
    area = 0.5 * np.linalg.norm(n, axis=1)
    x = e1 / np.linalg.norm(e1, axis=1)[:, None]
    y = np.cross(n / np.linalg.norm(n, axis=1)[:, None], x)
    D = np.stack([np.stack([np.einsum("ij,ij->i", v, x), np.einsum("ij,ij->i", v, y)], 1) for v in (b - a, c - a)], 2)
    Du = np.stack([UV[T[:, 1]] - UV[T[:, 0]], UV[T[:, 2]] - UV[T[:, 0]]], 2)
    J = Du @ np.linalg.inv(D)
    s = np.linalg.svd(J, compute_uv=False)
    s1, s2 = s[:, 0], s[:, 1]
    W = area.sum()
    tex_area = 0.5 * np.abs(np.linalg.det(Du)).sum()
    e_angle = area @ (s1 / s2 + s2 / s1) / W
    e_area = area @ (s1 * s2 + 1 / (s1 * s2)) / W
    e_stretch = np.sqrt(area @ (0.5 * (1 / s1**2 + 1 / s2**2)) / W) * np.sqrt(tex_area / W)
    return e_angle, e_area, e_stretch


@pytest.mark.parametrize("ext", [".obj", ".vtu", ".ply"])
def test_written_uvs_reread_with_meshio_equal_the_ones_in_memory(tube_case, tmp_path, ext):
    m, lab, res = tube_case
    surf = sampled_surface(res["c"], level=2)
    p = write_surface(tmp_path / f"s{ext}", surf)
    P, UV, C = read_surface(p)
    assert P.shape == surf.points.shape and UV.shape == surf.uv.shape
    tol = 0 if ext != ".ply" else 1e-6  # PLY stores float32 UVs ("s", "t") through meshio
    assert np.abs(UV - surf.uv).max() <= tol and np.abs(P - surf.points).max() <= max(tol, 1e-15)
    assert np.array_equal(C, surf.cells)


def test_written_obj_reads_the_same_in_libigl(tube_case, tmp_path):
    igl = pytest.importorskip("igl", reason="libigl not installed (pip install 'ccproof[bench]')")
    m, lab, res = tube_case
    surf = sampled_surface(res["c"], level=2)
    p = write_surface(tmp_path / "s.obj", surf)
    V, TC, _, F, FTC, _ = igl.readOBJ(str(p))
    assert np.array_equal(V, surf.points) and np.array_equal(TC, surf.uv)
    assert np.array_equal(F, surf.cells) and np.array_equal(FTC, surf.cells)


@pytest.mark.parametrize("method", ["b", "c"])
def test_written_triangles_do_not_fold_and_their_distortion_is_the_in_memory_metric(tube_case, tmp_path, method):
    m, lab, res = tube_case
    for level in (1, 3):
        surf = sampled_surface(res[method], level=level)
        P, UV, T = read_surface(write_surface(tmp_path / f"s{level}.obj", surf))
        a = UV[T[:, 1]] - UV[T[:, 0]]
        b = UV[T[:, 2]] - UV[T[:, 0]]
        assert (a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]).min() > 0  # no folded triangle
        mem = surf.metrics()
        ang, _, st = _independent_triangle_metrics(P, UV, T)
        _, are, _ = _independent_triangle_metrics(P, UV / surf.scale, T)  # E_area at the natural scale
        assert abs(ang - mem.E_angle) < 1e-6 and abs(st - mem.E_stretch) < 1e-6 and abs(are - mem.E_area) < 1e-6
    # the written mesh is a quadrature of the same map: close to the sample metric at that level
    assert abs(surf.metrics().E_area - res[method].metrics.E_area) < 1e-2


def test_charts_are_packed_into_the_unit_square_without_overlap_and_seams_are_duplicated(tube_case):
    m, lab, res = tube_case
    surf = sampled_surface(res["c"], level=2)
    assert surf.uv.min() >= 0 and surf.uv.max() <= 1
    boxes = [(surf.uv[surf.chart == c].min(0), surf.uv[surf.chart == c].max(0)) for c in range(2)]
    (lo0, hi0), (lo1, hi1) = boxes
    assert (hi0 < lo1).any() or (hi1 < lo0).any()  # boxes disjoint along some axis
    assert max(hi0.max(), hi1.max()) > 0.9  # the layout fills the square along one side
    # per chart the packing is a similarity with positive determinant: uv = s (raw R^T + t)
    for c, (R, t) in enumerate(surf.transforms):
        sel = surf.chart == c
        assert np.allclose(surf.uv[sel], surf.scale * (surf.uv_raw[sel] @ R.T + t), atol=1e-14)
        assert np.allclose(R @ R.T, np.eye(2)) and np.linalg.det(R) > 0
    # seam points: the same 3D point in both charts, with one UV per chart
    tree = cKDTree(surf.points[surf.chart == 1])
    d, _ = tree.query(surf.points[surf.chart == 0])
    assert (d < 1e-12).sum() == 2 * (2**2 * 6 + 1)  # two seam lines of 6 * 4 + 1 level-2 points


def test_pack_charts_many_boxes_disjoint():
    rng = np.random.default_rng(1)
    uvs = [rng.random((20, 2)) * rng.uniform(0.1, 3, 2) + rng.uniform(-5, 5, 2) for _ in range(30)]
    T, s = pack_charts(uvs)
    bx = []
    for uv, (R, t) in zip(uvs, T):
        q = s * (uv @ R.T + t)
        assert q.min() >= 0 and q.max() <= 1
        bx.append((q.min(0), q.max(0)))
    for i in range(len(bx)):
        for j in range(i):
            assert (bx[i][1] < bx[j][0]).any() or (bx[j][1] < bx[i][0]).any()


def test_uvs_are_the_exact_limit_of_the_texture(ev_case):
    """Level-1 output of (c) = limit masks of the mesh layer applied to the once-subdivided texture of E_0."""
    m, lab, res = ev_case
    tex = res["c"].textures[0]
    h = tex.hierarchy
    E0 = h.level(0).mesh
    surf = sampled_surface(res["c"], level=1)
    uv3 = np.c_[tex.values, np.zeros(E0.n_vertices)]
    E1 = subdivide(QuadMesh(np.c_[E0.vertices], E0.faces))
    T1 = subdivide(QuadMesh(uv3, E0.faces)).vertices
    P = limit_positions(E1)
    U = limit_positions(E1, T1)[:, :2]
    d, idx = cKDTree(P).query(surf.points)
    assert d.max() < 1e-12  # every written point is a limit point of the surface
    assert np.abs(surf.uv_raw - U[idx]).max() < 1e-12


def test_cli_writes_surface_and_control_mesh(tmp_path, capsys):
    m, chart = M.curved_ev_mesh()
    mp = tmp_path / "ev5.obj"
    write_obj(mp, m)
    lab = -np.ones(m.n_faces, dtype=int)
    lab[chart] = 0
    lp = tmp_path / "ev5.labels"
    lp.write_text("\n".join(map(str, lab)))
    out = tmp_path / "uv.vtu"
    ctl = tmp_path / "ctl.obj"
    rc = main(["arap", str(mp), "--charts", str(lp), "--levels", "2", "--eval-level", "2", "--out", str(out),
               "--out-level", "2", "--control-out", str(ctl)])
    text = capsys.readouterr().out
    assert rc == 0 and "0 folded" in text
    P, UV, C = read_surface(out)
    assert C.shape == (2 * 16 * len(chart), 3) and UV.min() >= 0 and UV.max() <= 1
    info = json.loads((tmp_path / "uv.vtu.json").read_text())
    assert info["folds"] == 0 and info["level"] == 2
    head = ctl.read_text()
    assert "FVAR_LINEAR_CORNERS_ONLY" in head and "does NOT reproduce" not in head


# ---------------------------------------------------------------------------- scale and refinement


def test_memory_budget_is_checked_before_allocating(ev_case):
    from ccproof.apps.arap.hierarchy import ChartHierarchy
    from ccproof.apps.arap.meshes import MemoryBudgetError, estimate_memory

    m, lab, _ = ev_case
    chart = np.flatnonzero(lab >= 0)
    h = ChartHierarchy(m, chart)
    from ccproof.apps.arap.meshes import BASE_BYTES

    e4, e5 = estimate_memory([h], 4), estimate_memory([h], 5)
    assert e5 - BASE_BYTES == pytest.approx(4 * (e4 - BASE_BYTES))  # linear in the faces of the deepest level
    assert h.n_faces(5) == 4 * h.n_faces(4) == 4**5 * h.levels[0].mesh.n_faces
    with pytest.raises(MemoryBudgetError, match=r"--max-memory.*lower --eval-level / --levels / --out-level"):
        compare(m, lab, ("c",), LevelPlan(eval_level=9), max_memory=2e9, hierarchies=[h])
    assert len(h.levels) == 1  # refused before building anything


def test_cli_memory_error_names_the_option(tmp_path, capsys):
    m, chart = M.curved_ev_mesh()
    write_obj(tmp_path / "m.obj", m)
    lab = -np.ones(m.n_faces, dtype=int)
    lab[chart] = 0
    (tmp_path / "l.txt").write_text("\n".join(map(str, lab)))
    rc = main(["arap", str(tmp_path / "m.obj"), "--charts", str(tmp_path / "l.txt"), "--eval-level", "10",
               "--no-progress"])
    assert rc == 2
    err = capsys.readouterr().err
    assert "exceeds the budget 2.00 GB (--max-memory)" in err and "Traceback" not in err


def test_release_and_refine_keep_the_texture(ev_case):
    """Charts processed one at a time give the same numbers; the texture lifted to the refined mesh is
    the same map (same metric samples: the refined mesh's level k - r is the input's level k)."""
    from ccproof.apps.arap.core import lift_to_refined, texture_metrics
    from ccproof.apps.arap.hierarchy import ChartHierarchy
    from ccproof.apps.arap.meshes import refine_mesh

    m, lab, res = ev_case
    r2, _ = compare(m, lab, ("c",), LevelPlan(levels=2, eval_level=2), release=True)
    assert r2["c"].metrics.as_tuple() == pytest.approx(res["c"].metrics.as_tuple(), abs=1e-12)
    tex = res["c"].textures[0]
    rm, rl = refine_mesh(m, lab, 1)
    hf = ChartHierarchy(rm, np.flatnonzero(rl >= 0))
    X = lift_to_refined(tex.hierarchy, tex.unknowns, "extended", hf, 1)
    from ccproof.apps.arap.core import ChartTexture

    texf = ChartTexture(hf, "extended", 0, hf.lift_unknowns(X, "extended"), X)
    a, b = texture_metrics(tex, 3), texture_metrics(texf, 2)
    assert a.samples == b.samples and a.as_tuple() == pytest.approx(b.as_tuple(), abs=1e-10)


def test_refining_the_control_mesh_makes_c_beat_d_on_a_bunny_patch(bunny_path):
    """(d): Liu et al.'s ARAP on the 3x subdivided control mesh, computed here (numpy engine)."""
    from ccproof.apps.arap.charts import grow_patch
    from ccproof.mesh import read_obj

    b = read_obj(bunny_path)
    lab = -np.ones(b.n_faces, dtype=int)
    lab[grow_patch(b, 1000, 4)] = 0
    d = compare(b, lab, ("d",), LevelPlan(eval_level=4), Solver(engine="numpy"))[0]["d"].metrics
    c0 = compare(b, lab, ("c",), LevelPlan(eval_level=4, refine=0))[0]["c"].metrics
    c2 = compare(b, lab, ("c",), LevelPlan(eval_level=4, refine=2))[0]["c"].metrics
    assert c0.E_area > d.E_area  # without refinement (c) is behind (d) here
    assert c2.E_area <= d.E_area and c2.E_stretch <= d.E_stretch
    assert c2.samples == d.samples


def test_preview_png_one_row_per_method(tmp_path, capsys):
    import matplotlib.image as mpimg

    m, chart = M.curved_ev_mesh()
    write_obj(tmp_path / "m.obj", m)
    lab = -np.ones(m.n_faces, dtype=int)
    lab[chart] = 0
    (tmp_path / "l.txt").write_text("\n".join(map(str, lab)))
    png = tmp_path / "p.png"
    rc = main(["arap", str(tmp_path / "m.obj"), "--charts", str(tmp_path / "l.txt"), "--baselines", "--engine",
               "numpy", "--levels", "2", "--eval-level", "3", "--out-level", "2", "--preview", str(png),
               "--refine", "0", "--no-progress"])
    assert rc == 0 and f"wrote {png}" in capsys.readouterr().out
    img = mpimg.imread(png)
    assert img.shape[0] > 1.2 * img.shape[1]  # four rows of three panels (13 x 16.8 inches)
    assert img[..., :3].std() > 0.1  # not blank
