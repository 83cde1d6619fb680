"""The models R, T and W of a ``dart:>=K0`` record, and the replay of its map trees (trusted).

The quantities (docs/tagged_c1.md, "A plan for every dart K >= 101", item 6): R, det J_Phi of the family's
nets; T, a1 X Y' - a2 Y X' along the four outer curves (a_i = -ln lam_i); W, the signs of X and Y on the
outer curves' Bezier points that, with T, make the outer curve cross {Y = 0, X > 0} exactly once
("Winding"). Each lives on three regions of quadrants q ("Dividing by h exactly"): the bulk s = q/K in
[s0, 1/2], the middle (a function of s and w = 1/q) and the layer quadrants 0..T-1. In the bulk and the
middle every quantity is sum_k c_k e^(i omega_k s) f_k(h), f_k a column of basis parts (X+-, Y0, Y+-, or
their products for R and T); on the layer quadrants it is one column.

:func:`quantities` is the one table of every quantity's Taylor coefficients in h (acb_series arithmetic) or
values (at an acb box h), keyed (quantity, ..., piece or curve). :class:`DartModels` bounds every entry on
the complex h-square once, for the whole sigma bracket (:func:`~ccproof.rigorous.analytic.disc_bound`: one
family per acb box); :class:`SigmaBox` holds, per sigma box, one :class:`~ccproof.rigorous.analytic.
AnalyticModel` per (quantity, piece or curve) (:func:`group_models`) and one evaluator for every quantity and
region (:meth:`SigmaBox.evaluate`); the coefficients that vanish exactly (:mod:`.dart_zeros`) are dropped.
:func:`read_map` reads the record's trees against the roots their regions fix (:func:`.replay.read_tree`),
before any arithmetic; :func:`replay_map` replays them sigma box by sigma box (:func:`.replay.replay_tree`).
"""

from __future__ import annotations

from flint import acb, acb_mat, acb_series, arb, ctx, fmpq

from ccproof.rigorous.analytic import AnalyticModel, ball, cauchy_factor, disc_bound, hull

from .dart_family import (
    PIECES,
    XB,
    YB,
    Family,
    basis_nets,
    curve_trans_series,
    det_series,
    layer_nets,
    packed_partials,
    series_coeffs,
    series_curves,
    series_variable,
)
from .errors import CertificateError
from .maps import STAR_CURVES
from .record import exact_keys
from .replay import read_tree, replay_tree

#: quantity -> (the exact zeros below h^low in the bulk; the middle's (m0, q) of :func:`middle_box`, None: X has
#: no middle; the layer's low order): R and T vanish at h = 0, to order 3 on the layer quadrants; Y to order 1
QUANTITIES = {"R": (1, (1, 2), 3), "T": (1, (1, 2), 3), "X": (0, None, None), "Y": (0, (0, 1), 1)}


def coefficient_nets(net, n, real=False):
    """[the 4 x 4 net of the h^m Taylor coefficients (acb), m = 0..n] of a net of series or of values
    (``real``: as :func:`.dart_family.series_coeffs`)."""
    cs = [[series_coeffs(z, n + 1, real) for z in row] for row in net]
    return [[[c[m] for c in row] for row in cs] for m in range(n + 1)]


def _log_coeffs(fam, n, real=False):
    """The Taylor coefficients of (a1, a2) = (-ln lam1, -ln lam2) (at an acb h, the values: ZeroDivisionError
    unless certainly off the branch cut)."""
    if isinstance(fam.lam1, acb) and not (acb(fam.lam1).real > 0 and acb(fam.lam2).real > 0):
        raise ZeroDivisionError("log lam: not certainly off the branch cut")
    return [series_coeffs(-lam.log(), n + 1, real) for lam in (fam.lam1, fam.lam2)]


