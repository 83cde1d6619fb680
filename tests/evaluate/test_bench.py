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
@pytest.mark.parametrize("kind", ["far", "bfr"])
def test_opensubdiv_in_process_agrees_on_regular_points(refdir, kind):
    """The benchmark's in-process OpenSubdiv (scripts/osd_capi.cpp through ctypes, system libosd) and ours
    agree on points inside regular patches, positions and (s, t) derivatives, n-gon sub-faces included."""
    import sys

    import numpy as np

    sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "scripts"))
    import _osd

    if _osd.why_unavailable():
        pytest.skip(_osd.why_unavailable())
    from ccproof.evaluate import limit_surface
    from ccproof.mesh.io import read_mesh

    lib = _osd.load()
    for name in ("catmark_pyramid_creases1", "catmark_smoothtris1", "catmark_nonquads"):
        mesh = read_mesh(refdir / "osd_features" / "meshes" / f"{name}.obj")
        S = limit_surface(mesh)
        rng = np.random.default_rng(0)
        n = 2000
        ok = np.flatnonzero(np.repeat(~mesh.is_hole, np.where(mesh.sizes == 4, 1, mesh.sizes)))
        f, s, t = ok[rng.integers(0, ok.size, n)], 0.1 + 0.8 * rng.random(n), 0.1 + 0.8 * rng.random(n)
        P, Ps, Pt = _osd.Evaluator(lib, kind, mesh, approx=10).evaluate(f, s, t)
        r = S.evaluate(f, s, t, 1)
        diag = mesh.bounding_box_diagonal
        assert np.abs(r["P"] - P).max() <= 1e-12 * diag, name
        assert max(np.abs(r["Pu"] - Ps).max(), np.abs(r["Pv"] - Pt).max()) <= 1e-9 * diag, name
