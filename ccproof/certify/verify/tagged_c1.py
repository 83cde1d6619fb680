"""Certificates for tagged configurations (schema ``ccproof.tagged-c1/1``): "C1" and "not C1" (trusted).

The statement is derived from the configuration name alone (:mod:`.tagged`: the sector matrix S from
OpenSubdiv's rules, its exact spectrum; for N, K >= 5 the same spectrum and the leading eigenvectors
through the modes of :mod:`.tagged_modes`, in O(N) for creases and corners). A ``"not C1"``
certificate names a control net
P = (x, y, z) whose three coordinates are eigenvectors of S, with eigenvalues alpha, beta, gamma,
alpha >= gamma > 0 and beta >= gamma, and a sharp ray r and a quadrant q. The verifier derives each
eigenvector itself (exactly for a rational eigenvalue, given its values on the crease points; in arb
for an irrational simple eigenvalue, whose crease values are exactly 0 because it is no eigenvalue of
the crease block) and checks:

* B (boundary segment): x = y = 0 on every crease point of r's limit curve (the centre and ray r; for a
  crease centre both sharp rays; exact rationals), z's limit position at v is 0 (the crease limit mask
  (e0 + 4 V + e1)/6 of a crease centre, V of a corner) and the limit position (z(C) + 4 z(r1) + z(r2))/6
  of r's first point is not 0. Every limit point of that curve is an affine combination of crease
  points, so the curve lies on the z-axis; it joins v = 0 to the limit of r's first point at every
  level m (scaled by gamma^m != 0), so the limit surface contains a segment of the z-axis ending at v.
  A C1 surface (with boundary) at v has e_z in its tangent plane T_v.
* N (normal): at the regular vertex (1, 1) of quadrant q (valence 4, smooth edges: its 1-ring evolves
  by the regular rules alone) the limit tangents are the B-spline masks T_a = sum w'(a) w(b) P(a, b),
  T_b = sum w(a) w'(b) P(a, b), w = (1, 4, 1)/6, w' = (-1, 0, 1)/2, and J_xy = T_a(x) T_b(y) - T_b(x) T_a(y)
  is certainly not 0. S^m P = (alpha^m x, beta^m y, gamma^m z + m gamma^(m-1) u), u = (S - gamma) z (0 for an
  eigenvector; a generalized z needs gamma < beta, and u vanishes on the crease points so the boundary
  curve of B is unchanged). The normal at the level-m copy p_m of that vertex, divided by
  alpha^m beta^m, has the z-component J_xy and x-, y-components O(m (gamma/beta)^m) (or bounded when
  gamma = beta and z is an eigenvector), so every limit n of the unit normals at p_m -> v has n_z != 0.

A C1 surface at v would have a continuous unit normal, n(v) = lim n(p_m), orthogonal to T_v, which
holds e_z: n_z = 0, a contradiction. So the limit surface of this control net is not C1 at v.

G (generic): alpha = lam1 and beta = lam2 are the two leading eigenvalues of S below 1 (every other
eigenvalue certainly smaller in modulus than beta, or beta itself), gamma is the crease block's largest
eigenvalue below 1 (the tangent of the crease curve of a generic net), and no eigenvalue of modulus
possibly >= beta is defective (a Jordan block below beta adds terms o(beta^m)). Then the witness is not
a degenerate net: for every net whose lam1-, lam2- and gamma-coefficients a1, a2, a3 are linearly
independent the same leading terms give the same contradiction (docs/tagged_c1.md), an open dense set
of nets.

Two witnesses beyond that generic pair, part G of each in :mod:`.tagged_refute`: a dart's flip (x, y and a
quadrant; alpha beta < 0, part F: J_xy != 0, the normal changes sign with every level) and a Jordan chain
(N < 5: y a generalized eigenvector of beta = gamma, part N on J_xe with e = (S - beta) y).

A ``"C1"`` certificate (the generalized Reif criterion for a sector): the spectral part
(:func:`.tagged.leading_spectrum`: 1 simple, lam1 >= lam2 > |others| real and non-defective), a tangent
plane that sees the crease (lam1 or lam2 an eigenvalue of the crease block), the eigenvectors x of lam1
and y of lam2 (hints: ``map``), and the characteristic map Phi = (X, Y) regular and injective on the
sector (:func:`.tagged_map.check_map` on the boxes of ``parts``; docs/tagged_c1.md).
"""

