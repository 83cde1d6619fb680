"""Smoke tests of scripts/bench_reparam.py and scripts/reproduce_bmz04_figures.py."""

import importlib.util
from pathlib import Path

import pytest

SCRIPTS = Path(__file__).resolve().parents[2] / "scripts"


def _load(name):
    spec = importlib.util.spec_from_file_location(name, SCRIPTS / f"{name}.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


@pytest.mark.parametrize("sampling", ["uniform", "ev-faces"])
def test_bench_runs(capsys, monkeypatch, sampling):
    monkeypatch.setenv("CCPROOF_BACKEND", "numpy")  # the script sets it; restored after the test
    _load("bench_reparam").main(["--mesh", "disk:5", "--points", "3000", "--rounds", "1", "--backend", "numpy",
                                 "--sampling", sampling, "--first-calls", "5" if sampling == "uniform" else ""])
    out = capsys.readouterr().out
    assert "ratio characteristic/natural" in out and "M points/s" in out
    if sampling == "uniform":
        assert "k =     5: valence_data" in out and "sympy imported by the numerics: no" in out


@pytest.mark.slow
def test_figures(tmp_path, capsys):
    _load("reproduce_bmz04_figures").main(["--out", str(tmp_path), "--lines", "8"])
    names = {p.name for p in tmp_path.iterdir()}
    assert names == {"fig2_natural.png", "fig4_vanishing.png", "fig5_characteristic.png", "fig7_derivatives.png"}
    assert "log2(2 lam)" in capsys.readouterr().out
