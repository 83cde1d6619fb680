"""Every ``crease:N`` (or ``corner:N``) with N >= N0 in one "not C1" certificate (trusted).

The witness of ``crease:N``, N >= 5 (:mod:`.tagged_c1`), has the same shape for every N: x and y the
real eigenvectors of the modes 1 and 2 (alpha = lam(cos theta), beta = lam(cos 2 theta), theta = pi/N,
lam(c) = (5 + c + sqrt((1 + c)(9 + c)))/16), z the crease tangent of gamma = 1/2, ray 0, quadrant 0.
This module checks each of its parts for every N >= N0 at once (docs/tagged_c1.md, "Every N >= N0"):

1. **S for every N from one window.** Each row of S is the translate of one stencil that depends on the
   point's position and on how far it is from the sharp rays 0 and N (the ring stencil reaches the
   sectors t - 1 .. t + 2, :func:`.tagged_modes.check_ring`): on its window class
   (min(t, 3), min(N - t, 3)). :func:`check_windows` checks that the rows of ``crease:7`` and
   ``crease:8``, written relative to their point, are one row per class, the same in both, summing to 1,
   with the same crease block C, and the folded-ring identity of :func:`.tagged_modes.check_structure`
   for both; every class of an N >= 7 occurs there. So for every N >= 7, S = [[C, 0], [X, I]] with I the
   smooth ring rule on the odd vectors, and the blocks of the modes w = +-1 are those of N = 7.
2. **Spectrum and G for every N** (:func:`uniform_spectrum`). spec(S) = spec(C) + spec(M_+1) + spec(M_-1) +
   for j = 1..N-1 {1/8, 1/16, 1/32, 1/64} and the roots lam(c_j), 1/(16 lam(c_j)) of
   q_c(x) = x^2 - (5 + c) x/8 + 1/16, c_j = cos(j theta). lam is strictly increasing on [-1, 1]
   (5 + c and (1 + c)(9 + c) are), lam(-1) = 1/4, so 1/(16 lam(c_j)) < 1/4 and lam(c_1) > lam(c_2) >
   lam(c_j), j >= 3; beta = lam(c_2) >= b0 = lam(cos(2 pi/N0)). Checked: every other entry (C's but 1,
   the blocks', the constants, the bound 1/4) is certainly below b0, gamma < b0, lam(1) < 1, 1 simple in
   C and no root of the blocks or of any q_c (c <= 1). A rational g is a root of q_c only at
   c*(g) = 8 g + 1/(2 g) - 5, so at most one mode has it, and simply unless (1 + c*)(9 + c*) = 0: then
   gamma is at most a simple eigenvalue of I, and z exists (as in :mod:`.tagged_c1`).
3. **Part N as one analytic function.** Let v^(s) solve the bordered 6 x 6 system of B(w), w = e^(i s),
   for lam(cos s) with v^(1,0) = 1, f(s) the values of v - v o R at the nine points of the (1,1) vertex
   of quadrant 0, and H(theta) = T_a(f(theta)) T_b(f(2 theta)) - T_b(f(theta)) T_a(f(2 theta)). For real
   theta = pi/N, f(j theta) is a non-zero complex multiple of the real eigenvector of mode j, so the
   witness's J_xy != 0 iff H(pi/N) != 0.
4. **H(theta) = O(theta^4).** The exact identity B(1/w) R_w = R_w B(w) (:func:`reflection_identity`;
   R_w: ray p -> v^(p), quadrant (a, b) -> v^(b, a)/w, the reflection in ray 0 on the modes) and the
   uniqueness of the bordered solution give v^(-s) = R_w v^(s), hence f(-s) = -f(s):
   (T_a, T_b)(f(s)) = s g(s) with g even and H(theta) = 2 theta^2 g(theta) x g(2 theta), an even
   function vanishing at 0: a zero of order >= 4 at 0 (or H = 0).
5. **No other zero for |theta| < rho.** H is analytic where both bordered systems are regular and
   (1 + c)(9 + c) has a positive real part (principal root): :func:`check_disc` proves it on acb boxes
   covering |theta| <= R. :func:`circle_bound` bounds |H| <= M on |theta| = R, so |H'| <= M R/(R - rho)^2
   on |theta| = rho (Cauchy). :func:`winding` checks on each of ``arcs`` arcs of |theta| = rho that
   |H'| * (arc length) < |H(z_k)| (the arc's image lies in a disc about H(z_k) that misses 0, so its turn
   is the principal argument of H(z_(k+1))/H(z_k)) and that the total turn / 2 pi is certainly in
   (3.5, 4.5). By the argument principle the order-4 zero at 0 is H's only zero in |theta| < rho, so
   J_xy != 0 for every N with pi/N < rho: rho > pi/N0 is checked.

The corner witness uses the same x, y, quadrant and ray (only z and C differ), so parts 3 to 5 serve both
families. The hints (rho, R, the arc counts, the box side) only choose where to subdivide: the verifier
derives every claim above itself.
"""

