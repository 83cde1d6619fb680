"""Trusted checker of injectivity certificates (bmz04 Proposition 1 and Appendix A).

This module is the trusted base. It imports only python-flint, the standard library,
:mod:`ccproof.rigorous` (Bernstein forms in arb) and :mod:`ccproof.tables.format` (hash-checked
table reading); never the prover nor any floating-point array or CAS library. It replays
the hints of a certificate and never searches. The statement, the grammar and a worked example
are in docs/certificates.md; in short,
for a valence k with table T (identified by its content hash) and N = N(k) it checks

  A. corner containment: lam^N * max(coefficients of X, Y of P1..P3) < 1/6, so the dyadic corner
     cell [0, 2^-N]^2 is mapped into [0, 1/6)^2 where w is the single piece (1-36u^3)(1-36v^3);
  B. regularity: det J_Phi > 0 on layer 0 (Bernstein boxes on P1, P2, P3; other layers follow by
     Phi(y/2) = lam Phi(y));
  C. square inside the image: the images of the outer sides u = 1 and v = 1 avoid [0,1/2]^2;
  D. cells: for every dyadic cell (l, m) != (0, 0) of level N and every polynomial piece (p, q) of
     w whose region meets the Bezier hull of Phi(cell), det J_G > 0 for
     G = w(Phi) y + (1 - w(Phi)) Phi (R7); pieces where w = 0 reduce to B;
  E. corner cell: on layer i >= N, with r = lam^(3i) = lam^(3N) rho, q = (2 lam^4)^i = (2 lam^4)^N kappa,
     det J_G / h^2 (h = 2^-i) is a polynomial in (rho, kappa, s, t) that must be > 0 on [0,1]^4 (R9).

Every Bernstein coefficient is recomputed in arb from the table's nets; each box of a part is
given by a split path, the boxes of a part must partition its domain exactly, and each claimed
bound must be positive and below every coefficient of its box.

For every valence k >= k0 at once (``"valence": {"min": k0}``) lam is a variable: the certificate's
pieces must cover [lam(k0), (3 + sqrt 5)/8]; on each piece the nets are Taylor models in zeta
(lam = mid + zeta * half-width) built exactly from the table's exact forms with a Bernstein bound on
the remainder; A, B, C, E use their hulls, D keeps zeta as a Bernstein variable (axis 0).
"""

from __future__ import annotations

import json
import re
import time
from pathlib import Path

from flint import arb, ctx, fmpq, fmpq_poly

from ccproof.rigorous import (
    BernsteinForm,
    Poly,
    bernstein_coefficients,
    bernstein_jacobian_determinant,
    exact_fmpq,
    jacobian_determinant,
    range_enclosure,
)
from ccproof.tables.format import (
    PATCHES,
    TableFormatError,
    read_table_json,
    table_nets_arb,
    table_nets_exact,
    table_path,
)

SCHEMA = "ccproof.injectivity/1"
C1_SCHEMA = "ccproof.c1/1"
BREAKS = (fmpq(0), fmpq(1, 6), fmpq(1, 3), fmpq(1, 2))  # w pieces (R5); piece 3 is w = 0
_TOKEN = re.compile(r"([0-3])([LH])")


class CertificateError(ValueError):
    """A certificate that is malformed or whose claims do not check."""


# ------------------------------------------------------------------------ the statement's maps
def weight_piece(p):
    """b(x) = B(6x+1) + B(6x) + B(6x-1) on [BREAKS[p], BREAKS[p+1]] (R5) as an exact 1-var Poly;
    B is the centred uniform cubic B-spline: (4 - 6z^2 + 3|z|^3)/6 on |z| <= 1, (2 - |z|)^3/6 on 1..2."""
    z = fmpq_poly([0, 6])  # z = 6x

    def B(shift, region):  # B(z + shift) on a region where z + shift has one sign/one piece
        a = z + shift
        if region == "inner+":
            return (4 - 6 * a**2 + 3 * a**3) / 6
        if region == "inner-":
            return (4 - 6 * a**2 - 3 * a**3) / 6
        if region == "outer+":
            return (2 - a) ** 3 / 6
        return fmpq_poly([0])

    pieces = {  # z in [0,1]: z+1 in [1,2], z in [0,1], z-1 in [-1,0]; and so on
        0: B(1, "outer+") + B(0, "inner+") + B(-1, "inner-"),
        1: B(1, "zero") + B(0, "outer+") + B(-1, "inner+"),
        2: B(0, "zero") + B(-1, "outer+"),
    }
    poly = pieces[p]
    return Poly({(i,): poly[i] for i in range(poly.degree() + 1)}, 1)


def _decimal(s):
    """Exact fmpq of a decimal string like '0.1234' or '-1.5e-3'."""
    if not isinstance(s, str) or not re.fullmatch(r"-?[0-9]+(\.[0-9]+)?(e-?[0-9]+)?", s):
        raise CertificateError(f"bound {s!r} is not a decimal string")
    mant, _, exp = s.partition("e")
    intpart, _, frac = mant.partition(".")
    num = int(intpart + frac) if intpart != "-" else 0
    q = fmpq(num, 10 ** len(frac))
    e = int(exp) if exp else 0
    return q * fmpq(10) ** e if e >= 0 else q / fmpq(10) ** (-e)


