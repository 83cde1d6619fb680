"""The maps of the statement as Bernstein forms: weight, cells, corner, regularity, outer curves (trusted).

Given nets of the characteristic map (arb balls enclosing the exact nets of :mod:`.statement`) and
lam, these functions build the polynomials whose positivity the certificates claim
(docs/certificates.md, parts A-E; docs/appendix_a.md derives them). Throughout, ``nets`` maps each piece
P1, P2, P3 to its 4 x 4 Bezier net of points (arb, arb), ``lam`` is an arb, ``prec`` the bits, and a
form is a :class:`~ccproof.rigorous.BernsteinForm` on the unit box of the local parameters.
"""

from __future__ import annotations

from flint import ctx, fmpq, fmpq_poly

from ccproof.rigorous import BernsteinForm, TaylorForm, exact_fmpq, jacobian_determinant

from .statement import PATCHES, split_half

BREAKS = (fmpq(0), fmpq(1, 6), fmpq(1, 3), fmpq(1, 2))  # w pieces (docs/readings.md R5); piece 3 is w = 0


def weight_piece(p):
    """b(x) = B(6x+1) + B(6x) + B(6x-1) on [BREAKS[p], BREAKS[p+1]] (R5) as an exact polynomial;
    B is the centred uniform cubic B-spline: (4 - 6z^2 + 3|z|^3)/6 on |z| <= 1, (2 - |z|)^3/6 on 1..2.

    Returns
    -------
    fmpq_poly
        Degree 3 in x; the weight w is 1 at 0 and 0 from 1/2 on (docs/readings.md R5).

    Examples
    --------
    >>> weight_piece(0)(0), weight_piece(2)(fmpq(1, 2)), weight_piece(0)(fmpq(1, 6)) == weight_piece(1)(fmpq(1, 6))
    (1, 0, True)
    """
    z = fmpq_poly([0, 6])  # z = 6x

    def B(shift, region):  # B(z + shift) on a region where z + shift has one sign/one piece
        a = z + shift
        if region == "inner+":
            return (4 - 6 * a**2 + 3 * a**3) / 6
        if region == "inner-":
            return (4 - 6 * a**2 - 3 * a**3) / 6
        if region == "outer+":
            return (2 - a) ** 3 / 6
        return fmpq_poly([0])

    pieces = {  # z in [0,1]: z+1 in [1,2], z in [0,1], z-1 in [-1,0]; and so on
        0: B(1, "outer+") + B(0, "inner+") + B(-1, "inner-"),
        1: B(1, "zero") + B(0, "outer+") + B(-1, "inner+"),
        2: B(0, "zero") + B(-1, "outer+"),
    }
    return pieces[p]


def net_form(net, coord, prec, box=None):
    """Bernstein form (unit box in the local variables) of one coordinate of a 4x4 Bezier net,
    restricted to ``box`` (dyadic sub-box of [0,1]^2 in the piece's local parameters).

    Returns
    -------
    BernsteinForm
        Degrees (3, 3) on [0, 1]^2.

    Examples
    --------
    >>> from ccproof.certify.verify.statement import c_lam, nets_for_valence
    >>> from ccproof.rigorous import range_enclosure
    >>> nets, (c, lam) = nets_for_valence(4, 64), c_lam(4, 64)   # k = 4: Phi is the identity, lam = 1/2
    >>> boxes = (None, ((0, 1), (0, "1/2")))
    >>> [[z.str(6, radius=False) for z in range_enclosure(net_form(nets["P1"], 1, 64, b))] for b in boxes]
    [['0', '0.500000'], ['0', '0.250000']]
    """
    f = BernsteinForm((4, 4), [net[i][j][coord] for i in range(4) for j in range(4)], prec=prec)
    if box is not None:
        f = f.restrict(box)
    return BernsteinForm((4, 4), f.coeffs, prec=prec)  # relabel the sub-box as the unit box


def cell_geometry(l, m, N):
    """Layer i, piece name and (s, t) sub-box of the dyadic cell (l, m) != (0, 0) of level N, the cell
    [l, l+1] x [m, m+1] / 2^N of the face (docs/appendix_a.md, part D).

    Examples
    --------
    >>> cell_geometry(1, 0, 1), cell_geometry(1, 0, 2), cell_geometry(3, 1, 2)
    ((0, 'P1', ((0, 1), (0, 1))), (1, 'P1', ((0, 1), (0, 1))), (0, 'P1', ((1/2, 1), (1/2, 1))))
    """
    M = max(l, m)
    i = N - 1 - (M.bit_length() - 1)
    scale = fmpq(2**i, 2**N)  # layer-0 coordinates of the cell: [l, l+1] * scale
    u0, v0 = l * scale, m * scale
    half = fmpq(1, 2)
    if u0 >= half and v0 < half:
        name, s0, t0 = "P1", 2 * u0 - 1, 2 * v0
    elif u0 >= half:
        name, s0, t0 = "P2", 2 * u0 - 1, 2 * v0 - 1
    else:
        name, s0, t0 = "P3", 2 * u0, 2 * v0 - 1
    h = 2 * scale
    return i, name, ((s0, s0 + h), (t0, t0 + h))


