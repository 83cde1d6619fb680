"""Prover for tagged configurations (untrusted): "not C1" witnesses and "C1" characteristic maps.

For ``crease:N``, ``corner:N`` and ``dart:K`` (docs/tagged_c1.md) the prover reads the spectrum the
verifier derives (:mod:`ccproof.certify.verify.tagged`), tries witness nets made of eigenvectors
(:mod:`ccproof.certify.verify.tagged_c1`) and keeps the first that the verifier accepts
(:func:`prove_tagged`); else :func:`prove_tagged_c1` builds the characteristic map's Bernstein forms
(:mod:`ccproof.certify.verify.tagged_map`) and subdivides them until they are certainly positive.
Floats only choose (pivots, isolating intervals); every certificate is re-checked by the verifier
before it is returned. Where neither works the configuration is reported with the reason.
"""

from __future__ import annotations

import json
from pathlib import Path

from flint import ctx, fmpq, fmpq_mat, fmpq_poly

from ccproof.certify.verify import TAGGED_SCHEMA, verify_certificate
from ccproof.certify.verify.tagged import (
    crease_block,
    crease_points,
    eigenvalues,
    labels,
    leading_spectrum,
    parse_configuration,
    sharp_rays,
)
from ccproof.certify.verify.tagged_modes import MIN_N, mode_spectrum, mode_vector, normalized_vector
from ccproof.errors import CCProofError

DEFAULT_PREC = 128


def configurations(text):
    """The configurations of a command-line argument: ``crease:4``, ``crease:1-30``, ``dart:3-10``.

    Parameters
    ----------
    text : str

    Returns
    -------
    list of str

    Raises
    ------
    CCProofError
        For anything else.

    Examples
    --------
    >>> configurations("corner:2-4"), configurations("dart:5"), configurations("crease:>=101")
    (['corner:2', 'corner:3', 'corner:4'], ['dart:5'], ['crease:>=101'])
    """
    fam, colon, rng = str(text).partition(":")
    if rng.startswith(">="):  # every N >= N0 in one certificate (tagged_limit)
        try:
            parse_configuration(str(text))
        except (ValueError, TypeError) as exc:
            raise CCProofError(str(exc)) from None
        return [str(text)]
    a, dash, b = rng.partition("-")
    try:
        lo, hi = int(a), int(b if dash else a)
    except ValueError:
        raise CCProofError(f"configuration {text!r}: expected FAMILY:N or FAMILY:A-B with FAMILY one of "
                           "dart, crease, corner") from None
    names = [f"{fam}:{n}" for n in range(lo, hi + 1)]
    for name in names:
        try:
            parse_configuration(name)
        except (ValueError, TypeError) as exc:  # names the configuration and what is wrong with it
            raise CCProofError(str(exc) if name == text else f"{text!r}: {exc}") from None
    if not colon or not names:
        raise CCProofError(f"configuration {text!r}: empty or without a family")
    return names


def _decimal(x):
    return f"{x:.25g}"


def _interval(z, others):
    """An isolating decimal interval around the real root z (floats only choose it; the verifier decides)."""
    m = float(z.real.mid())
    gap = min([abs(complex(float(o.real.mid()), float(o.imag.mid())) - m) for o in others] + [1.0])
    return [_decimal(m - gap / 3), _decimal(m + gap / 3)]


def _kernel(M):
    """Rational basis of the null space of an fmpq_mat."""
    R, rank = M.rref()
    n = M.ncols()
    leads = []
    for r in range(rank):
        leads.append(next(c for c in range(n) if R[r, c] != 0))
    basis = []
    for f in (c for c in range(n) if c not in leads):
        v = [fmpq(0)] * n
        v[f] = fmpq(1)
        for r, c in enumerate(leads):
            v[c] = -R[r, f] / R[r, c]
        basis.append(v)
    return basis


def _crease_vectors(fam, n):
    """(gamma, crease values) for the crease block's rational eigenvectors, per eigenvalue."""
    C = crease_block(fam, n)
    out = []
    for p, _ in C.charpoly().factor()[1]:
        if p.degree() == 1:
            g = -p[0] / p[1]
            if 0 < g < 1:
                M = fmpq_mat([[C[i, j] - (g if i == j else 0) for j in range(5)] for i in range(5)])
                out += [(g, v) for v in _kernel(M)]
    # single-ray vectors first (the corner's rays are independent), then by decreasing gamma
    return sorted(out, key=lambda t: -t[0])


