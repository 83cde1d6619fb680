"""Re-check injectivity certificates with the small trusted verifier.

  ccproof verify certificates/injectivity/k005.json
  ccproof verify --all            every certificate under certificates/injectivity/ and certificates/c1/,
                                  then the valence coverage of each statement: both the C1 and the
                                  injectivity (Appendix A) certificates must cover every k >= 3
                                  exactly once (k = 3..k0-1 one by one, k >= k0 in one certificate)

The verifier (ccproof/certify/verify.py) imports nothing from the prover: it checks the table hash,
recomputes every Bernstein coefficient in arb from the table, replays each box's split path,
checks each claimed bound and that the boxes partition each domain exactly. It prints PASS/FAIL
per part and VERIFIED only when every part passed; the exit status is 0 only then.
"""

from __future__ import annotations


def add_arguments(p):
    p.add_argument("files", nargs="*", help="certificate files")
    p.add_argument("--all", action="store_true", help="verify every certificate in certificates/injectivity")
    p.add_argument("--quiet", action="store_true", help="print only the VERIFIED/FAILED line per file")


def run(args):
    from pathlib import Path

    from ccproof.certify.verify import verify_file
    from ccproof.errors import CCProofError
    from ccproof.tables.format import certificates_dir

    files = [Path(f) for f in args.files]
    if args.all:
        files += sorted((certificates_dir() / "injectivity").glob("k*.json"))
        files += sorted((certificates_dir() / "c1").glob("k*.json"))
    if not files:
        raise CCProofError("give certificate files or --all")
    log = (lambda s: print(s) if s.startswith(("VERIFIED", "FAILED")) else None) if args.quiet else print
    bad = [f for f in files if not verify_file(f, log=log)]
    print(f"{len(files) - len(bad)} of {len(files)} certificates verified" + (
        "" if not bad else "; failed: " + ", ".join(str(b) for b in bad)))
    if args.all:
        import json

        from ccproof.certify.verify import check_coverage

        good = [json.loads(f.read_text()) for f in files if f not in bad]
        ok_all = True
        for label, schema in (("C1 (Reif)", "ccproof.c1/1"), ("injectivity (Appendix A)", "ccproof.injectivity/1")):
            ok, msg = check_coverage([c["valence"] for c in good if c.get("schema") == schema])
            print(f"{label} coverage: {'OK' if ok else 'INCOMPLETE'}: {msg}")
            ok_all &= ok
        if not ok_all:
            return 1
    return 0 if not bad else 1
