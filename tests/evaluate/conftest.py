"""Shared fixtures of the evaluation tests."""

import os
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]


def shared_reference():
    """../shared/reference relative to the repository root (override: CCPROOF_SHARED)."""
    base = os.environ.get("CCPROOF_SHARED")
    root = Path(base) if base else REPO.parent / "shared"
    return root / "reference" if (root / "reference").is_dir() else root


@pytest.fixture(scope="session")
def refdir():
    ref = shared_reference()
    if not (ref / "meshes").is_dir():
        pytest.skip(f"OpenSubdiv reference data not found at {ref}")
    return ref