def _interior_candidates(fam, n, prec):
    """Simple real positive eigenvalues that are not the crease block's, largest first, with intervals."""
    ev = eigenvalues(fam, n, prec)
    Cpoly = crease_block(fam, n).charpoly()
    out = []
    for i, (z, p, e, _) in enumerate(ev):
        if e == 1 and z.imag.is_zero() and z.real > 0 and p.gcd(Cpoly).degree() == 0:
            others = [t[0] for j, t in enumerate(ev) if j != i]
            out.append((float(z.real.mid()), z, _interval(z, others)))
    out.sort(key=lambda t: -t[0])
    return out


def _mode_candidates(fam, n, prec):
    """The two largest mode roots (crease, corner, N >= MIN_N) with intervals and pivots, from the closed
    forms of :mod:`ccproof.certify.verify.tagged_modes` (floats choose; the verifier decides)."""
    with ctx.workprec(prec):
        ev = mode_spectrum(fam, n)
        roots = sorted((i for i, t in enumerate(ev) if t[3] is not None and t[0].imag.is_zero()),
                       key=lambda i: -float(ev[i][0].real.mid()))
        out = []
        for i in roots[:2]:
            z = ev[i][0]
            f = mode_vector(fam, n, ev[i][3], z.real)
            if f is None:
                return []
            pivot = max((k for k, v in enumerate(f) if not isinstance(v, fmpq)), key=lambda k: float(abs(f[k]).mid()))
            others = [t[0] for k, t in enumerate(ev) if k != i]
            out.append((float(z.real.mid()), z, _interval(z, others), pivot))
    return out


def _pivot(fam, n, z, prec):
    """A point where the eigenvector of the simple eigenvalue z is large (numerical choice only; the
    verifier proves the bordered system regular)."""
    import numpy as np
    from flint import arb, arb_mat

    from ccproof.certify.verify.tagged import sector_matrix
    from ccproof.certify.verify.tagged_modes import bordered_solve

    S = sector_matrix(fam, n)
    cp = crease_points(fam, n) if fam != "dart" else []
    free = [i for i in range(S.nrows()) if i not in cp]
    A = np.array([[int(S[i, j].p) / int(S[i, j].q) for j in free] for i in free])
    # floats choose the pivot: the bordered system is regular where both the right and the left
    # eigenvector are non-zero, so take the largest |right * left| (the verifier decides)
    zf = float(z.real.mid())
    w, V = np.linalg.eig(A)
    wl, U = np.linalg.eig(A.T)
    v = np.abs(V[:, int(np.argmin(np.abs(w - zf)))]) * np.abs(U[:, int(np.argmin(np.abs(wl - zf)))])
    order = [free[i] for i in np.argsort(-v)]
    best = None
    with ctx.workprec(prec):
        for pv in order[:8]:
            try:
                sol = bordered_solve([[arb(S[i, j]) for j in free] for i in free], z.real, free.index(pv), arb_mat)
            except ZeroDivisionError:
                continue
            size = max(abs(float(x.mid())) for x in sol)
            if best is None or size < best[0]:
                best = (size, pv)
            if size <= 1.0:
                break
    return None if best is None else best[1]


def witness_candidates(name, prec=DEFAULT_PREC):
    """Witness dictionaries to try for a crease or corner sector, most promising first.

    Parameters
    ----------
    name : str
    prec : int

    Returns
    -------
    list of dict
        Each the ``witness`` field of a ``"not C1"`` certificate (docs/tagged_c1.md).
    """
    fam, n = parse_configuration(name)
    if fam == "dart":
        return _flip_candidates(n, prec)
    pts = labels(fam, n)
    modes = n >= MIN_N  # the verifier's closed forms: no exact spectrum, no pivot search
    inner = _mode_candidates(fam, n, prec) if modes else _interior_candidates(fam, n, prec)
    creases = _crease_vectors(fam, n)
    top = max(g for g, _ in creases) if creases else None
    creases = [(g, v) for g, v in creases if g == top]  # the verifier wants gamma = the crease block's largest
    zero = ["0"] * len(crease_points(fam, n))

    def irr(t):
        pv = t[3] if modes else _pivot(fam, n, t[1], prec)
        return None if pv is None else {"eigenvalue": t[2], "crease": zero, "pivot": pv}

    def rat(g, v):
        return {"eigenvalue": _decimal_exact(g), "crease": [_decimal_exact(x) for x in v]}

    out = []
    if len(inner) >= 2:
        x, y = irr(inner[0]), irr(inner[1])
        if x and y:
            for g, v in creases:
                if float(g.p) / float(g.q) <= inner[1][0] and _decimal_exact(g) and all(_decimal_exact(c) for c in v):
                    for r in sharp_rays(fam, n):
                        out.append({"x": x, "y": y, "z": rat(g, v), "ray": r})
    if fam == "corner" and inner and not modes:
        x = irr(inner[0])
        half = [(g, v) for g, v in creases if g == fmpq(1, 2)]
        if x and len(half) >= 2:
            for (g1, v1), (g2, v2) in ((half[0], half[1]), (half[1], half[0])):
                # z: the other ray's tangent; or, where y has no eigenvector (a Jordan chain at 1/2, corner:4),
                # the combinations of both rays' tangents that lift to one
                for zv in (v2, [a + b for a, b in zip(v1, v2)], [b - a for a, b in zip(v1, v2)]):
                    out += [{"x": x, "y": rat(g1, v1), "z": rat(g2, zv), "ray": r} for r in sharp_rays(fam, n)]
    del pts
    return out


