"""The command line lives in ccproof/cli/ alone: no library module imports argparse or the CLI, every
command has a thin module there, and ``ccproof --help`` answers without importing the heavy libraries."""

import ast
import subprocess
import sys
from pathlib import Path

import ccproof

ROOT = Path(ccproof.__file__).parent


def test_no_library_module_imports_argparse_or_the_cli():
    offenders = []
    for f in ROOT.rglob("*.py"):
        if "cli" in f.relative_to(ROOT).parts[:1]:
            continue
        for node in ast.walk(ast.parse(f.read_text())):
            names = ([a.name for a in node.names] if isinstance(node, ast.Import)
                     else [node.module or ""] if isinstance(node, ast.ImportFrom) else [])
            if any(n == "argparse" or n.startswith("ccproof.cli") for n in names):
                offenders.append(str(f.relative_to(ROOT)))
    assert not offenders, offenders


def test_every_command_is_a_module_of_the_cli_package():
    from ccproof.cli import COMMANDS

    assert set(COMMANDS) >= {"table", "certify", "verify", "report", "eval", "project", "invert", "arap", "fit"}
    for name, (modname, _) in COMMANDS.items():
        assert modname.startswith("ccproof.cli."), (name, modname)


def test_help_imports_no_heavy_library():
    code = ("import sys; from ccproof.cli import build_parser; build_parser(); "
            "print(sorted(m for m in ('numpy', 'sympy', 'scipy', 'matplotlib', 'flint') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "[]", out
