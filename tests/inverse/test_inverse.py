"""The inverse characteristic map: round trips, boundary clusters, fallback, certificates, errors.

Expected values are the inputs themselves (round trips t -> Phi^-1 -> Phi and y -> Phi -> Phi^-1),
the layer/piece of a known preimage y (from its coordinates), or arb certificates.
"""

import numpy as np
import pytest

from ccproof.errors import CCProofError, ValenceError
from ccproof.inverse import algorithm as alg
from ccproof.inverse import characteristic_map, inverse_characteristic_map

DEFAULT_K = [3, 4, 5, 6, 7, 8, 13, 29, 50, 100, 1000]
ALL_K = list(range(3, 51)) + [100, 1000]
TOL = 1e-14


def boundary_preimages(rng, n, max_layer=6):
    """Points y on the images' boundary lines: u = 1/2, u = 1, v = 1/2, v = 1 (layer-0 segments),
    the face diagonal and the axis, scaled into layers 0..max_layer."""
    w = rng.random(n)
    kind = rng.integers(0, 7, n)
    sc = 0.5 ** rng.integers(0, max_layer + 1, n)
    u = np.choose(kind, [np.full(n, 0.5), np.ones(n), w, w, w, w, w * 0.5])
    v = np.choose(kind, [w * 0.5, w, np.full(n, 0.5), np.ones(n), w, np.zeros(n), np.full(n, 0.5)])
    return u * sc, v * sc


def clustered_images(k, rng, n, eps=1e-12):
    """Points t within eps of every layer and piece boundary (images of boundary_preimages), of
    the axes and of the origin."""
    u, v = boundary_preimages(rng, n)
    x, y = characteristic_map(k, u, v)
    x = np.abs(x + rng.uniform(-eps, eps, n))
    y = np.abs(y + rng.uniform(-eps, eps, n) * (rng.random(n) < 0.9))
    o = rng.random(n) < 0.05
    x[o] = rng.random(o.sum()) * eps
    y[o] = rng.random(o.sum()) * eps
    return x, y


def roundtrip_error(k, x, y):
    res = inverse_characteristic_map(k, x, y, full_output=True)
    X, Y = characteristic_map(k, res.r, res.s)
    assert np.all(np.isfinite(res.r)) and np.all(np.isfinite(res.s))
    assert res.stats["failures"] == 0
    return float(np.maximum(np.abs(X - x), np.abs(Y - y)).max()), res


def inverse_error(k, u, v):
    x, y = characteristic_map(k, u, v)
    r, s = inverse_characteristic_map(k, x, y)
    return float(np.maximum(np.abs(r - u), np.abs(s - v)).max())


@pytest.mark.parametrize("k", DEFAULT_K)
def test_roundtrip_random_and_clustered(k):
    rng = np.random.default_rng(k)
    err, res = roundtrip_error(k, rng.random(20000), rng.random(20000))
    assert err <= TOL
    assert res.stats["fallback"] == 0  # the fast path handles random points
    err, _ = roundtrip_error(k, *clustered_images(k, rng, 5000))
    assert err <= TOL
    u, v = boundary_preimages(rng, 5000)
    u = np.abs(u + rng.uniform(-1e-12, 1e-12, u.size))
    v = np.abs(v + rng.uniform(-1e-12, 1e-12, v.size) * (v > 0))
    assert inverse_error(k, u, v) <= TOL
    assert inverse_error(k, rng.random(5000), rng.random(5000)) <= TOL


@pytest.mark.slow
@pytest.mark.parametrize("k", ALL_K)
def test_roundtrip_full(k):
    """The full benchmark set of docs/inverse.md: 10^6 random t, 10^5 clustered t, and the reverse round trips."""
    rng = np.random.default_rng(1000 + k)
    err, res = roundtrip_error(k, rng.random(10**6), rng.random(10**6))
    assert err <= TOL and res.stats["failures"] == 0
    err, res = roundtrip_error(k, *clustered_images(k, rng, 10**5))
    assert err <= TOL and res.stats["failures"] == 0
    assert inverse_error(k, rng.random(10**6), rng.random(10**6)) <= TOL
    u, v = boundary_preimages(rng, 10**5)
    u = np.abs(u + rng.uniform(-1e-12, 1e-12, u.size))
    v = np.abs(v + rng.uniform(-1e-12, 1e-12, v.size) * (v > 0))
    assert inverse_error(k, u, v) <= TOL


