"""The Taylor coefficients the dart family's models drop, computed exactly and checked 0 (trusted): the rows, the
degree argument (a grid of (a, b, c, t, l) suffices for every sigma) and the arithmetic (Q(sqrt 5, i)[h]/(h^3) as
Q[x]/(m^3), m = x^4 - 8 x^2 + 36) are docs/tagged_c1.md, "Every dart K >= 101", item 6."""

from __future__ import annotations

import itertools
from functools import cache

from flint import fmpq, fmpq_mat, fmpq_poly

from . import dart_family as _df
from .dart_family import PIECES, XB, YB
from .errors import CertificateError
from .maps import STAR_CURVES, curve_points
from .tagged_modes import RING_INDEX, bordered_matrix, ring_stencil

GRID_AB = (1, 2, 3)  # degree <= 2 in a and in b
GRID_CT = (1, 2)  # degree <= 1 in c, t, l

ROWS = ("bulk det: D_ij h^0", "middle det: e_10, e_11, e_20", "bulk T: T_ij h^0", "middle T: e_10, e_11, e_20",
        "W middle: Y(s = h = 0)", "layer det: h^0, h^1, h^2", "layer T: h^0, h^1, h^2",
        "W layer: Y h^0 (h^1 at ray 0's end)")

# --- Q(sqrt 5, i)[h]/(h^3) as Q[x]/(m^3) ---------------------------------------------------------------------

_X = fmpq_poly([0, 1])
_MOD = [fmpq_poly([1]), _X ** 4 - 8 * _X ** 2 + 36]  # m^0, m, m^2, m^3: h^k divides exactly when m^k does
_MOD += [_MOD[1] ** 2, _MOD[1] ** 3]
_M3 = _MOD[3]


def _inv_raw(p):
    s = p.xgcd(_M3)[1] % _M3
    if (s * p) % _M3 != 1:
        raise ZeroDivisionError("not a unit of Q(sqrt 5, i)[h]/(h^3)")
    return s


_TH = _X  # theta~, the root of m in Q[x]/(m^3) lifting x (Newton: m(th) = 0 mod m^2, then mod m^4)
for _ in range(2):
    _TH = (_TH - _MOD[1](_TH) * _inv_raw(_MOD[1].derivative()(_TH) % _M3)) % _M3
if not (_MOD[1](_TH) % _M3).is_zero() or not ((_TH - _X) % _MOD[1]).is_zero():
    raise AssertionError("theta~ is not the root of m in Q[x]/(m^3) lifting x")


def _raw(z):
    return z.p if isinstance(z, QS) else fmpq_poly([fmpq(z)])


class QS:
    """A power series in h to h^2 over Q(sqrt 5, i), exact: the class of the fmpq_poly ``p`` in Q[x]/(m^3).

    >>> e = QS(1) + I * 3 * H - H * H * fmpq(9, 2)  # e^(3 i h) to order 2
    >>> (e * (QS(1) - I * 3 * H - H * H * fmpq(9, 2)) - 1).is_zero(), (e - 1).vanishes(1), (e - 1).vanishes(2)
    (True, True, False)
    """

    __slots__ = ("p",)

    def __init__(self, p=0):
        self.p = p if isinstance(p, fmpq_poly) else fmpq_poly([fmpq(p)])

    def __add__(self, o):
        return QS(self.p + _raw(o))

    __radd__ = __add__

    def __sub__(self, o):
        return QS(self.p - _raw(o))

    def __rsub__(self, o):
        return QS(_raw(o) - self.p)

    def __neg__(self):
        return QS(-self.p)

    def __mul__(self, o):
        if isinstance(o, QS):
            return QS((self.p * o.p) % _M3)
        return QS(self.p * fmpq(o))

    __rmul__ = __mul__

    def __truediv__(self, o):
        return QS((self.p * _inv_raw(o.p)) % _M3) if isinstance(o, QS) else QS(self.p / fmpq(o))

    def is_zero(self):
        return self.p.is_zero()

    def vanishes(self, k):
        """True iff the coefficients of h^0 .. h^(k-1) are all 0."""
        return (self.p % _MOD[k]).is_zero()

    def coeffs(self):
        """[e_0, e_1, e_2]: the coefficients of h^0, h^1, h^2 as polynomials in theta (degree < 4)."""
        return _h_coeffs(self.p)


