"""Fixtures of the hsh10 (ARAP) tests."""

import importlib.util
import pathlib

import pytest

_spec = importlib.util.spec_from_file_location("arap_meshes", pathlib.Path(__file__).with_name("_arap_meshes.py"))
M = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(M)


@pytest.fixture(scope="session")
def bunny_path():
    if not M.BUNNY.is_file():
        pytest.skip(f"bunny mesh not found at {M.BUNNY}")
    return M.BUNNY
