"""Prover for tagged configurations (untrusted): classify and write "not C1" witnesses.

For ``crease:N``, ``corner:N`` and ``dart:K`` (docs/tagged_c1.md) the prover reads the spectrum the
verifier derives (:mod:`ccproof.certify.verify.tagged`), tries witness nets made of eigenvectors
(:mod:`ccproof.certify.verify.tagged_c1`) and keeps the first that the verifier accepts. Where no
witness is found the configuration is reported with the verifier's spectral reason and no file is
written: a C1 claim needs the characteristic-map part, which is not implemented for tagged sectors.
"""

from __future__ import annotations

import json
from pathlib import Path

from flint import arb, ctx, fmpq, fmpq_mat

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
    >>> configurations("corner:2-4"), configurations("dart:5")
    (['corner:2', 'corner:3', 'corner:4'], ['dart:5'])
    """
    fam, colon, rng = str(text).partition(":")
    a, dash, b = rng.partition("-")
    try:
        lo, hi = int(a), int(b if dash else a)
        names = [f"{fam}:{n}" for n in range(lo, hi + 1)]
        for name in names:
            parse_configuration(name)
    except (ValueError, TypeError) as exc:
        raise CCProofError(f"configuration {text!r}: expected FAMILY:N or FAMILY:A-B with FAMILY one of "
                           f"dart, crease, corner ({exc})") from None
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


def _pivot(fam, n, z, prec):
    """A non-crease point where the eigenvector of z is large (numerical choice only)."""
    from ccproof.certify.verify.tagged import sector_matrix

    S = sector_matrix(fam, n)
    cp = crease_points(fam, n)
    free = [i for i in range(S.nrows()) if i not in cp]
    with ctx.workprec(prec):
        lam = z.real
        best = None
        for pv in free[: min(len(free), 12)]:
            rest = [i for i in free if i != pv]
            from flint import arb_mat
            A = arb_mat([[arb(S[i, j]) - (lam if i == j else 0) for j in rest] for i in rest])
            b = arb_mat([[-arb(S[i, pv])] for i in rest])
            try:
                sol = A.solve(b)
            except ZeroDivisionError:
                continue
            size = max(abs(float(sol[k, 0].mid())) for k in range(len(rest)))
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
        return []
    pts = labels(fam, n)
    inner = _interior_candidates(fam, n, prec)
    creases = _crease_vectors(fam, n)
    top = max(g for g, _ in creases) if creases else None
    creases = [(g, v) for g, v in creases if g == top]  # the verifier wants gamma = the crease block's largest
    zero = ["0"] * len(crease_points(fam, n))

    def irr(t):
        pv = _pivot(fam, n, t[1], prec)
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
    if fam == "corner" and inner:
        x = irr(inner[0])
        half = [(g, v) for g, v in creases if g == fmpq(1, 2)]
        if x and len(half) >= 2:
            for (g1, v1), (g2, v2) in ((half[0], half[1]), (half[1], half[0])):
                for r in sharp_rays(fam, n):
                    out.append({"x": x, "y": rat(g1, v1), "z": rat(g2, v2), "ray": r})
    del pts
    return out


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
    """A verified certificate for the configuration, or None with the reason.

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
    >>> prove_tagged("crease:4")[1]
    'undecided: crease:4: lam2 = 1/2 lies in a Jordan block (multiplicity 2, minimal polynomial multiplicity 2)'
    """
    fam, n = parse_configuration(name)
    ok, msg, _ = leading_spectrum(fam, n, prec)
    why = []
    for w in witness_candidates(name, prec):
        for q in range(n):
            cert = {"schema": TAGGED_SCHEMA, "configuration": name, "statement": "not C1", "prec": prec,
                    "witness": dict(w, quadrant=q)}
            res = verify_certificate(cert, log=lambda line: None)
            if res:
                return cert, f"not C1 (witness: ray {w['ray']}, quadrant {q})"
            why += [f"{p.name.split(':')[0]}: {p.message}" for p in res.failures()][:1]
            if not any(p.name.startswith("N ") for p in res.failures()):
                break  # only the normal depends on the quadrant
    witness = f"; no witness ({why[0]})" if why else "; no witness candidate"
    if ok:
        return None, f"undecided: {msg}{witness}; the characteristic-map part is not checked for tagged sectors"
    return None, f"undecided: {msg}{witness}"


def write_tagged(cert, out_dir):
    """Write ``out_dir/FAMILY/nNNN.json`` (``kKKK`` for darts); returns the path."""
    fam, n = parse_configuration(cert["configuration"])
    d = Path(out_dir) / fam
    d.mkdir(parents=True, exist_ok=True)
    path = d / f"{'k' if fam == 'dart' else 'n'}{n:03d}.json"
    path.write_text(json.dumps(cert, indent=1) + "\n")
    return path
