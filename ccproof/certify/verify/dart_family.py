"""The characteristic map of ``dart:K``, every K >= K0, as one family analytic in h = 1/K (trusted): x, y and their
nets from the bordered Fourier systems (docs/tagged_c1.md, "Every dart K >= 101", item 6), h an acb ball or the
series variable; :class:`Modes` is shared with the exact family of :mod:`.dart_zeros`."""

from __future__ import annotations

from contextlib import contextmanager

from flint import acb, acb_mat, acb_poly, acb_series, arb, ctx, fmpq, fmpq_mat, fmpq_poly

from .errors import CertificateError
from .maps import STAR_CURVES, curve_points
from .rules import CENTRE
from .statement import B2Z, NET_OFFSETS, horner, lam_of
from .statement import PATCHES as PIECES
from .tagged import quadrant_level1
from .tagged_modes import RING_INDEX, bordered_matrix, bordered_solve, off_cut, ring_block, ring_stencil


def kappa():
    """The centre's weights in the six ring rows (exact)."""
    return [1 - sum(ring_stencil()[i].values()) for i in range(6)]


def adjugate(B):
    """adj(x - B) as a list of lists of fmpq_poly (Faddeev-LeVerrier, exact; Cayley-Hamilton checked)."""
    n = B.nrows()
    c = B.charpoly().coeffs()
    eye = fmpq_mat([[int(i == j) for j in range(n)] for i in range(n)])
    Ms = [eye]
    for k in range(1, n):
        Ms.append(B * Ms[-1] + c[n - k] * eye)
    if B * Ms[-1] + c[0] * eye != fmpq_mat(n, n):
        raise CertificateError("Cayley-Hamilton fails: the adjugate is wrong")
    return [[fmpq_poly([Ms[n - 1 - d][i, j] for d in range(n)]) for j in range(n)] for i in range(n)]


B_AT_1 = fmpq_mat(ring_block(fmpq(1)))  # B(1); N(lam) = adj(lam - B(1)) kappa as 6 coefficient lists (degree <= 5)
N_POLYS = [[sum((a[k][d] * x for k, x in enumerate(kappa())), fmpq(0)) for d in range(6)] for a in adjugate(B_AT_1)]


def l0():
    """L0 = lam(1) = (6 + sqrt 20)/16 and 1/(16 L0) = (6 - sqrt 20)/16 at the current precision."""
    r = arb(20).sqrt()
    return (6 + r) / 16, (6 - r) / 16


def u_denominator(lam, low):
    """(lam - 1/8)(lam - 1/16)(lam - 1/32)(lam - 1/64)(lam - low), low = 1/(16 L0) (of lam's type)."""
    return (lam - fmpq(1, 8)) * (lam - fmpq(1, 16)) * (lam - fmpq(1, 32)) * (lam - fmpq(1, 64)) * (lam - low)


def big_u(lam, low):
    """U(lam) = adj(lam - B(1)) kappa / :func:`u_denominator` (6 values of lam's type)."""
    den = u_denominator(lam, low)
    return [horner(p, lam, lam * 0) / den for p in N_POLYS]


@contextmanager
def series_variable(n):
    """Context: the series variable h to order n, ``ctx.cap`` >= n + 1 inside (flint truncates series to it)."""
    old = ctx.cap
    ctx.cap = max(old, n + 1)
    try:
        yield acb_series([0, 1], prec=n + 1)
    finally:
        ctx.cap = old


def series_coeffs(z, n, real=False):
    """The first n Taylor coefficients (acb; ``real``: their real parts) of a series, or of a value (its h^0)."""
    c = z.coeffs() if isinstance(z, acb_series) else [z]
    return [acb(c[i].real if real else c[i]) if i < len(c) else acb(0) for i in range(n)]


