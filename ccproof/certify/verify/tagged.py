"""The subdivision matrix of a tagged configuration and its leading spectrum, from the rules (trusted).

A configuration is named ``"dart:K"``, ``"crease:N"`` or ``"corner:N"`` (docs/tagged_c1.md). Its
sector complex is the grid of :mod:`.rules` around the centre C: rays r (an edge out of C) carry the
positions (1, 0), (2, 0); quadrant q (the face between rays q and q + 1) the positions (1, 1), (2, 1),
(1, 2), (2, 2).

* ``crease:N``: N quadrants between the sharp rays 0 and N (a boundary vertex with N faces, or one
  side of an interior crease: the points of a sector depend only on the crease points and their own,
  so the sectors decouple, docs/tagged_c1.md);
* ``corner:N``: the same complex with the centre fixed;
* ``dart:K``: K quadrants around C (rays taken mod K), ray 0 sharp, the crease continuing beyond it.

OpenSubdiv's rules (Sdc ``CATMARK``; written here once more, independently of the library): face
point the centroid; smooth edge point (a + b + f0 + f1)/4, sharp edge point (a + b)/2; smooth vertex
point (F + 2R + (n - 3)V)/n; crease vertex point (e0 + 6V + e1)/8; corner vertex point V. A dart
centre takes the smooth rule, a crease centre the crease rule along its two sharp rays.
"""

from __future__ import annotations

import re
from functools import cache, lru_cache

from flint import acb, ctx, fmpq, fmpq_mat, fmpq_poly

from .errors import CertificateError
from .rules import CENTRE, canonical, level1_rule

RAY_POS = ((1, 0), (2, 0))
QUAD_POS = ((1, 1), (2, 1), (1, 2), (2, 2))
MAX_SIZE = 100  # N, K at most this (exact characteristic polynomials of 6K + 1 rows)
_NAME = re.compile(r"(dart|crease|corner):(>=)?([0-9]{1,7})")
MAX_TAIL = 10**6  # FAMILY:>=N0 needs N0 at most this
EXACT_BUDGET = 128**3  # work m^3 of the exact route for S of m points; the published use at most 27 points


def parse_configuration(name):
    """``(family, n)`` from a configuration name such as ``"crease:4"``, or ``(family, {"min": N0})`` for
    every N >= N0 at once (``"crease:>=101"``; :mod:`.tagged_limit`).

    Parameters
    ----------
    name : str
        ``"dart:K"`` (K >= 2), ``"crease:N"`` or ``"corner:N"`` (N >= 1), at most :data:`MAX_SIZE`;
        ``"FAMILY:>=N0"`` with 2 <= N0 <= :data:`MAX_TAIL`.

    Raises
    ------
    CertificateError
        For any other name.

    Examples
    --------
    >>> parse_configuration("dart:5"), parse_configuration("crease:>=101")
    (('dart', 5), ('crease', {'min': 101}))
    >>> parse_configuration("dart:1")
    Traceback (most recent call last):
    ...
    ccproof.certify.verify.errors.CertificateError: configuration 'dart:1': dart:K needs 2 <= K <= 100
    """
    m = _NAME.fullmatch(name) if isinstance(name, str) else None
    if m is None:
        raise CertificateError(f"configuration {str(name)[:40]!r} is not dart:K, crease:N or corner:N (or FAMILY:>=N0)")
    fam, n = m.group(1), int(m.group(3))
    if m.group(2):
        if not 2 <= n <= MAX_TAIL:
            raise CertificateError(f"configuration {name!r}: {fam}:>=N0 needs 2 <= N0 <= {MAX_TAIL}")
        return fam, {"min": n}
    lo = 2 if fam == "dart" else 1
    if not lo <= n <= MAX_SIZE:
        raise CertificateError(f"configuration {name!r}: {fam}:{'K' if fam == 'dart' else 'N'} needs "
                               f"{lo} <= {'K' if fam == 'dart' else 'N'} <= {MAX_SIZE}")
    return fam, n


