"""Bad input is refused with a message naming the element; vertex normals at every kind of vertex."""

import json

import numpy as np
import pytest

from ccproof.errors import CCProofError, MeshError
from ccproof.evaluate import limit_surface
from ccproof.evaluate.backend import available_backends
from ccproof.evaluate.local import corner_scheme, quad_ring
from ccproof.mesh import QuadMesh, limit_normals, read_obj
from ccproof.mesh.examples import cube, k_regular_disk, l_shape


@pytest.fixture(scope="module")
def S():
    return limit_surface(cube())


def test_face_id_out_of_range(S):
    with pytest.raises(CCProofError, match=r"point 2: face id 6 out of range \[0, 6\)"):
        S.evaluate([0, 1, 6], [0.5] * 3, [0.5] * 3)
    with pytest.raises(CCProofError, match="point 0: face id -1"):
        S.evaluate([-1], [0.5], [0.5])
    with pytest.raises(CCProofError, match="point 1: face id 1.5 is not an integer"):
        S.evaluate([0.0, 1.5], [0.5] * 2, [0.5] * 2)


def test_parameter_outside_unit_square(S):
    with pytest.raises(CCProofError, match=r"point 1: u = 1.0000001 is outside \[0, 1\]"):
        S.evaluate([0, 0], [0.5, 1.0000001], [0.5, 0.5])
    with pytest.raises(CCProofError, match=r"point 0: v = -1e-300 is outside"):
        S.evaluate([0], [0.5], [-1e-300])
    with pytest.raises(CCProofError, match="point 0: u = nan"):
        S.evaluate([0], [np.nan], [0.5])


@pytest.mark.parametrize("backend, threads", [("numpy", 1), ("numba", 1), ("numba", 2), ("c", 1), ("c", 2)])
def test_bad_point_far_into_a_batch_is_named_by_every_backend(S, backend, threads):
    """The compiled kernels check the points themselves, block by block in their threads; the message is
    the same as the numpy path's and names the first bad point of the batch."""
    if backend not in available_backends():
        pytest.skip(f"backend {backend!r} not available in this install")
    n = 300_000
    rng = np.random.default_rng(5)
    f, u, v = rng.integers(0, 6, n), rng.random(n), rng.random(n)
    for i, field, bad, msg in [(250_001, "u", 1.5, r"point 250001: u = 1.5 is outside"),
                               (299_999, "v", np.nan, r"point 299999: v = nan is outside"),
                               (170_000, "f", 6, r"point 170000: face id 6 out of range \[0, 6\)")]:
        arrays = {"f": f.copy(), "u": u.copy(), "v": v.copy()}
        arrays[field][i::997] = bad  # later bad points too: the first one is named
        ff, uu, vv = arrays.values()
        with pytest.raises(CCProofError, match=msg):
            S.evaluate(ff, uu, vv, 1, backend=backend, threads=threads)


def test_shapes_and_derivative_order(S):
    with pytest.raises(CCProofError, match="same length"):
        S.evaluate([0, 1], [0.5, 0.5, 0.5], [0.5])
    with pytest.raises(CCProofError, match="derivatives must be 0, 1 or 2"):
        S.evaluate([0], [0.5], [0.5], derivatives=3)
    r = S.evaluate(np.array([], int), [], [], 2)
    assert set(r) == {"P", "Pu", "Pv", "Puu", "Puv", "Pvv"} and r["P"].shape == (0, 3)


def test_bad_meshes_are_refused():
    V = np.array(cube().vertices)
    V[3, 2] = np.nan
    with pytest.raises(MeshError, match="vertex 3 has a non-finite coordinate"):
        limit_surface(QuadMesh(V, cube().faces))
    with pytest.raises(MeshError, match=r"interior vertex \d has valence 2"):
        limit_surface(QuadMesh(np.eye(4, 3), [[0, 1, 2, 3], [3, 2, 1, 0]]))


