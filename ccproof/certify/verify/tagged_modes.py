"""The spectrum and leading eigenvectors of crease and corner sectors (N >= MIN_N) and darts' odd half in O(N)
through the Fourier modes of the smooth ring, every structural claim checked exactly; a dart's even half S_E
exactly; the bordered systems of the eigenvectors (trusted; docs/tagged_c1.md, "Spectrum in O(N)").
"""

from __future__ import annotations

from functools import cache

from flint import acb, acb_mat, arb, arb_mat, fmpq, fmpq_mat

from .errors import CertificateError
from .rules import TWO_RING
from .spectrum import RING_INDEX, SMALL_ROOTS, mode_polynomials_hold, ring_block, ring_stencil
from .statement import lam_of
from .tagged import crease_block, crease_points, identity, labels, sector_rows

MIN_N = 5  # crease:N, corner:N and dart:K with N, K >= MIN_N take the modes


def _reflect(t, pos):  # the reflection R in ray 0 on the ring: ray t -> ray -t, quadrant t (a, b) -> -t-1 (b, a)
    a, b = pos
    return (-t, pos) if b == 0 else (-t - 1, (b, a))


@cache
def check_ring():
    """True, or raise unless the ring stencil commutes with R, reaches sectors t - 1 .. t + 2 only, and its Fourier
    blocks have the claimed characteristic polynomials (:func:`.spectrum.mode_polynomials_hold`)."""
    for i, pos in enumerate(TWO_RING):
        t, p = _reflect(0, pos)
        image = {(d + t, q): x for (d, q), x in ring_stencil()[RING_INDEX[p]].items()}
        if image != {_reflect(d, q): x for (d, q), x in ring_stencil()[i].items()}:
            raise CertificateError(f"the ring stencil does not commute with the reflection at {pos}")
    if not mode_polynomials_hold(ring_block):  # w^6 det(x - B(w)) of degree <= 18 in w: |delta| <= 2, checked below
        raise CertificateError("a Fourier block of the ring stencil has another characteristic polynomial")
    if any(not -1 <= d <= 2 for row in ring_stencil() for d, _ in row):
        raise CertificateError("the ring stencil reaches beyond the neighbouring sectors")
    return True


def _ring_row(t, pos, place):
    """The ring rule of the ring point (t, pos), its columns placed by ``place(sector, pos)``: (sign, column) or None
    (weight dropped); zero weights left out."""
    out = {}
    for (d, q), x in ring_stencil()[RING_INDEX[pos]].items():
        f = place(t + d, q)
        if f is not None:
            out[f[1]] = out.get(f[1], 0) + f[0] * x
    return {j: x for j, x in out.items() if x != 0}


def kernel_basis(M):
    """The kernel of an fmpq_mat from its rref: {f: the kernel vector with 1 at the free column f, 0 at the others};
    for M = [A | b] the vector of the last column (if free) solves A v = -b with every free unknown 0.

    >>> kernel_basis(fmpq_mat([[1, 2, 3], [2, 4, 6]]))
    {1: [-2, 1, 0], 2: [-3, 0, 1]}
    """
    R, rank = M.rref()
    leads = [next(c for c in range(M.ncols()) if R[r, c] != 0) for r in range(rank)]
    out = {}
    for f in (c for c in range(M.ncols()) if c not in leads):
        out[f] = [fmpq(int(c == f)) for c in range(M.ncols())]
        for r, c in enumerate(leads):
            out[f][c] = -R[r, f] / R[r, c]
    return out


def mode_reflection(w):
    """R_w, the reflection R on the mode w: (v o R)(t, p) = w^-t (R_w v^)(p); rays p -> v^(p), quadrants (a, b) ->
    v^(b, a)/w (rows of numbers like w)."""
    rows = [[0 * w] * 6 for _ in range(6)]
    for p, i in RING_INDEX.items():
        rows[i][RING_INDEX[p if p[1] == 0 else (p[1], p[0])]] += 1 if p[1] == 0 else 1 / w
    return rows


def _odd_blocks(ends):
    """B(w) on the odd vectors (the kernel of R_w + 1) of each mode w in ``ends`` (1, and -1 for an even ring) that
    has any, checked invariant (exact)."""
    out = []
    for w in ends:
        cols = list(kernel_basis(fmpq_mat(mode_reflection(fmpq(w))) + identity(6)).values())
        if cols:
            K, B = fmpq_mat([[v[i] for v in cols] for i in range(6)]), fmpq_mat(ring_block(fmpq(w)))
            out.append((K.transpose() * K).inv() * K.transpose() * B * K)
            if B * K != K * out[-1]:
                raise CertificateError(f"the odd vectors of the mode w = {w} are not invariant")
    return tuple(out)


