"""--control-out: the control UVs, subdivided by an independent implementation of OpenSubdiv's face-varying
"corners only" rule (written here from its definition), do not fold at levels 1-3, for --refine 0 and the
default; the rule is the one the library optimizes and measures with; arap reads triangle meshes."""

import importlib.util
import json
import pathlib

import numpy as np
import pytest

from ccproof.apps.arap.charts import write_labels
from ccproof.cli import main
from ccproof.mesh import write_obj

_spec = importlib.util.spec_from_file_location("arap_meshes", pathlib.Path(__file__).with_name("_arap_meshes.py"))
M = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(M)


# ----------------------------------------------------------------------------- independent corners-only rule
def read_fvar_obj(path):
    """v, vt and the textured faces' vt indices of an OBJ (faces 'f v/vt ...'; faces without vt skipped)."""
    V, UV, FT = [], [], []
    for line in pathlib.Path(path).read_text().splitlines():
        s = line.split()
        if not s:
            continue
        if s[0] == "v":
            V.append([float(x) for x in s[1:4]])
        elif s[0] == "vt":
            UV.append([float(x) for x in s[1:3]])
        elif s[0] == "f" and "/" in s[1]:
            FT.append([int(c.split("/")[1]) - 1 for c in s[1:]])
    return np.array(V), np.array(UV), FT


def corners_only_step(UV, faces):
    """One Catmull-Clark step of face-varying values with OpenSubdiv's FVAR_LINEAR_CORNERS_ONLY.

    The values form their own mesh (faces of value indices). Face point: the average. Edge with two faces:
    (a + b + two face points) / 4; edge with one face (a face-varying boundary): the midpoint. Value with no
    boundary edge: (Q + 2 R + (n - 3) V) / n (Q: average of the face points, R: of the edge midpoints, n: its
    edges). Value with two boundary edges: if its span is one face, a sharp corner V; else the crease rule
    (e0 + 6 V + e1) / 8 on the other ends of its boundary edges. Anything else (a bowtie): sharp.
    """
    n = len(UV)
    fp = np.array([UV[f].mean(axis=0) for f in faces])
    edges = {}
    for fi, f in enumerate(faces):
        for i in range(len(f)):
            a, b = f[i], f[(i + 1) % len(f)]
            edges.setdefault((min(a, b), max(a, b)), []).append(fi)
    eid = {e: n + len(faces) + k for k, e in enumerate(edges)}
    out = np.zeros((n + len(faces) + len(edges), 2))
    out[n : n + len(faces)] = fp
    vfaces = [[] for _ in range(n)]
    vedges = [[] for _ in range(n)]
    for fi, f in enumerate(faces):
        for a in f:
            vfaces[a].append(fi)
    for (a, b), fs in edges.items():
        out[eid[(a, b)]] = (UV[a] + UV[b]) / 2 if len(fs) == 1 else (UV[a] + UV[b] + fp[fs[0]] + fp[fs[1]]) / 4
        vedges[a].append((b, len(fs) == 1))
        vedges[b].append((a, len(fs) == 1))
    for v in range(n):
        if not vfaces[v]:
            continue
        bnd = [w for w, isb in vedges[v] if isb]
        if not bnd:
            k = len(vedges[v])
            Q = fp[vfaces[v]].mean(axis=0)
            R = np.mean([(UV[v] + UV[w]) / 2 for w, _ in vedges[v]], axis=0)
            out[v] = (Q + 2 * R + (k - 3) * UV[v]) / k
        elif len(bnd) == 2 and len(vfaces[v]) >= 2:
            out[v] = (UV[bnd[0]] + 6 * UV[v] + UV[bnd[1]]) / 8
        else:
            out[v] = UV[v]
    new = []
    for fi, f in enumerate(faces):
        m = len(f)
        for i in range(m):
            a, b, c = f[i - 1], f[i], f[(i + 1) % m]
            new.append([b, eid[(min(b, c), max(b, c))], n + fi, eid[(min(a, b), max(a, b))]])
    return out, new


