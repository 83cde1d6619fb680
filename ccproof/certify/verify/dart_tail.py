"""Every ``dart:K`` with K >= K0 in one "C1" certificate: the record and its steps in order (trusted).

The grammar is docs/certificates.md, "Every dart K >= K0 in one certificate"; the argument is
docs/tagged_c1.md, "A plan for every dart K >= 101". The statement is fixed by the configuration: for every
K >= K0, 1 simple, lam1 = lam(cos(2 pi/K)) > lam2 = lam(cos(2 sigma(K)/K)) > |every other eigenvalue|, both
simple; x the odd mode-1 eigenvector, y the even eigenvector of lam2 (y = 1 at ray K/2, orientation +1);
det J_Phi > 0 on every piece of every quadrant, the transversality forms > 0 on the outer curves, and the
outer curve crosses {Y = 0, X > 0} once. The record holds hints only. The steps, each a part:

1. **Record** (:func:`read_record`): exactly the grammar's keys, every number in its range, every tree read
   against the root its region fixes (:func:`.dart_spectrum.region_roots`, :func:`.dart_models.read_map`)
   and the work the sizes declare within the budget (:func:`check_work`), before any arithmetic.
2. **Construction** (:func:`.dart_spectrum.check_construction`): S for every K >= 7 from one window.
3. **Exact zeros** (:func:`.dart_zeros.check_zeros`): every coefficient the Taylor models drop is 0.
4. **Spectrum** (:mod:`.dart_spectrum`): the identities of the secular equation, mode 0's roots below the
   circle, Re(1 - F) > 0 on every leaf of N, I, F: only 1, lam1 and one even eigenvalue outside the circle.
5. **Eigenvector lemma** (:func:`.dart_eigen.check_eigenvector`): that even eigenvalue is
   lam(cos(2 sigma*/K)), sigma* in the bracket, and the family member there (and x) are the eigenvectors.
6. **Map** (:func:`.dart_models.replay_map`): R, T and W on every leaf, sigma box by sigma box.
7. **Conclusion**: the reflection in ray 0 (x odd, y even) carries the quadrants q <= (K - 1)/2 to the
   rest; with 2 to 6 the generalized Reif criterion holds for every K >= K0.
"""

from __future__ import annotations

from flint import arb, ctx, fmpq

from ccproof.rigorous.analytic import disc_boxes

from .dart_eigen import check_eigenvector
from .dart_family import TaylorHints
from .dart_models import read_map, replay_map
from .dart_spectrum import (
    SpectralRegions,
    check_construction,
    check_mode0_roots,
    check_ranges,
    check_secular,
    region_roots,
)
from .dart_zeros import check_zeros
from .errors import CertificateError
from .record import exact_keys, field_of
from .replay import MAX_BOXES, parse_decimal, read_tree, replay_tree

MIN_K0 = 101  # the regions need 1/K0 < r, and the covers are shown from 101 on
MAX_WORK = 100_000  # units of 0.1 ms of CPU (:func:`record_work`): 10 s; the published record declares 8.4 s
MAX_BALLS = 8192
_DEC, _FRAC = "decimal", "fraction"
#: the record's fields (:func:`read_fields`): a dict of fields (exactly those keys), a list (that many items),
#: (lo, hi) an int in lo..hi, a decimal string, a fraction 'INT/INT', or a type (read by the step that needs it)
GRAMMAR = {
    "schema": str, "configuration": str, "statement": str, "prec": (64, 1024), "map": {"orientation": int},
    "spectrum": {"sigma": [_DEC, _DEC], "sigma_h": (1, MAX_BALLS), "circle": _DEC, "mode0_h": (1, MAX_BALLS),
                 "tau1": _DEC, "v0": _DEC, "re": {"N": dict, "I": dict, "F": dict}},
    "taylor": {"r": _DEC, "disc_grid": (1, 64), "sigma_boxes": (1, 256), "order": (3, 24), "layer_order": (3, 24),
               "exp_order": (2, 64)},
    "regions": {"s0": _FRAC, "layer": (3, 64), "winding": [_FRAC, _FRAC]},
    "parts": dict,
}


