"""The models R, T and W of a ``dart:>=K0`` record are replayed on, and the replay of its map trees (trusted).

:class:`DartModels` bounds every quantity of :mod:`.dart_regularity` (R) and :mod:`.dart_curves` (T, W) on
the complex h-square once, for the whole sigma bracket: one family per acb box, every quantity read off it
(:func:`~ccproof.rigorous.analytic.disc_bound`). :class:`SigmaBox` holds the Taylor coefficients on one sigma
box (one series family for the bulk, one for the layer quadrants) as analytic models; each evaluator returns
one arb containing every value of its region's scaled quantity on a box (a list of (lo, hi) fmpq).
:func:`read_map` reads the record's trees against the roots their regions fix (:func:`.replay.read_tree`),
before any arithmetic; :func:`replay_map` replays them sigma box by sigma box (:func:`.replay.replay_tree`).
"""

from __future__ import annotations

from flint import acb_series, ctx, fmpq

from ccproof.rigorous.analytic import ball, disc_bound

from . import dart_curves as C
from . import dart_regularity as R
from .dart_family import XB, YB, Family, basis_nets, layer_nets, series_cap, series_curves, series_variable
from .errors import CertificateError
from .record import exact_keys
from .replay import read_tree, replay_tree


def quantities(fam, n, layers=(), bulk=True):
    """{key: [coefficient list of h^m, m = 0..n]} of every quantity the models bound, from one family (of the
    series variable; at an acb h with n = 0, the values there): ("R", i, j, piece) and ("T", i, j, curve) of
    :mod:`.dart_regularity` and :mod:`.dart_curves`, ("X", part, curve), ("Y", part, curve) the outer curves'
    points; ("RL", q, piece), ("TL", q, curve), ("YL", q, curve) on the layer quadrants q in ``layers``."""
    out = {}
    if bulk:
        nets = basis_nets(fam)
        out.update({("R",) + k: v for k, v in R.dets_series(nets, n).items()})
        out.update({("T",) + k: v for k, v in C.trans_series(fam, nets, n).items()})
        for tag, parts in (("X", XB), ("Y", YB)):
            out.update({(tag, b, c): pts for b in parts for c, pts in series_curves(nets[b], n).items()})
    real = isinstance(fam.h, acb_series)  # the layer's series: real coefficients (real nets for real h)
    for q in layers:
        ln = layer_nets(fam, q)
        out.update({("RL", q, p): v for p, v in R.layer_dets_series(ln, n, real).items()})
        out.update({("TL", q, c): v for c, v in C.layer_trans_series(fam, ln, n, real).items()})
        out.update({("YL", q, c): v for c, v in C.layer_y_series(ln, n, real).items()})
    return out


def select(table, tag, q=None):
    """The entries of one quantity of a :func:`quantities` table (or of its disc bounds), keyed without the
    tag ("R", "T", "X", "Y"), or without (tag, q) for "RL", "TL", "YL" on layer quadrant q."""
    if q is None:
        return {key[1:]: v for key, v in table.items() if key[0] == tag}
    return {key[2]: v for key, v in table.items() if key[:2] == (tag, q)}


class DartModels:
    """The disc bounds of R, T and W over the whole sigma bracket, and one :class:`SigmaBox` per sigma box.

    Parameters
    ----------
    sig_lo, sig_hi : fmpq
        The bracket of sigma(K) (shown by the spectrum and the eigenvector lemma).
    hints : TaylorHints
    layer : int
        T: the layer quadrants are 0..T-1.
    prec : int

    Examples
    --------
    >>> from flint import fmpq
    >>> from ccproof.certify.verify.dart_family import TaylorHints
    >>> hints = TaylorHints(r=fmpq(1, 32), disc_grid=6, sigma_boxes=10, order=12, layer_order=14, exp_order=24)
    >>> box = DartModels(fmpq(4484, 1000), fmpq(44935, 10000), hints, 0, 128).sigma_box(0)
    >>> box.evaluate("R", "bulk", [(fmpq(1, 4), fmpq(26, 100)), (fmpq(0), fmpq(1, 101))]) > 0  # K det J_Phi, K >= 101
    True
    """

    def __init__(self, sig_lo, sig_hi, hints, layer, prec):
        self.hints, self.layer, self.prec = hints, layer, prec
        self.edges = [fmpq(sig_lo) + (fmpq(sig_hi) - fmpq(sig_lo)) * fmpq(i, hints.sigma_boxes)
                      for i in range(hints.sigma_boxes + 1)]
        with ctx.workprec(prec):
            sigma = ball(sig_lo, sig_hi)  # one family per acb box h, the values: the h^0 coefficients
            self.M = disc_bound(lambda h: {k: v[0] for k, v in quantities(Family(h, sigma), 0, range(layer)).items()},
                                hints.r, hints.disc_grid)
        self._boxes = {}

    def sigma_box(self, i):
        """The models on sigma box i of ``hints.sigma_boxes`` equal boxes of the bracket (cached)."""
        if not 0 <= i < self.hints.sigma_boxes:
            raise IndexError(f"sigma box {i} of {self.hints.sigma_boxes}")
        if i not in self._boxes:
            self._boxes[i] = SigmaBox(self, i)
        return self._boxes[i]