@cache
def check_structure(fam, n):
    """Raise unless S of crease:n or corner:n (n >= MIN_N) is [[C, 0], [X, I]] with I the ring rule folded by the
    odd extension (exact) and the modes account for every non-crease point; the blocks of the modes w = +-1.

    >>> [M.nrows() for M in check_structure("crease", 7)]
    [1, 3]
    """
    if fam not in ("crease", "corner") or n < MIN_N:
        raise CertificateError(f"{fam}:{n}: the mode structure is used for crease and corner sectors, N >= {MIN_N}")
    check_ring()
    crease_block(fam, n)  # the crease rows are closed (raises otherwise)
    pts, rows, cp = labels(fam, n), sector_rows(fam, n), set(crease_points(fam, n))
    idx = {p: i for i, p in enumerate(pts)}

    def fold(t, pos):  # the sector point of ring point (t, pos) with its sign under the odd extension, or None
        t %= 2 * n
        if pos[1] == 0:
            return None if t in (0, n) else (1, idx[("r", t) + pos]) if t < n else (-1, idx[("r", 2 * n - t) + pos])
        return (1, idx[("q", t) + pos]) if t < n else (-1, idx[("q", 2 * n - 1 - t, pos[1], pos[0])])
    for i, p in enumerate(pts):
        if i not in cp and _ring_row(p[1], p[2:], fold) != {j: x for j, x in rows[i].items() if j not in cp}:
            raise CertificateError(f"{fam}:{n}: the row of {p} is not the folded ring rule")
    blocks = _odd_blocks((1, -1))
    if 6 * (n - 1) + sum(M.nrows() for M in blocks) != len(pts) - len(cp):
        raise CertificateError(f"{fam}:{n}: the modes do not account for every non-crease point")
    return blocks


def charpoly_roots(M, fac=None):
    """(acb, fmpq or None) per eigenvalue of a rational matrix (or of the factors ``fac`` of a characteristic
    polynomial), repeated by algebraic multiplicity."""
    out = []
    for p, e in M.charpoly().factor()[1] if fac is None else fac:
        for z, _ in p.complex_roots():
            out += [(acb(z), -p[0] / p[1] if p.degree() == 1 else None)] * e
    return out


