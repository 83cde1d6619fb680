"""The compiled kernel's cache of corner nets (one per kernel call): the results are the same bits with and
without it, whatever the blocks and threads, also when nets share a slot (evicted and computed again)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from ccproof.evaluate import natural_limit_surface
from ccproof.evaluate.backend import available_backends
from ccproof.mesh import read_obj

DATA = Path(__file__).resolve().parents[1] / "data" / "meshes"
#: the cache's size and hash in both compiled kernels (_numba_kernel.py, _clib.c): the slots the test fills
CACHE_SLOTS, HASH = 16384, 2654435761


@pytest.mark.parametrize("backend", ["c", "numba"])
def test_cached_corner_nets_are_the_same_bits(backend):
    if backend not in available_backends():
        pytest.skip(f"backend {backend!r} not available in this install")

    S = natural_limit_surface(read_obj(DATA / "bunny_quads.obj"))
    rng = np.random.default_rng(7)
    n = 400000
    f = rng.integers(0, S.n_faces, n)
    # points at the four corners of their face, in every layer: more corner nets than cache slots
    a = 0.5 ** rng.integers(1, 80, n) * (0.5 + 0.5 * rng.random(n))
    b = a * rng.random(n)
    swap = rng.random(n) < 0.5
    a, b = np.where(swap, b, a), np.where(swap, a, b)
    corner = rng.integers(0, 4, n)
    u = np.where((corner == 1) | (corner == 2), 1.0 - a, a)
    v = np.where(corner >= 2, 1.0 - b, b)
    patch, *_ = S.locate(f, u, v)
    keep = np.flatnonzero(patch >= S.n_patches)[:40000]  # points in corner faces (at extraordinary vertices)
    f, u, v, patch = f[keep], u[keep], v[keep], patch[keep]
    deep = patch >= S.n_patches
    keys = np.unique(patch) - S.n_patches  # the kernel's cache keys: 3 (max_layers corner + layer) + code
    slots = (keys * HASH) & (CACHE_SLOTS - 1)
    assert keys.size > 5000 and np.unique(slots).size < keys.size  # slots shared: nets evicted and recomputed
    ref = S.evaluate(f, u, v, 2, backend="numpy")
    one = S.evaluate(f, u, v, 2, backend=backend, threads=1)  # one call: the cache on
    three = S.evaluate(f, u, v, 2, backend=backend, threads=3)
    k = np.flatnonzero(deep)[:200]
    single = [S.evaluate(f[i:i + 1], u[i:i + 1], v[i:i + 1], 2, backend=backend) for i in k]  # the cache off
    for key in ref:
        assert np.array_equal(ref[key], one[key]), key
        assert np.array_equal(one[key], three[key]), key
        assert np.array_equal(np.vstack([s[key] for s in single]), one[key][k]), key
