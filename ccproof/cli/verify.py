"""Re-check certificates with the small trusted verifier.

  ccproof verify certificates/injectivity/k005.json
  ccproof verify --all            every published certificate (certificates/c1/ and certificates/injectivity/),
                                  then the coverage, decided by the verifier from its verdicts
                                  (ccproof.certify.verify.registry.coverage): both the C1 and the
                                  injectivity (Appendix A) certificates must cover every k >= 3
                                  (k = 3..k0-1 one by one, each once; interval certificates k >= k0
                                  may overlap each other and single valences); per tagged family
                                  (dart, crease, corner) which N are certified C1 and not C1, each
                                  configuration at most once, every crease:1-100, corner:1-100,
                                  dart:2-100 certified or one of the undecided (shown with the reason),
                                  and every N >= 101 ('crease:>=101', 'corner:>=101', 'dart:>=101')
  ccproof verify FILE --json     one JSON object per file: "configuration" ("smooth:5", "smooth:>=40",
                                  "crease:5", "crease:>=101"), "statement" ("C1", "not C1", "injective"),
                                  "verdict" ("VERIFIED" or "FAILED"), "parts" (name, ok, message), "error"
  ccproof verify --all            runs on a local Dask cluster (one worker per core) by default;
  ccproof verify --all --serial   in this process; --scheduler local:2 | tcp://host:8786 elsewhere
                                  (the workers read the files: a remote cluster needs them on a shared
                                  file system, docs/scale-out.md)

The verifier (ccproof/certify/verify/, listed in docs/trusted_base.md) imports nothing from the prover
and reads no table: it derives each statement (c, lam, the eigenvector, the nets, the spectrum and every
hypothesis) from the valence and the Catmull-Clark rules, recomputes every Bernstein coefficient in arb,
replays each box's split path and checks each claimed bound and that the boxes partition each domain
exactly. It prints PASS/FAIL per part and VERIFIED only when every part passed; a malformed file ends in
FAILED with the reason and the others are still checked; the exit status is 0 only when all passed.
"""

from __future__ import annotations

import json


def add_arguments(p):
    p.add_argument("files", nargs="*", help="certificate files")
    p.add_argument("--all", action="store_true", help="verify every published certificate and the coverage")
    p.add_argument("--jobs", type=int, default=None, help="same as --scheduler local:JOBS (kept for old scripts)")
    from ccproof.scale.engine import add_scheduler_arguments

    add_scheduler_arguments(p)
    p.add_argument("--quiet", action="store_true", help="print only the VERIFIED/FAILED line per file")
    from ccproof.cli._progress import add_progress_argument

    add_progress_argument(p)
    p.add_argument("--json", action="store_true",
                   help="print one JSON object per file (configuration, statement, verdict, parts) instead")


def summary(res):
    """The JSON object of one verdict (``--json``): configuration, statement, verdict, parts, all as the
    verifier recorded them in ``res`` (nothing is read from the file again).

    >>> from ccproof.certify.verify import VerifyResult, Part
    >>> r = VerifyResult(path="k005.json", family="smooth", valence=5, statement="C1", parts=[Part("S", True)])
    >>> s = summary(r)
    >>> s["configuration"], s["statement"], s["verdict"]
    ('smooth:5', 'C1', 'VERIFIED')
    """
    return {"path": res.path, "configuration": res.configuration, "statement": res.statement,
            "verdict": "VERIFIED" if res.ok else "FAILED", "error": res.error, "seconds": round(res.seconds, 3),
            "parts": [{"name": p.name, "ok": p.ok, "message": p.message} for p in res.parts]}


def verify_task(args):
    """One task: verify a file; ``args`` is ``(path, quiet)`` or ``(absolute path, quiet, name shown)``."""
    path, quiet, *shown = args
    from ccproof.certify.verify import verify_file

    lines = []
    res = verify_file(path, log=lines.append)
    if shown and shown[0] != path:  # the worker read the absolute path; the lines name the file as given
        lines = [line.replace(str(path), shown[0], 1) for line in lines]
    if quiet:
        lines = [s for s in lines if s.startswith(("VERIFIED", "FAILED"))]
    return res, lines


def run(args):
    from pathlib import Path

    from ccproof.certify.verify import certificate_files, coverage
    from ccproof.errors import CCProofError
    from ccproof.tables.format import certificates_dir

    as_json = getattr(args, "json", False)  # callers that build their own args may omit it
    files = [Path(f) for f in args.files]
    if args.all:
        files += certificate_files(certificates_dir())
    if not files:
        raise CCProofError("give certificate files or --all")
    from ccproof.certify.verify import VerifyResult
    from ccproof.cli._progress import progress_enabled
    from ccproof.scale.engine import run_tasks, scheduler_from_args

    # absolute paths for the workers (a worker of a cluster may run in another folder)
    work = [(str(f.absolute()), args.quiet, str(f)) for f in files]
    # longest first (the k >= k0 certificates), so that the workers finish together
    size = [f.stat().st_size if f.is_file() else 0 for f in files]
    sweep = run_tasks(verify_task, work, scheduler_from_args(args), desc="verify", unit="file", priority=size,
                      names=[str(f) for f in files], raise_errors=False, progress=progress_enabled(args))
    results = []
    for f, out in zip(files, sweep.results):
        if out is None:  # the task itself failed (after its retries): reported, counted as FAILED
            res = VerifyResult(path=str(f), error=f"not checked: {sweep.errors[len(results)]!r}")
            print(json.dumps(summary(res)) if as_json else f"FAILED {f}: {res.error}")
        else:
            res, lines = out
            res.path = str(f)  # as given (the worker read the absolute path)
            print(json.dumps(summary(res)) if as_json else "\n".join(lines))
        results.append(res)
    for line in [] if as_json else sweep.report([str(f) for f in files]):
        print(line)
    bad = [r for r in results if not r]
    if as_json:
        return 0 if not bad else 1
    print(f"{len(results) - len(bad)} of {len(results)} certificates verified" + (
        "" if not bad else "; failed: " + ", ".join(str(r.path) for r in bad)))
    if args.all:  # decided in the trusted base from the verdicts above (ccproof.certify.verify.registry)
        ok_all, lines = coverage(results)
        print("\n".join(lines))
        if not ok_all:
            return 1
    return 0 if not bad else 1
