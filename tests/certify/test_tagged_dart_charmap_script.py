"""scripts/tagged_dart_charmap.py: the dart's characteristic map in closed form, analytic in (s, h, sigma),
against the verifier's exact per-K vectors and nets (an independent route: exact characteristic polynomial,
bordered solves, the verifier's own net construction), and its regions' proofs and controls."""

import importlib.util
from pathlib import Path
from types import SimpleNamespace

import pytest
from flint import acb, arb, ctx, fmpq

from ccproof.certify.verify.maps import regularity_form
from ccproof.certify.verify.tagged import labels
from ccproof.certify.verify.tagged_map import PIECES, quadrant_nets
from ccproof.certify.verify.tagged_modes import even_vector, mode_spectrum, mode_vector

SCRIPTS = Path(__file__).resolve().parents[2] / "scripts"



def _c(z):
    """The coefficients of h^0, h^1, h^2 of a dart_zeros.QS as p + q sqrt 5 + i (r + u sqrt 5) (theta = sqrt 5 + i:
    theta^2 = 4 + 2 i sqrt 5, theta^3 = 2 sqrt 5 + 14 i), read independently of the verifier."""
    out = []
    for e in z.coeffs():
        c = [e[k] for k in range(4)]
        out.append(SimpleNamespace(p=c[0] + 4 * c[2], q=c[1] + 2 * c[3], r=c[1] + 14 * c[3], u=2 * c[2]))
    return out

