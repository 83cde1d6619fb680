"""The ```python blocks of docs/*.md and README.md run (each file's blocks in order, in one namespace).

A block that is not meant to run takes another fence language (```text, ```pycon, ...). Blocks may
read the test data through ``REPO`` (the repository root), set in their namespace.
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
    text = "x\n```python\na = 1\n```\n```text\nnot run\n```\n```python\nb = 2\n```\n"
    assert FENCE.findall(text) == ["a = 1\n", "b = 2\n"]


@pytest.mark.parametrize("path", [p for p in DOCS if python_blocks(p)], ids=lambda p: p.name)
def test_doc_python_blocks_run(path, monkeypatch, tmp_path):
    monkeypatch.chdir(tmp_path)
    namespace = {"__name__": f"doc_{path.stem}", "REPO": REPO}
    for i, block in enumerate(python_blocks(path)):
        try:
            exec(compile(block, f"{path.name}[python block {i}]", "exec"), namespace)
        except Exception as exc:
            raise AssertionError(f"{path.name}, python block {i} fails: {exc!r}\n{block}") from exc