from __future__ import annotations

from flint import arb, arb_mat, ctx, fmpq, fmpq_mat

from .c1 import read_prec
from .errors import CertificateError
from .record import exact_keys, field_of
from .registry import TAGGED_SCHEMA
from .replay import parse_decimal
from .tagged import (
    crease_block,
    crease_points,
    eigenvalues,
    labels,
    leading_spectrum,
    parse_configuration,
    sector_matrix,
    sector_rows,
    sharp_rays,
)
from .tagged_map import all_zero, check_map
from .tagged_modes import MIN_N, bordered_solve, kernel_basis, mode_spectrum, normalized_vector
from .tagged_refute import chain_generic, chain_top, flip_generic, mode_generic, mode_lead_why, ordering, same_root

LIMIT_MASK = (fmpq(1, 6), fmpq(4, 6), fmpq(1, 6))  # a cubic B-spline's limit weights on three control points
TANGENT_MASK = (fmpq(-1, 2), fmpq(0), fmpq(1, 2))  # and its tangent's


def verify_tagged(cert, part, log):
    """Check a tagged-configuration certificate (module docstring) into ``part``.

    Parameters
    ----------
    cert : dict
        ``schema``, ``configuration``, ``statement``, ``prec``; ``witness`` (``"not C1"``) or
        ``map`` and ``parts`` (``"C1"``).
    part : Recorder
    log : callable (str) -> None

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
    >>> cert = json.loads((certificates_dir() / "c1" / "crease" / "n005.json").read_text())
    >>> res = VerifyResult()
    >>> verify_tagged(cert, Recorder(res, lambda line: None), lambda line: None), bool(res)
    ('crease:5', True)
    """
    statement = field_of(cert, "statement", str, "certificate")  # "C1" or "not C1": the registry's route took it
    keys = ("schema", "configuration", "statement", "prec") + (("witness",) if statement == "not C1" else
                                                                ("map", "parts"))
    exact_keys(cert, keys, "certificate")
    name = field_of(cert, "configuration", str, "certificate")
    fam, n = parse_configuration(name)
    prec = read_prec(cert)
    log(f"{statement} certificate for {name} ({prec} bits)")
    rows = sector_rows(fam, n)
    ok = all(sum(row.values(), fmpq(0)) == 1 for row in rows)
    part("S sector matrix derived from the rules", ok, f"{len(rows)} points, rows sum to 1 (exact)")
    with ctx.workprec(prec):
        if statement == "C1":
            _verify_c1(cert, fam, n, prec, part)
        else:
            _verify_witness(field_of(cert, "witness", dict, "certificate"), fam, n, prec, part, log)
    return name


