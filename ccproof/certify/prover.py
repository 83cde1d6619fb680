"""Injectivity and C1 prover for bmz04 Appendix A and Reif's criterion (untrusted search).

For a valence k the prover builds, from the characteristic map the verifier derives
(:func:`ccproof.certify.verify.statement.nets_for_valence`), every Bernstein form the verifier
will rebuild (det J_Phi on layer 0, det J_G on each dyadic cell and w piece, the R9 corner form),
subdivides each adaptively until all of its coefficients are certainly positive, and writes the
leaves as split paths with a lower bound each. Only the choice of where to split is heuristic;
every number written comes from arb balls. The certificate is re-checked by
:mod:`ccproof.certify.verify`, which trusts none of this module.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

from flint import arb, ctx, fmpq

from ccproof.certify.poly import certainly_positive
from ccproof.certify.verify import C1_SCHEMA, SCHEMA
from ccproof.certify.verify.injectivity import MAX_LEVEL, form_patches
from ccproof.certify.verify.interval import hull_nets, interval_cells, lam_interval_ok, parameter_nets, valence_cells
from ccproof.certify.verify.maps import (
    STAR_CURVES,
    corner_containment,
    corner_det_form,
    regularity_form,
    square_inside_image,
    star_form,
)
from ccproof.certify.verify.replay import MAX_BOXES, parse_decimal
from ccproof.certify.verify.statement import PATCHES, c_lam, derivation, nets_for_valence
from ccproof.errors import CCProofError, ValenceError, check_valence
from ccproof.rigorous import exact_fmpq, range_enclosure
from ccproof.tables.format import certificates_dir
from ccproof.valence import Valence, ValenceLike

DEFAULT_PREC = 128
MAX_DEPTH = 14



def lower_bound(form):
    """The lower end of ``range_enclosure(form)`` as an exact ``fmpq`` (None if it is -inf or NaN): the
    bound a leaf records (the verifier re-derives its own).

    >>> from flint import arb
    >>> lower_bound([arb(1) / 3, arb(2)]) < fmpq(1, 3)
    True
    """
    lo = range_enclosure(form)[0]
    return lo if isinstance(lo, fmpq) else exact_fmpq(lo)

class ProofFailed(CCProofError):
    """The search found no certificate (the claim may be false, or needs deeper subdivision).

    Raised by :func:`prove_valence`, :func:`prove_interval` and :func:`prove_c1` when a Bernstein form
    (bmz04 Appendix A; docs/readings.md R7-R9) is negative at a box corner or not certified positive
    after ``MAX_DEPTH`` splits; the message names the form and the box path.

    Parameters
    ----------
    message : str

    Examples
    --------
    >>> issubclass(ProofFailed, CCProofError)
    True
    >>> raise ProofFailed("det J_Phi on P1: no positive Bernstein bound after 14 splits (path '0101')")
    Traceback (most recent call last):
    ...
    ccproof.certify.prover.ProofFailed: det J_Phi on P1: no positive Bernstein bound after 14 splits (path '0101')
    """


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


def _smallest_level(nets, lam, max_level=MAX_LEVEL):
    """The smallest N with lam^N max(coordinates) < 1/6 (part A), found by trying N = 1, 2, ...; at most the
    verifier's bound on N, so that the prover never writes a certificate the verifier refuses."""
    for N in range(1, max_level + 1):
        if corner_containment(nets, lam, N)[0]:
            return N
    raise ProofFailed(f"no level N <= {max_level} maps the corner cell into [0,1/6)^2")


