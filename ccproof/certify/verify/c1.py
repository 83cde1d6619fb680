"""C1 certificates: Reif's criterion for Catmull-Clark at valence k or every k >= k0 (trusted).

Statement: the spectral ordering 1 = lam_0 > lam_1 = lam_2 = lam(k) > |lam_3| with the lam block
non-defective (:mod:`.spectrum`, from the rules), and the characteristic map (:mod:`.statement`, from
the rules) regular and injective: det J_Phi > 0 on layer 0 and a star-shaped image of the outer
boundary. With det J_Phi > 0 the L-shaped layer 0 is mapped locally homeomorphically; its boundary goes
to the Jordan curve made of the axis segments [lam, 1] (part S: the axis edges map onto the axes), the
outer curve C (in the first quadrant, part H) and lam C (the layer boundary identity of part S),
disjoint because C is star-shaped, so layer 0 maps injectively onto the annulus between lam C and C,
and the layers, scaled by lam^i, onto nested disjoint annuli: Phi is injective on the face, and on the
k-star by symmetry. The hints are the boxes of ``parts.regularity`` and ``parts.star``.
"""

from __future__ import annotations

from flint import arb, ctx

from .errors import CertificateError
from .injectivity import check_derivation, check_hypotheses, read_lam_pieces
from .interval import hull_nets, lam_interval_ok, parameter_nets
from .maps import STAR_CURVES, regularity_form, star_form
from .record import exact_keys, field_of, kname
from .replay import check_boxes, read_boxes
from .spectrum import check_block_polynomials, spectral_ordering
from .statement import PATCHES, StatementError, c_lam, derivation, nets_for_valence


def verify_c1(cert, k, part, log):
    """Check a C1 certificate (module docstring: Reif's criterion; docs/certificates.md) into ``part``.

    Parameters
    ----------
    cert : dict
        Schema :data:`C1_SCHEMA`: ``prec`` and ``parts`` (one valence) or ``pieces`` (lam pieces, k >= k0).
    k : int or dict ``{"min": k0}``
        From :func:`.record.read_valence`.
    part : Recorder
        Receives one :class:`.record.Part` per checked claim.

    Raises
    ------
    CertificateError
        On a malformed certificate (the caller turns it into FAILED).

    Examples
    --------
    >>> import json
    >>> from ccproof.tables.format import certificates_dir
    >>> from ccproof.certify.verify.record import Recorder, VerifyResult
    >>> cert = json.loads((certificates_dir() / "c1" / "k005.json").read_text())
    >>> res = VerifyResult()
    >>> verify_c1(cert, 5, Recorder(res, lambda line: None), lambda line: None)
    >>> bool(res), res.parts[4].name
    (True, 'det J_Phi > 0 on P1')
    """
    prec, piece_list, ends = _read_pieces(cert, k)
    log(f"C1 certificate for valence {kname(k)} ({prec} bits)")
    if not _check_spectrum(k, ends, prec, part):
        return
    exact = derivation().integer_forms("bspline") if ends else None
    for idx, pc in enumerate(piece_list):
        tag = f"[piece {idx}] " if ends else ""
        with ctx.workprec(prec):
            try:
                if ends:
                    La, Lb = ends[idx]
                    nets, lam = hull_nets(parameter_nets(exact, La, Lb, 0, 3, prec), prec), arb(La).union(arb(Lb))
                else:
                    nets, lam = nets_for_valence(k, prec), c_lam(k, prec)[1]
            except (StatementError, CertificateError) as exc:
                part(f"{tag}S nets of the characteristic map", False, str(exc))
                return
            check_hypotheses(nets, lam, part, tag)
            _check_parts(nets, pc["parts"], tag, prec, part)
            if part.failed:
                return


def _read_pieces(cert, k):
    """``(prec, pieces, ends)``: the record read and every box list checked to partition its domain, before
    any arithmetic; ``ends`` the exact (low, high) of each lam piece (empty for one valence)."""
    exact_keys(cert, ("schema", "valence", "prec", "pieces" if isinstance(k, dict) else "parts"), "certificate")
    prec = read_prec(cert)
    if not isinstance(k, dict):
        piece_list = [{"lam": None, "parts": field_of(cert, "parts", dict, "certificate")}]
        _read_parts(piece_list[0]["parts"])
        return prec, piece_list, []
    piece_list = field_of(cert, "pieces", list, "certificate")
    return prec, piece_list, read_lam_pieces(piece_list, _read_parts)



def read_prec(cert):
    """The working precision in bits of a C1 or tagged certificate (``prec``, 64..1024).

    Examples
    --------
    >>> read_prec({"prec": 128})
    128
    >>> read_prec({"prec": 32})
    Traceback (most recent call last):
    ...
    ccproof.certify.verify.errors.CertificateError: prec must lie in 64..1024
    """
    prec = field_of(cert, "prec", int, "certificate")
    if not 64 <= prec <= 1024:
        raise CertificateError("prec must lie in 64..1024")
    return prec

def _read_parts(parts):
    exact_keys(parts, ("regularity", "star"), "parts")
    reg, star = field_of(parts, "regularity", dict, "parts"), field_of(parts, "star", dict, "parts")
    exact_keys(reg, PATCHES, "parts.regularity")
    exact_keys(star, tuple(STAR_CURVES), "parts.star")
    for label, sec, nv in (("regularity", reg, 2), ("star", star, 1)):
        for name, boxes in sec.items():
            read_boxes(boxes, nv, f"parts.{label}.{name}")  # the partition, before any arithmetic


def _check_spectrum(k, ends, prec, part):
    """The derivation, the Fourier blocks, the spectral ordering and (every k >= k0) the lam interval."""
    if not check_derivation(part):
        return False
    ok = check_block_polynomials()
    part("spectrum: Fourier blocks of the rules have the stated characteristic polynomials", ok,
         "exact identities in (x, w) and (x, 1/k)" if ok else "an identity fails")
    if not ok:
        return False
    ok, msg = spectral_ordering(k, prec)
    part("spectral ordering 1 > lam = lam > |lam_3|, lam non-defective", ok, msg)
    if ok and ends:
        ok = lam_interval_ok(k["min"], ends[0][0], ends[-1][1], prec)
        part(f"lam(k) in [{ends[0][0]}, {ends[-1][1]}] for every k >= {k['min']}", ok)
    return ok


def _check_parts(nets, parts, tag, prec, part):
    """Replay the boxes of ``parts.regularity`` (det J_Phi) and ``parts.star`` (the outer curves)."""
    for name in PATCHES:
        ok, msg, mb = check_boxes(regularity_form(nets, name, prec), parts["regularity"][name], f"regularity {name}")
        part(f"{tag}det J_Phi > 0 on {name}", ok, msg or f"min bound {mb} (local s,t)", mb, "regularity")
    for curve in STAR_CURVES:
        ok, msg, mb = check_boxes(star_form(nets, curve, prec), parts["star"][curve], f"star {curve}")
        part(f"{tag}outer boundary star-shaped on {curve}", ok, msg or f"min bound {mb}", mb, "star")
