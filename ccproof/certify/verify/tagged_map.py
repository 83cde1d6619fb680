"""The characteristic map Phi = (X, Y) of a tagged sector and the checks R, T, W, E of a "C1" certificate (trusted;
docs/tagged_c1.md, "C1").
"""

from __future__ import annotations

from functools import cache

from flint import arb, ctx, fmpq

from ccproof.rigorous import BernsteinForm

from .errors import CertificateError
from .maps import STAR_CURVES, curve_points, regularity_form
from .record import exact_keys
from .replay import check_boxes, check_partition, parse_path
from .statement import B2Z, NET_OFFSETS, bspline_to_bezier
from .statement import PATCHES as PIECES
from .tagged import point_index, position_key, quadrant_level1, sector_rows, sharp_rays


def level1_values(fam, n, v):
    """``value(q, A, B)``: the level-1 value of v at position (A, B), -1 <= A, B <= 3, of quadrant q (ghost values
    across a sharp ray). The linear x = a on the regular boundary, halved, and continued across ray 0:

    >>> from ccproof.certify.verify.tagged import labels
    >>> v = [fmpq(p[2] if p[:2] in (("r", 0), ("q", 0)) else -p[2] if p[:2] == ("r", 2) else -p[3] if p[0] == "q"
    ...           else 0) for p in labels("crease", 2)]
    >>> val = level1_values("crease", 2, v)
    >>> [val(0, a, b) for a, b in ((3, 0), (2, 2), (1, -1))]
    [3/2, 1, 1/2]
    """
    idx, _ = point_index(fam, n)
    rows = sector_rows(fam, n)
    one = cache(lambda i: sum((w * v[j] for j, w in rows[i].items()), 0 * v[0]))  # (S v)[i], sparse, on demand

    def key(s, pos):  # the index of level-0 position pos of sector s
        if (k := position_key(fam, n, s, *pos)) not in idx:
            raise CertificateError(f"{fam}:{n}: position {pos} of sector {s} outside the complex")
        return idx[k]
    sharp = (lambda s: s % n in sharp_rays(fam, n)) if fam == "dart" else (lambda s: s in sharp_rays(fam, n))
    quadrant = cache(lambda q: quadrant_level1(q, sharp, one(0), lambda s, p: one(key(s, p)),
                                               lambda s, p: v[key(s, p)], 0 * v[0]))
    return lambda q, A, B: quadrant(q)(A, B)


def quadrant_nets(fam, n, vx, vy, q, prec):
    """Bezier nets {P1, P2, P3: 4 x 4 of (arb, arb)} of Phi = (X, Y) on quadrant q.

    >>> from ccproof.certify.verify.tagged import labels
    >>> pts = labels("corner", 1)   # the identity map: x = a, y = b
    >>> vx = [fmpq(p[2] if p[0] == "q" or p[:2] == ("r", 0) else 0) for p in pts]
    >>> vy = [fmpq(p[3] if p[0] == "q" else p[2] if p[:2] == ("r", 1) else 0) for p in pts]
    >>> [z.str(5, radius=False) for z in quadrant_nets("corner", 1, vx, vy, 0, 64)["P2"][3][3]]   # the corner (1, 1)
    ['1.0000', '1.0000']
    """
    X, Y = level1_values(fam, n, vx), level1_values(fam, n, vy)
    out = {}
    with ctx.workprec(prec):
        for name in PIECES:
            oa, ob = NET_OFFSETS[name]
            net = [[(arb(X(q, oa + i, ob + j)), arb(Y(q, oa + i, ob + j))) for j in range(4)] for i in range(4)]
            out[name] = bspline_to_bezier(net, (arb(0), arb(0)))
    return out


def transversal_form(nets, curve, a1, a2, prec):
    """Bernstein form (degree 5) of a1 X Y' - a2 Y X' along one outer cubic, oriented counterclockwise (for the
    identity map and a1 = a2 = 1 the star form x y' - y x')."""
    with ctx.workprec(prec):
        X, Y = axis_forms(nets, curve, (1, 0), prec)
        return X * Y.diff(0) * a1 - Y * X.diff(0) * a2


AXES = {"+x": (1, 0), "-x": (-1, 0), "+y": (0, 1), "-y": (0, -1)}


