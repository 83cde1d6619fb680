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