def prove_valence(k: int, prec: int = DEFAULT_PREC, progress: bool = True) -> dict[str, Any]:
    """Search an injectivity certificate for valence k (bmz04 Appendix A as corrected in docs/appendix_a.md).

    Parameters
    ----------
    k : int
        Valence, k >= 3.
    prec : int
        arb precision in bits of every Bernstein coefficient (written into the certificate).
    progress : bool
        Show a progress bar over the dyadic cells.

    Returns
    -------
    dict
        The certificate (docs/certificates.md): schema, valence, the level N and the boxes of parts B, D, E.
        Raises :class:`ProofFailed` when some form is not certainly positive after subdivision.

    >>> from ccproof.certify.verify import verify_certificate
    >>> cert = prove_valence(4, progress=False)
    >>> cert["N"], sorted(cert["parts"]), bool(verify_certificate(cert, log=lambda line: None))
    (3, ['cells', 'corner', 'regularity'], True)
    """
    k = check_valence(k)
    with ctx.workprec(prec):
        lam = c_lam(k, prec)[1]
        nets = nets_for_valence(k, prec)
        N = _smallest_level(nets, lam)
        regularity = {n: prove_positive(regularity_form(nets, n, prec), (0, 1), f"det J_Phi on {n}")
                      for n in form_patches(derivation().symmetric)}
        todo = valence_cells(nets, lam, N, prec, derivation().symmetric)
        it = todo
        if progress:
            from tqdm import tqdm

            it = tqdm(todo, desc=f"k={k} cells", unit="cell", leave=False)
        cells = {key: prove_positive(build(), (0, 1), f"cell {key}") for key, build in it}
        corner = {n: prove_positive(corner_det_form(nets, lam, N, n, prec), (2, 3, 0, 1),
                                    f"corner {n}") for n in form_patches(derivation().symmetric)}
    boxes = sum(len(b) for part in (regularity, cells, corner) for b in part.values())
    if boxes > MAX_BOXES:
        raise ProofFailed(f"valence {k}: {boxes} boxes, more than the verifier reads ({MAX_BOXES})")
    return {"schema": SCHEMA, "valence": k, "N": N, "prec": prec,
            "parts": {"regularity": regularity, "cells": cells, "corner": corner}}


def _decimal_str(x, up, digits=14):
    """A short decimal string below (``up=False``) or above an arb/fmpq ``x``, checked exactly."""
    from decimal import ROUND_CEILING, ROUND_FLOOR, Decimal

    d = Decimal(arb(x).mid().str(30, radius=False)).quantize(Decimal(10) ** -digits,
                                                                 rounding=ROUND_CEILING if up else ROUND_FLOOR)
    step = Decimal(10) ** -digits
    while True:  # move outward until the exact comparison holds
        q = parse_decimal(str(d))
        if (q >= x) if up else (q <= x):
            return str(d)
        d = d + step if up else d - step


def _lam_range(k0, prec):
    """Decimal strings [La, Lb] with La <= lam(k0) and Lb >= (3 + sqrt 5)/8 (checked by the verifier)."""
    with ctx.workprec(prec):
        lam0 = c_lam(k0, prec)[1]
        ends = [_decimal_str(lam0.lower(), up=False), _decimal_str(((3 + arb(5).sqrt()) / 8).upper(), up=True)]
    assert lam_interval_ok(k0, parse_decimal(ends[0]), parse_decimal(ends[1]), prec)
    return ends


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
                      for n in form_patches(derivation().symmetric)}
        corner = {n: prove_positive(corner_det_form(nets, lam, N, n, prec), (2, 3, 0, 1),
                                    f"{label} corner {n}") for n in form_patches(derivation().symmetric)}
        todo = interval_cells(zn, N, trunc, prec, derivation().symmetric)
        it = todo
        if progress:
            from tqdm import tqdm

            it = tqdm(todo, desc=f"{label} cells", unit="cell", leave=False)
        cells = {key: prove_positive(build(), (1, 2, 0), f"{label} cell {key}") for key, build in it}
    return {"regularity": regularity, "cells": cells, "corner": corner}


def _piece_task(task):
    """One lam piece as an independent task (for :func:`prove_interval` on a scheduler)."""
    a, b, N, taylor_degree, truncation_degree, prec, label = task
    exact = derivation().integer_forms()
    return _prove_piece(exact, parse_decimal(a), parse_decimal(b), N, taylor_degree, truncation_degree, prec,
                        False, label)


