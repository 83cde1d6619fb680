"""The reproduction and benchmark scripts run end to end (small cases)."""

import importlib.util
import json
import pathlib

import numpy as np

from ccproof.mesh import write_obj
from ccproof.mesh.examples import k_regular_disk

SCRIPTS = pathlib.Path(__file__).resolve().parents[3] / "scripts"


def _load(name):
    spec = importlib.util.spec_from_file_location(name, SCRIPTS / f"{name}.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_reproduce_script_small_case(tmp_path):
    mod = _load("reproduce_hsh10")
    assert mod.main(["--out", str(tmp_path), "--cases", "ev5", "--engine", "numpy"]) == 0
    assert (tmp_path / "ev5_compare.png").stat().st_size > 10_000
    assert (tmp_path / "ev5_texture.png").stat().st_size > 10_000
    summ = json.loads((tmp_path / "summary.json").read_text())["cases"]["ev5"]["methods"]
    for key in ("E_angle", "E_area", "E_stretch"):
        assert summ["c"][key] < summ["b"][key] < summ["a"][key]


def test_bench_script_small_mesh(tmp_path):
    mesh = k_regular_disk(5, rings=4, height=lambda x, y: 0.15 * (x**2 - 0.5 * y**2))
    write_obj(tmp_path / "m.obj", mesh)
    mod = _load("bench_arap")
    out = tmp_path / "b.json"
    assert mod.main(["--mesh", str(tmp_path / "m.obj"), "--engine", "numpy", "--repeat", "3", "--out", str(out)]) == 0
    r = json.loads(out.read_text())["cases"]["segmented"]
    assert r["c_total_seconds"] > 0 and np.isfinite(r["ratio_3_2"])
