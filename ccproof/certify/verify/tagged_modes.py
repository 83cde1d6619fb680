"""The spectrum and the leading eigenvectors of a crease or corner sector through its sine modes (trusted).

The work is O(N) (a few hundred arb operations per mode) instead of the O(N^3) of an exact
characteristic polynomial of the 6N + 3 points (docs/tagged_c1.md, "Spectrum in O(N)"). The argument:

1. **Block triangular.** The crease points (the centre and the two sharp rays) are combinations of
   crease points only (:func:`.tagged.crease_block` checks it), so S = [[C, 0], [X, I]] and
   spec(S) = spec(C) + spec(I) with algebraic multiplicities; I acts on the 6N - 2 other points.
2. **I is the smooth rule on odd vectors.** Let the 2N-regular complex carry the smooth rules
   (:mod:`.rules`; its sectors t mod 2N, each with the ray points (1,0), (2,0) and the quadrant points
   (1,1), (2,1), (1,2), (2,2)), and R the reflection in ray 0: ray t -> ray -t, quadrant t (a, b) ->
   quadrant -t-1 (b, a). A vector f is odd if f o R = -f; it vanishes on the centre and on rays 0 and
   N, and is fixed by its values on the sector's non-crease points (the odd extension E). The verifier
   checks exactly (:func:`check_structure`) that the ring's stencil commutes with R and that each
   non-crease row of S is the ring row folded by E (a point outside the sector counts with the sign -1
   at its mirror image, the centre and rays 0, N with 0). Then the ring operator L maps odd vectors to
   odd vectors and L E u = E I u: I is L on the odd vectors.
3. **Modes.** A vector v(t, p) = w^t v^(p) with w^(2N) = 1 has L v = w^t (B(w) v^)(p), B(w) the
   6 x 6 Fourier block of the ring stencil. R maps the mode w to the mode 1/w, so for w_j = exp(i pi j/N),
   j = 1..N-1, the odd vectors of the modes w_j and 1/w_j are the f = v - v o R, v in the mode w_j, and
   L acts on them as B(w_j); for j = 0 and j = N (w = +-1) the odd vectors of the mode are the kernel
   of R^_w + 1 (R^_w the 6 x 6 matrix of v -> v o R on the mode), checked exactly to be invariant under
   B(w) and to have, with the 6 (N - 1) others, the dimension 6N - 2 of I.
4. **Block polynomials.** det(x - B(w)) = (x - 1/8)(x - 1/16)(x - 1/32)(x - 1/64)(x^2 - (5 + c) x/8 + 1/16),
   c = (w + 1/w)/2: B(w) is the Fourier block :func:`.spectrum.ring_block` of the smooth rules, whose
   polynomials :func:`.spectrum.mode_polynomials_hold` checks exactly on a grid of rational points. So
   mode j has 1/8..1/64, lam(c_j) and 1/(16 lam(c_j)), c_j = cos(pi j/N),
   lam(c) = (5 + c + sqrt((1 + c)(9 + c)))/16 (:func:`.statement.lam_of`).

**Darts** (:func:`check_dart`, K >= MIN_N): S commutes with the reflection R in the sharp ray 0 (checked
row by row), so the even and the odd vectors are invariant; every row but the centre's and ray 0's is
the smooth rule of the K-regular ring, and those R-invariant rows vanish on odd vectors as L's do, so S
is L on the odd vectors: modes w_j = exp(2 pi i j/K), 1 <= j < K/2, and the odd parts of w = 1 (and -1
for even K), as above. The even part S_E (one row per R-orbit, about 3K + 3) keeps its exact
characteristic polynomial on the one-ring (centre, (1,0), (1,1): closed under the rules, checked; a
rank-2 change of the smooth even operator in the two rows of ray 0); on the rest, S_E is block
triangular below it, and its eigenvalues there are bounded in modulus by the exact infinity norm
(15/64 for each K = 5..100).

:func:`mode_spectrum` lists every eigenvalue of S once per unit of algebraic multiplicity with an
enclosure; :func:`mode_vector` gives the eigenvector of a simple eigenvalue of mode j in closed form,
:func:`even_vector` a dart's even eigenvector from S_E.
"""

from __future__ import annotations

from functools import cache

from flint import acb, acb_mat, arb, arb_mat, fmpq, fmpq_mat

