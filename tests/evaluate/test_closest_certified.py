"""Certified closest points (ccproof.evaluate.closest_certified): enclosures against brute force,
ambiguity at the centre of the cube, no certificate for a wrong answer."""

import numpy as np
import pytest

from ccproof.errors import CCProofError
from ccproof.evaluate import limit_surface
from ccproof.evaluate.closest import closest_points
from ccproof.evaluate.closest_certified import CertifyLimits, certify_closest

from .test_closest import brute_force


@pytest.fixture(scope="module")
def cube(refdir):
    return limit_surface(refdir / "meshes" / "cube.obj")


def test_certified_enclosure_contains_brute_force(cube):
    X = np.array([[0.3, -0.2, 0.9], [0.6, 0.5, -0.4]])
    res = closest_points(cube, X)
    ref, refP = brute_force(cube, X)
    for i in range(X.shape[0]):
        c = certify_closest(cube, X[i], res.face[i], res.u[i], res.v[i])
        assert c.verdict == "certified", c.message
        assert c.distance_lo <= ref[i] * (1 + 1e-15) and ref[i] <= c.distance_hi * (1 + 1e-15)
        assert c.distance_hi - c.distance_lo <= 1e-9
        # the brute-force minimizer lies in one of the certified parameter boxes (up to its accuracy)
        assert any(b[0] == res.face[i] for b in c.boxes)
        assert c.parameter_radius <= 1e-4


def test_centre_of_the_cube_is_ambiguous(cube):
    res = closest_points(cube, np.zeros((1, 3)))
    c = certify_closest(cube, np.zeros(3), res.face[0], res.u[0], res.v[0], CertifyLimits(max_level=4))
    assert c.verdict == "ambiguous", c.message
    assert c.distance_lo <= 68 / 81 <= c.distance_hi


def test_wrong_answer_is_not_certified(cube):
    x = np.array([0.3, -0.2, 0.9])
    res = closest_points(cube, x[None])
    wrong = (res.face[0] + 1) % 6  # a face on another side of the cube
    c = certify_closest(cube, x, wrong, 0.5, 0.5, CertifyLimits(max_level=5, max_pieces=3000))
    assert c.verdict != "certified"
    # the upper bound is still rigorous: a surface point at most that far
    assert c.distance_hi >= res.distance[0]


def test_non_quad_input_refused():
    class Fake:
        class mesh:
            faces = np.zeros((2, 3), dtype=int)
            vertices = np.zeros((3, 3))

    with pytest.raises(CCProofError, match="quad"):
        certify_closest(Fake(), [0, 0, 0], 0, 0.5, 0.5)


@pytest.mark.parametrize("name", ["cube", "sector_k5", "sector_k3"])
def test_local_refinement_matches_the_evaluator(refdir, name):
    """The arb one-rings of deep pieces: their corner limit points are the evaluator's positions at the
    piece corners, and the evaluator's point inside the piece lies in the box of its one-ring."""
    import flint

    from ccproof.evaluate import closest_certified as cc

    S = limit_surface(refdir / "meshes" / f"{name}.obj")
    F, Vx = S.mesh.faces, S.mesh.vertices
    rng = np.random.default_rng(2)
    old = flint.ctx.prec
    flint.ctx.prec = cc.PREC
    try:
        arb = flint.arb
        for _ in range(6):
            f = int(rng.integers(F.shape[0]))
            u, v = rng.random(2)
            ring = sorted({g for g in range(F.shape[0]) if set(F[g]) & set(F[f])})
            verts = sorted({w for g in ring for w in F[g]})
            loc = {w: i for i, w in enumerate(verts)}
            p = cc._Piece([tuple(loc[w] for w in F[g]) for g in ring], [[arb(float(t)) for t in Vx[w]] for w in verts],
                          ring.index(f), f, 0.0, 0.0, 1.0, 0)
            for _level in range(7):
                p = cc._corner_piece(p, u, v, arb)
            cu = np.array([p.u0, p.u0 + p.h, p.u0 + p.h, p.u0])
            cv = np.array([p.v0, p.v0, p.v0 + p.h, p.v0 + p.h])
            ref = S.evaluate(np.full(4, f), cu, cv, 0)["P"]
            lim = np.array([[float(c.mid()) for c in L] for L in cc._corner_limits(p, arb)])
            np.testing.assert_allclose(lim, ref, rtol=0, atol=1e-14)
            P = S.evaluate([f], [u], [v], 0)["P"][0]
            lo = np.array([min(float(q[k].lower()) for q in p.pts) for k in range(3)])
            hi = np.array([max(float(q[k].upper()) for q in p.pts) for k in range(3)])
            assert np.all(P >= lo - 1e-15) and np.all(P <= hi + 1e-15)
    finally:
        flint.ctx.prec = old
