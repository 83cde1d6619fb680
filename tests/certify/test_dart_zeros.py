"""verify.dart_zeros: every dropped Taylor coefficient of the dart family is exactly 0 on the grid of the degree
argument; perturbing the rule or the family makes the check FAIL naming the row; the exact series and nets
agree with dart_family's acb_series family (independent arithmetic: arb balls, flint's series)."""

from types import SimpleNamespace

import pytest
from flint import acb, arb, ctx, fmpq

from ccproof.certify.verify import dart_family as df
from ccproof.certify.verify.dart_zeros import (
    GRID,
    ONE,
    QS,
    ROWS,
    ExactFamily,
    H,
    I,
    check_zeros,
    count_zeros,
)
from ccproof.certify.verify.errors import CertificateError
from ccproof.certify.verify.tagged_modes import ring_stencil


def _c(z):
    """The coefficients of h^0, h^1, h^2 of a dart_zeros.QS as p + q sqrt 5 + i (r + u sqrt 5) (theta = sqrt 5 + i:
    theta^2 = 4 + 2 i sqrt 5, theta^3 = 2 sqrt 5 + 14 i), read independently of the verifier."""
    out = []
    for e in z.coeffs():
        c = [e[k] for k in range(4)]
        out.append(SimpleNamespace(p=c[0] + 4 * c[2], q=c[1] + 2 * c[3], r=c[1] + 14 * c[3], u=2 * c[2]))
    return out

def _moved(row, src, dst):
    e = fmpq(1, 64)
    st = [dict(r) for r in ring_stencil()]
    st[row][src] -= e
    st[row][dst] = st[row].get(dst, fmpq(0)) + e
    return st


def test_every_dropped_coefficient_is_exactly_zero():
    line = check_zeros()
    for row, n in zip(ROWS, (23328, 11664, 10368, 5184, 576, 34992, 15552, 1764)):
        assert f"{row} {n}" in line
    assert "103428 in all" in line and len(GRID) == 36


def test_the_ring_reads_its_coefficients_back():
    # 1/(1 + h) = 1 - h + h^2 and e^(i h) e^(-i h) = 1, read back coefficient by coefficient in (1, sqrt 5, i, i sqrt 5)
    inv = ONE / (ONE + H)
    assert [(z.p, z.q, z.r, z.u) for z in _c(inv)] == [(1, 0, 0, 0), (-1, 0, 0, 0), (1, 0, 0, 0)]
    z = QS(3) + I * H * fmpq(1, 2) + (I * 2 + 5) * H * H
    assert [(c.p, c.r) for c in _c(z)] == [(3, 0), (0, fmpq(1, 2)), (5, 2)]
    assert z.vanishes(0) and not z.vanishes(1) and (z - 3).vanishes(1) and not (z - 3).vanishes(2)
    with pytest.raises(ZeroDivisionError):
        ONE / H  # h is no unit


@pytest.mark.parametrize("perturbation, row, still_zero, bad", [
    # the row of (2, 1) no longer the mirror of the row of (1, 2): v^(0) asymmetric, D_ij(0), T_ij(0) != 0
    (dict(stencil=_moved(3, (0, (2, 1)), (0, (2, 0)))), "bulk det: D_ij h^0", (),
     (432, 324, 192, 144, 16, 972, 432, 49)),
    # the row of (2, 2) weighs (1, 2) and (2, 1) unequally: v^(0) still symmetric, the reflection identity fails,
    # so the h-orders of the middle and the layer break but the bulk's h^0 does not
    (dict(stencil=_moved(5, (0, (1, 2)), (0, (2, 1)))), "middle det: e_10, e_11, e_20",
     ("bulk det: D_ij h^0", "bulk T: T_ij h^0", "W middle: Y(s = h = 0)"), (0, 184, 0, 78, 0, 288, 118, 0)),
    # alpha -> -alpha: y's mode-0 part no longer cancels at h = 0
    (dict(flip_alpha=True), "middle det: e_10, e_11, e_20", ("bulk det: D_ij h^0",), (0, 108, 0, 48, 16, 324, 144, 48)),
])
def test_a_perturbed_rule_or_family_fails_naming_the_row(perturbation, row, still_zero, bad):
    with pytest.raises(CertificateError, match="dropped coefficient not 0: row '" + row.replace("^", r"\^")):
        check_zeros(**{"_" + k: v for k, v in perturbation.items()})
    res = count_zeros(points=[(1, 2, 1, 2)], **perturbation)
    # the non-zero counts per row are those of the former script (truncated series over Q(sqrt 5, i) as
    # fmpq quadruples, no shared parts: an independent implementation) at the same point
    assert tuple(res[r][1] for r in ROWS) == bad
    assert res[row][1] > 0
    assert all(res[r][1] == 0 for r in still_zero), res
    if "flip_alpha" in perturbation:
        assert res["layer det: h^0, h^1, h^2"][1] > 0 and res["W middle: Y(s = h = 0)"][1] > 0
        assert res["W layer: Y h^0 (h^1 at ray 0's end)"][1] > 0
    else:
        assert res["layer det: h^0, h^1, h^2"][1] > 0 and res["layer T: h^0, h^1, h^2"][1] > 0