def net_form(net, coord, prec, box=None):
    """Bernstein form (unit box in the local variables) of one coordinate of a 4x4 Bezier net,
    restricted to ``box`` (dyadic sub-box of [0,1]^2 in the piece's local parameters)."""
    f = BernsteinForm((4, 4), [net[i][j][coord] for i in range(4) for j in range(4)], prec=prec)
    if box is not None:
        f = f.restrict(box)
    return BernsteinForm((4, 4), f.coeffs, prec=prec)  # relabel the sub-box as the unit box


def cell_geometry(l, m, N):
    """Layer i, piece name and (s, t) sub-box of the dyadic cell (l, m) != (0, 0) of level N."""
    M = max(l, m)
    i = N - 1 - (M.bit_length() - 1)
    scale = fmpq(2**i, 2**N)  # layer-0 coordinates of the cell: [l, l+1] * scale
    u0, v0 = l * scale, m * scale
    half = fmpq(1, 2)
    if u0 >= half and v0 < half:
        name, s0, t0 = "P1", 2 * u0 - 1, 2 * v0
    elif u0 >= half:
        name, s0, t0 = "P2", 2 * u0 - 1, 2 * v0 - 1
    else:
        name, s0, t0 = "P3", 2 * u0, 2 * v0 - 1
    h = 2 * scale
    return i, name, ((s0, s0 + h), (t0, t0 + h))


def cell_pieces(X, Y):
    """The w pieces (p, q), p, q in 0..3, whose regions the Bezier hull of (X, Y) may meet."""
    out = []
    rng = []
    for F in (X, Y):
        lo = min(c.lower() for c in F.coeffs)
        hi = max(c.upper() for c in F.coeffs)
        rng.append([p for p in range(4) if not (hi < BREAKS[p] or (p < 3 and lo > BREAKS[p + 1]))])
    for p in rng[0]:
        for q in rng[1]:
            out.append((p, q))
    return out


def mirror_symmetric(exact):
    """True when the exact B-spline nets satisfy P3[i][j] = S P1[j][i] and P2[i][j] = S P2[j][i],
    S(x, y) = (y, x) (identical integer forms). Then Phi(S y) = S Phi(y) on the face, and as
    w(u, v) = b(u) b(v) is symmetric, G(S y) = S G(y), det J_G(S y) = det J_G(y): the cell (m, l) with
    piece (q, p) follows from (l, m) with (p, q) (part D; B and E still check P3, which is cheap)."""
    def swap(pt):
        return (pt[1], pt[0])
    return all(exact["P3"][i][j] == swap(exact["P1"][j][i]) and exact["P2"][i][j] == swap(exact["P2"][j][i])
               for i in range(4) for j in range(4))


def dyadic_cells(N, symmetric):
    """The cells (l, m) != (0, 0) of level N that part D checks (l <= m only when ``symmetric``)."""
    return [(l, m) for l in range(2**N) for m in range(2**N) if (l, m) != (0, 0) and not (symmetric and l > m)]


def required_cells(nets, lam, N, prec, symmetric=False):
    """Every (l, m, p, q) of part D: cell (l, m) of :func:`dyadic_cells` and w piece (p, q), p, q < 3, met
    by the Bezier hull of Phi(cell). Pieces with p = 3 or q = 3 have w = 0 (G = Phi, covered by part B)."""
    out = []
    with ctx.workprec(prec):
        for l, m in dyadic_cells(N, symmetric):
            i, name, box = cell_geometry(l, m, N)
            li = lam**i
            X, Y = (net_form(nets[name], d, prec, box) for d in (0, 1))
            X = BernsteinForm(X.shape, [c * li for c in X.coeffs], prec=prec)
            Y = BernsteinForm(Y.shape, [c * li for c in Y.coeffs], prec=prec)
            out += [(l, m, p, q) for p, q in cell_pieces(X, Y) if p < 3 and q < 3]
    return out


def cell_det_poly(nets, lam, N, l, m, p, q, prec):
    """det dG/d(s,t) on cell (l, m) for the w piece (p, q) (p, q < 3), local coordinates in [0,1]^2."""
    i, name, box = cell_geometry(l, m, N)
    with ctx.workprec(prec):
        li = lam**i
        X = net_form(nets[name], 0, prec, box).to_poly() * li
        Y = net_form(nets[name], 1, prec, box).to_poly() * li
        s, t = Poly.variable(0, 2), Poly.variable(1, 2)
        y1 = (s + l) * fmpq(1, 2**N)
        y2 = (t + m) * fmpq(1, 2**N)
        w = weight_piece(p).compose([X]) * weight_piece(q).compose([Y])
        G1 = w * y1 + (1 - w) * X
        G2 = w * y2 + (1 - w) * Y
        return jacobian_determinant([G1, G2])