from __future__ import annotations

from functools import cache

from flint import acb, arb, ctx, fmpq, fmpq_mat

from .c1 import read_prec
from .errors import CertificateError
from .record import exact_keys, field_of
from .replay import parse_decimal
from .spectrum import RING_INDEX, SMALL_ROOTS, ring_block
from .statement import lam_of
from .tagged import crease_block, crease_points, labels, window_rows
from .tagged_c1 import G_GENERIC, check_boundary, crease_eigen_why, read_z, vertex_tangents
from .tagged_modes import bordered_solve, charpoly_roots, check_ring, check_structure, mode_reflection

WINDOW = (7, 8)  # the window classes of every N >= 7 occur in both
MIN_TAIL = WINDOW[0]
MAX_ARCS = 8192  # arcs on either circle, and boxes on the disc (bounded work for a hostile file)
# evaluations of H (arcs on both circles, boxes on the disc) weighted by (prec + 1024)/1024, checked before any
# arithmetic: the published certificates need 3,042, the prover's widest hints (every N0 >= 7) about 21,000;
# at the budget a file costs about 5 s of CPU
TAIL_BUDGET = 3 * 8192
_LIMIT_KEYS = ("rho", "R", "arcs", "outer_arcs", "box")
_PIVOT = RING_INDEX[(1, 0)]


@cache
def check_windows(fam):
    """Raise unless the rows of fam:7 and fam:8 are one row per window class, the same in both (module
    docstring, part 1), summing to 1, with the same crease block and the folded-ring structure.

    Returns
    -------
    tuple of flint.fmpq_mat
        The crease block C and the blocks of the modes w = +-1 on their odd vectors (the same for every N).

    Examples
    --------
    >>> C, *blocks = check_windows("crease")
    >>> C.nrows(), [M.nrows() for M in blocks]
    (5, [1, 3])
    """
    if fam not in ("crease", "corner"):
        raise CertificateError(f"{fam}: the interval certificate is defined for crease and corner sectors")
    a, b = (window_rows(fam, n) for n in WINDOW)
    if a != b:
        raise CertificateError(f"{fam}: the window classes of {fam}:{WINDOW[0]} and {fam}:{WINDOW[1]} differ")
    if any(sum(row.values(), fmpq(0)) != 1 for row in a.values()):
        raise CertificateError(f"{fam}: a row does not sum to 1")
    blocks = [check_structure(fam, n) for n in WINDOW]
    C = crease_block(fam, WINDOW[0])
    if C != crease_block(fam, WINDOW[1]) or blocks[0] != blocks[1]:
        raise CertificateError(f"{fam}: the crease block or the blocks of the modes +-1 depend on N")
    return (C,) + tuple(blocks[0])