def quantities(fam, n, layers=(), bulk=True):
    """{key: [coefficient list of h^m, m = 0..n]} of every quantity, from one family (of the series variable;
    at an acb h with n = 0, the values there): in the bulk ("R", i, j, piece) the 36 Bernstein coefficients of
    D(X_i, Y_j) = X_i,u Y_j,v - X_i,v Y_j,u, ("T", i, j, curve) the 6 of a1 X_i Y_j' - a2 Y_j X_i' (T_ij(0) = 0
    exactly: a1 = a2, both parts multiples of one real curve at h = 0), ("X", i, curve), ("Y", j, curve) the
    4 Bezier points; on each layer quadrant q in ``layers`` ("R", q, piece), ("T", q, curve), ("Y", q, curve)
    of x, y themselves (for a series: the real parts, the nets being real for real h)."""
    out = {}
    if bulk:
        nets = basis_nets(fam)
        parts = {(b, p): packed_partials(coefficient_nets(net, n)) for b, pn in nets.items() for p, net in pn.items()}
        curves = {b: series_curves(nets[b], n) for b in nets}
        A = _log_coeffs(fam, n)
        for i in XB:
            for j in YB:
                out.update({("R", i, j, p): det_series(parts[(i, p)], parts[(j, p)], n) for p in PIECES})
                out.update({("T", i, j, c): curve_trans_series(curves[i][c], curves[j][c], *A, n)
                            for c in STAR_CURVES})
        out.update({(t, b, c): curves[b][c] for t, bs in (("X", XB), ("Y", YB)) for b in bs for c in STAR_CURVES})
    real = isinstance(fam.h, acb_series)
    A = _log_coeffs(fam, n, real) if layers else None
    for q in layers:
        ln = layer_nets(fam, q)
        out.update({("R", q, p): det_series(coefficient_nets(X, n, real), coefficient_nets(Y, n, real), n)
                    for p, (X, Y) in ln.items()})
        xs, ys = (series_curves({p: ln[p][k] for p in PIECES}, n, real) for k in (0, 1))
        out.update({("T", q, c): curve_trans_series(xs[c], ys[c], *A, n) for c in STAR_CURVES})
        out.update({("Y", q, c): ys[c] for c in STAR_CURVES})
    return out


def group_models(Q, M, r, quantity, q=None):
    """{piece or curve: AnalyticModel} of one quantity of a :func:`quantities` table ``Q`` with the disc bounds
    ``M`` (the same keys): the entries of one piece or curve (the key's last item) are the columns, in the
    table's order (i j in XB x YB, or the basis parts), their coefficient lists the rows; ``q``: the layer
    quadrant's entries (one column each)."""
    groups = {}
    for key in Q:
        if key[0] == quantity and (isinstance(key[1], str) if q is None else key[1] == q):
            groups.setdefault(key[-1], []).append(key)
    return {g: AnalyticModel.from_columns([Q[k] for k in keys], [M[k] for k in keys], r) for g, keys in groups.items()}


def omegas(quantity, sigma):
    """[(c_k, omega_k)] (acb, arb) of the bulk's columns of a quantity, the weights c_k e^(i omega_k s):
    E^(+-1) (E = e^(2 pi i s)) for X; 1, F, 1/F (F = e^(i sigma (2 s - 1))) for Y; their products (in the order
    XB x YB) for R and T."""
    tp, es = 2 * arb.pi(), acb(0, sigma).exp()
    x = [(acb(1), tp), (acb(1), -tp)]
    y = [(acb(1), arb(0)), (1 / es, 2 * sigma), (es, -2 * sigma)]
    return {"X": x, "Y": y}.get(quantity) or [(c, a + w) for _, a in x for c, w in y]


def mode_factors(quantity, s, sigma):
    """The bulk's weights c_k e^(i omega_k s) of :func:`omegas` at s (arb), formed as E = e^(2 pi i s) and
    F = e^(i sigma (2 s - 1)) (one ball each: sigma's width enters F once)."""
    E, F = acb(0, 2 * arb.pi() * s).exp(), acb(0, sigma * (2 * s - 1)).exp()
    x, y = [E, 1 / E], [acb(1), F, 1 / F]
    return {"X": x, "Y": y}.get(quantity) or [a * b for a in x for b in y]


