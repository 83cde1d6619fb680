"""LimitSurface.with_vertices (same connectivity, new control points) against a fresh build.

The reference is the evaluator built from scratch on ``mesh.with_vertices(X)`` (the builder's own
stencils on the new positions); ``with_vertices`` applies linear maps found by probing the builder
with indicator vectors, so the two share no arithmetic on the positions.
"""

import numpy as np
import pytest

from ccproof.errors import CCProofError, MeshError
from ccproof.evaluate import LimitSurface, natural_limit_surface
from ccproof.mesh import read_obj
from ccproof.mesh.examples import cube, k_regular_disk, l_shape, torus


def _meshes(refdir):
    return {
        "cube": cube(),  # every face has four extraordinary vertices: local splits
        "torus": torus(),  # regular
        "disk_k5": k_regular_disk(5, 3),  # boundary, an extraordinary vertex
        "l_shape": l_shape(),  # boundary corners
        "sector_k3": read_obj(refdir / "meshes" / "sector_k3.obj"),
    }


def _params(rng, nf, n):
    """Random points biased to the face corners, and the corners themselves."""
    f = rng.integers(0, nf, n)
    u, v = rng.random(n) ** 4, rng.random(n) ** 4
    flip = rng.random((2, n)) < 0.5
    u, v = np.where(flip[0], 1 - u, u), np.where(flip[1], 1 - v, v)
    fc = np.repeat(np.arange(nf), 4)
    uc, vc = np.tile([0.0, 1.0, 1.0, 0.0], nf), np.tile([0.0, 0.0, 1.0, 1.0], nf)
    return np.r_[f, fc], np.r_[u, uc], np.r_[v, vc]


@pytest.mark.parametrize("name", ["cube", "torus", "disk_k5", "l_shape", "sector_k3"])
def test_with_vertices_equals_a_fresh_build(refdir, name):
    mesh = _meshes(refdir)[name]
    rng = np.random.default_rng(7)
    S = LimitSurface(mesh)
    f, u, v = _params(rng, mesh.n_faces, 3000)
    before = S.evaluate(f, u, v, 2)
    V = np.asarray(mesh.vertices)
    scale = np.abs(V).max()
    for trial in range(2):  # the second call re-uses the maps of the first
        X = V + 0.2 * scale * rng.standard_normal(V.shape) + trial
        T = S.with_vertices(X)
        R = LimitSurface(mesh.with_vertices(X))
        assert np.array_equal(T.mesh.vertices, X) and T.n_patches == R.n_patches
        a, b = T.evaluate(f, u, v, 2), R.evaluate(f, u, v, 2)
        # round-off model: both evaluators carry nets with absolute errors of a few eps |X| (sums of
        # up to ~20 products), which a derivative of order k multiplies by the patch scale^k (up to
        # 2^62 deep in an irregular corner's layers, where the second derivatives are not determined by
        # floating point at all)
        psc = S.locate(f, u, v)[3]
        xmax = np.abs(X).max()
        for k in a:
            order = {"P": 0, "Pu": 1, "Pv": 1}.get(k, 2)
            err = np.linalg.norm(a[k] - b[k], axis=1)
            tol = 1e-12 * (1 + np.linalg.norm(b[k], axis=1)) + 64 * 2.2e-16 * xmax * psc**order
            assert (err <= tol).all(), (k, (err / tol).max())
            if order < 2:  # and P, Pu, Pv agree to 1e-12 relative everywhere (corners included)
                assert (err <= 1e-12 * (1 + np.linalg.norm(b[k], axis=1))).all(), k
        na, nb = T.vertex_normals(), R.vertex_normals()
        assert np.array_equal(np.isnan(na), np.isnan(nb))
        assert np.nanmax(np.abs(na - nb)) < 1e-12
        Na, Nb = T.normals(f, u, v), R.normals(f, u, v)
        # at the innermost layer of a corner (the corner itself) the eigen normal is oriented by the sign
        # of Pu x Pv there, which is round-off in both evaluators: compared up to sign
        inner = psc >= 2.0**60
        Na[inner] *= np.sign(np.einsum("ij,ij->i", Na[inner], Nb[inner]))[:, None]
        assert np.nanmax(np.abs(Na - Nb)) < 1e-10
        np.testing.assert_allclose(T.closest_points(b["P"][:50] + 0.01).distance,
                                   R.closest_points(b["P"][:50] + 0.01).distance, rtol=1e-10, atol=1e-13)
    # the original surface is untouched
    after = S.evaluate(f, u, v, 2)
    assert all(np.array_equal(before[k], after[k]) for k in before)
    # chained: a derived surface moves again like the original
    Y = V + 0.1 * scale * rng.standard_normal(V.shape)
    c = S.with_vertices(X).with_vertices(Y).evaluate(f, u, v, 0)
    d = LimitSurface(mesh.with_vertices(Y)).evaluate(f, u, v, 0)
    assert np.abs(c["P"] - d["P"]).max() < 1e-12 * (1 + np.abs(d["P"]).max())


def test_with_vertices_bad_input():
    S = LimitSurface(cube())
    with pytest.raises(MeshError, match="shape"):
        S.with_vertices(np.zeros((3, 3)))
    X = np.array(cube().vertices)
    X[3, 1] = np.nan
    with pytest.raises(MeshError, match="vertex 3"):
        S.with_vertices(X)
    from ccproof.mesh.polymesh import PolyMesh

    tagged = natural_limit_surface(PolyMesh(cube().vertices, [list(f) for f in cube().faces], corners={0: 10}))
    with pytest.raises(MeshError, match="shape"):
        tagged.with_vertices(np.zeros((3, 3)))
    with pytest.raises(MeshError, match="vertex 3"):
        tagged.with_vertices(X)
    with pytest.raises(CCProofError, match="shape"):  # MeshError is a CCProofError
        tagged.with_vertices(np.zeros((8, 2)))
