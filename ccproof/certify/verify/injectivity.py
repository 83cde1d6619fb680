"""Appendix-A injectivity certificates (trusted): parts S, H, A-E for one valence, or for every k >= k0 on each
lam piece (Taylor models in lam: :mod:`.interval`); the steps shared with the C1 certificates (the pieces, their
nets, parts S and H). The statement and the parts: docs/certificates.md, docs/appendix_a.md sections 0-3, 6, 8."""

import re

from flint import arb, ctx, fmpq

from .errors import CertificateError
from .interval import hull_nets, interval_cells, lam_interval_ok, parameter_nets, valence_cells
from .maps import STAR_CURVES, corner_containment, corner_det_form, curve_points, regularity_form, square_inside_image
from .record import bounded_int, exact_keys, field_of, read_prec
from .registry import SCHEMA  # noqa: F401 (named in the examples)
from .replay import check_boxes, parse_decimal, read_boxes
from .statement import PATCHES, StatementError, c_lam, derivation, nets_for_valence

_CELL_KEY = re.compile(r"[0-9]{1,4},[0-9]{1,4},[0-2],[0-2]")
MAX_LEVEL = 6  # N: every published certificate, every k >= 3, needs at most 5; the required cells grow as 4^N


def check_derivation(part):
    """Part S: the hypotheses of docs/appendix_a.md section 0 hold exactly in F (every valence at once).

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

    >>> from ccproof.certify.verify.record import Recorder, VerifyResult
    >>> res = VerifyResult()
    >>> for lam in (c_lam(4, 64)[1], arb(1)):
    ...     check_hypotheses(nets_for_valence(4, 64), lam, Recorder(res, lambda line: None))
    >>> [(p.ok, p.message) for p in res.parts]
    [(True, ''), (False, 'lam fails')]
    """
    exact = derivation().bezier  # a coordinate that is exactly 0 in F is on the axis
    quadrant = all(q.is_zero() or x >= 0 for cv in STAR_CURVES
                   for p, e in zip(curve_points(nets, cv), curve_points(exact, cv))
                   for x, q in zip(p, e))  # arb >= : certainly
    ok = lam > 0 and lam < 1 and 2 * lam**4 < 1
    part(f"{tag}H 0 < lam < 1, 2 lam^4 < 1, outer curve in the first quadrant", ok and quadrant,
         "" if ok and quadrant else ("lam fails" if not ok else "an outer control point may leave the quadrant"))


def form_patches(symmetric):
    """The pieces of parts B and E: P2 and P3 under the mirror symmetry (part S; docs/appendix_a.md section 8)."""
    return ("P2", "P3") if symmetric else PATCHES


def read_parts(parts, sections):
    """Read ``parts``: exactly the ``sections`` {name: (keys, or None for cell keys "l,m,p,q"; box variables)}, every
    box list's partition checked before any arithmetic.

    >>> read_parts({"star": {"a": [{"path": "0L", "bound": "1"}]}}, {"star": (("a",), 1)})
    Traceback (most recent call last):
    ...
    ccproof.certify.verify.errors.CertificateError: parts.star.a: the boxes do not partition the domain exactly: ...gap)
    """
    exact_keys(parts, tuple(sections), "parts")
    for section, (keys, nvars) in sections.items():
        sec = field_of(parts, section, dict, "parts")
        if keys is not None:
            exact_keys(sec, keys, f"parts.{section}")
        for key, boxes in sec.items():
            if keys is None and not (isinstance(key, str) and _CELL_KEY.fullmatch(key)):
                raise CertificateError(f"parts.{section}: malformed key {key!r} (expected 'l,m,p,q')")
            read_boxes(boxes, nvars, f"parts.{section}.{key}")  # the partition, before any arithmetic