def mode_spectrum(fam, n):
    """Every eigenvalue of S (n >= MIN_N) once per unit of algebraic multiplicity at the current precision:
    (enclosure, exact value when rational, where from: "C" the crease block, "I" the rest, a dart's "E" even and
    "O" odd part, the mode j of the roots lam(c_j) and 1/(16 lam(c_j)) or None).

    >>> ev = mode_spectrum("crease", 5)
    >>> len(ev), max(ev, key=lambda t: t[0].real.mid() if t[1] != 1 else 0)[3]
    (33, 1)
    """
    if fam == "dart":  # the even part exactly (S_E's one-ring factors, the rest by a bound), the odd part in modes
        _, _, extra, fac, (_, outer), bound = check_dart(n)
        out, tag, modes = [(z, q, "E", None) for z, q in charpoly_roots(None, fac)], "O", range(1, (n + 1) // 2)
        out += [(acb(arb(0, bound), arb(0, bound)), None, "E", None)] * len(outer)  # |z| <= bound, each
    else:
        extra, tag, modes = check_structure(fam, n), "I", range(1, n)
        out = [(z, q, "C", None) for z, q in charpoly_roots(crease_block(fam, n))]
    for M in extra:
        out += [(z, q, tag, None) for z, q in charpoly_roots(M)]
    ring = n if fam == "dart" else 2 * n
    for j in modes:
        lam = lam_of(arb(fmpq(2 * j, ring)).cos_pi())
        out += [(acb(lam), None, tag, j), (acb(1 / (16 * lam)), None, tag, j)] + [(acb(s), s, tag, None)
                                                                                  for s in SMALL_ROOTS]
    return out


def off_cut(c):
    """c, raising ZeroDivisionError where c is an acb ball whose (1 + c)(9 + c) is not certainly in the right
    half-plane: elsewhere its principal square root, and lam(c) (:func:`.statement.lam_of`), are analytic in c."""
    if isinstance(c, acb) and not ((1 + c) * (9 + c)).real > 0:
        raise ZeroDivisionError("(1 + c)(9 + c) is not certainly in the right half-plane (off the branch cut)")
    return c


def bordered_solve(B, lam, pivot, mat=acb_mat):
    """The null vector v of B - lam with v[pivot] = 1 from the bordered system [[B - lam, e_p], [e_p^T, 0]] (v, s) =
    (0, 1) in ``mat`` (acb_mat or arb_mat); ZeroDivisionError unless arb proves it regular for every lam of the
    ball (then lam is simple, v*[pivot] != 0 and v = v*/v*[pivot]: docs/tagged_c1.md).

    >>> [x.str(3) for x in bordered_solve([[2, 1], [1, 2]], arb(3), 0, arb_mat)]
    ['1.00', '1.00']
    """
    sol = mat(bordered_matrix(B, lam, 0, pivot)).solve(mat([[0]] * len(B) + [[1]]))
    return [sol[i, 0] for i in range(len(B))]


def bordered_matrix(B, lam, zero, pivot):
    """[[B - lam, e_pivot], [e_pivot^T, 0]] as a list of rows (``zero`` of B's ring: 0, an exact or a series zero)."""
    k = len(B)
    A = [[(B[i][j] - lam) if i == j else B[i][j] for j in range(k)] + [zero + int(i == pivot)] for i in range(k)]
    return A + [[zero + int(j == pivot) for j in range(k)] + [zero]]


def _unit(num, den):  # exp(i pi num/den), each from its own angle (no powers accumulate error)
    a = arb(fmpq(num % (2 * den), den))
    return acb(a.cos_pi(), a.sin_pi())


def mode_vector(fam, n, j, lam):
    """The eigenvector f = v - v o R of S for a simple eigenvalue lam (arb) of mode j (v(t, p) = w^t v^(p) on the ring
    of 2N sectors, K for a dart; v^ from B(w)'s bordered system at the first pivot proved regular), 0 on the crease
    points (a dart: the centre); a complex multiple of the real eigenvector, or None.

    >>> f = mode_vector("crease", 5, 1, max(t[0].real for t in mode_spectrum("crease", 5) if t[3] == 1))
    >>> len(f), f[0]
    (33, 0)
    """
    ring = n if fam == "dart" else 2 * n
    B = ring_block(_unit(2 * j, ring))
    for pv in range(6):
        try:
            vh = bordered_solve(B, lam, pv)
            break
        except ZeroDivisionError:
            continue
    else:
        return None
    skip = {0} if fam == "dart" else set(crease_points(fam, n))

    def value(t, pos):  # f = v - v o R at the ring point (t, pos)
        u = _unit(2 * j * t, ring)
        if pos[1] == 0:
            return vh[RING_INDEX[pos]] * (u - _unit(-2 * j * t, ring))
        return vh[RING_INDEX[pos]] * u - vh[RING_INDEX[(pos[1], pos[0])]] * _unit(-2 * j * (t + 1), ring)
    return [fmpq(0) if i in skip else value(p[1], p[2:]) for i, p in enumerate(labels(fam, n))]


def normalized_vector(fam, n, ev, i, pivot):
    """The real eigenvector, 1 at ``pivot``, of the entry i of ``ev`` = mode_spectrum(fam, n): closed form for a
    root of mode j, from S_E for a dart's even entry; None unless arb proves the system regular and f(pivot) != 0.

    >>> ev = mode_spectrum("crease", 5)
    >>> i = max((i for i, t in enumerate(ev) if t[3] == 1), key=lambda i: ev[i][0].real.mid())
    >>> v = normalized_vector("crease", 5, ev, i, 21)
    >>> v[21].contains(1), v[0]
    (True, 0)
    """
    lam, j = ev[i][0].real, ev[i][3]
    if j is None:
        try:
            return even_vector(n, lam, pivot) if fam == "dart" else None
        except ZeroDivisionError:
            return None
    f = mode_vector(fam, n, j, lam)
    if f is None or not abs(f[pivot]) > 0:
        return None
    return [v if isinstance(v, fmpq) else (v / f[pivot]).real for v in f]


@cache
def check_dart(k):
    """Raise unless dart:k's S commutes with the reflection R in the sharp ray, is the ring rule but at the centre and
    ray 0, and S_E = [[S_in, 0], [*, S_out]] on the one-ring (exact); S_E (one row per R-orbit), each point's orbit,
    the odd blocks of w = +-1, S_in's characteristic factors, (inner, outer rows), |S_out|_inf >= rho(S_out).

    >>> SE, rep, blocks, fac, (inner, outer), bound = check_dart(5)
    >>> SE.nrows(), len(rep), [M.nrows() for M in blocks], len(outer), bound
    (18, 31, [1], 11, 15/64)
    """
    if k < MIN_N:
        raise CertificateError(f"dart:{k}: the mode structure is used for K >= {MIN_N}")
    check_ring()
    pts, rows = labels("dart", k), sector_rows("dart", k)
    refl = _check_dart_rows(k, pts, rows)
    reps = [i for i in range(len(pts)) if i <= refl[i]]
    rep = [0] * len(pts)
    for a, i in enumerate(reps):
        rep[i] = rep[refl[i]] = a
    SE = fmpq_mat(len(reps), len(reps))
    for a, i in enumerate(reps):
        for j, x in rows[i].items():
            SE[a, rep[j]] += x
    blocks = _odd_blocks((1, -1) if k % 2 == 0 else (1,))
    if 6 * ((k + 1) // 2 - 1) + sum(M.nrows() for M in blocks) != len(pts) - len(reps):
        raise CertificateError(f"dart:{k}: the modes do not account for every odd vector")
    inner = tuple(a for a, i in enumerate(reps) if pts[i] == ("C",) or pts[i][2:] in ((1, 0), (1, 1)))
    return (SE, tuple(rep), blocks) + _one_ring(k, SE, inner)


def _one_ring(k, SE, inner):  # S_in's factors, (inner, outer), the bound, after checking that the one-ring is closed
    outer = tuple(a for a in range(SE.nrows()) if a not in inner)
    if any(SE[a, b] != 0 for a in inner for b in outer):
        raise CertificateError(f"dart:{k}: the one-ring is not closed under the rules")
    bound = max(sum((abs(SE[a, b]) for b in outer), fmpq(0)) for a in outer)
    return fmpq_mat([[SE[a, b] for b in inner] for a in inner]).charpoly().factor()[1], (inner, outer), bound


def _check_dart_rows(k, pts, rows):
    """The reflection in the sharp ray as a permutation, after checking exactly that the rows commute with it and
    that every row but the centre's and ray 0's (R-invariant: 0 on odd vectors, as L's) is the ring rule."""
    idx = {p: i for i, p in enumerate(pts)}
    refl = [idx[p if p == ("C",) else ("r", -p[1] % k) + p[2:] if p[0] == "r" else ("q", (-p[1] - 1) % k, p[3], p[2])]
            for p in pts]
    for i, p in enumerate(pts):
        if rows[refl[i]] != {refl[j]: x for j, x in rows[i].items()}:
            raise CertificateError(f"dart:{k}: the rules do not commute with the reflection at {p}")
        ring = None if p == ("C",) or p[:2] == ("r", 0) else _ring_row(
            p[1], p[2:], lambda s, q: (1, idx[("r" if q[1] == 0 else "q", s % k) + q]))
        if ring is not None and ring != {j: x for j, x in rows[i].items() if j != 0}:
            raise CertificateError(f"dart:{k}: the row of {p} is not the ring rule")
    return refl


def even_vector(k, lam, pivot):
    """The eigenvector (arb, 1 at ``pivot``) of dart:k for a simple eigenvalue lam of S_E: the bordered system on
    the one-ring rows (all of S_E if the pivot lies outside), then (lam - S_out) y_out = X y_in, spread over each
    R-orbit; ZeroDivisionError unless arb proves the systems regular.

    >>> v = even_vector(5, max(t[0].real for t in mode_spectrum("dart", 5) if t[2] == "E" and t[1] != 1), 7)
    >>> pts = labels("dart", 5)
    >>> v[7], v[pts.index(("r", 1, 1, 0))].overlaps(v[pts.index(("r", 4, 1, 0))])
    (1.00000000000000, True)
    """
    SE, rep, _, _, (inner, outer), _ = check_dart(k)
    if rep[pivot] not in inner:  # the whole of S_E
        inner, outer = tuple(range(SE.nrows())), ()
    sol = bordered_solve([[arb(SE[a, b]) for b in inner] for a in inner], lam, inner.index(rep[pivot]), arb_mat)
    y = dict(zip(inner, sol))
    if outer:  # (lam - S_out) y_out = X y_in: regular since rho(S_out) <= bound < lam (the caller checks lam)
        A = arb_mat([[(lam if a == b else 0) - arb(SE[a, b]) for b in outer] for a in outer])
        sol = A.solve(arb_mat([[sum((arb(SE[a, b]) * y[b] for b in inner if SE[a, b] != 0), arb(0))] for a in outer]))
        y.update({a: sol[i, 0] for i, a in enumerate(outer)})
    return [y[rep[i]] for i in range(len(rep))]
