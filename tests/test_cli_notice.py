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
    monkeypatch.setenv("CCPROOF_BACKEND", "numba")  # evaluation on numba: its kernel compiles too
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


def test_no_evaluation_kernel_to_compile_on_the_c_kernel(tmp_path, monkeypatch):
    """With the C kernel built and the automatic backend, ``eval`` compiles nothing (no notice with an empty
    numba cache) and ``project`` waits only for its other kernels (Newton descent, search structure)."""
    from ccproof.evaluate.backend import available_backends

    if "c" not in available_backends():
        pytest.skip("the C kernel was not built")
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path))
    monkeypatch.delenv("CCPROOF_BACKEND", raising=False)
    out = io.StringIO()
    assert not compile_notice("eval", out) and out.getvalue() == ""
    assert compile_notice("project", io.StringIO())  # its numba kernels are not cached yet
    for entry in COMMAND_KERNELS["project"][0]:
        if not entry.endswith(":_evaluate_points"):
            _index(tmp_path, entry)
    out = io.StringIO()
    assert not compile_notice("project", out) and out.getvalue() == ""
    monkeypatch.setenv("CCPROOF_BACKEND", "numba")  # now evaluation compiles its numba kernel
    assert compile_notice("eval", io.StringIO()) and compile_notice("project", io.StringIO())
