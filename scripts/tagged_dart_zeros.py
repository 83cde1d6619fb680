#!/usr/bin/env python
"""The Taylor coefficients that scripts/tagged_dart_charmap.py drops, computed exactly and checked to be 0
(not trusted; no certificate).

tagged_dart_charmap.py bounds det J_Phi, the transversality form and the winding signs of ``dart:K`` for every
K >= 101 by Taylor models in h = 1/K whose lowest coefficients it drops as 0 exactly (docs/tagged_c1.md, "A plan
for every dart K >= 101", item 6). This script computes each dropped coefficient in exact arithmetic and checks
that it is 0, so that no structural argument is left unchecked:

* **The variables.** Every value of the family is a power series in (a h, b h, a s, b s), a = 2 pi the angle
  unit of mode 1, b = 2 sigma that of y's mode, times constants in Q(sqrt 5, i) and the numbers c = cos(sigma),
  t = sin(sigma) (through alpha, proportional to c, and e^(-+ i sigma) = c -+ i t) and l = ln L0 (through
  a1 = a2 = -ln L0 at h = 0). So the coefficient of s^k h^m of any dropped quantity is a polynomial in
  (a, b, c, t, l) of degree <= k + m in a and in b and <= 1 in each of c, t, l: every quantity is linear in y
  (y is linear in (c, t)), the middle's factor e^(-+ i sigma) multiplies only y's parts Y+- (which have no c, t),
  and l enters only through a1, a2. A polynomial with these degree bounds that vanishes on the grid
  a, b in {1, 2, 3}, c, t, l in {1, 2} is 0 (one variable at a time), so in particular at a = 2 pi,
  b = 2 sigma, c = cos(sigma), t = sin(sigma), l = ln L0 for every sigma: the checks do not use the sigma
  bracket at all.
* **Exact arithmetic.** On each grid point the series in h are truncated power series with coefficients in
  Q(sqrt 5, i) (python-flint fmpq components): lam(cos(a h)) with sqrt((1 + c)(9 + c)) expanded at
  sqrt(20) = 2 sqrt 5, the bordered 7 x 7 systems of B(e^(i a h)) solved order by order from the one at h = 0
  (Gauss-Jordan over Q(sqrt 5, i)), U(lam) = adj(lam - B(1)) kappa/(...) from the exact polynomials, alpha,
  and the level-1 nets by the script's own assembly (``local_value``, ``layer_value``, ``_bezier``, exact
  fmpq weights). det J_Phi's h^m coefficient is a polynomial of degree <= (5, 5) in the patch parameters
  (u, v): it is checked 0 on the 6 x 6 grid u, v in {0, 1/5, ..., 1}; the transversality form's and the
  curve points' coefficients are checked as the Bernstein coefficients themselves.

The dropped coefficients (all pieces P1, P2, P3; all outer curves; both x parts and all three y parts):

=========================== ==========================================================================
bulk det                    D_ij's h^0 coefficient, every (i, j)
middle det                  e_10, e_11, e_20: the s^0 h^0, s^1 h^0, s^0 h^1 coefficients of K det J_Phi
layer det, q = 0, 1, 2      det J_Phi's h^0, h^1, h^2
bulk T                      T_ij's h^0, every (i, j)
middle T                    e_10, e_11, e_20 of K (a1 X Y' - a2 Y X')
layer T, q = 0, 1, 2        h^0, h^1, h^2 of a1 X Y' - a2 Y X'
W middle                    Y at s = h = 0 on every curve point
W layer, q = 0, 1, 2        Y's h^0 on every curve point, and h^1 at ray 0's end point (q = 0, P1s1, point 0)
=========================== ==========================================================================

``python scripts/tagged_dart_zeros.py`` prints the number of exact zeros per row (tagged_dart_charmap.py prints
the same line as its part Z). ``stencil`` and ``flip_alpha`` perturb the rule or the family: the checks must
then find non-zero coefficients (tests/certify/test_tagged_dart_charmap_script.py).
"""

from __future__ import annotations

import importlib.util
import itertools
import time
from pathlib import Path

