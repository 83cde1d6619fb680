#!/usr/bin/env python
"""Reproduce the comparisons of He, Schaefer, Hormann 2010 (Figs. 1, 4, 6, 7) on our meshes.

For every case, the four methods of the paper, measured the same way (metrics at level 5):
(a) ARAP on the triangulated control mesh, (b) ours with boundary rules, (c) ours with extended
charts, (d) ARAP on the control mesh subdivided 3 times. Cases:

* ``ev5``: a saddle-shaped disk around a valence-5 vertex, zigzag chart containing it;
* ``ev24``: a bowl around a valence-24 vertex, chart = 8 of its 24 sectors (the chart boundary
  turns by 120 degrees at the extraordinary vertex: hsh10 Fig. 4);
* ``cylinder``: half of an open tube (developable);
* ``bunny_patch``: an open patch of the quad bunny (``grow_patch(1000, 8)``) as one chart of the
  closed surface;
* ``bunny_charts``: the closed bunny cut by ``segment_by_normals`` (hsh10 Fig. 6).

Figures (PNG, in ``--out``, default ``out/hsh10``): ``<case>_compare.png`` (checkerboard on the limit surface and the
per-sample area distortion s1 s2 + 1/(s1 s2), colour from 2 (blue) to the 99th percentile of (a)
(red), chart boundaries in black), ``<case>_texture.png`` (texture control meshes of (a), (b), (c),
extension ring in red, and the subdivided chart boundary), ``levels_bunny_patch.png`` (extended
charts optimized at k = 1, 2, 3: hsh10 Fig. 7). ``summary.json`` holds every number.

Usage:  python scripts/reproduce_hsh10.py [--out DIR] [--cases ev5,cylinder,...] [--engine igl|numpy]
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

from ccproof.apps.arap.charts import grow_patch, segment_by_normals
from ccproof.apps.arap.core import METHOD_NAMES, ChartTexture, Solver, initial_texture, optimize_chart, texture_metrics
from ccproof.apps.arap.hierarchy import ChartHierarchy
from ccproof.apps.arap.meshes import compare
from ccproof.apps.arap.metrics import sample_metrics
from ccproof.apps.arap.samples import build_samples, limit_operator
from ccproof.mesh import QuadMesh, read_obj
from ccproof.mesh.examples import k_regular_disk

REPO = Path(__file__).resolve().parents[1]
BUNNY = REPO / "tests" / "data" / "meshes" / "bunny_quads.obj"


# --------------------------------------------------------------------------- cases
def tube(na=16, nz=10):
    r = na / (2 * np.pi)
    i, j = np.meshgrid(np.arange(na), np.arange(nz + 1), indexing="ij")
    V = np.stack([r * np.cos(2 * np.pi * i / na), r * np.sin(2 * np.pi * i / na), j * 1.0], -1).reshape(-1, 3)
    idx = np.arange(na * (nz + 1)).reshape(na, nz + 1)
    F = np.stack([idx[:, :-1], np.roll(idx, -1, 0)[:, :-1], np.roll(idx, -1, 0)[:, 1:], idx[:, 1:]], -1)
    return QuadMesh(V, F.reshape(-1, 4))


def polar_disk(k, rings, height):
    """k_regular_disk(k, rings) with its vertex (j, a, b) moved onto the circle of radius max(a, b),
    at its place along the sector's ring (a spider web instead of k thin parallelogram sectors)."""
    m = k_regular_disk(k, rings)
    R = rings
    V = np.zeros((m.n_vertices, 3))
    vid = np.arange(1, m.n_vertices)
    j, rem = np.divmod(vid - 1, R * (R + 1))
    a, b = rem // (R + 1) + 1, rem % (R + 1)
    r = np.maximum(a, b)
    t = np.where(b <= a, b, 2 * r - a)  # position along the ring (r, 0) -> (r, r) -> (0, r) of the sector
    th = 2 * np.pi * (j + t / (2 * r)) / k
    V[1:, 0] = r * np.cos(th)
    V[1:, 1] = r * np.sin(th)
    V[:, 2] = height(V[:, 0], V[:, 1])
    return m.with_vertices(V)


