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
    jacobian_determinant,
)
from ccproof.tables.format import PATCHES, TableFormatError, read_table_json, table_nets_arb, table_path

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


def required_cells(nets, lam, N, prec):
    """Every (l, m, p, q) of part D: cell (l, m) != (0, 0) and w piece (p, q), p, q < 3, met by the
    Bezier hull of Phi(cell). Pieces with p = 3 or q = 3 have w = 0 (G = Phi, covered by part B)."""
    out = []
    with ctx.workprec(prec):
        for l in range(2**N):
            for m in range(2**N):
                if (l, m) == (0, 0):
                    continue
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


def corner_det_poly(nets, lam, N, name, prec):
    """det(J_G)/h^2 on layer i >= N of piece ``name`` as a Poly in (rho, kappa, s, t) (R9 form)."""
    with ctx.workprec(prec):
        emb = [Poly.variable(2, 4, prec), Poly.variable(3, 4, prec)]
        Px = net_form(nets[name], 0, prec).to_poly().compose(emb)
        Py = net_form(nets[name], 1, prec).to_poly().compose(emb)
        r = Poly.variable(0, 4, prec) * lam ** (3 * N)
        qv = Poly.variable(1, 4, prec) * (2 * lam**4) ** N
        s, t = emb
        half = fmpq(1, 2)
        D = {"P1": (half + s * half, t * half), "P2": (half + s * half, half + t * half),
             "P3": (s * half, half + t * half)}[name]
        Px3, Py3 = Px**3, Py**3
        U = (Px3 + Py3) * 36 - r * Px3 * Py3 * 1296
        W = 1 - r * U
        P = (Px, Py)
        gradU = (U.diff(2), U.diff(3))
        J = [[None, None], [None, None]]
        for a in range(2):
            for b in range(2):
                e = W * half if a == b else Poly.constant(0, 4, prec)
                e = e - r * D[a] * gradU[b] + qv * (U * P[a].diff(2 + b) + P[a] * gradU[b])
                J[a][b] = e
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
    k = _field(cert, "valence", (int, dict), "certificate")
    if isinstance(k, dict):  # the interval of valences k >= k0: {"min": k0}
        if set(k) != {"min"} or not isinstance(k["min"], int) or isinstance(k["min"], bool):
            raise CertificateError(f"valence interval must be {{'min': K0}}, got {k!r}")
        if k["min"] < 3:
            raise CertificateError(f"valence {k['min']} < 3")
    elif k < 3:
        raise CertificateError(f"valence {k} < 3")
    kname = f">={k['min']}" if isinstance(k, dict) else str(k)
    N = _field(cert, "N", int, "certificate")
    prec = _field(cert, "prec", int, "certificate")
    if not 64 <= prec <= 1024 or not 1 <= N <= 12:
        raise CertificateError("prec must lie in 64..1024 and N in 1..12")
    tinfo = _field(cert, "table", dict, "certificate")
    thash = _field(tinfo, "hash", str, "table")
    parts = _field(cert, "parts", dict, "certificate")
    _check_structure(parts)
    log(f"certificate for valence {kname} (N = {N}, {prec} bits)")
    table = _load_table(k, kname, thash, tables_dir, part)
    if table is None:
        return False
    with ctx.workprec(prec):
        lam = arb_from_table(table, prec)
        nets = table_nets_arb(table, "bezier", prec)
        # A. corner containment
        hull = max((c[d].upper() for n in PATCHES for row in nets[n] for c in row for d in range(2)),
                   key=lambda z: z.mid())
        okA = bool(lam**N * hull < fmpq(1, 6))
        part("A corner cell maps into [0,1/6)^2", okA, "" if okA else f"lam^N * max = {(lam**N * hull).str(6)}")
        # B. regularity of Phi on layer 0
        regs = _field(parts, "regularity", dict, "parts")
        okB, minB = True, None
        for name in PATCHES:
            root = regularity_form(nets, name, prec)
            ok, msg, mb = check_boxes(root, _field(regs, name, list, "regularity"), f"regularity {name}")
            okB &= ok
            if not ok:
                part(f"B det J_Phi > 0 on {name}", False, msg)
            minB = mb if minB is None or (mb is not None and mb < minB) else minB
        if okB:
            part("B det J_Phi > 0 on layer 0", True, f"min bound {minB} (w.r.t. local s,t)")
        # C. [0,1/2]^2 inside the image of the face
        okC = all(_curve_avoids(cv, 40) for cv in _outer_curves(nets))
        part("C [0,1/2]^2 inside Phi([0,1]^2)", okC)
        # D. the cells (l, m) != (0, 0)
        cells = _field(parts, "cells", dict, "parts")
        okD, minD, nboxes = True, None, 0
        for l, m, p, q in required_cells(nets, lam, N, prec):
            key = f"{l},{m},{p},{q}"
            boxes = cells.get(key)
            if boxes is None:
                part(f"D cell {key}", False, "required (l, m, p, q) not in the certificate")
                okD = False
                continue
            root = bernstein_coefficients(cell_det_poly(nets, lam, N, l, m, p, q, prec))
            ok, msg, mb = check_boxes(root, boxes, f"cell {key}")
            nboxes += len(boxes)
            if not ok:
                part(f"D cell {key}", False, msg)
                okD = False
            elif minD is None or mb < minD:
                minD = mb
        if okD:
            part("D det J_G > 0 on every cell != (0,0)", True, f"{nboxes} boxes, min bound {minD}")
        # E. the corner cell, all layers i >= N at once
        corner = _field(parts, "corner", dict, "parts")
        okE, minE = True, None
        for name in PATCHES:
            root = bernstein_coefficients(corner_det_poly(nets, lam, N, name, prec))
            ok, msg, mb = check_boxes(root, _field(corner, name, list, "corner"), f"corner {name}")
            if not ok:
                part(f"E corner {name}", False, msg)
                okE = False
            elif minE is None or mb < minE:
                minE = mb
        if okE:
            part("E det J_G / h^2 > 0 on the corner cell (all layers >= N)", True, f"min bound {minE}")
    return all(results) and okB and okD and okE


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


def _check_structure(parts):
    """Validate every box list before any arithmetic, so a malformed file fails fast and by name."""
    for section, nvars in (("regularity", 2), ("cells", 2), ("corner", 4)):
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