def _verify_c1(cert, fam, n, prec, part):
    """A "C1" certificate: the spectral part, the crease seen, x and y, the map. A dart with K >= MIN_N takes
    :func:`.tagged_modes.mode_spectrum` (every eigenvalue enclosed, S_E's exactly, the odd half's through the
    modes; lam1 and lam2 each isolated, so simple; x and y in closed form (odd) or from S_E (even)); every
    other configuration its exact spectrum (:func:`.tagged.leading_spectrum`, :func:`eigenvector_of`)."""
    modes = fam == "dart" and n >= MIN_N
    if modes:
        ev = mode_spectrum("dart", n)
        i1, i2, why, msg = _dart_leading(n, ev)
        ok, lead = why is None, (None, i1, i2)
    else:
        ok, msg, lead = leading_spectrum(fam, n, prec)
    part("spectral part of the generalized Reif criterion", ok, msg)
    if ok and fam != "dart":
        cpoly = crease_block(fam, n).charpoly()
        ok = any(t[1].gcd(cpoly).degree() > 0 for t in lead[1:3])
        part("the tangent plane sees the crease: lam1 or lam2 is an eigenvalue of the crease block", ok,
             "" if ok else "both eigenvectors vanish on the crease points, so the characteristic map "
             "sends the sharp edges to v (not injective)")
    if part.failed:
        return
    mp, orient = _map_field(cert)
    vecs, vals = {}, {}
    for c, t in (("x", lead[1]), ("y", lead[2])):
        if modes:
            val, (_, vec, msg) = ev[t][0].real, _mode_coordinate(fam, n, ev, field_of(mp, c, dict, "map"), c, t)
        else:
            val, vec, msg = eigenvector_of(fam, n, field_of(mp, c, dict, "map"), c, prec)
        ok = vec is not None and (modes or same_root(t, val))
        part(f"{c}: eigenvector of lam{'1' if c == 'x' else '2'}", ok,
             msg if vec is None or ok else "not the eigenvalue of lam1 / lam2")
        if not ok:
            return
        vals[c], vecs[c] = val, vec
    check_map(fam, n, vecs["x"], vecs["y"], vals["x"], vals["y"], orient,
              field_of(cert, "parts", dict, "certificate"), prec, part)


def _map_field(cert):
    mp = field_of(cert, "map", dict, "certificate")
    exact_keys(mp, ("x", "y", "orientation"), "map")
    orient = mp["orientation"]
    if orient not in (1, -1) or isinstance(orient, bool):
        raise CertificateError("map.orientation must be 1 or -1")
    return mp, orient


def _where(t):
    return f"mode {t[3]}" if t[3] else "even"


def _isolated(ev, lo_hi, c):
    """The index of the one entry of ``ev`` certainly inside the decimal interval [low, high] with no
    other entry touching it, else None."""
    if len(lo_hi) != 2:
        raise CertificateError(f"{c}: the eigenvalue must be [low, high]")
    lo, hi = parse_decimal(lo_hi[0]), parse_decimal(lo_hi[1])
    inside = [j for j, t in enumerate(ev) if t[0].real > lo and t[0].real < hi]
    near = [j for j, t in enumerate(ev) if t[0].real.overlaps(arb(lo).union(arb(hi)))]
    return inside[0] if len(inside) == 1 and near == inside else None


def _dart_leading(k, ev):
    """(i1, i2, why, message): a dart's lam1 and lam2 in the mode list, why None when the spectral part holds."""
    rest = sorted((i for i, t in enumerate(ev) if abs(t[0]) < 1), key=lambda i: -abs(ev[i][0]).mid())
    i1, i2 = rest[0], rest[1]
    l1, l2 = ev[i1][0], ev[i2][0]
    why = mode_lead_why(ev, i1, i2) or (
        "lam1 or lam2 is not certainly real and positive" if not all(z.imag.is_zero() and z.real > 0 for z in (l1, l2))
        else "lam1 > lam2 is not certain" if not l1.real > l2.real else None)
    msg = (f"dart:{k}: 1 simple; lam1 = {l1.real.str(5, radius=False)} ({_where(ev[i1])}) > lam2 = "
           f"{l2.real.str(5, radius=False)} ({_where(ev[i2])}), each simple"
           f" > |lam3| = {abs(ev[rest[2]][0]).str(5, radius=False)}" if why is None else f"dart:{k}: {why}")
    return i1, i2, why, msg


