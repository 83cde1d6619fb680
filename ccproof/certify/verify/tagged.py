"""The sector matrix S of a tagged configuration from OpenSubdiv's rules, its exact spectrum and the spectral
part of the criterion, a quadrant's level-1 values (the nets of a sector and of the dart family), the grammar of
the FAMILY:>=N0 records (trusted; docs/tagged_c1.md, "Configurations and rules" and "Spectrum (exact)").

Points: the centre ``("C",)``, ray r's ``("r", r, a, b)`` at RAY_POS, quadrant q's ``("q", q, a, b)`` at QUAD_POS;
crease:N and corner:N have rays 0..N (sharp: 0 and N), dart:K rays 0..K-1 mod K (sharp: 0).
"""

from __future__ import annotations

import re
from functools import cache, lru_cache

from flint import acb, ctx, fmpq, fmpq_mat, fmpq_poly

from .errors import CertificateError
from .record import exact_keys
from .replay import parse_decimal
from .rules import CENTRE, TWO_RING, apply, canonical, level1_rule

RAY_POS, QUAD_POS = ((1, 0), (2, 0)), ((1, 1), (2, 1), (1, 2), (2, 2))
MAX_SIZE, MAX_TAIL = 100, 10**6  # N, K at most MAX_SIZE; FAMILY:>=N0 needs N0 at most MAX_TAIL
EXACT_BUDGET = 128**3  # work m^3 of the exact route for S of m points; the published use at most 27 points
_NAME = re.compile(r"(dart|crease|corner):(>=)?([0-9]{1,7})")
ONE = fmpq_poly([-1, 1])  # the factor of the eigenvalue 1
WINDOW = (7, 8)  # the window classes of every N >= 7 occur in both
DECIMAL, FRACTION = "decimal", "fraction"  # field kinds of :func:`read_fields`


