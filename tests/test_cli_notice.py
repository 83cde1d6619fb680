"""The first-run compile notice of ``ccproof fit``, ``eval`` and ``project``: printed exactly when numba's cache
(here an empty ``NUMBA_CACHE_DIR``) lacks an index file of a kernel the command compiles."""

from __future__ import annotations

import io

import pytest

from ccproof.cli._notice import COMMAND_KERNELS, compile_notice, kernels_cached

pytest.importorskip("numba")


def _index(root, entry):
    """An index file named as numba names them (``module.function-line.pyXY.nbi``) for ``module:function``."""
    name, _, func = entry.partition(":")
    path = root / "sub" / f"{name.rsplit('.', 1)[-1]}.{func or 'f'}-12.py311.nbi"
    path.parent.mkdir(exist_ok=True)
    path.write_bytes(b"")


@pytest.mark.parametrize("command", ["eval", "project", "fit"])
def test_notice_until_every_kernel_of_the_command_is_cached(tmp_path, monkeypatch, command):
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path))
    modules, (lo, hi) = COMMAND_KERNELS[command]
    for entry in modules:
        out = io.StringIO()
        assert compile_notice(command, out)
        line = out.getvalue()
        assert line.count("\n") == 1 and line.startswith(f"ccproof {command}: first run: compiling")
        assert f"{lo}-{hi} s" in line
        _index(tmp_path, entry)
    out = io.StringIO()
    assert not compile_notice(command, out) and out.getvalue() == ""


def test_a_function_entry_needs_that_functions_index(tmp_path, monkeypatch):
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path))
    _index(tmp_path, "ccproof.evaluate._numba_kernel:_newton_points")
    assert kernels_cached(["ccproof.evaluate._numba_kernel"])  # any kernel of the module
    assert not kernels_cached(["ccproof.evaluate._numba_kernel:_evaluate_points"])
    assert kernels_cached(["ccproof.evaluate._numba_kernel:_newton_points"])
