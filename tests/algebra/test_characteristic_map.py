"""Properties of the characteristic map nets, checked in arb (R2-R4)."""

import pytest
from flint import arb, ctx, fmpq

from ccproof.algebra.characteristic_map import symbolic_two_ring_eigenvector
from ccproof.algebra.specialize import (
    characteristic_map_patches,
    subdominant_eigenvalue,
)
from ccproof.algebra.subdivision import CENTER, ring_subdivision_matrix, two_ring_vertices
from ccproof.errors import ValenceError

from ._bruteforce import cc_step, level1_value, ring_mesh

PREC = 200
TINY = arb(2) ** -150
KS = [3, 4, 5, 6, 7, 8, 13, 14, 29, 40, 50]


def same(a, b):
    d = a - b
    return d.contains(0) and d.rad() < TINY


def same_pt(p, q):
    return same(p[0], q[0]) and same(p[1], q[1])


def split_left(curve):
    """de Casteljau: control points of the first half of a cubic Bezier curve."""
    b = [list(p) for p in curve]
    half = arb(fmpq(1, 2))
    out = [b[0]]
    pts = b
    for _ in range(3):
        pts = [[(p[i] + q[i]) * half for i in range(2)] for p, q in zip(pts, pts[1:])]
        out.append(pts[0])
    return [tuple(p) for p in out]


def split_right(curve):
    return list(reversed(split_left(list(reversed(curve)))))


def frame_to_plane(p, k):
    """Normalized-frame coordinates (x, y) w.r.t. e0 = (1,0), e1 = (cos, sin) -> plane."""
    c = arb(fmpq(2, k)).cos_pi()
    s = arb(fmpq(2, k)).sin_pi()
    return (p[0] + p[1] * c, p[1] * s)


def rot(p, j, k):
    c = arb(fmpq(2 * j, k)).cos_pi()
    s = arb(fmpq(2 * j, k)).sin_pi()
    return (c * p[0] - s * p[1], s * p[0] + c * p[1])


def eigenvector_on_ring(k):
    from ccproof.algebra.specialize import specialize

    sym = symbolic_two_ring_eigenvector()
    vals = {}
    for (a, b), (x, y) in sym.items():
        p = frame_to_plane((specialize(x.integer_form(), k, "arb", PREC),
                            specialize(y.integer_form(), k, "arb", PREC)), k)
        for j in range(k):
            vals[(j, a, b)] = rot(p, j, k)
    vals[CENTER] = (arb(0), arb(0))
    return vals


@pytest.mark.parametrize("k", KS)
def test_two_ring_vector_is_subdominant_eigenvector(k):
    with ctx.workprec(PREC):
        vals = eigenvector_on_ring(k)
        lam = subdominant_eigenvalue(k, "arb", PREC)
        verts = two_ring_vertices(k)
        S = ring_subdivision_matrix(k)
        for i, v in enumerate(verts):
            acc = [arb(0), arb(0)]
            for jj, w in enumerate(S[i]):
                if w:
                    wa = arb(fmpq(w.numerator, w.denominator))
                    acc = [acc[t] + wa * vals[verts[jj]][t] for t in range(2)]
            assert same_pt(acc, (lam * vals[v][0], lam * vals[v][1])), (k, v)


@pytest.mark.parametrize("k", [3, 5, 8])
def test_nets_are_level1_vertices_of_bruteforce_step(k):
    """Every B-spline control point of P1, P2, P3 equals the level-1 vertex a naive CC step
    produces from the eigenvector (mapped to the plane)."""
    with ctx.workprec(PREC):
        vals = eigenvector_on_ring(k)
        faces, vid = ring_mesh(k, 2)

        class V(tuple):
            def __add__(self, o):
                return V((self[0] + o[0], self[1] + o[1]))

            def __mul__(self, f):
                f = arb(fmpq(f.numerator, f.denominator)) if not isinstance(f, int) else arb(f)
                return V((self[0] * f, self[1] * f))

        values = {("c" if v == CENTER else v): V(p) for v, p in vals.items()}
        step = cc_step(faces, values, V((arb(0), arb(0))))
        nets = characteristic_map_patches(k, "bspline", "arb", PREC)
        offsets = {"P1": (0, -1), "P2": (0, 0), "P3": (-1, 0)}
        # scale: the nets are normalized so that Phi(1,0) = (1,0); undo with the ratio at one point
        ref = frame_to_plane(nets["P2"][1][0], k)
        raw = level1_value(faces, vid, step, 0, 1, 0)
        scale = ref[0] / raw[0]
        for name, (oa, ob) in offsets.items():
            for i in range(4):
                for j in range(4):
                    A, B = oa + i, ob + j
                    # bring (A, B) into a sector where A >= 1, B >= 0 (test-local rule)
                    sec, AA, BB = 0, A, B
                    if AA == 0 and BB == 0:
                        want = (arb(0), arb(0))
                    else:
                        if AA <= 0 and BB >= 1:
                            sec, AA, BB = 1, BB, -AA
                        elif BB < 0:
                            sec, AA, BB = -1, -BB, AA
                        elif BB == 0 and AA < 0:
                            sec, AA, BB = 2, -AA, 0
                        w = level1_value(faces, vid, step, sec % k, AA, BB)
                        want = (w[0] * scale, w[1] * scale)
                    got = frame_to_plane(nets[name][i][j], k)
                    assert same_pt(got, want), (k, name, i, j)


