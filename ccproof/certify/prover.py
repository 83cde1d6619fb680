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

from flint import arb, ctx, fmpq

from ccproof.certify.verify import (
    C1_SCHEMA,
    PATCHES,
    SCHEMA,
    STAR_CURVES,
    _decimal,
    arb_from_table,
    cell_det_poly,
    corner_containment,
    corner_det_form,
    hull_nets,
    interval_cells,
    lam_interval_ok,
    mirror_symmetric,
    parameter_nets,
    regularity_form,
    required_cells,
    square_inside_image,
    star_form,
)
from ccproof.errors import CCProofError, check_valence
from ccproof.rigorous import bernstein_coefficients, certainly_positive, lower_bound
from ccproof.tables.format import certificates_dir, read_table_json, table_nets_arb, table_nets_exact, table_path

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
        todo = required_cells(nets, lam, N, prec, mirror_symmetric(table_nets_exact(table)))
        it = todo
        if progress:
            from tqdm import tqdm

            it = tqdm(todo, desc=f"k={_kname(k)} cells", unit="cell", leave=False)
        for l, m, p, q in it:
            root = bernstein_coefficients(cell_det_poly(nets, lam, N, l, m, p, q, prec))
            cells[f"{l},{m},{p},{q}"] = prove_positive(root, (0, 1), f"cell ({l},{m}) piece ({p},{q})")
        corner = {n: prove_positive(corner_det_form(nets, lam, N, n, prec), (2, 3, 0, 1),
                                    f"corner {n}") for n in PATCHES}
    stats["cells_with_weight"] = len(todo)
    parts = {"regularity": regularity, "cells": cells, "corner": corner}
    summary, stats["boxes"] = _summary([parts])
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
        "parts": parts,
        "summary": summary,
        "stats": stats,
    }


def _decimal_str(x, up, digits=14):
    """A short decimal string below (``up=False``) or above an arb/fmpq ``x``, checked exactly."""
    from decimal import ROUND_CEILING, ROUND_FLOOR, Decimal

    d = Decimal(arb(x).mid().str(30, radius=False)).quantize(Decimal(10) ** -digits,
                                                                 rounding=ROUND_CEILING if up else ROUND_FLOOR)
    step = Decimal(10) ** -digits
    while True:  # move outward until the exact comparison holds
        q = _decimal(str(d))
        if (q >= x) if up else (q <= x):
            return str(d)
        d = d + step if up else d - step


def _prove_piece(exact, La, Lb, N, degree, trunc, prec, progress, label):
    """Boxes for one lam piece [La, Lb] (fmpq) of an interval certificate; raises ProofFailed."""
    with ctx.workprec(prec):
        zn = [parameter_nets(exact, La, Lb, i, degree, prec) for i in range(N)]
        nets = hull_nets(zn[0], prec)
        lam = arb(La).union(arb(Lb))
        if not corner_containment(nets, lam, N)[0]:
            raise ProofFailed(f"{label}: the corner cell [0, 2^-{N}]^2 is not certainly mapped into [0,1/6)^2")
        if not square_inside_image(nets):
            raise ProofFailed(f"{label}: [0,1/2]^2 not certainly inside Phi([0,1]^2)")
        regularity = {n: prove_positive(regularity_form(nets, n, prec), (0, 1), f"{label} det J_Phi on {n}")
                      for n in PATCHES}
        corner = {n: prove_positive(corner_det_form(nets, lam, N, n, prec), (2, 3, 0, 1),
                                    f"{label} corner {n}") for n in PATCHES}
        todo = interval_cells(zn, N, trunc, prec, mirror_symmetric(exact))
        it = todo
        if progress:
            from tqdm import tqdm

            it = tqdm(todo, desc=f"{label} cells", unit="cell", leave=False)
        cells = {key: prove_positive(build(), (1, 2, 0), f"{label} cell {key}") for key, build in it}
    return {"regularity": regularity, "cells": cells, "corner": corner}


