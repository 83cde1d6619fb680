"""Every ``dart:K``, K >= K0, in one "C1" certificate (trusted): the record read and priced before any arithmetic,
then the steps S, Z, G, E, M (docs/certificates.md, "Every dart K >= K0 in one certificate"; docs/tagged_c1.md,
"Every dart K >= 101", items 6 to 8). R (det J_Phi), T (a1 X Y' - a2 Y X' on the outer curves) and W (signs of X,
Y on their points) live on the bulk (s, h), the middle (s, w = 1/q) and the layer quadrants q (h); the bulk and
middle are sum_k c_k e^(i omega_k s) f_k(h) over the basis parts (:func:`omegas`), each f_k an analytic model."""

from __future__ import annotations

from collections import namedtuple
from functools import reduce
from itertools import product

from flint import acb, acb_mat, acb_series, arb, ctx, fmpq

from ccproof.rigorous.analytic import AnalyticModel, ball, cauchy_factor, disc_bound, disc_boxes, hull

from . import dart_family as df
from . import dart_spectrum as ds
from .dart_zeros import check_zeros
from .errors import CertificateError
from .maps import STAR_CURVES
from .record import field_of
from .replay import MAX_BOXES, read_tree, replay_tree
from .tagged import DECIMAL, FRACTION, read_fields

MIN_K0 = 101  # the regions need 1/K0 < r, and the covers are shown from 101 on
MAX_WORK = 100_000  # units of 0.1 ms of CPU (:func:`record_work`): 10 s; the published record declares 8.6 s
MAX_BALLS = 8192
#: the record's fields (:func:`.tagged.read_fields`): a dict of fields (exactly those keys), a list (that many items),
#: (lo, hi) an int in lo..hi, a decimal string, a fraction 'INT/INT', or a type (read by the step that needs it)
GRAMMAR = {
    "schema": str, "configuration": str, "statement": str, "prec": (64, 1024), "map": {"orientation": int},
    "spectrum": {"sigma": [DECIMAL, DECIMAL], "sigma_h": (1, MAX_BALLS), "circle": DECIMAL, "mode0_h": (1, MAX_BALLS),
                 "tau1": DECIMAL, "v0": DECIMAL, "re": {"N": dict, "I": dict, "F": dict}},
    "taylor": {"r": DECIMAL, "disc_grid": (1, 64), "sigma_boxes": (1, 256), "order": (3, 24), "layer_order": (3, 24),
               "exp_order": (2, 64)},
    "regions": {"s0": FRACTION, "layer": (3, 64), "winding": [FRACTION, FRACTION]},
    "parts": dict,
}
#: quantity -> (the exact zeros below h^low in the bulk; the middle's (m0, q) of :func:`middle_box`, None: X has
#: no middle; the layer's low order): R and T vanish at h = 0, to order 3 on the layer quadrants; Y to order 1
QUANTITIES = {"R": (1, (1, 2), 3), "T": (1, (1, 2), 3), "X": (0, None, None), "Y": (0, (0, 1), 1)}


#: the record's ``taylor`` hints (they only choose): the Cauchy radius r (the h-square [-r, r]^2), its grid, the
#: sigma boxes, the Taylor orders in h (bulk and middle; layer) and the middle's order in s
TaylorHints = namedtuple("TaylorHints", "r disc_grid sigma_boxes order layer_order exp_order")


def read_record(cert, k0):
    """Step 1: the record's fields (the spectrum's keys, prec, hints, layer; re and map as read trees), its leaves
    and work (:func:`record_work`) within the budget; CertificateError naming the field, before any arithmetic."""
    if not MIN_K0 <= k0 <= 10**6:
        raise CertificateError(f"dart:>={k0}: the interval certificate needs {MIN_K0} <= K0 <= 10^6")
    if field_of(cert, "statement", str, "certificate") != "C1":
        raise CertificateError("dart:>=K0 is certified \"C1\" only (its statement is fixed by the configuration)")
    g = read_fields(cert, GRAMMAR, "certificate")
    sp, rg, hints = g["spectrum"], g["regions"], TaylorHints(**g["taylor"])
    if g["map"]["orientation"] != 1:
        raise CertificateError("map: the statement fixes orientation +1 (x sine-like, y = 1 at ray K/2)")
    ds.check_ranges(k0, *sp["sigma"], sp["circle"], sp["tau1"], sp["v0"])
    if not fmpq(1, k0) < hints.r <= fmpq(1, 8):
        raise CertificateError("taylor: need 1/K0 < r <= 1/8")
    roots = ds.region_roots(k0, sp["tau1"], sp["v0"])
    rec = dict(sp, prec=g["prec"], hints=hints, layer=rg["layer"],
               re={n: read_tree(sp["re"][n], roots[n], f"spectrum re {n}", 1) for n in "NIF"})
    rec["map"] = read_map(g["parts"], k0, hints, rg["s0"], rg["layer"], tuple(rg["winding"]))
    leaves = sum(len(t) for *_, trees in rec["map"] for t in trees) + sum(len(v) for v in rec["re"].values())
    if leaves > MAX_BOXES:
        raise CertificateError(f"more than {MAX_BOXES} leaves in all ({leaves})")
    if (work := record_work(rec)) > MAX_WORK:
        raise CertificateError(f"the record declares about {work // 10000} s of work ({work:,} units of 0.1 ms: "
                               f"disc grid, sigma boxes, orders, leaves, prec), beyond the budget of "
                               f"{MAX_WORK // 10000} s (docs/certificates.md, \"Bounds\")")
    return rec