def test_obj_path_and_non_quad(tmp_path):
    p = tmp_path / "t.obj"
    p.write_text("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nf 1 2 3 4\nf 2 5 3\n")
    S = limit_surface(p)  # a quad and a triangle: 1 + 3 ptex faces
    assert S.n_faces == 4
    with pytest.raises(CCProofError, match=r"point 0: face id 4 out of range \[0, 4\)"):
        S.evaluate([4], [0.5], [0.5])
    # the triangle's sub-faces meet at its centre (1, 1) in every sub-face's (s, t)
    P = S.evaluate([1, 2, 3], [1.0] * 3, [1.0] * 3)["P"]
    assert np.abs(P - P[0]).max() < 1e-15


def test_chunking_and_backends_agree():
    m = cube()
    S = limit_surface(m)
    rng = np.random.default_rng(0)
    f, u, v = rng.integers(0, m.n_faces, 1000), rng.random(1000), rng.random(1000)
    u[:100] = 0.5 ** rng.integers(0, 200, 100)  # every layer, down to the innermost table and beyond
    v[:100] = u[:100] * rng.random(100)
    u[100:110], v[100:110] = 0.0, 0.0
    u[110:120], v[110:120] = 1.0, 1.0 - 2.0**-53
    a = S.evaluate(f, u, v, 2, backend="numpy")
    b = S.evaluate(f, u, v, 2, chunk=7, backend="numpy")
    assert all(np.array_equal(a[k], b[k]) for k in a)
    with pytest.raises(CCProofError, match="unknown backend"):
        S.evaluate(f, u, v, 1, backend="cuda")
    for backend in available_backends()[:-1]:  # the compiled ones: the same sums, the same bits
        c = S.evaluate(f, u, v, 2, backend=backend)
        for k in a:
            assert np.array_equal(a[k], c[k]), (backend, k)


def test_normals_at_opensubdiv_vertices(refdir):
    """All vertices, including boundary vertices with one face (tangent masks of the exact corner
    matrix, whose second eigenvalue 1/4 is defective)."""
    for name in ["sector_k3", "sector_k5", "cube"]:
        d = json.loads((refdir / f"osd_limit_{name}.json").read_text())
        S = limit_surface(read_obj(refdir / "meshes" / f"{name}.obj"))
        assert np.abs(S.vertex_normals() - np.array(d["vertex_limit_normal"])).max() < 1e-13


def test_corner_tangent_masks_equal_interior_masks():
    m = k_regular_disk(7, 3)
    m = m.with_vertices(m.vertices + 0.1 * np.random.default_rng(2).normal(size=m.vertices.shape))
    ring, key = quad_ring(m.faces, 0, 0)
    t1, t2 = corner_scheme(key).tangent_masks @ m.vertices[ring]
    n = np.cross(t1, t2)
    n /= np.linalg.norm(n)
    assert abs(abs(n @ limit_normals(m)[0]) - 1) < 1e-14


def test_concave_boundary_vertex_normal_is_the_limit_of_surface_normals():
    m = l_shape(0)
    S = limit_surface(m)
    v = int(np.flatnonzero(m.is_boundary_vertex & (m.face_count == 3))[0])
    N = S.vertex_normals()[v]
    _, _, faces = m.one_ring(v)
    errs = []
    for n in (10, 30, 50):
        h = 2.0**-n
        for f in faces:
            i = list(m.faces[f]).index(v)
            cu, cv = [(0, 0), (1, 0), (1, 1), (0, 1)][i]
            r = S.evaluate([f], [abs(cu - h)], [abs(cv - 0.7 * h)], 1)
            nn = np.cross(r["Pu"][0], r["Pv"][0])
            errs.append(np.linalg.norm(nn / np.linalg.norm(nn) - N))
    errs = np.array(errs).reshape(3, -1).max(axis=1)
    assert errs[2] < errs[1] < errs[0] and errs[2] < 1e-3  # converges like (0.5/0.5797)^n
