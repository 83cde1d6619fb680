"""The maps of the statement as Bernstein forms on the unit box of the local parameters (trusted): weight, cells,
det J_G, corner form, det J_Phi, outer curves, of ``nets`` {piece: 4 x 4 Bezier net of (arb, arb)} enclosing
:mod:`.statement`'s (docs/appendix_a.md sections 1-3, docs/certificates.md parts A-E).

>>> nets, lam = nets_for_valence(4, 64), c_lam(4, 64)[1]    # k = 4: Phi is the identity, lam = 1/2
>>> corner_containment(nets, lam, 3), corner_containment(nets, lam, 2)[0], square_inside_image(nets)   # part A, C
((True, 0.125000000000000), False, True)
"""

from flint import arb, ctx, fmpq, fmpq_poly  # noqa: F401 (arb: the examples)

from ccproof.rigorous import BernsteinForm, TaylorForm, exact_fmpq, jacobian_determinant, range_enclosure  # noqa: F401

from .statement import PATCHES, c_lam, nets_for_valence, split_half  # noqa: F401 (c_lam, nets: the examples)

BREAKS = (fmpq(0), fmpq(1, 6), fmpq(1, 3), fmpq(1, 2))  # w pieces (docs/readings.md R5); piece 3 is w = 0
#: layer-0 coordinates (u, v) = ORIGIN + (sigma, tau) / 2 of the local parameters (sigma, tau) of each piece
ORIGIN = {"P1": (fmpq(1, 2), fmpq(0)), "P2": (fmpq(1, 2), fmpq(1, 2)), "P3": (fmpq(0), fmpq(1, 2))}
STAR_CURVES = {"P1s1": ("P1", "s", 1), "P2s1": ("P2", "s", 1), "P2t1": ("P2", "t", -1), "P3t1": ("P3", "t", -1)}


def weight_piece(p):
    """b(x) = B(6x+1) + B(6x) + B(6x-1) on [BREAKS[p], BREAKS[p+1]] (R5), exact; B the centred cubic B-spline
    (4 - 6z^2 + 3|z|^3)/6 on |z| <= 1, (2 - |z|)^3/6 on 1..2.

    >>> weight_piece(0)(0), weight_piece(2)(fmpq(1, 2)), weight_piece(0)(fmpq(1, 6)) == weight_piece(1)(fmpq(1, 6))
    (1, 0, True)
    """
    out = fmpq_poly([])
    for shift in (1, 0, -1):  # z = 6x + shift runs over [p + shift, p + shift + 1]: one piece of B, one sign
        z, mid = fmpq_poly([shift, 6]), p + shift + fmpq(1, 2)
        sign = 1 if mid > 0 else -1
        if abs(mid) < 1:
            out += (4 - 6 * z**2 + 3 * sign * z**3) / 6
        elif abs(mid) < 2:
            out += (2 - sign * z) ** 3 / 6
    return out


def net_form(net, coord, prec):
    """Bernstein form on the unit box of one coordinate of a 4x4 Bezier net.

    >>> [z.str(6, radius=False) for z in range_enclosure(net_form(nets_for_valence(4, 64)["P1"], 1, 64))]
    ['0', '0.500000']
    """
    return BernsteinForm((4, 4), [net[i][j][coord] for i in range(4) for j in range(4)], prec=prec)


def cell_geometry(l, m, N):
    """(layer i, piece, (s, t) sub-box) of the dyadic cell (l, m) != (0, 0) of level N (part D).

    >>> cell_geometry(1, 0, 1), cell_geometry(1, 0, 2), cell_geometry(3, 1, 2)
    ((0, 'P1', ((0, 1), (0, 1))), (1, 'P1', ((0, 1), (0, 1))), (0, 'P1', ((1/2, 1), (1/2, 1))))
    """
    i = N - 1 - (max(l, m).bit_length() - 1)
    scale = fmpq(2**i, 2**N)  # layer-0 coordinates of the cell: [l, l+1] * scale
    u0, v0 = l * scale, m * scale
    name = "P3" if u0 < fmpq(1, 2) else "P1" if v0 < fmpq(1, 2) else "P2"
    s0, t0, h = 2 * (u0 - ORIGIN[name][0]), 2 * (v0 - ORIGIN[name][1]), 2 * scale
    return i, name, ((s0, s0 + h), (t0, t0 + h))