def folded_triangles(UV, faces):
    """UV triangles with signed area <= 0: the four corner triangles of every quad (either diagonal)."""
    F = np.asarray(faces)
    bad = 0
    for i in range(4):
        a, b, c = UV[F[:, i]], UV[F[:, (i + 1) % 4]], UV[F[:, (i + 3) % 4]]
        cross = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])
        bad += int((cross <= 0).sum())
    return bad


def test_independent_rule_on_a_known_case():
    # a single square value-face: level 1 keeps the corners (sharp), edge points are midpoints
    UV = np.array([[0, 0], [1, 0], [1, 1], [0, 1.0]])
    U1, F1 = corners_only_step(UV, [[0, 1, 2, 3]])
    assert np.allclose(U1[:4], UV) and np.allclose(U1[4], [0.5, 0.5]) and len(F1) == 4
    assert folded_triangles(U1, F1) == 0 and folded_triangles(U1[:, ::-1], F1) == 16


def _case(tmp_path):
    m, chart = M.curved_ev_mesh()
    mp, lp = tmp_path / "ev5.obj", tmp_path / "ev5.labels"
    write_obj(mp, m)
    write_labels(lp, [0 if f in set(chart) else -1 for f in range(m.n_faces)])
    return m, mp, lp


@pytest.mark.parametrize("refine", ["0", pytest.param("auto", marks=pytest.mark.slow)])
def test_control_out_does_not_fold_under_corners_only(tmp_path, capsys, refine):
    m, mp, lp = _case(tmp_path)
    out = tmp_path / "ctl.obj"
    rc = main(["arap", str(mp), "--charts", str(lp), "--levels", "2", "--eval-level", "4", "--refine", refine,
               "--control-out", str(out), "--no-progress"])
    assert rc == 0
    text = capsys.readouterr().out
    assert "what a subdivision tool will see" in text
    header = out.read_text()
    assert "FVAR_LINEAR_CORNERS_ONLY" in header
    V, UV, FT = read_fvar_obj(out)
    assert len(FT) > 0
    U, F = UV, FT
    for level in (1, 2, 3):
        U, F = corners_only_step(U, F)
        assert folded_triangles(U, F) == 0, (refine, level)
    side = json.loads(pathlib.Path(str(out) + ".json").read_text())
    co = side["table"]["control_out"]
    assert co["folds"] == [0, 0, 0]
    # the distortion a tool sees is within 5 % of the exact texture's excess, or the run said it is not
    if co["accepted"]:
        assert max(co["excess_ratio_to_exact"]) <= 1.05


def test_control_out_says_when_the_face_budget_stops_it(tmp_path, capsys):
    m, mp, lp = _case(tmp_path)
    out = tmp_path / "ctl.obj"
    rc = main(["arap", str(mp), "--charts", str(lp), "--levels", "2", "--eval-level", "4", "--refine", "0",
               "--control-out", str(out), "--control-max-faces", "400", "--no-progress"])
    assert rc == 0
    err = capsys.readouterr().err
    # 80 faces: 1 extra subdivision gives 320 <= 400 faces, 2 extra would give 1280
    assert "the next, 2 extra, needs 1280 faces > --control-max-faces 400" in err
    co = json.loads(pathlib.Path(str(out) + ".json").read_text())["table"]["control_out"]
    assert [t["extra"] for t in co["tried"]] == [0, 1] and co["accepted"] is False
    # the last refinement allowed missed the target with the ARAP polish: the minimax ran there, and says so
    mm = co["minimax"]
    assert len(mm["chart_weights"]) == 1 and max(co["excess_ratio_to_exact"]) > 1.05
    assert "minimizing the measured distortion" in out.read_text()