@cache
def reflection_identity():
    """Is B(1/w) R_w = R_w B(w) an identity of Laurent polynomials in w (exact)?

    The ring stencil reaches w^-1 .. w^2 (:func:`.tagged_modes.check_ring`) and R_w holds 1 and 1/w, so
    w^3 times the difference is a polynomial of degree <= 5: zero at the 12 points checked, it is zero.

    Examples
    --------
    >>> reflection_identity()
    True
    """
    check_ring()
    for w in (fmpq(a, b) for a in (1, 2, 3, -1, -2, -3) for b in (1, 5)):
        B, Bi, R = (fmpq_mat(m) for m in (ring_block(w), ring_block(1 / w), mode_reflection(w)))
        if Bi * R != R * B:
            return False
    return True


def _tangents(theta, j):
    """(T_a, T_b) of f(j theta) at the (1,1) vertex of quadrant 0 (acb); raises ZeroDivisionError unless
    (1 + c)(9 + c) certainly has a positive real part and the bordered system is certainly regular."""
    w = (acb(0, j) * theta).exp()
    c = (w + 1 / w) / 2
    disc = (1 + c) * (9 + c)
    if not disc.real > 0:
        raise ZeroDivisionError("(1 + c)(9 + c) is not certainly in the right half-plane")
    lam = lam_of(c)
    sol = bordered_solve(ring_block(w), lam, _PIVOT)
    vh = {p: sol[i] for p, i in RING_INDEX.items()}
    val = {}
    for a in range(3):
        for b in range(3):  # the centre and ray 0: 0; ray 1: v^(b,0)(w - 1/w); quadrant 0: v^(a,b) - v^(b,a)/w
            val[a, b] = (acb(0) if b == 0 else vh[(b, 0)] * (w - 1 / w) if a == 0 else vh[(a, b)] - vh[(b, a)] / w)
    return vertex_tangents(val)


def limit_h(theta):
    """H(theta) (module docstring, part 3) for an acb ball theta; ZeroDivisionError where not proved analytic.

    Examples
    --------
    H(pi/N) / theta^4 tends to about 1.37136:

    >>> th = arb.pi() / 1000
    >>> (limit_h(acb(th)) / th ** 4).real.str(5, radius=False)
    '1.3714'
    """
    a1, b1 = _tangents(theta, 1)
    a2, b2 = _tangents(theta, 2)
    return a1 * b2 - b1 * a2