def _h_coeffs(p):
    out, r = [], p
    for k in range(3):
        e = r % _MOD[1]
        out.append(e)
        if k < 2:
            r, rem = divmod((r - e(_TH)) % _MOD[3 - k], _MOD[1])
            if not rem.is_zero():
                raise AssertionError("h-coefficients: not divisible by h")
    return out


ONE = QS(1)
H = QS(_MOD[1])  # h
I = QS(((_TH ** 3 - 2 * _TH) / 12) % _M3)  # i = (theta^3 - 2 theta)/12
SQRT20 = (QS(_TH) - I) * 2  # 2 sqrt 5
if not ((I * I + 1).is_zero() and (SQRT20 * SQRT20 - 20).is_zero() and (H * H * H).is_zero()):
    raise AssertionError("i, sqrt 5, h in Q[x]/(m^3)")
L0 = (SQRT20 + 6) / 16  # lam(1), the root of 16 x^2 - 12 x + 1 with the + sign
L0_LOW = (6 - SQRT20) / 16  # 1/(16 L0)
_IH, _H2 = I * H, H * H


@cache
def _exp_i(k):
    """e^(i k h) = 1 + i k h - k^2 h^2/2 (k an fmpq; memoized, QS is never changed in place)."""
    return ONE + _IH * k - _H2 * (k * k / 2)


def _lam_series(k):
    """lam(cos(k h)), c = 1 - k^2 h^2/2, the root expanded at 20."""
    c = ONE - _H2 * (fmpq(k) ** 2 / 2)
    g = (c + 1) * (c + 9)
    z = g / 20 - 1
    root = SQRT20 * (ONE + z / 2 - z * z / 8)
    if not z.vanishes(1) or not (root * root - g).is_zero():
        raise CertificateError("sqrt((1 + c)(9 + c)) at h = 0 is not 2 sqrt 5")
    return (c + 5 + root) / 16


def _log_ratio(lam):
    """ln(lam/L0) = z - z^2/2, z = lam/L0 - 1 in (h)."""
    z = lam / L0 - 1
    if not z.vanishes(1):
        raise CertificateError("lam(0) != L0")
    return z - z * z / 2


def solve(A, b):
    """v with A v = b over Q[x]/(m^3) (12-dimensional over Q): A as the rational matrix of its multiplications,
    solved by fmpq_mat (exact; ZeroDivisionError unless A(h = 0) is regular)."""
    n = len(A)
    cols = [[[(z.p * _X ** k) % _M3 for k in range(12)] for z in row] for row in A]
    M = fmpq_mat([[cols[i][j][k][r] for j in range(n) for k in range(12)] for i in range(n) for r in range(12)])
    v = M.solve(fmpq_mat([[(z.p % _M3)[r]] for z in b for r in range(12)]))
    return [QS(fmpq_poly([v[12 * i + r, 0] for r in range(12)])) for i in range(n)]


def _mode(k, stencil):
    """(lam(cos(k h)), v^, U(lam)) for one angle unit k: B(e^(i k h)) v^ = lam v^, v^(1,0) = 1 (bordered)."""
    lam, B = _lam_series(k), [[QS(0)] * 6 for _ in range(6)]
    for i, row in enumerate(stencil):
        for (d, pos), x in row.items():
            B[i][RING_INDEX[pos]] += _exp_i(fmpq(k) * d) * fmpq(x)
    v = solve(bordered_matrix(B, lam, QS(0), 0), [QS(0)] * 6 + [ONE])[:6]
    return lam, v, _df.big_u(lam, L0_LOW)