@pytest.mark.parametrize("k", [3, 5, 8, 100])
def test_layers_and_pieces_reported(k):
    rng = np.random.default_rng(3)
    u = rng.uniform(0, 1, 4000)
    v = rng.uniform(0, 1, 4000)
    keep = (np.abs(np.log2(np.maximum(u, v)) % 1) > 1e-6) & (np.abs(np.log2(np.maximum(u, v)) % 1) < 1 - 1e-6)
    u, v = u[keep], v[keep]
    x, y = characteristic_map(k, u, v)
    res = inverse_characteristic_map(k, x, y, full_output=True)
    m = np.maximum(u, v)
    layer = -np.floor(np.log2(m)).astype(int) - 1
    assert np.array_equal(res.layer, layer)
    u0, v0 = u * 2.0**layer, v * 2.0**layer
    patch = np.where(u0 >= 0.5, np.where(v0 < 0.5, 0, 1), 2)
    clear = (np.abs(u0 - 0.5) > 1e-9) & (np.abs(v0 - 0.5) > 1e-9)
    assert np.array_equal(res.patch[clear], patch[clear])


@pytest.mark.parametrize("k", [3, 6, 40])
def test_forced_fallback_gives_the_same_answers(k, monkeypatch):
    """With Newton switched off every point goes through the subdivision fallback: it must still
    answer every point, verified, to round-off."""
    rng = np.random.default_rng(5)
    x = np.r_[rng.random(300), clustered_images(k, rng, 300)[0]]
    y = np.r_[rng.random(300), clustered_images(k, rng, 300)[1]]
    monkeypatch.setattr(alg, "NEWTON_STEPS", 0)
    monkeypatch.setattr(alg, "EXTRA_STEPS", 0)
    monkeypatch.setattr(alg, "STEP_TOL", -1.0)
    err, res = roundtrip_error(k, x, y)
    zero = (x == 0) & (y == 0)
    assert np.all(res.fallback[~zero])
    assert res.stats["fallback"] == (~zero).sum() and res.stats["failures"] == 0
    assert err <= 1e-14


def _same_bits(a, b):
    return np.ascontiguousarray(a).tobytes() == np.ascontiguousarray(b).tobytes()


def _in_batches(fn, x, y, bounds):
    parts = [fn(x[lo:hi], y[lo:hi]) for lo, hi in bounds]
    return [np.concatenate([p[i] for p in parts]) for i in range(len(parts[0]))]


@pytest.mark.parametrize("k", [3, 5, 8])
def test_a_point_does_not_depend_on_its_batch(k, monkeypatch):
    """The inverse, its fallback and the forward map with its Jacobian give every point the same bits
    alone, in batches of any size (1, 2, 3, ... points: a BLAS product takes other kernels for them)
    and at any place in its batch (reversed order)."""
    rng = np.random.default_rng(17)
    x = np.r_[rng.random(400), clustered_images(k, rng, 200)[0]]
    y = np.r_[rng.random(400), clustered_images(k, rng, 200)[1]]
    n = x.size
    cuts = np.unique(np.r_[0, np.cumsum(rng.integers(1, 12, n)), n])
    bounds = [(lo, hi) for lo, hi in zip(cuts[:-1], cuts[1:]) if lo < n]
    rev = np.arange(n)[::-1]

    def forward(a, b):
        X, Y, J = characteristic_map(k, a, b, jacobian=True)
        return X, Y, J.reshape(-1, 4)

    def inverse(a, b):
        return inverse_characteristic_map(k, a, b)

    for fn in (inverse, forward):
        whole = fn(x, y)
        alone = _in_batches(fn, x, y, [(i, i + 1) for i in range(0, n, 7)])
        assert all(_same_bits(w[::7], a) for w, a in zip(whole, alone)), fn.__name__
        assert all(_same_bits(w, a) for w, a in zip(whole, _in_batches(fn, x, y, bounds))), fn.__name__
        assert all(_same_bits(w[rev], a) for w, a in zip(whole, fn(x[rev], y[rev]))), fn.__name__
    # every point through the subdivision fallback: the same bits alone and in the batch
    monkeypatch.setattr(alg, "NEWTON_STEPS", 0)
    monkeypatch.setattr(alg, "EXTRA_STEPS", 0)
    monkeypatch.setattr(alg, "STEP_TOL", -1.0)
    sub = slice(0, n, 10)
    whole = inverse(x[sub], y[sub])
    alone = _in_batches(inverse, x[sub], y[sub], [(i, i + 1) for i in range(0, x[sub].size, 3)])
    assert all(_same_bits(w[::3], a) for w, a in zip(whole, alone))


