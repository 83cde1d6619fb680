"""Tagged certificates of one configuration (schema ``ccproof.tagged-c1/1``), "C1" and "not C1" (trusted).

"C1": the spectral part, the crease seen, the eigenvectors x, y, the map (:func:`.tagged_map.check_map`). "not C1":
a witness net's x, y, z, part G (the generic pair; a dart's flip; a Jordan chain), then B and N (a flip: F). The
arguments: docs/tagged_c1.md, "What a certificate states" and "Two refutations beyond the generic pair".
"""

from __future__ import annotations

from flint import arb, arb_mat, ctx, fmpq, fmpq_mat, fmpq_poly

from . import tagged as tg
from .c1 import read_prec
from .errors import CertificateError
from .record import exact_keys, field_of
from .replay import parse_decimal
from .tagged_map import all_zero, check_map
from .tagged_modes import MIN_N, bordered_solve, kernel_basis, mode_spectrum, normalized_vector

LIMIT_MASK = (fmpq(1, 6), fmpq(4, 6), fmpq(1, 6))  # a cubic B-spline's limit weights on three control points
TANGENT_MASK = (fmpq(-1, 2), fmpq(0), fmpq(1, 2))  # and its tangent's
G_GENERIC = ("G generic: alpha = lam1, beta = lam2, gamma = the crease block's largest eigenvalue below 1; "
             "no Jordan block at |lam| >= beta; gamma < beta for a generalized z")
_G_FLIP = ("G generic: alpha, beta simple, of opposite signs, each larger in modulus than every other eigenvalue "
           "but 1 (simple)")
_G_CHAIN = ("G generic (Jordan chain): alpha = lam1 simple > beta = gamma, the crease block's largest eigenvalue "
            "below 1; Jordan blocks at beta of size <= 2, y's chain tops at e; every other |lam| < beta")


def verify_tagged(cert, part, log):
    """Check a tagged certificate (``witness`` for "not C1", ``map`` and ``parts`` for "C1") into ``part``; the
    configuration name, or CertificateError on a malformed certificate.

    >>> import json
    >>> from ccproof.tables.format import certificates_dir
    >>> from ccproof.certify.verify.record import Recorder, VerifyResult
    >>> cert = json.loads((certificates_dir() / "c1" / "crease" / "n005.json").read_text())
    >>> res = VerifyResult()
    >>> verify_tagged(cert, Recorder(res, lambda line: None), lambda line: None), bool(res)
    ('crease:5', True)
    """
    statement = field_of(cert, "statement", str, "certificate")  # "C1" or "not C1": the registry's route took it
    exact_keys(cert, ("schema", "configuration", "statement", "prec") + (
        ("witness",) if statement == "not C1" else ("map", "parts")), "certificate")
    name = field_of(cert, "configuration", str, "certificate")
    fam, n = tg.parse_configuration(name)
    prec = read_prec(cert)
    log(f"{statement} certificate for {name} ({prec} bits)")
    rows = tg.sector_rows(fam, n)
    part("S sector matrix derived from the rules", all(sum(row.values(), fmpq(0)) == 1 for row in rows),
         f"{len(rows)} points, rows sum to 1 (exact)")
    with ctx.workprec(prec):
        if statement == "C1":
            _verify_c1(cert, fam, n, prec, part)
        else:
            _verify_witness(field_of(cert, "witness", dict, "certificate"), fam, n, prec, part, log)
    return name


