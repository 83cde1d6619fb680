"""Every valence k >= k0 in one certificate: lam as a variable, Taylor models in zeta (trusted).

The valence enters the statement only through lam = lam(k), with c = (16 lam^2 - 10 lam + 1)/(2 lam)
(docs/readings.md R2), so the exact forms of :mod:`.statement` are rational functions of lam. On a piece
[La, Lb] of lam, lam = mid + zeta * half-width with zeta in [-1, 1]; every net entry becomes an exact
Taylor polynomial in zeta plus a remainder bounded by exact Bernstein coefficients
(:func:`entry_model`). Parts A, B, C, E use the hulls over zeta, part D keeps zeta as a Bernstein
variable (axis 0). docs/appendix_a.md section 6 has the mathematics.
"""

from __future__ import annotations

from flint import arb, arb_mat, ctx, fmpq, fmpq_mat, fmpq_poly

from ccproof.rigorous import BernsteinForm, TaylorForm, conversion_matrix, range_enclosure

from .errors import CertificateError
from .maps import cell_geometry, cell_pieces, det_form, dyadic_cells, net_form
from .statement import B2Z, PATCHES, c_lam

ZBOX = ((fmpq(-1), fmpq(1)), (fmpq(0), fmpq(1)), (fmpq(0), fmpq(1)))  # (zeta, s, t) of part D


def _bern1(p, prec=None):
    """Bernstein coefficients on zeta in [-1, 1] of an fmpq_poly (or a list of arb coefficients)."""
    c = [p[i] for i in range(max(1, p.degree() + 1))] if isinstance(p, fmpq_poly) else p
    M = conversion_matrix(len(c) - 1, len(c) - 1, *ZBOX[0])
    if prec is None:
        return (M * fmpq_mat(len(c), 1, c)).entries()
    with ctx.workprec(prec):
        return (arb_mat(M) * arb_mat(len(c), 1, c)).entries()


def entry_model(form, L, layer, degree, prec):
    """lam^layer (A(c) + B(c) lam)/D(c) for lam = L(zeta), zeta in [-1, 1], c = (16 lam^2 - 10 lam + 1)/(2 lam)
    (R2), as arb coefficients of T(zeta) + [-r, r]: T the exact Taylor polynomial of ``degree`` at 0 and
    r = max|Bernstein coefficients of num - den T| / min|those of den| (den of one strict sign).

    Parameters
    ----------
    L : fmpq_poly
        lam as a polynomial in zeta.

    Returns
    -------
    list of degree + 1 arb
        Taylor coefficients, the remainder ball added to the constant one (docs/appendix_a.md section 6).

    Examples
    --------
    lam^2 for lam = 1/2 + zeta/10: exactly 1/4 + zeta/10 + zeta^2/100; at degree 1 the remainder is the
    largest Bernstein coefficient of zeta^2/100 on [-1, 1], 1/100:

    >>> L = fmpq_poly([fmpq(1, 2), fmpq(1, 10)])
    >>> [x.str(6, radius=False) for x in entry_model([[0], [1], [1]], L, 1, 2, 64)]
    ['0.250000', '0.100000', '0.0100000']
    >>> m = entry_model([[0], [1], [1]], L, 1, 1, 64)
    >>> m[0].mid().str(6), bool(arb('0.01') <= m[0].rad() < arb('0.0101'))
    ('0.250000', True)
    """
    cn, cd = 16 * L * L - 10 * L + 1, 2 * L
    M = max(len(f) for f in form) - 1

    def clear(P):  # P(c) (2 lam)^M as a polynomial in zeta
        return sum((cn**e * cd ** (M - e) * int(a) for e, a in enumerate(P)), fmpq_poly([]))

    num, den = (clear(form[0]) + clear(form[1]) * L) * L**layer, clear(form[2])
    db = _bern1(den)
    if not (all(c > 0 for c in db) or all(c < 0 for c in db)):
        raise CertificateError("a denominator of the exact nets may vanish on the lam interval")
    T = []
    for j in range(degree + 1):
        T.append((num[j] - sum((den[i] * T[j - i] for i in range(1, j + 1)), fmpq(0))) / den[0])
    r = max(abs(c) for c in _bern1(num - den * fmpq_poly(T))) / min(abs(c) for c in db)
    out = [arb(t) for t in T]
    out[0] += arb(0, arb(r).upper())
    return out