def read_fields(obj, spec, where):
    """``obj`` read by ``spec`` (:data:`GRAMMAR`): a dict of specs gives a dict of the values (exactly its keys,
    :func:`.record.exact_keys`), a list of specs a list of that length, (lo, hi) an int in lo..hi, "decimal" an
    fmpq (:func:`.replay.parse_decimal`), "fraction" the fmpq of 'INT/INT', a type a value of that type.

    Examples
    --------
    >>> read_fields({"a": [1, "3/4"]}, {"a": [(0, 9), _FRAC]}, "demo")
    {'a': [1, 3/4]}
    >>> read_fields({"a": 10}, {"a": (0, 9)}, "demo")
    Traceback (most recent call last):
    ...
    ccproof.certify.verify.errors.CertificateError: demo a must lie in 0..9
    """
    if isinstance(spec, dict):
        exact_keys(obj, tuple(spec), where)
        return {k: read_fields(obj[k], s, f"{where} {k}") for k, s in spec.items()}
    if isinstance(spec, list):
        if not isinstance(obj, list) or len(obj) != len(spec):
            raise CertificateError(f"{where}: a list of {len(spec)} is needed")
        return [read_fields(x, s, where) for x, s in zip(obj, spec)]
    if spec == _DEC:
        return parse_decimal(obj)
    kind = int if isinstance(spec, tuple) else str if spec == _FRAC else spec
    if not isinstance(obj, kind) or isinstance(obj, bool):
        raise CertificateError(f"{where} has the wrong type")
    if isinstance(spec, tuple) and not spec[0] <= obj <= spec[1]:
        raise CertificateError(f"{where} must lie in {spec[0]}..{spec[1]}")
    if spec == _FRAC:
        a, _, b = obj.partition("/")
        if len(obj) > 40 or not (a.isdigit() and b.isdigit() and int(b) > 0):
            raise CertificateError(f"{where}: a fraction 'INT/INT' is needed")
        return fmpq(int(a), int(b))
    return obj


def read_record(cert, k0):
    """Step 1: the record's hints as exact numbers and the spectral trees read (no arithmetic on forms).

    Parameters
    ----------
    cert : dict
    k0 : int

    Returns
    -------
    dict
        prec, sig_lo, sig_hi, sig_r, sigma_h, mode0_h, tau1, v0, re (name -> leaves), hints (TaylorHints),
        s0, layer, winding, map (:func:`.dart_models.read_map`); its work checked (:func:`check_work`).

    Raises
    ------
    CertificateError
        Naming the field.
    """
    if not MIN_K0 <= k0 <= 10**6:
        raise CertificateError(f"dart:>={k0}: the interval certificate needs {MIN_K0} <= K0 <= 10^6")
    if field_of(cert, "statement", str, "certificate") != "C1":
        raise CertificateError("dart:>=K0 is certified \"C1\" only (its statement is fixed by the configuration)")
    g = read_fields(cert, GRAMMAR, "certificate")
    sp, rg, hints = g["spectrum"], g["regions"], TaylorHints(**g["taylor"])
    if g["map"]["orientation"] != 1:
        raise CertificateError("map: the statement fixes orientation +1 (x sine-like, y = 1 at ray K/2)")
    check_ranges(k0, *sp["sigma"], sp["circle"], sp["tau1"], sp["v0"])
    if not fmpq(1, k0) < hints.r <= fmpq(1, 8):
        raise CertificateError("taylor: need 1/K0 < r <= 1/8")
    roots = region_roots(k0, sp["tau1"], sp["v0"])
    out = {"prec": g["prec"], "sig_lo": sp["sigma"][0], "sig_hi": sp["sigma"][1], "sig_r": sp["circle"],
           "sigma_h": sp["sigma_h"], "mode0_h": sp["mode0_h"], "tau1": sp["tau1"], "v0": sp["v0"], "hints": hints,
           "re": {n: read_tree(sp["re"][n], roots[n], f"spectrum re {n}", 1) for n in ("N", "I", "F")},
           "s0": rg["s0"], "layer": rg["layer"], "winding": tuple(rg["winding"])}
    out["map"] = read_map(g["parts"], k0, hints, out["s0"], out["layer"], out["winding"])
    check_work(out)
    return out


