"""The eigenvector lemma for every dart K >= K0: the map's x and y ARE the eigenvectors of lam1 and lam2 (trusted).

:mod:`.dart_family` writes y as a family in (sigma, h), h = 1/K (docs/tagged_c1.md, "A plan for every dart
K >= 101", items 4 and 6),

    y(t, p) = alpha U(p) + (v^(p) e^(i sigma (2 h t - 1)) + v^(p~) e^(-i sigma (2 h (t + eps) - 1)))/2,   0 <= t < K,
    y(C) = alpha (lam - L0),     lam = lam(cos theta), theta = 2 sigma h, w = e^(i theta),

(v^ the bordered solution of B(w) v^ = lam v^ with v^(1,0) = 1; p~ = p on rays, (b, a) on quadrants; eps = 0 on
rays, 1 on quadrants; U = (lam - L0)(lam - B(1))^-1 kappa with the pole at L0 divided out; alpha from the sharp
midpoint's row), and x = (v^_x(p) w1^t - v^_x(p~) w1^(-t-eps))/(2i), w1 = e^(2 pi i h), lam1 = lam(cos 2 pi h).
:func:`check_eigenvector` shows, for every K >= K0 at once, that the member at sigma = sigma(K) is the
eigenvector of lam2 (and x the eigenvector of lam1). The argument, with what is checked where:

1. **Every ring row holds identically** (every sigma, h; no K-dependent check). Let f(t, p) be the formula
   above for every integer t, with f(C) = y(C). Its mode part is (g + g o M)/2, g(t, p) = e^(-i sigma) w^t
   v^(p) a mode-w vector and M the reflection in ray K/2 (ray t -> ray K - t, quadrant t (a, b) ->
   quadrant K - 1 - t (b, a); M = R followed by the translation by K, and w^K = e^(2 i sigma) as Kh = 1).
   (a) B(w) v^ = lam v^: lam = lam(c) is a root of x^2 - (5 + c) x/8 + 1/16, so det(lam - B(w)) = 0 by the
   block polynomial of :func:`.tagged_modes.check_ring` (exact); a regular bordered matrix [[B - lam, e],
   [e^T, 0]] of a singular B - lam forces corank 1 and the border's multiplier 0 (the left null vector u
   has u^T e != 0), so the solution is an eigenvector. So the ring operator L (the ring stencil, the centre
   weight kappa(p) on the centre value) maps g to lam g on the whole strip of integer sectors, and g o M
   to lam g o M because the stencil commutes with R (check_ring, exact). (b) The mode-0 part: alpha U on
   every sector with the centre alpha (lam - L0) has L-image alpha (B(1) U + (lam - L0) kappa) = lam alpha U
   iff (lam - B(1)) N(lam) = det(lam - B(1)) kappa and det(lam - B(1)) = (lam - 1/8)(lam - 1/16)(lam - 1/32)
   (lam - 1/64)(lam - L0)(lam - 1/(16 L0)), N = adj(lam - B(1)) kappa the numerator of :func:`.dart_family.big_u`
   (exact in Q[lam], :func:`check_mode0`; (x - L0)(x - 1/(16 L0)) = x^2 - 3x/4 + 1/16). So L f = lam f on the
   strip. (c) Windows: S's row at ray t, 1 <= t < K, or at quadrant t, 0 <= t < K, is the ring row at
   (t, p) with sectors taken mod K (the construction, :mod:`.dart_spectrum`), and reads y at rays t - 1 ..
   t + 1 and quadrants t - 1, t from a ray, rays t, t + 1 and quadrant t from a quadrant (:func:`check_reach`,
   exact). These are y = f on 0..K (rays) and 0..K-1 (quadrants), ray K included: f(K - t, ray) = f(t, ray)
   is an identity of the formula (its two terms swap). So (S y - lam y) vanishes on every ring point.
2. **Ray 0's two sharp rows** read only y(C), e = y(0, (1,0)) = alpha U(1,0) + cos(sigma) and
   E = y(0, (2,0)) = alpha U(2,0) + cos(sigma) v^(2,0): a1 alpha + b1 cos sigma = 0 (sharp midpoint,
   lam e = (C + e)/2) and a2 alpha + b2 cos sigma = 0 (crease vertex, lam E = (C + 6 e + E)/8), with
   a1 = (lam - 1/2) U(1,0) - (lam - L0)/2, b1 = lam - 1/2, a2 = (lam - 1/8) U(2,0) - 3 U(1,0)/4 - (lam - L0)/8,
   b2 = (lam - 1/8) v^(2,0) - 3/4. alpha = -b1 cos(sigma)/a1 solves the first (its definition in
   :class:`.dart_family.Family`; :func:`check_eigenvector` confirms the code on every evaluation: a flipped
   alpha FAILs there), and the second then holds because a1 b2 = a2 b1 identically (:func:`check_crease_row`:
   with den = (x - 1/8)(x - 1/16)(x - 1/32)(x - 1/64)(x - 1/(16 L0)) the polynomials a_i den are in Q[x], and
   psi(x)^T adj(x - B(w)) = 0 modulo x^2 - (5 + c) x/8 + 1/16 for psi = (a1 den)(b2-row) - (a2 den)(b1-row),
   exact at 33 rational w: the remainders are w^-16 times polynomials of degree <= 32 in w (minors of
   x - B(w) have w-degrees in [-5, 5], x^j mod that quadratic has coefficients of degree < j in c, and
   deg psi adj <= 12). At a regular bordered system adj(lam - B(w)) = v^ l^T with l != 0, so psi^T v^ = 0.)
3. **One residual: the centre row.** By 1 and 2, S y - lam y = r(sigma, h) e_C. The closed sums over the K
   sectors (w^K = e^(2 i sigma)) give sum_t y(t, (1,0)) = K alpha U(1,0) + i sin(sigma) (1 + w)/(w - 1)
   and sum_t y(t, (1,1)) = K alpha U(1,1) + 2 i sin(sigma) v^(1,1)/(w - 1), so with the centre row
   (1 - 7h/4, 3h^2/2 on each ray's (1,0), h^2/4 on each quadrant's (1,1))

       r/h = (1 - 7h/4 - lam) alpha (lam - L0)/h + alpha (3 U(1,0)/2 + U(1,1)/4)
             + i sin(sigma) (h/(w - 1)) (3 (1 + w)/2 + v^(1,1)/2),

   with (lam - L0)/h = -(sigma^2 h sinc(sigma h)^2/8)(1 + (c + 11)/(sqrt((1 + c)(9 + c)) + sqrt 20)) and
   h/(w - 1) = e^(-i sigma h)/(2 i sigma sinc(sigma h)): analytic at h = 0 (there it is a non-zero multiple
   of sin(sigma)/sigma - cos(sigma), the limit tan sigma = sigma of the secular equation).
   :func:`scaled_centre_residual` evaluates it in acb; :func:`check_eigenvector` shows on `balls` equal
   h-balls covering [0, 1/K0] that r/h has certainly opposite signs at sig_lo and sig_hi and is finite, every
   division certainly regular, on the whole box [sig_lo, sig_hi] x h-ball (so, for real sigma and h = 1/K,
   a continuous function of sigma on the bracket). For real sigma and h the family is real (conj B(w) =
   B(1/w), and B(1/w) R_w = R_w B(w) with R_w fixing the pivot: conj v^(p) = v^(p~) w^(-eps)), so r is real
   and the intermediate value theorem gives sigma* in (sig_lo, sig_hi) with r(sigma*, 1/K) = 0: y at
   sigma* is an eigenvector of S with eigenvalue lam* = lam(cos(2 sigma* / K)). It is not 0: y(C) =
   alpha (lam* - L0) with lam* < L0 (c < 1, lam increasing) and alpha != 0 (cos sigma < 0 on the bracket,
   lam - 1/2 != 0: checked).
4. **sigma* = sigma(K).** y is even (y o R = y: the formula is symmetric about ray K/2 and K - t = -t mod
   K). By the spectral part (:mod:`.dart_spectrum`: 1 and lam2 are the only even eigenvalues outside the
   circle |lam| = lam(cos(2 sigma_r/K)), lam2 simple, and the record's sig_hi < sigma_r), lam* is real,
   != 1 (lam(c) < 1) and outside that circle (0 < 2 sigma* h < 2 sigma_r h < pi), so lam* = lam2 and, lam
   being strictly monotone there, sigma* = sigma(K): the family member at sigma(K) spans lam2's eigenspace.
5. **x.** w1^K = 1, so x's mode is K-periodic: L x = lam1 x on every ring row with no window condition (1a
   at w1, the bordered system regular on every h-ball: checked), x(C) = 0 and x = 0 on ray 0 (its two
   terms cancel), and the centre row reads sums of w1^t over the K-th roots of unity, 0. So S x = lam1 x,
   x != 0 (x(1, (1,0)) = sin(2 pi/K)), and x is the (odd) eigenvector of lam1.

What is assumed from the other modules, each checked there: the construction of S for every K (ring rows,
ray 0's two rows, the centre row; :mod:`.dart_spectrum`), the spectral count and lam2's simplicity, and
sig_hi < sigma_r (the record). Nothing here depends on K beyond h's range: the exact checks are identities
in (x, w), the arb checks run on h-balls covering [0, 1/K0].
"""