def _verify_witness(w, fam, n, prec, part, log):
    """A "not C1" witness: a crease's or corner's x, y, z, G, then B and N (module docstring); a dart's flip
    (x, y, quadrant; :mod:`.tagged_refute`): x, y eigenvectors of simple eigenvalues of opposite signs leading
    the spectrum, and J_xy != 0 (part F): the normal flips at every level."""
    dart = fam == "dart"
    exact_keys(w, ("x", "y", "quadrant") if dart else ("x", "y", "z", "ray", "quadrant"), "witness")
    r, q = 0 if dart else field_of(w, "ray", int, "witness"), field_of(w, "quadrant", int, "witness")
    if r not in sharp_rays(fam, n) or not 0 <= q < n:
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
        check_boundary(fam, n, r, vecs, part)
    J = _jacobian(fam, n, q, vecs["x"], second)
    ok = J > 0 or J < 0
    part(f"F flip at vertex (1,1) of quadrant {q}: J_xy != 0, so the normal there is (alpha beta)^m J_xy e_z + "
         "o(|alpha beta|^m)" if dart else f"N normal at vertex (1,1) of quadrant {q}: {label} != 0", ok,
         f"{label} = {J.str(6)}")
    if not part.failed:
        log(f"  the limit surface of this net is not C1 at the dart vertex: the unit normals at the level-m copies "
            f"of quadrant {q}'s (1,1) tend to (-1)^m sign(J_xy) e_z (no limit; the projection folds)" if dart else
            f"  the limit surface of this net is not C1 at the {fam} vertex: normals along the level-m "
            f"copies of quadrant {q}'s (1,1) tend to n_z != 0, yet e_z lies in T_v (ray {r})")


G_GENERIC = ("G generic: alpha = lam1, beta = lam2, gamma = the crease block's largest eigenvalue below 1; "
      "no Jordan block at |lam| >= beta; gamma < beta for a generalized z")


def _witness_exact(fam, n, w, prec, part):
    """Parts x, y, z (a dart: x, y) and G on the exact spectrum (N < MIN_N); (vectors, the vector paired with x
    in part N or F, its name) or None. A generalized y (a Jordan chain at beta) pairs x with its top
    e = (S - beta) y (:func:`.tagged_refute.chain_generic`)."""
    vecs, vals, tops = {}, {}, {}
    for c in ("x", "y") if fam == "dart" else ("x", "y", "z"):
        vals[c], vecs[c], msg = eigenvector_of(fam, n, field_of(w, c, dict, "witness"), c, prec,
                                               c != "x" and fam != "dart")
        tops[c] = None if vecs[c] is None else chain_top(fam, n, vals[c], vecs[c])
        part(f"{c}: {'(generalized) ' if c == 'z' or tops[c] else ''}eigenvector of S", vecs[c] is not None, msg)
        if vecs[c] is None:
            return None
    if fam == "dart":
        ok, msg = flip_generic(n, vals["x"], vals["y"], prec)
        part("G generic: alpha, beta simple, of opposite signs, each larger in modulus than every other eigenvalue "
             "but 1 (simple)", ok, msg)
        return (vecs, vecs["y"], "J_xy") if ok else None
    if tops["y"] is not None:
        ok, msg = chain_generic(fam, n, vals, tops, prec)
        part("G generic (Jordan chain): alpha = lam1 simple > beta = gamma, the crease block's largest eigenvalue "
             "below 1; Jordan blocks at beta of size <= 2, y's chain tops at e; every other |lam| < beta", ok, msg)
        return (vecs, tops["y"], "J_xe") if ok else None
    ok, msg = ordering(fam, n, vals["x"], vals["y"], vals["z"], prec, tops["z"] is not None)
    part(G_GENERIC, ok, msg)
    return (vecs, vecs["y"], "J_xy") if ok else None