def corner_det_form(nets, lam, N, name, prec):
    """Bernstein form on [0,1]^4 of det(J_G)/h^2 on layer i >= N of piece ``name`` in (rho, kappa, s, t)
    (R9 form), computed in Bernstein arithmetic (stays tight for the interval nets of k >= k0)."""
    with ctx.workprec(prec):
        def var(axis, c):  # c * x_axis
            return BernsteinForm(tuple(2 if i == axis else 1 for i in range(4)), [0, c], prec=prec)

        P = [BernsteinForm((1, 1, 4, 4), net_form(nets[name], d, prec).coeffs, prec=prec) for d in range(2)]
        r, qv, s, t = var(0, lam ** (3 * N)), var(1, (2 * lam**4) ** N), var(2, 1), var(3, 1)
        half = fmpq(1, 2)
        D = {"P1": (half + s * half, t * half), "P2": (half + s * half, half + t * half),
             "P3": (s * half, half + t * half)}[name]
        Px3, Py3 = P[0] * P[0] * P[0], P[1] * P[1] * P[1]
        U = (Px3 + Py3) * 36 - r * Px3 * Py3 * 1296
        W = 1 - r * U
        gradU = (U.diff(2), U.diff(3))
        J = [[None, None], [None, None]]
        for a in range(2):
            for b in range(2):
                e = qv * (U * P[a].diff(2 + b) + P[a] * gradU[b]) - r * D[a] * gradU[b]
                J[a][b] = e + W * half if a == b else e
        return J[0][0] * J[1][1] - J[0][1] * J[1][0]


def regularity_form(nets, name, prec):
    """Bernstein form (degree (5,5)) of det J_Phi w.r.t. the local (s, t) of piece ``name`` on layer 0,
    computed in Bernstein arithmetic (stays tight for the interval nets of k >= k0)."""
    with ctx.workprec(prec):
        return bernstein_jacobian_determinant([net_form(nets[name], 0, prec), net_form(nets[name], 1, prec)])


#: the outer boundary of the face, from Phi(1,0) = (1,0) to Phi(0,1) = (0,1): (piece, side, direction)
STAR_CURVES = {"P1s1": ("P1", "s", 1), "P2s1": ("P2", "s", 1), "P2t1": ("P2", "t", -1), "P3t1": ("P3", "t", -1)}


def star_form(nets, curve, prec):
    """Bernstein form (degree 5) of x y' - y x' along one cubic of the outer boundary, oriented from
    (1,0) towards (0,1). Positive on all four curves means the outer boundary is star-shaped."""
    name, side, sign = STAR_CURVES[curve]
    net = nets[name]
    pts = [net[3][j] for j in range(4)] if side == "s" else [net[i][3] for i in range(4)]
    with ctx.workprec(prec):
        X = BernsteinForm((4,), [p[0] for p in pts], prec=prec)
        Y = BernsteinForm((4,), [p[1] for p in pts], prec=prec)
        cross = X * Y.diff(0) - Y * X.diff(0)
        return cross if sign > 0 else -cross


# ------------------------------------------------------------------------ replaying boxes
def parse_path(path, nvars):
    if not isinstance(path, str) or _TOKEN.sub("", path) != "":
        raise CertificateError(f"malformed box path {path!r}")
    toks = [(int(a), side) for a, side in _TOKEN.findall(path)]
    if any(a >= nvars for a, _ in toks):
        raise CertificateError(f"box path {path!r} splits an axis >= {nvars}")
    return toks


def check_partition(paths, nvars):
    """True iff the leaf paths partition the root box exactly (no gap, no overlap)."""
    parsed = [parse_path(p, nvars) for p in paths]
    if len({tuple(p) for p in parsed}) != len(parsed):
        return False

    def rec(group, depth):
        if any(len(p) == depth for p in group):
            return len(group) == 1
        axes = {p[depth][0] for p in group}
        if len(axes) != 1:
            return False
        lo = [p for p in group if p[depth][1] == "L"]
        hi = [p for p in group if p[depth][1] == "H"]
        return bool(lo) and bool(hi) and rec(lo, depth + 1) and rec(hi, depth + 1)

    return bool(parsed) and rec(parsed, 0)


def check_boxes(root, boxes, what):
    """Replay the split paths on the Bernstein form ``root``; each box's coefficients must all be
    certainly > its claimed bound > 0. Returns (ok, message, min bound)."""
    if not isinstance(boxes, list) or not boxes:
        return False, f"{what}: no boxes", None
    paths = []
    min_bound = None
    cache = {"": root}
    for b in boxes:
        if not isinstance(b, dict) or set(b) != {"path", "bound"}:
            return False, f"{what}: a box must be {{'path', 'bound'}}", None
        toks = parse_path(b["path"], root.nvars)
        bound = _decimal(b["bound"])
        if not bound > 0:
            return False, f"{what}: box {b['path']!r} claims a non-positive bound", None
        key, f = "", root
        for a, side in toks:
            key += f"{a}{side}"
            if key not in cache:
                lo, hi = f.split(a)
                pre = key[:-2]
                cache[pre + f"{a}L"], cache[pre + f"{a}H"] = lo, hi
            f = cache[key]
        if not all(c.is_finite() and c > bound for c in f.coeffs):
            worst = min(f.coeffs, key=lambda c: c.lower())
            return False, (f"{what}: box {b['path']!r}: a Bernstein coefficient ({worst.str(8)}) is not "
                           f"above the claimed bound {b['bound']}"), None
        paths.append(b["path"])
        min_bound = bound if min_bound is None or bound < min_bound else min_bound
    if not check_partition(paths, root.nvars):
        return False, f"{what}: the boxes do not partition the domain exactly (gap or overlap)", None
    return True, "", min_bound