def _verify_c1(cert, fam, n, prec, part):
    """The spectral part (a dart with K >= MIN_N from the mode list, else exact), the crease seen, x, y, the map."""
    modes = fam == "dart" and n >= MIN_N
    ev = mode_spectrum("dart", n) if modes else None
    ok, msg, lead = _dart_leading(n, ev) if modes else tg.leading_spectrum(fam, n, prec)
    part("spectral part of the generalized Reif criterion", ok, msg)
    if ok and fam != "dart":
        cpoly = tg.crease_block(fam, n).charpoly()
        ok = any(t[1].gcd(cpoly).degree() > 0 for t in lead[1:3])
        part("the tangent plane sees the crease: lam1 or lam2 is an eigenvalue of the crease block", ok,
             "" if ok else "both eigenvectors vanish on the crease points, so the characteristic map "
             "sends the sharp edges to v (not injective)")
    if part.failed:
        return
    mp = field_of(cert, "map", dict, "certificate")
    exact_keys(mp, ("x", "y", "orientation"), "map")
    if mp["orientation"] not in (1, -1) or isinstance(mp["orientation"], bool):
        raise CertificateError("map.orientation must be 1 or -1")
    vecs, vals = {}, {}
    for c, t in (("x", lead[1]), ("y", lead[2])):
        spec = field_of(mp, c, dict, "map")  # a mode coordinate is the entry t itself, an exact one must be its root
        val, vec, msg = (ev[t][0].real, *_mode_coordinate(fam, n, ev, spec, c, t)[1:]) if modes else \
            eigenvector_of(fam, n, spec, c, prec)
        ok = vec is not None and (modes or _same_root(t, val))
        part(f"{c}: eigenvector of lam{'1' if c == 'x' else '2'}", ok,
             msg if vec is None or ok else "not the eigenvalue of lam1 / lam2")
        if not ok:
            return
        vals[c], vecs[c] = val, vec
    check_map(fam, n, vecs["x"], vecs["y"], vals["x"], vals["y"], mp["orientation"],
              field_of(cert, "parts", dict, "certificate"), prec, part)


def _dart_leading(k, ev):
    """(ok, message, (None, i1, i2)): a dart's lam1 and lam2 in the mode list and whether the spectral part holds."""
    rest = sorted((i for i, t in enumerate(ev) if abs(t[0]) < 1), key=lambda i: -abs(ev[i][0]).mid())
    (i1, i2), (l1, l2) = rest[:2], (ev[rest[0]][0], ev[rest[1]][0])
    why = _mode_lead_why(ev, i1, i2) or (
        "lam1 or lam2 is not certainly real and positive" if not all(z.imag.is_zero() and z.real > 0 for z in (l1, l2))
        else "lam1 > lam2 is not certain" if not l1.real > l2.real else None)
    where = [f"mode {ev[i][3]}" if ev[i][3] else "even" for i in (i1, i2)]
    return why is None, (f"dart:{k}: 1 simple; lam1 = {l1.real.str(5, radius=False)} ({where[0]}) > lam2 = "
                         f"{l2.real.str(5, radius=False)} ({where[1]}), each simple"
                         f" > |lam3| = {abs(ev[rest[2]][0]).str(5, radius=False)}" if why is None else
                         f"dart:{k}: {why}"), (None, i1, i2)


def _isolated_coordinate(ev, spec, c, cp, cval, simple, what, solve):
    """(i, vector, message) of a coordinate whose [low, high] isolates the entry i of ``ev`` (certainly inside, no
    other touching it), real, ``simple(i)``, its crease values 0; ``solve(i, pivot)``: (vector or None, message).
    (None, None, the reason) otherwise."""
    lo_hi = field_of(spec, "eigenvalue", list, c)
    if len(lo_hi) != 2:
        raise CertificateError(f"{c}: the eigenvalue must be [low, high]")
    lo, hi = parse_decimal(lo_hi[0]), parse_decimal(lo_hi[1])
    inside = [j for j, t in enumerate(ev) if t[0].real > lo and t[0].real < hi]
    near = [j for j, t in enumerate(ev) if t[0].real.overlaps(arb(lo).union(arb(hi)))]
    i = inside[0] if len(inside) == 1 and near == inside else None
    if any(v != 0 for v in cval):
        return None, None, "an irrational eigenvalue's eigenvector vanishes on the crease points"
    if i is None or not ev[i][0].imag.is_zero() or not simple(i):
        return None, None, f"[{lo_hi[0]}, {lo_hi[1]}] does not isolate {what}"
    return (i,) + solve(i, _pivot(spec, c, len(ev), cp))


