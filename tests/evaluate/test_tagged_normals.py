"""Limit normals of tagged meshes: at vertices against OpenSubdiv and closed-form eigen masks, and
unit and continuous near extraordinary, crease, dart and boundary vertices."""

import json

import numpy as np
import pytest

from ccproof.evaluate import limit_surface
from ccproof.evaluate.local import CORNERS
from ccproof.mesh import QuadMesh, limit_normals
from ccproof.mesh.io import read_obj_tagged


def _load(refdir, name):
    d = json.loads((refdir / "osd_features" / f"osd_limit_catmark_{name}.json").read_text())
    m = read_obj_tagged(refdir / "osd_features" / d["mesh"])
    return d, m, limit_surface(m)


@pytest.mark.parametrize("name", ["cube_corner2", "pyramid_creases1", "cube_creases0", "dart_edgeonly",
                                  "nonquads", "edgecorner", "cubes_infsharp"])
def test_vertex_normals_match_opensubdiv(refdir, name):
    d, m, S = _load(refdir, name)
    N = S.vertex_normals()
    ref = d["vertex_limit_normal"]
    rows = [v for v, r in enumerate(ref) if r is not None]
    assert len(rows) >= 5
    assert np.abs(N[rows] - np.array([ref[v] for v in rows])).max() <= 1e-13


def test_normals_at_evs_equal_eigen_masks_and_are_continuous(refdir):
    """nonquads: n-gon centres (valence 3, 5, 6 after one step) and triangle centres (valence 3)."""
    d, m, S = _load(refdir, "nonquads")
    m1, _ = m.refine()
    Q = QuadMesh(m1.vertices, np.array(m1.polygons))
    ref = limit_normals(Q)  # closed-form eigen masks (Halstead et al.) at interior vertices
    checked = 0
    for f in np.flatnonzero(m.sizes != 4):
        k = int(m.sizes[f])
        centre = m.n_vertices + len(m.complex().edges) + int(f)  # the face point at level 1
        assert Q.valence[centre] == k and not Q.is_boundary_vertex[centre]
        p = m.ptex_start[f] + np.arange(k)
        Nc = S.normals(p, np.ones(k), np.ones(k))
        assert np.abs(Nc - ref[centre]).max() <= 1e-14
        # approach along rays in every sub-face: unit, converging to the vertex normal
        prev = np.inf
        for r in (2.0**-4, 2.0**-12, 2.0**-24, 2.0**-36, 2.0**-48):
            Nr = S.normals(p, np.full(k, 1 - r), np.full(k, 1 - 0.5 * r))
            assert np.abs(np.linalg.norm(Nr, axis=1) - 1).max() <= 1e-15
            gap = np.abs(Nr - ref[centre]).max()
            assert gap <= max(prev, 1e-14)  # monotone approach
            prev = gap
        assert prev <= 1e-7
        checked += 1
    assert checked == 10


@pytest.mark.parametrize("name,kind", [("cubes_infsharp", "crease_ev"), ("cubes_infsharp", "dart"),
                                       ("dart_edgeonly", "boundary_ev"), ("xord_boundary", "boundary_ev"),
                                       ("cube_creases0", "ev"), ("edgecorner", "corner")])
def test_normals_near_feature_vertices_converge(refdir, name, kind):
    """In every face at the vertex (a crease has one tangent plane per side), along a ray."""
    d, m, S = _load(refdir, name)
    verts = [fv["vertex"] for fv in d["feature_vertices"] if fv["kind"] == kind]
    checked = 0
    for v in verts:
        for f, poly in enumerate(m.polygons):
            if v not in poly or m.is_hole[f] or len(poly) != 4:
                continue
            i = poly.index(v)
            c = np.array(CORNERS[i], float)
            a = np.array(CORNERS[(i + 1) % 4], float) - c
            b = np.array(CORNERS[(i + 3) % 4], float) - c
            n0 = S.normals([m.ptex_start[f]], [c[0]], [c[1]])[0]
            assert abs(np.linalg.norm(n0) - 1) <= 1e-15
            prev = first = None
            for e in (6, 14, 24, 36, 52):
                r = 2.0**-e
                st = c + r * a + 0.5 * r * b
                n = S.normals([m.ptex_start[f]], [st[0]], [st[1]])[0]
                assert abs(np.linalg.norm(n) - 1) <= 1e-15
                gap = np.abs(n - n0).max()
                if prev is not None:
                    assert gap <= max(prev, 1e-14), (v, f, e, gap, prev)  # monotone approach
                prev = gap
                first = gap if first is None else first
            # geometric convergence (slowest here: 6-face boundary vertex of xord_boundary, about 0.89 per level)
            assert prev <= max(1e-2 * first, 1e-14), (v, f, prev, first)
            checked += 1
    assert checked >= 3