def parse_configuration(name):
    """``(family, n)`` from ``"dart:K"`` (2 <= K), ``"crease:N"``, ``"corner:N"`` (1 <= N; N, K <= MAX_SIZE), or
    ``(family, {"min": N0})`` from ``"FAMILY:>=N0"`` (2 <= N0 <= MAX_TAIL); CertificateError otherwise.

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
    fam, tail, n = m.group(1), m.group(2), int(m.group(3))
    lo, hi, v = (2, MAX_TAIL, "N0") if tail else (2 if fam == "dart" else 1, MAX_SIZE, "K" if fam == "dart" else "N")
    if not lo <= n <= hi:
        raise CertificateError(f"configuration {name!r}: {fam}:{tail or ''}{v} needs {lo} <= {v} <= {hi}")
    return fam, {"min": n} if tail else n


def read_fields(obj, spec, where):
    """``obj`` read by ``spec``, the one record grammar of the FAMILY:>=N0 records (:data:`.dart_tail.GRAMMAR`,
    :data:`.tagged_limit.GRAMMAR`): dicts exactly their keys, lists their length, (lo, hi) an int in range,
    "decimal" (:func:`.replay.parse_decimal`) and "fraction" an fmpq, a type a value of that type.

    >>> read_fields({"a": [1, "3/4"]}, {"a": [(0, 9), FRACTION]}, "demo")
    {'a': [1, 3/4]}
    >>> read_fields({"a": 10}, {"a": (0, 9)}, "demo")
    Traceback (most recent call last):
    ...
    ccproof.certify.verify.errors.CertificateError: demo a must lie in 0..9
    """
    if isinstance(spec, dict):
        exact_keys(obj, tuple(spec), where)
        return {k: read_fields(obj[k], s, f"{where} {k}") for k, s in spec.items()}
    if isinstance(spec, list):
        if not isinstance(obj, list) or len(obj) != len(spec):
            raise CertificateError(f"{where}: a list of {len(spec)} is needed")
        return [read_fields(x, s, where) for x, s in zip(obj, spec)]
    if spec == DECIMAL:
        return parse_decimal(obj)
    kind = int if isinstance(spec, tuple) else str if spec == FRACTION else spec
    if not isinstance(obj, kind) or isinstance(obj, bool):
        raise CertificateError(f"{where} has the wrong type")
    if isinstance(spec, tuple) and not spec[0] <= obj <= spec[1]:
        raise CertificateError(f"{where} must lie in {spec[0]}..{spec[1]}")
    if spec == FRACTION:
        a, _, b = obj.partition("/")
        if len(obj) > 40 or not (a.isdigit() and b.isdigit() and int(b) > 0):
            raise CertificateError(f"{where}: a fraction 'INT/INT' is needed")
        return fmpq(int(a), int(b))
    return obj


def check_exact_budget(fam, n):
    """Refuse, before any arithmetic, a configuration whose exact route (about m^3 for S of m points, 9 s of CPU for
    crease:100) exceeds EXACT_BUDGET; larger ones take the modes of :mod:`.tagged_modes` or nothing."""
    m = len(labels(fam, n))
    if m**3 > EXACT_BUDGET:
        raise CertificateError(f"{fam}:{n}: the exact route on S of {m} points exceeds the budget (m^3 > 128^3: "
                               "N, K <= 20)")


def labels(fam, n):
    """The points in matrix order: centre, ray points, quadrant points (6n + 3; a dart 6n + 1).

    >>> pts = labels("crease", 1)
    >>> len(pts), pts[:3]
    (9, [('C',), ('r', 0, 1, 0), ('r', 0, 2, 0)])
    """
    rays = n if fam == "dart" else n + 1
    return ([("C",)] + [("r", r) + p for r in range(rays) for p in RAY_POS]
            + [("q", q) + p for q in range(n) for p in QUAD_POS])


def sharp_rays(fam, n):
    """The sharp rays: ray 0 for a dart, rays 0 and n otherwise."""
    return (0,) if fam == "dart" else (0, n)


def position_key(fam, n, q, a, b):
    """The label of the raw grid position (a, b) of quadrant q (:func:`.rules.canonical`; mod K for a dart),
    whether or not the complex holds it.

    >>> position_key("dart", 5, 4, 0, 2), position_key("crease", 2, 0, 1, -1), position_key("crease", 2, 1, 0, 0)
    (('r', 0, 2, 0), ('q', -1, 1, 1), ('C',))
    """
    delta, a2, b2 = canonical(a, b)
    if (a2, b2) == CENTRE:
        return ("C",)
    s = (q + delta) % n if fam == "dart" else q + delta
    return ("r", s, a2, b2) if b2 == 0 else ("q", s, a2, b2)


def quadrant_level1(q, sharp, centre, ring, level0, zero):
    """``value(A, B)`` (memoized): the level-1 value at position (A, B), -1 <= A, B <= 3, of quadrant q, for a
    tagged sector and the dart family alike: ``centre`` at (0, 0), ``ring(s, pos)`` at a two-ring position of sector
    s, ghost values across a sharp ray (``sharp(s)``), the midpoint of level-0 (1, 0), (2, 0) at (3, 0) of a sharp
    ray, elsewhere the rule of :mod:`.rules` on the level-0 values ``level0(s, pos)`` (pos CENTRE: the centre)."""
    @cache
    def value(A, B):
        if (A, B) == CENTRE:
            return centre
        if B == -1 and sharp(q):  # across the sharp ray q: the ghost row
            return 2 * value(A, 0) - value(A, 1)
        if A == -1 and sharp(q + 1):  # across the sharp ray q + 1
            return 2 * value(0, B) - value(1, B)
        d, A2, B2 = canonical(A, B)
        if (A2, B2) in TWO_RING:
            return ring(q + d, (A2, B2))
        if B2 == 0 and sharp(q + d):  # (3, 0) on a sharp ray
            return (level0(q + d, (1, 0)) + level0(q + d, (2, 0))) / 2
        return apply(level1_rule(A2, B2), lambda dd, p: level0(q + d + dd, p), zero)
    return value


def point_index(fam, n):
    """``(idx, at)``: the index of each label, and ``at(q, comb)``: a combination of raw positions of quadrant q
    as ``{index: weight}`` (raises for a position outside the complex).

    >>> idx, at = point_index("crease", 2)
    >>> idx[("r", 2, 1, 0)], at(1, {(0, 1): fmpq(1, 2), (1, 0): fmpq(1, 2)})
    (5, {5: 1/2, 3: 1/2})
    """
    idx = {p: i for i, p in enumerate(labels(fam, n))}

    def at(q, comb):
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
    """The rows of S as sparse dicts {column: weight} (level-1 point i = sum_j row_i[j] level-0 point j).

    >>> sector_rows("crease", 2)[0]   # the crease centre (e0 + 6 V + e1)/8
    {0: 3/4, 1: 1/8, 5: 1/8}
    """
    idx, at = point_index(fam, n)
    half, eighth, k = fmpq(1, 2), fmpq(1, 8), fmpq(n)
    if fam == "dart":  # the smooth rule (F + 2R + (k - 3)V)/k: weights 1 - 7/(4k), 3/(2k^2), 1/(4k^2)
        centre = {0: 1 - fmpq(7, 4) / k}
        for r in range(n):
            centre.update({idx[("r", r, 1, 0)]: fmpq(3, 2) / k**2, idx[("q", r, 1, 1)]: fmpq(1, 4) / k**2})
    else:
        centre = {0: fmpq(1)} if fam == "corner" else {0: 6 * eighth, idx[("r", 0, 1, 0)]: eighth,
                                                       idx[("r", n, 1, 0)]: eighth}
    rows = []
    for p in labels(fam, n):
        if p == ("C",):
            row = centre
        elif p[0] == "r" and p[1] in sharp_rays(fam, n):
            e1, e2 = idx[("r", p[1], 1, 0)], idx[("r", p[1], 2, 0)]
            row = {0: half, e1: half} if p[2] == 1 else {0: eighth, e1: 6 * eighth, e2: eighth}
        else:  # a smooth ray (its b = -1 side is quadrant r - 1) or a quadrant point: the rule in that quadrant
            row = at(p[1], level1_rule(*p[2:]))
        rows.append({j: w for j, w in row.items() if w != 0})
    return tuple(rows)


def window_rows(fam, n):
    """{window class: the row relative to its point}; raises if one class has two rows. A class is the kind,
    the ray or quadrant clipped to 3 from either end, and the position; a column the kind, the offset from the
    row's ray (mod K for a dart, in -K/2 .. K/2) and the position; the centre reads rays 0 and N (``"N"``,
    N - ray); a dart's centre row is left out (:mod:`.dart_spectrum` checks it).

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


