#!/usr/bin/env python
"""Explore the normal part of the "not C1" witness of ``crease:N`` for all large N at once (not trusted).

The witness's part N needs J_xy != 0 at the vertex (1,1) of quadrant 0, where x and y are the real
eigenvectors of the modes 1 and 2 (w = exp(i theta), exp(2 i theta), theta = pi/N). J_xy tends to 0
with theta. This script computes, in arb / acb (python-flint), independently of the verifier's
ccproof/certify/verify/tagged_limit.py (which checks them for the certificates crease:>=N0, corner:>=N0),
the quantities of docs/tagged_c1.md ("Every N >= N0 in one certificate"):

* H(theta) = T_a(f1) T_b(f2) - T_b(f1) T_a(f2), f_j the sector values of v - v o R for the mode
  vector v(t, p) = w^t v^(p) of mode j, v^ from the bordered 6 x 6 system of B(w) with v^(1,0) = 1
  (an analytic function of complex theta; for real theta it is a non-zero complex multiple of J_xy);
* the exact reflection identity B(1/w) R_w = R_w B(w) (R_w: ray p -> v^(p), quadrant (a, b) ->
  v^(b, a) / w) on rational points, which makes f odd in theta, so H has a zero of order >= 4 at 0;
* the bordered systems regular on the whole disc |theta| <= rho (acb boxes), so H is analytic there;
* the winding number of H along |theta| = rho (each arc's image in a disc that misses 0, by a centred
  form: H at the arc's start plus a Cauchy bound of |H'| from a crude bound of |H| on a larger circle).

If the winding number is 4, theta = 0 is H's only zero in the disc: J_xy != 0 for every N > pi/rho.
Prints one line per item.

  python scripts/tagged_c1_limit.py [--rho 0.2] [--arcs 512] [--outer 0.3] [--outer-arcs 2048] [--box 0.05]
"""

from __future__ import annotations

import argparse
import math

from flint import acb, acb_mat, arb, ctx, fmpq

from ccproof.certify.verify.tagged_modes import RING_INDEX, ring_block

_W = (fmpq(1, 6), fmpq(4, 6), fmpq(1, 6))
_DW = (fmpq(-1, 2), fmpq(0), fmpq(1, 2))
_PIVOT = RING_INDEX[(1, 0)]


def _reflection(w):
    """R_w as a 6 x 6 list (rows: hat positions of the mode 1/w vector v o R)."""
    rows = [[0 * w] * 6 for _ in range(6)]
    for p, i in RING_INDEX.items():
        if p[1] == 0:
            rows[i][i] += 1
        else:
            rows[i][RING_INDEX[(p[1], p[0])]] += 1 / w
    return rows


def _mul(A, B):
    return [[sum((A[i][k] * B[k][j] for k in range(6)), 0 * A[0][0]) for j in range(6)] for i in range(6)]


def reflection_identity(points=range(2, 14)):
    """True iff B(1/w) R_w == R_w B(w) exactly at the rational points w (Laurent degree <= 3 each side)."""
    for a in points:
        for w in (fmpq(a), fmpq(-a), fmpq(1, a), fmpq(-1, a)):
            if _mul(ring_block(1 / w), _reflection(w)) != _mul(_reflection(w), ring_block(w)):
                return False
    return True


def _local(theta, j):
    """(T_a, T_b) of f_j at the vertex (1,1) of quadrant 0; raises ZeroDivisionError if not regular."""
    w = (acb(0, 1) * j * theta).exp()
    c = (w + 1 / w) / 2
    disc = (1 + c) * (9 + c)
    if not disc.real > 0:  # the principal square root is analytic on the right half-plane
        raise ZeroDivisionError("(1 + c)(9 + c) not certainly in the right half-plane")
    lam = (5 + c + disc.sqrt()) / 16
    B = ring_block(w)
    rows = [[B[i][k] - (lam if i == k else 0) for k in range(6)] + [acb(int(i == _PIVOT))] for i in range(6)]
    rows.append([acb(int(k == _PIVOT)) for k in range(6)] + [acb(0)])
    sol = acb_mat(rows).solve(acb_mat([[0]] * 6 + [[1]]))
    vh = {p: sol[i, 0] for p, i in RING_INDEX.items()}
    val = {}
    for a in range(3):
        for b in range(3):
            if b == 0:  # the centre and ray 0: 0
                val[a, b] = acb(0)
            elif a == 0:  # ray 1
                val[a, b] = vh[(b, 0)] * (w - 1 / w)
            else:
                val[a, b] = vh[(a, b)] - vh[(b, a)] / w
    ta = sum((_DW[a] * _W[b] * val[a, b] for a in range(3) for b in range(3)), acb(0))
    tb = sum((_W[a] * _DW[b] * val[a, b] for a in range(3) for b in range(3)), acb(0))
    return ta, tb