def _verify_witness(w, fam, n, prec, part, log):
    """A "not C1" witness: x, y (, z), G, then B and N; a dart's flip (x, y, quadrant): G and F."""
    dart = fam == "dart"
    exact_keys(w, ("x", "y", "quadrant") if dart else ("x", "y", "z", "ray", "quadrant"), "witness")
    r, q = 0 if dart else field_of(w, "ray", int, "witness"), field_of(w, "quadrant", int, "witness")
    if r not in tg.sharp_rays(fam, n) or not 0 <= q < n:
        raise CertificateError(f"witness: quadrant {q} outside 0..{n - 1}" if r == 0 or r == n else
                               f"witness: ray {r} is not sharp")
    if dart and n >= MIN_N:
        part("x: eigenvector of S", False, f"a dart's witness is checked on the exact spectrum, K < {MIN_N} only")
        return
    got = _witness_modes(fam, n, w, part) if n >= MIN_N else _witness_exact(fam, n, w, prec, part)
    if got is None:
        return
    vecs, second, label = got
    if not dart:
        check_boundary(fam, n, r, (vecs["x"], vecs["y"]), vecs["z"], part)
    J = _jacobian(fam, n, q, vecs["x"], second)
    part(f"F flip at vertex (1,1) of quadrant {q}: J_xy != 0, so the normal there is (alpha beta)^m J_xy e_z + "
         "o(|alpha beta|^m)" if dart else f"N normal at vertex (1,1) of quadrant {q}: {label} != 0", J > 0 or J < 0,
         f"{label} = {J.str(6)}")
    if not part.failed:
        log(f"  the limit surface of this net is not C1 at the {fam} vertex: the unit normals at the level-m copies of "
            f"quadrant {q}'s (1,1) tend to " + ("(-1)^m sign(J_xy) e_z (no limit; the projection folds)" if dart else
                                                f"n_z != 0, yet e_z lies in T_v (ray {r})"))


def _witness_exact(fam, n, w, prec, part):
    """Parts x, y (, z) and G on the exact spectrum: (vectors, the vector paired with x in N or F, its name) or
    None; a generalized y (a Jordan chain at beta) pairs x with its top e = (S - beta) y."""
    vecs, vals, tops = {}, {}, {}
    for c in ("x", "y") if fam == "dart" else ("x", "y", "z"):
        vals[c], vecs[c], msg = eigenvector_of(fam, n, field_of(w, c, dict, "witness"), c, prec,
                                               c != "x" and fam != "dart")
        tops[c] = None if vecs[c] is None else _chain_top(fam, n, vals[c], vecs[c])
        part(f"{c}: {'(generalized) ' if c == 'z' or tops[c] else ''}eigenvector of S", vecs[c] is not None, msg)
        if vecs[c] is None:
            return None
    ev = tg.eigenvalues(fam, n, prec)  # each root once per unit of algebraic multiplicity
    if fam == "dart":
        title, second, check = _G_FLIP, "J_xy", lambda: _flip_generic(ev, vals["x"], vals["y"])
    elif tops["y"] is not None:
        title, second, check = _G_CHAIN, "J_xe", lambda: _chain_generic(fam, n, ev, vals, tops)
    else:
        title, second, check = G_GENERIC, "J_xy", lambda: _ordering(fam, n, ev, vals, tops["z"] is not None)
    ok, msg = (False, "eigenvalue 1 is not simple") if sum(1 for t in ev if t[1] == tg.ONE) != 1 else check()
    part(title, ok, msg)
    if ok and fam != "dart":  # B reads z on the crease points
        vecs["z"] = [vecs["z"][i] for i in tg.crease_points(fam, n)]
    return (vecs, tops["y"] if second == "J_xe" else vecs["y"], second) if ok else None