def _flip_candidates(k, prec):
    """A dart's witness (x, y): the two eigenvalues below 1 largest in modulus, when real and simple, with
    intervals and pivots (floats choose; the verifier decides whether their signs differ)."""
    if k >= MIN_N:
        return []
    ev = eigenvalues("dart", k, prec)
    rest = sorted((i for i, t in enumerate(ev) if t[1] != fmpq_poly([-1, 1])),
                  key=lambda i: -float(abs(ev[i][0]).mid()))
    coords = []
    for i in rest[:2]:
        z = ev[i][0]
        pv = _pivot("dart", k, z, prec) if z.imag.is_zero() and ev[i][2] == 1 else None
        if pv is None:
            return []
        coords.append({"eigenvalue": _interval(z, [t[0] for j, t in enumerate(ev) if j != i]), "crease": [],
                       "pivot": pv})
    return [{"x": coords[0], "y": coords[1]}]


def _decimal_exact(q):
    """The exact decimal string of a rational with denominator 2^a 5^b, else None."""
    q = fmpq(q)
    d, e = int(q.q), 0
    while d % 10 and (d % 2 == 0 or d % 5 == 0) or d % 10 == 0:
        if d % 10 == 0:
            d //= 10
        elif d % 2 == 0:
            d //= 2
        else:
            d //= 5
        e += 1
    if d != 1:
        return None
    s = int(q.p) * 10 ** e // int(q.q)
    sign = "-" if s < 0 else ""
    digits = str(abs(s)).rjust(e + 1, "0")
    return sign + (digits if e == 0 else digits[:-e] + "." + digits[-e:])


def prove_tagged(name, prec=DEFAULT_PREC):
    """A verified "not C1" certificate (a witness net) for one configuration, or None with the reason (the
    prover of the registry's route "tagged not C1"; :func:`ccproof.certify.prover.prove_configuration`).

    Parameters
    ----------
    name : str
        ``"crease:N"``, ``"corner:N"`` or ``"dart:K"``.
    prec : int

    Returns
    -------
    (dict or None, str)
        The certificate (already accepted by the verifier) and a one-line summary.

    Examples
    --------
    >>> cert, why = prove_tagged("crease:5")
    >>> cert["statement"], cert["witness"]["z"]["eigenvalue"]
    ('not C1', '0.5')
    >>> prove_tagged("crease:4")[1]  # doctest: +NORMALIZE_WHITESPACE
    'undecided: crease:4: lam2 = 1/2 lies in a Jordan block (algebraic multiplicity 2, geometric 1);
     no witness candidate'
    """
    fam, n = parse_configuration(name)
    if isinstance(n, dict):
        return None, f"undecided: {name}: the witness route takes one configuration"
    if fam == "dart" and n >= MIN_N:  # no flip (lam1 > lam2 > 0): the C1 route decides these
        return None, f"undecided: a dart's witness is checked for K < {MIN_N} only"
    why = []
    for w in witness_candidates(name, prec):
        for q in range(n):
            cert = {"schema": TAGGED_SCHEMA, "configuration": name, "statement": "not C1", "prec": prec,
                    "witness": dict(w, quadrant=q)}
            res = verify_certificate(cert, log=lambda line: None)
            if res:
                ray = f"ray {w['ray']}, " if "ray" in w else ""
                return cert, f"not C1 (witness: {ray}quadrant {q})"
            why += [f"{p.name.split(':')[0]}: {p.message}" for p in res.failures()][:1]
            if not any(p.name.startswith(("N ", "F ")) for p in res.failures()):
                break  # only the normal depends on the quadrant
    witness = f"; no witness ({why[0]})" if why else "; no witness candidate"
    return None, f"undecided: {leading_spectrum(fam, n, prec)[1]}{witness}"