def record_work(rec):
    """The CPU work the record's sizes declare, in units of 0.1 ms (upper estimates measured on the reference
    machine of docs/certificates.md, "Bounds", at 128 bits): the exact zeros (fixed), the disc bounds (one
    family per acb box of the grid that meets the disc, with the T layer quadrants), the Taylor series of each
    sigma box (order^2, and layer_order^2 per layer quadrant), each map leaf by its quantity and region (R in
    the bulk: order; T, X, Y in the bulk: order/3; the middle: exp_order + order, times 0.45 for R and 0.2
    otherwise; the layer: layer_order/3), each spectral leaf, each h-ball of the eigenvector and mode-0 checks;
    all times ceil(prec/128).

    Examples
    --------
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


def check_work(rec):
    """Refuse, before any arithmetic, a record whose declared work (:func:`record_work`) passes
    :data:`MAX_WORK`, or which holds more than :data:`.replay.MAX_BOXES` leaves in all."""
    leaves = sum(len(t) for _, _, _, trees in rec["map"] for t in trees) + sum(len(v) for v in rec["re"].values())
    if leaves > MAX_BOXES:
        raise CertificateError(f"more than {MAX_BOXES} leaves in all ({leaves})")
    work = record_work(rec)
    if work > MAX_WORK:
        raise CertificateError(f"the record declares about {work // 10000} s of work ({work:,} units of 0.1 ms: "
                               f"disc grid, sigma boxes, orders, leaves, prec), beyond the budget of "
                               f"{MAX_WORK // 10000} s (docs/certificates.md, \"Bounds\")")


def verify_dart_tail(cert, k0, part, log):
    """Check a ``"dart:>=K0"`` "C1" certificate (module docstring) into ``part``.

    Parameters
    ----------
    cert : dict
    k0 : int
    part : Recorder
    log : callable (str) -> None

    Returns
    -------
    str
        The configuration name.

    Raises
    ------
    CertificateError
        On a malformed record (step 1).
    """
    rec = read_record(cert, k0)
    name = f"dart:>={k0}"
    log(f"C1 certificate for {name} ({rec['prec']} bits)")
    with ctx.workprec(rec["prec"]):
        _steps(rec, k0, part, log)
    return name


def _attempt(part, title, fn):
    try:
        msg = fn()
    except (CertificateError, ZeroDivisionError, ValueError) as exc:
        part(title, False, str(exc))
        return False
    part(title, True, msg)
    return True


def _spectrum(rec, k0):
    check_secular()
    least0 = check_mode0_roots(rec["sig_r"], k0, rec["mode0_h"])
    regions = SpectralRegions(rec["sig_r"], k0)
    counts = {}
    for name, fn in (("N", regions.n), ("I", regions.i), ("F", regions.f)):
        counts[name] = replay_tree(rec["re"][name], fn, 1, f"spectrum re {name}")
    return (f"every K >= {k0}: 1, lam1 = lam(cos(2 pi/K)) and one even eigenvalue (lam2) outside |lam| = "
            f"lam(cos(2 x {rec['sig_r']}/K)), each simple; secular identities exact; mode 0's roots real and below "
            f"r on {rec['mode0_h']} h-balls (Q(r)/h >= {least0.str(3, radius=False)}); Re(1 - F) > 0: "
            + ", ".join(f"{n} {c} leaves (>= {_show(b)})" for n, (c, b) in counts.items()))


def _map(rec, k0):
    out = replay_map(rec["map"], rec["sig_lo"], rec["sig_hi"], rec["hints"], rec["layer"], rec["prec"])
    return "; ".join(f"{n} {c} (>= {_show(b)})" if b is not None else f"{n} {c}" for n, (c, b) in out.items())


def _show(q):
    """A bound (fmpq) to 3 digits for the message (arb's decimal printing: no float)."""
    return arb(q).str(3, radius=False)


def _steps(rec, k0, part, log):
    def construction():
        _, bound = check_construction()
        return (f"dart:7 and dart:8: one row per window class, the same in both; centre row (1 - 7h/4, 3h^2/2, "
                f"h^2/4) for K = 7..12; R-symmetric, odd part the ring modes, one-ring closed, outer bound {bound}")

    steps = [
        ("S sector matrices of every K >= 7 from one window", construction),
        ("Z dropped Taylor coefficients are 0 (exact, Q(sqrt 5, i))", check_zeros),
        (f"G spectrum for every K >= {k0}", lambda: _spectrum(rec, k0)),
        (f"E eigenvectors: y at sigma* in ({rec['sig_lo']}, {rec['sig_hi']}) and x span lam2, lam1",
         lambda: check_eigenvector(rec["sig_lo"], rec["sig_hi"], k0, rec["prec"], balls=rec["sigma_h"])),
        (f"M characteristic map regular (R), transversal (T), winding once (W) for every K >= {k0}",
         lambda: _map(rec, k0)),
    ]
    for title, fn in steps:
        if not _attempt(part, title, fn):
            return
    part(f"C generalized Reif criterion for every K >= {k0}", True,
         "1 simple, lam1 > lam2 > |every other|, both simple; the reflection in ray 0 carries the quadrants "
         "q <= (K - 1)/2 to the rest (x odd, y even): Phi regular and injective, so dart:K is C1")


__all__ = ["MAX_WORK", "MIN_K0", "check_work", "read_record", "record_work", "verify_dart_tail"]
