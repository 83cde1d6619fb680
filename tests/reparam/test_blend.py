"""The blend F_b of bmz04 eq. (4) maps every face onto itself.

Float checks on dense samples (corners fixed, each side onto itself and increasing, the face into
itself, det DF_b > 0), exact/arb checks on the sides (the characteristic map's boundary control
points lie on the axes, Phi(1, 0) = (1, 0), increasing control abscissae), the derivatives of F_b
against central differences, and the characteristic blend against the forward map (no inverse).
"""

import numpy as np
import pytest
from flint import arb

from ccproof.algebra.specialize import characteristic_map_patches, subdominant_eigenvalue
from ccproof.errors import CCProofError
from ccproof.inverse import characteristic_map
from ccproof.reparam.blend import face_map, from_local, quarter, to_local
from ccproof.reparam.weights import weight_tensor
from ccproof.tables.format import read_table_json, table_nets_arb, table_path

PARAMS = ["vanishing", "characteristic"]
CORNERS = [[5, 3, 13, 4], [20, 6, 8, 0], [3, 3, 3, 3]]
UV_CORNERS = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])


def test_local_frames_roundtrip():
    rng = np.random.default_rng(0)
    u, v = rng.random(1000), rng.random(1000)
    q = quarter(u, v)
    s, t = to_local(q, u, v)
    assert (s <= 0.5).all() and (t <= 0.5).all() and (s >= 0).all() and (t >= 0).all()
    uu, vv = from_local(q, s, t)
    assert np.array_equal(uu, u) and np.array_equal(vv, v)
    for i in range(4):  # local origin = corner i, local s axis towards corner i+1
        qq = np.array([i])
        assert np.array_equal(np.ravel(from_local(qq, np.zeros(1), np.zeros(1))), UV_CORNERS[i])
        a = np.ravel(from_local(qq, np.ones(1), np.zeros(1)))
        assert np.array_equal(a, UV_CORNERS[(i + 1) % 4])


@pytest.mark.parametrize("param", PARAMS)
@pytest.mark.parametrize("corners", CORNERS)
def test_corners_and_sides(param, corners):
    r = face_map(corners, UV_CORNERS[:, 0], UV_CORNERS[:, 1], param)
    assert np.array_equal(np.stack([r["u"], r["v"]], 1), UV_CORNERS)
    x = np.linspace(0, 1, 20001)
    z, o = np.zeros_like(x), np.ones_like(x)
    for u, v, fixed, moving in ((x, z, "v", "u"), (o, x, "u", "v"), (x, o, "v", "u"), (z, x, "u", "v")):
        r = face_map(corners, u, v, param)
        assert np.array_equal(r[fixed], u if fixed == "u" else v)  # stays on its side, exactly
        m = r[moving]
        assert m[0] == 0.0 and m[-1] == 1.0
        assert (np.diff(m) > 0).all()  # increasing: one-to-one onto the side


@pytest.mark.parametrize("param", PARAMS)
@pytest.mark.parametrize("corners", CORNERS)
def test_face_into_itself_positive_jacobian(param, corners):
    g = np.linspace(0, 1, 301)
    u, v = [a.ravel() for a in np.meshgrid(g, g)]
    r = face_map(corners, u, v, param)
    assert (r["u"] >= 0).all() and (r["u"] <= 1).all() and (r["v"] >= 0).all() and (r["v"] <= 1).all()
    ok = ~r["corner"]
    det = np.linalg.det(r["J"][ok])
    assert det.min() > 0  # Proposition 1: with the sides onto themselves, F_b is one-to-one
    assert r["corner"].sum() == sum(1 for k in corners if k not in (0, 4))


@pytest.mark.parametrize("param", PARAMS)
def test_derivatives_by_central_differences(param):
    rng = np.random.default_rng(5)
    corners = [5, 3, 13, 7]
    u, v = rng.uniform(1e-3, 1 - 1e-3, 4000), rng.uniform(1e-3, 1 - 1e-3, 4000)
    r = face_map(corners, u, v, param, derivatives=2)
    h = 1e-7
    for i, (du, dv) in enumerate(((h, 0), (0, h))):
        p = face_map(corners, u + du, v + dv, param, derivatives=1)
        m = face_map(corners, u - du, v - dv, param, derivatives=1)
        J = np.stack([(p["u"] - m["u"]) / (2 * h), (p["v"] - m["v"]) / (2 * h)], axis=1)
        scale = np.abs(r["J"]).max(axis=(1, 2))
        err = np.abs(J - r["J"][:, :, i]).max(axis=1) / scale
        assert err.max() < 1e-6, err.max()
        Hs = np.abs(r["H"]).max(axis=(1, 2, 3)) + scale
        errh = np.abs((p["J"] - m["J"]) / (2 * h) - r["H"][:, :, :, i]).max(axis=(1, 2)) / Hs
        assert errh.max() < 1e-5, errh.max()