def record_work(rec):
    """The CPU work the record's sizes declare, in units of 0.1 ms, priced per quantity and region from
    measurements (docs/certificates.md, "Bounds").

    >>> import json
    >>> from ccproof.tables.format import certificates_dir
    >>> rec = read_record(json.loads((certificates_dir() / "c1/dart/k_ge_101.json").read_text()), 101)
    >>> record_work(rec), MAX_WORK
    (86238, 100000)
    """
    hn, layer = rec["hints"], rec["layer"]
    work = 16000 + len(list(disc_boxes(hn.r, hn.disc_grid))) * (60 + 18 * layer)
    work += hn.sigma_boxes * (11 * hn.order ** 2 + 13 * layer * hn.layer_order ** 2 // 10)
    mid = hn.exp_order + hn.order
    per_leaf = {("R", "bulk"): hn.order, ("R", "middle"): 45 * mid // 100 + 1, ("R", "layer"): hn.layer_order // 3 + 1,
                ("", "bulk"): hn.order // 3 + 1, ("", "middle"): mid // 5 + 1, ("", "layer"): hn.layer_order // 3 + 1}
    for _, (quantity, region, _), _, trees in rec["map"]:
        work += per_leaf[("R" if quantity == "R" else "", region)] * sum(len(t) for t in trees)
    work += 2 * sum(len(v) for v in rec["re"].values()) + 15 * rec["sigma_h"] + rec["mode0_h"]
    return work * ((rec["prec"] + 127) // 128)


def _log_coeffs(fam, n, real=False):
    """The Taylor coefficients of (a1, a2) = (-ln lam1, -ln lam2) (ZeroDivisionError near the branch cut)."""
    if isinstance(fam.lam1, acb) and not (acb(fam.lam1).real > 0 and acb(fam.lam2).real > 0):
        raise ZeroDivisionError("log lam: not certainly off the branch cut")
    return [df.series_coeffs(-lam.log(), n + 1, real) for lam in (fam.lam1, fam.lam2)]


def quantities(fam, n, layers=(), bulk=True):
    """{key: [h^m coefficient lists, m <= n]} of every quantity of a family (at an acb h, n = 0: the values):
    bulk ("R", i, j, piece) D(X_i, Y_j)'s 36 Bernstein coefficients, ("T", i, j, curve) a1 X_i Y_j' - a2 Y_j X_i''s
    6, ("X", i, curve), ("Y", j, curve) the 4 points; layer quadrant q ("R"/"T"/"Y", q, piece or curve)."""
    out = {}

    def pair(key, part_x, part_y, curve_x, curve_y, A):
        out.update({("R", *key, p): df.det_series(part_x[p], part_y[p], n) for p in df.PIECES})
        out.update({("T", *key, c): df.curve_trans_series(curve_x[c], curve_y[c], *A, n) for c in STAR_CURVES})
    if bulk:
        nets, A = df.basis_nets(fam), _log_coeffs(fam, n)
        parts = {b: {p: df.packed_partials(df.coefficient_nets(net, n)) for p, net in pn.items()}
                 for b, pn in nets.items()}
        curves = {b: df.series_curves(nets[b], n) for b in nets}
        for i, j in product(df.XB, df.YB):
            pair((i, j), parts[i], parts[j], curves[i], curves[j], A)
        out.update({(t, b, c): curves[b][c] for t, bs in (("X", df.XB), ("Y", df.YB)) for b in bs for c in STAR_CURVES})
    real = isinstance(fam.h, acb_series)
    A = _log_coeffs(fam, n, real) if layers else None
    for q in layers:
        nets = [fam.layer_nets(q, k) for k in (0, 1)]  # x, y
        (px, py), (cx, cy) = ([{p: df.coefficient_nets(N[p], n, real) for p in df.PIECES} for N in nets],
                              [df.series_curves(N, n, real) for N in nets])
        pair((q,), px, py, cx, cy, A)
        out.update({("Y", q, c): cy[c] for c in STAR_CURVES})
    return out


def group_models(Q, M, r, quantity, q=None):
    """{piece or curve: AnalyticModel} of one quantity of a :func:`quantities` table with disc bounds ``M``: the
    entries of one piece or curve are the columns (bulk, ``q`` None), or layer quadrant q's one column each."""
    groups = {}
    for key in Q:
        if key[0] == quantity and (isinstance(key[1], str) if q is None else key[1] == q):
            groups.setdefault(key[-1], []).append(key)
    return {g: AnalyticModel.from_columns([Q[k] for k in keys], [M[k] for k in keys], r) for g, keys in groups.items()}


def omegas(quantity, sigma):
    """[(c_k, omega_k)] of the bulk's columns, weights c_k e^(i omega_k s): E^(+-1), E = e^(2 pi i s), for X;
    1, F, 1/F, F = e^(i sigma (2 s - 1)), for Y; their products (XB x YB) for R and T."""
    tp, es = 2 * arb.pi(), acb(0, sigma).exp()
    x = [(acb(1), tp), (acb(1), -tp)]
    y = [(acb(1), arb(0)), (1 / es, 2 * sigma), (es, -2 * sigma)]
    return {"X": x, "Y": y}.get(quantity) or [(c, a + w) for _, a in x for c, w in y]


def mode_factors(quantity, s, sigma):
    """The weights of :func:`omegas` at s, formed from E and F (one ball each: sigma's width enters once)."""
    E, F = acb(0, 2 * arb.pi() * s).exp(), acb(0, sigma * (2 * s - 1)).exp()
    x, y = [E, 1 / E], [acb(1), F, 1 / F]
    return {"X": x, "Y": y}.get(quantity) or [a * b for a in x for b in y]


def bulk_box(models, quantity, s_lo, s_hi, h_lo, h_hi, sigma):
    """An arb holding Re sum_k c_k e^(i omega_k s) f_k(h)/h^low (every row of every model) on the (s, h) box."""
    weights, low = mode_factors(quantity, ball(s_lo, s_hi), sigma), QUANTITIES[quantity][0]
    return hull(v for model in models.values() for v in model.real_part(weights, h_lo, h_hi, low=low))


def layer_box(models, quantity, q, h_lo, h_hi):
    """An arb holding f(h)/h^low on layer quadrant q; Y at ray 0's end point (q = 0, P1s1, point 0) /h^2."""
    vals = []
    for g, model in models.items():
        v = model.real_part([1], h_lo, h_hi, low=QUANTITIES[quantity][2])
        if quantity == "Y" and q == 0 and g == "P1s1":
            v[0] = model.real_part([1], h_lo, h_hi, low=2)[0]
        vals += v
    return hull(vals)


def middle_coeffs(model, om, m0, q, L=24):
    """{(m, l): e_ml} (acb_mat): the coefficient of s^l h^m of sum_k c_k e^(i omega_k s) f_k(h), m0 <= m < m0 + q."""
    return {(m, l): model.coeffs[m] * acb_mat([[c * acb(0, w) ** l / arb.fac_ui(l)] for c, w in om])
            for m in range(m0, m0 + q) for l in range(L + 1)}


def middle_box(models, E, om, s_lo, s_hi, w_lo, w_hi, m0, q, L=24):
    """An arb holding Re F/(h^m0 s^q) on s in [s_lo, s_hi], w = h/s in [w_lo, w_hi] (F's s^l h^m with
    l + m - m0 < q being 0): orders m < m0 + q expanded in s (:func:`middle_coeffs`; the tail past L at most
    z^(L+1)/(L+1)!/(1 - z/(L + 2)), z = |omega| s), the rest direct, plus the Cauchy remainder
    sum_k M_k s^(n+1-m0-q) w^(n+1-m0)/(r^(n+1) (1 - h/r)); K det J_Phi/s^2: m0 = 1, q = 2; Y/s: m0 = 0, q = 1."""
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

    >>> hints = TaylorHints(r=fmpq(1, 32), disc_grid=6, sigma_boxes=10, order=12, layer_order=14, exp_order=24)
    >>> box = DartModels(fmpq(4484, 1000), fmpq(44935, 10000), hints, 0, 128).sigma_box(0)
    >>> box.evaluate("R", "bulk", [(fmpq(1, 4), fmpq(26, 100)), (fmpq(0), fmpq(1, 101))]) > 0  # K det J_Phi
    True
    """

    def __init__(self, sig_lo, sig_hi, hints, layer, prec):
        self.hints, self.layer, self.prec = hints, layer, prec
        self.edges = [fmpq(sig_lo) + (fmpq(sig_hi) - fmpq(sig_lo)) * fmpq(i, hints.sigma_boxes)
                      for i in range(hints.sigma_boxes + 1)]
        with ctx.workprec(prec):
            sigma, layers = ball(sig_lo, sig_hi), range(layer)  # one family per acb box h; the h^0 coefficients
            self.M = disc_bound(lambda h: {k: v[0] for k, v in quantities(df.Family(h, sigma), 0, layers).items()},
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
    """The analytic models of R, T and W on one sigma box (bulk order ``hints.order``, layer ``layer_order``)."""

    def __init__(self, models, i):
        self.m, hn, r = models, models.hints, models.hints.r
        with ctx.workprec(models.prec):
            self.sigma = sigma = ball(models.edges[i], models.edges[i + 1])
            with df.series_variable(hn.order) as h:
                Q = quantities(df.Family(h, sigma), hn.order)
            with df.series_variable(hn.layer_order) as h:
                Q.update(quantities(df.Family(h, sigma), hn.layer_order, range(models.layer), bulk=False))
            self.om = {t: omegas(t, sigma) for t in QUANTITIES}
            self.models = {(t, None): group_models(Q, models.M, r, t) for t in QUANTITIES}
            self.models.update({(t, q): group_models(Q, models.M, r, t, q) for t in "RTY" for q in range(models.layer)})
            self.E = {t: {g: middle_coeffs(m, self.om[t], *mid, L=hn.exp_order)
                          for g, m in self.models[(t, None)].items()} for t, (_, mid, _) in QUANTITIES.items() if mid}

    def evaluator(self, method):
        """(box) -> arb for method = (quantity, region, layer quadrant or None) of :func:`map_regions`."""
        return lambda box: self.evaluate(*method[:2], box, method[2])

    def evaluate(self, quantity, region, box, q=None):
        """An arb holding the quantity's scaled values on a box (list of (lo, hi)) of its region: bulk K det J_Phi,
        K T, X, Y; middle K^3 det J_Phi/q^2, K^3 T/q^2, Y/s; layer K^3 det J_Phi, K^3 T, K Y (K^2 Y at ray 0's end)."""
        models = self.models[(quantity, q if region == "layer" else None)]
        with ctx.workprec(self.m.prec):
            if region == "layer":
                return layer_box(models, quantity, q, *box[0])
            if region == "middle":
                return middle_box(models, self.E[quantity], self.om[quantity], *box[0], *box[1],
                                  *QUANTITIES[quantity][1], L=self.m.hints.exp_order)
            return bulk_box(models, quantity, *box[0], *box[1], self.sigma)


def map_regions(k0, s0, layer, winding):
    """Every tree list of ``parts``: (name, keys, root box, (quantity, region, layer quadrant), sign, ``outside``
    allowed); the roots are fixed by K0 and the regions, never by the file.

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


def read_map(parts, k0, hints, s0, layer, winding):
    """Step 1 for the map: [(name, method, sign, [leaves per sigma box])], every tree read against the root its
    region fixes (no arithmetic); CertificateError naming the list and the leaf.

    >>> read_map({}, 101, TaylorHints(fmpq(1, 32), 12, 10, 12, 14, 24), fmpq(1, 20), 3, (fmpq(1, 4), fmpq(7, 20)))
    Traceback (most recent call last):
    ...
    ccproof.certify.verify.errors.CertificateError: parts: ...
    """
    s_a, s_b = winding
    if not (0 < s0 < s_a < s_b < fmpq(1, 2) and layer >= 3 and fmpq(1, k0) < hints.r and s0 / layer < hints.r):
        raise CertificateError("regions: need 0 < s0 < s_a < s_b < 1/2, T >= 3, 1/K0 < r and s0/T < r")
    regions, spec = map_regions(k0, s0, layer, winding), {}
    for _, keys, *_ in regions:  # the grammar of parts: exactly the keys the regions name, a list at each end
        reduce(lambda node, key: node.setdefault(key, {}), keys[:-1], spec)[keys[-1]] = list
    parts, out = read_fields(parts, spec, "parts"), []
    for name, keys, root, method, sign, outside in regions:
        trees = reduce(dict.__getitem__, keys, parts)
        if len(trees) != hints.sigma_boxes:
            raise CertificateError(f"{name}: one tree per sigma box ({hints.sigma_boxes}) is needed")
        out.append((name, method, sign, [read_tree(t, root, f"{name}, sigma box {i}", sign, k0=k0, outside=outside)
                                         for i, t in enumerate(trees)]))
    return out


def replay_map(lists, sig_lo, sig_hi, hints, layer, prec):
    """Step M: the lists of :func:`read_map` replayed sigma box by sigma box; {name: (leaves, least bound)}."""
    models, summary = DartModels(sig_lo, sig_hi, hints, layer, prec), {}
    for i in range(hints.sigma_boxes):
        box = models.sigma_box(i)
        for name, method, sign, leaves in lists:
            count, least = replay_tree(leaves[i], box.evaluator(method), sign, f"{name}, sigma box {i}")
            old, best = summary.get(name, (0, None))
            summary[name] = (old + count, min((b for b in (least, best) if b is not None), key=abs, default=None))
    return summary


def _show(counts):
    """{name: (count, least bound or None)} as one line (bounds to 3 digits by arb: no float)."""
    return "; ".join(f"{n} {c}" + ("" if b is None else f" (>= {arb(b).str(3, radius=False)})")
                     for n, (c, b) in counts.items())


def verify_dart_tail(cert, k0, part, log):
    """Check a ``"dart:>=K0"`` "C1" certificate into ``part`` (steps S, Z, G, E, M, C); returns its name.
    A malformed record raises CertificateError (step 1)."""
    rec = read_record(cert, k0)
    name, (lo, hi), sig_r = f"dart:>={k0}", rec["sigma"], rec["circle"]
    log(f"C1 certificate for {name} ({rec['prec']} bits)")

    def spectrum():  # SpectralRegions checks the secular identities first
        least0, reg = ds.check_mode0_roots(sig_r, k0, rec["mode0_h"]), ds.SpectralRegions(sig_r, k0)
        counts = {n: replay_tree(rec["re"][n], getattr(reg, n.lower()), 1, f"spectrum re {n}") for n in "NIF"}
        return (f"every K >= {k0}: 1, lam1 = lam(cos(2 pi/K)) and one even eigenvalue (lam2) outside |lam| = "
                f"lam(cos(2 x {sig_r}/K)), each simple; secular identities exact; mode 0's roots real and below "
                f"r on {rec['mode0_h']} h-balls (Q(r)/h >= {least0.str(3, radius=False)}); Re(1 - F) > 0 (leaves): "
                + _show(counts))

    steps = [
        ("S sector matrices of every K >= 7 from one window",
         lambda: "dart:7 and dart:8: one row per window class, the same in both; centre row (1 - 7h/4, 3h^2/2, "
                 "h^2/4) for K = 7..12; R-symmetric, odd part the ring modes, one-ring closed, outer bound "
                 f"{ds.check_construction()[1]}"),
        ("Z dropped Taylor coefficients are 0 (exact, Q(sqrt 5, i))", check_zeros),
        (f"G spectrum for every K >= {k0}", spectrum),
        (f"E eigenvectors: y at sigma* in ({lo}, {hi}) and x span lam2, lam1",
         lambda: ds.check_eigenvector(lo, hi, k0, rec["prec"], balls=rec["sigma_h"])),
        (f"M characteristic map regular (R), transversal (T), winding once (W) for every K >= {k0}",
         lambda: _show(replay_map(rec["map"], lo, hi, rec["hints"], rec["layer"], rec["prec"]))),
    ]
    with ctx.workprec(rec["prec"]):
        for title, fn in steps:
            try:
                msg = fn()
            except (CertificateError, ZeroDivisionError, ValueError) as exc:
                part(title, False, str(exc))
                return name
            part(title, True, msg)
    part(f"C generalized Reif criterion for every K >= {k0}", True,
         "1 simple, lam1 > lam2 > |every other|, both simple; the reflection in ray 0 carries the quadrants "
         "q <= (K - 1)/2 to the rest (x odd, y even): Phi regular and injective, so dart:K is C1")
    return name
