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


def private_reaches(path):
    """``["module.py: name"]`` for each private name (one leading underscore) that the base module at ``path``
    takes from another module: imported by name, or read as an attribute of an imported module or class. A
    package's private module itself (``from . import _tensor``) may be imported; its private names may not.

    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     f = Path(d) / "m.py"
    ...     _ = f.write_text("from .a import _x, y\\nfrom . import b as B\\nz = B._w + y._v + _x\\n")
    ...     private_reaches(f)
    ['m.py: _x', 'm.py: B._w', 'm.py: y._v']
    """
    tree, imported, out = ast.parse(path.read_text()), set(), []
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            for a in node.names:
                imported.add(a.asname or a.name)
                if _private(a.name) and not (path.parent / f"{a.name}.py").exists():
                    out.append(f"{path.name}: {a.name}")
        elif isinstance(node, ast.Import):
            imported.update(a.asname or a.name.split(".")[0] for a in node.names)
    for node in ast.walk(tree):
        if isinstance(node, ast.Attribute) and _private(node.attr) and isinstance(node.value, ast.Name) \
                and node.value.id in imported:
            out.append(f"{path.name}: {node.value.id}.{node.attr}")
    return out


def _private(name):
    return name.startswith("_") and not name.startswith("__")


def test_no_module_of_the_base_reaches_for_another_ones_private_names():
    found = [hit for m in MODULES for hit in private_reaches(m)]
    assert not found, found


MAX_FUNCTION_LINES, MAX_COMPLEXITY = 80, 20


def complexity(fn):
    """McCabe's cyclomatic complexity of a function: 1 + one per branch point (if, conditional expression,
    loop, except clause, match case, comprehension clause, and each extra operand of and/or), nested
    functions included.

    >>> complexity(ast.parse("def f(a, b):\\n    if a and b:\\n        return [x for x in a if x]\\n").body[0])
    5
    """
    n = 1
    for node in ast.walk(fn):
        if isinstance(node, (ast.If, ast.IfExp, ast.For, ast.AsyncFor, ast.While, ast.ExceptHandler, ast.match_case)):
            n += 1
        elif isinstance(node, ast.BoolOp):
            n += len(node.values) - 1
        elif isinstance(node, ast.comprehension):
            n += 1 + len(node.ifs)
    return n


def over_cap():
    """``{"module.py:function": (lines, complexity)}`` for every function of the base over a cap."""
    out = {}
    for m in MODULES:
        for node in ast.walk(ast.parse(m.read_text())):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                size, cc = node.end_lineno - node.lineno + 1, complexity(node)
                if size > MAX_FUNCTION_LINES or cc > MAX_COMPLEXITY:
                    out[f"{m.name}:{node.name}"] = (size, cc)
    return out


def test_the_complexity_count_sees_branches():
    src = "def f(x):\n    for i in x:\n        if i or not i:\n            pass\n    return 1 if x else 2\n"
    assert complexity(ast.parse(src).body[0]) == 5
    assert complexity(ast.parse("def g():\n    return 1\n").body[0]) == 1


def test_every_function_of_the_base_is_short_and_simple():
    found = over_cap()
    assert not found, f"over {MAX_FUNCTION_LINES} lines or complexity {MAX_COMPLEXITY} (lines, complexity): {found}"


def test_the_page_states_its_own_totals():
    """The total row and the prose ("Small.") state the sums of the table, the verifier and the kernel apart."""
    text = DOC.read_text()
    rows = [(p, int(a), int(b)) for p, a, b in re.findall(r"\| `(ccproof/[\w/]+\.py)` \| (\d+) \| (\d+) \|", text)]
    verifier = [r for r in rows if "/verify/" in r[0]]
    kernel = [r for r in rows if "/rigorous/" in r[0]]
    lines, code = sum(r[1] for r in rows), sum(r[2] for r in rows)
    want = (f"| **total** | **{lines}** | **{code}** | lines: the verifier proper {sum(r[1] for r in verifier)}, "
            f"the kernel {sum(r[1] for r in kernel)}; code (no docstrings, comments, blank lines): "
            f"{sum(r[2] for r in verifier)} and {sum(r[2] for r in kernel)} |")
    assert want in text, want
    assert f"**Small.** {code:,} lines of code (the rest of the {lines:,} lines" in text.replace("\n  ", " ")


def test_the_base_never_imports_the_power_basis_polynomials():
    """``ccproof.certify.poly`` (``Poly``: the prover's and the tests' power basis) lies outside the base: no module
    of the base imports it, and the import-linter contract of the base forbids it."""
    import tomllib

    contracts = tomllib.loads((ROOT.parent / "pyproject.toml").read_text())["tool"]["importlinter"]["contracts"]
    base = [c for c in contracts if c.get("source_modules") == ["ccproof.certify.verify"]]
    assert base and all("ccproof.certify.poly" in c["forbidden_modules"] for c in base)
    for m in MODULES:
        for node in ast.walk(ast.parse(m.read_text())):
            names = [node.module or ""] if isinstance(node, ast.ImportFrom) else \
                [a.name for a in node.names] if isinstance(node, ast.Import) else []
            assert not any(n.endswith("poly") and "flint" not in n for n in names), (m.name, names)