def case(name):
    """(mesh, labels, view (elev, azim), render level, description)."""
    if name == "ev5":
        m = k_regular_disk(5, rings=4, height=lambda x, y: 0.15 * (x**2 - 0.5 * y**2))
        chart = [(j * 4 + a) * 4 + b for j in range(5) for a in range(3) for b in range(3) if a + b < 4]
        lab = -np.ones(m.n_faces, dtype=int)
        lab[chart] = 0
        return m, lab, (50, -60), 5, "saddle around a valence-5 vertex, zigzag chart (40 faces)"
    if name == "ev24":
        m = polar_disk(24, 3, height=lambda x, y: 0.08 * (x**2 + y**2))
        lab = -np.ones(m.n_faces, dtype=int)
        lab[: 8 * 9] = 0  # sectors 0..7 of 24
        return m, lab, (60, -100), 5, "bowl around a valence-24 vertex, chart = 8 of 24 sectors (72 faces)"
    if name == "cylinder":
        m = tube(16, 10)
        lab = -np.ones(m.n_faces, dtype=int)
        lab[[i * 10 + j for i in range(8) for j in range(2, 8)]] = 0
        return m, lab, (20, -40), 5, "half of an open tube, 8 x 6 faces (developable)"
    if name in ("bunny_patch", "bunny_charts"):
        m = read_obj(BUNNY)
        if name == "bunny_patch":
            lab = -np.ones(m.n_faces, dtype=int)
            lab[grow_patch(m, 1000, 8)] = 0
            return m, lab, "auto", 4, "open patch of the bunny (283 faces) as one chart of the closed surface"
        return m, segment_by_normals(m), (15, -25, "y"), 3, "closed bunny, segment_by_normals charts"
    raise SystemExit(f"unknown case {name!r}")


# --------------------------------------------------------------------------- rendering
def chart_surface(tex: ChartTexture, level):
    """Limit points of the surface and of the texture at the level-``level`` chart vertices."""
    h = tex.hierarchy
    L = h.level(level)
    X = h.subdivide_values(tex.values, tex.rules, tex.level, level)
    P = limit_operator(L, "extended") @ L.mesh.vertices
    T = limit_operator(L, tex.rules) @ X
    return L, P, T


def vertex_values(vertex, values, n):
    """Mean of the per-sample ``values`` at every level-k vertex (corner samples share a vertex)."""
    acc = np.zeros(n)
    cnt = np.zeros(n)
    np.add.at(acc, vertex, values)
    np.add.at(cnt, vertex, 1)
    return acc / np.maximum(cnt, 1)


#: coordinate permutation that makes the mesh's "up" axis the z axis of the renderer
UP = {"z": [0, 1, 2], "y": [2, 0, 1]}


def project(P, view):
    """Orthographic projection; view = (elev, azim[, up]) with up "z" (default) or "y"."""
    P = P[:, UP[view[2] if len(view) > 2 else "z"]]
    elev, azim = np.radians(view[0]), np.radians(view[1])
    d = np.array([np.cos(elev) * np.cos(azim), np.cos(elev) * np.sin(azim), np.sin(elev)])  # towards viewer
    right = np.cross([0, 0, 1.0], d)
    right /= np.linalg.norm(right)
    up = np.cross(d, right)
    return np.stack([P @ right, P @ up], 1), P @ d, d


