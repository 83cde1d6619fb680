"""Where the published certificates are found and where new ones are written, checkout vs installed.

The installed layout is imitated by loading a copy of ``ccproof/tables/format.py`` from a fake
``site-packages/ccproof/tables/``: no ``pyproject.toml`` two levels up, the certificates shipped as
``ccproof/_certificates``. The real wheel is built, installed and smoke-tested by ``.ci/run``.
"""

import importlib.util
import shutil
from pathlib import Path

import pytest

import ccproof.tables.format as fmt

REPO = Path(__file__).resolve().parents[1]


def _load_copy(site):
    """``format.py`` copied to ``site/ccproof/tables/format.py`` and imported from there."""
    dst = site / "ccproof" / "tables" / "format.py"
    dst.parent.mkdir(parents=True)
    shutil.copy(fmt.__file__, dst)
    spec = importlib.util.spec_from_file_location("_installed_format", dst)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


@pytest.fixture
def clean_env(monkeypatch, tmp_path):
    monkeypatch.delenv("CCPROOF_CERTIFICATES", raising=False)
    monkeypatch.setenv("XDG_DATA_HOME", str(tmp_path / "xdg"))
    return tmp_path


def test_checkout_reads_and_writes_the_repository_certificates(clean_env):
    assert fmt.certificates_dir() == REPO / "certificates"
    assert fmt.output_dir() == REPO / "certificates"
    assert (fmt.certificates_dir() / "tables" / "k005.json").is_file()


def test_installed_reads_package_data_and_writes_to_the_user_folder(clean_env, monkeypatch):
    site = clean_env / "site-packages"
    mod = _load_copy(site)
    monkeypatch.chdir(REPO)  # a checkout in the current folder must not be picked up
    assert mod.certificates_dir() == site / "ccproof" / "_certificates"
    out = mod.output_dir()
    assert out == clean_env / "xdg" / "ccproof" / "certificates"
    assert site not in out.parents


def test_installed_without_xdg_uses_local_share(clean_env, monkeypatch):
    monkeypatch.delenv("XDG_DATA_HOME")
    monkeypatch.setenv("HOME", str(clean_env / "home"))
    mod = _load_copy(clean_env / "site-packages")
    assert mod.output_dir() == clean_env / "home" / ".local" / "share" / "ccproof" / "certificates"


def test_environment_variable_wins(clean_env, monkeypatch):
    monkeypatch.setenv("CCPROOF_CERTIFICATES", str(clean_env / "mine"))
    mod = _load_copy(clean_env / "site-packages")
    assert mod.certificates_dir() == clean_env / "mine"
    assert mod.output_dir() == clean_env / "mine"
    assert fmt.certificates_dir() == clean_env / "mine"


def test_certify_writes_to_out(tmp_path, capsys):
    from ccproof.cli import main

    assert main(["certify", "4", "--out", str(tmp_path / "new"), "--no-verify"]) == 0
    written = tmp_path / "new" / "k004.json"
    assert f"certificate written to {written}" in capsys.readouterr().out
    assert main(["verify", str(written), "--quiet"]) == 0
    assert f"VERIFIED {written}" in capsys.readouterr().out


def test_py_typed_is_shipped():
    assert (Path(fmt.__file__).resolve().parents[1] / "py.typed").is_file()