class SigmaBox:
    """The analytic models of R, T and W on one sigma box, and their evaluators (module docstring)."""

    def __init__(self, models, i):
        self.m, hn, prec, r = models, models.hints, models.prec, models.hints.r
        with ctx.workprec(prec):
            self.sigma = sigma = ball(models.edges[i], models.edges[i + 1])
            with series_cap(hn.order):
                Q = quantities(Family(series_variable(hn.order), sigma), hn.order)
            M = models.M
            self.R, self.T = (R.bulk_models(select(Q, t), select(M, t), r) for t in ("R", "T"))
            self.X, self.Y = (C.curve_models(select(Q, t), select(M, t), r, ps) for t, ps in (("X", XB), ("Y", YB)))
            self.om, self.omy = R.omegas(sigma), R.y_omegas(sigma)
            self.ER = {p: R.middle_coeffs(m, self.om, 1, 2, L=hn.exp_order) for p, m in self.R.items()}
            self.ET = {p: R.middle_coeffs(m, self.om, 1, 2, L=hn.exp_order) for p, m in self.T.items()}
            self.EY = {c: R.middle_coeffs(m, self.omy, 0, 1, L=hn.exp_order) for c, m in self.Y.items()}
            self._layers(hn.layer_order, r)

    def _layers(self, n, r):
        with series_cap(n):
            Q = quantities(Family(series_variable(n), self.sigma), n, range(self.m.layer), bulk=False)
        self.L = {q: tuple(R.column_models(select(Q, t, q), select(self.m.M, t, q), r) for t in ("RL", "TL", "YL"))
                  for q in range(self.m.layer)}

    def evaluator(self, method):
        """The evaluator (box) -> arb that :func:`map_regions` names: method = (quantity, region, layer
        quadrant or None); see :meth:`evaluate`."""
        return lambda box: self.evaluate(*method[:2], box, method[2])

    def evaluate(self, quantity, region, box, q=None):
        """One arb holding the quantity's scaled values on a box (a list of (lo, hi) fmpq) of its region:

        ========  ===========================  ===================================  ================================
        quantity  bulk (s, h)                  middle (s, w = 1/q)                  layer quadrant q (h)
        ========  ===========================  ===================================  ================================
        R         K det J_Phi                  K^3 det J_Phi/q^2                    K^3 det J_Phi
        T         K (a1 X Y' - a2 Y X')        K^3 (a1 X Y' - a2 Y X')/q^2          K^3 (a1 X Y' - a2 Y X')
        X, Y      X, Y on the Bezier points    Y/s on the Bezier points             K Y (K^2 Y at ray 0's end)
        ========  ===========================  ===================================  ================================
        """
        prec = self.m.prec
        if region == "layer":
            ((h_lo, h_hi),) = box
            models = self.L[q]["RTY".index(quantity)]
            if quantity == "Y":
                return C.layer_y_box(models, q, h_lo, h_hi, prec=prec)
            return R.layer_box(models, h_lo, h_hi, prec=prec)
        (s_lo, s_hi), (t_lo, t_hi) = box
        if region == "middle":
            models, E, om, m0, order = {"R": (self.R, self.ER, self.om, 1, 2), "T": (self.T, self.ET, self.om, 1, 2),
                                        "Y": (self.Y, self.EY, self.omy, 0, 1)}[quantity]
            return R.middle_box(models, E, om, s_lo, s_hi, t_lo, t_hi, m0, order, L=self.m.hints.exp_order, prec=prec)
        if quantity in "RT":
            return R.kdet_box(getattr(self, quantity), s_lo, s_hi, t_lo, t_hi, self.sigma, prec=prec)
        return C.coord_box(getattr(self, quantity), s_lo, s_hi, t_lo, t_hi, self.sigma, quantity.lower(), prec=prec)


