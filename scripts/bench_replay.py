"""Benchmark of the verifier's box replay: time and memory per box on the largest form it splits.

Builds the corner form of part E for valence 5 (degrees (4, 2, 41, 41), 26,460 arb coefficients, the
largest form a certificate makes the verifier split), partitions its box into 2^DEPTH boxes (complete
tree, axes cycled as the prover does) with a bound below the form's minimum, and replays the partition
with ``check_boxes`` (depth-first, one form per level) and with the replay it replaced (a cache of
every split form, keyed by path prefix), alternating round by round. Prints per round the CPU
seconds of each, min, median and max of their ratio, the peak traced memory of each (measured once,
apart from the timing) and the load.

    python scripts/bench_replay.py [--depth 6] [--rounds 3] [--prec 128] [--smoke]
"""

import argparse
import os
import sys
import time
import tracemalloc
from pathlib import Path

from flint import ctx

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _bench import load, ratio_line  # noqa: E402


def cached_replay(root, boxes):
    """The replay before the depth-first one: every split form kept in a dict keyed by its path."""
    from ccproof.certify.verify.replay import parse_decimal, parse_path

    cache = {"": root}
    for b in boxes:
        bound = parse_decimal(b["bound"])
        key, f = "", root
        for a, side in parse_path(b["path"], root.nvars):
            key += f"{a}{side}"
            if key not in cache:
                lo, hi = f.split(a)
                cache[key[:-2] + f"{a}L"], cache[key[:-2] + f"{a}H"] = lo, hi
            f = cache[key]
        if not all(c.is_finite() and c > bound for c in f.coeffs):
            return False
    return True


def cpu_seconds(fn):
    t = time.process_time()
    ok = fn()
    return ok, time.process_time() - t


def peak_bytes(fn):
    """Peak of Python's traced allocations (the arb balls are Python objects); traced apart from the
    timing, which tracemalloc would slow down several-fold."""
    tracemalloc.start()
    fn()
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    return peak


def form_bytes(root):
    tracemalloc.start()
    lo, hi = root.split(2)
    size = tracemalloc.get_traced_memory()[0]
    tracemalloc.stop()
    return size / 2


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--depth", type=int, default=6, help="2^DEPTH boxes (default 64)")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--prec", type=int, default=128)
    ap.add_argument("--smoke", action="store_true", help="depth 1, 2 rounds (the test suite's run)")
    args = ap.parse_args(argv)
    if args.smoke:
        args.depth, args.rounds = 1, 2
    from ccproof.certify.verify.maps import corner_det_form
    from ccproof.certify.verify.replay import check_boxes
    from ccproof.certify.verify.statement import c_lam, nets_for_valence

    nets = nets_for_valence(5, args.prec)
    with ctx.workprec(args.prec):
        root = corner_det_form(nets, c_lam(5, args.prec)[1], 3, "P2", args.prec)
        paths = [""]
        for d in range(args.depth):
            a = (2, 3, 0, 1)[d % 4]
            paths = [p + f"{a}{s}" for p in paths for s in "LH"]
        boxes = [{"path": p, "bound": "0.07"} for p in paths]  # the published bound is 0.0755
        print(f"corner form P2, k = 5: {len(root.coeffs)} coefficients, {args.prec} bits; {len(boxes)} boxes "
              f"(depth {args.depth}, {len(boxes) - 1} splits)")
        rt, loads = [], []
        for r in range(args.rounds):  # the order alternates round by round
            loads.append(load())
            if r % 2:
                ok_old, t_old = cpu_seconds(lambda: cached_replay(root, boxes))
            ok_new, t_new = cpu_seconds(lambda: check_boxes(root, boxes, "bench")[0])
            if not r % 2:
                ok_old, t_old = cpu_seconds(lambda: cached_replay(root, boxes))
            assert ok_new and ok_old
            rt.append(t_old / t_new)
            print(f"round {r}: depth-first {t_new:.2f} s CPU ({1e3 * t_new / (len(boxes) - 1):.0f} ms per split); "
                  f"cached {t_old:.2f} s ({1e3 * t_old / (len(boxes) - 1):.0f} ms per split)")
        m_new = peak_bytes(lambda: check_boxes(root, boxes, "bench"))
        m_old = peak_bytes(lambda: cached_replay(root, boxes))
    print(ratio_line("time cached / depth-first:", rt, loads))
    print(f"peak traced memory: depth-first {m_new / 2**20:.1f} MiB, cached {m_old / 2**20:.1f} MiB "
          f"(ratio {m_old / m_new:.1f}); one form {form_bytes(root) / 2**20:.2f} MiB")
    print(f"load average: {' '.join(f'{x:.2f}' for x in os.getloadavg())}")


if __name__ == "__main__":
    main()
