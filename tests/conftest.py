"""Fixtures shared by every test folder: the reference data that ships with the repository (tests/data)."""

from pathlib import Path

import pytest

DATA = Path(__file__).resolve().parent / "data"


@pytest.fixture(scope="session")
def refdir():
    """``tests/data``: OpenSubdiv reference values and the test meshes (see tests/data/README.md)."""
    return DATA


@pytest.fixture(scope="session")
def bunny_path():
    """The quad-remeshed Stanford bunny (2,038 vertices, 2,036 quads)."""
    return DATA / "meshes" / "bunny_quads.obj"