from .errors import CertificateError
from .rules import TWO_RING
from .spectrum import RING_INDEX, SMALL_ROOTS, mode_polynomials_hold, ring_block, ring_stencil
from .statement import lam_of
from .tagged import crease_block, crease_points, labels, sector_rows

MIN_N = 5  # crease:N, corner:N with N >= MIN_N take this path (a "not C1" witness)


def _reflect(t, pos):
    a, b = pos
    return (-t, pos) if b == 0 else (-t - 1, (b, a))


@cache
def check_ring():
    """Raise unless the ring stencil commutes with R and its Fourier blocks have the claimed polynomials.

    Examples
    --------
    >>> check_ring()
    True
    """
    for i, pos in enumerate(TWO_RING):
        t, p = _reflect(0, pos)
        image = {(d + t, q): x for (d, q), x in ring_stencil()[RING_INDEX[p]].items()}
        mirrored = {_reflect(d, q): x for (d, q), x in ring_stencil()[i].items()}
        if image != mirrored:
            raise CertificateError(f"the ring stencil does not commute with the reflection at {pos}")
    if not mode_polynomials_hold(ring_block):  # w^6 det(x - B(w)) of degree <= 18 in w: |delta| <= 2, checked below
        raise CertificateError("a Fourier block of the ring stencil has another characteristic polynomial")
    if any(not -1 <= d <= 2 for row in ring_stencil() for d, _ in row):
        raise CertificateError("the ring stencil reaches beyond the neighbouring sectors")
    return True


def _fold(t, pos, n):
    """The sector point of ring point (t, pos) with its sign under the odd extension, or None (value 0)."""
    t %= 2 * n
    if pos[1] == 0:
        if t in (0, n):
            return None
        return (1, ("r", t) + pos) if t < n else (-1, ("r", 2 * n - t) + pos)
    return (1, ("q", t) + pos) if t < n else (-1, ("q", 2 * n - 1 - t, pos[1], pos[0]))


def kernel_basis(M):
    """The kernel of an fmpq_mat M from its reduced row echelon form: {f: the kernel vector with 1 at the free
    column f and 0 at the other free columns}. With M = [A | b], the vector of the last column f (if free) is
    the solution of A v = -b with every free unknown 0 (its other entries).

    Examples
    --------
    >>> kernel_basis(fmpq_mat([[1, 2, 3], [2, 4, 6]]))
    {1: [-2, 1, 0], 2: [-3, 0, 1]}
    """
    R, rank = M.rref()
    m = M.ncols()
    leads = [next(c for c in range(m) if R[r, c] != 0) for r in range(rank)]
    out = {}
    for f in (c for c in range(m) if c not in leads):
        out[f] = [fmpq(int(c == f)) for c in range(m)]
        for r, c in enumerate(leads):
            out[f][c] = -R[r, f] / R[r, c]
    return out


def mode_reflection(w):
    """R_w, the reflection R on the mode w: (v o R)(t, p) = w^-t (R_w v^)(p), rays p -> v^(p), quadrants
    (a, b) -> v^(b, a)/w (rows of numbers like w).

    Examples
    --------
    >>> mode_reflection(fmpq(2))[RING_INDEX[(2, 1)]]
    [0, 0, 0, 0, 1/2, 0]
    """
    rows = [[0 * w] * 6 for _ in range(6)]
    for p, i in RING_INDEX.items():
        rows[i][RING_INDEX[p if p[1] == 0 else (p[1], p[0])]] += 1 if p[1] == 0 else 1 / w
    return rows


def _odd_block(w):
    """B(w) on the odd vectors of the mode w = +-1: (its matrix M, the dimension), checked invariant."""
    cols = list(kernel_basis(fmpq_mat(mode_reflection(fmpq(w))) + fmpq_mat([[int(i == j) for j in range(6)]
                                                                          for i in range(6)])).values())
    if not cols:
        return None, 0
    K = fmpq_mat([[v[i] for v in cols] for i in range(6)])
    B = fmpq_mat(ring_block(fmpq(w)))
    Kt = K.transpose()
    M = (Kt * K).inv() * Kt * B * K
    if B * K != K * M:
        raise CertificateError(f"the odd vectors of the mode w = {w} are not invariant")
    return M, K.ncols()


