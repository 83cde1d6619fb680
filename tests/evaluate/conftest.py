"""Shared fixtures of the evaluation tests."""

import os
from pathlib import Path

import numpy as np
import pytest

from ccproof.mesh import QuadMesh
from ccproof.mesh.examples import grid

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


def l_shape(seed=0):
    """A 4 x 4 grid minus its top-right 2 x 2 block, perturbed: a concave boundary vertex (3 faces)
    and boundary corners with one face."""
    rng = np.random.default_rng(seed)
    g = grid(4, 4)
    keep = [f for f in range(16) if not (f % 4 >= 2 and f // 4 >= 2)]
    F = g.faces[keep]
    used = np.unique(F)
    remap = -np.ones(25, dtype=int)
    remap[used] = np.arange(used.size)
    V = g.vertices[used] + 0.15 * rng.normal(size=(used.size, 3))
    return QuadMesh(V, remap[F])
