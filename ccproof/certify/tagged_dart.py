"""The covers of a ``dart:>=K0`` record: bisection over the trusted evaluators, written as trees (untrusted).

The verifier (:func:`ccproof.certify.verify.replay.replay_tree`) replays a tree and never searches; this module
is the search. :func:`cover` bisects each grid cell of a region's root until the region's evaluator
(:class:`~ccproof.certify.verify.dart_tail.SigmaBox`) proves the claim's sign on every leaf, and records the
leaves in the record's grammar (docs/certificates.md, "Every dart K >= K0 in one certificate"): a path of
halvings per leaf, a bound a little inside the leaf's enclosure (floats choose the bound; the verifier
decides), and ``outside`` leaves in the middle region where no K >= K0 lies. :func:`map_covers` builds the
covers of R, T and W for every sigma box, :func:`spectrum_covers` those of Re(1 - F) over the regions N, I,
F, and :func:`prove_dart_tail` the whole record (``ccproof certify 'dart:>=101' --c1``).
"""

from __future__ import annotations

import itertools
import math

from flint import fmpq

from ccproof.certify.verify.dart_tail import DartModels, map_regions
from ccproof.certify.verify.errors import CertificateError
from ccproof.certify.verify.replay import leaf_box


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
    models = DartModels(sig_lo, sig_hi, hints, layer, prec)
    regions = map_regions(k0, s0, layer, winding)
    out = {}
    for i in range(hints.sigma_boxes):
        box = models.sigma_box(i)
        for name, keys, root, method, sign, outside in regions:
            node = out
            for key in keys[:-1]:
                node = node.setdefault(key, {})
            grid = [1] * len(root) if "layer" in name or "middle" in name else [8 if name[0] in "XY" else 16, 1]
            node.setdefault(keys[-1], []).append(cover(root, box.evaluator(method), sign, grid, k0=k0,
                                                       outside=outside))
        if progress is not None:
            progress(f"sigma box {i + 1}/{hints.sigma_boxes}")
    return out


#: the hints of a ``dart:>=K0`` record (docs/tagged_c1.md, "A plan for every dart K >= 101", the scripts' values)
DART_HINTS = {"sigma": ("4.484", "4.4935"), "sigma_h": 16, "circle": "5.4", "mode0_h": 16, "tau1": "50", "v0": "0.4",
              "taylor": {"r": "0.03125", "disc_grid": 12, "sigma_boxes": 10, "order": 12, "layer_order": 14,
                         "exp_order": 24},
              "regions": {"s0": "1/20", "layer": 3, "winding": ["1/4", "7/20"]}}


def spectrum_covers(k0, sig_r, tau1, v0, prec=128):
    """The trees of Re(1 - F) > 0 over the regions N, I, F (:mod:`ccproof.certify.verify.dart_spectrum`)."""
    from flint import ctx

    from ccproof.certify.verify.dart_spectrum import SpectralRegions, region_roots

    roots = region_roots(k0, tau1, v0)
    with ctx.workprec(prec):
        reg = SpectralRegions(sig_r, k0)
        return {name: cover(roots[name], fn, 1, [40, 4]) for name, fn in (("N", reg.n), ("I", reg.i), ("F", reg.f))}


def prove_dart_tail(name, prec=128, hints=None, progress=None):
    """The ``dart:>=K0`` "C1" record (docs/certificates.md): the hints and every cover, or None with the reason.

    The record is not verified here: ``ccproof certify`` re-checks the written file with the verifier.

    Parameters
    ----------
    name : str
        ``"dart:>=K0"``.
    prec : int
    hints : dict, optional
        :data:`DART_HINTS` by default.
    progress : callable (str) -> None, optional

    Returns
    -------
    (dict or None, str)
    """
    from ccproof.certify.verify import TAGGED_SCHEMA
    from ccproof.certify.verify.dart_tail import TaylorHints
    from ccproof.certify.verify.replay import parse_decimal
    from ccproof.certify.verify.tagged import parse_configuration

    fam, n = parse_configuration(name)
    if fam != "dart" or not isinstance(n, dict):
        return None, f"undecided: {name}: not dart:>=K0"
    k0 = n["min"]
    hn = dict(DART_HINTS if hints is None else hints)
    t = hn["taylor"]
    th = TaylorHints(parse_decimal(t["r"]), t["disc_grid"], t["sigma_boxes"], t["order"], t["layer_order"],
                     t["exp_order"])
    rg = hn["regions"]

    def frac(s):
        a, b = s.split("/")
        return fmpq(int(a), int(b))
    sig_lo, sig_hi = (parse_decimal(s) for s in hn["sigma"])
    try:
        re = spectrum_covers(k0, parse_decimal(hn["circle"]), parse_decimal(hn["tau1"]), parse_decimal(hn["v0"]), prec)
        if progress is not None:
            progress("spectrum: regions N, I, F covered")
        parts = map_covers(k0, sig_lo, sig_hi, th, frac(rg["s0"]), rg["layer"], tuple(frac(s) for s in rg["winding"]),
                           prec=prec, progress=progress)
    except (ValueError, ZeroDivisionError, CertificateError) as exc:
        return None, f"undecided: {name}: {exc}"
    cert = {"schema": TAGGED_SCHEMA, "configuration": name, "statement": "C1", "prec": prec,
            "map": {"orientation": 1},
            "spectrum": {"sigma": list(hn["sigma"]), "sigma_h": hn["sigma_h"], "circle": hn["circle"],
                         "mode0_h": hn["mode0_h"], "tau1": hn["tau1"], "v0": hn["v0"], "re": re},
            "taylor": dict(t), "regions": {"s0": rg["s0"], "layer": rg["layer"], "winding": list(rg["winding"])},
            "parts": parts}
    leaves = sum(len(tr["leaves"]) for tr in re.values())
    return cert, (f"C1 for every K >= {k0} (spectral trees {leaves} leaves; map covers for {t['sigma_boxes']} "
                  "sigma boxes)")
