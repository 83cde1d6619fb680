"""Appendix-A injectivity certificates: one valence, or every k >= k0 at once (trusted).

Statement (valence k, everything derived by :mod:`.statement` from k and the rules): for the blend
G(y) = w(Phi(y)) y + (1 - w(Phi(y))) Phi(y) on the face y in [0, 1]^2 (docs/readings.md R5-R7),
det J_G > 0 on [0, 1]^2 minus the corner, det J_Phi > 0, and [0, 1/2]^2 lies inside Phi([0, 1]^2).
The hints are the level N and the boxes of parts B, D, E. Parts (docs/certificates.md):

  S  the derivation's identities in F (eigen-equation, normalization, axes, continuity, layers);
  H  0 < lam < 1, 2 lam^4 < 1 and the outer curve in the closed first quadrant (arb);
  A  lam^N max(coordinates) < 1/6;  B  det J_Phi > 0 on layer 0;  C  [0,1/2]^2 inside the image;
  D  det J_G > 0 on every required (cell, w piece);  E  det J_G / h^2 > 0 on the corner cell.
"""

from __future__ import annotations

import re

from flint import arb, ctx, fmpq

from .errors import CertificateError
from .interval import hull_nets, interval_cells, lam_interval_ok, parameter_nets, valence_cells
from .maps import (
    STAR_CURVES,
    corner_containment,
    corner_det_form,
    curve_points,
    regularity_form,
    square_inside_image,
)
from .record import exact_keys, field_of, kname
from .registry import SCHEMA  # noqa: F401 (named in the examples)
from .replay import check_boxes, parse_decimal, read_boxes
from .statement import PATCHES, StatementError, c_lam, derivation, nets_for_valence

_CELL_KEY = re.compile(r"[0-9]{1,4},[0-9]{1,4},[0-2],[0-2]")
MAX_LEVEL = 6  # N: every published certificate, every k >= 3, needs at most 5; the required cells grow as 4^N


def check_derivation(part):
    """Part S: the statement's identities (once per process; every valence at once).

    Returns
    -------
    bool
        The hypotheses of docs/appendix_a.md section 0 hold exactly in F.

    Examples
    --------
    >>> from ccproof.certify.verify.record import Recorder, VerifyResult
    >>> res = VerifyResult()
    >>> check_derivation(Recorder(res, lambda line: None)), res.parts[0].message
    (True, '8 identities in Q(c)[lam] hold exactly (mirror symmetry holds)')
    """
    d = derivation()
    bad = [name for name, ok in d.hypotheses if not ok]
    part("S statement derived from the rules", not bad,
         "fails: " + "; ".join(bad) if bad else f"{len(d.hypotheses)} identities in Q(c)[lam] hold exactly "
         f"(mirror symmetry {'holds' if d.symmetric else 'does not hold'})")
    return not bad


def check_hypotheses(nets, lam, part, tag=""):
    """Part H: 0 < lam < 1, 2 lam^4 < 1 and the outer curve of the face in the closed first quadrant.

    Parameters
    ----------
    tag : str
        Prefix of the part's name.

    Examples
    --------
    >>> from ccproof.certify.verify.record import Recorder, VerifyResult
    >>> res = VerifyResult()
    >>> check_hypotheses(nets_for_valence(4, 64), c_lam(4, 64)[1], Recorder(res, lambda line: None))
    >>> res.parts[0].ok, check_hypotheses(nets_for_valence(4, 64), arb(1), Recorder(res, lambda line: None))
    (True, None)
    >>> res.parts[1].ok, res.parts[1].message
    (False, 'lam fails')
    """
    exact = derivation().bezier  # a coordinate that is exactly 0 in F is on the axis
    quadrant = all(q.is_zero() or x >= 0 for cv in STAR_CURVES
                   for p, e in zip(curve_points(nets, cv), curve_points(exact, cv))
                   for x, q in zip(p, e))  # arb >= : certainly
    ok = lam > 0 and lam < 1 and 2 * lam**4 < 1
    part(f"{tag}H 0 < lam < 1, 2 lam^4 < 1, outer curve in the first quadrant", ok and quadrant,
         "" if ok and quadrant else ("lam fails" if not ok else "an outer control point may leave the quadrant"))