def parameter_nets(exact, La, Lb, layer, degree, prec):
    """Bezier nets of lam^layer Phi for every lam in [La, Lb]: net[i][j] = (x, y), each a list of arb
    coefficients of a polynomial in zeta in [-1, 1] (lam = (La + Lb)/2 + zeta (Lb - La)/2), from the
    table's exact B-spline forms (see :func:`entry_model`).

    Parameters
    ----------
    exact : dict[str, 4 x 4 of ([A, B, D], [A, B, D])]
        :meth:`.statement.Derivation.integer_forms` of the B-spline nets.

    Examples
    --------
    On the one-point interval lam = 1/2 (k = 4) the net is the identity's, (1/2 + i/6, j/6) on P1:

    >>> from ccproof.certify.verify.statement import derivation
    >>> exact, h = derivation().integer_forms(), fmpq(1, 2)    # the one-point interval lam = 1/2: k = 4
    >>> zn = {i: parameter_nets(exact, h, h, i, 2, 64) for i in (0, 1)}
    >>> [z[0].str(6, radius=False) for z in zn[0]["P1"][1][1]]
    ['0.666667', '0.166667']
    """
    L = fmpq_poly([(La + Lb) / 2, (Lb - La) / 2])
    out = {}
    with ctx.workprec(prec):
        for name in PATCHES:
            bs = [[[entry_model(f, L, layer, degree, prec) for f in pt] for pt in row] for row in exact[name]]
            out[name] = [[tuple([sum((bs[i][j][d][e] * B2Z[a][i] * B2Z[b][j] for i in range(4) for j in range(4)),
                                     arb(0)) / 36 for e in range(degree + 1)] for d in range(2))
                          for b in range(4)] for a in range(4)]
    return out


def hull_nets(znets, prec):
    """arb nets enclosing the zeta-polynomial nets for every zeta in [-1, 1] (Bernstein range).

    Examples
    --------
    >>> from ccproof.certify.verify.statement import derivation
    >>> exact, h = derivation().integer_forms(), fmpq(1, 2)    # the one-point interval lam = 1/2: k = 4
    >>> zn = {i: parameter_nets(exact, h, h, i, 2, 64) for i in (0, 1)}
    >>> x, y = hull_nets(zn[0], 64)["P1"][1][1]
    >>> x.overlaps(arb(2) / 3), y.overlaps(arb(1) / 6)
    (True, True)
    """
    def hull(co):
        lo, hi = range_enclosure(_bern1(co, prec))
        return lo.union(hi)
    return {n: [[tuple(hull(co) for co in pt) for pt in row] for row in net] for n, net in znets.items()}


def cell_maps_z(znets, N, l, m, D, prec):
    """(X, Y) = lam^i Phi on cell (l, m) as Bernstein forms on ZBOX in (zeta, s, t): the Taylor models in zeta
    (truncated to degree D) of the nets restricted to the cell, converted.

    Parameters
    ----------
    znets : dict[int, nets of :func:`parameter_nets`]
        By layer.

    Examples
    --------
    Cell (1, 0) of level 1 is piece P1 of layer 0, where Phi(s, t) = (1/2 + s/2, t/2) at k = 4:

    >>> from ccproof.certify.verify.statement import derivation
    >>> exact, h = derivation().integer_forms(), fmpq(1, 2)    # the one-point interval lam = 1/2: k = 4
    >>> zn = {i: parameter_nets(exact, h, h, i, 2, 64) for i in (0, 1)}
    >>> [[z.str(6, radius=False) for z in range_enclosure(F)] for F in cell_maps_z(zn, 1, 1, 0, 2, 64)]
    [['0.500000', '1.00000'], ['0', '0.500000']]
    """
    i, name, box = cell_geometry(l, m, N)
    net = znets[i][name]
    n = len(net[0][0][0])
    out = []
    for d in range(2):
        co = []  # zeta^e blocks of the (s, t) Bernstein forms on the cell
        for e in range(n):
            co += net_form([[(pt[0][e], pt[1][e]) for pt in row] for row in net], d, prec, box).coeffs
        out.append(TaylorForm((n, 4, 4), co, prec).truncate(D).bernstein())
    return out


def piece_maps_z(znets, i, name, D, prec):
    """(X, Y) = lam^i Phi on piece ``name`` of layer i as TaylorForms in (zeta; sigma, tau): the Bezier
    net entries are the Bernstein coefficients in (sigma, tau), their zeta polynomials the Taylor part.

    Examples
    --------
    >>> from ccproof.certify.verify.statement import derivation
    >>> exact, h = derivation().integer_forms(), fmpq(1, 2)    # the one-point interval lam = 1/2: k = 4
    >>> zn = {i: parameter_nets(exact, h, h, i, 2, 64) for i in (0, 1)}
    >>> X, Y = piece_maps_z(zn, 0, "P1", 2, 64)
    >>> X.shape, [c.str(6, radius=False) for c in Y.coeffs[:4]]  # zeta^0 of y: ordinates 0, 1/6, 1/3, 1/2
    ((3, 4, 4), ['0', '0.166667', '0.333333', '0.500000'])
    """
    net = znets[i][name]
    m = len(net[0][0][0])
    return [TaylorForm(((m, 4, 4)), [net[a][b][d][e] for e in range(m) for a in range(4) for b in range(4)],
                       prec).truncate(D) for d in range(2)]


