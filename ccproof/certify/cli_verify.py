"""Re-check certificates with the small trusted verifier.

  ccproof verify certificates/injectivity/k005.json
  ccproof verify --all            every published certificate (certificates/c1/ and certificates/injectivity/),
                                  then the valence coverage of each statement: both the C1 and the
                                  injectivity (Appendix A) certificates must cover every k >= 3
                                  exactly once (k = 3..k0-1 one by one, k >= k0 in one certificate)
  ccproof verify --all --jobs 2   the same on 2 processes

The verifier (ccproof/certify/verify/, listed in docs/trusted_base.md) imports nothing from the prover
and reads no table: it derives each statement (c, lam, the eigenvector, the nets, the spectrum and every
hypothesis) from the valence and the Catmull-Clark rules, recomputes every Bernstein coefficient in arb,
replays each box's split path and checks each claimed bound and that the boxes partition each domain
exactly. It prints PASS/FAIL per part and VERIFIED only when every part passed; a malformed file ends in
FAILED with the reason and the others are still checked; the exit status is 0 only when all passed.
"""

from __future__ import annotations


def add_arguments(p):
    p.add_argument("files", nargs="*", help="certificate files")
    p.add_argument("--all", action="store_true", help="verify every published certificate and the coverage")
    p.add_argument("--jobs", type=int, default=1, help="worker processes (default 1)")
    p.add_argument("--quiet", action="store_true", help="print only the VERIFIED/FAILED line per file")


def _check(args):
    path, quiet = args
    from ccproof.certify.verify import verify_file

    lines = []
    res = verify_file(path, log=lines.append)
    if quiet:
        lines = [s for s in lines if s.startswith(("VERIFIED", "FAILED"))]
    return res, lines


def run(args):
    from pathlib import Path

    from ccproof.certify.verify import certificate_files, check_coverage
    from ccproof.errors import CCProofError
    from ccproof.tables.format import certificates_dir

    files = [Path(f) for f in args.files]
    if args.all:
        files += certificate_files(certificates_dir())
    if not files:
        raise CCProofError("give certificate files or --all")
    work = [(f, args.quiet) for f in files]
    if args.jobs > 1 and len(files) > 1:
        from concurrent.futures import ProcessPoolExecutor

        # longest first (the k >= k0 certificates), so the two workers finish together
        order = sorted(range(len(work)), key=lambda i: -work[i][0].stat().st_size if work[i][0].exists() else 0)
        with ProcessPoolExecutor(max_workers=args.jobs) as ex:
            done = dict(zip(order, ex.map(_check, [work[i] for i in order])))
        outcome = [done[i] for i in range(len(work))]
        for _, lines in outcome:
            print("\n".join(lines))
    else:
        outcome = []
        for w in work:
            res, lines = _check(w)
            print("\n".join(lines))
            outcome.append((res, lines))
    results = [r for r, _ in outcome]
    bad = [r for r in results if not r]
    print(f"{len(results) - len(bad)} of {len(results)} certificates verified" + (
        "" if not bad else "; failed: " + ", ".join(str(r.path) for r in bad)))
    if args.all:
        ok_all = True
        for label, schema in (("C1 (Reif)", "ccproof.c1/2"), ("injectivity (Appendix A)", "ccproof.injectivity/2")):
            ok, msg = check_coverage([r.valence for r in results if r and r.schema == schema])
            print(f"{label} coverage: {'OK' if ok else 'INCOMPLETE'}: {msg}")
            ok_all &= ok
        if not ok_all:
            return 1
    return 0 if not bad else 1