def form_patches(symmetric):
    """The pieces whose forms parts B and E check: all three, or P2 and P3 under the mirror symmetry
    (exact, part S), which maps P1's det J_Phi and corner form onto P3's with (s, t) swapped
    (docs/appendix_a.md section 8), as part D keeps only the cells with l <= m.

    Examples
    --------
    >>> form_patches(True), form_patches(False)
    (('P2', 'P3'), ('P1', 'P2', 'P3'))
    """
    return ("P2", "P3") if symmetric else PATCHES


def _check_structure(parts, cell_vars):
    """Validate every box list (its partition included) before any arithmetic, so a malformed file fails fast
    and by name."""
    exact_keys(parts, ("regularity", "cells", "corner"), "parts")
    patches = form_patches(derivation().symmetric)
    for section, nvars in (("regularity", 2), ("cells", cell_vars), ("corner", 4)):
        sec = field_of(parts, section, dict, "parts")
        if section != "cells":
            exact_keys(sec, patches, f"parts.{section}")
        for key, boxes in sec.items():
            if section == "cells" and not (isinstance(key, str) and _CELL_KEY.fullmatch(key)):
                raise CertificateError(f"parts.cells: malformed key {key!r} (expected 'l,m,p,q')")
            read_boxes(boxes, nvars, f"parts.{section}.{key}")  # the partition, before any arithmetic


def read_n_prec(cert):
    """The level N (1..:data:`MAX_LEVEL`) and the precision in bits (64..1024) of a certificate.

    Examples
    --------
    >>> read_n_prec({"N": 3, "prec": 128})
    (3, 128)
    >>> read_n_prec({"N": 7, "prec": 128})
    Traceback (most recent call last):
    ...
    ccproof.certify.verify.errors.CertificateError: prec must lie in 64..1024 and N in 1..6
    """
    N = field_of(cert, "N", int, "certificate")
    prec = field_of(cert, "prec", int, "certificate")
    if not 64 <= prec <= 1024 or not 1 <= N <= MAX_LEVEL:
        raise CertificateError(f"prec must lie in 64..1024 and N in 1..{MAX_LEVEL}")
    return N, prec


def check_parts(parts, nets, lam, N, prec, cells, part, tag):
    """Parts A-E for the arb ``nets`` and ``lam``; ``cells`` lists (key, build root) of every required cell.
    Stops at the first failed part (it is named; the rest is moot).

    Parameters
    ----------
    parts : dict
        ``regularity``, ``cells``, ``corner`` box lists of the certificate.

    Examples
    --------
    At k = 4 (Phi the identity) det J_Phi = 1/4 and the corner form's coefficients exceed 0.1, so one
    root box per piece proves parts B and E; with no cells listed part D has nothing to check:

    >>> from ccproof.certify.verify.record import Recorder, VerifyResult
    >>> res = VerifyResult()
    >>> nets, lam = nets_for_valence(4, 64), c_lam(4, 64)[1]
    >>> box, corner = [{"path": "", "bound": "0.2"}], [{"path": "", "bound": "0.1"}]
    >>> parts = {"regularity": {"P2": box, "P3": box}, "cells": {}, "corner": {"P2": corner, "P3": corner}}
    >>> check_parts(parts, nets, lam, 3, 64, [], Recorder(res, lambda line: None), "")
    >>> [p.name[0] for p in res.parts], all(p.ok for p in res.parts)
    (['A', 'B', 'C', 'D', 'E'], True)
    >>> res = VerifyResult()
    >>> forged = dict(parts, corner={"P2": box, "P3": box})   # claims 0.2 where the form goes down to 0.102
    >>> check_parts(forged, nets, lam, 3, 64, [], Recorder(res, lambda line: None), "")
    >>> res.parts[-1].ok
    False
    """
    okA, value = corner_containment(nets, lam, N)
    part(f"{tag}A corner cell maps into [0,1/6)^2", okA, "" if okA else f"lam^N * max = {value.str(6)}")
    if part.failed:
        return
    patches = form_patches(derivation().symmetric)
    _replay([(n, lambda n=n: regularity_form(nets, n, prec)) for n in patches], parts["regularity"],
            "B det J_Phi > 0 on layer 0", "regularity", part, tag)
    if part.failed:
        return
    part(f"{tag}C [0,1/2]^2 inside Phi([0,1]^2)", square_inside_image(nets))
    if part.failed:
        return
    extra = sorted(set(parts["cells"]) - {key for key, _ in cells})
    if extra:
        part(f"{tag}D cells", False, f"cell(s) {', '.join(extra[:5])} are not required by the statement "
             "(a certificate holds nothing unchecked)")
        return
    _replay(cells, parts["cells"], "D det J_G > 0 on every cell != (0,0)", "cells", part, tag, "cell")
    if part.failed:
        return
    _replay([(n, lambda n=n: corner_det_form(nets, lam, N, n, prec)) for n in patches], parts["corner"],
            "E det J_G / h^2 > 0 on the corner cell (all layers >= N)", "corner", part, tag)


