"""Re-check certificates with the small trusted verifier.

  ccproof verify certificates/injectivity/k005.json
  ccproof verify --all            every published certificate (certificates/c1/ and certificates/injectivity/),
                                  then the valence coverage of each statement: both the C1 and the
                                  injectivity (Appendix A) certificates must cover every k >= 3
                                  (k = 3..k0-1 one by one, each once; interval certificates k >= k0
                                  may overlap each other and single valences); per tagged family
                                  (dart, crease, corner) which N are certified C1 and not C1, each
                                  configuration at most once, and every crease:1-100, corner:1-100,
                                  dart:2-100 certified or one of the undecided (docs/tagged_c1.md), and
                                  every N >= 101 of crease and corner ('crease:>=101', 'corner:>=101')
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
from pathlib import Path


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
    """The JSON object of one verdict (``--json``): configuration, statement, verdict, parts.

    >>> from ccproof.certify.verify import VerifyResult, Part
    >>> summary(VerifyResult(path="k005.json", schema="ccproof.c1/2", valence=5, parts=[Part("S", True)]))["statement"]
    'C1'
    """
    from ccproof.certify.verify import C1_SCHEMA, SCHEMA, TAGGED_SCHEMA

    v = res.valence
    if res.schema == TAGGED_SCHEMA:  # the statement the verifier checked, as the file states it
        config = v if isinstance(v, str) else None
        try:
            statement = json.loads(Path(res.path).read_text()).get("statement") if res.path else None
        except (OSError, ValueError, AttributeError):
            statement = None
        statement = statement if statement in ("C1", "not C1") else None
    else:
        config = None if v is None else f"smooth:>={v['min']}" if isinstance(v, dict) else f"smooth:{v}"
        statement = {SCHEMA: "injective", C1_SCHEMA: "C1"}.get(res.schema)
    return {"path": res.path, "configuration": config, "statement": statement,
            "verdict": "VERIFIED" if res.ok else "FAILED", "error": res.error, "seconds": round(res.seconds, 3),
            "parts": [{"name": p.name, "ok": p.ok, "message": p.message} for p in res.parts]}


def _check(args):
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


# The tagged configurations that verify --all requires, per family: every N (K for darts) in the range has
# a verified certificate ("C1" or "not C1") or is one of the undecided configurations of docs/tagged_c1.md
# (a Jordan block among lam1, lam2; dart:2, lam2 < 0).
TAGGED_TARGET = {"dart": (2, 100), "crease": (1, 100), "corner": (1, 100)}
TAGGED_UNDECIDED = {"dart": (2,), "crease": (1, 4), "corner": (2, 4)}
# the families whose every N must be covered: a certificate FAMILY:>=N0 (N0 at most the range's end + 1)
TAGGED_EVERY = ("dart", "crease", "corner")


def tagged_coverage(results):
    """(ok, lines): per tagged family, the N certified C1 and not C1; ok unless a configuration has two
    verified certificates (a statement and its negation, or a publishing mistake) or an N of
    :data:`TAGGED_TARGET` is neither certified nor one of :data:`TAGGED_UNDECIDED`; for the families of
    :data:`TAGGED_EVERY` every N: a verified ``FAMILY:>=N0`` with N0 at most the range's end + 1 (its
    statement must agree with every single certificate of an N >= N0).

    >>> from ccproof.certify.verify import VerifyResult, Part
    >>> r = VerifyResult(schema="ccproof.tagged-c1/1", valence="crease:5", parts=[Part("S", True)])
    >>> ok, lines = tagged_coverage([r, r])
    >>> ok, lines[1][:40]
    (False, 'crease: CONTRADICTORY: certified twice: ')
    >>> tagged_coverage([r])[1][1][:60]
    'crease: INCOMPLETE: no certificate for 2-3, 6-100, >= 101; C'
    """
    ok_all, lines = True, []
    for fam in ("dart", "crease", "corner"):
        rows, tails = [], []
        for r in results:
            if r and isinstance(r.valence, str) and r.valence.startswith(fam + ":"):
                n, st = r.valence.split(":")[1], summary(r)["statement"]
                if n.startswith(">="):
                    tails.append((int(n[2:]), st))
                else:
                    rows.append((int(n), st))
        ns = [n for n, _ in rows]
        twice = sorted({n for n in ns if ns.count(n) > 1})
        lo, hi = TAGGED_TARGET[fam]
        n0 = min((t for t, _ in tails), default=None)
        end = hi if n0 is None else min(hi, n0 - 1)
        missing = [n for n in range(lo, end + 1) if n not in ns and n not in TAGGED_UNDECIDED[fam]]
        clash = sorted(n for n, st in rows for t, st_t in tails if n >= t and st != st_t)
        every = fam in TAGGED_EVERY
        c1, not_c1 = (sorted(n for n, st in rows if st == want) for want in ("C1", "not C1"))
        c1 = _ranges(c1) + "".join(f", >= {t}" for t, st in sorted(tails) if st == "C1")
        not_c1 = _ranges(not_c1) + "".join(f", >= {t}" for t, st in sorted(tails) if st == "not C1")
        gap = [] if n0 is not None and n0 <= hi + 1 or not every else [f">= {hi + 1}"]
        status = (f"CONTRADICTORY: certified twice: {twice or clash}; " if twice or clash else
                  f"INCOMPLETE: no certificate for {', '.join(filter(None, [_ranges(missing)] + gap))}; "
                  if missing or gap else f"OK ({fam}:{lo}-{hi}{', every N' if every else ''}): ")
        lines.append(f"{fam}: {status}C1 for {c1.lstrip(', ') or 'none'}, not C1 for {not_c1.lstrip(', ') or 'none'}; "
                     f"undecided: {_ranges(list(TAGGED_UNDECIDED[fam]))} (docs/tagged_c1.md lists the reasons)")
        ok_all &= not twice and not clash and not missing and not gap
    return ok_all, lines


def _ranges(ns):
    """``[1, 2, 3, 5]`` -> ``'1-3, 5'``."""
    out, i = [], 0
    while i < len(ns):
        j = i
        while j + 1 < len(ns) and ns[j + 1] == ns[j] + 1:
            j += 1
        out.append(str(ns[i]) if i == j else f"{ns[i]}-{ns[j]}")
        i = j + 1
    return ", ".join(out)


def run(args):
    from pathlib import Path

    from ccproof.certify.verify import certificate_files, check_coverage
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
    sweep = run_tasks(_check, work, scheduler_from_args(args), desc="verify", unit="file", priority=size,
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
    if args.all:
        ok_all = True
        for label, schema in (("C1 (Reif)", "ccproof.c1/2"), ("injectivity (Appendix A)", "ccproof.injectivity/3")):
            ok, msg = check_coverage([r.valence for r in results if r and r.schema == schema])
            print(f"{label} coverage: {'OK' if ok else 'INCOMPLETE'}: {msg}")
            ok_all &= ok
        ok, lines = tagged_coverage(results)
        print("\n".join(lines))
        ok_all &= ok
        if not ok_all:
            return 1
    return 0 if not bad else 1