def _witness_modes(fam, n, w, part):
    """Parts x, y, z and G for crease:N, corner:N, N >= MIN_N: x and y eigenvectors of simple mode roots (closed
    form), z's existence from its crease values."""
    ev, vecs, at = mode_spectrum(fam, n), {}, {}
    for c in ("x", "y"):
        at[c], vecs[c], msg = _mode_coordinate(fam, n, ev, field_of(w, c, dict, "witness"), c)
        part(f"{c}: eigenvector of S", vecs[c] is not None, msg)
        if vecs[c] is None:
            return None
    g, cval = read_z(field_of(w, "z", dict, "witness"))
    at_g = [t for t in ev if t[2] == "I" and (t[1] == g if t[1] is not None else t[0].real.overlaps(arb(g)))]
    why = crease_eigen_why(tg.crease_block(fam, n), g, cval) or (
        f"{g} is possibly a multiple eigenvalue of I" if len(at_g) > 1 else None)
    part("z: (generalized) eigenvector of S", why is None, why or
         f"eigenvalue {g}: C c = {g} c exactly on the crease points, and {g} is at most a simple eigenvalue of I, so "
         f"some z with these crease values has (S - {g})^2 z = 0 and (S - {g}) z = 0 on the crease points")
    if why is not None:
        return None
    ia, ib = at["x"], at["y"]
    why = _mode_lead_why(ev, ia, ib) or crease_top_why(tg.crease_block(fam, n), g) or (
        "gamma < beta is not certain" if not arb(g) < ev[ib][0].real else None)
    part(G_GENERIC, why is None, why or f"alpha = {ev[ia][0].real.str(8)} > beta = {ev[ib][0].real.str(8)} > "
         f"|every other| (each simple), 1 simple; gamma = {g} < beta")
    vecs["z"] = cval
    return None if why else (vecs, vecs["y"], "J_xy")


def _crease_values(spec, c, cp):  # the crease values of a coordinate, one decimal per crease point
    crease = field_of(spec, "crease", list, c)
    if len(crease) != len(cp):
        raise CertificateError(f"{c}: crease values must be {len(cp)} decimals" + ("" if cp else " (dart: crease [])"))
    return [parse_decimal(v) for v in crease]


def _pivot(spec, c, m, cp):  # the pivot of a coordinate: a non-crease point
    pivot = field_of(spec, "pivot", int, c)
    if not 0 <= pivot < m or pivot in cp:
        raise CertificateError(f"{c}: pivot must index a non-crease point")
    return pivot


def _mode_coordinate(fam, n, ev, spec, c, want=None):
    """(index in the mode list ``ev``, eigenvector with 1 at the pivot, message) of x or y, or (None, None, the
    reason): [low, high] isolates one simple real root of a mode (a dart's even part too; the entry ``want``,
    a dart's lam1 or lam2, when given), whose eigenvector vanishes on the crease points."""
    exact_keys(spec, ("eigenvalue", "crease", "pivot"), c)
    cp = [] if fam == "dart" else tg.crease_points(fam, n)

    def solve(i, pivot):
        vec, j = normalized_vector(fam, n, ev, i, pivot), ev[i][3]
        if vec is None:
            return None, f"the eigenvector is not certainly non-zero at the pivot {pivot} (or its system not " \
                         "certainly regular)"
        how = (", simple; even: the bordered system on S_E" if j is None else
               f" = lam(cos({2 * j if fam == 'dart' else j} pi/{n})), simple; closed form in mode {j}: its 6x6 system")
        return vec, f"eigenvalue {ev[i][0].real.str(10)}{how} proved regular, pivot {tg.labels(fam, n)[pivot]}"
    return _isolated_coordinate(ev, spec, c, cp, _crease_values(spec, c, cp),
                                lambda i: want in (None, i) and (ev[i][3] is not None or fam == "dart"),
                                "one simple real root of a mode" if want is None else
                                f"lam{'1' if c == 'x' else '2'}: not the eigenvalue of lam1 / lam2", solve)


