"""Every benchmark of scripts/ runs on a tiny input and prints its ratio lines; none imports a private name.

The scripts are found by glob (``scripts/bench_*.py``): a new benchmark without a smoke run here fails
:func:`test_every_benchmark_has_a_smoke_run`. Each runs in a fresh process (two at a time) with its ``--smoke``
flag (or the tiny arguments below) and must exit 0 and print at least one ratio line, ``min X  median Y  max Z``
with the machine's ``load`` on the same line (scripts/_bench.py), or say that its baseline is missing
(``baseline missing: ...``: our side is still measured). The whole file takes about a minute on a loaded
2-core machine.
"""

from __future__ import annotations

import ast
import os
import re
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest

SCRIPTS = Path(__file__).resolve().parents[1] / "scripts"

#: per script, the arguments of its smoke run (a few seconds each)
SMOKE = {
    "bench_basis.py": ["--smoke"],
    "bench_arap.py": ["--smoke"],
    "bench_certify.py": ["--smoke"],
    "bench_evaluate.py": ["--smoke"],
    "bench_eval_scheduler.py": ["--smoke"],
    "bench_fem.py": ["--smoke"],
    "bench_first_move.py": ["--smoke"],
    "bench_fit_tagged.py": ["--smoke"],
    "bench_inverse.py": ["--smoke"],
    "bench_loop.py": ["--smoke"],
    "bench_kernel_ab.py": ["--smoke"],
    "bench_memory.py": ["--smoke"],
    "bench_ngon.py": ["--smoke"],
    "bench_ngon_table.py": ["--smoke"],
    "bench_project.py": ["--smoke"],
    "bench_refine.py": ["--smoke"],
    "bench_reparam.py": ["--smoke"],
    "bench_replay.py": ["--smoke"],
    "bench_scale.py": ["--smoke"],
    "bench_scans.py": ["--smoke"],
    "bench_step.py": ["--smoke"],
    "bench_stop.py": ["--smoke"],
    "bench_tables.py": ["--smoke"],
    "bench_topology.py": ["--smoke"],
    "bench_with_vertices.py": ["--smoke"],
}

#: a ratio line: min / median / max of per-round ratios and the load, on one line
RATIO = re.compile(r"\bmin\s+[-+0-9.eE]+\s+median\s+[-+0-9.eE]+\s+max\s+[-+0-9.eE]+.*\bload\b")
MISSING = re.compile(r"^baseline missing: ", re.M)
#: a private name of ccproof on a line of code that does not parse alone
PRIVATE_IN_LINE = re.compile(r"(from ccproof\S* import .*\b_[a-z]\w*|ccproof\.\S*\._[a-z]|\w\._[a-z]\w*)")
#: attributes of NamedTuples (documented public API despite the underscore)
NAMEDTUPLE_API = {"_fields", "_replace", "_asdict", "_make"}


def _scripts():
    return sorted(p.name for p in SCRIPTS.glob("bench_*.py"))


def test_every_benchmark_has_a_smoke_run():
    assert _scripts(), "no scripts/bench_*.py found"
    assert set(_scripts()) == set(SMOKE), (
        f"without a smoke run here: {sorted(set(_scripts()) - set(SMOKE))}; "
        f"listed but gone: {sorted(set(SMOKE) - set(_scripts()))}")


def _private_uses(source: str) -> list[str]:
    """Private names of ccproof a script's code uses: ``from ccproof.x import _y``, ``ccproof.x._mod``, any
    ``obj._name`` attribute; also in the code strings it runs in other processes (``python -c``)."""
    found = []
    tree = ast.parse(source)
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and (node.module or "").split(".")[0] == "ccproof":
            found += [f"from {node.module} import {a.name}" for a in node.names
                      if any(p.startswith("_") and not p.startswith("__") for p in [*node.module.split("."), a.name])]
        elif isinstance(node, ast.Import):
            found += [f"import {a.name}" for a in node.names if a.name.split(".")[0] == "ccproof"
                      and any(p.startswith("_") and not p.startswith("__") for p in a.name.split("."))]
        elif isinstance(node, ast.Attribute) and node.attr.startswith("_") and not node.attr.startswith("__"):
            if node.attr not in NAMEDTUPLE_API:
                found.append(ast.unparse(node))
        elif isinstance(node, ast.Constant) and isinstance(node.value, str) and "import ccproof" in node.value \
                or isinstance(node, ast.Constant) and isinstance(node.value, str) and "from ccproof" in node.value:
            try:
                found += _private_uses(node.value)
            except SyntaxError:  # a fragment with placeholders: look at its lines
                found += [ln.strip() for ln in node.value.splitlines() if PRIVATE_IN_LINE.search(ln)]
    return found


def _own_private_names(tree: ast.Module) -> set[str]:
    """Names of the script's own (or its helper modules') private functions and modules: ``_osd.load``."""
    return {a.asname or a.name for n in ast.walk(tree) if isinstance(n, (ast.Import, ast.ImportFrom))
            for a in n.names if (getattr(n, "module", None) or a.name).split(".")[0] != "ccproof"}


@pytest.mark.parametrize("name", _scripts())
def test_benchmark_uses_public_names_only(name):
    source = (SCRIPTS / name).read_text()
    own = _own_private_names(ast.parse(source)) | {"self", "cls"}
    bad = [u for u in _private_uses(source) if u.split(".")[0] not in own]
    assert bad == [], f"scripts/{name} uses private names of ccproof: {bad}"


def test_the_private_name_check_can_fail():
    """The check above flags what it must: a forger's private import, a private attribute, the same in code
    a script runs in another process."""
    assert _private_uses("from ccproof.evaluate._basis import basis_rows") != []
    assert _private_uses("from ccproof.evaluate.surface import _CORNER") != []
    assert _private_uses("S = f()\nT = S._table") != []
    assert _private_uses('CODE = """\nimport ccproof\nfrom ccproof.evaluate import _ckernel\n"""') != []
    assert _private_uses("from ccproof.evaluate import natural_limit_surface\nT = S.patch_map.table._fields") == []


@pytest.fixture(scope="module")
def smoke_runs():
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(SCRIPTS.parent), os.environ.get("PYTHONPATH", "")]))

    def run(name):
        try:
            p = subprocess.run([sys.executable, str(SCRIPTS / name), *SMOKE[name]], capture_output=True, text=True,
                               env=env, timeout=120, cwd=SCRIPTS.parent)
        except subprocess.TimeoutExpired as e:
            return name, -1, str(e.stdout or ""), "timed out after 120 s"
        return name, p.returncode, p.stdout, p.stderr

    with ThreadPoolExecutor(2) as pool:
        return {name: (rc, out, err) for name, rc, out, err in pool.map(run, sorted(set(SMOKE) & set(_scripts())))}


@pytest.mark.parametrize("name", _scripts())
def test_benchmark_smoke_run_prints_its_ratios(name, smoke_runs):
    if name not in smoke_runs:
        pytest.fail(f"scripts/{name} has no smoke run (SMOKE)")
    rc, out, err = smoke_runs[name]
    assert rc == 0, f"scripts/{name} {' '.join(SMOKE[name])} failed ({rc}):\n{out[-2000:]}\n{err[-3000:]}"
    ratios = [ln for ln in out.splitlines() if RATIO.search(ln)]
    assert ratios or MISSING.search(out), f"scripts/{name}: no ratio line (min/median/max, load) in:\n{out[-3000:]}"
    if not ratios:
        assert len(out.splitlines()) > 1, f"scripts/{name}: baseline missing and nothing measured:\n{out}"