def _load():
    spec = importlib.util.spec_from_file_location("tagged_dart_charmap", SCRIPTS / "tagged_dart_charmap.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


@pytest.mark.parametrize("k", [12, 40])
def test_closed_forms_are_the_verifiers_eigenvectors_and_nets(k):
    # x against mode_vector, y against even_vector (bordered solve on S_E, lam2 from the exact polynomial),
    # nets of a bulk quadrant and of the layer quadrants 0..2 against quadrant_nets (ghost rows, sharp rules)
    mod = _load()
    with ctx.workprec(128):
        errs = mod.exact_check(k)
    assert max(errs) < 1e-30, errs


@pytest.mark.slow
@pytest.mark.parametrize("k", [101, 150])
def test_closed_forms_at_large_k(k):
    mod = _load()
    with ctx.workprec(128):
        errs = mod.exact_check(k)
    assert max(errs) < 1e-30, errs


def test_a_perturbed_family_member_is_not_an_eigenvector_and_folds():
    # the family at sigma = 5 is no eigenvector (its y breaks S y = lam y at the sharp ray's neighbours), and its
    # det J_Phi changes sign in the bulk; the member sigma(K) is the eigenvector and stays positive there
    mod = _load()
    with ctx.workprec(128):
        assert all(v < 0 for v in mod.corner_dets(arb(5), 1000, fmpq(1, 20)))
        assert all(v > 0 for v in mod.corner_dets(arb(5), 1000, fmpq(1, 10)))
        s1000 = mod._limit_script().sigma_of(arb(fmpq(1, 1000)))
        assert all(v > 0 for v in mod.corner_dets(s1000, 1000, fmpq(1, 20)))
        # the residual of S y = lam y on the sector matrix, read from the verifier's rows, with the member sigma = 5
        k = 40
        from ccproof.certify.verify.tagged import sector_rows
        for sig, small in ((mod._limit_script().sigma_of(arb(fmpq(1, k))), True), (arb(5), False)):
            fam = mod.Family(acb(arb(fmpq(1, k))), sig)
            pts, rows = labels("dart", k), sector_rows("dart", k)
            y = [mod.family_values(fam, 0)[2]]
            for p in pts[1:]:
                y.append(mod.family_values(fam, fmpq(p[1], k))[1](0, p[2:]))
            lam = acb(fam.lam2).real
            res = max(float(abs(sum((w * y[j] for j, w in row.items()), arb(0)) - lam * y[i]).upper())
                      for i, row in enumerate(rows))
            assert (res < 1e-30) == small, res


def _verifier_kdet(k, q):
    """K det J_Phi's Bernstein coefficients per piece from the verifier's vectors and nets (x = 1 at ray K/4's
    (1,0) times its closed-form value there, y likewise at ray K/2: the script's normalization)."""
    mod = _load()
    pts = labels("dart", k)
    ev = mode_spectrum("dart", k)
    lam2 = max((z.real for z, r, src, _ in ev if src == "E" and r != 1 and z.imag.contains(0)), key=lambda r: r.mid())
    lam1 = max((z[0].real for z in ev if z[3] == 1), key=lambda r: r.mid())
    py, px = pts.index(("r", k // 2, 1, 0)), pts.index(("r", k // 4, 1, 0))
    fam = mod.Family(acb(arb(fmpq(1, k))), mod._limit_script().sigma_of(arb(fmpq(1, k))))
    vals = mod.family_values
    sx, sy = vals(fam, fmpq(k // 4, k))[0](0, (1, 0)), vals(fam, fmpq(k // 2, k))[1](0, (1, 0))
    f = mode_vector("dart", k, 1, lam1)
    x = [arb(0)] + [(z / f[px]).real * sx for z in f[1:]]
    y = [v * sy for v in even_vector(k, lam2, py)]
    nets = quadrant_nets("dart", k, x, y, q, 128)
    return {p: [c * k for c in regularity_form(nets, p, 128).coeffs] for p in PIECES}


@pytest.mark.slow
def test_taylor_models_enclose_the_verifiers_det_and_prove_each_region():
    mod = _load()
    k, q = 101, 30
    with ctx.workprec(128):
        sig = mod._limit_script().sigma_of(arb(fmpq(1, k)))
        ref = _verifier_kdet(k, q)
        r, n = mod.R_CAUCHY, 12
        T = mod.taylor_dets(sig, n)
        M = mod.disc_bounds(mod._ball(mod.SIGMA_LO, mod.SIGMA_HI), r, grid=12)
        # the Taylor model's enclosure of each coefficient, at the point (s, h) = (q/K, 1/K), contains the
        # verifier's value: evaluate the model piece by piece
        s, h = fmpq(q, k), fmpq(1, k)
        E, F = acb(0, 2 * arb.pi() * s).exp(), acb(0, sig * (2 * s - 1)).exp()
        a, b = {"X+": E, "X-": 1 / E}, {"Y0": acb(1), "Y+": F, "Y-": 1 / F}
        tail = arb(h) ** n / (arb(r) ** (n + 1) * (1 - arb(h) / r))
        for p in PIECES:
            for c, want in enumerate(ref[p]):
                got = acb(0)
                for i in mod.XB:
                    for j in mod.YB:
                        rad = (M[(i, j, p)] * tail).upper()
                        acc = sum((T[(i, j, p)][m][c] * arb(h) ** (m - 1) for m in range(1, n + 1)), acb(0))
                        got += a[i] * b[j] * (acc + acb(arb(0, rad), arb(0, rad)))
                assert got.real.overlaps(want), (p, c, got.real, want)
                assert got.real.rad() < 5e-3  # the enclosure is informative: the Cauchy tail (about 1.6e-3) dominates
        # and one box of each region proves positivity, with the sigma-box of K = 101
        sb = mod._ball(mod.SIGMA_LO, mod.SIGMA_LO + (mod.SIGMA_HI - mod.SIGMA_LO) / 10)
        Tb = mod.taylor_dets(sb, n)
        assert mod.kdet_box(Tb, M, fmpq(1, 4), fmpq(1, 4) + fmpq(1, 100), 0, h, sb, r, n)[0] > 0
        Eb = mod.middle_coeffs(Tb, sb)
        assert mod.middle_box(Tb, Eb, M, 0, fmpq(1, 200), 0, fmpq(1, 12), sb, r, n)[0] > 0
        # the smooth valence's map with the dart's orientation: certainly negative on the same bulk box
        Ts = mod.taylor_dets(arb.pi(), n, smooth=True)
        Ms = mod.disc_bounds(arb.pi(), r, grid=12, smooth=True)
        assert mod.kdet_box(Ts, Ms, fmpq(1, 4), fmpq(1, 4) + fmpq(1, 100), 0, h, arb.pi(), r, n)[1] < 0


@pytest.mark.slow
def test_layer_quadrant_zero_against_the_verifier():
    mod = _load()
    k = 101
    with ctx.workprec(128):
        ref = _verifier_kdet(k, 0)
        sig = mod._limit_script().sigma_of(arb(fmpq(1, k)))
        n, r = 14, mod.R_CAUCHY
        T = mod.layer_taylor(0, sig, n)
        M = mod.layer_disc(0, mod._ball(mod.SIGMA_LO, mod.SIGMA_HI), r)
        h = fmpq(1, k)
        for p in PIECES:
            for m in range(3):  # the coefficients that are 0 exactly (the first-order nets are proportional)
                assert all(abs(z) < 1e-25 for z in T[p][m])
        tail = arb(h) ** (n - 2) / (arb(r) ** (n + 1) * (1 - arb(h) / r))
        for p in PIECES:
            for c, want in enumerate(ref[p]):
                got = sum((T[p][m][c] * arb(h) ** (m - 3) for m in range(3, n + 1)), arb(0))
                got += arb(0, (M[p] * tail).upper())
                assert got.overlaps(want * k * k), (p, c, got, want * k * k)
        lo, hi = mod.layer_box(T, M, h, h, r, n)
        assert lo > 0


@pytest.mark.slow
def test_transversality_models_enclose_the_verifiers_forms():
    # a1 X Y' - a2 Y X' along the four outer curves: the bulk model at (q/K, 1/K) and the layer model of
    # quadrant 0 against the verifier's transversal_form on its own nets (K = 101), then one box of each
    from ccproof.certify.verify.tagged_map import transversal_form
    mod = _load()
    k = 101
    with ctx.workprec(128):
        sig = mod._limit_script().sigma_of(arb(fmpq(1, k)))
        fam = mod.Family(acb(arb(fmpq(1, k))), sig)
        a1, a2 = -acb(fam.lam1).real.log(), -acb(fam.lam2).real.log()
        pts = labels("dart", k)
        ev = mode_spectrum("dart", k)
        lam2 = max((z.real for z, r, src, _ in ev if src == "E" and r != 1 and z.imag.contains(0)),
                   key=lambda r: r.mid())
        lam1 = max((z[0].real for z in ev if z[3] == 1), key=lambda r: r.mid())
        py, px = pts.index(("r", k // 2, 1, 0)), pts.index(("r", k // 4, 1, 0))
        vals = mod.family_values
        sx, sy = vals(fam, fmpq(k // 4, k))[0](0, (1, 0)), vals(fam, fmpq(k // 2, k))[1](0, (1, 0))
        f = mode_vector("dart", k, 1, lam1)
        x = [arb(0)] + [(z / f[px]).real * sx for z in f[1:]]
        y = [v * sy for v in even_vector(k, lam2, py)]
        r, n = mod.R_CAUCHY, 12
        T = mod.taylor_trans(sig, n)
        M = mod.disc_trans(mod._ball(mod.SIGMA_LO, mod.SIGMA_HI), r)
        h = fmpq(1, k)
        for q in (30, 50):
            nets = quadrant_nets("dart", k, x, y, q, 128)
            want = min(min(c.lower() for c in transversal_form(nets, cv, a1, a2, 128).coeffs) for cv in mod.STAR_CURVES)
            lo, hi = mod.kdet_box(T, M, fmpq(q, k), fmpq(q, k), h, h, sig, r, n)
            assert lo <= want * k <= hi and lo > 0, (q, lo, want * k, hi)
        TL = mod.layer_trans_taylor(0, sig, 14)
        ML = mod.layer_trans_disc(0, mod._ball(mod.SIGMA_LO, mod.SIGMA_HI), r)
        assert all(abs(z) < 1e-25 for c in TL for m in range(3) for z in TL[c][m])
        nets = quadrant_nets("dart", k, x, y, 0, 128)
        want = min(min(c.lower() for c in transversal_form(nets, cv, a1, a2, 128).coeffs) for cv in mod.STAR_CURVES)
        lo, hi = mod.layer_box(TL, ML, h, h, r, 14)
        assert lo <= want * k ** 3 <= hi and lo > 0, (lo, want * k ** 3, hi)


@pytest.mark.slow
def test_winding_signs_and_their_controls():
    # the sign conditions of W hold for every K >= 101; the exact zeros are tiny at a point sigma; and Y
    # really changes sign between s_a and s_b (the zero that W counts), checked on the verifier's own y at K = 101
    mod = _load()
    k = 101
    with ctx.workprec(128):
        res, zeros = mod.winding(k, fmpq(1, 20), 3, sig_boxes=2)
        assert all(c > 0 and not f for c, f in res.values()), res
        sig = mod._limit_script().sigma_of(arb(fmpq(1, k)))
        T, _ = mod.layer_coord(0, sig, 14, mod.R_CAUCHY, grid=0)
        assert all(abs(T[c][0][p]) < 1e-25 for c in mod.STAR_CURVES for p in range(4))
        assert abs(T["P1s1"][1][0]) < 1e-25  # ray 0's end point: y = O(h^2)
        TY = mod.coord_taylor(sig, 12, "y")
        assert mod.ymid_zero(TY, sig) < 1e-25
        y = even_vector(k, max((z.real for z, r, src, _ in mode_spectrum("dart", k)
                                if src == "E" and r != 1 and z.imag.contains(0)), key=lambda r: r.mid()),
                        labels("dart", k).index(("r", k // 2, 1, 0)))
        pts = labels("dart", k)
        assert y[pts.index(("r", 25, 1, 0))] < 0 < y[pts.index(("r", 35, 1, 0))]
        assert y[pts.index(("r", 0, 1, 0))] < 0


@pytest.mark.slow
def test_the_reflection_keeps_det_j_so_half_the_quadrants_suffice():
    # the scripts prove quadrants q <= (K-1)/2 only; quadrant K-1-q is the mirror image (x odd, y even, the
    # pieces P1 <-> P3 with (u, v) swapped), so its det J_Phi coefficients are the same multiset: the verifier's
    # own nets at K = 101 (odd) and 40 (even)
    for k, qs in ((101, (0, 1, 7, 30, 50)), (40, (0, 3, 19))):
        with ctx.workprec(128):
            for q in qs:
                a, b = _verifier_kdet(k, q), _verifier_kdet(k, k - 1 - q)
                va = sorted(float(c.mid()) for p in PIECES for c in a[p])
                vb = sorted(float(c.mid()) for p in PIECES for c in b[p])
                assert max(abs(x - y) for x, y in zip(va, vb)) < 1e-20 * k ** 3, (k, q)
                assert min(va) > 0


def test_the_dropped_coefficients_vanish_at_a_point_sigma():
    # the script drops D_ij's h^0 coefficient (bulk), T_ij's h^0, and the middle's s^0, s^1, s^0 h
    # coefficients as 0 exactly; at a point sigma their enclosures must be tiny, while the first kept ones are not
    mod = _load()
    with ctx.workprec(128):
        sig = mod._limit_script().sigma_of(arb(fmpq(1, 500)))
        T = mod.taylor_dets(sig, 6)
        assert all(abs(z) < 1e-25 for v in T.values() for z in v[0])
        E = mod.middle_coeffs(T, sig, L=4)
        for key in ((1, 0), (1, 1), (2, 0)):
            assert all(abs(z) < 1e-25 for p in PIECES for z in E[key + (p,)])
        assert min(max(abs(z.real) for z in E[(1, 2, p)]) for p in PIECES) > 1  # K^3 det J/q^2 -> about 6..7
        Tt = mod.taylor_trans(sig, 6)
        assert all(abs(z) < 1e-25 for v in Tt.values() for z in v[0])
        assert any(abs(z) > 0.1 for v in Tt.values() for z in v[1])


def test_series_are_not_truncated_silently():
    # python-flint cuts every series to ctx.cap terms whatever its length: with the series variable of order 12
    # (ctx.cap raised inside, restored after) its order-12 coefficients must be there (the x-mode's v^(1,1) has a
    # nonzero h^11 term), and past ctx.cap = 10 they are not
    mod = _load()
    with ctx.workprec(128):
        old = ctx.cap
        try:
            ctx.cap = 10
            with mod.series_variable(12) as h:
                fam = mod.Family(h, arb("4.49"))
                c = mod.series_coeffs(fam.vx[2], 13)
            assert ctx.cap == 10
            cut = mod.series_coeffs(mod.Family(h, arb("4.49")).vx[2], 13)  # the same h under ctx.cap = 10
            assert abs(cut[11]) == 0 and abs(cut[12]) == 0
            assert ctx.cap == 10
            assert abs(c[11]) > 1e-6 and abs(c[12]) > 1e-6
        finally:
            ctx.cap = old


def test_the_exact_facts_behind_the_dropped_coefficients():
    # rho in Q(sqrt 5) (exact Gauss-Jordan) is the script's v^ at h = 0 for both modes (acb bordered solve)
    mod = _load()
    with ctx.workprec(128):
        rho = mod.exact_zeros()
        fam = mod.Family(acb(0), arb("4.49"))
        for z, vx, vy in zip(rho, fam.vx, fam.vy):
            e = _c(z)[0]  # p + q sqrt 5 + i (r + u sqrt 5), constant in h
            assert e.r == 0 and e.u == 0 and all(x.p == x.q == x.r == x.u == 0 for x in _c(z)[1:])
            want = arb(e.p) + arb(e.q) * arb(5).sqrt()
            assert abs(acb(vx) - want) < 1e-30 and abs(acb(vy) - want) < 1e-30
        assert (_c(rho[2])[0].p, _c(rho[2])[0].q) == (-1, 1)  # rho(1,1) = sqrt 5 - 1


def _load_zeros():
    spec = importlib.util.spec_from_file_location("tagged_dart_zeros", SCRIPTS / "tagged_dart_zeros.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def _qf(z):
    r5 = arb(5).sqrt()
    return acb(arb(z.p) + arb(z.q) * r5, arb(z.r) + arb(z.u) * r5)


def test_the_exact_series_are_the_acb_familys():
    # the exact Series (Q(sqrt 5, i), a = 1, b = 1, c = t = 1) against the script's acb_series Family at sigma = 1/2
    # (so b = 2 sigma = 1): y's h^m coefficients equal, x's scaled by (2 pi)^m (x is a function of a h),
    # alpha by cos(1/2) (alpha is c times a function of b h); an independent route: flint's acb_series solve
    zmod, mod = _load_zeros(), _load()
    ex = zmod.ExactFamily(mod, 1, 1, 1, 1)
    with ctx.workprec(128), mod.series_variable(2) as h:
        fam = mod.Family(h, arb(fmpq(1, 2)))
        tp = 2 * arb.pi()
        for k in range(6):
            cy, cx = mod.series_coeffs(fam.vy[k], 3), mod.series_coeffs(fam.vx[k], 3)
            for m in range(3):
                assert abs(cy[m] - _qf(_c(ex.vy[k])[m])) < 1e-30
                assert abs(cx[m] - tp ** m * _qf(_c(ex.vx[k])[m])) < 1e-30
        ca = mod.series_coeffs(fam.alpha, 3)
        for m in range(3):
            assert abs(ca[m] - arb(fmpq(1, 2)).cos() * _qf(_c(ex.alpha)[m])) < 1e-30
        assert abs(mod.series_coeffs(fam.lam2, 3)[2] - _qf(_c(ex.lam2)[2])) < 1e-30
        assert abs(_qf(_c(ex.lam2)[2])) > 0.01  # lam's h^2 term is there


def test_the_dropped_coefficients_are_exactly_zero_at_one_grid_point():
    zmod, mod = _load_zeros(), _load()
    res = zmod.check_point(mod, 1, 2, 1, 2)
    assert len(res) == 8 and all(n > 0 and bad == 0 for n, bad in res.values()), res


def test_the_exact_zero_check_refuses_a_perturbed_rule_or_family():
    # perturb the ring rule (a weight moved between mirror-image positions, row sums kept) or flip alpha:
    # the dropped coefficients are then not 0, and the exact check must say so
    zmod, mod = _load_zeros(), _load()
    from ccproof.certify.verify.tagged_modes import ring_stencil

    def moved(row, src, dst):
        e = fmpq(1, 64)
        st = [dict(r) for r in ring_stencil()]
        st[row][src] -= e
        st[row][dst] = st[row].get(dst, fmpq(0)) + e
        return st
    # B(1) no longer symmetric in (a, b) (the row of (2, 1) no longer the mirror of the row of (1, 2)): v^(0) is
    # no longer symmetric, X- no longer a multiple of X+ at h = 0, D_ij(0) != 0
    res = zmod.check_point(mod, 1, 2, 1, 2, stencil=moved(3, (0, (2, 1)), (0, (2, 0))))
    assert res["bulk det: D_ij h^0"][1] > 0 and res["bulk T: T_ij h^0"][1] > 0, res
    # the row of (2, 2) weighs (1, 2) and (2, 1) unequally: v^(0) stays symmetric ((2, 2) enters no other row), but
    # the reflection identity B(1/w) R_w = R_w B(w) breaks, and with it the h-orders (layer, middle)
    res = zmod.check_point(mod, 1, 2, 1, 2, stencil=moved(5, (0, (1, 2)), (0, (2, 1))))
    assert res["bulk det: D_ij h^0"][1] == 0
    assert res["layer det: h^0, h^1, h^2"][1] > 0 and res["middle det: e_10, e_11, e_20"][1] > 0, res
    # alpha -> -alpha: y's mode-0 part no longer cancels at h = 0
    res = zmod.check_point(mod, 1, 2, 1, 2, flip_alpha=True)
    assert res["layer det: h^0, h^1, h^2"][1] > 0 and res["W middle: Y(s = h = 0)"][1] > 0, res


@pytest.mark.slow
def test_every_dropped_coefficient_is_exactly_zero_on_the_whole_grid():
    zmod, mod = _load_zeros(), _load()
    res = zmod.check_all(mod)
    assert len(res) == 8 and all(n > 0 and bad == 0 for n, bad in res.values()), res


def test_the_exact_nets_are_the_acb_familys_nets():
    # the exact basis nets (bulk) and layer nets against the script's own (acb_series, sigma = 1/2, b = 1): x's
    # h^m coefficient scales by (2 pi)^m; Y0 and the layer's y are linear in (cos sigma, sin sigma),
    # y = cos y(1, 0) + sin y(0, 1); the bulk's Y+, Y- do not depend on them
    zmod, mod = _load_zeros(), _load()
    exs = [zmod.ExactFamily(mod, 1, 1, c, t) for c, t in ((1, 0), (0, 1))]

    def exact_y(zs, m):  # zs: the two exact Series (c, t) = (1, 0), (0, 1)
        return co * _qf(_c(zs[0])[m]) + si * _qf(_c(zs[1])[m])
    with ctx.workprec(128), mod.series_variable(2) as h:
        half = arb(fmpq(1, 2))
        co, si, tp = half.cos(), half.sin(), 2 * arb.pi()
        fam = mod.Family(h, half)
        mine = mod.basis_nets(fam)
        ex = [{n: mod.piece_nets(f, c, lam, e.zero) for n, (f, c, lam) in e.parts().items()} for e in exs]
        worst = 0.0
        for name in mine:
            for p in mod.PIECES:
                for i in range(4):
                    for j in range(4):
                        got = mod.series_coeffs(mine[name][p][i][j], 3)
                        for m in range(3):
                            if name.startswith("X"):
                                want = tp ** m * _qf(_c(ex[0][name][p][i][j])[m])
                            elif name != "Y0":
                                want = _qf(_c(ex[0][name][p][i][j])[m])
                            else:
                                want = exact_y([ex[0][name][p][i][j], ex[1][name][p][i][j]], m)
                            worst = max(worst, float(abs(got[m] - want).upper()))
        for q in range(3):
            ln = mod.layer_nets(fam, q)
            el = []
            for e in exs:
                x, y = e.layer_level0()
                el.append(mod.piece_nets(y, e.yc, e.lam2, e.zero, q))
                x0 = mod.piece_nets(x, e.zero, e.lam1, e.zero, q)
            for p in mod.PIECES:
                for i in range(4):
                    for j in range(4):
                        gx, gy = mod.series_coeffs(ln[p][0][i][j], 3), mod.series_coeffs(ln[p][1][i][j], 3)
                        for m in range(3):
                            worst = max(worst, float(abs(gx[m] - tp ** m * _qf(_c(x0[p][i][j])[m])).upper()),
                                        float(abs(gy[m] - exact_y([el[0][p][i][j], el[1][p][i][j]], m)).upper()))
        assert worst < 1e-30, worst