def _pieces_in_waves(k0, ends, N, taylor_degree, truncation_degree, prec, max_pieces, scheduler, piece=_piece_task):
    """The pieces of the serial bisection below, found wave by wave: every pending piece is one task, the
    failed ones are bisected into the next wave. The successful pieces (the leaves of the same bisection
    tree) are returned in lam order, as the serial depth-first search appends them."""
    from ccproof.scale.engine import open_scheduler

    with open_scheduler(scheduler) as sched:
        return _waves(k0, ends, N, taylor_degree, truncation_degree, prec, max_pieces, sched, piece)


def _waves(k0, ends, N, taylor_degree, truncation_degree, prec, max_pieces, scheduler, piece):
    from ccproof.scale.engine import run_tasks

    todo, pieces = [(ends[0], ends[1])], []
    name = f"k{Valence(k0, interval=True)}"
    while todo:
        tasks = [(a, b, N, taylor_degree, truncation_degree, prec, f"{name} lam in [{a}, {b}]") for a, b in todo]
        sweep = run_tasks(piece, tasks, scheduler, desc=f"{name} lam pieces", unit="piece", raise_errors=False,
                          retries=2, deterministic=(ProofFailed,), names=[t[-1] for t in tasks])
        failed = []
        for (a, b), parts in zip(todo, sweep.results):
            if parts is not None:
                pieces.append({"lam": [a, b], "parts": parts})
        for i, exc in sorted(sweep.errors.items()):
            if not isinstance(exc, ProofFailed):
                raise exc
            failed.append((todo[i], exc))
        if failed and len(pieces) + 2 * len(failed) > max_pieces:
            raise failed[0][1]
        todo = []
        for (a, b), _ in failed:
            mid = _decimal_str((parse_decimal(a) + parse_decimal(b)) / 2, up=False)
            todo += [(a, mid), (mid, b)]
    pieces.sort(key=lambda p: parse_decimal(p["lam"][0]))
    return pieces