def cell_pieces(X, Y):
    """The w pieces (p, q), p, q in 0..3, whose regions the Bezier hull of (X, Y) may meet.

    Returns
    -------
    list of (int, int)
        Pieces of :data:`BREAKS` (p = 3: w = 0).

    Examples
    --------
    >>> from ccproof.certify.verify.statement import c_lam, nets_for_valence
    >>> nets, (c, lam) = nets_for_valence(4, 64), c_lam(4, 64)   # k = 4: Phi is the identity, lam = 1/2
    >>> cell_pieces(net_form(nets["P1"], 0, 64), net_form(nets["P1"], 1, 64))   # x in [1/2, 1], y in [0, 1/2]
    [(2, 0), (2, 1), (2, 2), (2, 3), (3, 0), (3, 1), (3, 2), (3, 3)]
    """
    rng = []
    for F in (X, Y):
        lo = min(c.lower() for c in F.coeffs)
        hi = max(c.upper() for c in F.coeffs)
        rng.append([p for p in range(4) if not (hi < BREAKS[p] or (p < 3 and lo > BREAKS[p + 1]))])
    return [(p, q) for p in rng[0] for q in rng[1]]


def dyadic_cells(N, symmetric):
    """The cells (l, m) != (0, 0) of level N that part D checks (l <= m only when ``symmetric``).

    Examples
    --------
    >>> dyadic_cells(1, False), dyadic_cells(1, True)
    ([(0, 1), (1, 0), (1, 1)], [(0, 1), (1, 1)])
    """
    return [(l, m) for l in range(2**N) for m in range(2**N) if (l, m) != (0, 0) and not (symmetric and l > m)]


#: layer-0 coordinates (u, v) = ORIGIN + (sigma, tau) / 2 of the local parameters (sigma, tau) of each piece
ORIGIN = {"P1": (fmpq(1, 2), fmpq(0)), "P2": (fmpq(1, 2), fmpq(1, 2)), "P3": (fmpq(0), fmpq(1, 2))}