def check_exact_budget(fam, n):
    """Refuse, before any arithmetic, a configuration whose exact route exceeds :data:`EXACT_BUDGET`.

    The exact route (the characteristic polynomial of the whole S over Q, its factors, the ranks of
    p(S), :func:`exact_spectrum`) costs about m^3 operations on rationals for S of m points (m = 6N + 3,
    6K + 1 for a dart), 9 s of CPU for crease:100. The budget, 128^3 (N, K <= 20; under 0.1 s), admits
    every published certificate on that route (at most 27 points) with room; larger configurations are
    decided through the modes of :mod:`.tagged_modes` or not at all.

    Examples
    --------
    >>> check_exact_budget("crease", 20)
    >>> try:
    ...     check_exact_budget("crease", 100)
    ... except CertificateError as exc:
    ...     print(exc)
    crease:100: the exact route on S of 603 points exceeds the budget (m^3 > 128^3: N, K <= 20)
    """
    m = len(labels(fam, n))
    if m**3 > EXACT_BUDGET:
        raise CertificateError(f"{fam}:{n}: the exact route on S of {m} points exceeds the budget (m^3 > 128^3: "
                               "N, K <= 20)")


def labels(fam, n):
    """The points of the sector complex, in matrix order: centre, ray points, quadrant points.

    Returns
    -------
    list of tuple
        ``("C",)``, ``("r", r, a, b)``, ``("q", q, a, b)``; 6n + 3 points (crease, corner) or 6n + 1 (dart).

    Examples
    --------
    >>> pts = labels("crease", 1)
    >>> len(pts), pts[:3]
    (9, [('C',), ('r', 0, 1, 0), ('r', 0, 2, 0)])
    """
    rays = n if fam == "dart" else n + 1
    return ([("C",)] + [("r", r) + p for r in range(rays) for p in RAY_POS]
            + [("q", q) + p for q in range(n) for p in QUAD_POS])


def sharp_rays(fam, n):
    """The sharp rays: ray 0 for a dart, rays 0 and n otherwise.

    Examples
    --------
    >>> sharp_rays("dart", 5), sharp_rays("corner", 3)
    ((0,), (0, 3))
    """
    return (0,) if fam == "dart" else (0, n)


def position_key(fam, n, q, a, b):
    """The label (:func:`labels`) of the raw grid position (a, b) of quadrant q (:func:`.rules.canonical`;
    rays and quadrants mod K for a dart), whether or not the complex holds it.

    Examples
    --------
    >>> position_key("dart", 5, 4, 0, 2), position_key("crease", 2, 0, 1, -1), position_key("crease", 2, 1, 0, 0)
    (('r', 0, 2, 0), ('q', -1, 1, 1), ('C',))
    """
    delta, a2, b2 = canonical(a, b)
    if (a2, b2) == CENTRE:
        return ("C",)
    s = (q + delta) % n if fam == "dart" else q + delta
    return ("r", s, a2, b2) if b2 == 0 else ("q", s, a2, b2)


def point_index(fam, n):
    """``(idx, at)``: the index of each label (:func:`labels`), and ``at(q, comb)``, a combination of raw grid
    positions of quadrant q (:func:`position_key`) as ``{index: weight}``; raises for a position outside the
    complex.

    Examples
    --------
    >>> idx, at = point_index("crease", 2)
    >>> idx[("r", 2, 1, 0)], at(1, {(0, 1): fmpq(1, 2), (1, 0): fmpq(1, 2)})
    (5, {5: 1/2, 3: 1/2})
    """
    idx = {p: i for i, p in enumerate(labels(fam, n))}

    def at(q, comb):  # raw positions of quadrant q -> {index: weight}
        out = {}
        for (a, b), w in comb.items():
            key = position_key(fam, n, q, a, b)
            if key not in idx:
                raise CertificateError(f"{fam}:{n}: position {(a, b)} of quadrant {q} outside the complex")
            out[idx[key]] = out.get(idx[key], 0) + w
        return out
    return idx, at