def prove_interval(k0: ValenceLike, prec: int = DEFAULT_PREC, progress: bool = True, taylor_degree: int = 3,
                   truncation_degree: int = 2, max_pieces: int = 16, scheduler: object = None) -> dict[str, Any]:
    """Appendix-A certificate for every valence k >= k0 at once (docs/appendix_a.md section 6).

    lam runs over [La, Lb] with La <= lam(k0) and Lb >= (3 + sqrt 5)/8; the nets are Taylor models in
    zeta (lam = mid + zeta * half-width) built from the derived exact forms, so part D keeps the
    correlation between control points (an interval hull of the nets does not: its coefficients are
    ~0.02 wide against cell margins of ~4e-4). A piece that fails is bisected (up to ``max_pieces``).
    ``scheduler`` (a :func:`ccproof.scale.engine.parse_scheduler` spec or a Client): run the pieces of each
    bisection wave as tasks there; None keeps the serial search. Both give the same certificate.

    Parameters
    ----------
    k0 : int or str or dict or Valence
        The smallest valence of the interval: an int k0 >= 3 or an interval in any spelling of
        :meth:`ccproof.valence.Valence.parse` (``">=40"``, ``{"min": 40}``); a single valence such as
        ``"7"`` raises :class:`~ccproof.errors.ValenceError` (use :func:`prove_valence`).
    prec : int
        arb precision in bits of every Bernstein coefficient (written into the certificate).
    progress : bool
        Progress bars over the cells of each piece (serial search only).
    taylor_degree : int
        Degree in zeta of the Taylor models of the nets.
    truncation_degree : int
        zeta degree kept in the Taylor models of the cell determinants (part D).
    max_pieces : int
        Most lam pieces of the bisection; :class:`ProofFailed` beyond.
    scheduler : str or distributed.Client, optional
        Where the pieces of each bisection wave run (see above).

    Returns
    -------
    dict
        The certificate (docs/certificates.md): ``schema``, ``valence`` = ``{"min": k0}``, the level ``N``,
        ``prec``, ``parameter`` (the degrees) and ``pieces``, a list in lam order of
        ``{"lam": [La, Lb], "parts": {"regularity", "cells", "corner"}}`` (decimal strings and boxes).
        Raises :class:`ProofFailed` when a piece still fails after ``max_pieces`` pieces.

    Examples
    --------
    Every k >= 10^6 with a low precision and Taylor degrees (about 5 s; the published certificates use the
    defaults, ``ccproof certify '>=40'``):

    >>> from ccproof.certify.verify import verify_certificate
    >>> cert = prove_interval(10**6, prec=64, taylor_degree=2, truncation_degree=1, progress=False)
    >>> cert["valence"], cert["N"], len(cert["pieces"])
    ({'min': 1000000}, 5, 1)
    >>> bool(verify_certificate(cert, log=lambda line: None))
    True
    """
    v = Valence(k0, interval=True) if isinstance(k0, int) else Valence.parse(k0)
    if not v.interval:
        raise ValenceError(f"prove_interval proves every valence k >= k0: give k0 or '>=K0', got {k0!r}")
    k = v.to_json()
    exact = derivation().integer_forms()
    ends = _lam_range(v.k, prec)
    with ctx.workprec(prec):
        La, Lb = parse_decimal(ends[0]), parse_decimal(ends[1])
        N = _smallest_level(hull_nets(parameter_nets(exact, La, Lb, 0, taylor_degree, prec), prec),
                           arb(La).union(arb(Lb)))
    todo = [(ends[0], ends[1])] if scheduler is None else []
    pieces = [] if scheduler is None else _pieces_in_waves(
        v.k, ends, N, taylor_degree, truncation_degree, prec, max_pieces, scheduler)
    while todo:
        a, b = todo.pop(0)
        label = f"k{v} lam in [{a}, {b}]"
        try:
            parts = _prove_piece(exact, parse_decimal(a), parse_decimal(b), N, taylor_degree, truncation_degree,
                                 prec, progress, label)
        except ProofFailed:
            if len(pieces) + len(todo) + 2 > max_pieces:
                raise
            mid = _decimal_str((parse_decimal(a) + parse_decimal(b)) / 2, up=False)
            todo[:0] = [(a, mid), (mid, b)]
            continue
        pieces.append({"lam": [a, b], "parts": parts})
    return {"schema": SCHEMA, "valence": k, "N": N, "prec": prec,
            "parameter": {"variable": "lam", "taylor_degree": taylor_degree, "truncation_degree": truncation_degree},
            "pieces": pieces}


def claimed_margins(cert):
    """The smallest bound claimed per section of a certificate, and its number of boxes.

    The prover's own claims, printed before the verifier re-checks them (never read back as evidence;
    docs/certificates.md).

    Parameters
    ----------
    cert : dict
        An injectivity certificate (one valence, with ``parts``; or an interval, with ``pieces``).

    Returns
    -------
    margins : dict of str -> str
        ``min_bound_det_J_phi_local``, ``min_bound_det_J_G_cells_local``,
        ``min_bound_det_J_G_corner_over_h2``: the smallest claimed lower bound of each section.
    n_boxes : int
        Number of boxes in the certificate.

    Examples
    --------
    >>> import json
    >>> from fractions import Fraction
    >>> cert = json.loads(certificate_path(5).read_text())
    >>> margins, n = claimed_margins(cert)
    >>> bounds = [Fraction(b["bound"]) for s in cert["parts"].values() for v in s.values() for b in v]
    >>> n == len(bounds), min(Fraction(m) for m in margins.values()) == min(bounds) > 0
    (True, True)
    """
    parts_list = [pc["parts"] for pc in cert["pieces"]] if "pieces" in cert else [cert["parts"]]
    return _summary(parts_list)


def _summary(parts_list):
    """(smallest claimed bound per section as strings, number of boxes) over a list of ``parts``."""
    names = {"regularity": "min_bound_det_J_phi_local", "cells": "min_bound_det_J_G_cells_local",
             "corner": "min_bound_det_J_G_corner_over_h2"}
    summary = {name: str(min((parse_decimal(b["bound"]) for parts in parts_list for boxes in parts[sec].values()
                              for b in boxes), default=None)) for sec, name in names.items()}
    return summary, sum(len(v) for parts in parts_list for sec in parts.values() for v in sec.values())