@pytest.mark.parametrize("k", KS)
def test_normalization_symmetry_and_patch_continuity(k):
    with ctx.workprec(PREC):
        b = characteristic_map_patches(k, "bezier", "arb", PREC)
        P1, P2, P3 = b["P1"], b["P2"], b["P3"]
        # Phi(1, 0) = (1, 0): corner s=1, t=0 of P1
        assert same_pt(P1[3][0], (arb(1), arb(0)))
        # Phi(v, u) = swap Phi(u, v): P3(s, t) = swap P1(t, s)
        for i in range(4):
            for j in range(4):
                assert same_pt(P3[i][j], (P1[j][i][1], P1[j][i][0]))
                assert same_pt(P2[i][j], (P2[j][i][1], P2[j][i][0]))
        # the u-axis maps to the x-axis, monotonically: bottom row of P1 has y = 0, x increasing
        for i in range(4):
            assert same(P1[i][0][1], arb(0))
        assert all((P1[i + 1][0][0] - P1[i][0][0]) > 0 for i in range(3))
        # C0 and C1 between P1 and P2 along v = 1/2 (P1 top row t=1 vs P2 bottom row t=0)
        for i in range(4):
            assert same_pt(P1[i][3], P2[i][0])
            d1 = [P1[i][3][t] - P1[i][2][t] for t in range(2)]
            d2 = [P2[i][1][t] - P2[i][0][t] for t in range(2)]
            assert same_pt(d1, d2)


@pytest.mark.parametrize("k", KS)
def test_scaling_across_layer_boundary(k):
    """Phi(y/2) = lam Phi(y): the inner edge u = 1/2 of P1 is lam times the outer edges u = 1 of
    P1 (v in [0, 1/4]) and P2 (v in [1/4, 1/2]); same for the cross derivative with factor 2 lam."""
    with ctx.workprec(PREC):
        lam = subdominant_eigenvalue(k, "arb", PREC)
        b = characteristic_map_patches(k, "bezier", "arb", PREC)
        P1, P2 = b["P1"], b["P2"]
        inner = [P1[0][j] for j in range(4)]
        inner_d = [tuple(P1[1][j][t] - P1[0][j][t] for t in range(2)) for j in range(4)]
        for half, outer_patch in ((split_left, P1), (split_right, P2)):
            got = half(inner)
            got_d = half(inner_d)
            for j in range(4):
                want = (lam * outer_patch[3][j][0], lam * outer_patch[3][j][1])
                assert same_pt(got[j], want)
                # d/ds on the outer edge: 3 (b3 - b2); inner: 3 (b1 - b0) per unit s; u-scale 2
                wd = tuple(2 * lam * (outer_patch[3][j][t] - outer_patch[2][j][t]) for t in range(2))
                assert same_pt(got_d[j], wd)


def test_valence_four_is_identity_exactly():
    from sympy import Rational

    nets = characteristic_map_patches(4, "bezier", "exact")
    dom = {"P1": (Rational(1, 2), 0), "P2": (Rational(1, 2), Rational(1, 2)), "P3": (0, Rational(1, 2))}
    for name, (u0, v0) in dom.items():
        for i in range(4):
            for j in range(4):
                assert nets[name][i][j] == (u0 + Rational(i, 6), v0 + Rational(j, 6))
    assert subdominant_eigenvalue(4, "exact") == Rational(1, 2)


def test_interval_nets_contain_exact_nets_of_large_valences():
    wide = characteristic_map_patches(">=40", "bezier", "arb", 128)
    for k in (40, 41, 64, 1000):
        nets = characteristic_map_patches(k, "bezier", "arb", 128)
        for name in nets:
            for i in range(4):
                for j in range(4):
                    for t in range(2):
                        assert wide[name][i][j][t].contains(nets[name][i][j][t]), (k, name, i, j)


@pytest.mark.parametrize("bad", [2, 1.5, float("nan"), "abc", -1])
def test_bad_valence(bad):
    with pytest.raises(ValenceError):
        characteristic_map_patches(bad)
