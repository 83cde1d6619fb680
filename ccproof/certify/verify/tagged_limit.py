"""Every crease:N or corner:N with N >= N0 in one "not C1" certificate (trusted; docs/tagged_c1.md, "Every N >= N0 in
one certificate", parts 1-5): S from the window of N = 7, 8, the spectrum uniformly in N, part N as the zeros of
one analytic function H(theta) (the reflection identity, H analytic on acb boxes, a Cauchy bound, winding number 4).
"""

from __future__ import annotations

from functools import cache

from flint import acb, arb, ctx, fmpq, fmpq_mat

from ccproof.rigorous.analytic import disc_boxes

from .c1 import read_prec
from .errors import CertificateError
from .spectrum import RING_INDEX, SMALL_ROOTS, ring_block
from .statement import lam_of
from .tagged import DECIMAL, WINDOW, crease_block, read_fields, window_classes
from .tagged_c1 import G_GENERIC, check_boundary, crease_eigen_why, crease_top_why, read_z, vertex_tangents
from .tagged_modes import (
    bordered_solve,
    charpoly_roots,
    check_ring,
    check_structure,
    mode_reflection,
    off_cut,
)

MIN_TAIL = WINDOW[0]
MAX_ARCS = 8192  # arcs on either circle, and boxes on the disc (bounded work for a hostile file)
# evaluations of H weighted by (prec + 1024)/1024, checked before any arithmetic: the published need 3,042, the
# prover's widest hints (every N0 >= 7) about 21,000; at the budget a file costs about 5 s of CPU
TAIL_BUDGET = 3 * 8192
#: the record's fields (:func:`.tagged.read_fields`; ``prec`` by :func:`.c1.read_prec`, ``z`` by
#: :func:`.tagged_c1.read_z`); the limit's values in this order
GRAMMAR = {"schema": str, "configuration": str, "statement": str, "prec": int, "witness": {"z": dict},
           "limit": {"rho": DECIMAL, "R": DECIMAL, "box": DECIMAL, "arcs": (1, MAX_ARCS), "outer_arcs": (1, MAX_ARCS)}}


@cache
def check_windows(fam):
    """Raise unless the rows of fam:7 and fam:8 are one row per window class, the same in both, summing to 1, with
    the same crease block and folded-ring structure (part 1); the crease block C and the blocks of the modes +-1.

    >>> C, *blocks = check_windows("crease")
    >>> C.nrows(), [M.nrows() for M in blocks]
    (5, [1, 3])
    """
    if fam not in ("crease", "corner"):
        raise CertificateError(f"{fam}: the interval certificate is defined for crease and corner sectors")
    if any(sum(row.values(), fmpq(0)) != 1 for row in window_classes(fam).values()):
        raise CertificateError(f"{fam}: a row does not sum to 1")
    blocks = [check_structure(fam, n) for n in WINDOW]
    C = crease_block(fam, WINDOW[0])
    if C != crease_block(fam, WINDOW[1]) or blocks[0] != blocks[1]:
        raise CertificateError(f"{fam}: the crease block or the blocks of the modes +-1 depend on N")
    return (C,) + tuple(blocks[0])


@cache
def reflection_identity():
    """Is B(1/w) R_w = R_w B(w) an identity of Laurent polynomials in w (exact)? w^3 times the difference is a
    polynomial of degree <= 5 (the stencil reaches w^-1 .. w^2, R_w holds 1 and 1/w): zero at 12 points, zero."""
    check_ring()
    for w in (fmpq(a, b) for a in (1, 2, 3, -1, -2, -3) for b in (1, 5)):
        B, Bi, R = (fmpq_mat(m) for m in (ring_block(w), ring_block(1 / w), mode_reflection(w)))
        if Bi * R != R * B:
            return False
    return True


def limit_h(theta):
    """H(theta) = J_xy of f(theta), f(2 theta) at the (1,1) vertex of quadrant 0 for an acb ball theta (part 3);
    ZeroDivisionError unless each (1 + c)(9 + c) certainly has a positive real part and each bordered system is
    certainly regular (H analytic there). H(pi/N)/theta^4 tends to about 1.37136:

    >>> th = arb.pi() / 1000
    >>> (limit_h(acb(th)) / th ** 4).real.str(5, radius=False)
    '1.3714'
    """
    tangents = []
    for j in (1, 2):
        w = (acb(0, j) * theta).exp()
        c = (w + 1 / w) / 2
        sol = bordered_solve(ring_block(w), lam_of(off_cut(c)), RING_INDEX[(1, 0)])
        vh = {p: sol[i] for p, i in RING_INDEX.items()}
        # the centre and ray 0: 0; ray 1: v^(b,0)(w - 1/w); quadrant 0: v^(a,b) - v^(b,a)/w
        tangents.append(vertex_tangents({(a, b): acb(0) if b == 0 else vh[(b, 0)] * (w - 1 / w) if a == 0 else
                                         vh[(a, b)] - vh[(b, a)] / w for a in range(3) for b in range(3)}))
    (a1, b1), (a2, b2) = tangents
    return a1 * b2 - b1 * a2