def _witness_modes(fam, n, w, part):
    """Parts x, y, z and G for crease:N, corner:N, N >= MIN_N, from :mod:`.tagged_modes`: x and y
    eigenvectors of simple mode roots (closed form), z's existence from its crease values."""
    ev = mode_spectrum(fam, n)
    vecs, at = {}, {}
    for c in ("x", "y"):
        at[c], vecs[c], msg = _mode_coordinate(fam, n, ev, field_of(w, c, dict, "witness"), c)
        part(f"{c}: eigenvector of S", vecs[c] is not None, msg)
        if vecs[c] is None:
            return None
    gz = _mode_z(fam, n, ev, field_of(w, "z", dict, "witness"), part)
    if gz is None:
        return None
    g, cval = gz
    ia, ib = at["x"], at["y"]
    beta = ev[ib][0].real
    why = mode_generic(ev, ia, ib, g, crease_block(fam, n))
    part(G_GENERIC, why is None, f"alpha = {ev[ia][0].real.str(8)} > beta = {beta.str(8)} > |every other| (each "
         f"simple), 1 simple; gamma = {g} < beta" if why is None else why)
    if why is not None:
        return None
    cp = crease_points(fam, n)
    vecs["z"] = [cval[cp.index(i)] if i in cp else None for i in range(len(ev))]  # B reads the crease points only
    return vecs, vecs["y"], "J_xy"


def _mode_coordinate(fam, n, ev, spec, c, want=None):
    """(index in ``ev`` = :func:`.tagged_modes.mode_spectrum`, eigenvector with 1 at the pivot, message) of x or y,
    or (None, None, the reason): [low, high] isolates one real root of a mode (or a dart's even part; the
    entry ``want``, a dart's lam1 or lam2, when given), whose eigenvector vanishes on the crease points."""
    exact_keys(spec, ("eigenvalue", "crease", "pivot"), c)
    crease, lo_hi = field_of(spec, "crease", list, c), field_of(spec, "eigenvalue", list, c)
    cp = [] if fam == "dart" else crease_points(fam, n)
    if len(crease) != len(cp):
        raise CertificateError(f"{c}: crease values must be {len(cp)} decimals (a dart's crease [])")
    i = _isolated(ev, lo_hi, c)  # checks the [low, high] form
    if any(parse_decimal(v) != 0 for v in crease):
        return None, None, "an irrational eigenvalue's eigenvector vanishes on the crease points"
    if i is None or want not in (None, i) or not ev[i][0].imag.is_zero() or ev[i][3] is None and fam != "dart":
        what = ("one simple real root of a mode" if want is None else
                f"lam{'1' if c == 'x' else '2'}: not the eigenvalue of lam1 / lam2")
        return None, None, f"[{lo_hi[0]}, {lo_hi[1]}] does not isolate {what}"
    pivot = field_of(spec, "pivot", int, c)
    if not 0 <= pivot < len(ev) or pivot in cp:
        raise CertificateError(f"{c}: pivot must index a non-crease point")
    vec, j = normalized_vector(fam, n, ev, i, pivot), ev[i][3]
    if vec is None:
        return None, None, (f"the eigenvector is not certainly non-zero at the pivot {pivot} (or its system not "
                            "certainly regular)")
    how = (", simple; even: the bordered system on S_E" if j is None else
           f" = lam(cos({2 * j if fam == 'dart' else j} pi/{n})), simple; closed form in mode {j}: its 6x6 system")
    return i, vec, f"eigenvalue {ev[i][0].real.str(10)}{how} proved regular, pivot {labels(fam, n)[pivot]}"



def read_z(spec):
    """(gamma, crease values) of a witness's z: ``{"eigenvalue": decimal, "crease": 5 decimals}``, read exactly."""
    exact_keys(spec, ("eigenvalue", "crease"), "z")
    g, cval = field_of(spec, "eigenvalue", str, "z"), field_of(spec, "crease", list, "z")
    if len(cval) != 5:
        raise CertificateError("z: crease values must be 5 decimals")
    return parse_decimal(g), [parse_decimal(v) for v in cval]


def crease_eigen_why(C, g, cval):
    """None when C c = g c exactly with c != 0 (c the crease values), else the reason."""
    Cc = C * fmpq_mat([[v] for v in cval])
    ok = any(v != 0 for v in cval) and all(Cc[i, 0] == g * v for i, v in enumerate(cval))
    return None if ok else f"no eigenvector for {g} with the given crease values (C c = {g} c, c != 0 fails)"