def H(theta):
    """H(theta) (an acb ball, for an acb ball theta)."""
    a1, b1 = _local(theta, 1)
    a2, b2 = _local(theta, 2)
    return a1 * b2 - b1 * a2


def disc_regular(rho, box):
    """The number of boxes covering |theta| <= rho on which both bordered systems are proved regular, of all."""
    m = math.ceil(rho / box)
    ok = total = 0
    for u in range(-m, m):
        for v in range(-m, m):
            lo_x, lo_y = u * box, v * box
            near = math.hypot(min(abs(lo_x), abs(lo_x + box)) if lo_x * (lo_x + box) > 0 else 0,
                              min(abs(lo_y), abs(lo_y + box)) if lo_y * (lo_y + box) > 0 else 0)
            if near > rho:
                continue
            total += 1
            z = acb(arb(lo_x + box / 2, box / 2), arb(lo_y + box / 2, box / 2))
            try:
                H(z)
                ok += 1
            except ZeroDivisionError:
                pass
    return ok, total


def bound_on_circle(radius, arcs):
    """An upper bound of |H| on |theta| = radius (balls covering the arcs; a crude bound is enough)."""
    top = arb(0)
    for k in range(arcs):
        mid, half = arb(2 * k + 1) / arcs, arb(1) / arcs  # in units of pi
        ball = acb(arb(0), (mid + arb(0, half.mid())) * arb.pi()).exp() * radius  # covers the arc
        top = top.max(arb(abs(H(ball)).upper()))
    return top


def winding(rho, arcs, outer, outer_arcs):
    """The winding number of H along |theta| = rho by a centred form, or None if an arc is not certain.

    H is analytic on |theta| <= outer (the caller proves the bordered systems regular there), so by the
    Cauchy formula |H'| <= M outer / (outer - rho)^2 on |theta| = rho, M >= |H| on |theta| = outer. Each arc
    from z_k to z_(k+1) (length 2 pi rho / arcs) has its image within |H'| * length of H(z_k); if that is
    less than |H(z_k)|, the image lies in a disc that misses 0 and the turn along the arc is the principal
    argument of H(z_(k+1)) / H(z_k).
    """
    M = bound_on_circle(outer, outer_arcs)
    slope = M * outer / (outer - arb(rho)) ** 2
    length = 2 * arb.pi() * rho / arcs
    pts = [H(acb(arb(0), arb(2 * k) / arcs * arb.pi()).exp() * rho) for k in range(arcs + 1)]
    turn = arb(0)
    for h0, h1 in zip(pts, pts[1:]):
        if not slope * length < abs(h0):
            return None, M
        turn += (h1 / h0).arg()
    return turn / (2 * arb.pi()), M


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--rho", type=float, default=0.2)
    ap.add_argument("--arcs", type=int, default=512)
    ap.add_argument("--box", type=float, default=0.05)
    ap.add_argument("--outer", type=float, default=0.3, help="radius of the circle bounding |H| (Cauchy)")
    ap.add_argument("--outer-arcs", type=int, default=2048)
    ap.add_argument("--prec", type=int, default=128)
    args = ap.parse_args(argv)
    ctx.prec = args.prec
    print(f"reflection identity B(1/w) R_w = R_w B(w), exact at rational w: {reflection_identity()}")
    for n in (101, 1000, 10**6):
        th = arb.pi() / n
        print(f"N = {n}: H(pi/N) / theta^4 = {(H(acb(th)) / th ** 4).str(10)}")
    ok, total = disc_regular(args.outer, args.box)
    print(f"|theta| <= {args.outer}: bordered systems of modes 1 and 2 proved regular on {ok} of {total} boxes "
          f"(side {args.box})")
    wn, M = winding(args.rho, args.arcs, args.outer, args.outer_arcs)
    print(f"|H| <= {M.str(4)} on |theta| = {args.outer}; winding number of H along |theta| = {args.rho} "
          f"({args.arcs} arcs): {'not certified' if wn is None else wn.str(6)}")


if __name__ == "__main__":
    main()