from __future__ import annotations

from flint import acb, arb, ctx, fmpq, fmpq_mat, fmpq_poly

from ccproof.rigorous.analytic import ball

from .dart_family import B_AT_1, N_POLYS, Family, adjugate, kappa, l0, u_denominator
from .errors import CertificateError
from .rules import TWO_RING
from .tagged_modes import RING_INDEX, check_ring, ring_block, ring_stencil

_X = fmpq_poly([0, 1])
_E10, _E20, _E11 = RING_INDEX[(1, 0)], RING_INDEX[(2, 0)], RING_INDEX[(1, 1)]
W_POINTS = 33  # the remainders of check_crease_row: w^-16 times polynomials of degree <= 32 in w


def check_reach():
    """Raise unless a ray's ring row reads rays d = -1..1 and quadrants d = -1, 0, and a quadrant's reads rays
    d = 0, 1 and its own quadrant (exact; item 1c of the module docstring).

    Examples
    --------
    >>> check_reach()
    True
    """
    for pos, row in zip(TWO_RING, ring_stencil()):
        for d, q in row:
            if pos[1] == 0:
                ok = -1 <= d <= 1 if q[1] == 0 else d in (-1, 0)
            else:
                ok = d in (0, 1) if q[1] == 0 else d == 0
            if not ok:
                raise CertificateError(f"the ring row of {pos} reads {q} of sector +{d}: "
                                       "beyond the windows of the lemma")
    return True