def read_pieces(cert, k, read):
    """``(pieces, ends)``: one piece (no ends) for one valence, or the 1..64 lam pieces ``{"lam": [low, high],
    "parts": ...}``, their exact ends increasing and contiguous; ``read(parts)`` reads each piece's hints.

    >>> read_pieces({"pieces": [{"lam": ["0.5", "0.6"], "parts": {}}, {"lam": ["0.6", "0.7"], "parts": {}}]},
    ...             {"min": 9}, print)
    {}
    {}
    ([{'lam': ['0.5', '0.6'], 'parts': {}}, {'lam': ['0.6', '0.7'], 'parts': {}}], [(1/2, 3/5), (3/5, 7/10)])
    """
    if not isinstance(k, dict):
        read(field_of(cert, "parts", dict, "certificate"))
        return [cert], []
    pieces, ends = field_of(cert, "pieces", list, "certificate"), []
    if not 1 <= len(pieces) <= 64:
        raise CertificateError("there must be 1..64 lam pieces")
    for pc in pieces:
        exact_keys(pc, ("lam", "parts"), "piece")
        lo_hi = field_of(pc, "lam", list, "piece")
        if len(lo_hi) != 2:
            raise CertificateError("piece lam must be [low, high]")
        ends.append(tuple(parse_decimal(x) for x in lo_hi))
        read(field_of(pc, "parts", dict, "piece"))
    if any(not a < b for a, b in ends) or any(ends[i][1] != ends[i + 1][0] for i in range(len(ends) - 1)):
        raise CertificateError("the lam pieces must be increasing and contiguous")  # exact fmpq comparisons
    return pieces, ends


def check_pieces(k, pieces, ends, prec, degree, layers, check, part, spectrum=lambda: True):
    """Part S, ``spectrum()`` (C1), the lam range (every k >= k0), then each piece until a part fails: its nets
    (lam(k)'s or the Taylor models' hulls), part H, ``check(parts, nets, lam, znets (``layers``) or None, tag)``."""
    if not check_derivation(part) or not spectrum():
        return
    if ends:
        part(f"lam(k) in [{ends[0][0]}, {ends[-1][1]}] for every k >= {k['min']}",
             lam_interval_ok(k["min"], ends[0][0], ends[-1][1], prec))
    for idx, pc in enumerate(pieces):
        tag = f"[piece {idx}] " if ends else ""
        if part.failed:
            return
        with ctx.workprec(prec):
            try:
                if ends:
                    exact = derivation().integer_forms()
                    zn = [parameter_nets(exact, *ends[idx], i, degree, prec) for i in range(layers)]
                    nets, lam = hull_nets(zn[0], prec), arb(ends[idx][0]).union(arb(ends[idx][1]))
                else:
                    zn, nets, lam = None, nets_for_valence(k, prec), c_lam(k, prec)[1]
            except (StatementError, CertificateError) as exc:
                part(f"{tag}S nets of the characteristic map", False, str(exc))
                return
            check_hypotheses(nets, lam, part, tag)
            if not part.failed:
                check(pc["parts"], nets, lam, zn, tag)


def read_n_prec(cert):
    """The level N (1..:data:`MAX_LEVEL`) and the precision in bits (64..1024) of a certificate."""
    return bounded_int(cert, "N", 1, MAX_LEVEL), read_prec(cert)


def check_parts(parts, nets, lam, N, prec, cells, part, tag):
    """Parts A-E for the arb ``nets`` and ``lam`` and the (key, build root) ``cells`` of part D, in order until one
    fails.

    >>> from ccproof.certify.verify.record import Recorder, VerifyResult
    >>> nets, lam = nets_for_valence(4, 64), c_lam(4, 64)[1]     # k = 4: det J_Phi = 1/4, the corner form > 0.1
    >>> box, corner = [{"path": "", "bound": "0.2"}], [{"path": "", "bound": "0.1"}]
    >>> parts = {"regularity": {"P2": box, "P3": box}, "cells": {}, "corner": {"P2": corner, "P3": corner}}
    >>> for p in (parts, dict(parts, corner={"P2": box, "P3": box})):     # the second claims 0.2 for E
    ...     res = VerifyResult()
    ...     check_parts(p, nets, lam, 3, 64, [], Recorder(res, lambda line: None), "")
    ...     print([q.name[0] for q in res.parts], [q.ok for q in res.parts][-1])
    ['A', 'B', 'C', 'D', 'E'] True
    ['A', 'B', 'C', 'D', 'E'] False
    """
    patches = form_patches(derivation().symmetric)
    okA, value = corner_containment(nets, lam, N)
    steps = (
        lambda: part(f"{tag}A corner cell maps into [0,1/6)^2", okA, "" if okA else f"lam^N * max = {value.str(6)}"),
        lambda: _replay([(n, lambda n=n: regularity_form(nets, n, prec)) for n in patches], parts["regularity"],
                        "B det J_Phi > 0 on layer 0", "regularity", part, tag),
        lambda: part(f"{tag}C [0,1/2]^2 inside Phi([0,1]^2)", square_inside_image(nets)),
        lambda: _replay(cells, parts["cells"], "D det J_G > 0 on every cell != (0,0)", "cells", part, tag, "cell"),
        lambda: _replay([(n, lambda n=n: corner_det_form(nets, lam, N, n, prec)) for n in patches], parts["corner"],
                        "E det J_G / h^2 > 0 on the corner cell (all layers >= N)", "corner", part, tag),
    )
    for step in steps:
        step()
        if part.failed:
            return