def check_disc(R, side):
    """The number of boxes of the grid of ``side`` that meet |theta| <= R, each proved (H analytic there),
    or the failing box as a string.

    Examples
    --------
    >>> check_disc(fmpq(1, 10), fmpq(1, 10))
    4
    """
    m = int(-(-R.p * side.q // (R.q * side.p)))  # ceil(R / side)
    count = 0
    for u in range(-m, m):
        for v in range(-m, m):
            lo = (u * side, v * side)
            near = [0 if x <= 0 <= x + side else min(abs(x), abs(x + side)) for x in lo]
            if near[0] ** 2 + near[1] ** 2 > R * R:
                continue
            box = acb(*(arb(x).union(arb(x + side)) for x in lo))
            try:
                limit_h(box)
            except ZeroDivisionError:
                return f"[{lo[0]}, {lo[0] + side}] x [{lo[1]}, {lo[1] + side}]"
            count += 1
    return count


def _on_circle(radius, k, arcs):
    return acb(arb(0), arb(2 * k) / arcs * arb.pi()).exp() * radius


def circle_bound(R, arcs):
    """An upper bound M of |H| on |theta| = R (acb balls covering the arcs), or None if one is not proved.
    Not :func:`~ccproof.rigorous.analytic.disc_bound`: its square [-R, R]^2 reaches outside the disc that
    :func:`check_disc` proves analytic; with boxes of side 1/20 it bounds |H| by 47.3 where the arcs give 0.0261.

    Examples
    --------
    The balls overestimate (H is O(theta^4) from products of O(theta) terms): 2048 arcs give 0.0261.

    >>> circle_bound(fmpq(3, 10), 256) < fmpq(1, 5), circle_bound(fmpq(3, 10), 2048) < fmpq(3, 100)
    (True, True)
    """
    top = arb(0)
    for k in range(arcs):
        ball = acb(arb(0), (arb(2 * k + 1) + arb(0, 1)) / arcs * arb.pi()).exp() * R  # covers arc k
        try:
            top = top.max(arb(abs(limit_h(ball)).upper()))
        except ZeroDivisionError:
            return None
    return top


def winding(rho, arcs, R, M):
    """(the winding number of H along |theta| = rho (an arb ball), None) or (None, the reason).

    Examples
    --------
    >>> wn, why = winding(fmpq(1, 5), 512, fmpq(3, 10), arb("0.0261"))
    >>> wn.contains(4), why
    (True, None)
    >>> winding(fmpq(1, 5), 256, fmpq(3, 10), arb("0.0261"))[1][:37]
    "arc 0 of 256: |H'| * length = [0.0038"
    """
    slope = M * R / (R - rho) ** 2  # |H'| on |theta| = rho (Cauchy on |theta| = R)
    length = 2 * arb.pi() * rho / arcs
    vals = [limit_h(_on_circle(rho, k, arcs)) for k in range(arcs + 1)]
    turn = arb(0)
    for k, (h0, h1) in enumerate(zip(vals, vals[1:])):
        if not slope * length < abs(h0):
            return None, f"arc {k} of {arcs}: |H'| * length = {(slope * length).str(3)} is not below |H| = " \
                         f"{abs(h0).str(3)} (its image may touch 0)"
        turn += (h1 / h0).arg()
    return turn / (2 * arb.pi()), None


def _in_modes(x):  # is x a root of some q_c, c in [-1, 1]? c*(x) = 8 x + 1/(2 x) - 5
    return x != 0 and -1 <= 8 * x + 1 / (2 * x) - 5 <= 1


def _leading_gap(croots, below, blocks, others, b0, n0):
    """Why 1 is not simple or alpha, beta do not lead (None when they do)."""
    if croots.count(1) != 1 or len(below) != 4:
        return "eigenvalue 1 is not simple in the crease block"
    if _in_modes(fmpq(1)) or any(M.charpoly()(1) == 0 for M in blocks):
        return "1 is an eigenvalue of the modes"
    if not lam_of(arb(1)) < 1:
        return "lam(1) < 1 is not certain"
    if not all(x < b0 for x in others):
        return f"an eigenvalue other than alpha, beta is not certainly below lam(cos(2 pi/{n0}))"
    return None


def _gamma_gap(g, cg, below, blocks, b0, n0):
    """Why gamma = g is not the crease block's largest eigenvalue below 1, simple and below beta (or None)."""
    if g != max(below):
        return f"gamma is not the crease block's largest eigenvalue below 1 ({max(below)})"
    if not arb(g) < b0:
        return f"gamma < lam(cos(2 pi/{n0})) is not certain"
    if g in SMALL_ROOTS or cg is None or (1 + cg) * (9 + cg) == 0 or any(M.charpoly()(g) == 0 for M in blocks):
        return "gamma is possibly a multiple eigenvalue of I"
    return None


def uniform_spectrum(fam, n0, g, C, blocks):
    """(ok, message): part 2 of the module docstring for every N >= n0 with gamma = g (exact)."""
    fac = C.charpoly().factor()[1]
    if any(p.degree() > 1 for p, _ in fac):
        return False, "the crease block has irrational eigenvalues"
    croots = [r for p, e in fac for r in [-p[0] / p[1]] * e]
    below = [r for r in croots if r < 1]
    b0 = lam_of(arb(fmpq(2, n0)).cos_pi())  # <= beta = lam(cos(2 pi/N)) for every N >= n0
    inner = [z for M in blocks for z, _ in charpoly_roots(M)]
    others = [arb(abs(r)) for r in below] + [abs(z) for z in inner] + [arb(s) for s in SMALL_ROOTS] + [arb(fmpq(1, 4))]
    cg = 8 * g + 1 / (2 * g) - 5 if g != 0 else None
    why = _leading_gap(croots, below, blocks, others, b0, n0) or _gamma_gap(g, cg, below, blocks, b0, n0)
    if why is not None:
        return False, f"every N >= {n0}: {why}"
    return True, (f"every N >= {n0}: alpha = lam(cos(pi/N)) > beta = lam(cos(2 pi/N)) >= {b0.str(6, radius=False)} > "
                  f"every other eigenvalue (<= {max(others, key=lambda x: x.mid()).str(4)}, each simple), 1 simple "
                  f"(crease block); gamma = {g} < beta, at most simple in I (only at c = {cg})")


def verify_tail(cert, fam, n0, part, log):
    """Check a ``"FAMILY:>=N0"`` "not C1" certificate (module docstring) into ``part``.

    Parameters
    ----------
    cert : dict
        ``schema``, ``configuration``, ``statement`` ("not C1": the only statement the registry routes here),
        ``prec``, ``witness`` ({"z": coord}) and
        ``limit`` ({"rho", "R", "box": decimals, "arcs", "outer_arcs": ints}).

    Returns
    -------
    str
        The configuration name (for the verdict).

    Raises
    ------
    CertificateError
        On a malformed certificate.

    Examples
    --------
    >>> import json
    >>> from ccproof.tables.format import certificates_dir
    >>> from ccproof.certify.verify.record import Recorder, VerifyResult
    >>> cert = json.loads((certificates_dir() / "c1" / "crease" / "n_ge_101.json").read_text())
    >>> res = VerifyResult()
    >>> verify_tail(cert, "crease", 101, Recorder(res, lambda line: None), lambda line: None), bool(res)
    ('crease:>=101', True)
    """
    if not MIN_TAIL <= n0 <= 10**6:
        raise CertificateError(f"{fam}:>={n0}: the window argument needs N0 >= {MIN_TAIL}")
    exact_keys(cert, ("schema", "configuration", "statement", "prec", "witness", "limit"), "certificate")
    prec = read_prec(cert)
    w = field_of(cert, "witness", dict, "certificate")
    exact_keys(w, ("z",), "witness")
    g, cval = read_z(field_of(w, "z", dict, "witness"))
    lim = field_of(cert, "limit", dict, "certificate")
    exact_keys(lim, _LIMIT_KEYS, "limit")
    rho, R, side = (parse_decimal(field_of(lim, k, str, "limit")) for k in ("rho", "R", "box"))
    arcs, outer = (field_of(lim, k, int, "limit") for k in ("arcs", "outer_arcs"))
    if not (1 <= arcs <= MAX_ARCS and 1 <= outer <= MAX_ARCS and 0 < rho < R <= 1 and 0 < side <= R
            and (2 * R / side + 2) ** 2 <= MAX_ARCS):
        raise CertificateError(f"limit: need 0 < rho < R <= 1, 0 < box <= R, at most {MAX_ARCS} arcs and boxes")
    evals = arcs + outer + (2 * ((R / side).ceil())) ** 2  # at most (2 ceil(R/box))^2 boxes meet the disc
    if evals * fmpq(prec + 1024, 1024) > TAIL_BUDGET:
        raise CertificateError(f"limit: {evals} evaluations of H at {prec} bits exceed the budget "
                               f"({TAIL_BUDGET} weighted by (prec + 1024)/1024)")
    name = f"{fam}:>={n0}"
    log(f"not C1 certificate for {name} ({prec} bits)")
    with ctx.workprec(prec):
        _check_tail(fam, n0, g, cval, (rho, R, side, arcs, outer), part, log)
    return name


def _check_tail(fam, n0, g, cval, limit, part, log):
    C, *blocks = check_windows(fam)
    part("S sector matrices of every N >= 7 from one window", True,
         f"{fam}:7 and {fam}:8: one row per window class (min(t, 3), min(N - t, 3)), the same in both, rows sum "
         "to 1; crease block and odd blocks of the modes +-1 equal; non-crease rows the folded ring rule (exact)")
    rho = limit[0]
    ok = rho > arb.pi() / n0
    part(f"range: pi/N < rho for every N >= {n0}", ok, f"rho = {rho} > pi/{n0}" if ok else
         f"rho = {rho} is not certainly above pi/{n0} = {(arb.pi() / n0).str(6)}")
    why = crease_eigen_why(C, g, cval)
    part("z: (generalized) eigenvector of S", why is None,
         why or f"C c = {g} c exactly on the crease points (the same C for every N)")
    if part.failed:
        return
    ok, msg = uniform_spectrum(fam, n0, g, C, blocks)
    part(G_GENERIC, ok, msg)
    if not ok:
        return
    cp = crease_points(fam, WINDOW[0])
    zero = [fmpq(0) if i in cp else None for i in range(len(labels(fam, WINDOW[0])))]
    vecs = {"x": zero, "y": zero, "z": [cval[cp.index(i)] if i in cp else None for i in range(len(zero))]}
    check_boundary(fam, WINDOW[0], 0, vecs, part)  # reads the crease points only: the same for every N
    ok = reflection_identity()
    part("N reflection: B(1/w) R_w = R_w B(w) (exact), so f is odd and H has a zero of order >= 4 at 0", ok,
         "" if ok else "the ring stencil breaks the reflection identity")
    if not part.failed:
        _check_normal(fam, n0, limit, part, log)


def _check_normal(fam, n0, limit, part, log):
    """N for every N >= n0: H analytic on the disc |theta| <= R, bounded on its circle, winding 4 times
    (``limit`` the record's (rho, R, box, arcs, outer_arcs))."""
    rho, R, side, arcs, outer = limit
    got = check_disc(R, side)
    ok = isinstance(got, int)
    part(f"x, y and N analytic: the bordered systems of modes 1 and 2 regular on |theta| <= {R}", ok,
         f"{got} boxes of side {side}, (1 + c)(9 + c) in the right half-plane: x, y = f(pi/N), f(2 pi/N) are the "
         "eigenvectors of alpha, beta for every N >= 7 and H is analytic on the disc" if ok else
         f"box {got}: not proved regular, or (1 + c)(9 + c) not certainly in the right half-plane")
    if not ok:
        return
    M = circle_bound(R, outer)
    part(f"N bound: |H| <= M on |theta| = {R}", M is not None,
         f"M = {M.str(5, radius=False)} ({outer} arc balls)" if M is not None else "an arc ball is not proved")
    if M is None:
        return
    wn, why = winding(rho, arcs, R, M)
    ok = wn is not None and wn > fmpq(7, 2) and wn < fmpq(9, 2)
    part(f"N winding: H winds 4 times around 0 along |theta| = {rho}, so J_xy != 0 for every N >= {n0}", ok,
         f"{wn.str(6)} ({arcs} arcs, each image in a disc off 0: |H'| <= M R/(R - rho)^2)" if ok else
         why or f"the winding number {wn.str(6)} is not certainly 4")
    if not part.failed:
        log(f"  the limit surface is not C1 at the {fam} vertex for every N >= {n0}: normals along the level-m "
            "copies of quadrant 0's (1,1) tend to n_z != 0, yet e_z lies in T_v (ray 0)")


__all__ = ["MIN_TAIL", "check_disc", "check_windows", "circle_bound", "limit_h", "reflection_identity",
           "uniform_spectrum", "verify_tail", "winding"]