def cell_pieces(X, Y):
    """The w pieces (p, q), p, q in 0..3 (3: w = 0), whose regions the Bezier hull of (X, Y) may meet.

    >>> nets = nets_for_valence(4, 64)     # P1: x in [1/2, 1], y in [0, 1/2]
    >>> cell_pieces(net_form(nets["P1"], 0, 64), net_form(nets["P1"], 1, 64))
    [(2, 0), (2, 1), (2, 2), (2, 3), (3, 0), (3, 1), (3, 2), (3, 3)]
    """
    def pieces(F):
        lo, hi = min(c.lower() for c in F.coeffs), max(c.upper() for c in F.coeffs)
        return [p for p in range(4) if not (hi < BREAKS[p] or (p < 3 and lo > BREAKS[p + 1]))]
    return [(p, q) for p in pieces(X) for q in pieces(Y)]


def det_form(X, Y, i, name, p, q, D):
    """det dG/d(sigma, tau) on layer i of piece ``name``, w piece (p, q), G = Phi + w(Phi) (y - Phi), from Taylor
    models X, Y of lam^i Phi in (zeta; sigma, tau) truncated to degree D: a form on [-1, 1] x [0, 1]^2.

    >>> X, Y = TaylorForm((1, 2, 1), [arb(1) / 2, arb(1)], 64), TaylorForm((1, 1, 2), [0, arb(1) / 2], 64)
    >>> [z.str(6, radius=False) for z in range_enclosure(det_form(X, Y, 0, "P1", 2, 2, 0))]   # k = 4: G = y
    ['0.250000', '0.250000']
    """
    prec = X.prec
    with ctx.workprec(prec):
        u0, v0 = ORIGIN[name]
        scale = fmpq(1, 2 ** (i + 1))
        y1 = (TaylorForm.variable(1, 2, prec) + 2 * u0) * scale
        y2 = (TaylorForm.variable(2, 2, prec) + 2 * v0) * scale
        w = (_weight(p, X, D) * _weight(q, Y, D)).truncate(D)
        G = [(F + w * (y - F)).truncate(D) for y, F in ((y1, X), (y2, Y))]
        return jacobian_determinant(G, (1, 2)).truncate(D).bernstein()


def _weight(p, X, D):
    """b(X) on piece p, Horner around the exact midpoint x0 of X's first coefficient (tighter balls)."""
    x0 = exact_fmpq(X.coeffs[0].mid())
    b = weight_piece(p)(fmpq_poly([x0, 1])).coeffs() or [fmpq(0)]  # b(x0 + x)
    acc = TaylorForm.constant(b[-1], 2, X.prec)
    for c in b[-2::-1]:
        acc = (acc * (X - x0)).truncate(D) + c
    return acc


def corner_det_form(nets, lam, N, name, prec):
    """det(J_G)/h^2 on layer i >= N of piece ``name`` in (rho, kappa, s, t) on [0,1]^4 (R9, part E), in Bernstein
    arithmetic (tight for the hull nets of k >= k0).

    >>> f = corner_det_form(nets_for_valence(4, 64), c_lam(4, 64)[1], 2, "P1", 64)   # det I/2 at rho = kappa = 0
    >>> f.nvars, f.coeffs[0].overlaps(arb(1) / 4)
    (4, True)
    """
    with ctx.workprec(prec):
        def var(axis, c):  # c * x_axis
            return BernsteinForm(tuple(2 if i == axis else 1 for i in range(4)), [0, c], prec=prec)

        P = [BernsteinForm((1, 1, 4, 4), net_form(nets[name], d, prec).coeffs, prec=prec) for d in range(2)]
        r, qv, s, t = var(0, lam ** (3 * N)), var(1, (2 * lam**4) ** N), var(2, 1), var(3, 1)
        half = fmpq(1, 2)
        D = [ORIGIN[name][0] + s * half, ORIGIN[name][1] + t * half]
        Px3, Py3 = P[0] * P[0] * P[0], P[1] * P[1] * P[1]
        U = (Px3 + Py3) * 36 - r * Px3 * Py3 * 1296
        W = 1 - r * U
        gradU = (U.diff(2), U.diff(3))
        J = [[qv * (U * P[a].diff(2 + b) + P[a] * gradU[b]) - r * D[a] * gradU[b] for b in range(2)] for a in range(2)]
        return (J[0][0] + W * half) * (J[1][1] + W * half) - J[0][1] * J[1][0]


