"""Injectivity prover for bmz04 Appendix A (untrusted search; DESIGN.md section 3).

For a valence k the prover builds, from the certified table, every Bernstein form the verifier
will rebuild (det J_Phi on layer 0, det J_G on each dyadic cell and w piece, the R9 corner form),
subdivides each adaptively until all of its coefficients are certainly positive, and writes the
leaves as split paths with a lower bound each. Only the choice of where to split is heuristic;
every number written comes from arb balls. The certificate is re-checked by
:mod:`ccproof.certify.verify`, which trusts none of this module.
"""

from __future__ import annotations

import json
from pathlib import Path

from flint import ctx, fmpq

from ccproof.certify.verify import (
    C1_SCHEMA,
    PATCHES,
    SCHEMA,
    STAR_CURVES,
    arb_from_table,
    cell_det_poly,
    corner_det_poly,
    regularity_form,
    required_cells,
    star_form,
)
from ccproof.errors import CCProofError, check_valence
from ccproof.rigorous import bernstein_coefficients, certainly_positive, lower_bound
from ccproof.tables.format import certificates_dir, read_table_json, table_nets_arb, table_path

DEFAULT_PREC = 128
MAX_DEPTH = 14


class ProofFailed(CCProofError):
    """The search found no certificate (the claim may be false, or needs deeper subdivision)."""


def _round_down(q, digits=6):
    """A short decimal string <= the fmpq ``q`` (> 0), ``digits`` significant digits."""
    from math import floor, log10

    num, den = int(q.p), int(q.q)
    e = floor(log10(num) - log10(den)) - digits + 1
    if e >= 0:
        m = num // (den * 10**e)
        return f"{m}e{e}"
    m = (num * 10 ** (-e)) // den
    while m > 0 and fmpq(m, 10 ** (-e)) > q:  # guard against log10 rounding
        m -= 1
    return f"{m}e{e}"


def prove_positive(root, axes, what, max_depth=MAX_DEPTH):
    """Adaptive subdivision of a Bernstein form until every leaf is certainly positive.

    Returns the list of ``{"path", "bound"}`` leaves. ``axes`` is the cyclic order of split axes.
    Raises :class:`ProofFailed` when a leaf reaches ``max_depth`` or is certainly negative somewhere.
    """
    out = []
    stack = [(root, "", 0)]
    while stack:
        f, path, d = stack.pop()
        if certainly_positive(f):
            lb = lower_bound(f)
            out.append({"path": path, "bound": _round_down(lb)})
            continue
        corners_negative = any(c < 0 for c in _corners(f))
        if corners_negative:
            raise ProofFailed(f"{what}: the determinant is negative at a corner of box {path!r}: the claim is false")
        if d >= max_depth:
            raise ProofFailed(f"{what}: no positive Bernstein bound after {max_depth} splits (path {path!r})")
        a = axes[d % len(axes)]
        lo, hi = f.split(a)
        stack.append((hi, path + f"{a}H", d + 1))
        stack.append((lo, path + f"{a}L", d + 1))
    out.sort(key=lambda b: b["path"])
    return out


def _corners(f):
    import itertools

    vals = []
    for corner in itertools.product(*[(0, n - 1) for n in f.shape]):
        idx = 0
        for c, n in zip(corner, f.shape):
            idx = idx * n + c
        vals.append(f.coeffs[idx])
    return vals