def _mode_z(fam, n, ev, spec, part):
    """(gamma, crease values) once C c = gamma c exactly and gamma is at most a simple eigenvalue of I."""
    g, cval = read_z(spec)
    at_g = [t for t in ev if t[2] == "I" and (t[1] == g if t[1] is not None else t[0].real.overlaps(arb(g)))]
    why = crease_eigen_why(crease_block(fam, n), g, cval) or (
        f"{g} is possibly a multiple eigenvalue of I" if len(at_g) > 1 else None)
    part("z: (generalized) eigenvector of S", why is None,
         f"eigenvalue {g}: C c = {g} c exactly on the crease points, and {g} is at most a simple eigenvalue of I, so "
         f"some z with these crease values has (S - {g})^2 z = 0 and (S - {g}) z = 0 on the crease points"
         if why is None else why)
    return None if why is not None else (g, cval)


def eigenvector_of(fam, n, spec, c, prec, chain=False):
    """(eigenvalue, vector, message); vector None with the reason when the claim fails. With ``chain``
    a rational eigenvalue may also have a generalized eigenvector z: (S - lam)^2 z = 0, (S - lam) z != 0."""
    exact_keys(spec, ("eigenvalue", "crease", "pivot") if "pivot" in spec else ("eigenvalue", "crease"), c)
    crease = field_of(spec, "crease", list, c)
    cp = crease_points(fam, n) if fam != "dart" else []  # a dart's sharp ray is no closed block
    if len(crease) != len(cp):
        raise CertificateError(f"{c}: crease values must be {len(cp)} decimals")
    cval = [parse_decimal(v) for v in crease]
    if isinstance(spec["eigenvalue"], str):  # rational eigenvalue: exact
        return _exact_eigenvector(fam, n, spec, c, cp, cval, chain)
    return _ball_eigenvector(fam, n, spec, c, cp, cval, prec)


def _exact_eigenvector(fam, n, spec, c, cp, cval, chain):
    S = sector_matrix(fam, n)
    m = S.nrows()
    lam = parse_decimal(spec["eigenvalue"])
    A = S - lam * fmpq_mat([[1 if i == j else 0 for j in range(m)] for i in range(m)])
    if "pivot" in spec:  # one more fixed coordinate: 1 at the pivot
        pv = field_of(spec, "pivot", int, c)
        if not 0 <= pv < m or pv in cp:
            raise CertificateError(f"{c}: pivot must index a non-crease point")
        cp, cval = cp + [pv], cval + [fmpq(1)]
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


def _ball_eigenvector(fam, n, spec, c, cp, cval, prec):
    ev, lo_hi = eigenvalues(fam, n, prec), field_of(spec, "eigenvalue", list, c)
    i = _isolated(ev, lo_hi, c)  # checks the [low, high] form
    if i is None or not ev[i][0].imag.is_zero() or ev[i][2] != 1:
        return None, None, f"[{lo_hi[0]}, {lo_hi[1]}] does not isolate one simple real eigenvalue of {fam}:{n}"
    z, p = ev[i][0], ev[i][1]
    if any(v != 0 for v in cval):
        return None, None, "an irrational eigenvalue's eigenvector vanishes on the crease points"
    if cp and p.gcd(crease_block(fam, n).charpoly()).degree() > 0:
        return None, None, "the eigenvalue is one of the crease block's"
    pivot = field_of(spec, "pivot", int, c)
    S = sector_matrix(fam, n)
    free = [i for i in range(S.nrows()) if i not in cp]
    if pivot not in free:
        raise CertificateError(f"{c}: pivot must index a non-crease point")
    lam = z.real
    try:
        sol = bordered_solve([[arb(S[i, j]) for j in free] for i in free], lam, free.index(pivot), arb_mat)
    except ZeroDivisionError:
        return None, None, f"the system for the eigenvector of {lam.str(8)} (pivot {pivot}) is not certainly regular"
    vec = [arb(0)] * S.nrows()
    for k, i in enumerate(free):
        vec[i] = sol[k]
    return lam, vec, f"eigenvalue {lam.str(10)} (simple root of {p}); vector in arb, pivot {labels(fam, n)[pivot]}"


