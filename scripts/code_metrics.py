#!/usr/bin/env python
"""Size and coupling counts of a Python package, from its source alone (standard library ``ast``).

Four counts, each with the list behind it (``--list``):

* files longer than ``--max-file`` lines (default 600): the Python and the C sources (``*.py``, ``*.c``);
* functions and methods (nested ones included) longer than ``--max-function`` lines (default 80), from the
  ``def`` line to the last line of the body, decorators not counted;
* functions with more than ``--max-params`` parameters (default 10): positional-only, ordinary and
  keyword-only ones, ``*args`` and ``**kwargs``, a method's ``self`` or ``cls`` not counted;
* private names used across modules: a name ``_x`` (one leading underscore, not a dunder) of a module of the
  package imported by another module (``from ccproof.a import _x``, ``from . import _x``) or read as an attribute of an
  imported module of the package (``import ccproof.a as a`` ... ``a._x``), each (module, source, name) once.
  A private module is its package's business: importing it, or names from it, inside its package is not
  counted; from outside its package it is counted apart ("private modules imported from outside their
  package").

Usage::

    python scripts/code_metrics.py                      # the counts for ccproof/
    python scripts/code_metrics.py --list               # and every file, function and import behind them
    python scripts/code_metrics.py --json out.json PATH # another package directory; the numbers as JSON

Example (a throwaway package of two modules):

>>> import tempfile, pathlib
>>> d = pathlib.Path(tempfile.mkdtemp()) / "pkg"
>>> d.mkdir()
>>> _ = (d / "__init__.py").write_text("")
>>> _ = (d / "a.py").write_text("def _h(): pass\\ndef f(a, b, c, d, e, f, g, h, i, j, k): pass\\n")
>>> _ = (d / "b.py").write_text("from pkg.a import _h\\nimport pkg.a as A\\nx = A._h\\n")
>>> m = measure(d)
>>> m["long_params"], [(r["module"], r["name"]) for r in m["private_imports"]]
([('pkg/a.py', 'f', 11, 2)], [('pkg.b', '_h')])
"""

from __future__ import annotations

import argparse
import ast
import json
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _is_private(name: str) -> bool:
    return name.startswith("_") and not name.startswith("__")


def module_name(path: Path, package_dir: Path) -> str:
    """Dotted module name of a file of the package (``pkg/a/__init__.py`` -> ``pkg.a``)."""
    rel = path.relative_to(package_dir.parent).with_suffix("")
    parts = list(rel.parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def _resolve(module: str | None, level: int, importer: str, is_package: bool) -> str:
    """The absolute module of ``from <level dots><module> import ...`` written in ``importer``."""
    if level == 0:
        return module or ""
    base = importer.split(".")
    base = base if is_package else base[:-1]
    base = base[: len(base) - (level - 1)]
    return ".".join(base + ([module] if module else []))


def _param_count(fn: ast.FunctionDef | ast.AsyncFunctionDef, in_class: bool) -> int:
    a = fn.args
    names = [p.arg for p in a.posonlyargs + a.args]
    n = len(names) + len(a.kwonlyargs) + (a.vararg is not None) + (a.kwarg is not None)
    if in_class and names and names[0] in ("self", "cls"):
        n -= 1
    return n


def _functions(tree: ast.AST):
    """(function node, whether it is defined directly in a class body) for every def of a module."""
    stack: list[tuple[ast.AST, bool]] = [(tree, False)]
    while stack:
        node, _ = stack.pop()
        for child in ast.iter_child_nodes(node):
            if isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef)):
                yield child, isinstance(node, ast.ClassDef)
            stack.append((child, False))


def _module_aliases(tree: ast.AST, importer: str, top: str, is_package: bool) -> dict[str, str]:
    """Local name -> module of the package, for every ``import pkg.x [as y]`` / ``from pkg import x``."""
    aliases: dict[str, str] = {}
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for al in node.names:
                if al.name.split(".")[0] == top:
                    if al.asname:
                        aliases[al.asname] = al.name
                    else:
                        aliases[top] = top
        elif isinstance(node, ast.ImportFrom):
            src = _resolve(node.module, node.level, importer, is_package)
            if src.split(".")[0] == top:
                for al in node.names:
                    aliases.setdefault(al.asname or al.name, f"{src}.{al.name}")
    return aliases


def _dotted(node: ast.AST) -> str | None:
    parts = []
    while isinstance(node, ast.Attribute):
        parts.append(node.attr)
        node = node.value
    if isinstance(node, ast.Name):
        return ".".join([node.id, *reversed(parts)])
    return None