def check_mode0():
    """Raise unless (x - B(1)) N(x) = det(x - B(1)) kappa for the numerator N of :func:`.dart_family.big_u`
    (exact in Q[x]); det(x - B(1)) = (x - 1/8)(x - 1/16)(x - 1/32)(x - 1/64)(x^2 - 3x/4 + 1/16) is the block
    polynomial at w = 1 (:func:`.tagged_modes.check_ring`, run first by :func:`check_eigenvector`).

    Examples
    --------
    >>> check_mode0()
    True
    """
    B1 = B_AT_1
    p = B1.charpoly()
    N = [fmpq_poly(c) for c in N_POLYS]
    kap = kappa()
    for i in range(6):
        lhs = _X * N[i] - sum((B1[i, k] * N[k] for k in range(6)), fmpq_poly(0))
        if lhs != p * kap[i]:
            raise CertificateError("U's numerator is not adj(x - B(1)) kappa: the mode-0 part misses its rows")
    return True


def check_crease_row(points=W_POINTS):
    """Raise unless a1 b2 = a2 b1 on the curve lam = lam(c) (item 2 of the module docstring): the crease
    vertex row of ray 0 holds wherever the sharp midpoint's does. Exact, at w = 1..points.

    Examples
    --------
    >>> check_crease_row()
    True
    """
    if points < W_POINTS:
        raise CertificateError(f"{points} values of w cannot show an identity of degree {W_POINTS - 1}")
    p = B_AT_1.charpoly()  # the product of check_ring's block polynomial at w = 1
    N = [fmpq_poly(c) for c in N_POLYS]
    if any(n.degree() > 5 for n in N):
        raise CertificateError("U's numerator has degree > 5: the degree bound of the identity fails")
    h = fmpq(1, 2)
    a1 = (_X - h) * N[_E10] - p / 2
    a2 = (_X - fmpq(1, 8)) * N[_E20] - fmpq(3, 4) * N[_E10] - p / 8
    psi = [fmpq_poly(0)] * 6
    psi[_E20] = a1 * (_X - fmpq(1, 8))
    psi[_E10] = -fmpq(3, 4) * a1 - a2 * (_X - h)
    for w in range(1, points + 1):
        c = (fmpq(w) + fmpq(1, w)) / 2
        q = _X * _X - (5 + c) / 8 * _X + fmpq(1, 16)
        adj = adjugate(fmpq_mat(ring_block(fmpq(w))))
        for j in range(6):
            P = sum((psi[i] * adj[i][j] for i in range(6)), fmpq_poly(0))
            if P % q != 0:
                raise CertificateError(f"a1 b2 != a2 b1 at w = {w}: the crease vertex row of ray 0 fails")
    return True