def _solve_exact(A, cp, cval):
    """A vector v with A v = 0 exactly and v = cval on the points cp (free unknowns 0), or None."""
    m = A.nrows()
    free = [i for i in range(m) if i not in cp]
    sol = kernel_basis(fmpq_mat([[A[i, j] for j in free] + [sum((A[i, j] * cval[k] for k, j in enumerate(cp)), fmpq(0))]
                                 for i in range(m)])).get(len(free))  # consistent iff the last column is free
    if sol is None:
        return None
    vec = [fmpq(0)] * m
    for k, j in enumerate(cp):
        vec[j] = cval[k]
    for k, j in enumerate(free):
        vec[j] = sol[k]
    return vec if any(v != 0 for v in vec) else None


def check_boundary(fam, n, r, vecs, part):
    """Part B into ``part``: ray r's limit curve lies on the z-axis (x = y = 0 exactly on the crease points of
    ``fam:n``) and z's limit leaves v (0 at v, not 0 at ray r's first point); ``vecs`` {"x", "y", "z": values}."""
    pts = labels(fam, n)
    rays = sharp_rays(fam, n) if fam == "crease" else (r,)
    on_curve = [0] + [pts.index(("r", s, a, 0)) for s in rays for a in (1, 2)]
    zero_xy = all_zero(vecs[c][i] for c in ("x", "y") for i in on_curve)
    z = vecs["z"]
    r1, r2 = pts.index(("r", r, 1, 0)), pts.index(("r", r, 2, 0))
    exact = all(isinstance(z[i], fmpq) for i in on_curve)
    at_v = (z[0] if fam == "corner" else (z[pts.index(("r", 0, 1, 0))] + 4 * z[0] + z[pts.index(("r", n, 1, 0))]) / 6
            ) if exact else None
    leave = (z[0] + 4 * z[r1] + z[r2]) / 6 if exact else None
    ok = zero_xy and exact and at_v == 0 and leave != 0
    part(f"B boundary segment: ray {r}'s limit curve lies on the z-axis and leaves v", ok,
         f"x = y = 0 on its crease points, limit z at v = 0, limit z of ray {r}'s first point = {leave}" if ok
         else "x or y not exactly 0 on the curve, or z's limit curve does not start at v = 0 and leave it")


def _jacobian(fam, n, q, x, y):
    pts = labels(fam, n)

    def index(a, b):
        if (a, b) == (0, 0):
            return 0
        if b == 0:
            return pts.index(("r", q, a, 0))
        if a == 0:
            return pts.index(("r", (q + 1) % n if fam == "dart" else q + 1, b, 0))
        return pts.index(("q", q, a, b))

    (xa, xb), (ya, yb) = (vertex_tangents({(a, b): v[index(a, b)] for a in range(3) for b in range(3)}) for v in (x, y))
    return xa * yb - xb * ya


def vertex_tangents(val):
    """(T_a, T_b), the limit tangents at a regular vertex from the values ``val[a, b]`` (a, b = 0, 1, 2) of its
    1-ring: the B-spline masks sum w'(a) w(b) val and sum w(a) w'(b) val (an arb, or an acb from acb values).

    Examples
    --------
    >>> ta, tb = vertex_tangents({(a, b): fmpq(a + 2 * b) for a in range(3) for b in range(3)})
    >>> ta.contains(1), tb.contains(2)
    (True, True)
    """
    return tuple(sum((da[a] * db[b] * val[a, b] for a in range(3) for b in range(3)), arb(0))
                 for da, db in ((TANGENT_MASK, LIMIT_MASK), (LIMIT_MASK, TANGENT_MASK)))


__all__ = ["G_GENERIC", "LIMIT_MASK", "TAGGED_SCHEMA", "TANGENT_MASK", "check_boundary", "crease_eigen_why", "read_z",
           "verify_tagged", "vertex_tangents"]
