"""Vertex limits and normals of tagged meshes go through the batched evaluation of points (one corner per
vertex, the compiled kernels, the tangent masks of all the corners of a configuration in one product), with
the values of the former point-by-point route to the bit, and the limit positions of the masks of the refined
mesh (an independent formula) to round-off."""

import numpy as np
import pytest

from ccproof.evaluate import limit_surface
from ccproof.evaluate.tagged import vertex_corners
from ccproof.mesh import limit_positions
from ccproof.mesh.examples import cube
from ccproof.mesh.polymesh import PolyMesh


def _octahedron(noise=0.05, seed=2, levels=2):
    """A closed triangle mesh (valences 4 and 6 after 1-to-4 splits), vertices moved by noise."""
    V = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]], dtype=float)
    F = np.array([[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]])
    for _ in range(levels):
        e = np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1)
        uniq, inv = np.unique(e, axis=0, return_inverse=True)
        mid = V.shape[0] + inv.reshape(3, -1).T
        V = np.vstack([V, 0.5 * (V[uniq[:, 0]] + V[uniq[:, 1]])])
        a, b, c = F.T
        ab, bc, ca = mid.T
        F = np.concatenate([np.stack(x, 1) for x in ((a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca))])
    V = V / np.linalg.norm(V, axis=1)[:, None]
    V *= 1 + noise * np.random.default_rng(seed).standard_normal((V.shape[0], 1))
    return V, F


def _meshes():
    V, F = _octahedron()
    c = cube()
    mixed = [[0, 1, 2], [0, 2, 3, 4], [0, 4, 5], [0, 5, 6, 7, 1]]  # an open fan: triangles, a quad, a pentagon
    W = [[0, 0, 0.2], [1, 0, 0], [0.6, 0.9, 0.1], [-0.3, 1, 0], [-1, 0.2, 0.1], [-0.7, -0.8, 0], [0.1, -1, 0.2],
         [0.9, -0.6, 0]]
    return {
        "triangles": PolyMesh(V, F.tolist()),
        "open triangles": PolyMesh(V, F[:-5].tolist()),
        "tagged cube": PolyMesh(c.vertices, c.faces.tolist(), corners={0: 10}, creases={(1, 2): 2.5}, holes=[5]),
        "n-gons": PolyMesh(W, mixed),
    }


def _former_vertex_limits(S):
    """Every corner of every face by the numpy evaluation, the last corner of a vertex kept."""
    out = np.full((S.mesh.n_vertices, 3), np.nan)
    f, u, v, verts = vertex_corners(S.mesh)
    r = {"P": np.empty((f.size, 3))}
    S._eval_chunk(f, u, v, 0, r)  # (no check: the corners on holes too)
    out[verts] = r["P"]
    return out


def _former_vertex_normals(S):
    """The first corner of a vertex not on a hole; Pu x Pv, or at an irregular corner the tangent masks of that
    corner face alone (one point at a time), oriented like Pu x Pv just inside."""
    from ccproof.evaluate.patch_table import KIND_CORNER

    f, u, v, verts = vertex_corners(S.mesh)
    out = np.full((S.mesh.n_vertices, 3), np.nan)
    T = S._table
    for i in range(f.size)[::-1]:
        if S._hole_ptex[f[i]]:
            continue
        r = S.evaluate([f[i]], [u[i]], [v[i]], 1)
        N = np.cross(r["Pu"][0], r["Pv"][0])
        job, vf, kind = (a[0] for a in S.patch_map.faces(f[i:i + 1], u[i:i + 1], v[i:i + 1]))
        if kind == KIND_CORNER:
            U0, V0, H = T.u0[vf], T.v0[vf], T.h[vf]
            du = ((U0 + H) - u[i] if T.cu[vf] else u[i] - U0) / H
            dv = ((V0 + H) - v[i] if T.cv[vf] else v[i] - V0) / H
            if max(du, dv) < np.ldexp(1.0, -int(T.n_layers[T.cfg[vf]])):
                d = 2.0**-12 * H
                rr = S.evaluate([f[i]], [U0 + H - d if T.cu[vf] else U0 + d], [V0 + H - d if T.cv[vf] else V0 + d], 1)
                e = S._eigen_normal(job, vf)
                ref = np.cross(rr["Pu"][0], rr["Pv"][0])
                N = np.full(3, np.nan) if e is None else (e if np.dot(e, ref) >= 0 else -e)
        out[verts[i]] = N
    with np.errstate(invalid="ignore", divide="ignore"):
        return out / np.linalg.norm(out, axis=1)[:, None]  # as the former route normalized its batch


@pytest.mark.parametrize("name", ["triangles", "open triangles", "tagged cube", "n-gons"])
def test_vertex_limits_and_normals_equal_the_point_by_point_route_to_the_bit(name):
    S = limit_surface(_meshes()[name])
    L, N = S.vertex_limits(), S.vertex_normals()
    assert np.array_equal(L, _former_vertex_limits(S), equal_nan=True)
    assert np.array_equal(N, _former_vertex_normals(S), equal_nan=True)
    used = np.zeros(S.mesh.n_vertices, bool)
    used[S.mesh.indices] = True
    assert np.isfinite(L[used]).all() and np.isnan(L[~used]).all()
    ok = np.isfinite(N).all(axis=1)
    assert ok.sum() >= 0.8 * used.sum() and np.allclose(np.linalg.norm(N[ok], axis=1), 1.0, atol=1e-14)


def test_vertex_limits_equal_the_limit_masks_of_the_refined_mesh():
    """Independent: one Catmull-Clark step (PolyMesh.refine), then the limit masks at the old vertices."""
    mesh = _meshes()["triangles"]
    fine, _ = mesh.refine(operator=False)
    ref = limit_positions(fine.to_quad_mesh())[: mesh.n_vertices]
    got = limit_surface(mesh).vertex_limits()
    assert np.allclose(got, ref, rtol=0, atol=1e-14 * np.abs(ref).max())
    assert not np.allclose(got, mesh.vertices, atol=1e-3)  # (the limit is not the control point)