def bulk_box(models, quantity, s_lo, s_hi, h_lo, h_hi, sigma):
    """An arb holding Re sum_k c_k e^(i omega_k s) f_k(h)/h^low (:func:`mode_factors`; every row of every model
    of the quantity, low of :data:`QUANTITIES`) for s in [s_lo, s_hi], h in [h_lo, h_hi] (a bulk quadrant)."""
    weights = mode_factors(quantity, ball(s_lo, s_hi), sigma)
    low = QUANTITIES[quantity][0]
    return hull(v for model in models.values() for v in model.real_part(weights, h_lo, h_hi, low=low))


def layer_box(models, quantity, q, h_lo, h_hi):
    """An arb holding f(h)/h^low on layer quadrant q (every row of every one-column model of the quantity, low
    of :data:`QUANTITIES`), h in [h_lo, h_hi]; for Y at ray 0's end point of quadrant 0 (curve P1s1, point 0)
    f(h)/h^2: x, hence y's first order, vanishes there."""
    vals = []
    for g, model in models.items():
        v = model.real_part([1], h_lo, h_hi, low=QUANTITIES[quantity][2])
        if quantity == "Y" and q == 0 and g == "P1s1":
            v[0] = model.real_part([1], h_lo, h_hi, low=2)[0]
        vals += v
    return hull(vals)


def middle_coeffs(model, om, m0, q, L=24):
    """{(m, l): e_ml = D_m (c_k (i omega_k)^l/l!)_k} (acb_mat, a row per value) for m0 <= m < m0 + q and
    l <= L: the coefficient of s^l h^m in F = sum_k c_k e^(i omega_k s) sum_m D_km h^m (``om``: the (c_k,
    omega_k) of the model's columns, |c_k| = 1)."""
    return {(m, l): model.coeffs[m] * acb_mat([[c * acb(0, w) ** l / arb.fac_ui(l)] for c, w in om])
            for m in range(m0, m0 + q) for l in range(L + 1)}


