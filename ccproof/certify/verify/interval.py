"""Every valence k >= k0 in one certificate (trusted): on a lam piece lam = mid + zeta * half-width, the nets as
Taylor models in zeta with exact remainders, their hulls and the cells of part D (docs/appendix_a.md section 6).

On the one-point piece lam = 1/2 (k = 4: Phi the identity, det dG/d(s, t) = 1/4 on a cell of layer 0):

>>> h = fmpq(1, 2)
>>> zn = {i: parameter_nets(derivation().integer_forms(), h, h, i, 2, 64) for i in (0, 1)}
>>> [z.str(6, radius=False) for z in hull_nets(zn[0], 64)["P1"][1][1]]        # P1's Bezier point (2/3, 1/6)
['0.666667', '0.166667']
>>> cells = interval_cells(zn, 1, 2, 64)
>>> [key for key, _ in cells], [z.str(6, radius=False) for z in range_enclosure(cells[-1][1]())]
(['0,1,0,2', '0,1,1,2', '0,1,2,2', '1,0,2,0', '1,0,2,1', '1,0,2,2', '1,1,2,2'], ['0.250000', '0.250000'])
>>> one = valence_cells(nets_for_valence(4, 64), c_lam(4, 64)[1], 1, 64)
>>> [key for key, _ in one] == [key for key, _ in cells], one[-1][1]().box
(True, ((0, 1), (0, 1)))
"""

from flint import arb, ctx, fmpq, fmpq_poly

from ccproof.rigorous import BernsteinForm, TaylorForm, conversion_matrix, range_enclosure
from ccproof.rigorous.tensor import apply_along_axis

from .errors import CertificateError
from .maps import cell_geometry, cell_pieces, det_form
from .statement import PATCHES, bspline_to_bezier, c_lam, derivation, entrywise, nets_for_valence  # noqa: F401 (the examples)

ZBOX = ((fmpq(-1), fmpq(1)), (fmpq(0), fmpq(1)), (fmpq(0), fmpq(1)))  # (zeta, s, t) of part D


def _bern1(p, prec=None):
    """Bernstein coefficients on zeta in [-1, 1] of an fmpq_poly (or a list of arb coefficients)."""
    c = [p[i] for i in range(max(1, p.degree() + 1))] if isinstance(p, fmpq_poly) else list(p)
    return apply_along_axis(c, (len(c),), 0, conversion_matrix(len(c) - 1, len(c) - 1, *ZBOX[0]), prec)[0]


