"""Run every ```python block of docs/*.md and README.md against the ccproof that Python imports, each
file's blocks in order in one namespace, in an empty temporary folder; exit 1 naming the first
block that fails.

    python scripts/run_doc_blocks.py [--docs DOCS_FOLDER] [--readme README.md]

.ci/run calls it with the interpreter of a fresh environment that has only the built wheel installed,
so a block may use only what the wheel ships (ccproof.mesh.examples, the published certificates) or
what it writes itself; it cannot read the repository (tests/data). Fences:

* ```python           runs;
* ```python no-run    does not run; the text around the block says why (e.g. it needs a cluster or
                      takes hours);
* ```text, ``` ...    sketches, grammars and command synopses, never run.

tests/test_docs.py runs the same blocks with the same rule inside the test suite.
"""

from __future__ import annotations

import argparse
import os
import re
import sys
import tempfile
import time
import traceback
from pathlib import Path

#: a ```python fence with nothing after the language: ```python no-run does not match
FENCE = re.compile(r"^```python[ \t]*\n(.*?)^```[ \t]*$", re.S | re.M)
SKIPPED = re.compile(r"^```python[ \t]+no-run\b", re.M)


def python_blocks(text):
    """The runnable ```python blocks of a Markdown text, in order.

    >>> python_blocks("```python\\na = 1\\n```\\n```python no-run\\nb = 2\\n```\\n```text\\nc\\n```\\n")
    ['a = 1\\n']
    """
    return FENCE.findall(text)


def run_file(path):
    """Run the blocks of one Markdown file in one namespace; returns (blocks run, skipped, error or None)."""
    text = path.read_text(encoding="utf-8")
    blocks, skipped = python_blocks(text), len(SKIPPED.findall(text))
    namespace = {"__name__": f"doc_{path.stem}"}
    for i, block in enumerate(blocks):
        try:
            exec(compile(block, f"{path.name}[python block {i}]", "exec"), namespace)
        except Exception:
            return i, skipped, f"{path.name}, python block {i} fails:\n{traceback.format_exc()}\n{block}"
    return len(blocks), skipped, None


def main(argv=None):
    root = Path(__file__).resolve().parents[1]
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--docs", type=Path, default=root / "docs", help="folder of Markdown files (default docs/)")
    ap.add_argument("--readme", type=Path, default=root / "README.md")
    args = ap.parse_args(argv)
    files = sorted(args.docs.glob("*.md")) + ([args.readme] if args.readme.is_file() else [])
    import ccproof

    print(f"ccproof {ccproof.__version__} from {Path(ccproof.__file__).parent}")
    failed = 0
    with tempfile.TemporaryDirectory() as tmp:
        for path in files:
            path = path.resolve()
            folder = Path(tmp) / path.stem  # an empty folder per file
            folder.mkdir()
            os.chdir(folder)
            t0 = time.perf_counter()
            n, skipped, error = run_file(path)
            os.chdir(tmp)
            if error is None and n == 0 and not skipped:
                continue
            note = f", {skipped} marked no-run" if skipped else ""
            if error:
                failed += 1
                print(f"FAIL {path.name}: {error}")
            else:
                print(f"ok   {path.name}: {n} block(s) in {time.perf_counter() - t0:.1f} s{note}")
    print(f"{failed} file(s) have a failing python block" if failed else "every python block of the docs ran")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