@pytest.mark.slow
def test_default_refine_control_out_meets_the_target(tmp_path, capsys):
    """At the default --refine (and the default --control-extra / --control-max-faces) the written control mesh
    is accepted: no folded UV triangle at levels 1-3 under the independent rule above, every distortion excess
    within 5 % of the exact texture's, no warning, within the face budget."""
    m, mp, lp = _case(tmp_path)
    out = tmp_path / "ctl.obj"
    rc = main(["arap", str(mp), "--charts", str(lp), "--levels", "2", "--eval-level", "4", "--control-out", str(out),
               "--no-progress"])
    assert rc == 0
    cap = capsys.readouterr()
    assert "what a subdivision tool will see" in cap.out
    assert "warning: --control-out" not in cap.out + cap.err
    V, UV, FT = read_fvar_obj(out)
    assert 0 < len(FT) <= 150_000
    U, F = UV, FT
    for level in (1, 2, 3):
        U, F = corners_only_step(U, F)
        assert folded_triangles(U, F) == 0, level
    co = json.loads(pathlib.Path(str(out) + ".json").read_text())["table"]["control_out"]
    assert co["refine"] == 2  # the automatic choice on this 80-face mesh
    assert co["accepted"] is True, co
    assert co["folds"] == [0, 0, 0]
    assert len(co["excess_ratio_to_exact"]) == 3 and max(co["excess_ratio_to_exact"]) <= 1.05, co


def test_library_rule_is_the_independent_rule(tmp_path):
    """The boundary rules with surface_corners=True subdivide the written UVs exactly as the rule above."""
    from ccproof.apps.arap.fvar import ControlOptions, export_control
    from ccproof.apps.arap.io import write_uv_obj
    from ccproof.apps.arap.meshes import LevelPlan, compare

    m, chart = M.curved_ev_mesh()
    labels = np.array([0 if f in set(chart) else -1 for f in range(m.n_faces)])
    res, _ = compare(m, labels, methods=("c",), plan=LevelPlan(levels=2, eval_level=4))
    exp = export_control(res["c"], eval_level=4, options=ControlOptions(max_extra=0))
    tex = exp.textures[0]
    path = tmp_path / "c.obj"
    write_uv_obj(path, exp.mesh, res["c"].__class__("c", exp.textures, 0.0, 0))
    _, UV, FT = read_fvar_obj(path)
    U, F = UV, FT
    h = tex.hierarchy
    for level in (1, 2):
        U, F = corners_only_step(U, F)
        ours = h.subdivide_values(h.lift_unknowns(tex.unknowns, "boundary"), "boundary", 0, level)
        ours = ours[h.level(level).chart_vertex]
        used = np.unique(np.asarray(F))
        a = U[used] - U[used].mean(axis=0)  # the file's charts are translated (laid side by side)
        b = ours - ours.mean(axis=0)
        a, b = a[np.lexsort(a.T)], b[np.lexsort(b.T)]
        assert a.shape == b.shape and np.abs(a - b).max() < 1e-12


def test_arap_reads_triangle_meshes(tmp_path, capsys):
    import meshio

    from ccproof.mesh.examples import grid

    g = grid(4, 4)
    V = g.vertices.copy()
    V[:, 2] = 0.2 * np.sin(V[:, 0]) * np.cos(V[:, 1])
    T = np.r_[g.faces[:, [0, 1, 2]], g.faces[:, [0, 2, 3]]]
    p = tmp_path / "tri.ply"
    meshio.write(p, meshio.Mesh(V, [("triangle", T.astype(np.int32))]))
    out = tmp_path / "uv.obj"
    assert main(["arap", str(p), "--levels", "1", "--eval-level", "3", "--refine", "0", "--out", str(out),
                 "--no-progress"]) == 0
    cap = capsys.readouterr()
    assert "subdivided once (Catmull-Clark) to 96 quads" in cap.err
    assert out.exists()


# ----------------------------------------------------------------------------- OpenSubdiv itself


