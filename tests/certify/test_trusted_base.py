"""docs/trusted_base.md names every module of the trusted base with its line count; each stays small;
the prover uses only public names of the verifier."""

import ast
import io
import re
import tokenize
from pathlib import Path

import ccproof

ROOT = Path(ccproof.__file__).parent
DOC = ROOT.parent / "docs" / "trusted_base.md"
MODULES = sorted([*(ROOT / "certify" / "verify").glob("*.py"), *(ROOT / "rigorous").glob("*.py")])


def code_lines(src):
    """Lines holding code: not blank, not only a comment, not part of a docstring."""
    doc = set()
    for node in ast.walk(ast.parse(src)):
        if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)) and node.body:
            first = node.body[0]
            value = getattr(first, "value", None)
            if isinstance(first, ast.Expr) and isinstance(value, ast.Constant) and isinstance(value.value, str):
                doc.update(range(first.lineno, first.end_lineno + 1))
    skip = (tokenize.COMMENT, tokenize.NL, tokenize.NEWLINE, tokenize.INDENT, tokenize.DEDENT, tokenize.ENDMARKER)
    code = set()
    for tok in tokenize.generate_tokens(io.StringIO(src).readline):
        if tok.type not in skip:
            code.update(range(tok.start[0], tok.end[0] + 1))
    return len(code - doc)


def test_the_page_lists_every_module_with_its_line_count():
    rows = {p: (int(a), int(b)) for p, a, b in
            re.findall(r"\| `(ccproof/[\w/]+\.py)` \| (\d+) \| (\d+) \|", DOC.read_text())}
    listed = {str(m.relative_to(ROOT.parent)) for m in MODULES}
    assert set(rows) == listed
    for m in MODULES:
        src = m.read_text()
        n, k = len(src.splitlines()), code_lines(src)
        assert rows[str(m.relative_to(ROOT.parent))] == (n, k), f"{m.name}: {n} lines, {k} of code"
        assert n <= 600


def test_the_prover_imports_no_private_name_of_the_verifier():
    tree = ast.parse((ROOT / "certify" / "prover.py").read_text())
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and (node.module or "").startswith("ccproof.certify.verify"):
            assert all(not a.name.startswith("_") for a in node.names), [a.name for a in node.names]