def _replay(roots, boxes, label, sec, part, tag, what=None):
    """Replay the boxes ``boxes[key]`` on every (key, build root) of ``roots``: one failed part naming the first
    key (as ``what`` key: default the section ``sec``) whose boxes fail or are missing, else one passed part
    ``label`` with the least bound (the margin of ``sec``, in the local variables)."""
    what = what or sec
    least, count = None, 0
    for key, build in roots:
        if key not in boxes:
            part(f"{tag}{label[0]} {what} {key}", False, "required by the statement, not in the certificate")
            return
        ok, msg, mb = check_boxes(build(), boxes[key], f"{what} {key}")
        count += len(boxes[key])
        if not ok:
            part(f"{tag}{label[0]} {what} {key}", False, msg)
            return
        least = mb if least is None or mb < least else least
    part(f"{tag}{label}", True, f"{len(roots)} forms, {count} boxes, min bound {least} (w.r.t. the local variables)",
         least, sec)


def read_lam_pieces(pieces, read_parts):
    """The exact ends (low, high) of 1..64 lam pieces ``{"lam": [low, high], "parts": ...}``, increasing and
    contiguous; ``read_parts(parts)`` reads each piece's hints (their partitions, before any arithmetic).

    Examples
    --------
    >>> read_lam_pieces([{"lam": ["0.5", "0.6"], "parts": {}}, {"lam": ["0.6", "0.7"], "parts": {}}], print)
    {}
    {}
    [(1/2, 3/5), (3/5, 7/10)]
    """
    if not 1 <= len(pieces) <= 64:
        raise CertificateError("there must be 1..64 lam pieces")
    ends = []
    for pc in pieces:
        exact_keys(pc, ("lam", "parts"), "piece")
        lo_hi = field_of(pc, "lam", list, "piece")
        if len(lo_hi) != 2:
            raise CertificateError("piece lam must be [low, high]")
        ends.append(tuple(parse_decimal(x) for x in lo_hi))
        read_parts(field_of(pc, "parts", dict, "piece"))
    if any(not a < b for a, b in ends) or any(ends[i][1] != ends[i + 1][0] for i in range(len(ends) - 1)):
        raise CertificateError("the lam pieces must be increasing and contiguous")  # exact fmpq comparisons
    return ends