from flint import fmpq

from ccproof.certify.verify.tagged_modes import _POS, ring_stencil

ORDER = 3  # the series are kept to h^2: every dropped coefficient has m <= 2


def _charmap():
    path = Path(__file__).resolve().parent / "tagged_dart_charmap.py"
    spec = importlib.util.spec_from_file_location("tagged_dart_charmap", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


class QF:
    """(p + q sqrt 5) + i (r + u sqrt 5) in Q(sqrt 5, i), fmpq components (exact)."""

    __slots__ = ("p", "q", "r", "u")

    def __init__(self, p=0, q=0, r=0, u=0):
        self.p, self.q, self.r, self.u = fmpq(p), fmpq(q), fmpq(r), fmpq(u)

    @staticmethod
    def lift(z):
        return z if isinstance(z, QF) else QF(z)

    def __add__(self, o):
        if isinstance(o, Series):
            return NotImplemented
        o = QF.lift(o)
        return QF(self.p + o.p, self.q + o.q, self.r + o.r, self.u + o.u)

    __radd__ = __add__

    def __neg__(self):
        return QF(-self.p, -self.q, -self.r, -self.u)

    def __sub__(self, o):
        if isinstance(o, Series):
            return NotImplemented
        return self + (-QF.lift(o))

    def __rsub__(self, o):
        return QF.lift(o) - self

    def __mul__(self, o):
        if isinstance(o, Series):
            return NotImplemented
        if not isinstance(o, QF):
            o = fmpq(o)
            return QF(self.p * o, self.q * o, self.r * o, self.u * o)

        def m(a, b, c, d):  # (a + b sqrt 5)(c + d sqrt 5)
            return a * c + 5 * b * d, a * d + b * c
        rr, ii, ri, ir = m(self.p, self.q, o.p, o.q), m(self.r, self.u, o.r, o.u), m(self.p, self.q, o.r, o.u), \
            m(self.r, self.u, o.p, o.q)
        return QF(rr[0] - ii[0], rr[1] - ii[1], ri[0] + ir[0], ri[1] + ir[1])

    __rmul__ = __mul__

    def inv(self):
        # 1/(A + iB) = (A - iB)/(A^2 + B^2), 1/(x + y sqrt 5) = (x - y sqrt 5)/(x^2 - 5 y^2)
        n = self * QF(self.p, self.q, -self.r, -self.u)  # A^2 + B^2, in Q(sqrt 5)
        d = n.p * n.p - 5 * n.q * n.q
        if d == 0:
            raise ZeroDivisionError("0 in Q(sqrt 5, i)")
        ninv = QF(n.p / d, -n.q / d)
        return QF(self.p, self.q, -self.r, -self.u) * ninv

    def __truediv__(self, o):
        if isinstance(o, Series):
            return Series([self]) / o
        return self * QF.lift(o).inv()

    def is_zero(self):
        return self.p == 0 and self.q == 0 and self.r == 0 and self.u == 0


class Series:
    """A power series in h truncated after h^(ORDER - 1), coefficients QF."""

    __slots__ = ("c",)

    def __init__(self, c):
        c = [QF.lift(z) for z in c][:ORDER]
        self.c = c + [QF() for _ in range(ORDER - len(c))]

    @staticmethod
    def lift(z):
        return z if isinstance(z, Series) else Series([z])

    def __add__(self, o):
        o = Series.lift(o)
        return Series([a + b for a, b in zip(self.c, o.c)])

    __radd__ = __add__

    def __neg__(self):
        return Series([-a for a in self.c])

    def __sub__(self, o):
        return self + (-Series.lift(o))

    def __rsub__(self, o):
        return Series.lift(o) - self

    def __mul__(self, o):
        if not isinstance(o, Series):
            o = QF.lift(o)
            return Series([a * o for a in self.c])
        return Series([sum((self.c[k] * o.c[m - k] for k in range(m + 1)), QF()) for m in range(ORDER)])

    __rmul__ = __mul__

    def __truediv__(self, o):
        if not isinstance(o, Series):
            return self * QF.lift(o).inv()
        inv0 = o.c[0].inv()
        out = []
        for m in range(ORDER):
            acc = self.c[m] - sum((o.c[k] * out[m - k] for k in range(1, m + 1)), QF())
            out.append(acc * inv0)
        return Series(out)

    def __rtruediv__(self, o):
        return Series.lift(o) / self


I = QF(0, 0, 1)
SQRT20 = QF(0, 2)
L0 = (6 + SQRT20) * fmpq(1, 16)  # lam(1), the root of 16 x^2 - 12 x + 1 with the + sign
L0_LOW = (6 - SQRT20) * fmpq(1, 16)  # 1/(16 L0)


def _exp_i(k):
    """e^(i k h) as a Series (k an fmpq: the angle unit times the sector offset)."""
    out, term = [], QF(1)
    for m in range(ORDER):
        out.append(term)
        term = term * I * fmpq(k) * fmpq(1, m + 1)
    return Series(out)


def _cos(k):
    """cos(k h)."""
    return (_exp_i(k) + _exp_i(-k)) * fmpq(1, 2)


def _sqrt20(g):
    """sqrt(g) for a series g with g(0) = 20 (branch: + 2 sqrt 5)."""
    if not (g.c[0] - 20).is_zero():
        raise ValueError("the square root is expanded at 20 only")
    s = [SQRT20]
    for m in range(1, ORDER):
        acc = g.c[m] - sum((s[j] * s[m - j] for j in range(1, m)), QF())
        s.append(acc / (SQRT20 * 2))
    return Series(s)


def lam_series(k):
    """lam(cos(k h)) = (5 + c + sqrt((1 + c)(9 + c)))/16."""
    c = _cos(k)
    return (c + 5 + _sqrt20((c + 1) * (c + 9))) * fmpq(1, 16)


def _log_ratio(lam):
    """ln(lam/L0) for a series lam with lam(0) = L0: ln(1 + z) = z - z^2/2 + ..., z = lam/L0 - 1."""
    z = lam / L0 - 1
    if not z.c[0].is_zero():
        raise ValueError("lam(0) != L0")
    out, zp = Series([0]), Series([1])
    for m in range(1, ORDER):
        zp = zp * z
        out = out + zp * fmpq((-1) ** (m + 1), m)
    return out


def _block(k, stencil):
    """B(e^(i k h)) (6 x 6 Series)."""
    rows = [[Series([0]) for _ in range(6)] for _ in range(6)]
    for i, row in enumerate(stencil):
        for (d, pos), x in row.items():
            rows[i][_POS[pos]] = rows[i][_POS[pos]] + _exp_i(fmpq(k) * d) * fmpq(x)
    return rows


def _solve(A, b):
    """Gauss-Jordan over Q(sqrt 5, i): A x = b (A n x n QF, b n QF); ZeroDivisionError if A is singular."""
    n = len(A)
    M = [list(A[i]) + [b[i]] for i in range(n)]
    for c in range(n):
        piv = next((r for r in range(c, n) if not M[r][c].is_zero()), None)
        if piv is None:
            raise ZeroDivisionError("singular bordered system")
        M[c], M[piv] = M[piv], M[c]
        inv = M[c][c].inv()
        M[c] = [z * inv for z in M[c]]
        for r in range(n):
            if r != c and not M[r][c].is_zero():
                f = M[r][c]
                M[r] = [z - f * w for z, w in zip(M[r], M[c])]
    return [M[r][n] for r in range(n)]


def bordered(k, lam, stencil):
    """v^ (6 Series): B(e^(i k h)) v^ = lam v^ with v^(1,0) = 1, solved order by order in h."""
    B = _block(k, stencil)
    A = [[(B[i][j] - lam) if i == j else B[i][j] for j in range(6)] + [Series([int(i == 0)])] for i in range(6)]
    A.append([Series([int(j == 0)]) for j in range(6)] + [Series([0])])
    A0 = [[A[i][j].c[0] for j in range(7)] for i in range(7)]
    vs = []
    for m in range(ORDER):
        rhs = [QF(int(i == 6 and m == 0)) for i in range(7)]
        for j in range(1, m + 1):
            rhs = [r - sum((A[i][l].c[j] * vs[m - j][l] for l in range(7)), QF()) for i, r in enumerate(rhs)]
        vs.append(_solve(A0, rhs))
    return [Series([vs[m][i] for m in range(ORDER)]) for i in range(6)]


class ExactFamily:
    """The family of tagged_dart_charmap.Family at one grid point (a, b, c, t) as exact Series in h.

    Parameters
    ----------
    a, b : fmpq
        the angle units of x's mode (2 pi) and of y's mode (2 sigma)
    c, t : fmpq
        stand-ins for cos(sigma), sin(sigma)
    stencil : list of dict, optional
        the ring rows (``ring_stencil()``; a perturbed rule for the tests)
    flip_alpha : bool
        alpha -> -alpha (a perturbed family: the checks must fail)
    """

    def __init__(self, cm, a, b, c, t, stencil=None, flip_alpha=False):
        stencil = ring_stencil() if stencil is None else stencil
        self.a, self.b, self.c, self.t = fmpq(a), fmpq(b), fmpq(c), fmpq(t)
        self.zero = Series([0])
        self.lam1, self.lam2 = lam_series(self.a), lam_series(self.b)
        self.vx, self.vy = bordered(self.a, self.lam1, stencil), bordered(self.b, self.lam2, stencil)
        lam = self.lam2
        den = (lam - fmpq(1, 8)) * (lam - fmpq(1, 16)) * (lam - fmpq(1, 32)) * (lam - fmpq(1, 64)) * (lam - L0_LOW)
        self.U = []
        for p in cm._NPOLY:
            acc = Series([0])
            for coef in reversed(p):
                acc = acc * lam + fmpq(coef)
            self.U.append(acc / den)
        half = lam - fmpq(1, 2)
        self.alpha = -(half * self.c) / (half * self.U[0] - (lam - L0) * fmpq(1, 2))
        if flip_alpha:
            self.alpha = -self.alpha
        self.yc = self.alpha * (lam - L0)
        self.em, self.ep = QF(self.c, 0, -self.t), QF(self.c, 0, self.t)  # e^(-i sigma), e^(i sigma)

    def parts(self):
        """{basis part: (level0(delta, pos), centre, lam)} as Family.parts, exact."""
        vx, vy, a, b = self.vx, self.vy, self.a, self.b
        i2 = I * 2

        def eps(pos):
            return 0 if pos[1] == 0 else 1

        def sw(p):
            return p if p[1] == 0 else (p[1], p[0])
        return {
            "X+": (lambda d, p: vx[_POS[p]] * _exp_i(a * d) / i2, self.zero, self.lam1),
            "X-": (lambda d, p: -(vx[_POS[sw(p)]] * _exp_i(-a * (d + eps(p)))) / i2, self.zero, self.lam1),
            "Y0": (lambda d, p: self.alpha * self.U[_POS[p]], self.yc, self.lam2),
            "Y+": (lambda d, p: vy[_POS[p]] * _exp_i(b * d) * fmpq(1, 2), self.zero, self.lam2),
            "Y-": (lambda d, p: vy[_POS[sw(p)]] * _exp_i(-b * (d + eps(p))) * fmpq(1, 2), self.zero, self.lam2),
        }

    def layer_level0(self, q):
        """(x(t, pos), y(t, pos)) as tagged_dart_charmap.layer_level0 (y reflected in ray 0 for t < 0)."""
        vx, vy, a, b = self.vx, self.vy, self.a, self.b

        def eps(pos):
            return 0 if pos[1] == 0 else 1

        def sw(p):
            return p if p[1] == 0 else (p[1], p[0])

        def x(t, pos):
            return (vx[_POS[pos]] * _exp_i(a * t) - vx[_POS[sw(pos)]] * _exp_i(-a * (t + eps(pos)))) / (I * 2)

        def y(t, pos):
            if t < 0:
                t, pos = (-t, pos) if pos[1] == 0 else (-t - 1, sw(pos))
            return (self.alpha * self.U[_POS[pos]]
                    + (vy[_POS[pos]] * _exp_i(b * t) * self.em
                       + vy[_POS[sw(pos)]] * _exp_i(-b * (t + eps(pos))) * self.ep) * fmpq(1, 2))
        return x, y


# --- det J as a polynomial in the patch parameters (u, v), tested on a 6 x 6 grid -------------------------

_GRID = [fmpq(k, 5) for k in range(6)]


def _bern3(u):
    return [(1 - u) ** 3, 3 * u * (1 - u) ** 2, 3 * u * u * (1 - u), u ** 3]


def _dbern3(u):
    return [-3 * (1 - u) ** 2, 3 * (1 - u) ** 2 - 6 * u * (1 - u), 6 * u * (1 - u) - 3 * u * u, 3 * u * u]


_WEIGHTS = [(_bern3(u), _dbern3(u), _bern3(v), _dbern3(v)) for u in _GRID for v in _GRID]


def _partials(net):
    """[(X_u, X_v) at each grid point] (Series) of a 4 x 4 Bezier net of Series."""
    out = []
    for bu, du, bv, dv in _WEIGHTS:
        xu = sum((net[i][j] * (du[i] * bv[j]) for i in range(4) for j in range(4) if du[i] * bv[j] != 0), Series([0]))
        xv = sum((net[i][j] * (bu[i] * dv[j]) for i in range(4) for j in range(4) if bu[i] * dv[j] != 0), Series([0]))
        out.append((xu, xv))
    return out


def _det_series(px, py):
    """[det (X_u Y_v - X_v Y_u) at each grid point] (Series) from the partials of two nets."""
    return [xu * yv - xv * yu for (xu, xv), (yu, yv) in zip(px, py)]


def _nonzero(zs):
    return sum(0 if z.is_zero() else 1 for z in zs)


GRID_AB = (1, 2, 3)  # degree <= 2 in a and in b
GRID_CT = (1, 2)  # degree <= 1 in c, t, l


# --- the dropped coefficients at one grid point --------------------------------------------------------

def _middle(G, fam):
    """e_10, e_11, e_20 (lists of QF over the points) of sum_ij a_i(s) b_j(s) G_ij(h)/h, G_ij's coefficients in h
    given: a_i b_j = c_ij e^(i omega_ij s), c_ij = 1, e^(-i sigma), e^(i sigma) for Y0, Y+, Y-, omega_ij =
    +-a + (0, b, -b)."""
    cj = {"Y0": (QF(1), 0), "Y+": (fam.em, fam.b), "Y-": (fam.ep, -fam.b)}
    om_i = {"X+": fam.a, "X-": -fam.a}
    out = {}
    for name, m, l in (("e10", 1, 0), ("e11", 1, 1), ("e20", 2, 0)):
        acc = None
        for (i, j), vals in G.items():
            f = cj[j][0] * (I * (om_i[i] + cj[j][1]) if l == 1 else QF(1))
            v = [z.c[m] * f for z in vals]
            acc = v if acc is None else [x + y for x, y in zip(acc, v)]
        out[name] = acc
    return out


def check_point(cm, a, b, c, t, ells=GRID_CT, stencil=None, flip_alpha=False):
    """{row: (coefficients checked, non-zero among them)} at the grid points (a, b, c, t, l), l in ``ells``."""
    fam = ExactFamily(cm, a, b, c, t, stencil=stencil, flip_alpha=flip_alpha)
    res = {}

    def add(key, zs):
        n, bad = res.get(key, (0, 0))
        res[key] = (n + len(zs), bad + _nonzero(zs))
    nets = {name: cm.piece_nets(f, cen, lam, fam.zero) for name, (f, cen, lam) in fam.parts().items()}
    # a_i = -ln lam_i = -l - ln(lam_i/L0)
    A = [(-_log_ratio(fam.lam1) - fmpq(ell), -_log_ratio(fam.lam2) - fmpq(ell)) for ell in ells]

    # det, bulk and middle
    part = {(n, p): _partials(nets[n][p]) for n in nets for p in cm.PIECES}
    for piece in cm.PIECES:
        G = {(i, j): _det_series(part[(i, piece)], part[(j, piece)]) for i in cm.XB for j in cm.YB}
        for vals in G.values():
            add("bulk det: D_ij h^0", [z.c[0] for z in vals])
        for zs in _middle(G, fam).values():
            add("middle det: e_10, e_11, e_20", zs)

    # transversality, bulk and middle (exact Bernstein coefficients of the degree-5 curve forms)
    def trans(xs, ys):  # the coefficients for every l, one after the other
        P, Q = cm._bprod(xs, ys), cm._bprod(ys, xs)
        return [A1 * p - A2 * q for A1, A2 in A for p, q in zip(P, Q)]
    for curve in cm.CURVES:
        G = {(i, j): trans(cm.curve_points(nets[i], curve), cm.curve_points(nets[j], curve))
             for i in cm.XB for j in cm.YB}
        for vals in G.values():
            add("bulk T: T_ij h^0", [z.c[0] for z in vals])
        for zs in _middle(G, fam).values():
            add("middle T: e_10, e_11, e_20", zs)
        # W middle: Y at s = h = 0 = sum_j c_j Y_j(0), c = 1, e^(-i sigma), e^(i sigma)
        ys = {j: cm.curve_points(nets[j], curve) for j in cm.YB}
        add("W middle: Y(s = h = 0)", [(ys["Y0"][p] + ys["Y+"][p] * fam.em + ys["Y-"][p] * fam.ep).c[0]
                                       for p in range(4)])

    # the layer quadrants
    for q in range(3):
        x, y = fam.layer_level0(q)
        VX = cm.layer_value(x, fam.zero, fam.lam1, q, fam.zero)
        VY = cm.layer_value(y, fam.yc, fam.lam2, q, fam.zero)
        lnets = {}
        for name in cm.PIECES:
            oa, ob = cm._OFFSET[name]
            lnets[name] = tuple(cm._bezier([[V(oa + i, ob + j) for j in range(4)] for i in range(4)], fam.zero)
                                for V in (VX, VY))
            d = _det_series(_partials(lnets[name][0]), _partials(lnets[name][1]))
            add("layer det: h^0, h^1, h^2", [z.c[m] for z in d for m in range(3)])
        for curve in cm.CURVES:
            xs = cm.curve_points({p: lnets[p][0] for p in cm.PIECES}, curve)
            ys = cm.curve_points({p: lnets[p][1] for p in cm.PIECES}, curve)
            add("layer T: h^0, h^1, h^2", [z.c[m] for z in trans(xs, ys) for m in range(3)])
            add("W layer: Y h^0 (h^1 at ray 0's end)",
                [ys[p].c[0] for p in range(4)] + ([ys[0].c[1]] if (q == 0 and curve == "P1s1") else []))
    return res


def check_all(cm=None, stencil=None, flip_alpha=False, grid_ab=GRID_AB, grid_ct=GRID_CT):
    """{row: (coefficients checked, non-zero among them)} over the whole grid."""
    cm = _charmap() if cm is None else cm
    total = {}
    for a, b, c, t in itertools.product(grid_ab, grid_ab, grid_ct, grid_ct):
        for key, (n, bad) in check_point(cm, a, b, c, t, grid_ct, stencil=stencil, flip_alpha=flip_alpha).items():
            n0, b0 = total.get(key, (0, 0))
            total[key] = (n0 + n, b0 + bad)
    return total


def report(total):
    return "; ".join(f"{key}: {n - bad}/{n} exactly 0" for key, (n, bad) in total.items())


def main():
    t0 = time.time()
    total = check_all()
    print(f"Z  the dropped coefficients, exact in Q(sqrt 5, i) on the grid a, b in {GRID_AB}, c, t, l in {GRID_CT}: "
          + report(total) + f" ({time.time() - t0:.1f} s)")
    if any(bad for _, bad in total.values()):
        raise SystemExit("a dropped coefficient is not 0")


if __name__ == "__main__":
    main()
