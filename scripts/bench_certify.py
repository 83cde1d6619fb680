"""Benchmark of the certificates.

Certifies each valence of a range with a process pool (certify runs are independent), then verifies
every certificate written, and prints per valence: N, boxes, certify seconds, verify seconds, and the
totals (wall clock) with the ratio certify/verify, against the targets (all of 3..39 certified in
<= 10 min and verified in <= 2 min on 2 cores; verification >= 3x faster than certification).

    python scripts/bench_certify.py [--kmin 3] [--kmax 39] [--jobs 2]
    python scripts/bench_certify.py --interval 40     the one certificate for every k >= 40
                                                       (targets certify <= 5 min, verify <= 1 min)
    python scripts/bench_certify.py --verify-all      `ccproof verify --all` on 2 processes (target
                                                       <= 90 s), and the share of the statement derivation
    python scripts/bench_certify.py --verify-all --before DIR --rounds 2
                                                      `ccproof verify --all --jobs JOBS` of this tree against
                                                      the checkout DIR of an earlier revision (its own
                                                      certificates), alternating round by round: the ratio
                                                      (this) / (before) as min, median, max, load
    python scripts/bench_certify.py --tagged 2        what the tagged certificates (certificates/c1/{dart,
                                                       crease,corner}/) add to `verify --all`: the smooth
                                                       ones and the tagged ones verified on JOBS fresh
                                                       processes, alternating, ROUNDS rounds: the ratio
                                                       (all) / (smooth) (target <= 2), per family seconds
    python scripts/bench_certify.py --dart-budget     the published dart:>=101 record and the costliest ones the
                                                       work budget admits (one declared size raised to the
                                                       largest value within it, the last map leaf false), each
                                                       verified in a fresh process: declared work, verdict,
                                                       CPU seconds (target: every one under 10 s)

Certificates go to a temporary folder; the published ones are not touched.
"""

import argparse
import os
import sys
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor


def _certify(args):
    k, d = args
    from ccproof.certify.prover import certificate_path, prove_valence, write_certificate

    t = time.perf_counter()
    cert = prove_valence(k, progress=False)
    dt = time.perf_counter() - t
    write_certificate(cert, certificate_path(k, d))
    return k, cert["N"], sum(len(v) for sec in cert["parts"].values() for v in sec.values()), dt


def _verify(args):
    k, d = args
    from ccproof.certify.prover import certificate_path
    from ccproof.certify.verify import verify_file

    t = time.perf_counter()
    ok = verify_file(certificate_path(k, d), log=lambda s: None)
    return k, ok, time.perf_counter() - t


def smoke():
    """The test suite's run: valence 3 certified and verified in this process, once; the ratio."""
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    from _bench import load, ratio_line

    ratios, loads = [], []
    with tempfile.TemporaryDirectory() as d:
        for _ in range(1):
            loads.append(load())
            _, N, boxes, tc = _certify((3, d))
            _, ok, tv = _verify((3, d))
            if not ok:
                raise SystemExit("valence 3: the certificate written does not verify")
            ratios.append(tc / tv)
    print(f"valence 3: N = {N}, {boxes} boxes, certify {tc:.2f} s, verify {tv:.2f} s")
    print(ratio_line("valence 3 certify/verify:", ratios, loads))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--kmin", type=int, default=3)
    ap.add_argument("--kmax", type=int, default=39)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--interval", type=int, default=None, metavar="K0", help="bench the k >= K0 certificate")
    ap.add_argument("--verify-all", action="store_true", help="time `ccproof verify --all --jobs JOBS`")
    ap.add_argument("--tagged", type=int, default=None, metavar="ROUNDS",
                    help="what the tagged certificates add to verify --all (ROUNDS alternating rounds)")
    ap.add_argument("--before", default=None, metavar="DIR",
                    help="with --verify-all: a checkout of an earlier revision to compare against")
    ap.add_argument("--rounds", type=int, default=2, help="with --before: alternating rounds")
    ap.add_argument("--smoke", action="store_true", help="valence 3, in this process (the test suite's run)")
    ap.add_argument("--dart-budget", action="store_true", help="the costliest dart:>=101 records within the budget")
    args = ap.parse_args()
    if args.dart_budget:
        return bench_dart_budget()
    if args.verify_all and args.before:
        return bench_verify_all_against(args.before, args.jobs, args.rounds)
    if args.smoke:
        return smoke()
    if args.tagged is not None:
        return bench_tagged(args.jobs, args.tagged)
    if args.verify_all:
        return bench_verify_all(args.jobs)
    if args.interval is not None:
        return bench_interval(args.interval)
    ks = list(range(args.kmin, args.kmax + 1))
    with tempfile.TemporaryDirectory() as d:
        t0 = time.perf_counter()
        with ProcessPoolExecutor(args.jobs) as ex:
            cert = {k: (N, b, dt) for k, N, b, dt in ex.map(_certify, [(k, d) for k in ks])}
        t_cert = time.perf_counter() - t0
        t0 = time.perf_counter()
        with ProcessPoolExecutor(args.jobs) as ex:
            ver = {k: (ok, dt) for k, ok, dt in ex.map(_verify, [(k, d) for k in ks])}
        t_ver = time.perf_counter() - t0
    print(f"{'k':>4} {'N':>2} {'boxes':>6} {'certify s':>10} {'verify s':>9} {'ratio':>6}  verified")
    for k in ks:
        N, b, tc = cert[k]
        ok, tv = ver[k]
        print(f"{k:>4} {N:>2} {b:>6} {tc:>10.2f} {tv:>9.2f} {tc / tv:>6.2f}  {ok}")
    print(f"all {ks[0]}..{ks[-1]} with {args.jobs} processes: certify {t_cert:.1f} s (target 600 s), "
          f"verify {t_ver:.1f} s (target 120 s), certify/verify = {t_cert / t_ver:.2f} (target >= 3)")
    print(f"failures: {[k for k in ks if not ver[k][0]]}")


