"""Tagged exact evaluation against brute force: N global steps of the tagged rules plus limit masks.

At a dyadic ptex point (i / 2^N, j / 2^N) (n-gon sub-faces: level-1 quads, so one step less) the
limit surface passes through the limit point of the level-N vertex there. Once every semi-sharp
sharpness has decayed (N > the largest finite sharpness), the limit point of a vertex has a
closed-form mask: smooth rule (any valence) ``(k^2 V + 4 sum e + sum d) / (k (k + 5))``, crease rule
(two sharp edges) ``(e0 + 4 V + e1) / 6`` along the crease, corner rule ``V``. Darts have no
closed-form mask and are skipped. This checks the locality of the evaluator (the local refinement,
the regular nets with sharp ghosts, the stationary corner schemes), not the rules themselves (those
are checked against OpenSubdiv in test_osd_features.py).
"""

import math

import numpy as np
import pytest

from ccproof.evaluate import limit_surface
from ccproof.evaluate.local import CORNERS
from ccproof.mesh.io import read_obj_tagged
from ccproof.mesh.polymesh import PolyMesh
from ccproof.mesh.rules import CORNER, CREASE, SMOOTH, vertex_rule


def child_frame(i):
    c = np.array(CORNERS, dtype=float)
    return c[i], (c[(i + 1) % 4] - c[i]) / 2, (c[(i + 3) % 4] - c[i]) / 2


def compose(fr, sub):
    o, a, b = fr
    so, sa, sb = sub
    return o + a * so[0] + b * so[1], a * sa[0] + b * sa[1], a * sb[0] + b * sb[1]


def refine_with_frames(mesh, levels):
    """Refine ``levels`` times; return the last mesh and, per face, (ptex, frame in ptex (s, t))."""
    m, _ = mesh.refine()
    frames = []
    ident = (np.zeros(2), np.array([1.0, 0.0]), np.array([0.0, 1.0]))
    for f in range(mesh.n_faces):
        k = int(mesh.sizes[f])
        for i in range(k):
            if k == 4:
                frames.append((int(mesh.ptex_start[f]), child_frame(i)))
            else:
                frames.append((int(mesh.ptex_start[f]) + i, ident))
    for _ in range(levels - 1):
        m, _ = m.refine()
        frames = [(p, compose(fr, child_frame(i))) for p, fr in frames for i in range(4)]
    return m, frames


def limit_point(m, cx, v):
    """Closed-form limit point of vertex v of an all-quad refined mesh without semi-sharp tags, or None."""
    es, nb, fan, closed = cx.vertex_edges(v)
    sh = [cx.sharpness(e) for e in es]
    assert all(s == 0 or math.isinf(s) for s in sh)
    rule = vertex_rule(cx.vsharp(v), sh)
    X = m.vertices
    if rule == CORNER:
        return X[v]
    if rule == CREASE:
        e0, e1 = (u for u, s in zip(nb, sh) if s > 0)
        return (X[e0] + 4 * X[v] + X[e1]) / 6
    if rule == SMOOTH:
        k = len(fan)
        d = [cx.org[cx.nxt[cx.nxt[c]]] for c in fan]
        return (k * k * X[v] + 4 * X[nb].sum(axis=0) + X[d].sum(axis=0)) / (k * (k + 5))
    return None  # dart


def _chaikin_grid():
    V = [[x, y, 0.3 * math.sin(x + 2 * y)] for y in range(5) for x in range(5)]
    F = [[5 * y + x, 5 * y + x + 1, 5 * y + x + 6, 5 * y + x + 5] for y in range(4) for x in range(4)]
    creases = {(10, 11): 1.5, (11, 12): 2.5, (12, 13): 0.5, (13, 14): 2.0, (7, 12): 1.25, (12, 17): 2.5}
    return PolyMesh(V, F, creases=creases, corners={6: 1.5}, options={"crease_method": "chaikin"})


def _shape(refdir, name):
    return read_obj_tagged(refdir / "osd_features" / "meshes" / f"catmark_{name}.obj")


CASES = [("chaikin_grid", 3), ("pyramid_creases1", 4), ("cube_creases0", 3), ("nonquads", 3),
         ("edgecorner", 3), ("cubes_infsharp", 2), ("dart_edgeonly", 3)]


@pytest.mark.parametrize("name,levels", CASES)
def test_dyadic_points_equal_subdivision_limits(refdir, name, levels):
    mesh = _chaikin_grid() if name == "chaikin_grid" else _shape(refdir, name)
    S = limit_surface(mesh)
    m, frames = refine_with_frames(mesh, levels)
    assert all(s == 0 or math.isinf(s) for s in m.edge_sharpness.values())
    rng = np.random.default_rng(1)
    faces = set(rng.choice(m.n_faces, size=min(m.n_faces, 150), replace=False).tolist())
    # and every level-N face at a base vertex (vertex points keep their index) or an n-gon centre
    # (the level-1 face point n + E + f keeps its index too): the points next to creases, corners,
    # darts, extraordinary vertices and n-gon centres, at distance 2^-N
    E1 = len(mesh.complex().edges)
    special = set(range(mesh.n_vertices)) | {mesh.n_vertices + E1 + f for f in np.flatnonzero(mesh.sizes != 4)}
    faces |= {g for g, poly in enumerate(m.polygons) if special.intersection(poly)}
    pts, want = [], []
    cx = m.complex()
    for g in sorted(faces):
        p, (o, a, b) = frames[g]
        if mesh.is_hole[mesh.face_of_ptex(p)[0]]:
            continue
        for i, v in enumerate(m.polygons[g]):
            L = limit_point(m, cx, v)
            if L is None:
                continue
            st = o + a * CORNERS[i][0] + b * CORNERS[i][1]
            pts.append((p, st[0], st[1]))
            want.append(L)
    assert len(pts) >= 300
    assert special.intersection(m.polygons[g][i] for g in faces for i in range(4))
    f, s, t = (np.array([q[i] for q in pts]) for i in range(3))
    got = S.evaluate(f.astype(int), s, t, 0)["P"]
    err = np.abs(got - np.array(want)).max() / mesh.bounding_box_diagonal
    print(name, len(pts), "points, max error / diagonal", err)
    assert err <= 1e-13, err


@pytest.mark.parametrize("name", ["chaikin_grid", "pyramid_creases1", "cubes_infsharp", "nonquads"])
def test_derivatives_match_central_differences(refdir, name):
    mesh = _chaikin_grid() if name == "chaikin_grid" else _shape(refdir, name)
    S = limit_surface(mesh)
    rng = np.random.default_rng(2)
    n = 400
    f = rng.integers(0, mesh.n_ptex, n)
    s, t = 0.02 + 0.96 * rng.random(n), 0.02 + 0.96 * rng.random(n)
    h = 1e-6
    r = S.evaluate(f, s, t, 2)
    scale = mesh.bounding_box_diagonal
    for key, (ds, dt) in (("Pu", (h, 0)), ("Pv", (0, h))):
        fd = (S.evaluate(f, s + ds, t + dt, 0)["P"] - S.evaluate(f, s - ds, t - dt, 0)["P"]) / (2 * h)
        assert np.abs(fd - r[key]).max() <= 1e-6 * scale * 10, key
    for key, src, (ds, dt) in (("Puu", "Pu", (h, 0)), ("Puv", "Pu", (0, h)), ("Pvv", "Pv", (0, h))):
        fd = (S.evaluate(f, s + ds, t + dt, 1)[src] - S.evaluate(f, s - ds, t - dt, 1)[src]) / (2 * h)
        assert np.abs(fd - r[key]).max() <= 1e-4 * scale * 10, key