# ------------------------------------------------------------------------ the verifier
def _field(obj, key, kind, where):
    if not isinstance(obj, dict) or key not in obj:
        raise CertificateError(f"{where}: missing field {key!r}")
    val = obj[key]
    if not isinstance(val, kind) or isinstance(val, bool):
        raise CertificateError(f"{where}: field {key!r} has the wrong type")
    return val


def verify_certificate(cert, tables_dir=None, log=print):
    """Check a parsed certificate. Returns True when every part passed; logs PASS/FAIL per part."""
    results = []

    def part(name, ok, msg=""):
        results.append(ok)
        log(f"  {'PASS' if ok else 'FAIL'}  {name}{(': ' + msg) if msg else ''}")

    if not isinstance(cert, dict) or cert.get("schema") != SCHEMA:
        raise CertificateError(f"unknown certificate schema {cert.get('schema') if isinstance(cert, dict) else None!r}"
                               f" (expected {SCHEMA!r})")
    k = _valence(cert)
    kname = f">={k['min']}" if isinstance(k, dict) else str(k)
    N = _field(cert, "N", int, "certificate")
    prec = _field(cert, "prec", int, "certificate")
    if not 64 <= prec <= 1024 or not 1 <= N <= 12:
        raise CertificateError("prec must lie in 64..1024 and N in 1..12")
    thash = _field(_field(cert, "table", dict, "certificate"), "hash", str, "table")
    if isinstance(k, dict):
        return _verify_interval(cert, k, N, prec, thash, tables_dir, log, part, results)
    parts = _field(cert, "parts", dict, "certificate")
    _check_structure(parts, 2)
    log(f"certificate for valence {kname} (N = {N}, {prec} bits)")
    table = _load_table(k, kname, thash, tables_dir, part)
    if table is None:
        return False
    sym = _symmetry(table, log)
    with ctx.workprec(prec):
        lam = arb_from_table(table, prec)
        nets = table_nets_arb(table, "bezier", prec)
        cells = [(f"{l},{m},{p},{q}",
                  lambda c=(l, m, p, q): bernstein_coefficients(cell_det_poly(nets, lam, N, *c, prec)))
                 for l, m, p, q in required_cells(nets, lam, N, prec, sym)]
        _check_parts(parts, nets, lam, N, prec, cells, part, "")
    return all(results)


def _symmetry(table, log):
    sym = mirror_symmetric(table_nets_exact(table))
    log("  mirror symmetry of the exact nets: " + ("holds; the cells (l, m) with l > m follow from their mirror "
        "images (m, l)" if sym else "does not hold; every cell is checked"))
    return sym


def _check_parts(parts, nets, lam, N, prec, cells, part, tag, failed=lambda: False):
    """Parts A-E (module docstring) for the arb ``nets`` and ``lam``; ``cells`` lists (key, build root).
    Stops after the first part for which ``failed()`` is true (the interval check uses it)."""
    okA, value = corner_containment(nets, lam, N)
    part(f"{tag}A corner cell maps into [0,1/6)^2", okA, "" if okA else f"lam^N * max = {value.str(6)}")
    if failed():
        return
    _check_sections(parts, "regularity", "B det J_Phi > 0 on layer 0", lambda n: regularity_form(nets, n, prec),
                    part, tag)
    part(f"{tag}C [0,1/2]^2 inside Phi([0,1]^2)", square_inside_image(nets))
    if failed():
        return
    # D. the cells (l, m) != (0, 0)
    okD, minD, nboxes = True, None, 0
    for key, build in cells:
        boxes = parts["cells"].get(key)
        if boxes is None:
            part(f"{tag}D cell {key}", False, "required (l, m, p, q) not in the certificate")
            okD = False
            if failed():
                break
            continue
        ok, msg, mb = check_boxes(build(), boxes, f"cell {key}")
        nboxes += len(boxes)
        if not ok:
            part(f"{tag}D cell {key}", False, msg)
            okD = False
            if failed():
                break
        elif minD is None or mb < minD:
            minD = mb
    if okD:
        part(f"{tag}D det J_G > 0 on every cell != (0,0)", True,
             f"{len(cells)} cells, {nboxes} boxes, min bound {minD}")
    if failed():
        return
    # E. the corner cell, all layers i >= N at once (R9)
    _check_sections(parts, "corner", "E det J_G / h^2 > 0 on the corner cell (all layers >= N)",
                    lambda n: corner_det_form(nets, lam, N, n, prec), part, tag)


