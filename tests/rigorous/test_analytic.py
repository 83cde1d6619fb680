"""ccproof.rigorous.analytic: the disc bound and the Cauchy remainder against functions known in closed form.

f(h) = 1/(1 - h) has Taylor coefficients 1 (exact) and |f| <= 1/(1 - r) on the disc |h| <= r (the grid's boxes
that meet the disc reach at most sqrt 2 r from 0); its values at sample points are computed independently in fmpq.
"""

import pytest
from flint import acb, acb_mat, arb, ctx, fmpq

from ccproof.rigorous.analytic import AnalyticModel, ball, cauchy_factor, disc_bound, disc_boxes, hull

R = fmpq(1, 2)


def geometric(order, M):
    return AnalyticModel([acb_mat([[acb(1)], [acb(2)]]) for _ in range(order + 1)], [M, M], R)


def test_the_boxes_cover_the_disc_and_leave_out_the_far_corners():
    boxes = list(disc_boxes(R, 4))
    assert len(boxes) == 16  # at grid 4 every box meets the disc (the corner boxes at distance R/sqrt 2)
    for z in (acb(fmpq(1, 2), fmpq(0)), acb(fmpq(-1, 3), fmpq(-1, 3)), acb(fmpq(1, 7), fmpq(-2, 9))):
        assert any(b.real.contains(z.real) and b.imag.contains(z.imag) for b in boxes)
    assert not any(b.real.contains(fmpq(3, 4)) for b in boxes)
    # grid 12: a box is kept iff its point nearest 0 lies in the closed disc (checked here on a fine sample
    # of points of the disc: each lies in a kept box), and the 3 boxes at each corner are left out
    fine = list(disc_boxes(R, 12))
    assert len(fine) == 144 - 12
    for i in range(-12, 13):
        for j in range(-12, 13):
            z = acb(R * fmpq(i, 12), R * fmpq(j, 12))
            if fmpq(i * i + j * j, 144) <= 1:
                assert any(b.real.contains(z.real) and b.imag.contains(z.imag) for b in fine), (i, j)
    assert not any(b.real.contains(R * fmpq(23, 24)) and b.imag.contains(R * fmpq(23, 24)) for b in fine)


def test_the_disc_bound_holds_the_maximum_and_fails_where_the_function_has_a_pole():
    with ctx.workprec(128):
        M = disc_bound(lambda h: {"f": [1 / (1 - h)]}, fmpq(1, 4), 8)["f"]
        # the maximum of |1/(1 - h)| on the disc |h| <= 1/4 is at h = 1/4: 4/3
        assert M >= arb(4) / 3
        assert M < 2  # and the grid keeps it informative
        with pytest.raises(ZeroDivisionError):  # the pole h = 1 lies in [-1, 1]^2: no finite bound
            disc_bound(lambda h: {"f": [1 / (1 - h)]}, fmpq(1), 4)


@pytest.mark.parametrize("h", [fmpq(0), fmpq(1, 10), fmpq(1, 5), fmpq(9, 20)])
def test_the_model_encloses_the_function_and_needs_its_remainder(h):
    order = 4
    exact = 1 / (1 - h)  # fmpq
    with ctx.workprec(128):
        M = arb(1) / (1 - arb(2).sqrt() * arb(R))  # |1/(1 - h)| on [-1/2, 1/2]^2 (the corner at sqrt 2/2)
        V, rho = geometric(order, M).enclose(h, h)
        assert (V[0, 0].real + arb(0, rho[0].upper())).contains(exact)
        assert (V[1, 0].real + arb(0, rho[1].upper())).contains(2 * exact)
        if h > fmpq(1, 10):  # the truncation alone misses the value: the remainder is what makes it hold
            assert not V[0, 0].real.contains(exact)
        # dividing by h^low: (f(h) - 1)/h = 1/(1 - h) for the geometric series
        if h > 0:
            V1, rho1 = geometric(order, M).enclose(h, h, low=1)
            assert (V1[0, 0].real + arb(0, rho1[0].upper())).contains(exact)


def test_the_real_part_of_a_weighted_sum_holds_its_value():
    with ctx.workprec(128):
        M = arb(1) / (1 - arb(2).sqrt() * arb(R))
        model = AnalyticModel([acb_mat([[acb(1), acb(2)]]) for _ in range(7)], [M, 2 * M], R)  # columns f, 2 f
        w = [acb(0, 1), acb(fmpq(1, 3), fmpq(-1, 2))]  # Re(i f + (1/3 - i/2) 2 f) = (2/3) f for real h
        for h in (fmpq(1, 8), fmpq(2, 5)):
            (val,) = model.real_part(w, h, h)
            assert val.contains(fmpq(2, 3) / (1 - h))
        span = hull(model.real_part(w, fmpq(0), fmpq(2, 5)))
        assert span.contains(fmpq(2, 3)) and span.contains(fmpq(2, 3) / (1 - fmpq(2, 5)))


def test_outside_the_disc_nothing_is_claimed():
    with pytest.raises(ZeroDivisionError):
        cauchy_factor(R, 4, R)
    with pytest.raises(ZeroDivisionError):
        geometric(4, arb(2)).enclose(fmpq(0), fmpq(3, 5))
    assert ball(fmpq(1, 3), fmpq(1, 2)).contains(fmpq(5, 12))