# hints of the interval certificate, tried in turn: rho, R, arcs on |theta| = rho, arcs on |theta| = R, box side;
# rho = 0.2 serves N0 >= 16 (about 1 s), 0.3 N0 >= 11 (3 s), 0.45 every N0 >= 7 (13 s; docs/tagged_c1.md)
LIMIT_HINTS = (("0.2", "0.3", 512, 2048, "0.05"), ("0.3", "0.4", 1024, 4096, "0.05"),
               ("0.45", "0.5", 4096, 8192, "0.0125"))
_Z = {"crease": ["0", "-0.5", "-1", "0.5", "1"], "corner": ["0", "0.5", "1", "0", "0"]}


def prove_tagged_limit(name, prec=DEFAULT_PREC):
    """A verified "not C1" certificate for every N >= N0 at once (``"crease:>=101"``, ``"corner:>=101"``;
    :mod:`ccproof.certify.verify.tagged_limit`), or None with the reason.

    The witness is fixed (modes 1 and 2, the crease tangent z of eigenvalue 1/2, ray 0, quadrant 0); the
    prover only picks the hints (:data:`LIMIT_HINTS`) and keeps the first set the verifier accepts.

    Examples
    --------
    >>> cert, why = prove_tagged_limit("corner:>=101")
    >>> cert["limit"]["rho"], why
    ('0.2', 'not C1 for every N >= 101 (the limit of H(theta) along |theta| = 0.2)')
    """
    fam, n = parse_configuration(name)
    if fam not in _Z or not isinstance(n, dict):
        return None, f"undecided: {name}: interval certificates are defined for crease:>=N0 and corner:>=N0"
    why = "no hints"
    for rho, R, arcs, outer, box in LIMIT_HINTS:
        cert = {"schema": TAGGED_SCHEMA, "configuration": name, "statement": "not C1", "prec": prec,
                "witness": {"z": {"eigenvalue": "0.5", "crease": _Z[fam]}},
                "limit": {"rho": rho, "R": R, "arcs": arcs, "outer_arcs": outer, "box": box}}
        res = verify_certificate(cert, log=lambda line: None)
        if res:
            return cert, f"not C1 for every N >= {n['min']} (the limit of H(theta) along |theta| = {rho})"
        why = res.error or "; ".join(f"{p.name.split(':')[0]}: {p.message}" for p in res.failures())
    return None, f"undecided: {why}"


def write_tagged(cert, out_dir):
    """Write ``out_dir/FAMILY/nNNN.json`` (``kKKK`` for darts; ``n_ge_N0``, ``k_ge_K0`` for every N >= N0, K >= K0);
    returns the path."""
    fam, n = parse_configuration(cert["configuration"])
    d = Path(out_dir) / fam
    d.mkdir(parents=True, exist_ok=True)
    letter = "k" if fam == "dart" else "n"
    path = d / (f"{letter}_ge_{n['min']}.json" if isinstance(n, dict) else f"{letter}{n:03d}.json")
    path.write_text(json.dumps(cert, indent=1) + "\n")
    return path


_PIVOT_PAIRS = ((("q", 0, 1, 1), ("q", 1, 1, 1)), (("q", 0, 2, 1), ("q", 1, 1, 2)), (("r", 1, 1, 0), ("r", 2, 1, 0)),
                (("q", 0, 1, 1), ("q", 2, 1, 1)), (("q", 1, 2, 2), ("q", 3, 2, 1)))


