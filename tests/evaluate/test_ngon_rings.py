"""The long fans of n-gon centres are read with array operations (evaluate/local.py, fans of more than 48
corners); the rings, faces and rule counts equal those of the plain loop that reads every other fan, from
every corner of every face next to a centre, at depths 1 and 2 (a disc and a drum with n-gons, a crease)."""

import numpy as np
import pytest

from ccproof.evaluate import local
from ccproof.evaluate.halfedge_views import ComplexView, TaggedHalfEdges
from ccproof.mesh.halfedges import HalfEdges
from ccproof.mesh.polymesh import PolyMesh


def _drum(n, seed=0):
    rng = np.random.default_rng(seed)
    t = np.arange(n) * 2 * np.pi / n
    top = np.c_[np.cos(t), np.sin(t), 1 + 0.05 * rng.standard_normal(n)]
    bot = np.c_[np.cos(t), np.sin(t), -1 + 0.05 * rng.standard_normal(n)]
    F = [list(range(n)), list(range(2 * n - 1, n - 1, -1))]
    F += [[i, n + i, n + (i + 1) % n, (i + 1) % n] for i in range(n)]
    return PolyMesh(np.vstack([top, bot]), F)


def _disc(n):
    t = np.arange(n) * 2 * np.pi / n
    X = np.vstack([np.c_[np.cos(t), np.sin(t), 0 * t], np.c_[2 * np.cos(t), 2 * np.sin(t), 0 * t]])
    return PolyMesh(X, [list(range(n))] + [[i, n + i, n + (i + 1) % n, (i + 1) % n] for i in range(n)],
                    creases={(0, 1): 2.0})


@pytest.mark.parametrize("mesh", [_drum(60), _disc(70)], ids=["drum60", "disc70-crease"])
def test_long_fans_read_as_the_loop_reads_them(mesh, monkeypatch):
    m1, _ = mesh.refine()
    he = HalfEdges.from_quads(np.array(m1.polygons), m1.n_vertices, m1.options)
    cx = ComplexView(TaggedHalfEdges.of(he.with_tags(dict(m1.edge_sharpness), dict(m1.vertex_sharpness))))
    read = []
    monkeypatch.setattr(local, "_read_fan", lambda *a, f=local._read_fan: read.append(1) or f(*a))
    counts = np.bincount(np.concatenate([np.asarray(p) for p in m1.polygons]))
    centres = set(np.flatnonzero(counts > local._BIG_FAN).tolist())
    faces = [g for g, poly in enumerate(m1.polygons) if centres & set(poly)]
    assert len(faces) >= 60
    cases = [(g, r, d) for g in faces[::7] for r in range(4) for d in (1, 2)]
    fast = [local.canonical_ring(cx, g, r, d) for g, r, d in cases]
    assert len(read) >= len(cases)  # (the array reading was taken: the factory's view of the half-edges)
    monkeypatch.setattr(local, "_BIG_FAN", 10**9)  # every fan by the loop
    slow = [local.canonical_ring(cx, g, r, d) for g, r, d in cases]
    for case, a, b in zip(cases, fast, slow):
        assert a[0] == b[0] and a[1] == b[1] and a[2] == b[2], case