def det_form(X, Y, i, name, p, q, D):
    """Bernstein form on [-1, 1] x [0, 1]^2 of det dG/d(sigma, tau) on layer i of piece ``name`` for the w piece
    (p, q), G = Phi + w(Phi) (y - Phi), from the Taylor models X, Y of lam^i Phi in (zeta; sigma, tau) (truncated
    to degree D in zeta; zeta-degree 0 for one valence); y = 2^-i (ORIGIN + (sigma, tau)/2): one form for all the
    cells of that layer, piece and w piece (:func:`.interval.interval_cells` restricts it to each).

    Examples
    --------
    At k = 4 (Phi = y on P1, lam = 1/2) the blend G is y and det = 1/4 on layer 0:

    >>> from flint import arb
    >>> from ccproof.rigorous import range_enclosure
    >>> X, Y = (TaylorForm((1, 2, 1), [arb(1) / 2, arb(1)], 64), TaylorForm((1, 1, 2), [0, arb(1) / 2], 64))
    >>> [z.str(6, radius=False) for z in range_enclosure(det_form(X, Y, 0, "P1", 2, 2, 0))]
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
    """Bernstein form on [0,1]^4 of det(J_G)/h^2 on layer i >= N of piece ``name`` in (rho, kappa, s, t)
    (R9 form), computed in Bernstein arithmetic (stays tight for the interval nets of k >= k0).

    Returns
    -------
    BernsteinForm
        Degrees (1, 1, ., .) in (rho, kappa) (docs/readings.md R9, part E of docs/certificates.md).

    Examples
    --------
    At rho = kappa = 0 the Jacobian is I/2, so those coefficients are det = 1/4:

    >>> from ccproof.certify.verify.statement import c_lam, nets_for_valence
    >>> from flint import arb
    >>> nets, (c, lam) = nets_for_valence(4, 64), c_lam(4, 64)   # k = 4: Phi is the identity, lam = 1/2
    >>> f = corner_det_form(nets, lam, 2, "P1", 64)
    >>> f.nvars, f.coeffs[0].overlaps(arb(1) / 4)
    (4, True)
    """
    with ctx.workprec(prec):
        def var(axis, c):  # c * x_axis
            return BernsteinForm(tuple(2 if i == axis else 1 for i in range(4)), [0, c], prec=prec)

        P = [BernsteinForm((1, 1, 4, 4), net_form(nets[name], d, prec).coeffs, prec=prec) for d in range(2)]
        r, qv, s, t = var(0, lam ** (3 * N)), var(1, (2 * lam**4) ** N), var(2, 1), var(3, 1)
        half = fmpq(1, 2)
        D = {"P1": (half + s * half, t * half), "P2": (half + s * half, half + t * half),
             "P3": (s * half, half + t * half)}[name]
        Px3, Py3 = P[0] * P[0] * P[0], P[1] * P[1] * P[1]
        U = (Px3 + Py3) * 36 - r * Px3 * Py3 * 1296
        W = 1 - r * U
        gradU = (U.diff(2), U.diff(3))
        J = [[None, None], [None, None]]
        for a in range(2):
            for b in range(2):
                e = qv * (U * P[a].diff(2 + b) + P[a] * gradU[b]) - r * D[a] * gradU[b]
                J[a][b] = e + W * half if a == b else e
        return J[0][0] * J[1][1] - J[0][1] * J[1][0]


def regularity_form(nets, name, prec):
    """Bernstein form (degree (5,5)) of det J_Phi w.r.t. the local (s, t) of piece ``name`` on layer 0,
    computed in Bernstein arithmetic (stays tight for the interval nets of k >= k0).

    Examples
    --------
    At k = 4, Phi(s, t) on a piece is the identity scaled by 1/2, so det J_Phi = 1/4:

    >>> from ccproof.certify.verify.statement import c_lam, nets_for_valence
    >>> from ccproof.rigorous import range_enclosure
    >>> nets, (c, lam) = nets_for_valence(4, 64), c_lam(4, 64)   # k = 4: Phi is the identity, lam = 1/2
    >>> [z.str(6, radius=False) for z in range_enclosure(regularity_form(nets, "P2", 64))]
    ['0.250000', '0.250000']
    """
    with ctx.workprec(prec):
        return jacobian_determinant([net_form(nets[name], 0, prec), net_form(nets[name], 1, prec)])


STAR_CURVES = {"P1s1": ("P1", "s", 1), "P2s1": ("P2", "s", 1), "P2t1": ("P2", "t", -1), "P3t1": ("P3", "t", -1)}


def curve_points(nets, curve, oriented=False):
    """The Bezier points of one cubic of the outer boundary (a key of :data:`STAR_CURVES`: the side s = 1 or
    t = 1 of a piece), in the piece's parameter order, or counterclockwise around the star (``oriented``).

    Examples
    --------
    >>> nets = {"P2": [[(i, j) for j in range(4)] for i in range(4)]}
    >>> curve_points(nets, "P2s1"), curve_points(nets, "P2t1")
    ([(3, 0), (3, 1), (3, 2), (3, 3)], [(0, 3), (1, 3), (2, 3), (3, 3)])
    >>> curve_points(nets, "P2t1", oriented=True)
    [(3, 3), (2, 3), (1, 3), (0, 3)]
    """
    name, side, sign = STAR_CURVES[curve]
    net = nets[name]
    pts = [net[3][j] for j in range(4)] if side == "s" else [net[i][3] for i in range(4)]
    return pts[::-1] if oriented and sign < 0 else pts


def star_form(nets, curve, prec):
    """Bernstein form (degree 5) of x y' - y x' along one cubic of the outer boundary, oriented from
    (1,0) towards (0,1). Positive on all four curves means the outer boundary is star-shaped.

    Examples
    --------
    At k = 4 the outer boundary is the square's: on u = 1, x y' - y x' = 1 * 1/2:

    >>> from ccproof.certify.verify.statement import c_lam, nets_for_valence
    >>> from flint import arb
    >>> from ccproof.rigorous import range_enclosure
    >>> nets, (c, lam) = nets_for_valence(4, 64), c_lam(4, 64)   # k = 4: Phi is the identity, lam = 1/2
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
    """Part A: (lam^N * max(all Bezier coordinates) < 1/6 certainly, that ball).

    Examples
    --------
    >>> from ccproof.certify.verify.statement import c_lam, nets_for_valence
    >>> nets, (c, lam) = nets_for_valence(4, 64), c_lam(4, 64)   # k = 4: Phi is the identity, lam = 1/2
    >>> corner_containment(nets, lam, 3), corner_containment(nets, lam, 2)[0]   # 1/8 < 1/6 < 1/4
    ((True, 0.125000000000000), False)
    """
    hull = max((c[d].upper() for n in PATCHES for row in nets[n] for c in row for d in range(2)),
               key=lambda z: z.mid())
    return bool(lam**N * hull < fmpq(1, 6)), lam**N * hull


def square_inside_image(nets):
    """Part C: the images of the outer sides u = 1, v = 1 avoid [0,1/2]^2 (replayed bisection).

    Examples
    --------
    >>> from ccproof.certify.verify.statement import c_lam, nets_for_valence
    >>> nets, (c, lam) = nets_for_valence(4, 64), c_lam(4, 64)   # k = 4: Phi is the identity, lam = 1/2
    >>> square_inside_image(nets)
    True
    """
    return all(_curve_avoids(curve_points(nets, cv), 40) for cv in STAR_CURVES)


def _curve_avoids(curve, depth):
    """max(x, y) > 1/2 on the whole cubic Bezier curve (replayed bisection, bounded depth)."""
    half = fmpq(1, 2)
    if all(p[0] > half for p in curve) or all(p[1] > half for p in curve):
        return True
    if depth == 0:
        return False
    left, right = split_half(curve)
    return _curve_avoids(left, depth - 1) and _curve_avoids(right, depth - 1)