def _private_uses(tree, importer, top, is_package, modules):
    """(kind, source module, name, line) of the private names ``importer`` takes from other modules."""
    out = []
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            src = _resolve(node.module, node.level, importer, is_package)
            if src.split(".")[0] != top or src == importer:
                continue
            for al in node.names:
                full = f"{src}.{al.name}"
                if full in modules and _is_private(al.name):  # a private module of the package src
                    if not _inside_private(importer, full):
                        out.append(("private-module", full, "", node.lineno))
                elif _is_private(al.name):
                    out.append(("import", src, al.name, node.lineno))
                elif any(_is_private(p) for p in src.split(".")) and not _inside_private(importer, src):
                    out.append(("private-module", src, al.name, node.lineno))
        elif isinstance(node, ast.Import):
            for al in node.names:
                if any(_is_private(p) for p in al.name.split(".")) and not _inside_private(importer, al.name):
                    out.append(("private-module", al.name, "", node.lineno))
    aliases = {k: v for k, v in _module_aliases(tree, importer, top, is_package).items() if v in modules}
    for node in ast.walk(tree):
        if isinstance(node, ast.Attribute) and _is_private(node.attr):
            chain = _dotted(node.value)
            if chain is None:
                continue
            head, *rest = chain.split(".")
            if head in aliases:
                mod = ".".join([aliases[head], *rest])
                if mod in modules and mod != importer:
                    out.append(("attribute", mod, node.attr, node.lineno))
    return out


def _inside_private(importer: str, src: str) -> bool:
    """Whether ``importer`` lives in the package that owns the private module ``src``."""
    parts = src.split(".")
    first = next(i for i, p in enumerate(parts) if _is_private(p))
    owner = ".".join(parts[:first])
    return importer == owner or importer.startswith(owner + ".")


def measure(package_dir: Path, max_file: int = 600, max_function: int = 80, max_params: int = 10) -> dict:
    """The four counts of the module docstring for the package in ``package_dir``, with their lists."""
    package_dir = Path(package_dir).resolve()
    top = package_dir.name
    files = sorted(package_dir.rglob("*.py"))
    modules = {module_name(p, package_dir) for p in files}
    res: dict = {"files": len(files), "lines": 0, "long_files": [], "long_functions": [], "long_params": [],
                 "private_imports": [], "private_modules": []}
    for path in sorted(package_dir.rglob("*.c")):  # C sources count for the file lengths only
        n_lines = len(path.read_text(encoding="utf-8").splitlines())
        res["lines"] += n_lines
        if n_lines > max_file:
            res["long_files"].append((str(path.relative_to(package_dir.parent)), n_lines))
    for path in files:
        text = path.read_text(encoding="utf-8")
        rel = str(path.relative_to(package_dir.parent))
        n_lines = len(text.splitlines())
        res["lines"] += n_lines
        if n_lines > max_file:
            res["long_files"].append((rel, n_lines))
        tree = ast.parse(text, filename=rel)
        for fn, in_class in _functions(tree):
            length = fn.end_lineno - fn.lineno + 1
            if length > max_function:
                res["long_functions"].append((rel, fn.name, length, fn.lineno))
            n = _param_count(fn, in_class)
            if n > max_params:
                res["long_params"].append((rel, fn.name, n, fn.lineno))
        importer = module_name(path, package_dir)
        for kind, src, name, line in _private_uses(tree, importer, top, path.name == "__init__.py", modules):
            key = "private_modules" if kind == "private-module" else "private_imports"
            if any((r["module"], r["from"], r["name"]) == (importer, src, name) for r in res[key]):
                continue  # one name of one module used by another counts once
            res[key].append({"module": importer, "line": line, "from": src, "name": name, "kind": kind})
    return res


def summary(m: dict) -> list[str]:
    """The counts as printed lines."""
    return [f"package: {m['files']} Python files, {m['lines']} lines (with the C sources)",
            f"files > 600 lines: {len(m['long_files'])}",
            f"functions > 80 lines: {len(m['long_functions'])}",
            f"functions with > 10 parameters: {len(m['long_params'])}",
            f"private names used across modules: {len(m['private_imports'])}"
            f" (in {len({r['module'] for r in m['private_imports']})} modules)",
            f"private modules imported from outside their package: {len(m['private_modules'])}"]


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("package", nargs="?", default=str(ROOT / "ccproof"))
    ap.add_argument("--list", action="store_true", help="list every file, function and import counted")
    ap.add_argument("--json", default=None, help="write the counts and lists here")
    ap.add_argument("--max-file", type=int, default=600)
    ap.add_argument("--max-function", type=int, default=80)
    ap.add_argument("--max-params", type=int, default=10)
    args = ap.parse_args(argv)
    m = measure(Path(args.package), args.max_file, args.max_function, args.max_params)
    lines = summary(m)
    if (args.max_file, args.max_function, args.max_params) != (600, 80, 10):
        lines = [ln.replace("600", str(args.max_file)).replace("80 lines", f"{args.max_function} lines")
                 .replace("10 param", f"{args.max_params} param") for ln in lines]
    print("\n".join(lines))
    if args.list:
        for rel, n in sorted(m["long_files"], key=lambda r: -r[1]):
            print(f"  file {rel}: {n} lines")
        for rel, name, n, line in sorted(m["long_functions"], key=lambda r: -r[2]):
            print(f"  function {rel}:{line} {name}: {n} lines")
        for rel, name, n, line in sorted(m["long_params"], key=lambda r: -r[2]):
            print(f"  parameters {rel}:{line} {name}: {n}")
        for r in m["private_imports"] + m["private_modules"]:
            print(f"  {r['kind']} {r['module']}:{r['line']} {r['from']} {r['name']}".rstrip())
    if args.json:
        Path(args.json).write_text(json.dumps(m, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
