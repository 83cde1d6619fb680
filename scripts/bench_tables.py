"""Benchmark of the characteristic-map tables (docs/tables.md).

Prints, measured in one run: the time to derive the symbolic nets once, the time per valence to
specialize them exactly (sympy), in arb at 53 and 256 bits and in float64, and the time to build the
whole table set k = 3..100 (+ k >= 40) with 2 worker processes, against the targets (60 s for the
set, 20 s for the symbolic derivation).

    python scripts/bench_tables.py [--kmax 100] [--jobs 2]
"""

import argparse
import importlib
import os
import sys
import tempfile
import time


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--kmax", type=int, default=100)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--smoke", action="store_true",
                    help="k = 3 specialized exactly and in arb, 2 rounds in turn, no table set (the test suite's run)")
    args = ap.parse_args()

    import ccproof.algebra.characteristic_map as cm

    importlib.reload(cm)
    t = time.perf_counter()
    cm.symbolic_bspline_nets()
    cm.symbolic_bezier_nets()
    t_sym = time.perf_counter() - t
    print(f"symbolic derivation of P1, P2, P3 (once):   {t_sym:8.3f} s   (target 20 s)")

    from ccproof.algebra.specialize import characteristic_map_patches

    if args.smoke:
        sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
        from _bench import load, ratio_line

        ratios, loads = [], []
        for r in range(2):
            loads.append(load())
            t = {}
            for arith, prec in (("exact", 128), ("arb", 53)) if r % 2 == 0 else (("arb", 53), ("exact", 128)):
                t0 = time.perf_counter()
                characteristic_map_patches(3, "bezier", arith, prec)
                t[arith] = time.perf_counter() - t0
            ratios.append(t["exact"] / t["arb"])
        print(ratio_line("specialize k = 3, exact/arb53:", ratios, loads))
        return
    for k in (3, 7, 40):
        row = []
        for arith, prec in (("exact", 0), ("arb", 53), ("arb", 256), ("float", 53)):
            t = time.perf_counter()
            characteristic_map_patches(k, "bezier", arith, prec or 128)
            row.append(f"{arith}{prec or ''}: {time.perf_counter() - t:7.3f} s")
        print(f"specialize k = {k:3d}:  " + "   ".join(row))

    from concurrent.futures import ProcessPoolExecutor

    from ccproof.tables.build import DEFAULT_INTERVAL_K0, write_table
    from ccproof.valence import Valence

    ks = [Valence(k) for k in range(3, args.kmax + 1)] + [Valence(DEFAULT_INTERVAL_K0, interval=True)]
    with tempfile.TemporaryDirectory() as d:
        t = time.perf_counter()
        with ProcessPoolExecutor(args.jobs) as ex:
            list(ex.map(write_table, ks, [d] * len(ks)))
        t_all = time.perf_counter() - t
    print(f"whole table set ({len(ks)} tables, {args.jobs} processes): {t_all:8.1f} s   (target 60 s; "
          f"ratio target/measured = {60 / t_all:.2f})")


if __name__ == "__main__":
    main()