def _acb(z):
    r5 = arb(5).sqrt()
    return acb(arb(z.p) + arb(z.q) * r5, arb(z.r) + arb(z.u) * r5)


def test_the_exact_series_and_nets_are_the_acb_familys():
    # grid point a = 1, b = 1 against Family at sigma = 1/2 (b = 2 sigma = 1), a = 2 pi: x's h^m coefficient scales
    # by (2 pi)^m; Y0 and the layer's y are linear in (cos sigma, sin sigma), so y = cos y(1, 0) + sin y(0, 1)
    exs = [ExactFamily(1, 1, c, t) for c, t in ((1, 0), (0, 1))]
    with ctx.workprec(128), df.series_variable(2) as h:
        half = arb(fmpq(1, 2))
        co, si, tp = half.cos(), half.sin(), 2 * arb.pi()
        fam = df.Family(h, half)
        worst = 0.0

        def cmp(got, zs, scale_x):
            nonlocal worst
            g = df.series_coeffs(got, 3)
            for m in range(3):
                want = (tp ** m * _acb(_c(zs[0])[m]) if scale_x
                        else co * _acb(_c(zs[0])[m]) + si * _acb(_c(zs[1])[m]) if len(zs) == 2 else _acb(_c(zs[0])[m]))
                worst = max(worst, float(abs(g[m] - want).upper()))
        for k in range(6):
            cmp(fam.vx[k], [exs[0].vx[k]], True)
            cmp(fam.vy[k], [exs[0].vy[k]], False)
            cmp(fam.U[k], [exs[0].U[k]], False)
        cmp(fam.alpha, [exs[0].alpha, exs[1].alpha], False)
        cmp(fam.lam1, [exs[0].lam1], True)
        cmp(fam.lam2, [exs[0].lam2], False)
        mine = df.basis_nets(fam)
        ex = [{n: df.piece_nets(*p, e.zero) for n, p in e.parts().items()} for e in exs]
        for name in mine:
            for p in df.PIECES:
                for i in range(4):
                    for j in range(4):
                        zs = [ex[0][name][p][i][j]] + ([ex[1][name][p][i][j]] if name == "Y0" else [])
                        cmp(mine[name][p][i][j], zs, name.startswith("X"))
        for q in range(3):
            ln = df.layer_nets(fam, q)
            ey = [e.layer_nets(q, 1) for e in exs]
            ex0 = exs[0].layer_nets(q, 0)
            for p in df.PIECES:
                for i in range(4):
                    for j in range(4):
                        cmp(ln[p][0][i][j], [ex0[p][i][j]], True)
                        cmp(ln[p][1][i][j], [ey[0][p][i][j], ey[1][p][i][j]], False)
        assert worst < 1e-30, worst
        assert abs(_acb(_c(exs[0].lam2)[2])) > 0.01 and abs(_acb(_c(exs[0].vx[3])[1])) > 0.01  # the h-terms are there