def certificate_path(k, directory=None):
    """``k005.json`` for a valence, ``k_ge_40.json`` for the interval ``{"min": 40}``/``">=40"`` (any spelling
    of :meth:`ccproof.valence.Valence.parse`), in ``directory`` or the injectivity certificates folder.

    Parameters
    ----------
    k : int or str or dict or Valence
        A valence or an interval of valences.
    directory : str or pathlib.Path, optional
        Default: ``certificates_dir() / "injectivity"``.

    Returns
    -------
    pathlib.Path

    Examples
    --------
    >>> certificate_path(5, "d").as_posix(), certificate_path({"min": 40}, "d").name
    ('d/k005.json', 'k_ge_40.json')
    """
    return Path(directory or certificates_dir() / "injectivity") / (Valence.parse(k).stem + ".json")


def write_certificate(cert, path=None):
    """Write a certificate as sorted, indented ASCII JSON; returns the path.

    Parameters
    ----------
    cert : dict
        A certificate of :func:`prove_valence`, :func:`prove_interval` or :func:`prove_c1`.
    path : str or pathlib.Path, optional
        Default: :func:`certificate_path` of ``cert["valence"]`` (the published folder).

    Returns
    -------
    pathlib.Path

    Examples
    --------
    >>> import json, tempfile
    >>> from pathlib import Path
    >>> tmp = tempfile.TemporaryDirectory()          # removed when the example ends
    >>> p = write_certificate({"valence": 5, "N": 3}, Path(tmp.name) / "k005.json")
    >>> json.loads(p.read_text()) == {"valence": 5, "N": 3}
    True
    """
    path = Path(path or certificate_path(cert["valence"]))
    path.parent.mkdir(parents=True, exist_ok=True)
    # under a temporary name first, renamed when complete: an interrupted write leaves no partial certificate
    tmp = path.with_name(f".tmp-{os.getpid()}-{path.name}")
    try:
        tmp.write_text(json.dumps(cert, indent=1, sort_keys=True) + "\n", encoding="ascii")
        os.replace(tmp, path)
    finally:
        tmp.unlink(missing_ok=True)
    return path


def prove_c1(k: ValenceLike, prec: int = DEFAULT_PREC) -> dict[str, Any]:
    """C1 certificate (Reif's criterion) for valence k or the interval ``">=K0"``: det J_Phi > 0 on
    layer 0 and a star-shaped outer boundary, boxes found by subdivision; the spectral ordering is
    re-derived by the verifier from the rules (:mod:`ccproof.certify.verify.spectrum`).

    Parameters
    ----------
    k : int or str
        A valence k >= 3, or ``">=K0"`` for every k >= K0 (one lam piece covering lam(K0)..lim lam).
    prec : int
        arb precision in bits.

    Returns
    -------
    dict
        The certificate (schema ``ccproof.c1/2``).

    >>> cert = prove_c1(5)
    >>> cert["schema"], sorted(cert["parts"]["star"])
    ('ccproof.c1/2', ['P1s1', 'P2s1', 'P2t1', 'P3t1'])
    """
    v = Valence.parse(k)
    k = v.to_json()
    with ctx.workprec(prec):
        if v.interval:
            ends = _lam_range(v.k, prec)
            La, Lb = parse_decimal(ends[0]), parse_decimal(ends[1])
            nets = hull_nets(parameter_nets(derivation().integer_forms(), La, Lb, 0, 3, prec), prec)
        else:
            nets = nets_for_valence(v.k, prec)
        reg = {n: prove_positive(regularity_form(nets, n, prec), (0, 1), f"det J_Phi on {n}") for n in PATCHES}
        star = {c: prove_positive(star_form(nets, c, prec), (0,), f"star {c}") for c in STAR_CURVES}
    parts = {"regularity": reg, "star": star}
    if v.interval:
        return {"schema": C1_SCHEMA, "valence": k, "prec": prec, "pieces": [{"lam": ends, "parts": parts}]}
    return {"schema": C1_SCHEMA, "valence": k, "prec": prec, "parts": parts}


