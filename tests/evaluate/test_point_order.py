"""Points in any order: the compiled kernels take large calls on large surfaces batched by face
(``surface.SORT_MIN``, ``surface.SORT_FACES``: here every surface is batched) and write the results back in the
caller's order; every point gets the bits it gets alone, on every backend, with the nets kept precomputed or
computed from the rings."""

import numpy as np
import pytest

from ccproof.evaluate import surface
from ccproof.evaluate.backend import available_backends
from ccproof.evaluate.surface import LimitSurface
from ccproof.mesh.io import read_obj_tagged


@pytest.fixture(autouse=True)
def _batch_every_surface(monkeypatch):
    monkeypatch.setattr(surface, "SORT_FACES", 0)


@pytest.fixture(scope="module", params=["kept", "computed"])
def surf(request, refdir):
    mesh = read_obj_tagged(refdir / "osd_features" / "meshes" / "catmark_smoothtris1.obj")
    if request.param == "kept":
        return LimitSurface(mesh, progress=False)
    mp = pytest.MonkeyPatch()
    mp.setenv("CCPROOF_NETS_BUDGET", "0")  # the environment's budgets (bytes) over _table's defaults
    mp.setenv("CCPROOF_HOT_BUDGET", "0")
    try:
        S = LimitSurface(mesh, progress=False)
        ct = S._c_table() if "c" in available_backends() else None  # (the C kernel's nets: none either)
    finally:
        mp.undo()
    assert S._table.nets.shape[0] == 0 and S._table.hot.shape[0] == 0
    assert ct is None or (ct.struct.n_nets == 0 and ct.struct.n_hot == 0)
    return S


def _points(S, n, seed):
    rng = np.random.default_rng(seed)
    f = rng.integers(0, S.n_faces, n)
    u, v = rng.random(n), rng.random(n)
    u[: n // 4] = np.ldexp(u[: n // 4], -rng.integers(0, 30, n // 4))  # deep layers at the corners
    v[: n // 4] *= u[: n // 4]
    return f, u, v


@pytest.mark.parametrize("threads", [1, 2])
def test_shuffled_points_same_bits_as_alone(surf, threads, monkeypatch):
    """Points shuffled (batched by face inside ``evaluate``), the same points in face order (no batching:
    already in order) and one by one in calls below ``SORT_MIN`` give the same bits, and the numpy path's."""
    monkeypatch.setattr(surface, "SORT_CHUNK", 1000)  # several chunks per call
    S = surf
    n = 3 * surface.SORT_MIN
    f, u, v = _points(S, n, 4)
    o = np.argsort(f, kind="stable")
    for backend in available_backends():
        shuffled = S.evaluate(f, u, v, 2, backend=backend, threads=threads)
        in_order = S.evaluate(f[o], u[o], v[o], 2, backend=backend, threads=threads)
        small = {k: np.empty((n, 3)) for k in shuffled}
        for lo in range(0, n, surface.SORT_MIN - 1):
            r = S.evaluate(f[lo:lo + surface.SORT_MIN - 1], u[lo:lo + surface.SORT_MIN - 1],
                           v[lo:lo + surface.SORT_MIN - 1], 2, backend=backend)
            for k in r:
                small[k][lo:lo + surface.SORT_MIN - 1] = r[k]
        ref = S.evaluate(f, u, v, 2, backend="numpy")
        for k in shuffled:
            assert np.array_equal(shuffled[k][o], in_order[k]), (backend, k)
            assert np.array_equal(shuffled[k], small[k]), (backend, k)
            assert np.array_equal(shuffled[k], ref[k]), (backend, k)


def test_out_arrays_filled_in_the_callers_order(surf):
    """``out`` given (a strided view among them): every row is its point's, after the batched evaluation."""
    S = surf
    n = 2 * surface.SORT_MIN
    f, u, v = _points(S, n, 9)
    big = np.empty((n, 6))
    out = {"P": big[:, :3], "Pu": np.empty((n, 3)), "Pv": np.empty((n, 3))}
    r = S.evaluate(f, u, v, 1, out=out)
    assert r is out
    ref = S.evaluate(f, u, v, 1, backend="numpy")
    for k in ref:
        assert np.array_equal(out[k], ref[k]), k


def test_a_bad_point_is_named_after_batching(surf):
    S = surf
    n = 2 * surface.SORT_MIN
    f, u, v = _points(S, n, 2)
    u[777] = 1.5
    with pytest.raises(Exception, match="point 777: u = 1.5"):
        S.evaluate(f, u, v, 1)


def test_a_bad_budget_is_named(refdir, monkeypatch):
    monkeypatch.setenv("CCPROOF_NETS_BUDGET", "lots")
    mesh = read_obj_tagged(refdir / "osd_features" / "meshes" / "catmark_smoothtris1.obj")
    with pytest.raises(Exception, match="CCPROOF_NETS_BUDGET='lots': a budget in bytes"):
        LimitSurface(mesh, progress=False)
