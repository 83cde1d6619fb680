"""The compiled Newton descent of the closest points gives the numpy descent's numbers bit for bit."""

import numpy as np
import pytest

from ccproof import limit_surface
from ccproof.errors import CCProofError
from ccproof.evaluate import natural_limit_surface
from ccproof.evaluate.closest import closest_points
from ccproof.evaluate.newton import newton_descent
from ccproof.mesh.examples import torus
from ccproof.mesh.io import read_mesh

pytest.importorskip("numba")


def _starts(S, n, seed):
    """Points off the surface and starting parameters away from their feet, many deep in the
    layers of irregular corners and on face edges."""
    rng = np.random.default_rng(seed)
    f = rng.choice(np.flatnonzero(~S._refused_faces()), n)  # not on holes
    u, v = rng.random(n), rng.random(n)
    r = S.evaluate(f, u, v, 1)
    nrm = np.cross(r["Pu"], r["Pv"])
    nrm /= np.linalg.norm(nrm, axis=1)[:, None]
    X = r["P"] + 0.05 * rng.standard_normal((n, 1)) * nrm + 0.02 * rng.standard_normal((n, 3))
    u0 = np.clip(u + 0.3 * rng.standard_normal(n), 0.0, 1.0)
    v0 = np.clip(v + 0.3 * rng.standard_normal(n), 0.0, 1.0)
    m = n // 10
    u0[:m] = 2.0 ** -rng.integers(1, 70, m)
    v0[:m] = u0[:m] * rng.random(m)
    u0[m : 2 * m] = 1.0
    return X, f, u0, v0


MESHES = ["torus", "catmark_pyramid_creases1", "catmark_dart_edgeonly", "catmark_hole_test2", "catmark_smoothtris1",
          "sector_k5"]


@pytest.mark.parametrize("mesh", MESHES)
def test_compiled_descent_equals_numpy_descent(refdir, mesh):
    if mesh == "torus":
        S = natural_limit_surface(torus())
    elif mesh == "sector_k5":
        S = natural_limit_surface(refdir / "meshes" / "sector_k5.obj")
    else:
        S = natural_limit_surface(read_mesh(refdir / "osd_features" / "meshes" / f"{mesh}.obj"))
    X, f, u0, v0 = _starts(S, 3000, seed=len(mesh))
    a = newton_descent(S, X, f, u0, v0, backend="numpy")
    b = newton_descent(S, X, f, u0, v0, backend="numba", threads=1)
    c = newton_descent(S, X, f, u0, v0, backend="numba", threads=3)
    for x, y, z in zip(a, b, c):
        assert np.array_equal(x, y) and np.array_equal(y, z)
    # the descent did something: most points moved, none got farther
    E0 = 0.5 * ((S.evaluate(f, u0, v0, 0)["P"] - X) ** 2).sum(axis=1)
    assert (a[2] <= E0).all() and (a[2] < E0).mean() > 0.5


def test_compiled_descent_checks_its_points():
    S = natural_limit_surface(torus())
    X = np.zeros((2, 3))
    with pytest.raises(CCProofError, match=r"point 1: face id \d+ out of range"):
        newton_descent(S, X, [0, S.n_faces], [0.5, 0.5], [0.5, 0.5])
    with pytest.raises(CCProofError, match="point 0: u = nan"):
        newton_descent(S, X, [0, 1], [np.nan, 0.5], [0.5, 0.5])
    with pytest.raises(CCProofError, match="one row per point"):
        newton_descent(S, np.zeros((3, 3)), [0, 1], [0.5, 0.5], [0.5, 0.5])


def test_reparameterizable_surfaces_take_the_compiled_descent():
    """A parameterization is an argument of evaluate, not a kind of surface: the surface of
    ccproof.limit_surface is the natural evaluator, descended by the compiled kernel."""
    S = limit_surface(torus())  # named parameterizations recorded; its evaluate defaults to natural
    assert S._newton_kernel() is not None
    assert natural_limit_surface(torus())._newton_kernel() is not None
    X = natural_limit_surface(torus()).evaluate([3, 7], [0.2, 0.9], [0.4, 0.1], 0)["P"]
    res = closest_points(S, X)
    assert res.distance.max() < 1e-12