def corner_containment(nets, lam, N):
    """Part A: (lam^N * max(all Bezier coordinates) < 1/6 certainly, that ball)."""
    hull = max((c[d].upper() for n in PATCHES for row in nets[n] for c in row for d in range(2)),
               key=lambda z: z.mid())
    return bool(lam**N * hull < fmpq(1, 6)), lam**N * hull


def square_inside_image(nets):
    """Part C: the images of the outer sides u = 1, v = 1 avoid [0,1/2]^2 (replayed bisection)."""
    return all(_curve_avoids(cv, 40) for cv in _outer_curves(nets))


def _check_sections(parts, sec, label, build, part, tag):
    ok_all, mins = True, []
    for name in PATCHES:
        ok, msg, mb = check_boxes(build(name), parts[sec][name], f"{sec} {name}")
        ok_all &= ok
        mins.append(mb)
        if not ok:
            part(f"{tag}{label[0]} {sec} {name}", False, msg)
    if ok_all:
        part(f"{tag}{label}", True, f"min bound {min(mins)} (w.r.t. the local variables)")


# ------------------------------------------------------------------------ every k >= k0 at once (R10)
ZBOX = ((fmpq(-1), fmpq(1)), (fmpq(0), fmpq(1)), (fmpq(0), fmpq(1)))  # (zeta, s, t) of part D
_B2Z = ((1, 4, 1, 0), (0, 4, 2, 0), (0, 2, 4, 0), (0, 1, 4, 1))  # uniform cubic B-spline -> Bezier, / 6


def _bern1(p, prec=None):
    """Bernstein coefficients on zeta in [-1, 1] of an fmpq_poly (or a list of arb coefficients)."""
    c = [p[i] for i in range(max(1, p.degree() + 1))] if isinstance(p, fmpq_poly) else p
    return bernstein_coefficients(Poly.from_dense((len(c),), c, prec), box=ZBOX[:1]).coeffs


def entry_model(form, L, layer, degree, prec):
    """lam^layer (A(c) + B(c) lam)/D(c) for lam = L(zeta), zeta in [-1, 1], c = (16 lam^2 - 10 lam + 1)/(2 lam)
    (R2), as arb coefficients of T(zeta) + [-r, r]: T the exact Taylor polynomial of ``degree`` at 0 and
    r = max|Bernstein coefficients of num - den T| / min|those of den| (den of one strict sign)."""
    cn, cd = 16 * L * L - 10 * L + 1, 2 * L
    M = max(len(f) for f in form) - 1

    def clear(P):  # P(c) (2 lam)^M as a polynomial in zeta
        return sum((cn**e * cd ** (M - e) * int(a) for e, a in enumerate(P)), fmpq_poly([]))

    num, den = (clear(form[0]) + clear(form[1]) * L) * L**layer, clear(form[2])
    db = _bern1(den)
    if not (all(c > 0 for c in db) or all(c < 0 for c in db)):
        raise CertificateError("a denominator of the exact nets may vanish on the lam interval")
    T = []
    for j in range(degree + 1):
        T.append((num[j] - sum((den[i] * T[j - i] for i in range(1, j + 1)), fmpq(0))) / den[0])
    r = max(abs(c) for c in _bern1(num - den * fmpq_poly(T))) / min(abs(c) for c in db)
    out = [arb(t) for t in T]
    out[0] += arb(0, arb(r).upper())
    return out


def parameter_nets(exact, La, Lb, layer, degree, prec):
    """Bezier nets of lam^layer Phi for every lam in [La, Lb]: net[i][j] = (x, y), each a list of arb
    coefficients of a polynomial in zeta in [-1, 1] (lam = (La + Lb)/2 + zeta (Lb - La)/2), from the
    table's exact B-spline forms (see :func:`entry_model`)."""
    L = fmpq_poly([(La + Lb) / 2, (Lb - La) / 2])
    out = {}
    with ctx.workprec(prec):
        for name in PATCHES:
            bs = [[[entry_model(f, L, layer, degree, prec) for f in pt] for pt in row] for row in exact[name]]
            out[name] = [[tuple([sum((bs[i][j][d][e] * _B2Z[a][i] * _B2Z[b][j] for i in range(4) for j in range(4)),
                                     arb(0)) / 36 for e in range(degree + 1)] for d in range(2))
                          for b in range(4)] for a in range(4)]
    return out


def hull_nets(znets, prec):
    """arb nets enclosing the zeta-polynomial nets for every zeta in [-1, 1] (Bernstein range)."""
    def hull(co):
        lo, hi = range_enclosure(_bern1(co, prec))
        return lo.union(hi)
    return {n: [[tuple(hull(co) for co in pt) for pt in row] for row in net] for n, net in znets.items()}