def window_classes(fam):
    """The rows of fam:N by window class (:func:`window_rows`), one table for every N >= 7: raise unless those of
    fam:7 and fam:8 (:data:`WINDOW`), in which every class occurs, are the same."""
    a, b = (window_rows(fam, n) for n in WINDOW)
    if a != b:
        raise CertificateError(f"{fam}: the window classes of {fam}:{WINDOW[0]} and {fam}:{WINDOW[1]} differ")
    return a


def _window_column(p, q, n, ring):  # the column of point q in the row of point p
    if q == ("C",):
        return q
    if p == ("C",):
        return q if q[1] <= 3 else (q[0], "N", n - q[1]) + q[2:]
    d = (q[1] - p[1]) % n if ring else q[1] - p[1]
    return (q[0], d - n if ring and d > n // 2 else d) + q[2:]


@cache
def sector_matrix(fam, n):
    """S as an exact fmpq_mat (:func:`sector_rows`)."""
    rows = sector_rows(fam, n)
    return fmpq_mat([[row.get(j, fmpq(0)) for j in range(len(rows))] for row in rows])


def kernel_dim(fam, n, p):
    """dim ker p(S) (exact; p(S) by Horner) for a polynomial p over Q.

    >>> kernel_dim("crease", 1, fmpq_poly([-1, 4])), kernel_dim("crease", 1, fmpq_poly([-1, 4]) ** 2)
    (1, 2)
    """
    S = sector_matrix(fam, n)
    P = fmpq_mat(S.nrows(), S.nrows())
    for c in reversed(p.coeffs()):
        P = P * S + identity(S.nrows()) * c
    return S.nrows() - P.rank()


def identity(m):
    """The m x m identity as an fmpq_mat."""
    return fmpq_mat([[int(i == j) for j in range(m)] for i in range(m)])


def crease_points(fam, n):
    """Indices of the crease points: the centre, then (1, 0), (2, 0) of each sharp ray (crease:3: 0, 1, 2, 7, 8)."""
    pts = labels(fam, n)
    return [0] + [pts.index(("r", r) + p) for r in sharp_rays(fam, n) for p in RAY_POS]


def crease_block(fam, n):
    """The block C of S on the crease points, after checking exactly that their rows vanish elsewhere (raises
    otherwise, and for a dart).

    >>> sorted(str(p) for p, _ in crease_block("crease", 4).charpoly().factor()[1])
    ['2*x + (-1)', '4*x + (-1)', '8*x + (-1)', 'x + (-1)']
    """
    if fam == "dart":
        raise CertificateError("a dart's sharp ray is not a closed block (its centre is smooth)")
    rows, cp = sector_rows(fam, n), crease_points(fam, n)
    bad = [i for i in cp if not set(rows[i]) <= set(cp)]  # the rows hold their non-zero weights only
    if bad:
        raise CertificateError(f"{fam}:{n}: crease row {bad[0]} involves a non-crease point")
    return fmpq_mat([[rows[i].get(j, fmpq(0)) for j in cp] for i in cp])


@cache
def _factors(fam, n):  # (p, algebraic multiplicity e, geometric multiplicity dim ker p(S) / deg p) per factor
    _, fac = sector_matrix(fam, n).charpoly().factor()
    return [(p, e, 1 if e == 1 else kernel_dim(fam, n, p) // p.degree()) for p, e in fac]


@lru_cache(maxsize=64)
def eigenvalues(fam, n, prec):
    """Every eigenvalue once per unit of algebraic multiplicity: (acb, its irreducible factor over Q, algebraic,
    geometric multiplicity); real roots have an exactly zero imaginary part.

    >>> sorted({(str(p), a, g) for z, p, a, g in eigenvalues("crease", 1, 64)})[:3]   # 1/4: a Jordan block
    [('16*x + (-1)', 2, 2), ('2*x + (-1)', 1, 1), ('4*x + (-1)', 2, 1)]
    """
    out = []
    with ctx.workprec(prec):
        for p, e, g in _factors(fam, n):
            out += [(acb(z), p, e, g) for z, _ in p.complex_roots() for _ in range(e)]
    return tuple(out)


def _show(t):  # an eigenvalue entry for a message: exact when rational
    return str(-t[1][0] / t[1][1]) if t[1].degree() == 1 else t[0].real.str(5, radius=False)


def leading_spectrum(fam, n, prec):
    """(ok, reason, the leading entries of :func:`eigenvalues`, at most 4): 1 simple, lam1 >= lam2 > |others| real
    and positive, lam1 and lam2 non-defective; refused beyond :func:`check_exact_budget`.

    >>> leading_spectrum("crease", 2, 64)[:2]
    (True, 'crease:2: 1 simple; lam1 = lam2 = 1/2 (double, non-defective) > |lam3| = 1/4')
    >>> leading_spectrum("crease", 4, 64)[1]
    'crease:4: lam2 = 1/2 lies in a Jordan block (algebraic multiplicity 2, geometric 1)'
    >>> leading_spectrum("crease", 100, 64)[1]
    'crease:100: the exact route on S of 603 points exceeds the budget (m^3 > 128^3: N, K <= 20)'
    """
    name = f"{fam}:{n}"
    try:
        check_exact_budget(fam, n)  # before any arithmetic on the whole S
    except CertificateError as exc:
        return False, str(exc), []
    with ctx.workprec(prec):
        ev = sorted(eigenvalues(fam, n, prec), key=lambda t: -abs(t[0]).mid())  # order only: decisions in arb
        rest = [t for t in ev if t[1] != ONE]
        l1, l2, l3 = rest[:3]
        same12 = l1[1] == l2[1] and l1[0].overlaps(l2[0])
        why = (f"eigenvalue 1 has multiplicity {len(ev) - len(rest)}" if len(ev) - len(rest) != 1 else
               "an eigenvalue other than 1 is not certainly inside the unit disc"
               if any(not abs(t[0]) < 1 for t in rest) else  # reviewed (tests/certify/test_arb_comparisons.py)
               _not_simple_positive("lam1", l1) or _not_simple_positive("lam2", l2) or
               ("lam1 and lam2 are not separated" if not (same12 or l1[0].real > l2[0].real) else
                f"lam2 = lam3 = {_show(l2)} (multiplicity {l2[2]}): a tie" if l3[1] == l2[1] and l3[0].overlaps(l2[0])
                else f"|lam3| is not certainly below lam2 = {_show(l2)}"
                if not all(abs(t[0]) < l2[0].real for t in rest[2:]) else None))
        if why:
            return False, f"{name}: {why}", ev[:4]
        lead = (f"lam1 = lam2 = {_show(l1)} (double, non-defective)" if same12 else
                f"lam1 = {_show(l1)} > lam2 = {_show(l2)} (simple)")
        return True, f"{name}: 1 simple; {lead} > |lam3| = {_show(l3)}", ev[:4]



def _not_simple_positive(lab, t):  # why the entry t is not certainly real, positive and non-defective
    if not (t[0].imag.is_zero() and t[0].real > 0):
        return f"{lab} = {_show(t)} is not certainly real and positive"
    return f"{lab} = {_show(t)} lies in a Jordan block (algebraic multiplicity {t[2]}, geometric {t[3]})" \
        if t[3] < t[2] else None