@cache
def check_structure(fam, n):
    """Raise unless S has the structure of the module docstring for ``crease:n`` or ``corner:n`` (exact).

    Returns
    -------
    tuple of flint.fmpq_mat
        The blocks of the modes w = 1 and w = -1 on their odd vectors.

    Examples
    --------
    >>> [M.nrows() for M in check_structure("crease", 7)]
    [1, 3]
    """
    if fam not in ("crease", "corner") or n < MIN_N:
        raise CertificateError(f"{fam}:{n}: the mode structure is used for crease and corner sectors, N >= {MIN_N}")
    check_ring()
    crease_block(fam, n)  # the crease rows are closed (raises otherwise)
    pts, rows = labels(fam, n), sector_rows(fam, n)
    idx = {p: i for i, p in enumerate(pts)}
    cp = set(crease_points(fam, n))
    for i, p in enumerate(pts):
        if i in cp:
            continue
        t, pos = p[1], p[2:]
        folded = {}
        for (d, q), x in ring_stencil()[RING_INDEX[pos]].items():
            f = _fold(t + d, q, n)
            if f is not None:
                folded[idx[f[1]]] = folded.get(idx[f[1]], 0) + f[0] * x
        if {j: x for j, x in folded.items() if x != 0} != {j: x for j, x in rows[i].items() if j not in cp}:
            raise CertificateError(f"{fam}:{n}: the row of {p} is not the folded ring rule")
    (M0, d0), (Mn, dn) = _odd_block(1), _odd_block(-1)
    if 6 * (n - 1) + d0 + dn != len(pts) - len(cp):
        raise CertificateError(f"{fam}:{n}: the modes do not account for every non-crease point")
    return tuple(M for M in (M0, Mn) if M is not None)


def charpoly_roots(M, fac=None):
    """(acb, fmpq or None) per eigenvalue of a rational matrix (or of the factors ``fac`` of a characteristic
    polynomial), repeated by algebraic multiplicity."""
    out = []
    for p, e in M.charpoly().factor()[1] if fac is None else fac:
        for z, _ in p.complex_roots():
            out += [(acb(z), -p[0] / p[1] if p.degree() == 1 else None)] * e
    return out


def mode_spectrum(fam, n):
    """Every eigenvalue of S, once per unit of algebraic multiplicity, at the current precision.

    Parameters
    ----------
    fam : str
        ``"crease"``, ``"corner"`` or ``"dart"``.
    n : int
        N or K >= :data:`MIN_N`.

    Returns
    -------
    list of (acb, fmpq or None, str, int or None)
        (enclosure, the exact value when rational, where from: ``"C"`` the crease block, ``"I"`` the
        rest; for a dart ``"E"`` the even part, ``"O"`` the odd part; mode j for the roots lam(c_j) and
        1/(16 lam(c_j)), else None); one entry per point.

    Examples
    --------
    >>> ev = mode_spectrum("crease", 5)
    >>> len(ev), max(ev, key=lambda t: t[0].real.mid() if t[1] != 1 else 0)[3]
    (33, 1)
    """
    if fam == "dart":  # the even part exactly (S_E's factors), the odd part through the modes w = exp(2 pi i j/K)
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
        out += [(acb(lam), None, tag, j), (acb(1 / (16 * lam)), None, tag, j)]
        out += [(acb(s), s, tag, None) for s in SMALL_ROOTS]
    return out


def bordered_solve(B, lam, pivot, mat=acb_mat):
    """The null vector v of B - lam (B square: a list of rows of balls or exact numbers) with v[pivot] = 1,
    from the bordered system [[B - lam, e_p], [e_p^T, 0]] (v, s) = (0, 1) solved in ``mat`` (``acb_mat`` or
    ``arb_mat``); raises ZeroDivisionError unless arb proves it regular for every lam of the ball. Regular at
    the exact lam, it has one solution: the eigenvector v* (geometric multiplicity 1) gives the kernel vector
    (v*, 0) if v*[pivot] = 0, so lam is simple with v*[pivot] != 0, v = v* / v*[pivot] and s = 0.

    Examples
    --------
    >>> [z.real.mid() for z in bordered_solve([[acb(int(i == k)) * (i + 1) for k in range(6)] for i in range(6)],
    ...                                       acb(2), 1)]
    [0, 1.00000000000000, 0, 0, 0, 0]
    >>> [x.str(3) for x in bordered_solve([[2, 1], [1, 2]], arb(3), 0, arb_mat)]
    ['1.00', '1.00']
    """
    k = len(B)
    sol = mat(bordered_matrix(B, lam, 0, pivot)).solve(mat([[0]] * k + [[1]]))
    return [sol[i, 0] for i in range(k)]