def _check_disc(R, grid):
    """The number of boxes of the grid x grid grid on [-R, R]^2 that meet |theta| <= R (:func:`disc_boxes`), each
    proved (H analytic there), or the failing box as a string."""
    boxes = list(disc_boxes(R, grid))
    for box in boxes:
        try:
            limit_h(box)
        except ZeroDivisionError:
            return str(box)
    return len(boxes)


def _circle_bound(R, arcs):
    """An upper bound M of |H| on |theta| = R from acb balls covering ``arcs`` arcs, or None if one is not proved (not
    :func:`~ccproof.rigorous.analytic.disc_bound`: its square leaves the disc that the disc check proves)."""
    top = arb(0)
    for k in range(arcs):
        ball = acb(arb(0), (arb(2 * k + 1) + arb(0, 1)) / arcs * arb.pi()).exp() * R  # covers arc k
        try:
            top = top.max(arb(abs(limit_h(ball)).upper()))
        except ZeroDivisionError:
            return None
    return top


def _winding(rho, arcs, R, M):
    """(the winding number of H along |theta| = rho (an arb ball), None) or (None, the reason); each arc's image lies
    in a disc about H(z_k) that misses 0 (|H'| <= M R/(R - rho)^2 by Cauchy)."""
    step = M * R / (R - rho) ** 2 * 2 * arb.pi() * rho / arcs  # |H'| on |theta| = rho times an arc's length
    vals = [limit_h(acb(arb(0), arb(2 * k) / arcs * arb.pi()).exp() * rho) for k in range(arcs + 1)]
    turn = arb(0)
    for k, (h0, h1) in enumerate(zip(vals, vals[1:])):
        if not step < abs(h0):
            return None, f"arc {k} of {arcs}: |H'| * length = {step.str(3)} is not below |H| = {abs(h0).str(3)} " \
                         "(its image may touch 0)"
        turn += (h1 / h0).arg()
    return turn / (2 * arb.pi()), None


def _uniform_spectrum(fam, n0, g, C, blocks):
    """(ok, message): part 2 for every N >= n0 with gamma = g (exact): 1 simple, alpha and beta lead, gamma the crease
    block's largest eigenvalue below 1, at most simple in I and below beta."""
    why = crease_top_why(C, g)
    if why is None:  # the crease block's roots are rational
        croots = [q for _, q in charpoly_roots(C)]
        below = [r for r in croots if r < 1]
        b0 = lam_of(arb(fmpq(2, n0)).cos_pi())  # <= beta = lam(cos(2 pi/N)) for every N >= n0
        others = [arb(abs(r)) for r in below] + [abs(z) for M in blocks for z, _ in charpoly_roots(M)] + [
            arb(s) for s in SMALL_ROOTS] + [arb(fmpq(1, 4))]
        why, cg = _gap(croots, below, blocks, others, g, b0, n0)
    if why is not None:
        return False, f"every N >= {n0}: {why}"
    return True, (f"every N >= {n0}: alpha = lam(cos(pi/N)) > beta = lam(cos(2 pi/N)) >= {b0.str(6, radius=False)} > "
                  f"every other eigenvalue (<= {max(others, key=lambda x: x.mid()).str(4)}, each simple), 1 simple "
                  f"(crease block); gamma = {g} < beta, at most simple in I (only at c = {cg})")


def _gap(croots, below, blocks, others, g, b0, n0):
    """(the first reason 1 is not simple, alpha and beta do not lead, or gamma = g is not simple in I and below
    beta, or None; c*(g))."""
    cstar = lambda x: 8 * x + 1 / (2 * fmpq(x)) - 5  # a rational x != 0 is a root of q_c only at c = c*(x)
    cg = cstar(g) if g != 0 else None
    return next((why for bad, why in (
        (lambda: croots.count(1) != 1 or len(below) != 4, "eigenvalue 1 is not simple in the crease block"),
        (lambda: -1 <= cstar(1) <= 1 or any(M.charpoly()(1) == 0 for M in blocks), "1 is an eigenvalue of the modes"),
        (lambda: not lam_of(arb(1)) < 1, "lam(1) < 1 is not certain"),
        (lambda: not all(x < b0 for x in others),
         f"an eigenvalue other than alpha, beta is not certainly below lam(cos(2 pi/{n0}))"),
        (lambda: not arb(g) < b0, f"gamma < lam(cos(2 pi/{n0})) is not certain"),
        (lambda: g in SMALL_ROOTS or cg is None or (1 + cg) * (9 + cg) == 0 or any(M.charpoly()(g) == 0
                                                                                    for M in blocks),
         "gamma is possibly a multiple eigenvalue of I")) if bad()), None), cg