def bordered(w, lam, pivot=0):
    """v^: B(w) v^ = lam v^, v^[pivot] = 1 (the bordered system A v = e_7): on acb balls
    :func:`.tagged_modes.bordered_solve`; on series order by order, A_0 v_k = -sum_(j >= 1) A_j v_(k-j)."""
    if not isinstance(w, acb_series):
        return bordered_solve(ring_block(w), lam, pivot)
    A = bordered_matrix(ring_block(w), lam, w * 0, pivot)
    n = w.prec
    cs = [[series_coeffs(A[i][k], n) for k in range(7)] for i in range(7)]
    Ak = [acb_mat([[cs[i][k][m] for k in range(7)] for i in range(7)]) for m in range(n)]
    inv0 = Ak[0].inv()
    vs = [inv0 * acb_mat([[0]] * 6 + [[1]])]
    for m in range(1, n):
        vs.append(inv0 * sum((-(Ak[j] * vs[m - j]) for j in range(1, m + 1)), acb_mat(7, 1)))
    return [acb_series([vs[m][i, 0] for m in range(n)], prec=n) for i in range(6)]


def _mirror(d, pos):
    """The image of ring point (d, pos) under the reflection in ray 0: (-d, pos) on a ray, (-d - 1, (b, a)) else."""
    return (-d, pos) if pos[1] == 0 else (-d - 1, (pos[1], pos[0]))


class Modes:
    """x = E X+ + E^-1 X-, y = Y0 + F Y+ + F^-1 Y- (E = e^(2 pi i s), F = e^(i sigma (2 s - 1))) from vx, vy, U,
    lam1, lam2, zero, i2 = 2i, sign, em, ep = e^(-+ i sigma) and ``e(c, k)`` = e^(i k a h) ("x"), e^(i k b h) ("y");
    no Re or Im (the conjugate of a mode is the mode of 1/w with (a, b) swapped)."""

    def mode0(self, cos_sigma, L0, flip=False):
        """alpha from the sharp midpoint's row (-alpha with ``flip``, a control), y's centre yc = alpha (lam2 - L0)."""
        lam, half = self.lam2, self.lam2 - fmpq(1, 2)
        self.alpha = -(half * cos_sigma) / (half * self.U[0] - (lam - L0) / 2) * (-1 if flip else 1)
        self.yc = self.alpha * (lam - L0)

    def parts(self):
        """{X+, X-, Y0, Y+, Y-: (level0(delta, pos), centre, lam)}, level0 at sector K s + delta, position pos."""
        vx, vy, e, i2, z = self.vx, self.vy, self.e, self.i2, self.zero

        def mode(v, c, d, p):  # v^(p) e^(i k d h), k = a or b
            return v[RING_INDEX[p]] * e(c, d)
        return {
            "X+": (lambda d, p: mode(vx, "x", d, p) / i2, z, self.lam1),
            "X-": (lambda d, p: -mode(vx, "x", *_mirror(d, p)) / i2, z, self.lam1),
            "Y0": (lambda d, p: self.alpha * self.U[RING_INDEX[p]], self.yc, self.lam2),
            "Y+": (lambda d, p: mode(vy, "y", d, p) * self.sign / 2, z, self.lam2),
            "Y-": (lambda d, p: mode(vy, "y", *_mirror(d, p)) * self.sign / 2, z, self.lam2),
        }

    def layer_level0(self):
        """(x(t, p), y(t, p)) at integer sectors t of any sign (y reflected in ray 0 for t < 0)."""
        f = {name: part[0] for name, part in self.parts().items()}

        def y(t, pos):
            if t < 0:
                t, pos = _mirror(t, pos)
            return f["Y0"](t, pos) + (f["Y+"](t, pos) * self.em + f["Y-"](t, pos) * self.ep) * self.sign
        return (lambda t, pos: f["X+"](t, pos) + f["X-"](t, pos)), y

    def layer_nets(self, q, coordinate):
        """{piece: 4 x 4 Bezier net} of x (coordinate 0) or y (1) on layer quadrant q."""
        return piece_nets(self.layer_level0()[coordinate], (self.zero, self.yc)[coordinate],
                          (self.lam1, self.lam2)[coordinate], self.zero, q)