def middle_box(models, E, om, s_lo, s_hi, w_lo, w_hi, m0, q, L=24):
    """An arb holding Re F/(h^m0 s^q) (F of :func:`middle_coeffs`, every model's rows) on s in [s_lo, s_hi],
    w = h/s in [w_lo, w_hi], s_lo >= 0, where F's coefficients of h^m s^l with l + m - m0 < q are 0 exactly:
    the orders m < m0 + q expanded in s, sum_l e_ml s^(l + m - m0 - q) w^(m - m0), the tails of those
    exponential series (|omega s|^l/l! summed past L: at most z^(L+1)/(L+1)!/(1 - z/(L + 2)), z = |omega| s)
    and the rest direct, (c e^(i omega s) . D_m) s^(m - m0 - q) w^(m - m0), with the Cauchy remainder
    sum_k M_k s^(n+1-m0-q) w^(n+1-m0)/(r^(n+1) (1 - h/r)). K det J_Phi/s^2 is m0 = 1, q = 2; Y/s is m0 = 0,
    q = 1 (at the current precision)."""
    s, w = acb(ball(s_lo, s_hi)), acb(ball(w_lo, w_hi))
    wmax = max((abs(x[1]).upper() for x in om), key=lambda x: x)
    z, sh, wh = wmax * arb(fmpq(s_hi)), arb(fmpq(s_hi)), arb(fmpq(w_hi))
    if not z < L + 2:
        raise ValueError("s too large for the exponential series")
    geo = 1 / (arb.fac_ui(L + 1) * (1 - z / (L + 2)))
    ab = acb_mat([[c * (w_ * s * acb(0, 1)).exp()] for c, w_ in om])
    vals = []
    for key, model in models.items():
        n, D = model.order, model.coeffs
        rad = sum(model.M, arb(0)) * sh ** (n + 1 - m0 - q) * wh ** (n + 1 - m0) * cauchy_factor(
            model.r, n, fmpq(s_hi) * fmpq(w_hi))
        g = None
        for j in range(q):
            e = E[key]
            dmax = max((abs(D[m0 + j][c, k]).upper() for c in range(D[m0 + j].nrows()) for k in range(len(om))),
                       key=lambda x: x)
            rad += len(om) * dmax * wh ** j * wmax ** (q - j) * z ** (L + 1 + j - q) * geo
            acc = e[(m0 + j, L)]
            for l in range(L - 1, q - j - 1, -1):
                acc = acc * s + e[(m0 + j, l)]
            g = acc * w ** j if g is None else g + acc * w ** j
        for m in range(m0 + q, n + 1):
            g = g + (D[m] * ab) * (s ** (m - m0 - q) * w ** (m - m0))
        vals += [g[c, 0].real + arb(0, rad.upper()) for c in range(g.nrows())]
    return hull(vals)


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
    """The analytic models of R, T and W on one sigma box, and their evaluators (module docstring): one series
    family for the bulk (order ``hints.order``), one for the layer quadrants (``hints.layer_order``)."""

    def __init__(self, models, i):
        self.m, hn, r = models, models.hints, models.hints.r
        with ctx.workprec(models.prec):
            self.sigma = sigma = ball(models.edges[i], models.edges[i + 1])
            with series_variable(hn.order) as h:
                Q = quantities(Family(h, sigma), hn.order)
            with series_variable(hn.layer_order) as h:
                Q.update(quantities(Family(h, sigma), hn.layer_order, range(models.layer), bulk=False))
            self.om = {t: omegas(t, sigma) for t in QUANTITIES}
            self.models = {(t, None): group_models(Q, models.M, r, t) for t in QUANTITIES}
            self.models.update({(t, q): group_models(Q, models.M, r, t, q) for t in "RTY" for q in range(models.layer)})
            self.E = {t: {g: middle_coeffs(m, self.om[t], *mid, L=hn.exp_order)
                          for g, m in self.models[(t, None)].items()} for t, (_, mid, _) in QUANTITIES.items() if mid}

    def evaluator(self, method):
        """The evaluator (box) -> arb that :func:`map_regions` names: method = (quantity, region, layer
        quadrant or None); see :meth:`evaluate`."""
        return lambda box: self.evaluate(*method[:2], box, method[2])

    def evaluate(self, quantity, region, box, q=None):
        """One arb holding the quantity's scaled values (every row of every model) on a box (a list of (lo, hi)
        fmpq) of its region, the coefficients below h^low dropped (:data:`QUANTITIES`: 0 exactly):

        ========  ===========================  ===================================  ================================
        quantity  bulk (s, h)                  middle (s, w = 1/q)                  layer quadrant q (h)
        ========  ===========================  ===================================  ================================
        R         K det J_Phi                  K^3 det J_Phi/q^2                    K^3 det J_Phi
        T         K (a1 X Y' - a2 Y X')        K^3 (a1 X Y' - a2 Y X')/q^2          K^3 (a1 X Y' - a2 Y X')
        X, Y      X, Y on the Bezier points    Y/s on the Bezier points             K Y (K^2 Y at ray 0's end)
        ========  ===========================  ===================================  ================================

        (:func:`bulk_box`, :func:`middle_box`, :func:`layer_box`).
        """
        mid = QUANTITIES[quantity][1]
        models = self.models[(quantity, q if region == "layer" else None)]
        with ctx.workprec(self.m.prec):
            if region == "layer":
                return layer_box(models, quantity, q, *box[0])
            (s_lo, s_hi), (t_lo, t_hi) = box
            if region == "middle":
                return middle_box(models, self.E[quantity], self.om[quantity], s_lo, s_hi, t_lo, t_hi, *mid,
                                  L=self.m.hints.exp_order)
            return bulk_box(models, quantity, s_lo, s_hi, t_lo, t_hi, self.sigma)


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
