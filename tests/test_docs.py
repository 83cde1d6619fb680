"""The ```python blocks of docs/*.md and README.md run (each file's blocks in order, in one namespace),
in an empty folder and without the repository: a block uses what an installed wheel has
(ccproof.mesh.examples, the published certificates) or writes its data itself. .ci/run runs the same
blocks from the installed wheel (scripts/run_doc_blocks.py).

A block that is not meant to run takes another fence language (```text, ```pycon, ...), or
```python no-run with the reason in the text around it.
"""

import re
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
DOCS = sorted((REPO / "docs").glob("*.md")) + [REPO / "README.md"]
FENCE = re.compile(r"^```python[ \t]*\n(.*?)^```[ \t]*$", re.S | re.M)


def python_blocks(path):
    return FENCE.findall(path.read_text(encoding="utf-8"))


def test_the_fence_pattern_finds_blocks():
    text = "x\n```python\na = 1\n```\n```text\nnot run\n```\n```python\nb = 2\n```\n```python no-run\nc\n```\n"
    assert FENCE.findall(text) == ["a = 1\n", "b = 2\n"]


def test_no_block_reads_the_repository():
    """A wheel has no tests/data and no checkout: the blocks never name them."""
    for path in DOCS:
        for block in python_blocks(path):
            assert "REPO" not in block and "tests/data" not in block and '"tests"' not in block, path.name


@pytest.mark.parametrize("path", [p for p in DOCS if python_blocks(p)], ids=lambda p: p.name)
def test_doc_python_blocks_run(path, monkeypatch, tmp_path):
    monkeypatch.chdir(tmp_path)
    namespace = {"__name__": f"doc_{path.stem}"}
    for i, block in enumerate(python_blocks(path)):
        try:
            exec(compile(block, f"{path.name}[python block {i}]", "exec"), namespace)
        except Exception as exc:
            raise AssertionError(f"{path.name}, python block {i} fails: {exc!r}\n{block}") from exc