class Family(Modes):
    """x and y of dart:K at one h (acb, or the series variable) and sigma (arb); controls: ``flip_mode0``
    (alpha -> -alpha), ``smooth`` (alpha = 0, the smooth valence's mode-1 cosine at sigma = pi)."""

    def __init__(self, h, sigma, flip_mode0=False, smooth=False):
        self.h, self.sigma = h, sigma
        pi = arb.pi()
        self.zero, self.i2 = h * 0, acb(0, 2)
        self.ix, self.iy = acb(0, 2) * pi, acb(0, 2) * sigma   # w_x = e^(ix h), w_y = e^(iy h)
        self.em, self.ep = (acb(0, -1) * sigma).exp(), (acb(0, 1) * sigma).exp()
        self.lam1, self.lam2 = (lam_of(off_cut((h * (2 * a)).cos())) for a in (pi, sigma))
        self.vx, self.vy = bordered((h * self.ix).exp(), self.lam1), bordered((h * self.iy).exp(), self.lam2)
        L0, low = l0()
        self.U = big_u(self.lam2, low)
        self.mode0(sigma.cos(), L0, flip_mode0)
        self.sign = 1
        if smooth:
            self.alpha, self.yc, self.sign = self.zero, self.zero, -1
        self._exp = {}

    def e(self, c, k):
        """e^(i k a h) (c = "x") or e^(i k b h) (c = "y"), memoized."""
        if (c, k) not in self._exp:
            self._exp[(c, k)] = (self.h * ((self.ix if c == "x" else self.iy) * k)).exp()
        return self._exp[(c, k)]


def _bezier(net, zero):
    """4 x 4 B-spline control values -> Bezier (any ring): ``B2Z`` both ways, one division by 36."""
    tmp = [[sum((net[r][j] * c for r, c in enumerate(B2Z[i]) if c), zero) for j in range(4)] for i in range(4)]
    return [[sum((tmp[i][r] * c for r, c in enumerate(B2Z[j]) if c), zero) / 36 for j in range(4)]
            for i in range(4)]


def piece_nets(level0, centre, lam, zero, q=None):
    """{piece: 4 x 4 Bezier net} of one coordinate or basis part (:func:`.tagged.quadrant_level1`: lam times level 0
    on the two-ring, an eigenvector's level 1): ``q`` None a bulk quadrant (``level0(delta, pos)``, no sharp ray),
    else layer quadrant q (``level0(t, pos)``, ray 0 sharp)."""
    V = quadrant_level1(q or 0, (lambda s: False) if q is None else (lambda s: s == 0), lam * centre,
                        lambda s, p: lam * level0(s, p), lambda s, p: centre if p == CENTRE else level0(s, p), zero)
    return {name: _bezier([[V(NET_OFFSETS[name][0] + i, NET_OFFSETS[name][1] + j) for j in range(4)]
                           for i in range(4)], zero) for name in PIECES}


XB, YB = ("X+", "X-"), ("Y0", "Y+", "Y-")
_SU, _SH = 6, 36  # Kronecker strides: a product of bicubic partials has degree <= 5 in u and in v
_BIN = ((1,), (1, 1), (1, 2, 1), (1, 3, 3, 1), (1, 4, 6, 4, 1), (1, 5, 10, 10, 5, 1))  # C(d, i)


def _packed(nets, axis, stride=_SH):
    """One acb_poly: each h^m coefficient net's (4 x 4, 1 x 4 or 1 x 1) partial along ``axis`` (0: u, 1: v; None:
    the net) times its binomial weights, at x^(m stride + i _SU + j) (Kronecker packing of (h, u, v))."""
    coeffs = [acb(0)] * (stride * len(nets))
    for m, net in enumerate(nets):
        rows, cols = len(net) - (axis == 0), len(net[0]) - (axis == 1)
        for i in range(rows):
            for j in range(cols):
                d = net[i + 1][j] - net[i][j] if axis == 0 else net[i][j + 1] - net[i][j] if axis == 1 else net[i][j]
                w = (1 if axis is None else 3) * _BIN[rows - 1][i] * _BIN[cols - 1][j]
                coeffs[m * stride + i * _SU + j] = w * acb(d)
    return acb_poly(coeffs)