def cell_maps_z(znets, N, l, m, D, prec):
    """(X, Y) = lam^i Phi on cell (l, m) as ball Polys in (zeta, s, t), truncated to degree D in zeta."""
    i, name, box = cell_geometry(l, m, N)
    out = []
    for d in range(2):
        co = []  # zeta^e blocks of the (s, t) power forms
        for e in range(len(znets[i][name][0][0][d])):
            net = [[(pt[0][e], pt[1][e]) for pt in row] for row in znets[i][name]]
            co += net_form(net, d, prec, box).to_poly().coeffs
        out.append(Poly.from_dense((len(co) // 16, 4, 4), co, prec).truncate(D))
    return out


def _weight_z(p, X, D):
    """b(X) on piece p, Horner around the exact midpoint x0 of X's constant term (tighter balls)."""
    x0 = exact_fmpq(X.coeffs[0].mid())
    b = weight_piece(p).affine(0, x0, x0 + 1)
    acc = Poly.constant(b.coeffs[-1], 3, X.prec)
    for c in b.coeffs[-2::-1]:
        acc = (acc * (X - x0)).truncate(D) + c
    return acc


def interval_cells(znets, N, D, prec, symmetric=False):
    """Part D for an interval: every (key, build root) with a w piece met by the Bernstein hull of the
    cell's image over all zeta; the root is det dG/d(s,t) in (zeta, s, t) on ZBOX (Taylor model in zeta)."""
    out = []
    v = [Poly.variable(a, 3, prec) for a in range(3)]
    with ctx.workprec(prec):
        for l, m in dyadic_cells(N, symmetric):
            X, Y = cell_maps_z(znets, N, l, m, D, prec)
            XY = [bernstein_coefficients(F, box=ZBOX) for F in (X, Y)]
            y1, y2 = (v[1] + l) * fmpq(1, 2**N), (v[2] + m) * fmpq(1, 2**N)
            for p, q in cell_pieces(*XY):
                if p < 3 and q < 3:
                    def build(X=X, Y=Y, p=p, q=q, y1=y1, y2=y2):
                        with ctx.workprec(prec):
                            w = (_weight_z(p, X, D) * _weight_z(q, Y, D)).truncate(D)
                            G = [(F + w * (y - F)).truncate(D) for y, F in ((y1, X), (y2, Y))]
                            return bernstein_coefficients(jacobian_determinant(G, (1, 2)).truncate(D), box=ZBOX)
                    out.append((f"{l},{m},{p},{q}", build))
    return out


def lam_interval_ok(k0, La, Lb, prec):
    """[La, Lb] contains lam(k) for every k >= k0: La <= lam(k0) and Lb >= (3 + sqrt 5)/8 = lim lam
    (lam increases with c = cos(2 pi/k), which increases with k)."""
    with ctx.workprec(prec):
        c = arb(fmpq(2, k0)).cos_pi()
        lam0 = (5 + c + ((1 + c) * (9 + c)).sqrt()) / 16
        return bool(lam0 >= La) and bool((3 + arb(5).sqrt()) / 8 <= Lb)


def _verify_interval(cert, k, N, prec, thash, tables_dir, log, part, results):
    param = _field(cert, "parameter", dict, "certificate")
    deg, D = _field(param, "taylor_degree", int, "parameter"), _field(param, "truncation_degree", int, "parameter")
    if param.get("variable") != "lam" or not 1 <= D <= deg <= 8:
        raise CertificateError("parameter must be {'variable': 'lam', 1 <= truncation_degree <= taylor_degree <= 8}")
    pieces = _field(cert, "pieces", list, "certificate")
    if not pieces:
        raise CertificateError("no pieces")
    ends = []
    for pc in pieces:
        lo_hi = _field(pc, "lam", list, "piece")
        if len(lo_hi) != 2:
            raise CertificateError("piece lam must be [low, high]")
        ends.append(tuple(_decimal(x) for x in lo_hi))
        _check_structure(_field(pc, "parts", dict, "piece"), 3)
    if any(a >= b for a, b in ends) or any(ends[i][1] != ends[i + 1][0] for i in range(len(ends) - 1)):
        raise CertificateError("the lam pieces must be increasing and contiguous")
    log(f"certificate for valences k >= {k['min']} (N = {N}, {prec} bits, {len(pieces)} lam piece(s), "
        f"Taylor degree {deg}, truncation {D})")
    table = _load_table(k, f">={k['min']}", thash, tables_dir, part)
    if table is None:
        return False
    exact = table_nets_exact(table)
    sym = _symmetry(table, log)
    ok = lam_interval_ok(k["min"], ends[0][0], ends[-1][1], prec)
    part(f"lam(k) in [{ends[0][0]}, {ends[-1][1]}] for every k >= {k['min']}", ok)
    for idx, ((La, Lb), pc) in enumerate(zip(ends, pieces)):
        if not all(results):  # stop at the first failure: it is named, the rest is moot
            break
        with ctx.workprec(prec):
            zn = [parameter_nets(exact, La, Lb, i, deg, prec) for i in range(N)]
            nets = hull_nets(zn[0], prec)
            lam = arb(La).union(arb(Lb))
            _check_parts(pc["parts"], nets, lam, N, prec, interval_cells(zn, N, D, prec, sym), part,
                         f"[piece {idx}] ", failed=lambda: not all(results))
    return all(results)


def _load_table(k, kname, thash, tables_dir, part):
    """The hash-checked table of valence ``k`` whose hash is ``thash``, or None (after a FAIL line)."""
    try:
        table = read_table_json(table_path(k, tables_dir))
    except FileNotFoundError:
        part("table", False, f"no table for valence {kname}")
        return None
    except TableFormatError as exc:
        part("table", False, str(exc))
        return None
    if table["valence"] != k or table["hash"] != thash:
        part("table", False, f"the table's hash {table['hash']} is not the certificate's {thash}")
        return None
    part("table", True, thash)
    return table


def _check_structure(parts, cell_vars):
    """Validate every box list before any arithmetic, so a malformed file fails fast and by name."""
    for section, nvars in (("regularity", 2), ("cells", cell_vars), ("corner", 4)):
        sec = _field(parts, section, dict, "parts")
        if section != "cells" and set(sec) != set(PATCHES):
            raise CertificateError(f"parts.{section} must have exactly the keys {', '.join(PATCHES)}")
        for key, boxes in sec.items():
            if section == "cells" and not re.fullmatch(r"[0-9]+,[0-9]+,[0-2],[0-2]", key):
                raise CertificateError(f"parts.cells: malformed key {key!r} (expected 'l,m,p,q')")
            if not isinstance(boxes, list) or not boxes:
                raise CertificateError(f"parts.{section}.{key}: boxes must be a non-empty list")
            for b in boxes:
                if not isinstance(b, dict) or set(b) != {"path", "bound"}:
                    raise CertificateError(f"parts.{section}.{key}: a box must be {{'path', 'bound'}}")
                parse_path(b["path"], nvars)
                _decimal(b["bound"])


def arb_from_table(table, prec):
    from ccproof.tables.format import arb_from_json

    return arb_from_json(table["lam"], prec)


def _outer_curves(nets):
    return [[nets["P1"][3][j] for j in range(4)], [nets["P2"][3][j] for j in range(4)],
            [nets["P2"][i][3] for i in range(4)], [nets["P3"][i][3] for i in range(4)]]


def _curve_avoids(curve, depth):
    """max(x, y) > 1/2 on the whole cubic Bezier curve (replayed bisection, bounded depth)."""
    half = fmpq(1, 2)
    if all(p[0] > half for p in curve) or all(p[1] > half for p in curve):
        return True
    if depth == 0:
        return False
    b = [list(p) for p in curve]
    left, right, pts = [b[0]], [b[3]], b
    for _ in range(3):
        pts = [[(p[i] + q[i]) * half for i in range(2)] for p, q in zip(pts, pts[1:])]
        left.append(pts[0])
        right.append(pts[-1])
    return _curve_avoids(left, depth - 1) and _curve_avoids(right[::-1], depth - 1)


def verify_file(path, tables_dir=None, log=print):
    """Verify one certificate file; prints VERIFIED or names what failed. Returns True/False."""
    t0 = time.perf_counter()
    try:
        cert = json.loads(Path(path).read_text(encoding="ascii"))
        if isinstance(cert, dict) and cert.get("schema") == C1_SCHEMA:
            ok = verify_c1_certificate(cert, tables_dir, log)
        else:
            ok = verify_certificate(cert, tables_dir, log)
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        log(f"FAILED {path}: not a readable certificate ({exc})")
        return False
    except (CertificateError, TableFormatError) as exc:
        log(f"FAILED {path}: {exc}")
        return False
    dt = time.perf_counter() - t0
    log(f"{'VERIFIED' if ok else 'FAILED'} {path} ({dt:.1f} s)")
    return ok


# ------------------------------------------------------------------------ C1 (Reif) certificates
def _valence(cert):
    k = _field(cert, "valence", (int, dict), "certificate")
    if isinstance(k, dict):
        if set(k) != {"min"} or not isinstance(k["min"], int) or isinstance(k["min"], bool) or k["min"] < 3:
            raise CertificateError(f"valence interval must be {{'min': K0 >= 3}}, got {k!r}")
    elif k < 3:
        raise CertificateError(f"valence {k} < 3")
    return k


def spectral_check(table, k, prec):
    """1 = lam_0 > lam_1 = lam_2 = lam > |lam_3| from the Fourier-block spectrum (docs/readings.md R2):
    every eigenvalue is 1, 1/8..1/64, a root of 16L^2 - 2(5 + c_m)L + 1 (m != 0, increasing in c_m, so
    lam = lam(c_1) beats the modes 2 <= m <= k-2 since c_m < c_1) or of the mode-0 quadratic
    16k x^2 - (12k-28)x + k - 3, whose larger root mu < lam iff (28 lam - 3)/k > 2(1 - c) lam."""
    from ccproof.tables.format import arb_from_json

    with ctx.workprec(prec):
        c, lam = arb_from_json(table["c"], prec), arb_from_json(table["lam"], prec)
        if not (16 * lam**2 - 2 * (5 + c) * lam + 1).contains(0) or not lam > (5 + c) / 16:
            return False, "lam is not the larger root of 16 L^2 - 2(5 + c) L + 1"
        if not (lam < 1 and lam > fmpq(1, 8)):
            return False, "lam not in (1/8, 1)"
        if isinstance(k, dict):
            k0 = k["min"]
            if not (c.contains(arb(fmpq(2, k0)).cos_pi()) and c.contains(1)):
                return False, f"the table's c does not cover [cos(2 pi/{k0}), 1]"
            if not 28 * lam - 3 > 4 * arb.pi() ** 2 * lam / k0:
                return False, "28 lam - 3 > 4 pi^2 lam / k0 fails: mode 0 not separated"
            return True, f"all k >= {k0}: lam > mu by (28 lam - 3) > 4 pi^2 lam / k0"
        c1 = arb(fmpq(2, k)).cos_pi()
        if not c.contains(c1):
            return False, f"the table's c does not contain cos(2 pi/{k})"
        b = arb(12 * k - 28)
        mu = (b + (b * b - 64 * k * (k - 3)).sqrt()) / (32 * k)
        others = [mu]
        if k >= 4:
            c2 = arb(fmpq(4, k)).cos_pi()
            others.append((5 + c2 + ((1 + c2) * (9 + c2)).sqrt()) / 16)
        if not all(lam > o for o in others):
            return False, "an eigenvalue of another mode is not below lam"
        gap = min((lam - o for o in others), key=lambda z: z.lower())
        return True, f"gap lam - max|other| >= {gap.lower().str(6)}"


def verify_c1_certificate(cert, tables_dir=None, log=print):
    """Reif's C1 criterion for valence k (or every k >= k0): spectral ordering, det J_Phi > 0 on
    layer 0 (hence on the face), and a star-shaped image of the outer boundary. With det J_Phi > 0 the
    L-shaped layer 0 is mapped locally homeomorphically; its boundary goes to the Jordan curve made of
    the axis segments [lam, 1], the outer curve C and lam C (disjoint because C is star-shaped), so
    layer 0 maps injectively onto the annulus between lam C and C, and the layers, scaled by lam^i,
    onto nested disjoint annuli: Phi is injective on the face, and on the k-star by symmetry."""
    if not isinstance(cert, dict) or cert.get("schema") != C1_SCHEMA:
        raise CertificateError(f"unknown certificate schema (expected {C1_SCHEMA!r})")
    k = _valence(cert)
    prec = _field(cert, "prec", int, "certificate")
    if not 64 <= prec <= 1024:
        raise CertificateError("prec must lie in 64..1024")
    thash = _field(_field(cert, "table", dict, "certificate"), "hash", str, "table")
    parts = _field(cert, "parts", dict, "certificate")
    reg, star = _field(parts, "regularity", dict, "parts"), _field(parts, "star", dict, "parts")
    if set(reg) != set(PATCHES) or set(star) != set(STAR_CURVES):
        raise CertificateError("parts.regularity needs P1..P3 and parts.star needs " + ", ".join(STAR_CURVES))
    for sec, nv in ((reg, 2), (star, 1)):
        for boxes in sec.values():
            for b in boxes if isinstance(boxes, list) else [None]:
                if not isinstance(b, dict) or set(b) != {"path", "bound"}:
                    raise CertificateError("a box must be {'path', 'bound'}")
                parse_path(b["path"], nv)
                _decimal(b["bound"])
    kname = f">={k['min']}" if isinstance(k, dict) else str(k)
    log(f"C1 certificate for valence {kname} ({prec} bits)")
    results = []

    def part(name, ok, msg=""):
        results.append(ok)
        log(f"  {'PASS' if ok else 'FAIL'}  {name}{(': ' + msg) if msg else ''}")

    table = _load_table(k, kname, thash, tables_dir, part)
    if table is None:
        return False
    ok, msg = spectral_check(table, k, prec)
    part("spectral ordering 1 > lam = lam > |lam_3|", ok, msg)
    with ctx.workprec(prec):
        nets = table_nets_arb(table, "bezier", prec)
        for name in PATCHES:
            ok, msg, mb = check_boxes(regularity_form(nets, name, prec), reg[name], f"regularity {name}")
            part(f"det J_Phi > 0 on {name}", ok, msg or f"min bound {mb} (local s,t)")
        for curve in STAR_CURVES:
            ok, msg, mb = check_boxes(star_form(nets, curve, prec), star[curve], f"star {curve}")
            part(f"outer boundary star-shaped on {curve}", ok, msg or f"min bound {mb}")
    return all(results)


def check_coverage(valences):
    """Do the valences (ints and {'min': k0}) cover every k >= 3 exactly once? Returns (ok, message)."""
    ints = sorted(v for v in valences if isinstance(v, int))
    tails = sorted(v["min"] for v in valences if isinstance(v, dict))
    if len(set(ints)) != len(ints):
        return False, "a valence is claimed twice"
    if len(tails) != 1:
        return False, "no interval k >= k0" if not tails else "more than one interval k >= k0"
    k0 = tails[0]
    if ints != list(range(3, k0)):
        missing = sorted(set(range(3, k0)) - set(ints))
        extra = [k for k in ints if k >= k0]
        return False, f"missing valences {missing}" if missing else f"valences {extra} overlap k >= {k0}"
    return True, f"every k >= 3 exactly once (3..{k0 - 1} and k >= {k0})"
