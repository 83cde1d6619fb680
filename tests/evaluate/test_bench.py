"""Smoke test of scripts/bench_evaluate.py (slow: run with ``pytest -m slow``)."""

import importlib.util
from pathlib import Path

import pytest


@pytest.mark.slow
def test_bench_quick(capsys, refdir):
    path = Path(__file__).resolve().parents[2] / "scripts" / "bench_evaluate.py"
    spec = importlib.util.spec_from_file_location("bench_evaluate", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    assert mod.main(["--quick"]) == 0
    out = capsys.readouterr().out
    assert "points/s" in out and "per-point" in out and "peak memory" in out


@pytest.mark.slow
def test_opensubdiv_driver_agrees_on_regular_points(refdir):
    """The benchmark's OpenSubdiv driver (system libosd) and ours agree on points in regular patches."""
    import numpy as np

    path = Path(__file__).resolve().parents[2] / "scripts" / "bench_evaluate.py"
    spec = importlib.util.spec_from_file_location("bench_evaluate", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    exe = mod.build_osd_driver()
    if exe is None:
        pytest.skip("OpenSubdiv (libosd-dev) or g++ not installed")
    from ccproof.evaluate import limit_surface
    from ccproof.mesh.io import read_mesh

    mesh = read_mesh(refdir / "osd_features" / "meshes" / "catmark_pyramid_creases1.obj")
    S = limit_surface(mesh)
    rng = np.random.default_rng(0)
    n = 2000
    f, s, t = rng.integers(0, mesh.n_ptex, n), 0.1 + 0.8 * rng.random(n), 0.1 + 0.8 * rng.random(n)
    _, _, P, Ps, Pt = mod.run_osd(exe, mesh, f, s, t)
    r = S.evaluate(f, s, t, 1)
    diag = mesh.bounding_box_diagonal
    assert np.abs(r["P"] - P).max() <= 1e-12 * diag
    assert max(np.abs(r["Pu"] - Ps).max(), np.abs(r["Pv"] - Pt).max()) <= 1e-9 * diag