def read_z(spec):
    """(gamma, crease values) of a witness's z ``{"eigenvalue": decimal, "crease": 5 decimals}``, read exactly.

    >>> read_z({"eigenvalue": "0.5", "crease": ["0", "1", "2", "0", "0"]})
    (1/2, [0, 1, 2, 0, 0])
    """
    exact_keys(spec, ("eigenvalue", "crease"), "z")
    return parse_decimal(field_of(spec, "eigenvalue", str, "z")), _crease_values(spec, "z", range(5))


def crease_eigen_why(C, g, cval):
    """None when C c = g c exactly with c != 0 (c the crease values), else the reason."""
    Cc = C * fmpq_mat([[v] for v in cval])
    ok = any(v != 0 for v in cval) and all(Cc[i, 0] == g * v for i, v in enumerate(cval))
    return None if ok else f"no eigenvector for {g} with the given crease values (C c = {g} c, c != 0 fails)"


def eigenvector_of(fam, n, spec, c, prec, chain=False):
    """(eigenvalue, vector, message) of a coordinate on the exact spectrum (vector None with the reason when the
    claim fails): a rational eigenvalue exactly (with ``chain`` also a generalized eigenvector z: (S - lam)^2 z = 0,
    (S - lam) z != 0 and 0 on the crease points), an irrational one by the bordered system in arb.

    >>> eigenvector_of("crease", 2, {"eigenvalue": "0.5", "crease": ["0", "1", "2", "-1", "-2"]}, "x", 64)[2]
    'eigenvalue 1/2; S v = 1/2 v exactly'
    """
    exact_keys(spec, ("eigenvalue", "crease", "pivot") if "pivot" in spec else ("eigenvalue", "crease"), c)
    cp = [] if fam == "dart" else tg.crease_points(fam, n)  # a dart's sharp ray is no closed block
    cval, S = _crease_values(spec, c, cp), tg.sector_matrix(fam, n)
    if not isinstance(spec["eigenvalue"], str):  # an irrational eigenvalue, [low, high]: the bordered system in arb
        ev, free = tg.eigenvalues(fam, n, prec), [j for j in range(S.nrows()) if j not in cp]

        def solve(i, pivot):
            if cp and ev[i][1].gcd(tg.crease_block(fam, n).charpoly()).degree() > 0:
                return None, "the eigenvalue is one of the crease block's"
            try:
                sol = dict(zip(free, bordered_solve([[arb(S[a, b]) for b in free] for a in free], ev[i][0].real,
                                                    free.index(pivot), arb_mat)))
            except ZeroDivisionError:
                return None, f"the system for the eigenvector of {ev[i][0].real.str(8)} (pivot {pivot}) is not " \
                             "certainly regular"
            return [sol.get(j, arb(0)) for j in range(S.nrows())], f"eigenvalue {ev[i][0].real.str(10)} (simple " \
                f"root of {ev[i][1]}); vector in arb, pivot {tg.labels(fam, n)[pivot]}"
        i, vec, msg = _isolated_coordinate(ev, spec, c, cp, cval, lambda i: ev[i][2] == 1,
                                           f"one simple real eigenvalue of {fam}:{n}", solve)
        return None if i is None else ev[i][0].real, vec, msg
    lam = parse_decimal(spec["eigenvalue"])
    A = S - lam * tg.identity(S.nrows())
    if "pivot" in spec:  # one more fixed coordinate: 1 at the pivot
        cp, cval = cp + [_pivot(spec, c, S.nrows(), cp)], cval + [fmpq(1)]
    vec = _solve_exact(A, cp, cval)
    if vec is not None:
        return lam, vec, f"eigenvalue {lam}; S v = {lam} v exactly"
    vec = _solve_exact(A * A, cp, cval) if chain else None
    if vec is None:
        return lam, None, f"no eigenvector for {lam} with the given crease values"
    u = A * fmpq_mat([[v] for v in vec])
    if any(u[i, 0] != 0 for i in cp):
        return lam, None, f"(S - {lam}) z is not 0 on the crease points"
    return lam, vec, f"eigenvalue {lam}; (S - {lam})^2 z = 0 exactly, (S - {lam}) z != 0 vanishes on the crease " \
                     "(generalized)"