def test_newton_failure_is_caught(monkeypatch):
    """A location that is wrong (piece flipped) makes Newton leave the piece: the fallback fixes it."""
    real = alg.locate

    def wrong(D, a, b, fast=True):
        n, p, a1, b1, n0 = real(D, a, b, fast)
        return n, 1 - p, a1, b1, n0

    monkeypatch.setattr(alg, "locate", wrong)
    rng = np.random.default_rng(9)
    x, y = rng.random(2000), rng.random(2000)
    err, res = roundtrip_error(8, x, y)
    assert err <= TOL
    assert res.stats["fallback"] > 1000


def test_special_points():
    for k in (3, 5, 12):
        r, s = inverse_characteristic_map(k, [0.0, 0.7, 0.0, 0.4], [0.0, 0.0, 0.7, 0.4])
        assert r[0] == 0 and s[0] == 0
        assert s[1] == 0 and r[2] == 0          # axes to axes, exactly
        assert r[3] == pytest.approx(s[3], abs=1e-14)  # the diagonal to the diagonal
        r, s = inverse_characteristic_map(k, 1.0, 0.0)
        assert r == pytest.approx(1.0, abs=1e-15) and s == 0
    # far out and very close to the extraordinary vertex (quadrant extension, no overflow); for
    # k >= 5 (lam > 1/2) preimages of t ~ 1e-300 are below the float range and underflow to 0
    for k in (3, 5, 100):
        x = np.array([1e6, 3e-300, 5e-324, 1e-12, 2.0, 1e-100])
        y = np.array([2e5, 1e-300, 0.0, 3e-13, 7.0, 1e-101])
        res = inverse_characteristic_map(k, x, y, full_output=True)
        assert np.all(np.isfinite(res.r)) and np.all(res.r >= 0) and np.all(res.s >= 0)
        X, Y = characteristic_map(k, res.r, res.s)
        ok = res.r > 1e-280
        assert ok.sum() >= (6 if k == 3 else 4)
        scale = np.maximum(x, y)[ok]
        assert np.all(np.abs(X - x)[ok] <= 1e-14 * scale) and np.all(np.abs(Y - y)[ok] <= 1e-14 * scale)


def test_face_domain():
    r, s = inverse_characteristic_map(5, [0.3, 1.0], [0.2, 0.0], domain="face")
    assert np.all(r <= 1) and np.all(s <= 1)
    with pytest.raises(CCProofError, match="outside the image"):
        inverse_characteristic_map(5, 0.95, 0.95, domain="face")   # Phi(1,1) = (0.833, 0.833) for k = 5
    with pytest.raises(CCProofError):
        inverse_characteristic_map(5, 0.5, 0.5, domain="disk")


def test_bad_input():
    for bad in (np.nan, np.inf, -np.inf, -1e-300, -1.0):
        with pytest.raises(CCProofError):
            inverse_characteristic_map(5, [0.2, bad], [0.3, 0.3])
        with pytest.raises(CCProofError):
            inverse_characteristic_map(5, 0.2, bad)
    for k in (2, 0, -3, 2.5, "x", True):
        with pytest.raises(ValenceError):
            inverse_characteristic_map(k, 0.2, 0.3)
    with pytest.raises(CCProofError):
        inverse_characteristic_map(5, "a", 0.3)
    with pytest.raises(CCProofError):
        inverse_characteristic_map(5, [0.1, 0.2], [0.1, 0.2, 0.3])
    assert isinstance(CCProofError("x"), ValueError)


def test_shapes():
    r, s = inverse_characteristic_map(5, np.full((3, 4), 0.3), 0.2)
    assert r.shape == (3, 4) and s.shape == (3, 4)
    r, s = inverse_characteristic_map(5, [], [])
    assert r.shape == (0,)


@pytest.mark.parametrize("k", [3, 4, 7, 100])
def test_rigorous_boxes(k):
    """arb certificates: every box is certified and the float answer is within 1e-14 of it."""
    rng = np.random.default_rng(2)
    x = np.r_[rng.random(6), [1.0, 0.0, 0.6, 2.5, 1e-9]]
    y = np.r_[rng.random(6), [0.0, 0.6, 0.6, 0.1, 2e-9]]
    # and two points exactly on piece boundaries (images of u = 1/2, v = 1/2)
    bx, by = characteristic_map(k, [0.5, 0.75], [0.25, 0.5])
    x, y = np.r_[x, bx], np.r_[y, by]
    res = inverse_characteristic_map(k, x, y, rigorous=True)
    assert res.stats["uncertified"] == 0
    for i, box in enumerate(res.boxes):
        assert box.certified
        assert box.width < 1e-25
        assert box.distance(res.r[i], res.s[i]) <= 1e-14 * max(1.0, res.r[i], res.s[i])
