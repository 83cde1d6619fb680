"""PatchMap.locate against independent rules: the layer of a corner point from log2, the regular patch of a
regular face, and the point recovered from (patch domain, s, t) exactly."""

import numpy as np

from ccproof.evaluate import natural_limit_surface
from ccproof.mesh.examples import k_regular_disk, torus


def test_corner_face_layers_are_floor_of_minus_log2():
    S = natural_limit_surface(k_regular_disk(5, 3))  # face 0: the extraordinary vertex at its (0, 0)
    rng = np.random.default_rng(3)
    e = rng.uniform(1, 40, 400)
    u = np.exp2(-e) * rng.uniform(0.0, 1.0, 400)
    v = np.exp2(-e) * rng.uniform(0.0, 1.0, 400)
    f = np.zeros(400, dtype=np.int64)
    loc = S.patch_map.locate(f, u, v)
    assert (loc.kind == 1).all() and np.array_equal(loc.corner, np.arange(400))
    last = int(S._table.n_layers[S._table.cfg[loc.vface[0]]]) - 1
    expect = np.minimum(np.floor(-np.log2(np.maximum(u, v))).astype(np.int64), last)
    assert np.array_equal(loc.layer, expect)
    # the patch has side 2^-(n+1); the point is recovered from its corner and (s, t) exactly where it lies inside
    h = 1.0 / loc.scale
    assert np.array_equal(h, np.exp2(-(loc.layer + 1.0)))
    assert ((loc.s >= 0) & (loc.s <= 1) & (loc.t >= 0) & (loc.t <= 1)).all()
    inner = loc.layer < last
    u0 = u - loc.s * h
    assert np.all(np.isclose(u0[inner] / h[inner], np.round(u0[inner] / h[inner]), rtol=0, atol=1e-9))


def test_regular_faces_are_their_own_patch():
    S = natural_limit_surface(torus())
    rng = np.random.default_rng(4)
    f = rng.integers(0, S.n_faces, 200)
    u, v = rng.uniform(0, 1, 200), rng.uniform(0, 1, 200)
    loc = S.patch_map.locate(f, u, v)
    assert (loc.kind == 0).all() and loc.corner.size == 0
    assert np.array_equal(loc.s, u) and np.array_equal(loc.t, v) and (loc.scale == 1.0).all()
    assert np.array_equal(S.locate(f, u, v)[0], loc.patch)