def _solve_exact(A, cp, cval):
    """A vector v != 0 with A v = 0 exactly and v = cval on the points cp (free unknowns 0), or None."""
    free = [i for i in range(A.nrows()) if i not in cp]
    sol = kernel_basis(fmpq_mat([[A[i, j] for j in free] + [sum((A[i, j] * cval[k] for k, j in enumerate(cp)), fmpq(0))]
                                 for i in range(A.nrows())])).get(len(free))  # consistent iff the last column is free
    vec = None if sol is None else dict(zip(cp, cval)) | dict(zip(free, sol))
    return [vec[j] for j in range(A.nrows())] if vec and any(v != 0 for v in vec.values()) else None


def check_boundary(fam, n, r, xy, zc, part):
    """Part B into ``part``: ray r's limit curve lies on the z-axis (the vectors ``xy`` exactly 0 on its crease
    points) and z's limit leaves v (0 at v, not 0 at ray r's first point); ``zc`` z on the crease points."""
    idx, _ = tg.point_index(fam, n)
    curve = [0] + [idx[("r", s, a, 0)] for s in (tg.sharp_rays(fam, n) if fam == "crease" else (r,)) for a in (1, 2)]
    z, leave = dict(zip(tg.crease_points(fam, n), zc)), None
    ok = all_zero(v[i] for v in xy for i in curve) and all(isinstance(z[i], fmpq) for i in curve)
    if ok:  # the limit of z at v and at ray r's first point (the B-spline limit mask)
        at_v = z[0] if fam == "corner" else (z[idx[("r", 0, 1, 0)]] + 4 * z[0] + z[idx[("r", n, 1, 0)]]) / 6
        leave = (z[0] + 4 * z[idx[("r", r, 1, 0)]] + z[idx[("r", r, 2, 0)]]) / 6
        ok = at_v == 0 and leave != 0
    part(f"B boundary segment: ray {r}'s limit curve lies on the z-axis and leaves v", ok,
         f"x = y = 0 on its crease points, limit z at v = 0, limit z of ray {r}'s first point = {leave}" if ok
         else "x or y not exactly 0 on the curve, or z's limit curve does not start at v = 0 and leave it")


def _jacobian(fam, n, q, x, y):  # J_xy at the vertex (1,1) of quadrant q
    idx, _ = tg.point_index(fam, n)
    (xa, xb), (ya, yb) = (vertex_tangents({(a, b): v[idx[tg.position_key(fam, n, q, a, b)]] for a in range(3)
                                           for b in range(3)}) for v in (x, y))
    return xa * yb - xb * ya


def vertex_tangents(val):
    """(T_a, T_b), the limit tangents at a regular vertex from its 1-ring's values ``val[a, b]`` (a, b = 0, 1, 2):
    the B-spline masks sum w'(a) w(b) val and sum w(a) w'(b) val (arb, or acb from acb values).

    >>> ta, tb = vertex_tangents({(a, b): fmpq(a + 2 * b) for a in range(3) for b in range(3)})
    >>> ta.contains(1), tb.contains(2)
    (True, True)
    """
    return tuple(sum((da[a] * db[b] * val[a, b] for a in range(3) for b in range(3)), arb(0))
                 for da, db in ((TANGENT_MASK, LIMIT_MASK), (LIMIT_MASK, TANGENT_MASK)))


# ----------------------------------------------------------------- part G (docs/tagged_c1.md, "not C1")
def _same_root(t, v):
    """Is v (an fmpq, or the arb ball of an irrational root) the root t[0] of the factor t[1]?"""
    if isinstance(v, fmpq):
        return t[1].degree() == 1 and -t[1][0] / t[1][1] == v
    return t[1].degree() > 1 and t[0].real.overlaps(v) and t[0].imag.is_zero()