def _crossings(nets, curve, paths, direction, prec):
    """How often one outer cubic crosses the half-line H = {t d : t > 0} (d = (a, b)), or why a box decides nothing:
    each box of a partition of [0, 1] is certainly off H (-b X + a Y of one sign, or a X + b Y < 0) or on its side
    (a X + b Y > 0), where a sign change of -b X + a Y between the ends is one crossing (one direction for all: T)."""
    if not check_partition(paths, 1):
        return f"{curve}: the boxes do not partition [0, 1]"
    count = 0
    with ctx.workprec(prec):
        A, P = axis_forms(nets, curve, direction, prec)
        for path in paths:
            fa, fp = A, P
            for ax, side in parse_path(path, 1):
                fa, fp = (f.split(ax)[0 if side == "L" else 1] for f in (fa, fp))
            fa, fp = fa.coeffs, fp.coeffs
            if _sign(fp) or _sign(fa) < 0:  # off H
                continue
            if _sign(fa) <= 0 or _sign(fp[:1]) * _sign(fp[-1:]) == 0:
                return f"{curve}: box {path!r}" + (" decides nothing" if _sign(fa) <= 0 else
                                                   ": the sign at an end is not certain")
            count += _sign(fp[:1]) * _sign(fp[-1:]) < 0  # on H's side: a sign change across H is one crossing
    return count


def axis_forms(nets, curve, direction, prec):
    """The Bernstein forms (degree 3) of a X + b Y (along H) and -b X + a Y (across H) on one outer cubic, oriented
    counterclockwise, for ``direction`` (a, b) of the half-line H.

    >>> from ccproof.certify.verify.tagged import labels
    >>> pts = labels("corner", 1)   # the identity map: x = a, y = b
    >>> vx = [fmpq(p[2] if p[0] == "q" or p[:2] == ("r", 0) else 0) for p in pts]
    >>> vy = [fmpq(p[3] if p[0] == "q" else p[2] if p[:2] == ("r", 1) else 0) for p in pts]
    >>> A, P = axis_forms(quadrant_nets("corner", 1, vx, vy, 0, 64), "P1s1", (0, 1), 64)
    >>> A.coeffs[3].str(3, radius=False), P.coeffs[0].str(3, radius=False)   # Y at the end, -X at the start
    ('0.500', '-1.00')
    """
    a, b = direction
    pts = curve_points(nets, curve, oriented=True)
    return (BernsteinForm((4,), [p[0] * a + p[1] * b for p in pts], prec=prec),
            BernsteinForm((4,), [p[1] * a - p[0] * b for p in pts], prec=prec))


def _sign(values):
    """+1 or -1 when every value is certainly of that sign, else 0."""
    return 1 if all(c > 0 for c in values) else -1 if all(c < 0 for c in values) else 0


def _rays_on_axes(fam, n, vx, vy):
    """(ok, message): E, the sharp rays' layer-0 segments lie on the half-axes: a segment's limit curve is the cubic
    B-spline of its level-1 values at 0..3 (a coordinate 0 when they are exactly 0; the other's sign from the Bezier
    points). Crease: X = 0, Y < 0 on ray 0; corner: Y = 0, X > 0; both: X = 0, Y > 0 on ray N."""
    X, Y = level1_values(fam, n, vx), level1_values(fam, n, vy)
    ray0 = [X(0, a, 0) for a in range(4)], [Y(0, a, 0) for a in range(4)]
    zero, signed, sign = (ray0[0], ray0[1], -1) if fam == "crease" else (ray0[1], ray0[0], 1)
    ok = all_zero(zero + [X(n - 1, 0, b) for b in range(4)]) and _sign(_bez(signed)) == sign and _sign(
        _bez([Y(n - 1, 0, b) for b in range(4)])) > 0
    return ok, ("X = 0 on both sharp rays, Y < 0 on ray 0 and Y > 0 on ray N" if fam == "crease" else
                "ray 0 onto the positive X half-axis, ray N onto the positive Y half-axis") if ok else \
        f"the sharp rays are not mapped onto the {'negative and positive Y' if fam == 'crease' else 'positive'} " \
        "half-axes"


def all_zero(vals):
    """Is every value exactly 0 (an fmpq 0, or an arb that is the exact 0)?

    >>> all_zero([fmpq(0), arb(0)]), all_zero([arb(0, 1)])
    (True, False)
    """
    return all(isinstance(z, fmpq) and z == 0 or isinstance(z, arb) and z.is_zero() for z in vals)


def _bez(vals):  # Bezier points of the segment [1, 2] of the B-spline with these values
    return [sum((arb(z) * fmpq(c, 6) for c, z in zip(row, vals) if c), arb(0)) for row in B2Z]