def bench_interval(k0):
    from ccproof.certify.prover import certificate_path, prove_interval, write_certificate
    from ccproof.certify.verify import verify_file

    with tempfile.TemporaryDirectory() as d:
        t = time.perf_counter()
        cert = prove_interval(k0, progress=False)
        tc = time.perf_counter() - t
        path = write_certificate(cert, certificate_path(cert["valence"], d))
        t = time.perf_counter()
        ok = verify_file(path, log=lambda s: None)
        tv = time.perf_counter() - t
    boxes = sum(len(v) for pc in cert["pieces"] for sec in pc["parts"].values() for v in sec.values())
    print(f"k >= {k0}: {len(cert['pieces'])} lam piece(s), {boxes} boxes; "
          f"certify {tc:.1f} s (target 300 s), verify {tv:.1f} s (target 60 s), certify/verify = {tc / tv:.2f}; "
          f"verified: {ok}")


def _derivation_seconds(_):
    t = time.perf_counter()
    from ccproof.certify.verify.spectrum import check_block_polynomials
    from ccproof.certify.verify.statement import derivation

    derivation()
    check_block_polynomials()
    return time.perf_counter() - t


def _verify_path(path):
    from ccproof.certify.verify import verify_file

    t = time.perf_counter()
    ok = bool(verify_file(path, log=lambda s: None))
    return path, ok, time.perf_counter() - t


def bench_tagged(jobs, rounds):
    """Wall clock of verifying the smooth certificates and the tagged ones, each on ``jobs`` fresh
    processes, alternating round by round; prints min, median, max of (smooth + tagged) / smooth."""
    import os
    import statistics
    from pathlib import Path

    from ccproof.certify.verify import certificate_files
    from ccproof.tables.format import certificates_dir

    # largest file first, as `ccproof verify --all` schedules them (so that the workers finish together)
    files = sorted((str(f) for f in certificate_files(certificates_dir())), key=lambda f: -Path(f).stat().st_size)
    tagged = [f for f in files if Path(f).parent.name in ("dart", "crease", "corner")]
    smooth = [f for f in files if f not in tagged]
    ratios, fam_s, loads = [], {}, []
    for r in range(rounds):
        wall = {}
        for name, group in (("smooth", smooth), ("tagged", tagged)):
            loads.append(os.getloadavg()[0])
            t = time.perf_counter()
            with ProcessPoolExecutor(jobs) as ex:
                res = list(ex.map(_verify_path, group))
            wall[name] = time.perf_counter() - t
            assert all(ok for _, ok, _ in res), [p for p, ok, _ in res if not ok]
            if name == "tagged":
                for p, _, dt in res:
                    fam_s.setdefault(Path(p).parent.name, []).append(dt)
        ratios.append((wall["smooth"] + wall["tagged"]) / wall["smooth"])
        print(f"round {r}: smooth {len(smooth)} files {wall['smooth']:.1f} s, tagged {len(tagged)} files "
              f"{wall['tagged']:.1f} s, (all) / (smooth) = {ratios[-1]:.2f}")
    print(f"(all) / (smooth) over {rounds} rounds: min {min(ratios):.2f}, median {statistics.median(ratios):.2f}, "
          f"max {max(ratios):.2f} (target <= 2); load average {min(loads):.1f}..{max(loads):.1f}")
    for fam, ts in sorted(fam_s.items()):
        print(f"  {fam}: {len(ts) // rounds} files, {sum(ts) / rounds:.1f} s of process time per round, "
              f"max {max(ts):.1f} s")


def bench_verify_all(jobs):
    """Wall clock of `ccproof verify --all --jobs JOBS` (fresh processes, derivation included), and the
    derivation's cost per worker process measured alone."""
    import subprocess
    import sys

    t = time.perf_counter()
    out = subprocess.run([sys.executable, "-m", "ccproof.cli", "verify", "--all", "--quiet", "--jobs", str(jobs)],
                         capture_output=True, text=True)
    total = time.perf_counter() - t
    with ProcessPoolExecutor(1) as ex:
        deriv = ex.submit(_derivation_seconds, None).result()
    tail = out.stdout.strip().splitlines()[-3:]
    print("\n".join(tail))
    print(f"verify --all with {jobs} processes: {total:.1f} s (target 90 s); statement derivation {deriv:.2f} s "
          f"per worker process ({jobs} x {deriv:.2f} s = {100 * jobs * deriv / (jobs * total):.1f} % of the "
          f"{jobs} x {total:.1f} s of process time); exit status {out.returncode}")