@pytest.mark.parametrize("k", [3, 5, 6, 8, 13, 20])
def test_characteristic_blend_against_forward_map(k):
    """G = w Phi^-1(t) + (1 - w) t  <=>  Phi((G - (1 - w) t) / w) = t, checked with Phi only."""
    rng = np.random.default_rng(k)
    s, t = rng.uniform(0, 0.5, 5000), rng.uniform(0, 0.5, 5000)
    r = face_map([k, 4, 4, 4], s, t, "characteristic")
    w = weight_tensor(s, t)[0]
    ok = w > 1e-3
    y = (np.stack([r["u"], r["v"]], 1)[ok] - (1 - w[ok, None]) * np.stack([s, t], 1)[ok]) / w[ok, None]
    x, yy = characteristic_map(k, y[:, 0], y[:, 1])
    assert np.hypot(x - s[ok], yy - t[ok]).max() < 1e-12
    assert np.array_equal(r["u"][~r["active"]], s[~r["active"]])


@pytest.mark.parametrize("k", [3, 5, 6, 8, 13, 20])
def test_phi_keeps_the_sides_arb(k):
    """Certified table nets: the side v = 0 of P1 (layer 0) has control ordinates exactly 0, its
    abscissae increase from lam to 1 (so Phi maps [1/2, 1] x {0} onto [lam, 1] x {0}); P3's side
    u = 0 has abscissae exactly 0. With Phi(y/2) = lam Phi(y) Phi maps each axis onto itself,
    Phi(0) = 0, so Phi^-1 and the blend keep every side of the quarter (and w = 0 at its other
    end): F_b maps each side onto itself by continuity."""
    nets = table_nets_arb(read_table_json(table_path(k)), "bezier")
    lam = subdominant_eigenvalue(k, "arb", 128)
    side = [nets["P1"][i][0] for i in range(4)]
    assert all(p[1] == 0 for p in side)
    assert (side[0][0] - lam).contains(0) and side[3][0] == 1
    assert all(side[i + 1][0] > side[i][0] for i in range(3))
    assert all(nets["P3"][0][j][0] == 0 for j in range(4))
    assert nets["P3"][0][3] == (arb(0), arb(1))  # Phi(0, 1) = (0, 1)


@pytest.mark.parametrize("k", [5])
def test_phi_keeps_the_sides_exact(k):
    nets = characteristic_map_patches(k, "bezier", "exact")
    assert all(nets["P1"][i][0][1] == 0 for i in range(4))
    assert nets["P1"][3][0] == (1, 0)
    assert all(nets["P3"][0][j][0] == 0 for j in range(4))


def test_bad_parameterization():
    with pytest.raises(CCProofError, match="unknown parameterization"):
        face_map([5, 4, 4, 4], np.zeros(1), np.zeros(1), "smooth")


@pytest.mark.parametrize("param", PARAMS)
@pytest.mark.parametrize("k", [3, 5, 20])
def test_relative_precision_near_the_corner(param, k):
    """G = w F + (1 - w) t near the corner, against 150-digit mpmath with the same F (F << t there for
    k >= 5, so 1 - w must be computed without cancellation)."""
    import mpmath

    from ccproof.reparam.quadrant import default_alpha, inverse_characteristic_map_derivatives, vanishing_map

    rho = 2.0 ** -np.arange(4, 60, 3)
    s, t = 0.8 * rho, 0.6 * rho
    r = face_map([k, 4, 4, 4], s, t, param)
    if param == "vanishing":
        F = vanishing_map(s, t, default_alpha(k), 0)[0]
    else:
        F = inverse_characteristic_map_derivatives(k, s, t, 0)[0]
    with mpmath.workdps(150):  # 1 - w ~ 1e-51 at the smallest rho: no cancellation at 150 digits
        for i in range(s.size):
            S, Tt = mpmath.mpf(s[i]), mpmath.mpf(t[i])

            def b(x):
                z = 6 * abs(x)
                return 1 - z**3 / 6 if z <= 1 else None

            if param == "vanishing":
                w = b(mpmath.sqrt(S * S + Tt * Tt))
            else:
                w = b(S) * b(Tt)
            want = [w * mpmath.mpf(F[i, 0]) + (1 - w) * S, w * mpmath.mpf(F[i, 1]) + (1 - w) * Tt]
            got = [r["u"][i], r["v"][i]]
            for g, x in zip(got, want):
                assert abs(mpmath.mpf(g) - x) <= 4e-16 * abs(x), (i, g, x)