def _nonzero(z, what):
    if not (z.is_finite() and abs(z) > 0):
        raise ZeroDivisionError(f"{what} is not certainly non-zero")


def scaled_centre_residual(fam):
    """r/h, the centre row's residual of S y - lam y divided by h (item 3), from a Family at an acb ball h
    (which may contain 0) and an arb sigma; ZeroDivisionError where a division is not certainly regular.

    Examples
    --------
    >>> from flint import acb, arb, fmpq
    >>> r = scaled_centre_residual(Family(acb(fmpq(1, 101)), arb("4.484")))
    >>> r.real > 0, abs(r.imag) < 1e-10, abs(r.real - 0.0013118) < 1e-6
    (True, True, True)
    """
    h, sigma, lam = fam.h, fam.sigma, fam.lam2
    _denominators(fam)
    sh = h * sigma
    sinc = sh.sinc()
    _nonzero(sinc, "sinc(sigma h)")
    c = (2 * sh).cos()
    if not ((1 + c) * (9 + c)).real > 0:
        raise ZeroDivisionError("sqrt((1 + c)(9 + c)): the argument is not certainly off the branch cut")
    root = ((1 + c) * (9 + c)).sqrt()
    _nonzero(root + arb(20).sqrt(), "sqrt((1 + c)(9 + c)) + sqrt 20")
    dl = -(sigma * sigma * h * sinc * sinc / 8) * (1 + (c + 11) / (root + arb(20).sqrt()))  # (lam - L0)/h
    w = (2 * acb(0, 1) * sh).exp()
    quot = (-acb(0, 1) * sh).exp() / (2 * acb(0, 1) * sigma * sinc)  # h/(w - 1)
    U, v, alpha = fam.U, fam.vy, fam.alpha
    out = ((1 - 7 * h / 4 - lam) * alpha * dl + alpha * (3 * U[_E10] / 2 + U[_E11] / 4)
           + acb(0, 1) * sigma.sin() * quot * (3 * v[_E10] * (1 + w) / 2 + v[_E11] / 2))
    if not out.is_finite():
        raise ZeroDivisionError("r/h is not finite")
    return out


def _denominators(fam):
    """ZeroDivisionError unless U's denominator, alpha's a1 and lam - 1/2 (alpha != 0) are certainly non-zero
    and U, v^ finite (then the family is analytic on the ball: items 1b, 2, 3)."""
    lam, L0, L1 = fam.lam2, *l0()
    _nonzero(u_denominator(lam, L1), "U's denominator")
    _nonzero((lam - fmpq(1, 2)) * fam.U[_E10] - (lam - L0) / 2, "alpha's denominator a1")
    _nonzero(lam - fmpq(1, 2), "lam - 1/2")
    if not all(z.is_finite() for z in list(fam.U) + list(fam.vy) + list(fam.vx)):
        raise ZeroDivisionError("U or a bordered solution is not finite")


