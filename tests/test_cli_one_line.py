"""Failures that used to end in a traceback (or an "internal error" naming neither file nor vertex) are one line:
standard output closed (``>&-``: eval and arap now write their files and say the report is discarded), vertex
coordinates near 1e308 (named with the file and the vertex), ``invert --rigorous --prec 1``."""

import os
import subprocess
import sys

import numpy as np
import pytest

from ccproof.cli import main
from ccproof.mesh import write_obj
from ccproof.mesh.examples import k_regular_disk

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


@pytest.fixture
def disk(tmp_path):
    write_obj(tmp_path / "d.obj", k_regular_disk(5, rings=3, height=lambda x, y: 0.1 * x * y))
    return tmp_path / "d.obj"


@pytest.mark.parametrize("argv, out", [
    (["eval", "d.obj", "--samples", "20", "--out", "o.npz"], "o.npz"),
    (["arap", "d.obj", "--levels", "1", "--refine", "0", "--eval-level", "1", "--out", "u.obj"], "u.obj"),
])
def test_closed_stdout_still_writes_the_outputs(disk, argv, out):
    env = dict(os.environ, PYTHONPATH=ROOT + os.pathsep + os.environ.get("PYTHONPATH", ""))
    r = subprocess.run([sys.executable, "-m", "ccproof.cli", *argv], cwd=disk.parent, env=env, stderr=subprocess.PIPE,
                       text=True, timeout=120, preexec_fn=lambda: os.close(1))
    assert r.returncode == 0 and "Traceback" not in r.stderr, r.stderr
    assert [ln for ln in r.stderr.splitlines() if "standard output is closed" in ln]
    assert (disk.parent / out).stat().st_size > 0


def test_huge_coordinates_are_named_by_file_and_vertex(disk, tmp_path, capsys):
    lines = disk.read_text().splitlines()
    i = next(j for j, ln in enumerate(lines) if ln.startswith("v "))
    lines[i + 3] = "v 1.5e308 0 0"  # vertex 3
    (tmp_path / "big.obj").write_text("\n".join(lines) + "\n")
    for argv in (["eval", str(tmp_path / "big.obj"), "--samples", "5", "--out", str(tmp_path / "o.npz")],
                 ["project", str(tmp_path / "big.obj"), str(tmp_path / "p.csv"), "--out", str(tmp_path / "o.npz")]):
        np.savetxt(tmp_path / "p.csv", [[0, 0, 0]], delimiter=",", header="x,y,z", comments="")
        assert main(argv) == 2
        err = capsys.readouterr().err
        assert "big.obj: vertex 3 (0-based) has coordinates [1.5e+308, 0.0, 0.0] beyond 1e+150" in err, err
        assert "internal error" not in err and len(err.strip().splitlines()) == 1


def test_invert_prec_out_of_range_is_one_line(capsys):
    for prec in ("1", "0", "-5", "100000"):
        assert main(["invert", "5", "0.3", "0.2", "--rigorous", "--prec", prec]) == 2
        err = capsys.readouterr().err
        assert f"--prec must be 2..4096 bits, got {prec}" in err and len(err.strip().splitlines()) == 1, err


@pytest.mark.parametrize("option, value, words", [
    ("--tol", "nan", "--tol must be a finite number"), ("--stray-fraction", "nan", "--stray-fraction must be in"),
    ("--stray-distance", "nan", "--stray-distance must be"), ("--max-steps", "-1", "--max-steps must be >= 1"),
    ("--sample-level", "-1", "--sample-level must be 0..6"), ("--sample-level", "12", "--sample-level must be 0..6"),
    ("--tension", "nan", "--tension must be a finite number >= 0"), ("--rigidity", "-1", "--rigidity must be"),
    ("--damping", "inf", "--damping must be"), ("--mass", "-1", "--mass must be"),
    ("--spring", "inf", "--spring must be a finite number > 0"), ("--dt", "nan", "--dt must be a finite number > 0"),
    ("--init-scale", "nan", "--init-scale must be in (0, 1]"), ("--levels", "-1", "--levels must be >= 0"),
    ("--truncation", "-1", "--truncation must be >= 1"),
])
def test_fit_refuses_nan_and_out_of_range_options_before_the_work(tmp_path, monkeypatch, capsys, option, value, words):
    """NaN compares false, so it used to pass the checks and run (--tol nan: until --max-steps); --sample-level
    -1 ended in numba's SystemError."""
    import ccproof.apps.dynamics.fit as fit

    def no_work(*a, **k):
        raise AssertionError("the work started before the options were checked")

    monkeypatch.setattr(fit, "fit_points", no_work)
    np.savetxt(tmp_path / "p.xyz", np.random.default_rng(0).normal(size=(50, 3)))
    assert main(["fit", str(tmp_path / "p.xyz"), "--out", str(tmp_path / "o.obj"), option, value]) == 2
    err = capsys.readouterr().err
    assert words in err and len(err.strip().splitlines()) == 1, err


def test_eval_negative_seed_is_refused_before_the_work(disk, tmp_path, capsys):
    """It used to fail in every task after the setup ('FAILED: ValueError: expected non-negative integer')."""
    assert main(["eval", str(disk), "--samples", "5", "--seed", "-1", "--out", str(tmp_path / "o.npz")]) == 2
    err = capsys.readouterr().err
    assert "--seed must be an integer >= 0, got -1" in err and len(err.strip().splitlines()) == 1, err