class ExactFamily(_df.Modes):
    """The family of :class:`.dart_family.Family` at a grid point (a, b, c, t) (stand-ins for 2 pi, 2 sigma,
    cos sigma, sin sigma), exact; ``stencil``, ``flip_alpha``: perturbations for the tests.

    >>> fam = ExactFamily(1, 2, 1, 2)
    >>> (fam.vx[0] - 1).is_zero(), (fam.lam1 - L0).vanishes(2), fam.yc.vanishes(2)  # the pivot, no h^1 terms
    (True, True, True)
    """

    def __init__(self, a, b, c, t, stencil=None, flip_alpha=False, _modes=None):
        stencil = ring_stencil() if stencil is None else stencil
        self.a, self.b, self.c, self.t = fmpq(a), fmpq(b), fmpq(c), fmpq(t)
        (self.lam1, self.vx, _), (self.lam2, self.vy, self.U) = _modes or (_mode(a, stencil), _mode(b, stencil))
        self.mode0(self.c, L0, flip_alpha)
        self.em, self.ep = QS(self.c) - I * self.t, QS(self.c) + I * self.t  # e^(-i sigma), e^(i sigma)
        self.zero, self.i2, self.sign = QS(0), I * 2, 1

    def e(self, c, k):
        """e^(i k a h) (c = "x") or e^(i k b h) (c = "y"), exact."""
        return _exp_i((self.a if c == "x" else self.b) * k)


# --- det J as a polynomial in the patch parameters (u, v), on the 6 x 6 grid; raw fmpq_poly below -------

_GRID = [fmpq(k, 5) for k in range(6)]
_BERN = [[(1 - u) ** 3, 3 * u * (1 - u) ** 2, 3 * u * u * (1 - u), u ** 3] for u in _GRID]
_DBERN = [[-3 * (1 - u) ** 2, 3 * (1 - u) ** 2 - 6 * u * (1 - u), 6 * u * (1 - u) - 3 * u * u, 3 * u * u]
          for u in _GRID]
_UV = "(u, v) in {0, 1/5, .., 1}^2 (row-major)"
_MID = "(S: e_10, e_20; S': e_11) alternating per " + _UV
_COEF = "the 6 Bernstein coefficients per l"


def _lin(ps, ws):
    return sum((p * w for p, w in zip(ps, ws) if w != 0), fmpq_poly([0]))


def _partials(net):
    """[(X_u, X_v) at each (u, v) of the grid] (raw) of a 4 x 4 Bezier net of QS (tensor-product sums)."""
    cols = [[net[i][j].p for i in range(4)] for j in range(4)]
    bu = [[_lin(cols[j], _BERN[u]) for j in range(4)] for u in range(6)]
    du = [[_lin(cols[j], _DBERN[u]) for j in range(4)] for u in range(6)]
    return [(_lin(du[u], _BERN[v]), _lin(bu[u], _DBERN[v])) for u in range(6) for v in range(6)]


def _det(px, py):
    """[X_u Y_v - X_v Y_u at each (u, v)] (raw, reduced)."""
    return [(xu * yv - xv * yu) % _M3 for (xu, xv), (yu, yv) in zip(px, py)]


class _Tally(dict):
    """{row: [checked, non-zero]}; with ``stop`` the first non-zero coefficient raises CertificateError."""

    def __init__(self, stop):
        super().__init__((row, [0, 0]) for row in ROWS)
        self.stop = stop

    def add(self, row, items, where, kind, orders=None):
        """items: raw elements whose h-orders ``orders`` must be 0 (None: (element, orders) pairs) at ``where``,
        numbered as ``kind``."""
        for k, item in enumerate(items):
            p, ords = item if orders is None else (item, orders)
            self[row][0] += len(ords)
            if (p % _MOD[max(ords) + 1]).is_zero():
                continue
            cs = _h_coeffs(p % _M3)
            bad = [m for m in ords if not cs[m].is_zero()]
            self[row][1] += len(bad)
            if bad and self.stop:
                raise CertificateError(f"dropped coefficient not 0: row '{row}', h^{bad[0]} coefficient "
                                       f"at {where}, item {k} of {kind}")