def _guard(fam, tol):
    """Raise unless the Family computes the lemma's formula at this (sigma, h): v^(1,0) = 1, y(C) =
    alpha (lam - L0), ray 0's two sharp rows and the ring rows of sector 1 satisfied (balls containing 0,
    radii below tol; they are identities, items 1 and 2)."""
    lam, L0 = fam.lam2, l0()[0]
    y, yc = fam.layer_level0(0)[1], fam.yc
    kap = kappa()
    res = [fam.vy[_E10] - 1, yc - fam.alpha * (lam - L0),
           (lam - fmpq(1, 2)) * y(0, (1, 0)) - yc / 2,
           (lam - fmpq(1, 8)) * y(0, (2, 0)) - fmpq(3, 4) * y(0, (1, 0)) - yc / 8]
    for i, pos in enumerate(TWO_RING):
        acc = kap[i] * yc - lam * y(1, pos)
        for (d, q), x in ring_stencil()[i].items():
            acc += x * y(1 + d, q)
        res.append(acc)
    for k, z in enumerate(res):
        if not (z.contains(0) and abs(z) < tol):
            raise CertificateError(f"the family misses identity {k} of the eigenvector lemma "
                                   "(pivot, centre value, sharp midpoint, crease vertex, ring rows of sector 1)")


def check_eigenvector(sig_lo, sig_hi, k0, prec, balls=64, family=Family):
    """Show that for every K >= k0 the family member of :mod:`.dart_family` at sigma = sigma(K) is the
    eigenvector of lam2 (and x the mode-1 eigenvector of lam1): the argument of the module docstring.

    Parameters
    ----------
    sig_lo, sig_hi : fmpq
        The bracket of sigma(K), pi < sig_lo < sig_hi < 2 pi (the record's; sig_hi < sigma_r is checked with
        the spectrum).
    k0 : int
        K0 >= 7 (the windows of item 1c).
    prec : int
        arb precision in bits.
    balls : int
        Equal h-balls covering [0, 1/k0].
    family : callable
        ``family(h, sigma)`` -> a Family (tests pass perturbed families).

    Returns
    -------
    str
        One line: what was shown, with counts.

    Raises
    ------
    CertificateError
        With the reason.

    Examples
    --------
    >>> from flint import fmpq
    >>> check_eigenvector(fmpq(4484, 1000), fmpq(44935, 10000), 101, 128).split(":")[0]
    'eigenvector lemma for every K >= 101'
    """
    sig_lo, sig_hi = fmpq(sig_lo), fmpq(sig_hi)
    if k0 < 7 or balls < 1:
        raise CertificateError(f"eigenvector lemma: K0 = {k0} < 7 or no h-balls")
    with ctx.workprec(prec):
        pi = arb.pi()
        if not (arb(sig_lo) > pi and arb(sig_hi) < 2 * pi and sig_lo < sig_hi):
            raise CertificateError("eigenvector lemma: the bracket is not inside (pi, 2 pi)")
        check_ring()
        check_reach()
        check_mode0()
        check_crease_row()
        box = ball(sig_lo, sig_hi)
        if not box.cos() < 0:
            raise CertificateError("eigenvector lemma: cos(sigma) is not certainly < 0 on the bracket (alpha != 0)")
        tol = arb(2) ** (-(prec // 2))
        for i in range(balls):
            h = acb(ball(fmpq(i, balls * k0), fmpq(i + 1, balls * k0)))
            try:
                _guard(family(acb(fmpq(2 * i + 1, 2 * balls * k0)), arb(sig_lo)), tol)  # at the ball's centre
                vals = [scaled_centre_residual(family(h, s)) for s in (arb(sig_lo), arb(sig_hi), box)]
            except ZeroDivisionError as exc:
                raise CertificateError(f"eigenvector lemma: h-ball {i}: {exc}") from None
            lo, hi = vals[0].real, vals[1].real
            if not (lo > 0 > hi or lo < 0 < hi):
                raise CertificateError(f"eigenvector lemma: h-ball {i}: the centre residual r/h has no certain sign "
                                       f"change over the bracket (at sig_lo {lo.str(3)}, at sig_hi {hi.str(3)})")
        return (f"eigenvector lemma for every K >= {k0}: ring rows and ray 0's rows identically (exact: reach, "
                f"mode 0, crease row at {W_POINTS} w), centre residual changes sign on ({sig_lo}, {sig_hi}) on "
                f"{balls} h-balls, the family (x's and y's bordered systems, U, alpha) regular on the whole bracket")


__all__ = ["W_POINTS", "check_crease_row", "check_eigenvector", "check_mode0", "check_reach",
           "scaled_centre_residual"]