def _map_specs(fam, n, lead, prec, choice=0):
    """Coordinate specs (x for lam1, y for lam2) of the characteristic map, or None (``choice`` picks
    another pair of pivots for a double rational eigenvalue of a dart)."""
    l1, l2 = lead[1], lead[2]
    ev = eigenvalues(fam, n, prec)
    if fam == "corner":
        if l1[1].degree() != 1 or l2[1].degree() != 1:
            return None
        return ({"eigenvalue": "0.5", "crease": ["0", "0.5", "1", "0", "0"]},
                {"eigenvalue": "0.5", "crease": ["0", "0", "0", "0.5", "1"]})
    if fam == "crease":
        t = {"eigenvalue": "0.5", "crease": ["0", "-0.5", "-1", "0.5", "1"]}
        if l1[1].degree() == 1:  # 1/2 double: the interior 1/2 vector, normalized at a quadrant point
            pts = labels(fam, n)
            return {"eigenvalue": "0.5", "crease": ["0"] * 5, "pivot": pts.index(("q", 0, 1, 1))}, t
        others = [t_[0] for t_ in ev if t_[0] is not l1[0]]
        pv = _pivot(fam, n, l1[0], prec)
        return {"eigenvalue": _interval(l1[0], others), "crease": ["0"] * 5, "pivot": pv}, t
    out = []
    for i, t_ in enumerate((l1, l2)):
        if t_[1].degree() == 1:  # dart:4, 1/2 double: two exact vectors with different pivots
            pts = labels(fam, n)
            out.append({"eigenvalue": _decimal_exact(-t_[1][0] / t_[1][1]), "crease": [],
                        "pivot": pts.index(_PIVOT_PAIRS[choice % len(_PIVOT_PAIRS)][i])})
        else:
            others = [o[0] for o in ev if o[0] is not t_[0]]
            out.append({"eigenvalue": _interval(t_[0], others), "crease": [], "pivot": _pivot(fam, n, t_[0], prec)})
    if out[0].get("pivot") is None or out[1].get("pivot") is None:
        return None
    return tuple(out)


def _winding_paths(root_a, root_p, depth=12):
    """Split a curve until each box is decided for the crossing count (as the verifier's check_map counts them)."""
    out = []
    stack = [(root_a, root_p, "", 0)]
    while stack:
        fa, fp, path, d = stack.pop()
        if (all(c > 0 for c in fp.coeffs) or all(c < 0 for c in fp.coeffs) or all(c < 0 for c in fa.coeffs)
                or all(c > 0 for c in fa.coeffs) and any(
                    s0 < 0 < s1 or s1 < 0 < s0 for s0, s1 in [(fp.coeffs[0], fp.coeffs[-1])])):
            out.append(path)
            continue
        if d >= depth:
            raise CCProofError(f"crossing count: box {path!r} undecided after {depth} splits")
        (al, ah), (pl, ph) = fa.split(0), fp.split(0)
        stack += [(ah, ph, path + "0H", d + 1), (al, pl, path + "0L", d + 1)]
    return sorted(out)


def prove_tagged_c1(name, prec=DEFAULT_PREC):
    """A verified "C1" certificate (characteristic map regular and injective), or None with the reason.

    Parameters
    ----------
    name : str
    prec : int

    Returns
    -------
    (dict or None, str)

    Examples
    --------
    >>> cert, why = prove_tagged_c1("corner:1")
    >>> cert["statement"], why
    ('C1', 'C1')
    """
    fam, n = parse_configuration(name)
    if isinstance(n, dict):
        return None, "undecided: no C1 certificate for an interval of configurations"
    if fam == "dart" and n >= MIN_N:  # the verifier's mode route: no exact spectrum of the whole matrix
        specs, entries = _dart_specs(n, prec)
        if specs is None:
            return None, "undecided: no isolated lam1 > lam2 or no regular pivot"
        cert, last = _prove_map(name, fam, n, specs, prec, entries)
        return (cert, "C1") if cert is not None else (None, f"undecided: {last}")
    ok, msg, lead = leading_spectrum(fam, n, prec)
    if not ok:
        return None, f"undecided: {msg}"
    last = "no characteristic-map coordinates found"
    double = lead[1][1].degree() == 1 and fam == "dart"
    for choice in range(len(_PIVOT_PAIRS) if double else 1):
        specs = _map_specs(fam, n, lead, prec, choice)
        if specs is None:
            break
        cert, last = _prove_map(name, fam, n, specs, prec)
        if cert is not None:
            return cert, "C1"
    return None, f"undecided: {last}"