@cache
def sector_rows(fam, n):
    """The rows of the sector matrix S as sparse dicts (column index -> weight), from the rules.

    Parameters
    ----------
    fam : str
        ``"dart"``, ``"crease"`` or ``"corner"``.
    n : int
        K or N.

    Returns
    -------
    tuple of dict[int, fmpq]
        One per point of :func:`labels` (level-1 point i = sum_j row_i[j] level-0 point j).

    Examples
    --------
    The crease centre (e0 + 6 V + e1)/8 (rays 0 and 2 start at indices 1 and 5):

    >>> sector_rows("crease", 2)[0]
    {0: 3/4, 1: 1/8, 5: 1/8}
    """
    pts = labels(fam, n)
    idx, at = point_index(fam, n)
    rows = []
    sharp = sharp_rays(fam, n)
    half, eighth = fmpq(1, 2), fmpq(1, 8)
    for p in pts:
        if p == ("C",):
            row = _centre_row(fam, n, idx)
        elif p[0] == "r" and p[1] in sharp:
            e1, e2 = idx[("r", p[1], 1, 0)], idx[("r", p[1], 2, 0)]
            row = {0: half, e1: half} if p[2] == 1 else {0: eighth, e1: 6 * eighth, e2: eighth}
        else:  # a smooth ray (its b = -1 side is quadrant r - 1) or a quadrant point: the rule in that quadrant
            row = at(p[1], level1_rule(*p[2:]))
        rows.append({j: w for j, w in row.items() if w != 0})
    return tuple(rows)


def window_rows(fam, n):
    """{window class: the row relative to its point} for fam:n; raises if one class has two rows.

    A point's class is its kind, its ray or quadrant clipped to 3 from either end, and its position; a
    column is the point's kind, its offset from the row's ray (mod K for a dart, taken in -K/2 .. K/2) and
    its position. The centre row of a crease or corner reads rays 0 and N (``"N"``, N - ray); a dart's
    centre row depends on K and is left out (:mod:`.dart_spectrum` checks it apart).

    Examples
    --------
    The crease centre (e0 + 6 V + e1)/8 on rays 0 and N, and a dart's sharp midpoint (C + e1)/2:

    >>> window_rows("crease", 7)[("C",)]
    {('C',): 3/4, ('r', 0, 1, 0): 1/8, ('r', 'N', 0, 1, 0): 1/8}
    >>> window_rows("dart", 7)[("r", 0, 3, 1, 0)]
    {('C',): 1/2, ('r', 0, 1, 0): 1/2}
    """
    pts, out = labels(fam, n), {}
    for p, row in zip(pts, sector_rows(fam, n)):
        if p == ("C",) and fam == "dart":
            continue
        key = p if p == ("C",) else (p[0], min(p[1], 3), min(n - p[1], 3)) + p[2:]
        rel = {_window_column(p, pts[j], n, fam == "dart"): x for j, x in row.items()}
        if len(rel) != len(row) or out.setdefault(key, rel) != rel:
            raise CertificateError(f"{fam}:{n}: two points of window class {key} have different rows")
    return out