def regularity_form(nets, name, prec):
    """det J_Phi in the local (s, t) of piece ``name`` on layer 0, degree (5, 5), in Bernstein arithmetic.

    >>> [z.str(6, radius=False) for z in range_enclosure(regularity_form(nets_for_valence(4, 64), "P2", 64))]
    ['0.250000', '0.250000']
    """
    return jacobian_determinant([net_form(nets[name], 0, prec), net_form(nets[name], 1, prec)])


def curve_points(nets, curve, oriented=False):
    """The Bezier points of one outer cubic (a key of :data:`STAR_CURVES`: side s = 1 or t = 1 of a piece), in the
    piece's parameter order or counterclockwise around the star (``oriented``).

    >>> nets = {"P2": [[(i, j) for j in range(4)] for i in range(4)]}
    >>> curve_points(nets, "P2s1"), curve_points(nets, "P2t1"), curve_points(nets, "P2t1", oriented=True)[0]
    ([(3, 0), (3, 1), (3, 2), (3, 3)], [(0, 3), (1, 3), (2, 3), (3, 3)], (3, 3))
    """
    name, side, sign = STAR_CURVES[curve]
    net = nets[name]
    pts = [net[3][j] for j in range(4)] if side == "s" else [net[i][3] for i in range(4)]
    return pts[::-1] if oriented and sign < 0 else pts


def star_form(nets, curve, prec):
    """x y' - y x' (degree 5) along one outer cubic, oriented from (1, 0) towards (0, 1): positive on all four
    curves, the outer boundary is star-shaped.

    >>> nets = nets_for_valence(4, 64)      # k = 4, on u = 1: x y' - y x' = 1 * 1/2
    >>> [bool(abs(range_enclosure(star_form(nets, cv, 64))[0] - arb(1) / 2) < 1e-12) for cv in STAR_CURVES]
    [True, True, True, True]
    """
    pts = curve_points(nets, curve)
    with ctx.workprec(prec):
        X = BernsteinForm((4,), [p[0] for p in pts], prec=prec)
        Y = BernsteinForm((4,), [p[1] for p in pts], prec=prec)
        cross = X * Y.diff(0) - Y * X.diff(0)
        return cross if STAR_CURVES[curve][2] > 0 else -cross


def corner_containment(nets, lam, N):
    """Part A: (lam^N * max(all Bezier coordinates) < 1/6 certainly, that ball); example: the module's."""
    hull = max((c[d].upper() for n in PATCHES for row in nets[n] for c in row for d in range(2)),
               key=lambda z: z.mid())
    return bool(lam**N * hull < fmpq(1, 6)), lam**N * hull


def square_inside_image(nets):
    """Part C: the images of the outer sides u = 1, v = 1 avoid [0,1/2]^2 (replayed bisection); example: the
    module's."""
    return all(_curve_avoids(curve_points(nets, cv), 40) for cv in STAR_CURVES)


def _curve_avoids(curve, depth):
    """max(x, y) > 1/2 on the whole cubic Bezier curve (replayed bisection, bounded depth)."""
    half = fmpq(1, 2)
    if all(p[0] > half for p in curve) or all(p[1] > half for p in curve):
        return True
    return depth > 0 and all(_curve_avoids(part, depth - 1) for part in split_half(curve))
