"""``arap`` with default options fits its --max-memory budget by lowering the default levels, as its help says, and
says which it chose; a single chart that folds names the fix (charts); ``--normal-angle`` sets the segmentation.

The scan: a 562-triangle noisy spherical cap (an open disk like a face scan), generated here. With the defaults
the metrics level 5 used to be kept and the run refused ("2.57 GB exceeds the budget 2.00 GB"); the peak memory of
the run is measured in a child process (its maximum resident set), independently of the estimate."""

import subprocess
import sys

import numpy as np
import pytest

from ccproof.apps.arap.charts import check_disk, segment_by_normals
from ccproof.cli import main
from ccproof.mesh import QuadMesh
from ccproof.mesh.examples import cube


def noisy_cap_obj(path, nx=20, ny=14, seed=7):
    """An nx x ny grid of split quads (560 triangles) on a noisy sphere cap and two ear triangles on its boundary
    (562); returns the number of triangles."""
    rng = np.random.default_rng(seed)
    x, y = np.meshgrid(np.linspace(-0.8, 0.8, nx + 1), np.linspace(-0.6, 0.6, ny + 1), indexing="ij")
    z = np.sqrt(2.0 - x**2 - y**2) + 0.01 * rng.standard_normal(x.shape)
    V = [[float(c) for c in p] for p in np.stack([x, y, z], axis=-1).reshape(-1, 3)]
    vid = lambda i, j: i * (ny + 1) + j
    T = []
    for i in range(nx):
        for j in range(ny):
            a, b, c, d = vid(i, j), vid(i + 1, j), vid(i + 1, j + 1), vid(i, j + 1)
            T += [[a, b, c], [a, c, d]]
    for j in (3, 9):  # ears outside the side x = -0.8, oriented as the grid (its boundary edge runs j+1 -> j)
        V.append([-0.85, float(y[0, j] + y[0, j + 1]) / 2, float(np.sqrt(2.0 - 0.85**2 - y[0, j] ** 2))])
        T.append([vid(0, j), vid(0, j + 1), len(V) - 1])
    with open(path, "w") as fh:
        fh.writelines(f"v {p[0]!r} {p[1]!r} {p[2]!r}\n" for p in V)
        fh.writelines(f"f {t[0] + 1} {t[1] + 1} {t[2] + 1}\n" for t in T)
    return len(T)


def test_default_levels_fit_the_budget_of_a_562_triangle_scan(tmp_path):
    mesh = tmp_path / "cap.obj"
    assert noisy_cap_obj(mesh) == 562
    code = ("import resource, sys; from ccproof.cli import main; "
            f"rc = main(['arap', {str(mesh)!r}, '--max-iter', '20']); "
            "print('peak KB', resource.getrusage(resource.RUSAGE_SELF).ru_maxrss); sys.exit(rc)")
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, run.stderr
    assert "chosen to fit --max-memory 2 GB: metrics level 5 -> 4" in run.stderr, run.stderr
    assert "metrics at level 4" in run.stdout and "levels 1..3" in run.stdout
    peak_kb = int(run.stdout.split("peak KB")[1])  # the child's own maximum resident set (Linux: KB)
    assert peak_kb * 1024 < 2.0e9, f"peak {peak_kb / 1e6:.2f} GB above the 2 GB budget"


def test_a_tighter_budget_lowers_the_optimization_levels_too_and_a_hopeless_one_refuses(tmp_path, capsys):
    mesh = tmp_path / "cap.obj"
    noisy_cap_obj(mesh)
    assert main(["arap", str(mesh), "--max-memory", "0.5", "--max-iter", "5"]) == 0
    cap = capsys.readouterr()
    assert "levels 3 -> 2" in cap.err and "levels 1..2" in cap.out, cap.err
    assert main(["arap", str(mesh), "--max-memory", "0.1"]) == 2  # below the fixed base of a run
    assert "exceeds the budget 0.10 GB" in capsys.readouterr().err


def _ball_with_a_hole(path, times=2):
    """A sphere (the cube subdivided ``times``, projected) less one face: a disk that folds as one chart."""
    from ccproof.apps.control_mesh import subdivide_control
    from ccproof.mesh.write import write_obj

    m = cube()
    for _ in range(times):
        m = subdivide_control(m)
    write_obj(path, QuadMesh(m.vertices / np.linalg.norm(m.vertices, axis=1)[:, None], m.faces[1:]))


def test_a_single_chart_that_folds_names_the_fix(tmp_path, capsys):
    ball = tmp_path / "ball.obj"
    _ball_with_a_hole(ball)
    base = ["arap", str(ball), "--refine", "0", "--levels", "2", "--eval-level", "3"]
    assert main(base) == 0
    cap = capsys.readouterr()
    flips = int(cap.out.split("\n")[3].split()[-3])  # the table's "flips L3" column of (c)
    assert flips > 0 and "single chart, which folds: segment the mesh into charts (--segment normals" in cap.err
    assert main(base + ["--segment", "normals"]) == 0  # several charts: no such hint
    assert "single chart" not in capsys.readouterr().err


def _normals(m):
    V, F = m.vertices, m.faces
    n = np.cross(V[F[:, 2]] - V[F[:, 0]], V[F[:, 3]] - V[F[:, 1]])
    return n / np.linalg.norm(n, axis=1)[:, None]


@pytest.mark.parametrize("angle", [25.0, 50.0, 100.0])
def test_normal_angle_bounds_every_chart(tmp_path, angle):
    from ccproof.apps.control_mesh import subdivide_control

    m = cube()
    for _ in range(3):
        m = subdivide_control(m)
    m = QuadMesh(m.vertices / np.linalg.norm(m.vertices, axis=1)[:, None], m.faces)  # 384 faces on a sphere
    lab = segment_by_normals(m, min_faces=1, max_angle=angle)
    nrm = _normals(m)
    for c in np.unique(lab):
        fc = np.flatnonzero(lab == c)
        check_disk(m, fc)
        cos = nrm[fc] @ nrm[fc].T  # some face of the chart sees every other within the angle
        assert np.any(np.all(cos >= np.cos(np.radians(angle)) - 1e-12, axis=1)), (angle, c)
    counts = {a: np.unique(segment_by_normals(m, min_faces=1, max_angle=a)).size for a in (25.0, 50.0, 100.0)}
    assert counts[25.0] > counts[50.0] > counts[100.0] >= 2


def test_normal_angle_option(tmp_path, capsys):
    ball = tmp_path / "ball.obj"
    _ball_with_a_hole(ball, 3)  # 383 faces
    n = {}
    for a in ("30", "120"):
        out = tmp_path / f"l{a}.txt"
        assert main(["arap", str(ball), "--segment", "normals", "--normal-angle", a, "--levels", "1",
                     "--eval-level", "2", "--labels-out", str(out)]) == 0, capsys.readouterr().err
        n[a] = len(set(out.read_text().split()))
    assert n["30"] > n["120"] >= 1
    assert main(["arap", str(ball), "--normal-angle", "30"]) == 2
    assert "--normal-angle is a setting of --segment normals" in capsys.readouterr().err
