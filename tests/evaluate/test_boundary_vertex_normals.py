"""Limit normals at the irregular boundary vertices of a quad mesh (one face, or three and more: no closed-form
mask), computed at once from the exact corner matrices, against two independent computations: ``Pu x Pv`` of the
limit surface evaluated ever closer to the vertex (it converges to the vertex's normal, slowly where the third
eigenvalue is close to the subdominant ones), and the tagged evaluator's normals of the same mesh as a PolyMesh
(another corner per vertex, another orientation rule)."""

import numpy as np
import pytest

from ccproof.evaluate.surface import LimitSurface
from ccproof.mesh import QuadMesh
from ccproof.mesh.polymesh import PolyMesh


def _capped_sphere_quads(level=2, noise=0.02):
    """A noisy icosphere with its cap z > 0.5 removed (a boundary with vertices of 3 and 4 triangles), each
    triangle split into three quads (centroid and edge midpoints)."""
    t = (1 + 5**0.5) / 2
    V = np.array([[-1, t, 0], [1, t, 0], [-1, -t, 0], [1, -t, 0], [0, -1, t], [0, 1, t], [0, -1, -t], [0, 1, -t],
                  [t, 0, -1], [t, 0, 1], [-t, 0, -1], [-t, 0, 1]], dtype=float)
    F = np.array([[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9], [5, 11, 4], [11, 10, 2],
                  [10, 7, 6], [7, 1, 8], [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8], [3, 8, 9], [4, 9, 5],
                  [2, 4, 11], [6, 2, 10], [8, 6, 7], [9, 8, 1]])

    def split(V, F, quads):
        e = np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1)
        uniq, inv = np.unique(e, axis=0, return_inverse=True)
        ab, bc, ca = (len(V) + inv.reshape(3, -1)).reshape(3, -1)
        V = np.vstack([V, 0.5 * (V[uniq[:, 0]] + V[uniq[:, 1]])])
        a, b, c = F.T
        if quads:
            cen = len(V) + np.arange(len(F))
            V = np.vstack([V, V[F].mean(axis=1)])
            return V, np.concatenate([np.stack(x, 1) for x in ((a, ab, cen, ca), (b, bc, cen, ab), (c, ca, cen, bc))])
        return V, np.concatenate([np.stack(x, 1) for x in ((a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca))])

    for _ in range(level):
        V, F = split(V, F, False)
    V /= np.linalg.norm(V, axis=1)[:, None]
    F = F[V[F].mean(axis=1)[:, 2] < 0.5]
    used = np.unique(F)
    remap = np.full(len(V), -1)
    remap[used] = np.arange(used.size)
    V, F = split(V[used], remap[F], True)
    V = V + noise * np.random.default_rng(7).standard_normal(V.shape)
    return QuadMesh(V, F)


@pytest.fixture(scope="module")
def case():
    Q = _capped_sphere_quads()
    return Q, LimitSurface(Q), LimitSurface(Q).vertex_normals()


def _corner_points(Q, verts, h):
    """(face, u, v) at distance h (in u and v) from each vertex inside its first face, and the corner's index."""
    F = Q.faces
    face, corner = np.divmod(np.array([np.flatnonzero(F.reshape(-1) == x)[0] for x in verts]), 4)
    u = np.where(np.isin(corner, (1, 2)), 1 - h, h)
    v = np.where(np.isin(corner, (2, 3)), 1 - h, h)
    return face, u, v


def test_boundary_normals_are_the_limit_of_pu_x_pv(case):
    Q, S, N = case
    irregular = np.flatnonzero(Q.is_boundary_vertex & (Q.face_count != 2))
    assert irregular.size >= 10 and {3, 4}.issubset(set(Q.face_count[irregular].tolist()))
    assert not np.isnan(N[irregular]).any()
    dist = []
    for h in (1e-4, 1e-8, 1e-12):
        r = S.evaluate(*_corner_points(Q, irregular, h), 1)
        n = np.cross(r["Pu"], r["Pv"])
        n /= np.linalg.norm(n, axis=1)[:, None]
        dist.append(np.linalg.norm(N[irregular] - n, axis=1))
    # closer to the vertex, closer to its normal, at every irregular boundary vertex (a wrong plane or a wrong
    # orientation stays away: about 1 or 2)
    assert (dist[2] < dist[1]).all() and (dist[1] < dist[0]).all(), dist
    assert dist[2].max() < 0.25 and np.median(dist[2]) < 0.02, dist[2]


def test_boundary_normals_equal_the_tagged_evaluators(case):
    Q, S, N = case
    M = LimitSurface(PolyMesh(Q.vertices, Q.faces.tolist())).vertex_normals()
    assert np.abs(N - M).max() < 1e-12