def _find(ev, v, skip=()):  # the first entry other than 1 and those in skip with the root v
    return next((i for i, t in enumerate(ev) if i not in skip and t[1] != tg.ONE and _same_root(t, v)), None)


def _pair(ev, a, b):  # the entries of alpha and beta (distinct, neither the eigenvalue 1), None where missing
    ia = _find(ev, a)
    return ia, None if ia is None else _find(ev, b, (ia,))


def _below(ev, skip, bounds, what, tie=None):
    """The reason an entry other than 1, those in ``skip`` and roots equal to ``tie`` is not certainly below each
    of ``bounds`` in modulus, or None."""
    bad = [t for i, t in enumerate(ev) if i not in skip and t[1] != tg.ONE and not (
        tie is not None and _same_root(t, tie)) and not all(abs(t[0]) < b for b in bounds)]
    return f"an eigenvalue ({bad[0][0].str(6)}) is not certainly {what}" if bad else None


def _chain_top(fam, n, lam, vec):
    """(S - lam) vec exactly, or None when vec is an eigenvector (or lam is not rational)."""
    if not isinstance(lam, fmpq) or any(not isinstance(v, fmpq) for v in vec):
        return None
    u = tg.sector_matrix(fam, n) * fmpq_mat([[v] for v in vec])
    top = [u[i, 0] - lam * vec[i] for i in range(len(vec))]
    return top if any(v != 0 for v in top) else None


def _flip_generic(ev, a, b):
    """(ok, message): G of a dart's flip (1 simple): alpha, beta simple, certainly of opposite signs, each certainly
    larger in modulus than every other eigenvalue."""
    ia, ib = _pair(ev, a, b)
    A, B = (None, None) if ib is None else (ev[ia][0].real, ev[ib][0].real)
    why = ("alpha or beta is not an eigenvalue (distinct from the other)" if ib is None else
           "alpha or beta is not a simple eigenvalue" if ev[ia][2] != 1 or ev[ib][2] != 1 else
           "alpha beta < 0 is not certain" if not (A > 0 and B < 0 or A < 0 and B > 0) else
           _below(ev, (ia, ib), (abs(A), abs(B)), "smaller in modulus than alpha and beta"))
    return why is None, why or (f"alpha = {A.str(8, radius=False)}, beta = {B.str(8, radius=False)}: alpha beta < 0, "
                                "each simple, > |every other|; 1 simple")


def _chain_generic(fam, n, ev, vals, tops):
    """(ok, message): G of a Jordan-chain witness (1 simple); ``vals`` the eigenvalues of x, y, z, ``tops`` (S - lam)
    of each (None for an eigenvector, :func:`_chain_top`); e = (S - beta) y is 0 on the crease points (and the
    pivot) by :func:`eigenvector_of`, which returns a generalized y only then."""
    a, b, g = vals["x"], vals["y"], vals["z"]
    if tops["y"] is None or tops["z"] is not None or tops["x"] is not None or not isinstance(b, fmpq):
        return False, "y is no generalized eigenvector of a rational beta, or z or x is one"
    ia = _find(ev, a)
    at_b = [i for i, t in enumerate(ev) if _same_root(t, b)]
    why = (
        "alpha is not a simple eigenvalue" if ia is None or ev[ia][2] != 1 or ia in at_b else
        "alpha > beta > 0 is not certain" if not (b > 0 and ev[ia][0].real > b) else
        # beta's Jordan blocks have size <= 2 iff dim ker (S - beta)^2 is its algebraic multiplicity (exact)
        f"a Jordan block of size > 2 at beta = {b}" if tg.kernel_dim(fam, n, fmpq_poly([-b, 1]) ** 2) != len(at_b) else
        _below(ev, [ia, *at_b], (b,), "below beta in modulus") or crease_top_why(tg.crease_block(fam, n), g) or
        ("gamma is not beta" if g != b else None))
    return why is None, why or (
        f"alpha = {ev[ia][0].real.str(8, radius=False)} > beta = {b} = gamma > |every other|, 1 simple; beta: "
        f"algebraic multiplicity {len(at_b)}, geometric {ev[at_b[0]][3]}, Jordan blocks of size <= 2 (dim ker "
        "(S - beta)^2 = algebraic multiplicity); e = (S - beta) y != 0, 0 on the crease points")