def c1_certificate_path(k, directory=None):
    """:func:`certificate_path` in the C1 certificates folder.

    Parameters
    ----------
    k : int or str or dict or Valence
        Any spelling of :meth:`ccproof.valence.Valence.parse`.
    directory : str or pathlib.Path, optional
        Default: ``certificates_dir() / "c1"``.

    Returns
    -------
    pathlib.Path

    Examples
    --------
    >>> c1_certificate_path(5, "d").as_posix(), c1_certificate_path(">=40").parent.name
    ('d/k005.json', 'c1')
    """
    return Path(directory or certificates_dir() / "c1") / (Valence.parse(k).stem + ".json")


def _prove_smooth(prove, name, prec, statement):
    k = Valence.parse(name.partition(":")[2]).to_json()
    try:
        return prove(k, prec), statement
    except ProofFailed as exc:
        return None, f"undecided: {exc}"


def _prove_injective(name, prec):
    v = Valence.parse(name.partition(":")[2])
    return _prove_smooth(lambda k, p: (prove_interval if v.interval else prove_valence)(k, p, progress=False),
                         name, prec, "injective")


def _prove_c1(name, prec):
    return _prove_smooth(prove_c1, name, prec, "C1")


def _tagged_prover(which):
    """The prover ``which`` of :mod:`ccproof.certify.tagged` or :mod:`ccproof.certify.tagged_dart`, imported
    when it runs (the smooth routes need neither)."""
    def prove(name, prec):
        from ccproof.certify import tagged, tagged_dart

        fn = {"witness": tagged.prove_tagged, "map": tagged.prove_tagged_c1, "limit": tagged.prove_tagged_limit,
              "dart tail": tagged_dart.prove_dart_tail}[which]
        return fn(name, prec)
    return prove


#: one prover per route of the verifier's registry (:data:`ccproof.certify.verify.ROUTES`), by the route's name;
#: each takes a configuration name and a precision and returns (certificate or None, reason)
PROVERS = {
    "smooth injective": _prove_injective,
    "smooth C1": _prove_c1,
    "tagged not C1": _tagged_prover("witness"),
    "tagged C1": _tagged_prover("map"),
    "dart:>=K0 C1": _tagged_prover("dart tail"),
    "crease, corner:>=N0 not C1": _tagged_prover("limit"),
}


def prove_configuration(name, prec=DEFAULT_PREC, statement=None):
    """A certificate for a configuration (``"crease:5"``, ``"dart:>=101"``, ``"smooth:5"``) from the first
    route of the verifier's registry that takes it (and proves ``statement``, when given) whose prover finds
    one; else None with each route's reason (``"undecided: not C1: ...; C1: ..."``). The caller re-checks
    the written file with the verifier.

    Parameters
    ----------
    name : str
    prec : int
    statement : str, optional
        ``"injective"``, ``"C1"`` or ``"not C1"``; default: any, in the registry's order.

    Returns
    -------
    (dict or None, str)

    Examples
    --------
    >>> cert, why = prove_configuration("corner:1")
    >>> cert["statement"], why
    ('C1', 'C1')
    >>> prove_configuration("crease:5", statement="injective")
    Traceback (most recent call last):
    ...
    ccproof.errors.CCProofError: crease:5: no route of the registry certifies 'injective'
    """
    from ccproof.certify.verify.registry import routes_for

    routes = [r for r in routes_for(name) if statement in (None, r.statement)]
    if not routes:
        raise CCProofError(f"{name}: no route of the registry certifies {statement!r}")
    whys = []
    for route in routes:
        cert, why = PROVERS[route.name](name, prec)
        if cert is not None:
            return cert, why
        whys.append(f"{route.statement}: {why.removeprefix('undecided: ')}")
    return None, "undecided: " + "; ".join(whys)