@pytest.fixture(scope="module")
def osd_driver(tmp_path_factory):
    import shutil
    import subprocess

    if shutil.which("g++") is None or not pathlib.Path("/usr/include/opensubdiv/far/primvarRefiner.h").exists():
        pytest.skip("OpenSubdiv headers (libosd-dev) or g++ not installed")
    exe = tmp_path_factory.mktemp("osd") / "drv"
    src = pathlib.Path(__file__).with_name("osd_fvar_driver.cpp")
    r = subprocess.run(["g++", "-O1", "-std=c++14", str(src), "-o", str(exe), "-losdCPU"], capture_output=True,
                       text=True)
    if r.returncode != 0:
        pytest.skip(f"cannot build the OpenSubdiv driver: {r.stderr[-500:]}")
    return exe


def _osd_subdivide(exe, path, level):
    """OpenSubdiv's level-``level`` values of the textured faces of an OBJ with v/vt (untextured corners get
    values of their own)."""
    import subprocess

    V, F, FT = 0, [], []
    UV = []
    for line in pathlib.Path(path).read_text().splitlines():
        s = line.split()
        if not s:
            continue
        if s[0] == "v":
            V += 1
        elif s[0] == "vt":
            UV.append([float(x) for x in s[1:3]])
        elif s[0] == "f":
            F.append([int(c.split("/")[0]) - 1 for c in s[1:]])
            FT.append([int(c.split("/")[1]) - 1 if "/" in c else -1 for c in s[1:]])
    ui, n = [], len(UV)
    for ft in FT:
        for k in ft:
            ui.append(k if k >= 0 else n)
            n += k < 0
    vals = np.r_[np.array(UV), np.zeros((n - len(UV), 2))]
    inp = (f"{V} {len(F)} {n} {level}\n" + " ".join(str(len(f)) for f in F) + "\n"
           + " ".join(str(v) for f in F for v in f) + "\n" + " ".join(map(str, ui)) + "\n"
           + "\n".join(f"{u:.17g} {v:.17g}" for u, v in vals) + "\n")
    out = subprocess.run([str(exe)], input=inp, capture_output=True, text=True, check=True).stdout.splitlines()
    m = int(out[0])
    U = np.array([[float(x) for x in ln.split()] for ln in out[1 : 1 + m]])
    faces = [[int(x) for x in ln.split()] for ln in out[2 + m :]]
    q = 4**level  # uniform refinement of a quad mesh: the children of face f are q f .. q f + q - 1
    tex = [f for f, ft in enumerate(FT) if ft[0] >= 0]
    return U, [faces[q * f + c] for f in tex for c in range(q)], FT, np.array(UV), tex


def test_opensubdiv_subdivides_the_control_uvs_as_the_rule_and_they_do_not_fold(tmp_path, osd_driver):
    from scipy.spatial import cKDTree

    from ccproof.apps.arap.core import MethodResult
    from ccproof.apps.arap.fvar import ControlOptions, export_control
    from ccproof.apps.arap.io import write_uv_obj
    from ccproof.apps.arap.meshes import LevelPlan, compare

    m, chart = M.curved_ev_mesh()
    labels = np.array([0 if f in set(chart) else -1 for f in range(m.n_faces)])
    res, _ = compare(m, labels, methods=("c",), plan=LevelPlan(levels=2, eval_level=4))
    exp = export_control(res["c"], eval_level=4, options=ControlOptions(max_extra=0))
    path = tmp_path / "c.obj"
    write_uv_obj(path, exp.mesh, MethodResult("c", exp.textures, 0.0, 0))
    for level in (1, 2, 3):
        U, faces, FT, UV, tex = _osd_subdivide(osd_driver, path, level)
        assert folded_triangles(U, faces) == 0, level
        mine, mf = UV, [FT[f] for f in tex]
        for _ in range(level):
            mine, mf = corners_only_step(mine, mf)
        ours = mine[np.unique(np.asarray(mf))]
        theirs = U[np.unique(np.asarray(faces))]
        assert ours.shape == theirs.shape
        # OpenSubdiv accumulates with float32 weights: agreement to ~1e-8 of the UV extent
        tol = 1e-7 * float(np.ptp(ours, axis=0).max())
        assert cKDTree(ours).query(theirs)[0].max() < tol and cKDTree(theirs).query(ours)[0].max() < tol


