"""The chart hierarchy reproduces the surface and both texture rule sets.

Expected values: the mesh layer's global Catmull-Clark step applied to the whole mesh (surface and
extended-chart texture: docs/hsh10.md A8/A11.5), and the mesh layer's subdivision of the chart cut out as
its own mesh (crease boundary) with the corner rule V' = V written out here (boundary rules).
Vertices are matched by position (generic perturbed meshes: positions are distinct).
"""

import importlib.util
import pathlib

import numpy as np
import pytest
from scipy.spatial import cKDTree

from ccproof.apps.arap.hierarchy import ChartHierarchy
from ccproof.mesh import QuadMesh, subdivide, subdivision_matrix
from ccproof.mesh.examples import cube, grid, k_regular_disk, torus

_spec = importlib.util.spec_from_file_location("arap_meshes", pathlib.Path(__file__).with_name("_arap_meshes.py"))
M = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(M)


def snake_chart_grid():
    """A snake-shaped chart of grid(10, 10) whose ring touches itself at one outer vertex."""
    path = [(1, 1), (0, 1)] + [(0, y) for y in range(2, 10)] + [(x, 9) for x in range(1, 10)]
    path += [(9, y) for y in range(8, 3, -1)] + [(x, 4) for x in range(8, 3, -1)]
    return grid(10, 10), [x + 10 * y for x, y in path]


CASES = {
    "ev5-zigzag": lambda: (k_regular_disk(5, 4), M.zigzag_chart()),
    "cube-2faces": lambda: (cube(), [0, 2]),
    "torus-block": lambda: (torus(8, 6), [0, 1, 6, 7, 12, 13]),
    "snake": snake_chart_grid,
    "ev3-all": lambda: (k_regular_disk(3, 2), list(range(12))),  # chart touches the surface boundary
}


def _wavy(m, seed):
    rng = np.random.default_rng(seed)
    return m.with_vertices(m.vertices + 0.05 * rng.normal(size=m.vertices.shape))


@pytest.mark.parametrize("case", list(CASES))
def test_surface_and_extended_texture_equal_global_subdivision(case):
    m, chart = CASES[case]()
    m = _wavy(m, 1)
    h = ChartHierarchy(m, chart)
    rng = np.random.default_rng(2)
    T = rng.normal(size=(m.n_vertices, 2))
    g, Tg = m, T
    for k in range(1, 4):
        Tg = subdivision_matrix(g) @ Tg
        g = subdivide(g)
        L = h.level(k)
        d, idx = cKDTree(g.vertices).query(L.mesh.vertices)
        assert d.max() < 1e-13
        X = h.operator(k, "extended") @ T[h.unknown_vertices]
        assert np.abs(X - Tg[idx]).max() < 1e-13
        Xv = h.subdivide_values(h.lift_unknowns(T[h.unknown_vertices], "extended"), "extended", 0, k)
        assert np.abs(Xv - X).max() < 1e-13


def test_snake_chart_needs_a_split_vertex():
    m, chart = snake_chart_grid()
    h = ChartHierarchy(m, chart)
    assert h.orig0.size == h.unknown_vertices.size + 1


def _chart_submesh_step(sub, corner):
    """Crease-boundary CC step of the chart mesh (mesh layer) with the corner rule V' = V."""
    S = subdivision_matrix(sub).tolil()
    for v in np.flatnonzero(corner):
        S[v, :] = 0
        S[v, v] = 1
    return S.tocsr()


@pytest.mark.parametrize("case", ["ev5-zigzag", "cube-2faces", "torus-block", "snake"])
def test_boundary_rules_equal_the_chart_as_its_own_mesh(case):
    m, chart = CASES[case]()
    m = _wavy(m, 3)
    h = ChartHierarchy(m, chart)
    used, loc = np.unique(m.faces[chart], return_inverse=True)
    sub = QuadMesh(m.vertices[used], loc.reshape(-1, 4))
    rng = np.random.default_rng(4)
    # channels: 3 for matching vertices by position, 2 texture channels to compare
    D = np.hstack([sub.vertices, rng.normal(size=(sub.n_vertices, 2))])
    pos = {int(g): i for i, g in enumerate(used)}
    X0 = D[[pos[int(g)] for g in h.unknown_vertices[: h.n_chart_vertices]]]
    cur, Dg = sub, D
    # a one-face corner of the surface itself keeps the surface's crease rule (vertex points keep their index)
    surface_corner = np.flatnonzero(m.is_boundary_vertex[used] & (m.face_count[used] == 1))
    for k in range(1, 4):
        corner = cur.is_boundary_vertex & (cur.face_count == 1)
        corner[surface_corner] = False
        Dg = _chart_submesh_step(cur, corner) @ Dg
        cur = subdivide(cur)
        L = h.level(k)
        cv = np.flatnonzero(L.chart_vertex)
        A = h.operator(k, "boundary")
        X = (A @ X0)[cv]
        d, idx = cKDTree(Dg[:, :3]).query(X[:, :3])
        assert d.max() < 1e-13 and np.unique(idx).size == cv.size == Dg.shape[0]
        assert np.abs(X[:, 3:] - Dg[idx, 3:]).max() < 1e-13
        assert abs(A[np.flatnonzero(~L.chart_vertex)]).max() == 0  # boundary-rule textures live on the chart


def _fans_by_walk(F, n):
    """Independent fans: corners (f, i) at one vertex joined when their faces share an edge through it (plain
    Python union-find over the edges written out corner by corner)."""
    parent = list(range(4 * len(F)))

    def root(c):
        while parent[c] != c:
            parent[c] = parent[parent[c]]
            c = parent[c]
        return c

    at_edge = {}
    for f, face in enumerate(F):
        for i in range(4):
            v, w, u = face[i], face[(i + 1) % 4], face[(i - 1) % 4]
            for other in (w, u):  # the two edges of the face through corner (f, i)
                key = (v, other)
                if key in at_edge:
                    parent[root(4 * f + i)] = root(at_edge[key])
                else:
                    at_edge[key] = 4 * f + i
    fans = {}
    for c in range(4 * len(F)):
        fans.setdefault(root(c), []).append(c)
    return sorted(fans.values())  # each fan's corners increasing; fans by their smallest corner


@pytest.mark.parametrize("seed", range(6))
def test_split_nonmanifold_matches_a_fan_walk(seed):
    """Random face subsets of a torus and a valence-5 disk (fans touching at vertices): every fan of a vertex
    becomes a vertex of its own, the fan with the vertex's smallest corner keeps the index, the others get
    n, n + 1, ... by vertex then smallest corner (the documented numbering), faces otherwise unchanged."""
    from ccproof.apps.arap.hierarchy import split_nonmanifold

    rng = np.random.default_rng(seed)
    mesh = torus(8, 6) if seed % 2 else k_regular_disk(5, 3)
    keep = np.flatnonzero(rng.random(mesh.n_faces) < 0.55)
    used, inv = np.unique(mesh.faces[keep], return_inverse=True)
    F, n = inv.reshape(-1, 4), used.size
    fans = _fans_by_walk(F.tolist(), n)
    by_vertex = {}
    for fan in fans:
        by_vertex.setdefault(int(F.ravel()[fan[0]]), []).append(fan)
    expect = F.ravel().copy()
    orig = list(range(n))
    for v in sorted(by_vertex):
        for fan in by_vertex[v][1:]:
            expect[fan] = len(orig)
            orig.append(v)
    Fn, got_orig = split_nonmanifold(F, n)
    assert len(orig) > n  # the subset has vertices with several fans
    assert Fn.tolist() == expect.reshape(-1, 4).tolist() and got_orig.tolist() == orig