def _unpacked(P, n, stride, rows):
    """The h^m coefficients, m <= n, of a packed product of degree 5 (``rows`` 6: in u, v; 1: a curve)."""
    c = P.coeffs()
    c += [acb(0)] * max(0, stride * (n + 1) - len(c))
    return [[c[m * stride + i * _SU + j] / (_BIN[5][i] * _BIN[5][j]) for i in range(rows) for j in range(6)]
            for m in range(n + 1)]


def packed_partials(nets):
    """(u-partial, v-partial) of a net's h^m coefficient nets, packed once for :func:`det_series`."""
    return _packed(nets, 0), _packed(nets, 1)


def det_series(A, B, n):
    """[m <= n: D(A, B)'s 36 Bernstein coefficients (degree (5, 5), row-major)], D = A_u B_v - A_v B_u, of nets
    given by their h^m coefficient nets or :func:`packed_partials`: one polynomial product (scaled Bernstein
    coefficients of a product convolve)."""
    (Au, Av), (Bu, Bv) = (X if isinstance(X, tuple) else packed_partials(X) for X in (A, B))
    return _unpacked(Au * Bv - Av * Bu, n, _SH, 6)


def basis_nets(fam):
    """{basis part: {piece: 4 x 4 net}} of the family's five basis parts."""
    return {name: piece_nets(f, c, lam, fam.zero) for name, (f, c, lam) in fam.parts().items()}


def layer_nets(fam, q):
    """{piece: (X net, Y net)} (4 x 4 Bezier, values of fam.h's type) of layer quadrant q."""
    X, Y = fam.layer_nets(q, 0), fam.layer_nets(q, 1)
    return {name: (X[name], Y[name]) for name in PIECES}


def bezier_product(f, g):
    """Bernstein coefficients (degree 5) of f g' for cubic Bezier values f, g (any ring)."""
    gd = [3 * (g[i + 1] - g[i]) for i in range(3)]
    return [sum((f[i] * gd[k - i] * fmpq(_BIN[3][i] * _BIN[2][k - i], _BIN[5][k])
                 for i in range(max(0, k - 2), min(3, k) + 1)), 0 * f[0]) for k in range(6)]


def coefficient_nets(zs, n, real=False):
    """[the h^m Taylor coefficients (acb) of every entry of a list, or list of lists, of series or values, m <= n]."""
    if not isinstance(zs, list):
        return series_coeffs(zs, n + 1, real)
    cols = [coefficient_nets(z, n, real) for z in zs]
    return [[c[m] for c in cols] for m in range(n + 1)]


def series_curves(nets, n, real=False):
    """{curve: [order m: 4 acb]} of one coordinate's nets {piece: 4 x 4 series or values}."""
    return {name: coefficient_nets(curve_points(nets, name, oriented=True), n, real) for name in STAR_CURVES}


def curve_trans_series(xc, yc, A1, A2, n):
    """[m <= n: the 6 Bernstein coefficients of a1 X Y' - a2 Y X'] from the curves' (xc, yc: [m: 4 values]) and
    a_i's Taylor coefficients, as packed acb_poly products (stride 6)."""
    a1, a2 = (_packed([[[z]] for z in A[:n + 1]], None, 6) for A in (A1, A2))
    X, Y = ([[pts] for pts in c] for c in (xc, yc))
    P = a1 * (_packed(X, None, 6) * _packed(Y, 1, 6)) - a2 * (_packed(Y, None, 6) * _packed(X, 1, 6))
    return _unpacked(P, n, 6, 1)