def bordered_matrix(B, lam, zero, pivot):
    """The bordered matrix [[B - lam, e_pivot], [e_pivot^T, 0]] as a list of rows (``zero`` of B's ring:
    0, an exact or a series zero), one size larger than B.

    Examples
    --------
    >>> bordered_matrix([[2, 1], [1, 2]], 3, 0, 1)
    [[-1, 1, 0], [1, -1, 1], [0, 1, 0]]
    """
    k = len(B)
    A = [[(B[i][j] - lam) if i == j else B[i][j] for j in range(k)] + [zero + int(i == pivot)] for i in range(k)]
    return A + [[zero + int(j == pivot) for j in range(k)] + [zero]]


def _unit(num, den):
    """exp(i pi num/den), each from its own angle (no powers accumulate error)."""
    a = arb(fmpq(num % (2 * den), den))
    return acb(a.cos_pi(), a.sin_pi())


def mode_vector(fam, n, j, lam):
    """The eigenvector of S for a simple eigenvalue lam (an arb ball) of mode j, as f = v - v o R on the ring
    points (v(t, p) = w^t v^(p), w = exp(2 pi i j/M) on the ring of M = 2N sectors, or M = K for a dart;
    v^ from the bordered 6 x 6 system of B(w)) and 0 on the crease points (dart: the centre).

    Returns
    -------
    list of acb or fmpq, or None
        None where no pivot of v^ makes the bordered system certainly regular. Not normalized: a complex
        multiple of the real eigenvector.

    Examples
    --------
    >>> ev = mode_spectrum("crease", 5)
    >>> lam = max(t[0].real for t in ev if t[3] == 1)
    >>> f = mode_vector("crease", 5, 1, lam)
    >>> len(f), f[0]
    (33, 0)
    """
    ring = n if fam == "dart" else 2 * n
    B = ring_block(_unit(2 * j, ring))
    vh = None
    for pv in range(6):  # the first pivot that arb proves regular (the bordered-system argument of tagged_c1)
        try:
            vh = bordered_solve(B, lam, pv)
            break
        except ZeroDivisionError:
            continue
    if vh is None:
        return None
    skip = {0} if fam == "dart" else set(crease_points(fam, n))
    out = []
    for i, p in enumerate(labels(fam, n)):
        if i in skip:
            out.append(fmpq(0))
            continue
        t, pos = p[1], p[2:]
        if pos[1] == 0:
            out.append(vh[RING_INDEX[pos]] * (_unit(2 * j * t, ring) - _unit(-2 * j * t, ring)))
        else:
            out.append(vh[RING_INDEX[pos]] * _unit(2 * j * t, ring)
                       - vh[RING_INDEX[(pos[1], pos[0])]] * _unit(-2 * j * (t + 1), ring))
    return out


