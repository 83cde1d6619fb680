"""Search the smallest k0 for which the one-certificate argument for every k >= k0 succeeds.

For each k0 (largest first) the script runs the interval prover (lam as a Taylor-model variable,
ccproof.certify.prover.prove_interval)
with at most ``--max-pieces`` lam pieces, and prints success or the reason of failure with the time.

  python scripts/smallest_k0.py --k0 30 20 14 10 --max-pieces 1
"""

from __future__ import annotations

import argparse
import time
from fractions import Fraction


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--k0", type=int, nargs="+", default=[30, 20, 14, 10, 8, 6, 5, 4, 3])
    ap.add_argument("--max-pieces", type=int, default=1)
    ap.add_argument("--truncation-degree", type=int, default=2, help="zeta degree kept in part D (default 2)")
    ap.add_argument("--out", default=None, help="folder to keep the certificates found (default: discard)")
    args = ap.parse_args(argv)

    from ccproof.certify.prover import ProofFailed, certificate_path, claimed_margins, prove_interval, write_certificate

    for k0 in sorted(args.k0, reverse=True):
        t1 = time.perf_counter()
        try:
            cert = prove_interval(k0, progress=False, max_pieces=args.max_pieces,
                                  truncation_degree=args.truncation_degree)
        except ProofFailed as exc:
            print(f"k0 = {k0:3d}: FAILED after {time.perf_counter() - t1:.0f} s: {exc}", flush=True)
            continue
        summary, boxes = claimed_margins(cert)
        s = {k: float(Fraction(v)) for k, v in summary.items()}
        print(f"k0 = {k0:3d}: proved in {time.perf_counter() - t1:.0f} s, "
              f"N = {cert['N']}, {len(cert['pieces'])} piece(s), {boxes} boxes; claimed min bounds: "
              f"det J_Phi {s['min_bound_det_J_phi_local']:.4g}, cells {s['min_bound_det_J_G_cells_local']:.4g}, "
              f"corner {s['min_bound_det_J_G_corner_over_h2']:.4g}", flush=True)
        if args.out:
            write_certificate(cert, certificate_path(cert["valence"], args.out))


if __name__ == "__main__":
    main()