def _subdominant(S, p, c):
    """Largest eigenvalue below 1 of the corner's subdivision matrix on the points the face uses."""
    from ccproof.evaluate.local import _fmpq_mat_to_float
    from ccproof.evaluate.surface import KIND_CORNER

    job, vf, kind = S.patch_map.faces(np.array([p]), np.array([c[0]]), np.array([c[1]]))
    assert kind[0] == KIND_CORNER
    scheme, _ = S._corner_leaf(int(job[0]), int(vf[0]))
    A = _fmpq_mat_to_float(scheme.A)
    sup = list(scheme.support) if scheme.support else list(range(A.shape[0]))
    ev = np.abs(np.linalg.eigvals(A[np.ix_(sup, sup)]))
    return float(ev[ev < 1 - 1e-9].max())


def _growth(S, p, c, a, b):
    """Fitted slope of log2 |Pu| along the diagonal (2^-m) (a + b), m = 12..44."""
    ms = np.arange(12, 45, 2)
    st = c[None, :] + (2.0**-ms)[:, None] * (a + b)[None, :]
    r = S.evaluate(np.full(ms.size, p), st[:, 0], st[:, 1], 1)
    return float(np.polyfit(ms, np.log2(np.linalg.norm(r["Pu"], axis=1)), 1)[0])


@pytest.mark.parametrize("name,kind", [("cube_creases0", "ev"), ("cubes_infsharp", "corner"),
                                       ("cubes_infsharp", "crease_ev"), ("cubes_infsharp", "dart"),
                                       ("dart_edgeonly", "boundary_ev")])
def test_derivative_growth_follows_the_subdominant_eigenvalue(refdir, name, kind):
    """|Pu| at distance 2^-m grows like (2 lam)^m (bmz04 eq. 3): fitted slope within 1 % of log2(2 lam)."""
    d, m, S = _load(refdir, name)
    v = next(fv["vertex"] for fv in d["feature_vertices"] if fv["kind"] == kind)
    f = next(f for f, poly in enumerate(m.polygons) if v in poly and len(poly) == 4 and not m.is_hole[f])
    i = m.polygons[f].index(v)
    c = np.array(CORNERS[i], float)
    a = np.array(CORNERS[(i + 1) % 4], float) - c
    b = np.array(CORNERS[(i + 3) % 4], float) - c
    lam = _subdominant(S, int(m.ptex_start[f]), c)
    want, got = np.log2(2 * lam), _growth(S, int(m.ptex_start[f]), c, a, b)
    if abs(want) < 1e-9:  # lam = 1/2 (crease curve, one-face corner): bounded derivatives
        assert abs(got) < 1e-4, (lam, got)
    else:
        assert abs(got - want) <= 0.01 * abs(want), (lam, want, got)


def test_derivative_growth_at_ngon_centres_matches_closed_form_eigenvalue(refdir):
    """n-gon centres are smooth vertices of valence n after one step: lam of Catmull-Clark in closed form."""
    d, m, S = _load(refdir, "nonquads")
    for k in (3, 5, 6):
        f = int(np.flatnonzero(m.sizes == k)[0])
        ck = np.cos(2 * np.pi / k)
        lam = (5 + ck + np.cos(np.pi / k) * np.sqrt(2 * (9 + ck))) / 16
        p = int(m.ptex_start[f])
        c = np.array([1.0, 1.0])
        assert abs(_subdominant(S, p, c) - lam) < 1e-12
        got = _growth(S, p, c, np.array([-1.0, 0.0]), np.array([0.0, -1.0]))
        assert abs(got - np.log2(2 * lam)) <= 0.01 * abs(np.log2(2 * lam)), (k, got)