def test_metric_energy_is_the_measured_distortion_and_its_gradient_matches_differences():
    """The energy metric_polish minimizes, from the invariants |J|^2 and det J, equals the excesses that
    texture_metrics computes from the singular values; its gradient equals central differences."""
    from ccproof.apps.arap.core import ChartTexture, texture_metrics
    from ccproof.apps.arap.fvar import _metric_energy, _metric_system
    from ccproof.apps.arap.hierarchy import ChartHierarchy

    m, chart = M.curved_ev_mesh()
    h = ChartHierarchy(m, chart, surface_corners=True)
    P = m.vertices[h.unknown_vertices[: h.n_chart_vertices]]
    Y = P[:, :2] @ np.array([[1.0, 0.2], [-0.1, 0.9]]) + 0.01 * np.sin(7 * P[:, 2:3])
    B1, B2, w = _metric_system(h, 2)
    wa, wr, ws = 0.7, 1.3, 2.0
    val, grad = _metric_energy(B1, B2, w, (wa, wr, ws))(Y.ravel())
    mt = texture_metrics(ChartTexture(h, "boundary", 0, h.lift_unknowns(Y, "boundary"), Y), 2)
    assert mt.flips == 0
    ref = mt.area * (wa * (mt.E_angle - 2) + wr * (mt.E_area - 2) + ws * (mt.E_stretch**2 - 1) / 2)
    assert abs(val - ref) < 1e-9 * abs(ref)
    f = _metric_energy(B1, B2, w, (wa, wr, ws))
    rng = np.random.default_rng(1)
    for _ in range(3):
        d = rng.standard_normal(Y.size)
        e = 1e-6
        fd = (f(Y.ravel() + e * d)[0] - f(Y.ravel() - e * d)[0]) / (2 * e)
        assert abs(fd - grad @ d) < 1e-5 * max(1.0, abs(fd))
    # a folded texture is outside the energy's domain
    assert f(Y[:, ::-1].ravel())[0] == np.inf


# ----------------------------------------------------------------------------- the minimax over candidates
def _global_ratios(parts, exact):
    """The three excess ratios of a sum of per-chart metrics, from the raw sums (E_stretch: Sander's L2 stretch
    times the square root of the texture-to-surface area ratio)."""
    A = sum(p.area for p in parts)
    ang = sum(p.angle_sum for p in parts) / A
    are = sum(p.area_sum for p in parts) / A
    st = np.sqrt(sum(p.stretch_sum for p in parts) / A) * np.sqrt(sum(p.texture_area for p in parts) / A)
    e = exact
    ex = (e.angle_sum / e.area - 2, e.area_sum / e.area - 2,
          np.sqrt(e.stretch_sum / e.area) * np.sqrt(e.texture_area / e.area) - 1)
    return np.array([(ang - 2) / ex[0], (are - 2) / ex[1], (st - 1) / ex[2]])


def _metrics(area, e_angle, e_area, e_stretch):
    from ccproof.apps.arap.metrics import Metrics

    return Metrics(area=area, angle_sum=area * e_angle, area_sum=area * e_area, stretch_sum=area * e_stretch**2,
                   texture_area=area)


