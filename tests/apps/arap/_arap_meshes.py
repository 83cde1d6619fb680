"""Shared test meshes for the hsh10 (ARAP) tests (loaded by path: tests run with --import-mode=importlib)."""

from pathlib import Path

import numpy as np

from ccproof.mesh import QuadMesh
from ccproof.mesh.examples import grid, k_regular_disk

REPO = Path(__file__).resolve().parents[3]
BUNNY = REPO / "tests" / "data" / "meshes" / "bunny_quads.obj"


def zigzag_chart(k=5, rings=4):
    """Faces of a k_regular_disk(k, rings) with a + b < 4 in every sector: contains the EV, staircase boundary."""
    return [(j * rings + a) * rings + b for j in range(k) for a in range(3) for b in range(3) if a + b < 4]


def curved_ev_mesh():
    """Valence-5 disk with a saddle-like height field (non-developable), and a zigzag chart around the EV."""
    m = k_regular_disk(5, rings=4, height=lambda x, y: 0.15 * (x**2 - 0.5 * y**2))
    return m, zigzag_chart()


def flat_ev_mesh():
    return k_regular_disk(5, rings=4), zigzag_chart()


def tube(na=16, nz=10, radius=None):
    """Open cylinder of na x nz unit-ish quads, faces counter-clockwise seen from outside."""
    r = radius or na / (2 * np.pi)
    i, j = np.meshgrid(np.arange(na), np.arange(nz + 1), indexing="ij")
    V = np.stack([r * np.cos(2 * np.pi * i / na), r * np.sin(2 * np.pi * i / na), j * 1.0], -1).reshape(-1, 3)
    idx = np.arange(na * (nz + 1)).reshape(na, nz + 1)
    F = np.stack([idx[:, :-1], np.roll(idx, -1, 0)[:, :-1], np.roll(idx, -1, 0)[:, 1:], idx[:, 1:]], -1)
    return QuadMesh(V, F.reshape(-1, 4))


def rect_chart_grid():
    """8 x 8 planar grid and the 4 x 4 block of faces in its middle (straight boundary, regular vertices)."""
    return grid(8, 8), [i + 8 * j for i in range(2, 6) for j in range(2, 6)]