def _replay(roots, boxes, label, sec, part, tag, what=None):
    """Replay ``boxes[key]`` on every (key, build root) of ``roots``: one failed part naming a key not required or
    the first (``what`` key) whose boxes fail or are missing, else one passed part with the least bound."""
    what, least, count = what or sec, None, 0
    extra = sorted(set(boxes) - {key for key, _ in roots})
    if extra:
        part(f"{tag}{label[0]} {sec}", False, f"cell(s) {', '.join(extra[:5])} are not required by the statement "
             "(a certificate holds nothing unchecked)")
        return
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


def verify_injectivity(cert, k, part, log):
    """An injectivity certificate for the valence k or every k >= k0 (``{"min": k0}``) into ``part``;
    :class:`.errors.CertificateError` on a malformed one.

    >>> cert = {"schema": SCHEMA, "valence": {"min": 9}, "N": 3, "prec": 128, "pieces": [],
    ...         "parameter": {"variable": "c", "taylor_degree": 4, "truncation_degree": 2}}
    >>> verify_injectivity(cert, cert["valence"], None, None)
    Traceback (most recent call last):
    ...
    ccproof.certify.verify.errors.CertificateError: parameter must be {'variable': 'lam', ...}
    """
    every = isinstance(k, dict)
    exact_keys(cert, ("schema", "valence", "N", "prec") + (("parameter", "pieces") if every else ("parts",)),
               "certificate")
    N, prec = read_n_prec(cert)
    deg, D = _read_parameter(cert) if every else (0, 0)
    sym = derivation().symmetric
    patches = form_patches(sym)
    sections = {"regularity": (patches, 2), "cells": (None, 3 if every else 2), "corner": (patches, 4)}
    pieces, ends = read_pieces(cert, k, lambda parts: read_parts(parts, sections))
    if every and not (ends[0][0] > fmpq(1, 4) and ends[-1][1] < 1):
        raise CertificateError("the lam pieces must lie inside (1/4, 1)")
    log(f"certificate for valence {k} (N = {N}, {prec} bits)" if not every else
        f"certificate for valences k >= {k['min']} (N = {N}, {prec} bits, {len(pieces)} lam piece(s), "
        f"Taylor degree {deg}, truncation {D})")

    def check(parts, nets, lam, zn, tag):
        cells = valence_cells(nets, lam, N, prec, sym) if zn is None else interval_cells(zn, N, D, prec, sym)
        check_parts(parts, nets, lam, N, prec, cells, part, tag)
    check_pieces(k, pieces, ends, prec, deg, N, check, part)


def _read_parameter(cert):
    """(Taylor degree, truncation degree) of every k >= k0: 1 <= truncation <= Taylor degree <= 8, lam."""
    param = field_of(cert, "parameter", dict, "certificate")
    exact_keys(param, ("variable", "taylor_degree", "truncation_degree"), "parameter")
    deg, D = field_of(param, "taylor_degree", int, "parameter"), field_of(param, "truncation_degree", int, "parameter")
    if param["variable"] != "lam" or not 1 <= D <= deg <= 8:
        raise CertificateError("parameter must be {'variable': 'lam', 1 <= truncation_degree <= taylor_degree <= 8}")
    return deg, D