def piece_det_form_z(znets, i, name, p, q, D, prec):
    """Bernstein form on ZBOX of det dG/d(sigma, tau) on layer i of piece ``name`` for the w piece (p, q),
    every lam of the interval at once (Taylor model in zeta, truncated to degree D; one form for all the
    cells of that layer, piece and w piece: :func:`.maps.det_form` of :func:`piece_maps_z`).

    Examples
    --------
    At k = 4, Phi = y, so the blend G is y and det = 4^-(i+1):

    >>> from ccproof.certify.verify.statement import derivation
    >>> from ccproof.rigorous import range_enclosure
    >>> exact, h = derivation().integer_forms(), fmpq(1, 2)    # the one-point interval lam = 1/2: k = 4
    >>> zn = {i: parameter_nets(exact, h, h, i, 2, 64) for i in (0, 1)}
    >>> [z.str(6, radius=False) for z in range_enclosure(piece_det_form_z(zn, 0, "P1", 2, 2, 2, 64))]
    ['0.250000', '0.250000']
    """
    with ctx.workprec(prec):
        return det_form(*piece_maps_z(znets, i, name, D, prec), i, name, p, q, D)


def interval_cells(znets, N, D, prec, symmetric=False):
    """Part D for an interval: every (key, build root) with a w piece met by the Bernstein hull of the
    cell's image over all zeta; the root is det dG/d(s,t) in (zeta, s, t) on ZBOX: the form of its layer,
    piece and w piece (:func:`piece_det_form_z`) restricted to the cell's box, times h^2 (h a power of 2).

    Returns
    -------
    list of (str, callable () -> BernsteinForm)
        Keys ``"l,m,p,q"``.

    Examples
    --------
    For k = 4 at N = 1 (the cells :func:`valence_cells` gives at lam = 1/2):

    >>> from ccproof.certify.verify.statement import derivation
    >>> from ccproof.rigorous import range_enclosure
    >>> exact, h = derivation().integer_forms(), fmpq(1, 2)    # the one-point interval lam = 1/2: k = 4
    >>> zn = {i: parameter_nets(exact, h, h, i, 2, 64) for i in (0, 1)}
    >>> cells = interval_cells(zn, 1, 2, 64)
    >>> [key for key, _ in cells]
    ['0,1,0,2', '0,1,1,2', '0,1,2,2', '1,0,2,0', '1,0,2,1', '1,0,2,2', '1,1,2,2']
    >>> [z.str(6, radius=False) for z in range_enclosure(cells[-1][1]())]
    ['0.250000', '0.250000']
    """
    out = []
    forms = {}

    def build(l, m, p, q):
        i, name, box = cell_geometry(l, m, N)
        if (i, name, p, q) not in forms:
            forms[i, name, p, q] = piece_det_form_z(znets, i, name, p, q, D, prec)
        h = box[0][1] - box[0][0]
        with ctx.workprec(prec):
            return forms[i, name, p, q].restrict((ZBOX[0],) + box) * (h * h)

    with ctx.workprec(prec):
        for l, m in dyadic_cells(N, symmetric):
            for p, q in cell_pieces(*cell_maps_z(znets, N, l, m, D, prec)):
                if p < 3 and q < 3:
                    out.append((f"{l},{m},{p},{q}", lambda c=(l, m, p, q): build(*c)))
    return out


def lam_interval_ok(k0, La, Lb, prec):
    """[La, Lb] contains lam(k) for every k >= k0: La <= lam(k0) and Lb >= (3 + sqrt 5)/8 = lim lam
    (lam increases with c = cos(2 pi/k), which increases with k).

    Examples
    --------
    lam(5) = 0.5497..., lim lam = 0.6545... (docs/readings.md R2, R10):

    >>> [lam_interval_ok(5, La, Lb, 64) for La, Lb in ((fmpq(1, 2), fmpq(2, 3)), (fmpq(1, 2), fmpq(13, 20)),
    ...                                                (fmpq(14, 25), fmpq(2, 3)))]
    [True, False, False]
    """
    with ctx.workprec(prec):
        return bool(c_lam(k0, prec)[1] >= La) and bool((3 + arb(5).sqrt()) / 8 <= Lb)


def valence_cells(nets, lam, N, prec, symmetric=False):
    """Part D for one valence: :func:`interval_cells` of the arb nets as Taylor models of degree 0 in zeta
    (``lam^i`` times the nets on layer i), the zeta axis dropped from each root (the boxes of one valence split
    (s, t) only).

    Returns
    -------
    list of (str, callable () -> BernsteinForm)
        Keys ``"l,m,p,q"``; the roots on [0, 1]^2.

    Examples
    --------
    >>> from ccproof.certify.verify.statement import nets_for_valence
    >>> cells = valence_cells(nets_for_valence(4, 64), c_lam(4, 64)[1], 1, 64)   # k = 4: Phi is the identity
    >>> [key for key, _ in cells][:3], cells[-1][1]().box, cells[-1][1]().coeffs[0].str(6, radius=False)
    (['0,1,0,2', '0,1,1,2', '0,1,2,2'], ((0, 1), (0, 1)), '0.250000')
    """
    with ctx.workprec(prec):
        zn = {i: {n: [[tuple([x * lam**i] for x in pt) for pt in row] for row in net] for n, net in nets.items()}
              for i in range(N)}

    def flat(build):
        f = build()
        return BernsteinForm.from_raw(f.shape[1:], f.coeffs, f.box[1:], f.prec)

    return [(key, lambda b=build: flat(b)) for key, build in interval_cells(zn, N, 0, prec, symmetric)]