def _dart_specs(k, prec):
    """Map coordinates (x for lam1, y for lam2) of dart:k, K >= MIN_N: isolating intervals and pivots where
    the vector is large (floats choose; the verifier decides)."""
    with ctx.workprec(prec):
        ev = mode_spectrum("dart", k)
        rest = sorted((i for i, t in enumerate(ev) if abs(t[0]) < 1), key=lambda i: -float(abs(ev[i][0]).mid()))
        pts = labels("dart", k)
        out = []
        for i in rest[:2]:
            trial = [pts.index(("q", q, 1, 1)) for q in range(k)] + [pts.index(("r", r, 1, 0)) for r in range(1, k)]
            vec = next((v for v in (normalized_vector("dart", k, ev, i, p) for p in trial) if v is not None), None)
            if vec is None:
                return None, None
            # the largest coordinate among the one-ring points (the left eigenvector vanishes on the outer
            # ring, where the bordered system is singular)
            order = sorted(trial, key=lambda j: -float(abs(vec[j]).mid()))[:24]
            pivot = next((j for j in order if normalized_vector("dart", k, ev, i, j) is not None), None)
            if pivot is None:
                return None, None
            others = [t[0] for j, t in enumerate(ev) if j != i]
            out.append({"eigenvalue": _interval(ev[i][0], others), "crease": [], "pivot": pivot})
    return tuple(out), rest[:2]


def _prove_map(name, fam, n, specs, prec, entries=None):
    from flint import arb as _arb

    from ccproof.certify.verify.maps import regularity_form
    from ccproof.certify.verify.tagged_map import quadrant_nets

    cert = {"schema": TAGGED_SCHEMA, "configuration": name, "statement": "C1", "prec": prec,
            "map": {"x": specs[0], "y": specs[1], "orientation": 1}, "parts": {}}
    # the vectors as the verifier derives them (through a dry run of its parser)
    from ccproof.certify.verify.tagged_c1 import eigenvector_of

    with ctx.workprec(prec):
        if entries is not None:  # a dart's mode spectrum entries of lam1, lam2
            ev = mode_spectrum("dart", n)
            lx, ly = (ev[i][0].real for i in entries)
            vx, vy = (normalized_vector("dart", n, ev, i, s["pivot"]) for i, s in zip(entries, specs))
            if vx is None or vy is None:
                return None, "no eigenvector at the chosen pivot"
        else:
            (lx, vx, mx), (ly, vy, my) = (eigenvector_of(fam, n, s, c, prec) for s, c in zip(specs, "xy"))
            if vx is None or vy is None:
                return None, mx if vx is None else my
        nets = [quadrant_nets(fam, n, vx, vy, q, prec) for q in range(n)]
        mid = regularity_form(nets[0], "P2", prec).coeffs[12]
        orient = 1 if mid > 0 else -1
        cert["map"]["orientation"] = orient
        a1, a2 = -_arb(lx).log(), -_arb(ly).log()
        axes = {"crease": ("-x", "+x"), "corner": ("-y", "-x")}.get(fam, ("+x", "-x", "+y", "-y"))
        if fam == "dart" and lx == ly:  # isotropic: any ray is an orbit
            axes += ([2, 1], [1, 2], [-1, 2], [3, 1])
        last = None
        for axis in axes:
            parts, last = _c1_parts(name, nets, n, orient, a1, a2, axis, prec)
            if parts is None:
                continue
            cert["parts"] = parts
            res = verify_certificate(cert, log=lambda line: None)
            if res:
                return cert, "C1"
            last = "the verifier refused: " + "; ".join(f"{p.name}: {p.message}" for p in res.failures())
    return None, last


def _c1_parts(name, nets, n, orient, a1, a2, axis, prec):
    from ccproof.certify.prover import ProofFailed, prove_positive
    from ccproof.certify.verify.maps import STAR_CURVES, regularity_form
    from ccproof.certify.verify.tagged_map import AXES, PIECES, axis_forms, transversal_form

    parts = {"regularity": {}, "transversal": {}, "winding": {"axis": axis, "boxes": {}}}
    a, b = AXES[axis] if isinstance(axis, str) else axis
    with ctx.workprec(prec):
        try:
            for q in range(n):
                for p in PIECES:
                    parts["regularity"][f"{q}:{p}"] = prove_positive(
                        regularity_form(nets[q], p, prec) * orient, (0, 1), f"{name} det J on {q}:{p}")
                for c in STAR_CURVES:
                    parts["transversal"][f"{q}:{c}"] = prove_positive(
                        transversal_form(nets[q], c, a1, a2, prec) * orient, (0,), f"{name} transversality {q}:{c}")
                    parts["winding"]["boxes"][f"{q}:{c}"] = _winding_paths(*axis_forms(nets[q], c, (a, b), prec))
        except (ProofFailed, CCProofError) as exc:
            return None, str(exc)
    return parts, None
