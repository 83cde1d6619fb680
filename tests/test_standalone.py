"""The repository stands alone: no file refers to material outside it.

Greps the package, tests, scripts, docs, README, build files and CI script for references to a
sibling ``shared`` folder, to design notes that are not in the repository, to item names of an
outside specification ("spec" and a letter-digit item name) and to issue numbers. The reference data
under ``tests/data`` is skipped except its READMEs (which describe the data and must stand alone too).
Every hit is listed.
"""

import re
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
ROOTS = ["ccproof", "tests", "scripts", "docs", ".ci", "README.md", "pyproject.toml", "setup.py", "MANIFEST.in",
         "certificates"]
BINARY = {".png", ".jpg", ".pdf", ".npz", ".npy", ".pyc", ".whl", ".gz", ".zip"}
SKIP_DIRS = {"__pycache__", ".pytest_cache", ".ruff_cache", ".hypothesis", "_certificates"}

FORBIDDEN = [
    ("a path into a sibling shared folder", re.compile(r"\.\./shared")),
    ("the design notes", re.compile(r"DESIGN\.md", re.IGNORECASE)),
    ("an item of an outside specification", re.compile(r"\bspec [A-Z][0-9]", re.IGNORECASE)),
    ("an issue number", re.compile(r"\bissues? #?[0-9]", re.IGNORECASE)),
]


def _files():
    me = Path(__file__).resolve()
    data = REPO / "tests" / "data"
    for root in ROOTS:
        path = REPO / root
        if path.is_file():
            yield path
            continue
        for f in sorted(path.rglob("*")):
            if not f.is_file() or f.resolve() == me or f.suffix.lower() in BINARY:
                continue
            if SKIP_DIRS & set(f.relative_to(REPO).parts) or any(p.endswith(".egg-info") for p in f.parts):
                continue
            if data in f.parents and f.name.lower() != "readme.md":
                continue
            yield f


def test_the_grep_finds_what_it_must():
    # assembled from pieces, so that this file itself never contains the forbidden strings
    text = "see " + ".." + "/shared/x, " + "DESIGN" + ".md R3, " + "spec" + " A8, Issue 14, issue #3"
    assert sum(len(rx.findall(text)) for _, rx in FORBIDDEN) == 5
    assert not any(rx.search("a respectable spec: A8 is fine; tissue 5 layers") for _, rx in FORBIDDEN)


def test_every_searched_root_exists():
    assert all((REPO / r).exists() for r in ROOTS if r not in (".ci",)), [r for r in ROOTS if not (REPO / r).exists()]
    assert (REPO / "tests" / "data" / "README.md") in set(_files())


def test_no_file_refers_outside_the_repository():
    hits = []
    for f in _files():
        text = f.read_text(encoding="utf-8", errors="replace")
        for no, line in enumerate(text.splitlines(), 1):
            for what, rx in FORBIDDEN:
                if rx.search(line):
                    hits.append(f"{f.relative_to(REPO)}:{no}: {what}: {line.strip()[:120]}")
    assert not hits, f"{len(hits)} references to material outside the repository:\n" + "\n".join(hits)