def draw(ax, items, view, cull):
    """items: list of (P (n,3), F (m,4), rgb (m,3), boundary segments (k,2,3)); painter's algorithm."""
    from matplotlib.collections import LineCollection, PolyCollection

    polys, cols, depth = [], [], []
    segs = []
    for P, F, rgb, (bsegs, bface) in items:
        xy, z, d = project(P, view)
        P = P[:, UP[view[2] if len(view) > 2 else "z"]]
        nrm = np.cross(P[F[:, 2]] - P[F[:, 0]], P[F[:, 3]] - P[F[:, 1]])
        nrm /= np.maximum(np.linalg.norm(nrm, axis=1, keepdims=True), 1e-300)
        facing = nrm @ d
        keep = facing > 0 if cull else np.ones(F.shape[0], dtype=bool)
        shade = 0.55 + 0.45 * np.abs(facing)
        polys.append(xy[F[keep]])
        cols.append(rgb[keep] * shade[keep, None])
        depth.append(z[F[keep]].mean(axis=1))
        if bsegs is not None and len(bsegs):
            bxy, bz, _ = project(bsegs.reshape(-1, 3), view)
            segs.append(bxy.reshape(-1, 2, 2)[keep[bface]])
    polys = np.concatenate(polys)
    cols = np.concatenate(cols)
    order = np.argsort(np.concatenate(depth))
    ax.add_collection(PolyCollection(polys[order], facecolors=np.clip(cols[order], 0, 1), edgecolors="none",
                                     antialiased=False))
    if segs:
        ax.add_collection(LineCollection(np.concatenate(segs), colors="k", linewidths=0.8))
    allp = polys.reshape(-1, 2)
    lo, hi = allp.min(axis=0), allp.max(axis=0)
    pad = 0.03 * (hi - lo).max()
    ax.set_xlim(lo[0] - pad, hi[0] + pad)
    ax.set_ylim(lo[1] - pad, hi[1] + pad)
    ax.set_aspect("equal")
    ax.axis("off")


def boundary_segments(L, P):
    """Chart boundary edges at level L (as 3D segments) and the chart face of each."""
    be = np.flatnonzero(L.chart_boundary_edge)
    e = L.mesh.edges[be]
    ef = L.mesh.edge_faces[be]
    face = np.where(ef[:, 0] < L.n_chart_faces, ef[:, 0], ef[:, 1])
    return np.stack([P[e[:, 0]], P[e[:, 1]]], 1), face