def _verify_all_seconds(tree, jobs):
    """Wall clock of `ccproof verify --all --quiet --jobs JOBS` run from the package under ``tree`` (None: this
    one), a fresh process; the run must end with exit status 0."""
    import subprocess

    env = dict(os.environ)
    if tree is not None:
        env["PYTHONPATH"] = os.pathsep.join([str(tree), env.get("PYTHONPATH", "")])
    code = "import sys; from ccproof.cli import main; sys.exit(main(sys.argv[1:]))"
    t = time.perf_counter()
    out = subprocess.run([sys.executable, "-c", code, "verify", "--all", "--quiet", "--jobs", str(jobs)],
                         capture_output=True, text=True, env=env, cwd=tempfile.gettempdir())
    if out.returncode != 0:
        raise SystemExit(f"verify --all ({tree or 'this tree'}) failed:\n{out.stdout[-2000:]}{out.stderr[-2000:]}")
    return time.perf_counter() - t, out.stdout.strip().splitlines()[-1]


def bench_verify_all_against(before, jobs, rounds):
    """(this) / (before) for `verify --all --jobs JOBS`, alternating which runs first round by round."""
    from _bench import ratio_line

    ratios, loads = [], []
    for r in range(rounds):
        order = [None, before] if r % 2 else [before, None]
        wall = {}
        for tree in order:
            loads.append(os.getloadavg()[0])
            wall[tree], last = _verify_all_seconds(tree, jobs)
            print(f"round {r}: {'before' if tree else 'this'} {wall[tree]:.1f} s ({last})", flush=True)
        ratios.append(wall[None] / wall[before])
    print(ratio_line(f"verify --all --jobs {jobs}, (this) / (before):", ratios, loads))


DART_SIZES = (("taylor", "disc_grid"), ("spectrum", "sigma_h"), ("spectrum", "mode0_h"), ("taylor", "order"),
              ("taylor", "layer_order"), ("taylor", "exp_order"))
_CPU_CHILD = r"""
import json, resource, sys
from ccproof.certify.verify import verify_file
lines = []
res = verify_file(sys.argv[1], log=lines.append)
use = resource.getrusage(resource.RUSAGE_SELF)
print(json.dumps({"ok": bool(res), "fail": [s for s in lines if "FAIL " in s][:1], "cpu": use.ru_utime + use.ru_stime}))
"""


def _declared(cert):
    """The declared work of a dart:>=101 record, or None where it is refused (past the budget)."""
    from ccproof.certify.verify import CertificateError
    from ccproof.certify.verify.dart_tail import read_record, record_work

    try:
        return record_work(read_record(cert, 101))
    except CertificateError:
        return None


def _largest_within(cert, section, key):
    """Raise cert[section][key] to the largest value whose declared work is within the budget (in place)."""
    lo, hi = cert[section][key], None
    step = 1
    while hi is None:
        cert[section][key] = lo + step
        if _declared(cert) is None:
            hi = lo + step
        else:
            lo, step = lo + step, 2 * step
    while hi - lo > 1:
        cert[section][key] = (lo + hi) // 2
        lo, hi = (cert[section][key], hi) if _declared(cert) is not None else (lo, cert[section][key])
    cert[section][key] = lo
    return lo


def bench_dart_budget():
    """The published dart:>=101 record and, per declared size, the costliest record within the budget with its
    last map leaf false, each verified in a fresh process (CPU seconds, getrusage)."""
    import copy
    import json
    import subprocess

    from ccproof.certify.verify.dart_tail import MAX_WORK
    from ccproof.tables.format import certificates_dir

    published = json.loads((certificates_dir() / "c1" / "dart" / "k_ge_101.json").read_text())
    cases = [("published", published)]
    for section, key in DART_SIZES:
        c = copy.deepcopy(published)
        v = _largest_within(c, section, key)
        c["parts"]["winding"]["Y<0 layer"]["2"][-1]["leaves"][-1]["bound"] = "-1e3"
        cases.append((f"{key} = {v}, last leaf false", c))
    with tempfile.TemporaryDirectory() as d:
        for name, cert in cases:
            path = os.path.join(d, "record.json")
            with open(path, "w") as f:
                json.dump(cert, f)
            load = os.getloadavg()[0]
            out = subprocess.run([sys.executable, "-c", _CPU_CHILD, path], capture_output=True, text=True,
                                 cwd=tempfile.gettempdir())
            res = json.loads(out.stdout.strip().splitlines()[-1])
            verdict = "VERIFIED" if res["ok"] else "FAILED ..." + (res["fail"] or ["?"])[0].strip()[-70:]
            print(f"{name}: declared {_declared(cert):,} of {MAX_WORK:,} units, {res['cpu']:.1f} s CPU (load "
                  f"{load:.1f}): {verdict}", flush=True)


if __name__ == "__main__":
    main()