def crease_top_why(C, g):
    """None if g is the largest eigenvalue below 1 of the crease block C (its factors all linear), else the reason.

    >>> crease_top_why(tg.crease_block("crease", 7), fmpq(1, 2)), crease_top_why(tg.crease_block("crease", 7), 0)
    (None, "gamma is not the crease block's largest eigenvalue below 1 (1/2)")
    """
    fac = [p for p, _ in C.charpoly().factor()[1]]
    if any(p.degree() > 1 for p in fac):
        return "the crease block has irrational eigenvalues"
    below = [-p[0] / p[1] for p in fac if -p[0] / p[1] < 1]
    if not isinstance(g, fmpq) or not below or g != max(below):
        return f"gamma is not the crease block's largest eigenvalue below 1 ({max(below) if below else None})"
    return None


def _mode_lead_why(ev, ia, ib):
    """The reason 1 (from the crease block, or a dart's even part) is not simple or the entries ia, ib of the mode
    list (:func:`.tagged_modes.mode_spectrum`) do not lead (alpha >= beta > |every other|), or None."""
    one = [t for t in ev if not abs(t[0]) < 1]
    beta = ev[ib][0].real
    others = [t for i, t in enumerate(ev) if i not in (ia, ib) and t[1] != 1]
    return ("x and y are the same eigenvector (beta is not an eigenvalue distinct from alpha)" if ia == ib else
            "eigenvalue 1 is not simple" if len(one) != 1 or one[0][1] != 1 or one[0][2] not in ("C", "E") else
            "alpha >= beta is not certain" if not ev[ia][0].real >= beta else
            "an eigenvalue is not certainly below beta (lam1, lam2 not alpha, beta)"
            if not all(abs(t[0]) < beta for t in others) else None)


def _ordering(fam, n, ev, vals, generalized):
    """(ok, message): G of the generic pair (1 simple): a = lam1 >= b = lam2 >= every other |lam| (ties only with b
    itself), g the crease block's largest eigenvalue below 1, every eigenvalue of modulus possibly >= b
    non-defective, and g < b when z is a generalized eigenvector."""
    a, b, g = vals["x"], vals["y"], vals["z"]
    ia, ib = _pair(ev, a, b)
    beta = None if ib is None else abs(ev[ib][0])
    why = (
        "alpha is not an eigenvalue" if ia is None else "beta is not an eigenvalue (distinct from alpha's copy)"
        if ib is None else "alpha >= beta is not certain" if not (abs(ev[ia][0]) >= beta or ev[ia][1] == ev[ib][1])
        else _below(ev, (ia, ib), (beta,), "below beta (lam1, lam2 not alpha, beta)", b) or
        crease_top_why(tg.crease_block(fam, n), g) or _jordan_at(ev, beta) or
        ("z is a generalized eigenvector but gamma < beta is not certain" if generalized and not arb(g) < beta
         else None))
    show = [str(v) if isinstance(v, fmpq) else v.str(8) for v in (a, b)] + [" (Jordan chain)" if generalized else ""]
    return why is None, why or f"alpha = {show[0]}, beta = {show[1]}, gamma = {g}{show[2]}; 1 simple; no Jordan " \
        "block at |lam| >= beta"


def _jordan_at(ev, beta):  # the reason if an eigenvalue of modulus possibly >= beta is defective
    bad = [t for t in ev if t[3] < t[2] and not abs(t[0]) < beta]
    return (f"a Jordan block at |lam| >= beta: {bad[0][1]} (algebraic multiplicity {bad[0][2]}, geometric {bad[0][3]})"
            if bad else None)
