"""``eval`` says how many points have no normal (``Pu x Pv = 0``, a collapsed part of the mesh) and in which faces,
instead of writing them without a word (one .npz file and shards alike). The count is checked against the
written derivatives, and the faces against the construction: the 16 control points of face 14 of a 6 x 6 grid
are one point, so its whole patch is that point and no other face's patch is constant."""

import re

import numpy as np
import pytest

from ccproof.cli import main
from ccproof.mesh import write_obj
from ccproof.mesh.examples import grid


@pytest.mark.parametrize("out", ["o.npz", "shards/"])
def test_eval_reports_points_without_a_normal(tmp_path, capsys, out):
    m = grid(6, 6, height=lambda x, y: 0.1 * x * y)
    V = np.array(m.vertices, dtype=float)
    net = [i + 7 * j for i in range(1, 5) for j in range(1, 5)]  # the one-ring of face 2 + 6 * 2 = 14
    V[net] = V[net].mean(axis=0)
    write_obj(tmp_path / "c.obj", type(m)(V, m.faces))
    assert main(["eval", str(tmp_path / "c.obj"), "--samples", "3000", "--chunk", "1000", "--serial",
                 "--out", str(tmp_path / out)]) == 0
    err = capsys.readouterr().err
    hit = re.search(r"warning: (\d+) of 3000 points have no normal .* in faces ([\d, ]+)", err)
    assert hit, err
    if out.endswith("/"):
        parts = sorted((tmp_path / "shards").glob("part-*.npz"))
        z = {k: np.concatenate([np.load(p)[k] for p in parts]) for k in ("face", "Pu", "Pv")}
    else:
        z = dict(np.load(tmp_path / out))
    in14 = z["face"] == 14
    assert int(hit.group(1)) == int(in14.sum()) > 0 and hit.group(2).strip() == "14"
    assert np.abs(z["Pu"][in14]).max() == 0 and np.abs(z["Pv"][in14]).max() == 0
