#!/usr/bin/env python
"""A/B benchmark of the one vectorized Catmull-Clark step (:func:`ccproof.mesh.step.catmark_operator`).

Against the implementations it replaced, kept below verbatim as baselines (the evaluator's untagged
polygon step from face points, the untagged quad operator assembled in floats, the applications'
tagged step with ``refine_complex`` on the fans of semi-sharp vertices), in one process, taking turns
round by round (min, median, max of the ratio new / old per round; the 1-minute load before each round):

1. ``subdivision_matrix`` on bunny_quads subdivided once;
2. ``tagged_step`` on catmark_cubes_infsharp and catmark_pyramid_creases1 (semi-sharp) subdivided twice
   (the former code as "old", the operator as "new");
3. the step's fast path (:func:`ccproof.mesh.step_fast.catmark_step`, the points from the face points) as "new"
   against the operator (``catmark_operator`` without scipy, then ``apply_csr``) as "old", on an icosphere of
   triangles (``--tri-levels``, default 5: 20,480 triangles; the setup of a scan takes this step).

The baselines' private helpers are copied here verbatim too (``_boundary_neighbours``, ``_decrement``,
``_pair_keys``, ``_semi``, ``_fan_complex``): the script uses public names of ccproof only. The former A/B of
the evaluator's polygon step swapped into the evaluator by assignment is no longer measured (it needed a private
module); case 3 times the fast path itself.

Usage: python scripts/bench_step.py [--rounds 7] [--smoke]
"""

from __future__ import annotations

import argparse
import math
import os
import statistics
import time
from pathlib import Path

import numpy as np

from ccproof.apps.control_file import read_control_mesh
from ccproof.apps.control_mesh import subdivide_control, tags_of, vertex_rules
from ccproof.mesh import QuadMesh, subdivide
from ccproof.rule_weights import (
    crease_vertex_weights,
    face_point_weight,
    sharp_edge_weight,
    smooth_edge_weights,
    smooth_vertex_weights,
)

REPO = Path(__file__).resolve().parent.parent
DATA = REPO / "tests" / "data"


# ------------------------------------------------------------------ the baselines (the former code)
#: ccproof.mesh.rules.INFINITE (the sharpness that means infinitely sharp)
INFINITE = 10.0
_F32 = np.float32
_ONE = _F32(1.0)


def _boundary_neighbours(mesh):
    """For every boundary vertex its two boundary neighbours (e0 after it, e1 before it)."""
    F = mesh.faces
    org = F.reshape(-1)
    dst = np.roll(F, -1, axis=1).reshape(-1)
    bh = np.flatnonzero(mesh.twin < 0)
    n = mesh.n_vertices
    e0 = np.full(n, -1, dtype=np.int64)
    e1 = np.full(n, -1, dtype=np.int64)
    e0[org[bh]] = dst[bh]
    e1[dst[bh]] = org[bh]
    return e0, e1


def _decrement(s):
    if s <= 0.0:
        return 0.0
    if s >= INFINITE:
        return math.inf
    if s > 1.0:
        return float(_F32(s) - _ONE)
    return 0.0


def _pair_keys(pairs, n):
    p = np.asarray(pairs, dtype=np.int64).reshape(-1, 2)
    return np.minimum(p[:, 0], p[:, 1]) * n + np.maximum(p[:, 0], p[:, 1])


def _semi(x):
    return (x > 0) & np.isfinite(x)


