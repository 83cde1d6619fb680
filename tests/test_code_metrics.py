"""scripts/code_metrics.py counts what it says on a package built here, whose counts are known by construction."""

import importlib.util
import subprocess
import sys
from pathlib import Path

import pytest

SCRIPT = Path(__file__).resolve().parents[1] / "scripts" / "code_metrics.py"


def _load():
    spec = importlib.util.spec_from_file_location("code_metrics", SCRIPT)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def _function(name, n_lines, params="", indent=""):
    """A def of exactly ``n_lines`` lines (the def line and n_lines - 1 body lines)."""
    body = "".join(f"{indent}    x{i} = {i}\n" for i in range(n_lines - 1))
    return f"{indent}def {name}({params}):\n{body}"


@pytest.fixture()
def package(tmp_path):
    pkg = tmp_path / "pkg"
    (pkg / "sub").mkdir(parents=True)
    (pkg / "__init__.py").write_text("")
    (pkg / "sub" / "__init__.py").write_text("from pkg.sub._inner import helper\n")  # inside its package
    (pkg / "sub" / "_inner.py").write_text("def helper():\n    pass\n\n\ndef _secret():\n    pass\n")
    long_file = "".join(f"y{i} = {i}\n" for i in range(601))  # 601 lines: counted
    (pkg / "long.py").write_text(long_file)
    (pkg / "edge.py").write_text("".join(f"y{i} = {i}\n" for i in range(600)))  # 600 lines: not counted
    (pkg / "kernel.c").write_text("int x;\n" * 700)  # a C source: counted for its length
    a = (_function("f81", 81) + _function("f80", 80)
         + _function("p11", 2, ", ".join(f"a{i}" for i in range(11)))
         + _function("p10", 2, ", ".join(f"a{i}" for i in range(10)))
         + _function("p_star", 2, ", ".join(f"a{i}" for i in range(9)) + ", *args, **kw")  # 11
         + "class C:\n" + _function("m", 2, "self, " + ", ".join(f"a{i}" for i in range(10)), "    ")  # 10
         + "def _h():\n    pass\n")
    (pkg / "a.py").write_text(a)
    (pkg / "b.py").write_text(
        "from pkg.a import _h, f80\n"          # one private name
        "import pkg.a as A\n"
        "from pkg.sub import _inner\n"         # a private module, from outside its package
        "x = A._h\n"                           # the same name again: counted once
        "y = A.f80\n"
        "z = _inner._secret\n")                # a private name of another module, as an attribute
    return pkg


def test_counts_of_a_known_package(package):
    m = _load().measure(package)
    assert sorted(f for f, _ in m["long_files"]) == ["pkg/kernel.c", "pkg/long.py"]
    assert sorted(name for _, name, _, _ in m["long_functions"]) == ["f81"]
    assert sorted((name, n) for _, name, n, _ in m["long_params"]) == [("p11", 11), ("p_star", 11)]
    assert sorted((r["module"], r["from"], r["name"]) for r in m["private_imports"]) == [
        ("pkg.b", "pkg.a", "_h"), ("pkg.b", "pkg.sub._inner", "_secret")]
    assert [(r["module"], r["from"]) for r in m["private_modules"]] == [("pkg.b", "pkg.sub._inner")]


def test_the_command_line_prints_the_four_counts(package):
    out = subprocess.run([sys.executable, str(SCRIPT), str(package), "--list"], capture_output=True, text=True,
                         check=True).stdout
    assert "files > 600 lines: 2" in out and "functions > 80 lines: 1" in out
    assert "functions with > 10 parameters: 2" in out and "private names used across modules: 2" in out
    assert "function pkg/a.py:1 f81: 81 lines" in out


#: the package's own ceilings: files > 600 lines, functions > 80 lines, functions with > 10 parameters, private
#: names used across modules (the counts of the third turn; ``python scripts/code_metrics.py --list`` names them)
CEILINGS = {"long_files": 8, "long_functions": 13, "long_params": 8, "private_imports": 20}


def test_ccproof_stays_within_its_ceilings():
    m = _load().measure(SCRIPT.parents[1] / "ccproof")
    over = {k: [x for x in m[k]] for k, cap in CEILINGS.items() if len(m[k]) > cap}
    assert not over, f"over the ceilings {CEILINGS}: {over}"
    assert not m["private_modules"], m["private_modules"]