def verify_tail(cert, fam, n0, part, log):
    """Check a ``"FAMILY:>=N0"`` "not C1" certificate (``witness`` {"z"}, ``limit`` {"rho", "R", "box": decimals,
    "arcs", "outer_arcs": ints}) into ``part``; the configuration name, or CertificateError on a malformed one.

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
    prec = read_prec(cert)
    rec = read_fields(cert, GRAMMAR, "certificate")
    g, cval = read_z(rec["witness"]["z"])
    rho, R, side, arcs, outer = rec["limit"].values()
    if not (0 < rho < R <= 1 and 0 < side <= R and (grid := 2 * R / side).q == 1 and grid ** 2 <= MAX_ARCS):
        raise CertificateError(f"limit: need 0 < rho < R <= 1, 0 < box <= R, 2R/box an integer, at most {MAX_ARCS} "
                               "boxes")
    evals = arcs + outer + grid ** 2  # at most grid^2 boxes meet the disc
    if evals * fmpq(prec + 1024, 1024) > TAIL_BUDGET:
        raise CertificateError(f"limit: {evals} evaluations of H at {prec} bits exceed the budget "
                               f"({TAIL_BUDGET} weighted by (prec + 1024)/1024)")
    log(f"not C1 certificate for {fam}:>={n0} ({prec} bits)")
    with ctx.workprec(prec):
        _check_tail(fam, n0, g, cval, (rho, R, side, arcs, outer, int(grid.p)), part, log)
    return f"{fam}:>={n0}"


def _check_tail(fam, n0, g, cval, limit, part, log):  # parts 1-5 in order, each only after the previous held
    C, *blocks = check_windows(fam)
    part("S sector matrices of every N >= 7 from one window", True, f"{fam}:7 and {fam}:8: one row per window class "
         "(min(t, 3), min(N - t, 3)), the same in both, rows sum to 1; crease block and odd blocks of the modes +-1 "
         "equal; non-crease rows the folded ring rule (exact)")
    ok = limit[0] > arb.pi() / n0
    part(f"range: pi/N < rho for every N >= {n0}", ok, f"rho = {limit[0]} > pi/{n0}" if ok else
         f"rho = {limit[0]} is not certainly above pi/{n0} = {(arb.pi() / n0).str(6)}")
    why = crease_eigen_why(C, g, cval)
    part("z: (generalized) eigenvector of S", why is None,
         why or f"C c = {g} c exactly on the crease points (the same C for every N)")
    if not part.failed:
        part(G_GENERIC, *_uniform_spectrum(fam, n0, g, C, blocks))
    if part.failed:
        return
    check_boundary(fam, WINDOW[0], 0, (), cval, part)  # x, y are 0 on the crease points: the same for every N
    ok = reflection_identity()
    part("N reflection: B(1/w) R_w = R_w B(w) (exact), so f is odd and H has a zero of order >= 4 at 0", ok,
         "" if ok else "the ring stencil breaks the reflection identity")
    if part.failed:  # N for every N >= n0: H analytic on |theta| <= R, bounded on its circle, winding 4 times
        return
    rho, R, side, arcs, outer, grid = limit
    got = _check_disc(R, grid)
    ok = isinstance(got, int)
    part(f"x, y and N analytic: the bordered systems of modes 1 and 2 regular on |theta| <= {R}", ok,
         f"{got} boxes of side {side}, (1 + c)(9 + c) in the right half-plane: x, y = f(pi/N), f(2 pi/N) are the "
         "eigenvectors of alpha, beta for every N >= 7 and H is analytic on the disc" if ok else
         f"box {got}: not proved regular, or (1 + c)(9 + c) not certainly in the right half-plane")
    if not ok:
        return
    M = _circle_bound(R, outer)
    part(f"N bound: |H| <= M on |theta| = {R}", M is not None,
         f"M = {M.str(5, radius=False)} ({outer} arc balls)" if M is not None else "an arc ball is not proved")
    if M is None:
        return
    wn, why = _winding(rho, arcs, R, M)
    ok = wn is not None and wn > fmpq(7, 2) and wn < fmpq(9, 2)
    part(f"N winding: H winds 4 times around 0 along |theta| = {rho}, so J_xy != 0 for every N >= {n0}", ok,
         f"{wn.str(6)} ({arcs} arcs, each image in a disc off 0: |H'| <= M R/(R - rho)^2)" if ok else
         why or f"the winding number {wn.str(6)} is not certainly 4")
    if ok:
        log(f"  the limit surface is not C1 at the {fam} vertex for every N >= {n0}: normals along the level-m "
            "copies of quadrant 0's (1,1) tend to n_z != 0, yet e_z lies in T_v (ray 0)")