def normalized_vector(fam, n, ev, i, pivot):
    """The real eigenvector, 1 at ``pivot``, of the entry i of ``ev`` = :func:`mode_spectrum` (fam, n): in closed
    form for a root of mode j (:func:`mode_vector`), from S_E for a dart's even entry (:func:`even_vector`);
    None unless arb proves the system regular and the value at the pivot non-zero.

    Examples
    --------
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


def _dart_reflect(p, k):
    if p == ("C",):
        return p
    return ("r", -p[1] % k, p[2], p[3]) if p[0] == "r" else ("q", (-p[1] - 1) % k, p[3], p[2])


@cache
def check_dart(k):
    """Raise unless dart:k's S commutes with the reflection R in the sharp ray and is the ring rule on every
    point but the centre and ray 0 (exact); then S is L on the odd vectors and S_E on the even ones.

    Returns
    -------
    (fmpq_mat, tuple of int, tuple of fmpq_mat, list, (tuple, tuple), fmpq)
        S_E on one representative per R-orbit, the representative's row in S_E of each point, the odd
        blocks of the modes w = 1 (and w = -1 for even k), the factors of the characteristic polynomial of
        S_E on the one-ring (closed under the rules: checked), the rows of S_E on the one-ring and on the
        rest (outer), and the infinity norm of S_E on the outer rows, a bound on their eigenvalues' moduli.

    Examples
    --------
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
    blocks = [M for M, _ in [_odd_block(1)] + ([_odd_block(-1)] if k % 2 == 0 else []) if M is not None]
    if 6 * ((k + 1) // 2 - 1) + sum(M.nrows() for M in blocks) != len(pts) - len(reps):
        raise CertificateError(f"dart:{k}: the modes do not account for every odd vector")
    inner = [a for a, i in enumerate(reps) if pts[i] == ("C",) or pts[i][2:] in ((1, 0), (1, 1))]
    fac, outer, bound = _one_ring(k, SE, inner)
    return SE, tuple(rep), tuple(blocks), fac, (tuple(inner), outer), bound


def _one_ring(k, SE, inner):
    """The one-ring (centre, (1,0), (1,1)) is closed: S_E = [[S_in, 0], [*, S_out]] (checked exactly); the
    factors of S_in's characteristic polynomial, the outer rows and |S_out|_inf >= rho(S_out)."""
    outer = tuple(a for a in range(SE.nrows()) if a not in inner)
    if any(SE[a, b] != 0 for a in inner for b in outer):
        raise CertificateError(f"dart:{k}: the one-ring is not closed under the rules")
    bound = max(sum((abs(SE[a, b]) for b in outer), fmpq(0)) for a in outer)
    return fmpq_mat([[SE[a, b] for b in inner] for a in inner]).charpoly().factor()[1], outer, bound


def _check_dart_rows(k, pts, rows):
    """The reflection in the sharp ray (as a permutation of the points), after checking exactly that the
    rows commute with it and that every row but the centre's and ray 0's is the ring rule."""
    idx = {p: i for i, p in enumerate(pts)}
    refl = [idx[_dart_reflect(p, k)] for p in pts]
    for i, p in enumerate(pts):
        if rows[refl[i]] != {refl[j]: x for j, x in rows[i].items()}:
            raise CertificateError(f"dart:{k}: the rules do not commute with the reflection at {p}")
        if p == ("C",) or p[:2] == ("r", 0):
            continue  # R-invariant rows: 0 on odd vectors, as L's
        ring = {}
        for (d, q), x in ring_stencil()[RING_INDEX[p[2:]]].items():
            j = idx[("r" if q[1] == 0 else "q", (p[1] + d) % k) + q]
            ring[j] = ring.get(j, 0) + x
        if {j: x for j, x in ring.items() if x != 0} != {j: x for j, x in rows[i].items() if j != 0}:
            raise CertificateError(f"dart:{k}: the row of {p} is not the ring rule")
    return refl


def even_vector(k, lam, pivot):
    """The eigenvector (arb, 1 at ``pivot``) of dart:k for a simple eigenvalue lam of S_E: the bordered
    system (:func:`bordered_solve`) on the one-ring rows of S_E when the pivot lies there,
    then the rest from (lam - S_out) y_out = X y_in (S_E is block triangular), spread over each R-orbit.
    Raises ZeroDivisionError unless arb proves the systems regular.

    Examples
    --------
    >>> lam = max(t[0].real for t in mode_spectrum("dart", 5) if t[2] == "E" and t[1] != 1)
    >>> v = even_vector(5, lam, 7)
    >>> pts = labels("dart", 5)
    >>> v[7], v[pts.index(("r", 1, 1, 0))].overlaps(v[pts.index(("r", 4, 1, 0))])
    (1.00000000000000, True)
    """
    SE, rep, _, _, (inner, outer), _ = check_dart(k)
    if rep[pivot] not in inner:  # the whole of S_E
        inner, outer = tuple(range(SE.nrows())), ()
    sol = bordered_solve([[arb(SE[a, b]) for b in inner] for a in inner], lam, inner.index(rep[pivot]), arb_mat)
    y = {a: sol[i] for i, a in enumerate(inner)}
    if outer:  # (lam - S_out) y_out = X y_in: regular since rho(S_out) <= bound < lam (the caller checks lam)
        A = arb_mat([[(lam if a == b else 0) - arb(SE[a, b]) for b in outer] for a in outer])
        rhs = arb_mat([[sum((arb(SE[a, b]) * y[b] for b in inner if SE[a, b] != 0), arb(0))] for a in outer])
        sol = A.solve(rhs)
        y.update({a: sol[i, 0] for i, a in enumerate(outer)})
    return [y[rep[i]] for i in range(len(rep))]


__all__ = ["MIN_N", "RING_INDEX", "charpoly_roots", "check_dart", "check_ring", "check_structure", "even_vector",
           "kernel_basis", "mode_reflection", "mode_spectrum", "mode_vector", "normalized_vector", "ring_block",
           "ring_stencil"]