def entry_model(form, L, layer, degree, prec):
    """lam^layer (A(c) + B(c) lam)/D(c), lam = L(zeta), c = (16 lam^2 - 10 lam + 1)/(2 lam), as the arb Taylor
    coefficients of T + [-r, r] (T exact to ``degree``, r = max|Bernstein coefficients of num - den T| /
    min|those of den|, den of one strict sign).

    >>> L = fmpq_poly([fmpq(1, 2), fmpq(1, 10)])      # lam^2 = 1/4 + zeta/10 + zeta^2/100; degree 1: r = 1/100
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
    """Bezier nets of lam^layer Phi for every lam in [La, Lb]: net[i][j] = (x, y), each the arb coefficients of a
    polynomial in zeta (:func:`entry_model` of the B-spline forms ``exact``: ``Derivation.integer_forms``)."""
    L, m = fmpq_poly([(La + Lb) / 2, (Lb - La) / 2]), degree + 1
    out = {}
    with ctx.workprec(prec):
        for name in PATCHES:  # (x, y) as one vector of 2m coefficients through the B-spline -> Bezier map
            bs = [[[c for f in pt for c in entry_model(f, L, layer, degree, prec)] for pt in row]
                  for row in exact[name]]
            out[name] = [[(list(p[:m]), list(p[m:])) for p in row] for row in bspline_to_bezier(bs, [arb(0)] * 2 * m)]
    return out


def hull_nets(znets, prec):
    """arb nets enclosing the zeta-polynomial nets for every zeta in [-1, 1] (Bernstein range)."""
    return entrywise(znets, lambda co: arb.union(*range_enclosure(_bern1(co, prec))))


def piece_det_form_z(znets, i, name, p, q, D, prec):
    """det dG/d(sigma, tau) on ZBOX for layer i, piece ``name``, w piece (p, q), every lam of the piece at once:
    :func:`.maps.det_form` of the Taylor models (the net entries' Bernstein coefficients in (sigma, tau), their
    zeta polynomials the Taylor part, truncated to degree D)."""
    return det_form(*(_taylor(znets[i][name], d, prec).truncate(D) for d in range(2)), i, name, p, q, D)


def _taylor(net, d, prec):
    """Coordinate d of a net of zeta polynomials as a Taylor model in (zeta; sigma, tau)."""
    m = len(net[0][0][0])
    return TaylorForm((m, 4, 4), [net[a][b][d][e] for e in range(m) for a in range(4) for b in range(4)], prec)


def interval_cells(znets, N, D, prec, symmetric=False):
    """Part D: (key ``"l,m,p,q"``, build root) for every cell (l, m) != (0, 0) of level N (l <= m if ``symmetric``)
    and w piece met by the hull of its image over all zeta; the root is :func:`piece_det_form_z` of its layer,
    piece and w piece restricted to the cell's box, times h^2 (h a power of 2)."""
    out, forms = [], {}

    def build(l, m, p, q):
        i, name, box = cell_geometry(l, m, N)
        if (i, name, p, q) not in forms:
            forms[i, name, p, q] = piece_det_form_z(znets, i, name, p, q, D, prec)
        h = box[0][1] - box[0][0]
        return forms[i, name, p, q].restrict((ZBOX[0],) + box) * (h * h)  # the forms round at their own prec

    with ctx.workprec(prec):
        cells = [(l, m) for l in range(2**N) for m in range(2**N) if (l, m) != (0, 0) and not (symmetric and l > m)]
        for l, m in cells:
            out += [(f"{l},{m},{p},{q}", lambda c=(l, m, p, q): build(*c))
                    for p, q in cell_pieces(*_cell_maps(znets, N, l, m, D, prec)) if p < 3 and q < 3]
    return out


def _cell_maps(znets, N, l, m, D, prec):
    """(X, Y) = lam^i Phi on cell (l, m) as Bernstein forms on ZBOX in (zeta, s, t)."""
    i, name, box = cell_geometry(l, m, N)
    return [_taylor(znets[i][name], d, prec).restrict((ZBOX[0],) + box).truncate(D).bernstein() for d in range(2)]


def lam_interval_ok(k0, La, Lb, prec):
    """[La, Lb] holds lam(k) for every k >= k0: La <= lam(k0), Lb >= (3 + sqrt 5)/8 = lim lam (lam increases with k).

    >>> [lam_interval_ok(5, fmpq(*a), fmpq(*b), 64) for a, b in (((1, 2), (2, 3)), ((1, 2), (13, 20)),
    ...                                                          ((14, 25), (2, 3)))]
    [True, False, False]
    """
    with ctx.workprec(prec):
        return bool(c_lam(k0, prec)[1] >= La) and bool((3 + arb(5).sqrt()) / 8 <= Lb)


def valence_cells(nets, lam, N, prec, symmetric=False):
    """Part D for one valence: :func:`interval_cells` of the arb nets times lam^i as Taylor models of degree 0, the
    zeta axis dropped from each root."""
    with ctx.workprec(prec):
        zn = {i: entrywise(nets, lambda x, i=i: [x * lam**i]) for i in range(N)}

    def flat(build):
        f = build()
        return BernsteinForm.from_raw(f.shape[1:], f.coeffs, f.box[1:], f.prec)

    return [(key, lambda b=build: flat(b)) for key, build in interval_cells(zn, N, 0, prec, symmetric)]
