"""A git revision of this repository as a source tree beside the working tree, for the benchmarks that time
the code before a change against the code after it (``--before REV``), each in its own worker process.

>>> with tempfile.TemporaryDirectory() as tmp:              # doctest: +SKIP
...     rev = export_revision("main", Path(tmp))
"""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def export_revision(rev, dest):
    """Write the files of revision ``rev`` into the folder ``dest`` (``git archive``) and copy this tree's built
    C kernel (``ccproof/evaluate/_clib*.so``, git-ignored) into it; return the revision's short hash."""
    short = subprocess.run(["git", "rev-parse", "--short", rev], cwd=ROOT, capture_output=True, text=True,
                           check=True).stdout.strip()
    tar = subprocess.run(["git", "archive", rev], cwd=ROOT, capture_output=True, check=True).stdout
    subprocess.run(["tar", "-x", "-C", str(dest)], input=tar, check=True)
    for so in (ROOT / "ccproof" / "evaluate").glob("_clib*.so"):
        shutil.copy(so, Path(dest) / "ccproof" / "evaluate" / so.name)
    return short
