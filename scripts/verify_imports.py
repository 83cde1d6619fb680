"""The ccproof source the verifier loads: modules and lines imported to verify one published certificate of
each kind, each in a fresh process, then all of them in one process (the import trace of ``sys.modules``).

  python scripts/verify_imports.py          every kind (about a minute: dart:>=101 and smooth:>=40)
  python scripts/verify_imports.py --fast   without dart:>=101
"""

import json
import subprocess
import sys
from pathlib import Path

CERTS = Path(__file__).resolve().parents[1] / "certificates"

KINDS = ["injectivity/k005.json", "injectivity/k_ge_40.json", "c1/k005.json", "c1/k_ge_40.json",
         "c1/crease/n005.json", "c1/corner/n005.json", "c1/dart/k005.json", "c1/crease/n_ge_101.json",
         "c1/dart/k_ge_101.json"]
CHILD = r'''
import json, sys, time
from pathlib import Path
from ccproof.certify.verify import verify_file
out = []
for f in sys.argv[1:]:
    t = time.perf_counter()
    ok = bool(verify_file(f, log=lambda s: None))
    mods = [m for m, v in list(sys.modules.items()) if m.startswith("ccproof") and getattr(v, "__file__", None)]
    lines = sum(len(Path(sys.modules[m].__file__).read_text().splitlines()) for m in mods)
    out.append([f, ok, len(mods), lines, round(time.perf_counter() - t, 1)])
print(json.dumps(out))
'''


def trace(files):
    """[file, verified, modules, lines, seconds] after each file, in one fresh process (the certificates of
    this checkout, named by path: nothing of ccproof is imported but the verifier)."""
    run = subprocess.run([sys.executable, "-c", CHILD, *[str(CERTS / f) for f in files]], capture_output=True,
                         text=True, check=True)
    return [[f, *row[1:]] for f, row in zip(files, json.loads(run.stdout))]


def main():
    kinds = KINDS[:-1] if "--fast" in sys.argv else KINDS
    for f, ok, n, lines, s in [trace([f])[0] for f in kinds]:
        print(f"{f:28s} {'VERIFIED' if ok else 'FAILED':8s} {n:3d} modules {lines:6d} lines ({s} s)")
    _, ok, n, lines, _ = trace(kinds)[-1]
    print(f"{'every kind, one process':28s} {'':8s} {n:3d} modules {lines:6d} lines")


if __name__ == "__main__":
    main()