def compare_figure(path, name, desc, results, view, level, cull):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    methods = list(results)
    diag = None
    # per-face area distortion and checkerboard, per method
    panels = {}
    for mth in methods:
        chk, dist = [], []
        for tex in results[mth].textures:
            L, P, T = chart_surface(tex, level)
            F = L.chart_faces()
            S = build_samples(L, tex.rules, "metric")
            X = tex.hierarchy.subdivide_values(tex.values, tex.rules, tex.level, level)
            _, ps = sample_metrics(S, X, per_sample=True)
            vv = vertex_values(ps["vertex"], ps["area_distortion"], L.n_vertices)
            chk.append((P, F, T[F].mean(axis=1), boundary_segments(L, P)))
            dist.append((P, F, vv[F].mean(axis=1), boundary_segments(L, P)))
            if diag is None:
                diag = np.linalg.norm(np.ptp(P, axis=0))
        panels[mth] = (chk, dist)
    square = diag / 24
    vals = np.concatenate([d[2] for d in panels["a" if "a" in panels else methods[0]][1]])
    vmax = 2 + max(np.percentile(vals - 2, 99), 1e-6)
    fig, axes = plt.subplots(2, len(methods), figsize=(4.2 * len(methods), 8.4))
    axes = np.atleast_2d(axes).reshape(2, len(methods))
    cmap = matplotlib.colormaps["jet"]
    for j, mth in enumerate(methods):
        chk, dist = panels[mth]
        items = []
        for P, F, c, b in chk:
            k = (np.floor(c[:, 0] / square) + np.floor(c[:, 1] / square)).astype(int) % 2
            rgb = np.where(k[:, None] == 0, [0.95, 0.95, 0.95], [0.85, 0.2, 0.2])
            items.append((P, F, rgb, b))
        draw(axes[0, j], items, view, cull)
        met = results[mth].metrics
        axes[0, j].set_title(f"{METHOD_NAMES[mth]}\n({met.E_angle:.4f}, {met.E_area:.4f}, {met.E_stretch:.4f})",
                             fontsize=9)
        items = []
        for P, F, v, b in dist:
            rgb = cmap(np.clip((v - 2) / (vmax - 2), 0, 1))[:, :3]
            items.append((P, F, rgb, b))
        draw(axes[1, j], items, view, cull)
        axes[1, j].set_title(f"area distortion (flips at level 5: {met.flips})", fontsize=9)
    fig.suptitle(f"{name}: {desc}\n(E_angle, E_area, E_stretch) at level 5; area distortion colour 2 (blue) .. "
                 f"{vmax:.4f} (red)", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return vmax


def texture_figure(path, name, results):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.collections import LineCollection

    methods = [m for m in ("a", "b", "c") if m in results]
    fig, axes = plt.subplots(1, len(methods), figsize=(5 * len(methods), 5))
    axes = np.atleast_1d(axes)
    for ax, mth in zip(axes, methods):
        tex = results[mth].textures[0]
        h = tex.hierarchy
        L0 = h.level(0)
        X = tex.values
        F0 = L0.mesh.faces
        fe = np.concatenate([F0[:, [0, 1]], F0[:, [1, 2]], F0[:, [2, 3]], F0[:, [3, 0]]])
        ischart = np.tile(np.arange(F0.shape[0]) < L0.n_chart_faces, 4)
        if tex.rules == "extended":
            ax.add_collection(LineCollection(X[fe[~ischart]], colors="r", linewidths=0.6))
        ax.add_collection(LineCollection(X[fe[ischart]], colors="k", linewidths=0.6))
        L3, _, T3 = chart_surface(tex, 3)
        e = L3.mesh.edges[L3.chart_boundary_edge]
        ax.add_collection(LineCollection(np.stack([T3[e[:, 0]], T3[e[:, 1]]], 1), colors="b", linewidths=1.2))
        pts = X[np.unique(F0 if tex.rules == "extended" else F0[: L0.n_chart_faces])]
        lo, hi = pts.min(axis=0), pts.max(axis=0)
        ax.set_xlim(lo[0], hi[0])
        ax.set_ylim(lo[1], hi[1])
        ax.set_aspect("equal")
        ax.set_title(f"{METHOD_NAMES[mth]}: texture control mesh (black; ring red)\n"
                     f"and limit chart boundary (blue)", fontsize=9)
    fig.suptitle(name)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def levels_figure(path, mesh, labels, view, out):
    """(c) optimized at k = 1, 2, 3 only (hsh10 Fig. 7), each from the same LSCM start."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    faces = np.flatnonzero(labels == 0)
    h = ChartHierarchy(mesh, faces)
    X0 = initial_texture(h, "extended")
    rows = []
    texs = []
    for k in (1, 2, 3):
        t0 = time.perf_counter()
        X, st, _ = optimize_chart(h, "extended", X0, levels=k, start_level=k)
        sec = time.perf_counter() - t0
        tex = ChartTexture(h, "extended", 0, h.lift_unknowns(X, "extended"), X)
        met = texture_metrics(tex, 5)
        rows.append({"level": k, "E_angle": met.E_angle, "E_area": met.E_area, "E_stretch": met.E_stretch,
                     "E_arap": met.E_arap, "iterations": st[0].iterations, "seconds": sec,
                     "ms_per_iteration": 1e3 * st[0].seconds_per_iteration})
        texs.append((tex, met))
    fig, axes = plt.subplots(1, 3, figsize=(13, 4.8))
    cmap = matplotlib.colormaps["jet"]
    vmax = None
    for ax, (tex, met), row in zip(axes, texs, rows):
        L, P, T = chart_surface(tex, 4)
        S = build_samples(L, "extended", "metric")
        X = tex.hierarchy.subdivide_values(tex.values, "extended", 0, 4)
        _, ps = sample_metrics(S, X, per_sample=True)
        v = vertex_values(ps["vertex"], ps["area_distortion"], L.n_vertices)[L.chart_faces()].mean(axis=1)
        if vmax is None:
            vmax = 2 + max(np.percentile(v - 2, 99), 1e-6)
        rgb = cmap(np.clip((v - 2) / (vmax - 2), 0, 1))[:, :3]
        draw(ax, [(P, L.chart_faces(), rgb, boundary_segments(L, P))], view, False)
        ax.set_title(f"k = {row['level']}: ({met.E_angle:.5f}, {met.E_area:.5f}, {met.E_stretch:.5f})", fontsize=9)
    fig.suptitle(f"extended charts optimized at level k only (bunny patch); colour 2 .. {vmax:.4f}")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return rows


# --------------------------------------------------------------------------- main
def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", default="out/hsh10")
    ap.add_argument("--cases", default="ev5,ev24,cylinder,bunny_patch,bunny_charts")
    ap.add_argument("--engine", choices=["igl", "numpy"], default=None)
    args = ap.parse_args(argv)
    engine = args.engine
    if engine is None:
        try:
            import igl  # noqa: F401

            engine = "igl"
        except ImportError:
            engine = "numpy"
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    summary = {"engine": engine, "cases": {}}
    for name in args.cases.split(","):
        t0 = time.perf_counter()
        mesh, labels, view, level, desc = case(name)
        results, hs = compare(mesh, labels, solver=Solver(engine=engine))
        entry = {"description": desc, "charts": len(hs), "faces": int((labels >= 0).sum()), "methods": {}}
        for m, r in results.items():
            met = r.metrics
            entry["methods"][m] = {
                "name": r.name, "E_angle": met.E_angle, "E_area": met.E_area, "E_stretch": met.E_stretch,
                "E_area_rescaled": met.rescaled()[1], "E_arap": met.E_arap, "flips_level5": met.flips,
                "samples_level5": met.samples, "flips_control": r.flips_control,
                "triangles_control": r.triangles_control, "seconds": r.seconds, "iterations": r.iterations,
            }
        ea = {m: results[m].metrics.E_area - 2 for m in results}
        entry["area_excess_ratio_a_over_c"] = ea["a"] / ea["c"]
        entry["area_excess_ratio_c_over_d"] = ea["c"] / ea["d"]
        cull = name == "bunny_charts"
        if view == "auto":  # look along the mean normal of the chart
            F = mesh.faces[labels >= 0]
            V = mesh.vertices
            nrm = np.cross(V[F[:, 2]] - V[F[:, 0]], V[F[:, 3]] - V[F[:, 1]]).sum(axis=0)
            nrm /= np.linalg.norm(nrm)
            view = (float(np.degrees(np.arcsin(nrm[2]))), float(np.degrees(np.arctan2(nrm[1], nrm[0]))))
        entry["colour_max"] = compare_figure(out / f"{name}_compare.png", name, desc, results, view, level, cull)
        if len(hs) == 1:
            texture_figure(out / f"{name}_texture.png", name, results)
        if name == "bunny_patch":
            entry["levels"] = levels_figure(out / "levels_bunny_patch.png", mesh, labels, view, out)
        entry["seconds_total"] = time.perf_counter() - t0
        summary["cases"][name] = entry
        print(f"== {name}: {desc}  ({entry['seconds_total']:.1f} s)")
        for v in entry["methods"].values():
            print(f"   {v['name']:<30} {v['E_angle']:.6f} {v['E_area']:.6f} {v['E_stretch']:.6f}  "
                  f"flips T0 {v['flips_control']}/{v['triangles_control']}, L5 {v['flips_level5']}, "
                  f"{v['seconds']:.2f} s, {v['iterations']} it")
        print(f"   (E_area(a)-2)/(E_area(c)-2) = {entry['area_excess_ratio_a_over_c']:.2f} (paper Fig. 6: 6.0); "
              f"(E_area(c)-2)/(E_area(d)-2) = {entry['area_excess_ratio_c_over_d']:.3f}", flush=True)
        (out / "summary.json").write_text(json.dumps(summary, indent=1, default=float))
    print(f"wrote {out}/")
    return 0


if __name__ == "__main__":
    np.seterr(all="ignore")
    sys.exit(main())