def _window_column(p, q, n, ring):  # the column of point q in the row of point p (window_rows)
    if q == ("C",):
        return q
    if p == ("C",):
        return q if q[1] <= 3 else (q[0], "N", n - q[1]) + q[2:]
    d = (q[1] - p[1]) % n if ring else q[1] - p[1]
    return (q[0], d - n if ring and d > n // 2 else d) + q[2:]


@cache
def sector_matrix(fam, n):
    """The exact subdivision matrix S of the configuration: level-1 point i = sum_j S[i, j] level-0 point j.

    Parameters
    ----------
    fam : str
        ``"dart"``, ``"crease"`` or ``"corner"``.
    n : int
        K or N.

    Returns
    -------
    flint.fmpq_mat, shape (m, m)
        m = len(labels(fam, n)); rows sum to 1 (:func:`sector_rows`, dense).

    Examples
    --------
    The crease centre (e0 + 6 V + e1)/8 and a sharp edge midpoint:

    >>> S = sector_matrix("crease", 2)
    >>> [S[0, j] for j in range(7)], S[1, 0], S[1, 1]
    ([3/4, 1/8, 0, 0, 0, 1/8, 0], 1/2, 1/2)
    """
    rows = sector_rows(fam, n)
    m = len(rows)
    return fmpq_mat([[row.get(j, fmpq(0)) for j in range(m)] for row in rows])


def _centre_row(fam, n, idx):
    if fam == "corner":
        return {0: fmpq(1)}
    if fam == "crease":
        return {0: fmpq(3, 4), idx[("r", 0, 1, 0)]: fmpq(1, 8), idx[("r", n, 1, 0)]: fmpq(1, 8)}
    k = fmpq(n)  # dart: smooth rule (F + 2R + (k - 3)V)/k, weights 1 - 7/(4k), 3/(2k^2), 1/(4k^2)
    row = {0: 1 - fmpq(7, 4) / k}
    for r in range(n):
        row[idx[("r", r, 1, 0)]] = fmpq(3, 2) / (k * k)
        row[idx[("q", r, 1, 1)]] = fmpq(1, 4) / (k * k)
    return row


@cache
def exact_spectrum(fam, n):
    """The characteristic polynomial's irreducible factors over Q with their algebraic multiplicity and
    the geometric multiplicity of each of their roots (exact): for a factor p of multiplicity e > 1,
    dim ker p(S) = deg(p) * (geometric multiplicity), so the roots are non-defective iff
    dim ker p(S) = e deg(p).

    Returns
    -------
    list of (fmpq_poly, int, int)
        ``(p, algebraic multiplicity, geometric multiplicity)`` (p primitive with integer coefficients).

    Examples
    --------
    The boundary vertex with one face: the cubic B-spline spectrum 1, 1/2, 1/4, 1/8 (twice) and the
    face's own eigenvalues; 1/4 is defective (a Jordan block of size 2):

    >>> sorted((str(p), a, g) for p, a, g in exact_spectrum("crease", 1))[:3]
    [('16*x + (-1)', 2, 2), ('2*x + (-1)', 1, 1), ('4*x + (-1)', 2, 1)]
    """
    _, fac = sector_matrix(fam, n).charpoly().factor()
    return [(p, e, 1 if e == 1 else kernel_dim(fam, n, p) // p.degree()) for p, e in fac]


def kernel_dim(fam, n, p):
    """dim ker p(S) (exact; p(S) by Horner) for a polynomial p over Q.

    Examples
    --------
    >>> kernel_dim("crease", 1, fmpq_poly([-1, 4])), kernel_dim("crease", 1, fmpq_poly([-1, 4]) ** 2)
    (1, 2)
    """
    S = sector_matrix(fam, n)
    m = S.nrows()
    eye, P = fmpq_mat([[int(i == j) for j in range(m)] for i in range(m)]), fmpq_mat(m, m)
    for c in reversed(p.coeffs()):
        P = P * S + eye * c
    return m - P.rank()


def crease_points(fam, n):
    """Indices (in :func:`labels` order) of the crease points: the centre, then (1, 0), (2, 0) of each
    sharp ray. Their rows involve only themselves for ``crease`` and ``corner`` (the block C).

    Examples
    --------
    >>> crease_points("crease", 3)
    [0, 1, 2, 7, 8]
    """
    pts = labels(fam, n)
    return [0] + [pts.index(("r", r) + p) for r in sharp_rays(fam, n) for p in RAY_POS]


def crease_block(fam, n):
    """The block C of S on :func:`crease_points`, after checking exactly that those rows vanish elsewhere.

    Raises
    ------
    CertificateError
        If a crease row involves another point (never for the true rules; a tripwire), or for a dart.

    Examples
    --------
    >>> C = crease_block("crease", 4)
    >>> sorted(str(p) for p, _ in C.charpoly().factor()[1])
    ['2*x + (-1)', '4*x + (-1)', '8*x + (-1)', 'x + (-1)']
    """
    if fam == "dart":
        raise CertificateError("a dart's sharp ray is not a closed block (its centre is smooth)")
    S, cp = sector_matrix(fam, n), crease_points(fam, n)
    for i in cp:
        if any(S[i, j] != 0 for j in range(S.ncols()) if j not in cp):
            raise CertificateError(f"{fam}:{n}: crease row {i} involves a non-crease point")
    return fmpq_mat([[S[i, j] for j in cp] for i in cp])


@lru_cache(maxsize=64)
def eigenvalues(fam, n, prec):
    """Every eigenvalue as (acb enclosure, its factor, algebraic multiplicity, geometric multiplicity),
    each root listed once per unit of algebraic multiplicity; isolated by arb (``complex_roots``), real
    roots with an exactly zero imaginary part.

    Examples
    --------
    >>> ev = eigenvalues("crease", 3, 64)
    >>> len(ev), sum(1 for z, p, a, g in ev if z.real.contains(1) and z.imag.is_zero())
    (21, 1)
    """
    out = []
    with ctx.workprec(prec):
        for p, e, g in exact_spectrum(fam, n):
            for z, _ in p.complex_roots():
                out += [(acb(z), p, e, g)] * e
    return tuple(out)


def _key(item):  # ordering for display and for choosing candidates; every decision is re-checked in arb
    return -abs(item[0]).mid()


def leading_spectrum(fam, n, prec):
    """The spectral part of the generalized Reif criterion for a sector (docs/tagged_c1.md):
    1 simple, lam1 >= lam2 > |every other| real and positive, lam1 and lam2 non-defective.

    Returns
    -------
    (bool, str, list)
        Whether the spectral part holds, the reason (which tie or Jordan block when not), and the
        leading eigenvalues (acb, factor, algebraic multiplicity, geometric multiplicity), at most 4.

    Examples
    --------
    >>> leading_spectrum("crease", 2, 64)[:2]
    (True, 'crease:2: 1 simple; lam1 = lam2 = 1/2 (double, non-defective) > |lam3| = 1/4')
    >>> leading_spectrum("crease", 4, 64)[1]
    'crease:4: lam2 = 1/2 lies in a Jordan block (algebraic multiplicity 2, geometric 1)'
    >>> leading_spectrum("crease", 100, 64)[:2]   # refused before any arithmetic (check_exact_budget)
    (False, 'crease:100: the exact route on S of 603 points exceeds the budget (m^3 > 128^3: N, K <= 20)')
    """
    name = f"{fam}:{n}"
    try:
        check_exact_budget(fam, n)  # before any arithmetic on the whole S
    except CertificateError as exc:
        return False, str(exc), []
    with ctx.workprec(prec):
        ev = sorted(eigenvalues(fam, n, prec), key=_key)
        one = [t for t in ev if t[1] == fmpq_poly([-1, 1])]
        if len(one) != 1:
            return False, f"{name}: eigenvalue 1 has multiplicity {len(one)}", ev[:4]
        rest = [t for t in ev if t[1] != fmpq_poly([-1, 1])]
        if any(not abs(t[0]) < 1 for t in rest):  # reviewed (tests/certify/test_arb_comparisons.py)
            return False, f"{name}: an eigenvalue other than 1 is not certainly inside the unit disc", ev[:4]
        l1, l2, l3 = rest[0], rest[1], rest[2]
        why = _not_simple_positive(name, "lam1", l1) or _not_simple_positive(name, "lam2", l2)
        if why:
            return False, why, ev[:4]
        same12 = l1[1] == l2[1] and l1[0].overlaps(l2[0])
        if not (same12 or l1[0].real > l2[0].real):
            return False, f"{name}: lam1 and lam2 are not separated", ev[:4]
        if l3[1] == l2[1] and l3[0].overlaps(l2[0]):
            return False, f"{name}: lam2 = lam3 = {_show(l2)} (multiplicity {l2[2]}): a tie", ev[:4]
        if not all(abs(t[0]) < l2[0].real for t in rest[2:]):
            return False, f"{name}: |lam3| is not certainly below lam2 = {_show(l2)}", ev[:4]
        lead = (f"lam1 = lam2 = {_show(l1)} (double, non-defective)" if same12 else
                f"lam1 = {_show(l1)} > lam2 = {_show(l2)} (simple)")
        return True, f"{name}: 1 simple; {lead} > |lam3| = {_show(l3)}", ev[:4]


def _not_simple_positive(name, lab, t):
    """Why the eigenvalue t is not certainly real, positive and non-defective (None when it is)."""
    if not (t[0].imag.is_zero() and t[0].real > 0):
        return f"{name}: {lab} = {_show(t)} is not certainly real and positive"
    if t[3] < t[2]:
        return f"{name}: {lab} = {_show(t)} lies in a Jordan block (algebraic multiplicity {t[2]}, geometric {t[3]})"
    return None


def _show(t):
    z, p = t[0], t[1]
    if p.degree() == 1:
        return str(-p[0] / p[1])
    return z.real.str(5, radius=False)