def verify_injectivity(cert, k, part, log):
    """An injectivity certificate (docs/appendix_a.md, docs/certificates.md): parts S, H, A-E for one valence
    k (an int), or for every k >= k0 (``k = {"min": k0}``) on each lam piece with Taylor models
    (:mod:`.interval`); one valence is one piece whose nets are those of lam(k) (:func:`_piece`).

    Parameters
    ----------
    cert : dict
        Schema :data:`SCHEMA` with ``N``, ``prec`` and ``parts`` (``regularity``, ``cells``, ``corner``), or
        for k >= k0 ``parameter`` and ``pieces`` in place of ``parts``.

    Returns
    -------
    str
        :func:`.record.kname` of k.

    Raises
    ------
    CertificateError
        On a malformed certificate.

    Examples
    --------
    >>> verify_injectivity({"schema": SCHEMA, "valence": 5, "N": 9, "prec": 128, "parts": {}}, 5, None, None)
    Traceback (most recent call last):
    ...
    ccproof.certify.verify.errors.CertificateError: prec must lie in 64..1024 and N in 1..6
    >>> verify_injectivity({"schema": SCHEMA, "valence": 5, "N": 3, "prec": 128}, 5, None, None)
    Traceback (most recent call last):
    ...
    ccproof.certify.verify.errors.CertificateError: certificate: missing field(s) 'parts'
    >>> cert = {"schema": SCHEMA, "valence": {"min": 9}, "N": 3, "prec": 128, "pieces": [],
    ...         "parameter": {"variable": "c", "taylor_degree": 4, "truncation_degree": 2}}
    >>> verify_injectivity(cert, cert["valence"], None, None)
    Traceback (most recent call last):
    ...
    ccproof.certify.verify.errors.CertificateError: parameter must be {'variable': 'lam', ...}
    """
    N, prec, degrees, pieces, ends = _read(cert, k)
    log(f"certificate for valence {k} (N = {N}, {prec} bits)" if not ends else
        f"certificate for valences k >= {k['min']} (N = {N}, {prec} bits, {len(pieces)} lam piece(s), "
        f"Taylor degree {degrees[0]}, truncation {degrees[1]})")
    if not check_derivation(part):
        return kname(k)
    if ends:
        part(f"lam(k) in [{ends[0][0]}, {ends[-1][1]}] for every k >= {k['min']}",
             lam_interval_ok(k["min"], ends[0][0], ends[-1][1], prec))
    for idx, pc in enumerate(pieces):
        tag = f"[piece {idx}] " if ends else ""
        if part.failed:
            break
        with ctx.workprec(prec):
            try:
                nets, lam, cells = _piece(k, ends[idx] if ends else None, N, prec, degrees)
            except (StatementError, CertificateError) as exc:
                part(f"{tag}S nets of the characteristic map", False, str(exc))
                break
            check_hypotheses(nets, lam, part, tag)
            if not part.failed:
                check_parts(pc["parts"], nets, lam, N, prec, cells, part, tag)
    return kname(k)


def _read(cert, k):
    """(N, prec, (Taylor degree, truncation degree), pieces, exact ends of the lam pieces): one piece and no
    ends for one valence; every box list read (its partition checked) before any arithmetic."""
    every = isinstance(k, dict)
    exact_keys(cert, ("schema", "valence", "N", "prec") + (("parameter", "pieces") if every else ("parts",)),
               "certificate")
    N, prec = read_n_prec(cert)
    if not every:
        parts = field_of(cert, "parts", dict, "certificate")
        _check_structure(parts, 2)
        return N, prec, (0, 0), [{"parts": parts}], []
    param = field_of(cert, "parameter", dict, "certificate")
    exact_keys(param, ("variable", "taylor_degree", "truncation_degree"), "parameter")
    deg, D = field_of(param, "taylor_degree", int, "parameter"), field_of(param, "truncation_degree", int, "parameter")
    if param["variable"] != "lam" or not 1 <= D <= deg <= 8:
        raise CertificateError("parameter must be {'variable': 'lam', 1 <= truncation_degree <= taylor_degree <= 8}")
    pieces = field_of(cert, "pieces", list, "certificate")
    ends = read_lam_pieces(pieces, lambda parts: _check_structure(parts, 3))
    if not (ends[0][0] > fmpq(1, 4) and ends[-1][1] < 1):
        raise CertificateError("the lam pieces must lie inside (1/4, 1)")
    return N, prec, (deg, D), pieces, ends


def _piece(k, ends, N, prec, degrees):
    """(nets, lam, cells of part D) of one valence k (``ends`` None: the arb nets at lam(k)) or of the lam piece
    ``ends`` = (La, Lb) (the hulls of the Taylor models in lam, lam in [La, Lb])."""
    sym = derivation().symmetric
    if ends is None:
        nets, lam = nets_for_valence(k, prec), c_lam(k, prec)[1]
        return nets, lam, valence_cells(nets, lam, N, prec, sym)
    exact = derivation().integer_forms("bspline")
    zn = [parameter_nets(exact, *ends, i, degrees[0], prec) for i in range(N)]
    return hull_nets(zn[0], prec), arb(ends[0]).union(arb(ends[1])), interval_cells(zn, N, degrees[1], prec, sym)
