"""The covers of a ``dart:>=K0`` record: bisection over the trusted evaluators, written as trees (untrusted).

The verifier (:mod:`ccproof.certify.verify.dart_trees`) replays a tree and never searches; this module is the
search. :func:`cover` bisects each grid cell of a region's root until the region's evaluator
(:class:`~ccproof.certify.verify.dart_regularity.RegularityBox`,
:class:`~ccproof.certify.verify.dart_curves.CurveBox`) proves the claim's sign on every leaf, and records the
leaves in the record's grammar (docs/certificates.md, "Every dart K >= K0 in one certificate"): a path of
halvings per leaf, a bound a little inside the leaf's enclosure (floats choose the bound; the verifier
decides), and ``outside`` leaves in the middle region where no K >= K0 lies. :func:`map_covers` builds the
covers of R, T and W for every sigma box. The spectrum's trees and the record around them are not written
yet: no ``dart:>=K0`` certificate exists (docs/tagged_c1.md, "What remains before a certificate").
"""

from __future__ import annotations

import functools
import itertools
import math

from flint import fmpq

from ccproof.certify.verify.dart_curves import CurveModels
from ccproof.certify.verify.dart_regularity import RegularityModels
from ccproof.certify.verify.dart_trees import leaf_box
from ccproof.certify.verify.errors import CertificateError


def _inside(val, sign):
    """A short decimal strictly inside the enclosure's side that the claim needs (None if none)."""
    edge = float(val.lower()) if sign > 0 else float(val.upper())
    if not math.isfinite(edge) or edge * sign <= 0:
        return None
    mag = 10.0 ** math.floor(math.log10(abs(edge)))
    q = math.floor(abs(edge) * 0.99 / mag * 100) / 100 * mag  # three digits, rounded towards 0
    return f"{sign * q:.3g}" if q > 0 else None


def cover(root, evaluate, sign, grid, max_depth=16, k0=None, outside=False):
    """A tree proving sign * quantity > 0 on the root box, in the record's grammar.

    Parameters
    ----------
    root : list of (fmpq, fmpq)
    evaluate : callable (box) -> arb
    sign : int
        +1 (the quantity > 0) or -1 (< 0).
    grid : sequence of int
        Equal cells per axis before bisecting.
    max_depth : int
        Halvings per leaf at most (the verifier accepts 32).
    k0 : int, optional
        With ``outside``: leaves with s_lo w_lo > 1/k0 are written ``outside`` (the middle region).
    outside : bool

    Returns
    -------
    dict
        ``{"grid": [...], "leaves": [...]}``.

    Raises
    ------
    ValueError
        Where a leaf stays undecided at ``max_depth``.

    Examples
    --------
    >>> from flint import arb, fmpq
    >>> tree = cover([(fmpq(0), fmpq(1))], lambda b: arb(b[0][0] + 1).union(arb(b[0][1] + 1)), 1, [2])
    >>> [leaf["bound"] for leaf in tree["leaves"]]
    ['0.989', '1.48']
    """
    n = len(root)
    leaves = []
    for cell in itertools.product(*(range(g) for g in grid)):
        stack = [""]
        while stack:
            path = stack.pop()
            box = leaf_box(root, list(grid), list(cell), path)
            if outside and box[0][0] * box[1][0] > fmpq(1, k0):
                leaves.append({"cell": list(cell), "path": path, "outside": True})
                continue
            try:
                val = evaluate(box)
                bound = _inside(val, sign) if (val > 0 if sign > 0 else val < 0) else None
            except (ZeroDivisionError, ValueError, CertificateError):
                bound = None
            if bound is not None:
                leaves.append({"cell": list(cell), "path": path, "bound": bound})
                continue
            depth = len(path) // 2
            if depth >= max_depth:
                raise ValueError(f"undecided at depth {depth}: cell {list(cell)}, box {box}")
            axis = depth % n
            stack += [f"{path}{axis}H", f"{path}{axis}L"]
    return {"grid": list(grid), "leaves": leaves}


def map_covers(k0, sig_lo, sig_hi, hints, s0, layer, winding, prec=128, progress=None):
    """The covers of R, T and W for every sigma box: ``{"regularity": ..., "transversal": ..., "winding": ...}``
    as the record's ``parts`` (docs/certificates.md).

    Parameters
    ----------
    k0 : int
    sig_lo, sig_hi : fmpq
        The bracket of sigma(K).
    hints : TaylorHints
    s0 : fmpq
        The bulk is s in [s0, 1/2].
    layer : int
        T: the layer quadrants 0..T-1; the middle is (s, w) in [0, s0] x [0, 1/T].
    winding : (fmpq, fmpq)
        (s_a, s_b): Y < 0 on [s0, s_a], X > 0 on [s_a, s_b], Y > 0 on [s_b, 1/2].
    prec : int
    progress : callable (str) -> None, optional

    Returns
    -------
    dict
    """
    R = RegularityModels(sig_lo, sig_hi, hints, layer, prec)
    C = CurveModels(sig_lo, sig_hi, hints, layer, prec)
    h0, half = fmpq(1, k0), fmpq(1, 2)
    s_a, s_b = winding
    bulk, middle, hroot = [(s0, half), (fmpq(0), h0)], [(fmpq(0), s0), (fmpq(0), fmpq(1, layer))], [(fmpq(0), h0)]
    out = {"regularity": {"bulk": [], "middle": [], "layer": {str(q): [] for q in range(layer)}},
           "transversal": {"bulk": [], "middle": [], "layer": {str(q): [] for q in range(layer)}},
           "winding": {"Y<0 bulk": [], "X>0 bulk": [], "Y>0 bulk": [], "Y<0 middle": [],
                       "Y<0 layer": {str(q): [] for q in range(layer)}}}
    for i in range(hints.sigma_boxes):
        rb, cb = R.sigma_box(i), C.sigma_box(i)
        reg, tra, win = out["regularity"], out["transversal"], out["winding"]
        reg["bulk"].append(cover(bulk, rb.bulk, 1, [16, 1]))
        reg["middle"].append(cover(middle, rb.middle, 1, [1, 1], k0=k0, outside=True))
        tra["bulk"].append(cover(bulk, cb.transversal_bulk, 1, [16, 1]))
        tra["middle"].append(cover(middle, cb.transversal_middle, 1, [1, 1], k0=k0, outside=True))
        win["Y<0 bulk"].append(cover([(s0, s_a), (fmpq(0), h0)], cb.y_bulk, -1, [8, 1]))
        win["X>0 bulk"].append(cover([(s_a, s_b), (fmpq(0), h0)], cb.x_bulk, 1, [8, 1]))
        win["Y>0 bulk"].append(cover([(s_b, half), (fmpq(0), h0)], cb.y_bulk, 1, [8, 1]))
        win["Y<0 middle"].append(cover(middle, cb.y_middle, -1, [1, 1], k0=k0, outside=True))
        for q in range(layer):
            reg["layer"][str(q)].append(cover(hroot, functools.partial(rb.layer, q), 1, [1]))
            tra["layer"][str(q)].append(cover(hroot, functools.partial(cb.transversal_layer, q), 1, [1]))
            win["Y<0 layer"][str(q)].append(cover(hroot, functools.partial(cb.y_layer, q), -1, [1]))
        if progress is not None:
            progress(f"sigma box {i + 1}/{hints.sigma_boxes}")
    return out