def _fan_complex(mesh: QuadMesh, v, edge_sharpness, vertex_sharpness):
    """The faces around ``v`` as a :class:`ccproof.mesh.rules.Complex` in local labels (``v`` is label 0),
    with the sharpness of the edges at ``v`` and of ``v``; and the local -> global vertex map."""
    from ccproof.mesh.rules import Complex, Options

    c = mesh.fan_corners[mesh.fan_ptr[v]: mesh.fan_ptr[v] + mesh.face_count[v]]
    F = mesh.faces[(c // 4)[:, None], ((c % 4)[:, None] + np.arange(4)[None, :]) % 4]  # each face from v
    glob, loc = np.unique(F, return_inverse=True)
    order = np.argsort(glob != v, kind="stable")  # v -> label 0
    rank = np.empty_like(order)
    rank[order] = np.arange(order.size)
    faces = rank[loc.reshape(F.shape)]
    gl = glob[order]
    tags = {}
    ekey = _pair_keys(np.c_[np.full(F.shape[0] * 2, v), np.r_[F[:, 1], F[:, 3]]], mesh.n_vertices)
    allkey = _pair_keys(mesh.edges, mesh.n_vertices)
    srt = np.argsort(allkey)
    pos = srt[np.searchsorted(allkey[srt], ekey)]
    for u, e in zip(np.r_[F[:, 1], F[:, 3]].tolist(), pos.tolist()):
        s = float(edge_sharpness[e])
        if s > 0 and not mesh.is_boundary_edge[e]:
            lu = int(rank[np.searchsorted(glob, u)])
            tags[(0, lu)] = s
    vs = float(vertex_sharpness[v])
    cx = Complex(faces.tolist(), tags, {0: vs} if vs > 0 else {}, Options(), level=1, n_vertices=gl.size)
    return cx, gl

def old_subdivision_matrix(mesh):
    F = mesh.faces
    n, E, m = mesh.n_vertices, mesh.n_edges, mesh.n_faces
    rows, cols, vals = [], [], []

    def add(r, c, w):
        r, c = np.broadcast_arrays(np.asarray(r), np.asarray(c))
        rows.append(r.reshape(-1))
        cols.append(c.reshape(-1))
        vals.append(np.broadcast_to(np.asarray(w, dtype=np.float64), r.shape).reshape(-1))

    one = 1.0  # the rule functions in floats (exact_one() would give the exact weights)
    wq = face_point_weight(4, one)
    # face points
    add(np.repeat(n + E + np.arange(m), 4), F.reshape(-1), wq)
    # edge points
    a, b = mesh.edges[:, 0], mesh.edges[:, 1]
    er = n + np.arange(E)
    bnd = mesh.is_boundary_edge
    half = sharp_edge_weight(one)
    add(er[bnd], a[bnd], half)
    add(er[bnd], b[bnd], half)
    it = ~bnd
    we_end, we_face = smooth_edge_weights(one)
    add(er[it], a[it], we_end)
    add(er[it], b[it], we_end)
    for s in range(2):  # the face point of each adjacent face, spelled out on its vertices
        add(np.repeat(er[it], 4), F[mesh.edge_faces[it, s]].reshape(-1), we_face * wq)
    # interior vertex points (smooth rule), assembled corner by corner
    org = F.reshape(-1)
    dst = np.roll(F, -1, axis=1).reshape(-1)
    inner = ~mesh.is_boundary_vertex
    k = np.maximum(mesh.valence.astype(np.int64), 1)  # (unused vertices: valence 0, weights unused)
    wv, we, wf = smooth_vertex_weights(k, one)
    iv = np.flatnonzero(inner)
    add(iv, iv, wv[iv])
    c = np.flatnonzero(inner[org])  # corners at interior vertices: one edge and one face each
    v = org[c]
    add(v, dst[c], we[v])
    add(np.repeat(v, 4), F[c // 4].reshape(-1), np.repeat(wf[v] * wq, 4))
    # boundary vertex points (crease rule along the boundary)
    bv = np.flatnonzero(mesh.is_boundary_vertex)
    if bv.size:
        e0, e1 = _boundary_neighbours(mesh)
        wc, wn = crease_vertex_weights(one)
        add(bv, bv, wc)
        add(bv, e0[bv], wn)
        add(bv, e1[bv], wn)
    import scipy.sparse as sp

    S = sp.coo_matrix(
        (np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(n + E + m, n)
    )
    return S.tocsr()


def _local_step_rows(mesh: QuadMesh, v, edge_sharpness, vertex_sharpness):
    from ccproof.mesh.rules import refine_complex, to_float

    cx, gl = _fan_complex(mesh, v, edge_sharpness, vertex_sharpness)
    inc = [e for e, h in enumerate(cx.edges) if cx.org[h] == 0 or cx.dst(h) == 0]
    stencils, _, _, _ = refine_complex(cx, vertices=[0], edges=inc)
    n = cx.n_vertices

    def glob(st):
        return {int(gl[c]): to_float(w) for c, w in st.items()}

    edges = {}
    for e in inc:
        h = cx.edges[e]
        u = cx.dst(h) if cx.org[h] == 0 else cx.org[h]
        edges[int(gl[u])] = glob(stencils[n + e])
    return glob(stencils[0]), edges


def old_tagged_step(mesh: QuadMesh, edge_sharpness=None, vertex_sharpness=None):
    import scipy.sparse as sp


    if edge_sharpness is None:
        edge_sharpness, vertex_sharpness = tags_of(mesh)
    S = old_subdivision_matrix(mesh)
    n = mesh.n_vertices
    es, vs = edge_sharpness, vertex_sharpness
    se = np.flatnonzero(es > 0)
    none = (np.zeros((0, 2), dtype=np.int64), np.zeros(0)), (np.zeros(0, dtype=np.int64), np.zeros(0))
    if not se.size and not (vs > 0).any():
        return S, *none
    _, corner, crease, _, nb, stationary = vertex_rules(mesh, es, vs)
    a, b = mesh.edges[se, 0], mesh.edges[se, 1]
    touched = vs > 0
    touched[a] = touched[b] = True
    cor = np.flatnonzero(touched & corner & stationary)
    cre = np.flatnonzero(touched & crease & stationary)
    inf_e = se[np.isinf(es[se])]
    er = n + inf_e
    wv, wn = crease_vertex_weights(1.0)
    half = sharp_edge_weight(1.0)
    rows = [cor, cre, cre, cre, er, er]
    cols = [cor, cre, nb[cre, 0], nb[cre, 1], mesh.edges[inf_e, 0], mesh.edges[inf_e, 1]]
    vals = [np.ones(cor.size), np.full(cre.size, wv), np.full(2 * cre.size, wn), np.full(2 * er.size, half)]
    replaced = [cor, cre, er]
    moving = np.flatnonzero(~stationary)
    if moving.size:  # semi-sharp: the exact stencils of the rules on the vertex's fan
        key = _pair_keys(mesh.edges, n)
        srt = np.argsort(key)
        r_, c_, w_ = [], [], []
        for v in moving.tolist():
            vrow, erows = _local_step_rows(mesh, v, es, vs)
            r_ += [v] * len(vrow)
            c_ += list(vrow)
            w_ += list(vrow.values())
            for u, st in erows.items():
                e = int(srt[np.searchsorted(key[srt], min(u, v) * n + max(u, v))])
                if _semi(es[e]):
                    r_ += [n + e] * len(st)
                    c_ += list(st)
                    w_ += list(st.values())
        rows.append(np.asarray(r_, dtype=np.int64))
        cols.append(np.asarray(c_, dtype=np.int64))
        vals.append(np.asarray(w_, dtype=np.float64))
        replaced.append(np.unique(rows[-1]))
    replace = np.ones(S.shape[0])
    replace[np.concatenate(replaced)] = 0.0
    extra = sp.coo_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=S.shape)
    # an edge point computed from both of its ends is the same stencil: keep one (halve the sum)
    out = (sp.diags(replace) @ S + _dedup(extra)).tocsr()
    out.eliminate_zeros()
    child_s = np.array([_decrement(x) for x in es[se].tolist()])
    keep = child_s > 0
    er_all = n + se
    ce = np.r_[np.c_[a, er_all][keep], np.c_[b, er_all][keep]]
    cs = np.r_[child_s[keep], child_s[keep]]
    cv = np.flatnonzero(vs > 0)
    cvs = np.array([_decrement(x) for x in vs[cv].tolist()])
    return out, (ce, cs), (cv[cvs > 0], cvs[cvs > 0])


def _dedup(M):
    M = M.tocoo()
    if not M.nnz:
        return M
    import scipy.sparse as sp

    key = np.c_[M.row, M.col]
    _, first = np.unique(key, axis=0, return_index=True)
    return sp.coo_matrix((M.data[first], (M.row[first], M.col[first])), shape=M.shape)


# ------------------------------------------------------------------ the runs
def _icosphere(levels):
    """An icosphere: the icosahedron's triangles split ``levels`` times, projected to the sphere."""
    t = (1 + 5 ** 0.5) / 2
    V = [[-1, t, 0], [1, t, 0], [-1, -t, 0], [1, -t, 0], [0, -1, t], [0, 1, t], [0, -1, -t], [0, 1, -t],
         [t, 0, -1], [t, 0, 1], [-t, 0, -1], [-t, 0, 1]]
    F = [[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9], [5, 11, 4], [11, 10, 2],
         [10, 7, 6], [7, 1, 8], [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8], [3, 8, 9], [4, 9, 5], [2, 4, 11],
         [6, 2, 10], [8, 6, 7], [9, 8, 1]]
    V = [np.array(v, dtype=float) / np.linalg.norm(v) for v in V]
    for _ in range(levels):
        mid, G = {}, []
        for a, b, c in F:
            m = []
            for p, q in ((a, b), (b, c), (c, a)):
                k = (min(p, q), max(p, q))
                if k not in mid:
                    x = V[p] + V[q]
                    V.append(x / np.linalg.norm(x))
                    mid[k] = len(V) - 1
                m.append(mid[k])
            G += [[a, m[0], m[2]], [b, m[1], m[0]], [c, m[2], m[1]], m]
        F = G
    return np.array(V), np.array(F)


def _stats(r):
    return f"min {min(r):.3f}  median {statistics.median(r):.3f}  max {max(r):.3f}"


def _ab(name, old, new, rounds):
    ratios, loads, t_old, t_new = [], [], [], []
    old(), new()  # warm-up (imports, the disk cache)
    for i in range(rounds):
        loads.append(os.getloadavg()[0])
        pair = [(old, t_old), (new, t_new)] if i % 2 == 0 else [(new, t_new), (old, t_old)]
        for f, acc in pair:
            t0 = time.perf_counter()
            f()
            acc.append(time.perf_counter() - t0)
        ratios.append(t_new[-1] / t_old[-1])
    print(f"{name:52s} old {min(t_old) * 1e3:8.1f} ms  new {min(t_new) * 1e3:8.1f} ms  new/old {_stats(ratios)}"
          f"  (load {min(loads):.1f}-{max(loads):.1f})", flush=True)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--rounds", type=int, default=7)
    ap.add_argument("--tri-levels", type=int, default=5, help="icosphere of case 3: 20 * 4^L triangles")
    ap.add_argument("--smoke", action="store_true", help="one round on the smallest inputs (the test suite's run)")
    a = ap.parse_args(argv)
    from ccproof.apps.control_mesh import tagged_step
    from ccproof.mesh import subdivision_matrix
    from ccproof.mesh.io import read_mesh

    rounds = 1 if a.smoke else a.rounds
    print(f"{os.cpu_count()} cpus; rounds {rounds}", flush=True)
    bunny = read_mesh(DATA / "meshes" / "bunny_quads.obj").to_quad_mesh()
    b1 = bunny if a.smoke else subdivide(bunny)
    _ab(f"subdivision_matrix bunny level {0 if a.smoke else 1} ({b1.n_faces:,} quads)",
        lambda: old_subdivision_matrix(b1), lambda: subdivision_matrix(b1), rounds)
    for name in ("catmark_cubes_infsharp", "catmark_pyramid_creases1"):
        m, _ = read_control_mesh(DATA / "osd_features" / "meshes" / f"{name}.obj")
        m = subdivide_control(subdivide_control(m))
        _ab(f"tagged_step {name} level 2 ({m.n_faces:,} quads)", lambda m=m: old_tagged_step(m),
            lambda m=m: tagged_step(m), rounds)
    _fast_path(1 if a.smoke else a.tri_levels, rounds)


def _fast_path(levels, rounds):
    """Case 3: catmark_step against the operator's step on an icosphere (points compared to round-off first)."""
    from ccproof.mesh import PolyMesh
    from ccproof.mesh.csr import apply_csr
    from ccproof.mesh.step import StepOptions, catmark_operator
    from ccproof.mesh.step_fast import catmark_step

    V, F = _icosphere(levels)
    pm = PolyMesh(V, F.tolist())
    he = pm.halfedges

    def operator():
        st = catmark_operator(pm.n_vertices, he.org, he.sizes, halfedges=he,
                              options=StepOptions(pm.options, pm.level, sparse=False))
        return apply_csr(st.csr, pm.vertices), st.faces

    (X0, F0), (X1, F1) = operator(), catmark_step(pm)
    if not np.array_equal(F0, F1) or np.abs(X0 - X1).max() > 1e-15:
        raise SystemExit("the fast path and the operator differ")
    _ab(f"catmark_step / operator icosphere ({len(F):,} triangles)", operator, lambda: catmark_step(pm), rounds)


if __name__ == "__main__":
    main()