def prove_valence(k, prec=DEFAULT_PREC, tables_dir=None, progress=True):
    """Search a certificate for valence k; returns the certificate dict (see docs/certificates.md)."""
    if isinstance(k, str) and k.strip().startswith(">="):
        k = {"min": check_valence(k.strip()[2:])}
    else:
        k = check_valence(k)
    table = read_table_json(table_path(k, tables_dir))
    N = int(table["derived"]["N"])
    stats = {}
    with ctx.workprec(prec):
        lam = arb_from_table(table, prec)
        nets = table_nets_arb(table, "bezier", prec)
        regularity = {n: prove_positive(regularity_form(nets, n, prec), (0, 1), f"det J_Phi on {n}")
                      for n in PATCHES}
        cells = {}
        todo = required_cells(nets, lam, N, prec)
        it = todo
        if progress:
            from tqdm import tqdm

            it = tqdm(todo, desc=f"k={_kname(k)} cells", unit="cell", leave=False)
        for l, m, p, q in it:
            root = bernstein_coefficients(cell_det_poly(nets, lam, N, l, m, p, q, prec))
            cells[f"{l},{m},{p},{q}"] = prove_positive(root, (0, 1), f"cell ({l},{m}) piece ({p},{q})")
        corner = {n: prove_positive(bernstein_coefficients(corner_det_poly(nets, lam, N, n, prec)), (2, 3, 0, 1),
                                    f"corner {n}") for n in PATCHES}
    stats["cells_with_weight"] = len(todo)
    stats["boxes"] = (sum(len(v) for v in regularity.values()) + sum(len(v) for v in cells.values())
                      + sum(len(v) for v in corner.values()))

    def minb(groups):
        return min((fmpq_of(b["bound"]) for g in groups for b in g), default=None)

    summary = {
        "min_bound_det_J_phi_local": str(minb(regularity.values())),
        "min_bound_det_J_G_cells_local": str(minb(cells.values())),
        "min_bound_det_J_G_corner_over_h2": str(minb(corner.values())),
    }
    return {
        "schema": SCHEMA,
        "valence": k,
        "N": N,
        "prec": prec,
        "table": {"file": f"tables/{table_path(k).name}", "hash": table["hash"]},
        "statement": (
            "For the blend F_b of bmz04 eq. (4) with F = Phi^-1 of valence k and w(u,v) = b(u) b(v) (R5), "
            "det J_G > 0 on [0,1]^2 minus the corner for G(y) = w(Phi(y)) y + (1 - w(Phi(y))) Phi(y) (R7), "
            "det J_Phi > 0, and [0,1/2]^2 lies inside Phi([0,1]^2); with the injectivity of Phi (Reif) "
            "this gives det J_F_b > 0 on the corner quarter (Proposition 1)."
        ),
        "readings": {"weight": "R5 (c = 6)", "N": "R8 (smallest N with Phi([0,2^-N]^2) in [0,1/6)^2)",
                     "corner": "R9 with rho = lam^(3(i-N)), kappa = (2 lam^4)^(i-N)",
                     "jacobians": "cells and regularity w.r.t. the local (s,t) of each box's root"},
        "parts": {"regularity": regularity, "cells": cells, "corner": corner},
        "summary": summary,
        "stats": stats,
    }


def _kname(k):
    return f">={k['min']}" if isinstance(k, dict) else str(k)


def fmpq_of(s):
    from ccproof.certify.verify import _decimal

    return _decimal(s)


def certificate_path(k, directory=None):
    """``k005.json`` for a valence, ``k_ge_40.json`` for the interval ``{"min": 40}``/``">=40"``."""
    if isinstance(k, str) and k.startswith(">="):
        k = {"min": int(k[2:])}
    name = f"k_ge_{int(k['min'])}.json" if isinstance(k, dict) else f"k{int(k):03d}.json"
    return Path(directory or certificates_dir() / "injectivity") / name


def write_certificate(cert, path=None):
    path = Path(path or certificate_path(cert["valence"]))
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(cert, indent=1, sort_keys=True) + "\n", encoding="ascii")
    return path


def _parse_k(k):
    if isinstance(k, str) and k.strip().startswith(">="):
        return {"min": check_valence(k.strip()[2:])}
    if isinstance(k, dict):
        return {"min": check_valence(k["min"])}
    return check_valence(k)


def prove_c1(k, prec=DEFAULT_PREC, tables_dir=None):
    """C1 certificate (Reif's criterion) for valence k or the interval ``">=K0"``: det J_Phi > 0 on
    layer 0 and a star-shaped outer boundary, boxes found by subdivision; the spectral ordering is
    re-derived by the verifier from the table (see :func:`ccproof.certify.verify.verify_c1_certificate`)."""
    k = _parse_k(k)
    table = read_table_json(table_path(k, tables_dir))
    if not table["spectral"]["ok"]:
        raise ProofFailed(f"the spectral ordering is not certified in the table of {_kname(k)}")
    with ctx.workprec(prec):
        nets = table_nets_arb(table, "bezier", prec)
        reg = {n: prove_positive(regularity_form(nets, n, prec), (0, 1), f"det J_Phi on {n}") for n in PATCHES}
        star = {c: prove_positive(star_form(nets, c, prec), (0,), f"star {c}") for c in STAR_CURVES}
    return {
        "schema": C1_SCHEMA,
        "valence": k,
        "prec": prec,
        "table": {"file": f"tables/{table_path(k).name}", "hash": table["hash"]},
        "statement": ("Reif's C1 criterion for Catmull-Clark at valence k: 1 = lam_0 > lam_1 = lam_2 > |lam_3|, "
                      "the characteristic map is regular (det J_Phi > 0) and injective (layer 0 locally "
                      "homeomorphic with a star-shaped outer boundary image)."),
        "parts": {"regularity": reg, "star": star},
    }


def c1_certificate_path(k, directory=None):
    k = _parse_k(k)
    name = f"k_ge_{k['min']}.json" if isinstance(k, dict) else f"k{k:03d}.json"
    return Path(directory or certificates_dir() / "c1") / name
