"""C1 certificates (trusted): Reif's criterion for Catmull-Clark at the valence k or every k >= k0: the spectral
ordering (:mod:`.spectrum`), det J_Phi > 0 on layer 0 and a star-shaped outer boundary (the boxes of
``parts.regularity`` and ``parts.star``); why these suffice: docs/appendix_a.md section 9.4."""

from .injectivity import check_pieces, read_parts, read_pieces
from .maps import STAR_CURVES, regularity_form, star_form
from .record import exact_keys, kname, read_prec
from .replay import check_boxes
from .spectrum import check_block_polynomials, spectral_ordering
from .statement import PATCHES

PARTS = (("regularity", PATCHES, 2, regularity_form, "det J_Phi > 0 on"),
         ("star", tuple(STAR_CURVES), 1, star_form, "outer boundary star-shaped on"))


def verify_c1(cert, k, part, log):
    """A C1 certificate for the valence k or every k >= k0 (``{"min": k0}``) into ``part``;
    :class:`.errors.CertificateError` on a malformed one."""
    exact_keys(cert, ("schema", "valence", "prec", "pieces" if isinstance(k, dict) else "parts"), "certificate")
    prec = read_prec(cert)
    pieces, ends = read_pieces(cert, k, lambda parts: read_parts(parts, {s: (keys, n) for s, keys, n, _, _ in PARTS}))
    log(f"C1 certificate for valence {kname(k)} ({prec} bits)")

    def spectrum():
        ok = check_block_polynomials()
        part("spectrum: Fourier blocks of the rules have the stated characteristic polynomials", ok,
             "exact identities in (x, w) and (x, 1/k)" if ok else "an identity fails")
        if ok:
            ok, msg = spectral_ordering(k, prec)
            part("spectral ordering 1 > lam = lam > |lam_3|, lam non-defective", ok, msg)
        return ok

    def check(parts, nets, lam, zn, tag):
        for sec, keys, _, form, what in PARTS:
            for key in keys:
                ok, msg, mb = check_boxes(form(nets, key, prec), parts[sec][key], f"{sec} {key}")
                part(f"{tag}{what} {key}", ok, msg or f"min bound {mb}", mb, sec)
    check_pieces(k, pieces, ends, prec, 3, 1, check, part, spectrum)
