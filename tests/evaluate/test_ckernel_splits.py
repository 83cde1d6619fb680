"""The C kernel on meshes whose faces split over several levels (semi-sharp creases and corners, where the
patch table's virtual faces nest 2 to 5 deep): the same bits as the numpy path, the independent array
formulation of the same sums, uniform points and points in deep layers at the corners, in calls with and
without the corner-net cache."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from ccproof.evaluate import natural_limit_surface
from ccproof.evaluate.backend import available_backends
from ccproof.mesh.io import read_mesh

MESHES = Path(__file__).resolve().parents[1] / "data" / "osd_features" / "meshes"

pytestmark = pytest.mark.skipif("c" not in available_backends(),
                                reason="the C kernel was not built (python setup.py build_ext --inplace)")


@pytest.mark.parametrize("name", ["catmark_cube_creases0", "catmark_cube_corner2", "catmark_pyramid_creases1",
                                  "catmark_chaikin1"])
def test_nested_splits_give_the_numpy_bits(name):
    mesh = read_mesh(MESHES / f"{name}.obj")
    S = natural_limit_surface(mesh)
    assert S._table.split_depth >= 2  # the case under test: faces split over several levels
    rng = np.random.default_rng(11)
    n = 3000
    f = rng.integers(0, mesh.n_ptex, n)
    u, v = rng.random(n), rng.random(n)
    k = n // 2  # deep layers at the four corners of the face
    a = 0.5 ** rng.integers(0, 60, k) * rng.random(k)
    b = a * rng.random(k)
    corner = rng.integers(0, 4, k)
    u[:k] = np.where((corner == 1) | (corner == 2), 1.0 - a, a)
    v[:k] = np.where(corner >= 2, 1.0 - b, b)
    for lo, hi in ((0, n), (7, 200)):  # one call with the cache, one below its threshold (256 points)
        ref = S.evaluate(f[lo:hi], u[lo:hi], v[lo:hi], 2, backend="numpy")
        got = S.evaluate(f[lo:hi], u[lo:hi], v[lo:hi], 2, backend="c", threads=1)
        assert set(got) == set(ref) == {"P", "Pu", "Pv", "Puu", "Puv", "Pvv"}
        for key in ref:
            assert np.array_equal(ref[key].view(np.int64), got[key].view(np.int64)), key
