"""Budgets checked up front, refused by name with the figure and the option that raises the limit: an ``eval``
result larger than the machine's memory (one .npz) or the free disk (shards), ``project --cells`` whose search
structure exceeds ``--max-memory`` (``--cells 100000`` used to end in a memory traceback asking 298 GiB). The
work itself is replaced by one that fails the test, so a check after the work is caught at once."""

import os

import pytest

from ccproof.cli import main
from ccproof.mesh import write_obj
from ccproof.mesh.examples import k_regular_disk


def _no_work(*a, **k):
    raise AssertionError("the work started before the budget was checked")


@pytest.fixture
def disk(tmp_path):
    write_obj(tmp_path / "d.obj", k_regular_disk(5, rings=3, height=lambda x, y: 0.1 * x * y))
    return tmp_path / "d.obj"


def test_eval_refuses_a_result_that_cannot_be_held(disk, tmp_path, monkeypatch, capsys):
    import ccproof.scale as scale

    monkeypatch.setattr(scale, "evaluate_points", _no_work)
    monkeypatch.setattr(scale, "point_chunks", _no_work)  # 10^12 samples: a million chunk tuples before
    ram = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    n = ram // 96 + 1  # one point more than fits (96 bytes per point with first derivatives)
    assert main(["eval", str(disk), "--samples", str(n), "--out", str(tmp_path / "o.npz")]) == 2
    err = capsys.readouterr().err
    assert "bytes per point), more than this machine's memory" in err and "--out FOLDER/" in err, err
    assert main(["eval", str(disk), "--samples", str(10**15), "--out", str(tmp_path / "shards") + "/"]) == 2
    err = capsys.readouterr().err
    assert "the result takes 96 PB" in err and "more than the free space of" in err, err


def test_project_refuses_a_search_structure_above_max_memory(disk, tmp_path, monkeypatch, capsys):
    import ccproof.evaluate.closest as closest
    import ccproof.evaluate.surface as surface

    monkeypatch.setattr(surface, "limit_surface", _no_work)
    monkeypatch.setattr(closest, "ClosestPointFinder", _no_work)
    (tmp_path / "p.csv").write_text("x,y,z\n0,0,1\n")
    argv = ["project", str(disk), str(tmp_path / "p.csv"), "--out", str(tmp_path / "o.npz")]
    assert main(argv + ["--cells", "100000"]) == 2
    err = capsys.readouterr().err
    # one face's 200001^2 samples at 400 bytes (1.6e4 GB) + a full cell cache (2^20 cells of 64 bytes) + 45 faces
    assert "--cells 100000: the search structure of 45 faces needs about 1.66e+04 GB" in err, err
    assert "above --max-memory 2 GB; lower --cells or raise --max-memory" in err
    for bad in ("nan", "0", "-1"):
        assert main(argv + ["--max-memory", bad]) == 2
        assert "--max-memory must be a positive number" in capsys.readouterr().err


def test_a_large_polygon_is_refused_up_front_and_the_option_raises_the_limit(tmp_path, capsys):
    """A polygon above the default limit (1024: a 1000-gon and 100 points now take seconds, 26 minutes and 2.2 GB
    before) is refused at once, by face and size."""
    import time

    import numpy as np

    def ngon(n):
        a = np.linspace(0, 2 * np.pi, n, endpoint=False)
        p = tmp_path / f"ngon{n}.obj"
        p.write_text("".join(f"v {float(np.cos(t))!r} {float(np.sin(t))!r} 0\n" for t in a)
                     + "f " + " ".join(str(i + 1) for i in range(n)) + "\n")
        return str(p)

    t0 = time.perf_counter()
    assert main(["eval", ngon(1500), "--samples", "100", "--out", str(tmp_path / "o.npz")]) == 2
    err = capsys.readouterr().err
    assert "ngon1500.obj: face 0 has 1500 vertices, above --max-polygon 1024" in err, err
    assert time.perf_counter() - t0 < 5
    assert main(["eval", ngon(12), "--samples", "20", "--out", str(tmp_path / "o.npz"), "--max-polygon", "8"]) == 2
    assert "face 0 has 12 vertices, above --max-polygon 8" in capsys.readouterr().err
    assert main(["eval", ngon(12), "--samples", "20", "--out", str(tmp_path / "o.npz"), "--max-polygon", "12"]) == 0
    assert main(["eval", ngon(12), "--samples", "20", "--out", str(tmp_path / "o.npz"), "--max-polygon", "2"]) == 2
    assert "--max-polygon must be an integer >= 3" in capsys.readouterr().err