def _xy(xs, ys):
    """(X Y', Y X'): the degree-5 Bernstein coefficients (raw, reduced) from the curves' cubic Bezier points."""
    xs, ys = [z.p for z in xs], [z.p for z in ys]
    return [z % _M3 for z in _df.bezier_product(xs, ys)], [z % _M3 for z in _df.bezier_product(ys, xs)]


def _trans(PQ, A):
    """a1 X Y' - a2 Y X' (raw; the Bernstein coefficients, for every l one after the other)."""
    return [(a1 * p - a2 * q) % _M3 for a1, a2 in A for p, q in zip(*PQ)]


def _middle(G, fam):
    """The middle's items from {(i, j): [raw G_ij per place]}: e_10, e_20 = h^1, h^2 of S = sum c_ij G_ij, e_11
    = h^1 of S' = sum c_ij i omega_ij G_ij (a_i b_j = c_ij e^(i omega_ij s)); (S, (1, 2)), (S', (1,)) per place."""
    cj = {"Y0": (ONE, 0), "Y+": (fam.em, fam.b), "Y-": (fam.ep, -fam.b)}
    om = {"X+": fam.a, "X-": -fam.a}
    f = {(i, j): (cj[j][0].p, (cj[j][0] * I * (om[i] + cj[j][1])).p) for i, j in G}  # the weights of S and S'
    return [(sum((f[ij][d] * vals[k] for ij, vals in G.items()), fmpq_poly([0])), ((1, 2), (1,))[d])
            for k in range(len(next(iter(G.values())))) for d in (0, 1)]


def _nets(memo, key, make):
    """(nets, their partials) {piece: ...} under ``key``, made once."""
    if key not in memo:
        n = make()
        memo[key] = (n, {p: _partials(n[p]) for p in PIECES})
    return memo[key]


def _check_bulk(fam, A, tally, memo, pt):
    """The bulk's D_ij and T_ij at h^0, the middle's e_10, e_11, e_20 of K det J_Phi per piece and of
    K (a1 X Y' - a2 Y X') per outer curve, and Y at s = h = 0."""
    keys = {n: (n, fam.a) for n in XB} | {"Y0": ("Y0", fam.b, fam.c), "Y+": ("Y+", fam.b), "Y-": ("Y-", fam.b)}
    nets, part = {}, {}
    for name, key in keys.items():  # X's nets depend on a only, Y+-'s on b, Y0's on (b, c)
        nets[name], part[name] = _nets(memo, key, lambda name=name: _df.piece_nets(*fam.parts()[name], fam.zero))
    for piece in PIECES:
        G = {(i, j): _det(part[i][piece], part[j][piece]) for i in XB for j in YB}
        for (i, j), vals in G.items():
            tally.add(ROWS[0], vals, f"{pt}, {piece}, D({i}, {j})", _UV, (0,))
        tally.add(ROWS[1], _middle(G, fam), f"{pt}, {piece}", _MID)
    for curve in STAR_CURVES:
        pts, G = {n: curve_points(nets[n], curve, oriented=True) for n in nets}, {}
        for i, j in itertools.product(XB, YB):  # X Y', Y X' depend on (a, b) or (a, b, c) only
            if (keys[i], keys[j], curve) not in memo:
                memo[(keys[i], keys[j], curve)] = _xy(pts[i], pts[j])
            G[(i, j)] = _trans(memo[(keys[i], keys[j], curve)], A)
            tally.add(ROWS[2], G[(i, j)], f"{pt}, {curve}, T({i}, {j})", _COEF, (0,))
        tally.add(ROWS[3], _middle(G, fam), f"{pt}, {curve}", "(S, S') alternating per " + _COEF)
        tally.add(ROWS[4], [(pts["Y0"][p] + pts["Y+"][p] * fam.em + pts["Y-"][p] * fam.ep).p for p in range(4)],
                  f"{pt}, {curve}", "the 4 Bezier points", (0,))