def check_map(fam, n, vx, vy, lam1, lam2, orient, parts, prec, part):
    """Run R, T, W, E on the hints ``parts`` ({"regularity": {"q:P": boxes}, "transversal": {"q:curve": boxes},
    "winding": {"axis", "boxes": {"q:curve": [path]}}}) into ``part``."""
    regs = [f"{q}:{p}" for q in range(n) for p in PIECES]
    curves = [f"{q}:{c}" for q in range(n) for c in STAR_CURVES]
    _check_keys(parts, regs, curves)
    with ctx.workprec(prec):
        a1, a2 = -arb(lam1).log(), -arb(lam2).log()
        nets = [quadrant_nets(fam, n, vx, vy, q, prec) for q in range(n)]
        for hint, keys, form, title, note in (
                ("regularity", regs, lambda net, c: regularity_form(net, c, prec), "R det J_Phi > 0 on every piece",
                 f"{len(regs)} pieces, min bound {{}} (local s,t)"),
                ("transversal", curves, lambda net, c: transversal_form(net, c, a1, a2, prec),
                 "T the outer curve is transversal to the flow of diag(lam1, lam2)", "min bound {}")):
            worst = None  # the smallest bound of the boxes of parts[hint] on form(quadrant, name) * orient
            for key in keys:
                q, c = key.split(":")
                ok, msg, mb = check_boxes(form(nets[int(q)], c) * orient, parts[hint][key], f"{hint} {key}")
                if not ok:
                    part(title, False, msg)
                    return
                worst = mb if worst is None or mb < worst else worst
            part(title, True, note.format(worst), worst, hint)
        ray = fam == "dart" and isinstance(lam1, fmpq) and lam1 == lam2  # D a multiple of 1: every ray an orbit
        if _check_winding(fam, nets, curves, parts["winding"], ray, orient, prec, part) and fam != "dart":
            part("E the sharp rays map onto half-axes", *_rays_on_axes(fam, n, vx, vy))


def _check_keys(parts, regs, curves):
    exact_keys(parts, ("regularity", "transversal", "winding"), "parts")
    exact_keys(parts["winding"], ("axis", "boxes"), "parts.winding")
    for sec, got, keys in (("regularity", parts["regularity"], regs), ("transversal", parts["transversal"], curves),
                           ("winding.boxes", parts["winding"]["boxes"], curves)):
        if not isinstance(got, dict) or set(got) != set(keys):
            raise CertificateError(f"parts.{sec} must have exactly the keys {keys[:3]}... ({len(keys)})")


# the half-axes a curve may be counted against, and how often it crosses each: from -y to +y through x > 0
# (x < 0 when the orientation is -1) for a crease, from +x to +y through the first quadrant (the other three
# when -1) for a corner, once around for a dart
_WANT = {"crease": {("+x", 1): 1, ("-x", 1): 0, ("+x", -1): 0, ("-x", -1): 1},
         "corner": {("-x", 1): 0, ("-y", 1): 0, ("-x", -1): 1, ("-y", -1): 1},
         "dart": {(a, o): 1 for a in AXES for o in (1, -1)}}


def _check_winding(fam, nets, curves, win, ray, orient, prec, part):
    """W: the count of crossings says the D-angle (monotone by T) turns by exactly the sector's angle; False when a
    box decides nothing. A ray direction (integers) when every ray is an orbit of D, else a half-axis of _WANT."""
    axis = win.get("axis")
    if ray and isinstance(axis, list) and len(axis) == 2 and axis != [0, 0] \
            and all(type(c) is int and abs(c) <= 16 for c in axis):
        direction, want = tuple(axis), 1
    elif (want := _WANT[fam].get((axis, orient)) if isinstance(axis, str) else None) is not None:
        direction = AXES[axis]
    else:
        raise CertificateError(f"parts.winding.axis {str(axis)[:12]!r} is not allowed for {fam}")
    title, total = f"W the outer curve crosses the {axis} half-axis {want} time(s)", 0
    for key in curves:
        q, c = key.split(":")
        paths = win["boxes"][key]
        if not isinstance(paths, list) or not paths or not all(isinstance(p, str) for p in paths):
            raise CertificateError(f"parts.winding.{key} must be a list of paths")
        got = _crossings(nets[int(q)], c, paths, direction, prec)
        if isinstance(got, str):
            part(title, False, got)
            return False
        total += got
    part(title, total == want, f"{total} crossing(s)")
    return True