def test_minimax_choice_mixes_charts_to_the_brute_force_optimum():
    """Two equal charts, each with a polish high in E_angle and a candidate high in E_area: no uniform choice
    meets 1.05, one chart on each does (brute force over the 4 choices, computed here from the raw sums)."""
    import itertools

    from ccproof.apps.arap.metrics import minimax_choice

    exact = _metrics(2.0, 2.01, 2.01, 1.01)
    cands = [[_metrics(1.0, 2.0110, 2.0098, 1.0104), _metrics(1.0, 2.0098, 2.0110, 1.0104)] for _ in range(2)]
    ch = minimax_choice(exact, cands)
    got = _global_ratios([c[j] for c, j in zip(cands, ch)], exact).max()
    brute = min(_global_ratios([c[j] for c, j in zip(cands, js)], exact).max()
                for js in itertools.product(range(2), repeat=2))
    uniform = min(_global_ratios([c[j] for c in cands], exact).max() for j in range(2))
    assert sorted(ch) == [0, 1] and abs(got - brute) < 1e-12 and got <= 1.05 < uniform


def test_minimax_choice_is_no_worse_than_any_uniform_choice_and_locally_optimal():
    from ccproof.apps.arap.metrics import minimax_choice

    rng = np.random.default_rng(7)
    exact = _metrics(10.0, 2.01, 2.01, 1.01)
    for _ in range(5):
        cands = [[_metrics(a, 2 + 0.01 * rng.uniform(0.8, 1.3), 2 + 0.01 * rng.uniform(0.8, 1.3),
                           1 + 0.01 * rng.uniform(0.8, 1.3)) for _ in range(int(rng.integers(1, 4)))]
                 for a in rng.uniform(0.5, 2, size=6)]
        ch = minimax_choice(exact, cands)
        worst = _global_ratios([c[j] for c, j in zip(cands, ch)], exact).max()
        for j in range(3):
            uni = [c[j] if j < len(c) else c[0] for c in cands]
            assert worst <= _global_ratios(uni, exact).max() + 1e-12
        for i, c in enumerate(cands):
            for j in range(len(c)):
                alt = [cc[jj] for cc, jj in zip(cands, ch)]
                alt[i] = c[j]
                assert _global_ratios(alt, exact).max() >= worst - 1e-12


def test_export_control_minimax_keeps_no_fold_and_does_not_raise_the_largest_ratio(tmp_path):
    """metric=True on a chart whose ARAP polish misses the target: the largest excess ratio does not rise, the
    written UVs have no folded triangle at levels 1-3 under the independent rule, and the ARAP-only metrics are
    those of metric=False."""
    from ccproof.apps.arap.core import MethodResult
    from ccproof.apps.arap.fvar import METRIC_WEIGHTS, ControlOptions, export_control
    from ccproof.apps.arap.io import write_uv_obj
    from ccproof.apps.arap.meshes import LevelPlan, compare

    m, chart = M.curved_ev_mesh()
    labels = np.array([0 if f in set(chart) else -1 for f in range(m.n_faces)])
    res, _ = compare(m, labels, methods=("c",), plan=LevelPlan(levels=2, eval_level=4))
    plain = export_control(res["c"], eval_level=4, options=ControlOptions(max_extra=0, metric=False))
    # the last refinement allowed misses: the minimax runs
    auto = export_control(res["c"], eval_level=4, options=ControlOptions(max_extra=0))
    assert not plain.accepted and plain.arap_metrics is None and plain.chart_weights == [None]
    assert auto.arap_metrics is not None and auto.arap_metrics.as_tuple() == plain.metrics.as_tuple()
    assert auto.chart_weights[0] in METRIC_WEIGHTS
    assert max(auto.excess_ratio()) < max(plain.excess_ratio())
    assert auto.folds == [0, 0, 0]
    path = tmp_path / "mm.obj"
    write_uv_obj(path, auto.mesh, MethodResult("c", auto.textures, 0.0, 0))
    _, UV, FT = read_fvar_obj(path)
    U, F = UV, FT
    for level in (1, 2, 3):
        U, F = corners_only_step(U, F)
        assert folded_triangles(U, F) == 0, level