def prove_interval(k0, prec=DEFAULT_PREC, tables_dir=None, progress=True, taylor_degree=3, truncation_degree=2,
                   max_pieces=16):
    """Appendix-A certificate for every valence k >= k0 at once (R10, docs/appendix_a.md).

    lam runs over [La, Lb] with La <= lam(k0) and Lb >= (3 + sqrt 5)/8; the nets are Taylor models in
    zeta (lam = mid + zeta * half-width) built from the table's exact forms, so part D keeps the
    correlation between control points (an interval hull of the nets does not: its coefficients are
    ~0.02 wide against cell margins of ~4e-4). A piece that fails is bisected (up to ``max_pieces``).
    """
    k = _parse_k(f">={k0}" if isinstance(k0, int) else k0)
    table = read_table_json(table_path(k, tables_dir))
    exact = table_nets_exact(table)
    N = int(table["derived"]["N"])
    with ctx.workprec(prec):
        c = arb(fmpq(2, k["min"])).cos_pi()
        lam0 = (5 + c + ((1 + c) * (9 + c)).sqrt()) / 16
        ends = [_decimal_str(lam0.lower(), up=False), _decimal_str(((3 + arb(5).sqrt()) / 8).upper(), up=True)]
    assert lam_interval_ok(k["min"], _decimal(ends[0]), _decimal(ends[1]), prec)
    todo = [(ends[0], ends[1])]
    pieces = []
    while todo:
        a, b = todo.pop(0)
        label = f"k>={k['min']} lam in [{a}, {b}]"
        try:
            parts = _prove_piece(exact, _decimal(a), _decimal(b), N, taylor_degree, truncation_degree, prec,
                                 progress, label)
        except ProofFailed:
            if len(pieces) + len(todo) + 2 > max_pieces:
                raise
            mid = _decimal_str((_decimal(a) + _decimal(b)) / 2, up=False)
            todo[:0] = [(a, mid), (mid, b)]
            continue
        pieces.append({"lam": [a, b], "parts": parts})
    summary, boxes = _summary([pc["parts"] for pc in pieces])
    return {
        "schema": SCHEMA,
        "valence": k,
        "N": N,
        "prec": prec,
        "table": {"file": f"tables/{table_path(k).name}", "hash": table["hash"]},
        "parameter": {"variable": "lam", "taylor_degree": taylor_degree, "truncation_degree": truncation_degree},
        "pieces": pieces,
        "statement": (
            f"For every valence k >= {k['min']}: the Appendix-A statement of the per-valence certificates "
            "(det J_Phi > 0, [0,1/2]^2 inside Phi([0,1]^2), det J_G > 0 on every cell and on the corner cell), "
            "proved for every lam in the pieces, which cover [lam(k0), (3 + sqrt 5)/8]; c = (16 lam^2 - 10 lam + 1)"
            "/(2 lam). Part D uses Taylor models in zeta (lam = mid + zeta * half-width), axis 0 of its boxes."
        ),
        "readings": {"weight": "R5 (c = 6)", "N": "R8", "corner": "R9", "interval": "R10 with lam as the variable"},
        "summary": summary,
        "stats": {"pieces": len(pieces), "boxes": boxes,
                  "cells_with_weight": sum(len(pc["parts"]["cells"]) for pc in pieces)},
    }


def _summary(parts_list):
    """(smallest claimed bound per section as strings, number of boxes) over a list of ``parts``."""
    names = {"regularity": "min_bound_det_J_phi_local", "cells": "min_bound_det_J_G_cells_local",
             "corner": "min_bound_det_J_G_corner_over_h2"}
    summary = {name: str(min((fmpq_of(b["bound"]) for parts in parts_list for boxes in parts[sec].values()
                              for b in boxes), default=None)) for sec, name in names.items()}
    return summary, sum(len(v) for parts in parts_list for sec in parts.values() for v in sec.values())


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