def _check_layers(fam, A, tally, memo, pt):
    """On the layer quadrants q = 0, 1, 2: det J_Phi, the transversality and Y's curve points (h^0 .. h^2)."""
    for q in range(3):
        xn, xp = _nets(memo, ("LX", fam.a, q), lambda q=q: fam.layer_nets(q, 0))
        yn, yp = _nets(memo, ("LY", fam.b, fam.c, fam.t, q), lambda q=q: fam.layer_nets(q, 1))  # y: (b, c, t)
        for piece in PIECES:
            tally.add(ROWS[5], _det(xp[piece], yp[piece]), f"{pt}, q = {q}, {piece}", _UV, (0, 1, 2))
        for curve in STAR_CURVES:
            xs, ys = curve_points(xn, curve, oriented=True), curve_points(yn, curve, oriented=True)
            tally.add(ROWS[6], _trans(_xy(xs, ys), A), f"{pt}, q = {q}, {curve}", _COEF, (0, 1, 2))
            end = q == 0 and curve == "P1s1"  # ray 0's end point: h^1 too
            tally.add(ROWS[7], [(y.p, (0, 1) if end and k == 0 else (0,)) for k, y in enumerate(ys)],
                      f"{pt}, q = {q}, {curve}", "the 4 Bezier points")


def _run(points, ells, stencil, flip_alpha, stop):
    """Every dropped coefficient at the points (a, b, c, t) and l in ``ells``, into a :class:`_Tally`."""
    stencil = ring_stencil() if stencil is None else stencil
    tally, memo, mode = _Tally(stop), {}, cache(lambda k: _mode(k, stencil))
    for a, b, c, t in points:
        fam = ExactFamily(a, b, c, t, stencil, flip_alpha, _modes=(mode(a), mode(b)))
        A = [((-_log_ratio(fam.lam1) - ell).p, (-_log_ratio(fam.lam2) - ell).p) for ell in ells]  # -l - ln(lam/L0)
        pt = f"(a, b, c, t) = ({fam.a}, {fam.b}, {fam.c}, {fam.t})"
        _check_bulk(fam, A, tally, memo, pt)
        _check_layers(fam, A, tally, memo, pt)
    return tally


GRID = tuple(itertools.product(GRID_AB, GRID_AB, GRID_CT, GRID_CT))  # (a, b, c, t); l runs over GRID_CT


def count_zeros(points=GRID, ells=GRID_CT, stencil=None, flip_alpha=False):
    """{row: (coefficients checked, non-zero among them)} at the points (a, b, c, t) and l in ``ells``;
    ``stencil`` and ``flip_alpha`` perturb the rule or the family.

    >>> res = count_zeros(points=[(1, 2, 1, 2)])
    >>> res["bulk det: D_ij h^0"], sum(n for n, _ in res.values()), sum(bad for _, bad in res.values())
    ((648, 0), 2873, 0)
    """
    return {row: tuple(v) for row, v in _run(points, ells, stencil, flip_alpha, stop=False).items()}


def check_zeros(*, _stencil=None, _flip_alpha=False) -> str:
    """Every dropped coefficient exactly 0 on the grid: one line with the counts per row, or CertificateError
    naming the row, grid point and place of the first non-zero one (``_stencil``, ``_flip_alpha``: for tests).

    >>> print(check_zeros())
    dropped coefficients exactly 0 on the grid a, b in (1, 2, 3), c, t, l in (1, 2): ... 103428 in all
    """
    rows = _run(GRID, GRID_CT, _stencil, _flip_alpha, stop=True)
    if not all(n > 0 for n, _ in rows.values()):
        raise CertificateError("a row of dropped coefficients checked nothing")
    return (f"dropped coefficients exactly 0 on the grid a, b in {GRID_AB}, c, t, l in {GRID_CT}: "
            + "; ".join(f"{row} {n}" for row, (n, _) in rows.items())
            + f"; {sum(n for n, _ in rows.values())} in all")