def map_regions(k0, s0, layer, winding):
    """Every tree list of a record's ``parts``: (name, keys into ``parts``, root box, (quantity, region, layer
    quadrant) of :meth:`SigmaBox.evaluate`, sign of the claim, ``outside`` leaves allowed); the roots are fixed by
    K0 and the regions, never by the file. The prover covers the same lists.

    >>> [r[:2] for r in map_regions(101, fmpq(1, 20), 3, (fmpq(1, 4), fmpq(7, 20)))][-1]
    ('Y<0 layer 2', ('winding', 'Y<0 layer', '2'))
    """
    s_a, s_b = winding
    half, h0 = fmpq(1, 2), fmpq(1, k0)
    bulk, middle = [(s0, half), (fmpq(0), h0)], [(fmpq(0), s0), (fmpq(0), fmpq(1, layer))]
    out = [("R bulk", ("regularity", "bulk"), bulk, ("R", "bulk", None), 1, False),
           ("R middle", ("regularity", "middle"), middle, ("R", "middle", None), 1, True),
           ("T bulk", ("transversal", "bulk"), bulk, ("T", "bulk", None), 1, False),
           ("T middle", ("transversal", "middle"), middle, ("T", "middle", None), 1, True),
           ("Y<0 bulk", ("winding", "Y<0 bulk"), [(s0, s_a), (fmpq(0), h0)], ("Y", "bulk", None), -1, False),
           ("X>0 bulk", ("winding", "X>0 bulk"), [(s_a, s_b), (fmpq(0), h0)], ("X", "bulk", None), 1, False),
           ("Y>0 bulk", ("winding", "Y>0 bulk"), [(s_b, half), (fmpq(0), h0)], ("Y", "bulk", None), 1, False),
           ("Y<0 middle", ("winding", "Y<0 middle"), middle, ("Y", "middle", None), -1, True)]
    for q in range(layer):
        out += [(f"R layer {q}", ("regularity", "layer", str(q)), [(fmpq(0), h0)], ("R", "layer", q), 1, False),
                (f"T layer {q}", ("transversal", "layer", str(q)), [(fmpq(0), h0)], ("T", "layer", q), 1, False),
                (f"Y<0 layer {q}", ("winding", "Y<0 layer", str(q)), [(fmpq(0), h0)], ("Y", "layer", q), -1, False)]
    return out


def _check_keys(obj, regions, where, depth=0):
    """Exactly the keys that ``regions`` (:func:`map_regions`) name at this depth, recursively."""
    keys = {r[1][depth] for r in regions}
    exact_keys(obj, tuple(sorted(keys)), where)
    for key in keys:
        inner = [r for r in regions if r[1][depth] == key and len(r[1]) > depth + 1]
        if inner:
            _check_keys(obj[key], inner, f"{where} {key}", depth + 1)


def read_map(parts, k0, hints, s0, layer, winding):
    """Step 1 for the map: every tree of R, T and W read against the root its region fixes, no arithmetic.

    Parameters
    ----------
    parts : object (parsed JSON)
        ``{"regularity": cover, "transversal": cover, "winding": signs}`` (docs/certificates.md).
    k0 : int
    hints : TaylorHints
    s0 : fmpq
        The bulk is s in [s0, 1/2]; the middle is (s, w) in [0, s0] x [0, 1/layer].
    layer : int
        T >= 3: the layer quadrants 0..T-1.
    winding : (fmpq, fmpq)
        (s_a, s_b), s0 < s_a < s_b < 1/2.

    Returns
    -------
    list of (name, evaluator name, sign, [leaves per sigma box])

    Raises
    ------
    CertificateError
        Naming the list and the leaf.

    Examples
    --------
    >>> from flint import fmpq
    >>> from ccproof.certify.verify.dart_family import TaylorHints
    >>> hints = TaylorHints(fmpq(1, 32), 12, 10, 12, 14, 24)
    >>> read_map({}, 101, hints, fmpq(1, 20), 3, (fmpq(1, 4), fmpq(7, 20)))
    Traceback (most recent call last):
    ...
    ccproof.certify.verify.errors.CertificateError: parts: ...
    """
    s_a, s_b = winding
    if not (0 < s0 < s_a < s_b < fmpq(1, 2) and layer >= 3 and fmpq(1, k0) < hints.r and s0 / layer < hints.r):
        raise CertificateError("regions: need 0 < s0 < s_a < s_b < 1/2, T >= 3, 1/K0 < r and s0/T < r")
    regions = map_regions(k0, s0, layer, winding)
    _check_keys(parts, regions, "parts")
    out = []
    for name, keys, root, method, sign, outside in regions:
        trees = parts
        for key in keys:
            trees = trees[key]
        if not isinstance(trees, list) or len(trees) != hints.sigma_boxes:
            raise CertificateError(f"{name}: one tree per sigma box ({hints.sigma_boxes}) is needed")
        out.append((name, method, sign, [read_tree(t, root, f"{name}, sigma box {i}", sign, k0=k0, outside=outside)
                                         for i, t in enumerate(trees)]))
    return out


def replay_map(lists, sig_lo, sig_hi, hints, layer, prec):
    """Step 6 of a ``dart:>=K0`` record: the lists of :func:`read_map` replayed on the trusted models, sigma
    box by sigma box; {list name: (leaves evaluated, least bound)}. Raises CertificateError naming the leaf."""
    models = DartModels(sig_lo, sig_hi, hints, layer, prec)
    summary = {}
    for i in range(hints.sigma_boxes):
        box = models.sigma_box(i)
        for name, method, sign, leaves in lists:
            count, least = replay_tree(leaves[i], box.evaluator(method), sign, f"{name}, sigma box {i}")
            old = summary.get(name, (0, None))
            best = least if old[1] is None or (least is not None and abs(least) < abs(old[1])) else old[1]
            summary[name] = (old[0] + count, best)
    return summary
