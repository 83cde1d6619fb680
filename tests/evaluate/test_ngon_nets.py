"""A lone n-gon's table precomputes no nets: its n corner faces share the centre's 2n + 8 ring points, so
precomputing them was n^2 products (a 1000-gon: 3.4 s of CPU for 100 points); the kernels compute them per
point from the ring instead, and give the same numbers as the precomputed ones (checked against a table
that keeps them)."""

import numpy as np

from ccproof.evaluate import LimitSurface, available_backends, nets
from ccproof.mesh.polymesh import PolyMesh


def _ngon(n):
    t = np.arange(n) * 2 * np.pi / n
    return PolyMesh(np.c_[np.cos(t), np.sin(t), 0.1 * np.sin(3 * t)], [list(range(n))])


def test_an_ngon_keeps_no_precomputed_nets_and_gives_the_same_bits(monkeypatch):
    mesh = _ngon(60)
    lean = LimitSurface(mesh, progress=False)
    assert lean._table.hot.shape[0] == 0 and lean._table.nets.shape[0] == 0
    monkeypatch.setattr(nets, "RING_MEAN_PRECOMPUTED", 10**9)  # the former rule: precomputed within the bytes
    kept = LimitSurface(mesh, progress=False)
    assert kept._table.hot.shape[0] == 3 * kept._table.n_corner > 0
    rng = np.random.default_rng(3)
    n = 1000
    f = rng.integers(0, mesh.n_ptex, n)
    u, v = rng.random(n), rng.random(n)
    u[: n // 2] = np.ldexp(u[: n // 2], -rng.integers(0, 3, n // 2))  # layers 0 to 2 at the centre (1, 1)
    u[: n // 2], v[: n // 2] = 1 - u[: n // 2], 1 - v[: n // 2] * u[: n // 2]
    for backend in available_backends():
        a = lean.evaluate(f, u, v, 1, backend=backend)
        b = kept.evaluate(f, u, v, 1, backend=backend)
        for k in ("P", "Pu", "Pv"):
            assert np.array_equal(a[k], b[k]), (backend, k)


def test_a_small_quad_mesh_still_keeps_them():
    from ccproof.mesh.examples import k_regular_disk

    S = LimitSurface(PolyMesh(*_vf(k_regular_disk(5, rings=2))), progress=False)
    assert S._table.hot.shape[0] == 3 * S._table.n_corner > 0


def _vf(m):
    return np.asarray(m.vertices), [list(map(int, f)) for f in m.faces]
