#!/usr/bin/env python
"""Benchmark of exact limit evaluation (ccproof.evaluate) on the quad-remeshed Stanford bunny.

Measures, in one run:

1. points per second for positions + first derivatives at 10^6 random (face, u, v) on
   ``bunny_quads.obj`` (2,036 quads, 103 extraordinary vertices), for the numpy kernel and, when
   numba is installed, the compiled kernel; wall-clock and CPU-time rates (the CPU-time rate is
   the single-thread rate even on a loaded machine);
2. (a) a straightforward per-point implementation (Python loop over points, the same tables)
   on a subsample, extrapolated to the same number of points: ratio;
3. (b) uniform Catmull-Clark subdivision with pygel3d (if installed) level by level: time,
   size, and accuracy of the level-L control points as surface points (distance to their own
   limit positions, relative to the bounding-box diagonal), extrapolated to the level that would
   reach the accuracy of exact evaluation;
4. the peak memory beyond inputs and outputs for 10^7 points (tracemalloc);
5. side by side with OpenSubdiv Far (one thread, isolation level 10, Gregory end caps), on the bunny,
   a crease shape and a triangle shape: setup times and points/s for 10^6 uniform points and 10^6
   points near irregular vertices (distance 2^-(12 x) from the vertex, x uniform), ours with the
   numpy kernel, the compiled kernel on one thread and on all threads; ratios ours / OpenSubdiv,
   and the largest position difference. The C++ driver is compiled against the system's
   OpenSubdiv (Debian: ``apt-get install -y libosd-dev g++``); without it this part is skipped
   with that instruction.

The bunny mesh is read from the repository's test data (``tests/data/meshes/bunny_quads.obj``).

Usage: python scripts/bench_evaluate.py [--points 1000000] [--memory-points 10000000] [--quick] [--osd-only]
[--setup-only]  (``--setup-only``: only the setup times of part 5, ours and OpenSubdiv's; ours as the
first build in a fresh process with the per-configuration disk cache empty and filled, and in this process)
"""

from __future__ import annotations

import argparse
import math
import sys
import time
import tracemalloc
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from ccproof.evaluate import natural_limit_surface as limit_surface  # noqa: E402
from ccproof.evaluate.local import CORNERS  # noqa: E402
from ccproof.evaluate.surface import _CORNER, _SPLIT  # noqa: E402
from ccproof.mesh import limit_normals, limit_positions, read_obj, subdivide  # noqa: E402
from ccproof.mesh.io import read_mesh  # noqa: E402

OSD_DRIVER = r"""
// OpenSubdiv Far evaluation driver for scripts/bench_evaluate.py (written by the script).
// Input (binary, little endian): see write_mesh() in the script. Output: timings on stdout and the
// evaluated P, Ps, Pt of all points (double, n x 9) in the output file.
#include <opensubdiv/far/topologyDescriptor.h>
#include <opensubdiv/far/primvarRefiner.h>
#include <opensubdiv/far/patchTableFactory.h>
#include <opensubdiv/far/patchMap.h>
#include <chrono>
#include <cstdio>
#include <cstdint>
#include <vector>

using namespace OpenSubdiv;

struct V3 {
    double p[3];
    void Clear(void * = 0) { p[0] = p[1] = p[2] = 0; }
    void AddWithWeight(V3 const &s, double w) { p[0] += w * s.p[0]; p[1] += w * s.p[1]; p[2] += w * s.p[2]; }
};

template <class T> static void rd(FILE *f, T *x, size_t n) {
    if (n && fread(x, sizeof(T), n, f) != n) { fprintf(stderr, "short read\n"); exit(2); }
}

int main(int argc, char **argv) {
    if (argc < 5) { fprintf(stderr, "usage: driver mesh.bin points.bin out.bin level\n"); return 2; }
    FILE *fm = fopen(argv[1], "rb");
    int32_t hdr[8];  // nv nf nidx ncrease ncorner nhole boundary flags (1 chaikin, 2 smooth triangles)
    rd(fm, hdr, 8);
    int nv = hdr[0], nf = hdr[1], nidx = hdr[2], nc = hdr[3], nk = hdr[4], nh = hdr[5];
    std::vector<double> X(3 * nv); rd(fm, X.data(), X.size());
    std::vector<int> sizes(nf), idx(nidx), cre(2 * nc), cor(nk), holes(nh);
    std::vector<float> cw(nc), kw(nk);
    rd(fm, sizes.data(), nf); rd(fm, idx.data(), nidx); rd(fm, cre.data(), 2 * nc); rd(fm, cw.data(), nc);
    rd(fm, cor.data(), nk); rd(fm, kw.data(), nk); rd(fm, holes.data(), nh);
    fclose(fm);
    FILE *fp = fopen(argv[2], "rb");
    int64_t n; rd(fp, &n, 1);
    std::vector<int32_t> pf(n); std::vector<double> ps(n), pt(n);
    rd(fp, pf.data(), n); rd(fp, ps.data(), n); rd(fp, pt.data(), n);
    fclose(fp);
    int level = atoi(argv[4]);

    auto t0 = std::chrono::steady_clock::now();
    Sdc::Options so;
    so.SetVtxBoundaryInterpolation((Sdc::Options::VtxBoundaryInterpolation)hdr[6]);
    so.SetCreasingMethod(hdr[7] & 1 ? Sdc::Options::CREASE_CHAIKIN : Sdc::Options::CREASE_UNIFORM);
    so.SetTriangleSubdivision(hdr[7] & 2 ? Sdc::Options::TRI_SUB_SMOOTH : Sdc::Options::TRI_SUB_CATMARK);
    Far::TopologyDescriptor d;
    d.numVertices = nv; d.numFaces = nf; d.numVertsPerFace = sizes.data(); d.vertIndicesPerFace = idx.data();
    d.numCreases = nc; d.creaseVertexIndexPairs = cre.data(); d.creaseWeights = cw.data();
    d.numCorners = nk; d.cornerVertexIndices = cor.data(); d.cornerWeights = kw.data();
    d.numHoles = nh; d.holeIndices = holes.data();
    typedef Far::TopologyRefinerFactory<Far::TopologyDescriptor> Factory;
    Far::TopologyRefiner *ref = Factory::Create(d, Factory::Options(Sdc::SCHEME_CATMARK, so));
    Far::PatchTableFactory::Options po(level);
    po.SetEndCapType(Far::PatchTableFactory::Options::ENDCAP_GREGORY_BASIS);
    po.SetPatchPrecision<double>();
    po.useInfSharpPatch = true;
    po.generateLegacySharpCornerPatches = false;
    ref->RefineAdaptive(po.GetRefineAdaptiveOptions());
    Far::PatchTable *tab = Far::PatchTableFactory::Create(*ref, po);
    int nref = ref->GetNumVerticesTotal(), nloc = tab->GetNumLocalPoints();
    std::vector<V3> V(nref + nloc);
    for (int i = 0; i < nv; ++i) for (int c = 0; c < 3; ++c) V[i].p[c] = X[3 * i + c];
    Far::PrimvarRefinerReal<double> pr(*ref);
    V3 *src = V.data();
    for (int l = 1; l <= ref->GetMaxLevel(); ++l) {
        V3 *dst = src + ref->GetLevel(l - 1).GetNumVertices();
        pr.Interpolate(l, src, dst);
        src = dst;
    }
    if (nloc) tab->GetLocalPointStencilTable<double>()->UpdateValues(V.data(), V.data() + nref);
    Far::PatchMap pmap(*tab);
    auto t1 = std::chrono::steady_clock::now();

    std::vector<double> out(9 * n);
    double w[20], ws[20], wt[20];
    for (int64_t i = 0; i < n; ++i) {
        Far::PatchTable::PatchHandle const *h = pmap.FindPatch(pf[i], ps[i], pt[i]);
        double *o = &out[9 * i];
        for (int k = 0; k < 9; ++k) o[k] = 0;
        if (!h) { for (int k = 0; k < 9; ++k) o[k] = 0.0 / 0.0; continue; }
        tab->EvaluateBasis(*h, ps[i], pt[i], w, ws, wt);
        if (tab->GetPatchParam(*h).NonQuadRoot()) {  // EvaluateBasis scales by the depth of the
            for (int j = 0; j < 20; ++j) { ws[j] *= 0.5; wt[j] *= 0.5; }  // n-gon's level-1 quad
        }
        Far::ConstIndexArray cv = tab->GetPatchVertices(*h);
        for (int j = 0; j < cv.size(); ++j) {
            double const *p = V[cv[j]].p;
            for (int c = 0; c < 3; ++c) { o[c] += w[j] * p[c]; o[3 + c] += ws[j] * p[c]; o[6 + c] += wt[j] * p[c]; }
        }
    }
    auto t2 = std::chrono::steady_clock::now();
    FILE *fo = fopen(argv[3], "wb");
    fwrite(out.data(), sizeof(double), out.size(), fo);
    fclose(fo);
    printf("setup %.6f eval %.6f patches %d\n", std::chrono::duration<double>(t1 - t0).count(),
           std::chrono::duration<double>(t2 - t1).count(), tab->GetNumPatchesTotal());
    return 0;
}
"""


def build_osd_driver():
    """Compile the OpenSubdiv driver (cached in the temp folder); None with a message if impossible."""
    import shutil
    import subprocess
    import tempfile

    header = Path("/usr/include/opensubdiv/far/patchTable.h")
    if not header.exists() or shutil.which("g++") is None:
        print("   OpenSubdiv headers or g++ not found: install them with\n"
              "       apt-get update && apt-get install -y libosd-dev g++\n"
              "   (Debian/Ubuntu; elsewhere build OpenSubdiv and put far/ under /usr/include/opensubdiv)."
              " Skipped.")
        return None
    d = Path(tempfile.gettempdir()) / "ccproof_bench_osd"
    d.mkdir(exist_ok=True)
    src, exe = d / "driver.cpp", d / "driver"
    if not exe.exists() or not src.exists() or src.read_text() != OSD_DRIVER:
        src.write_text(OSD_DRIVER)
        r = subprocess.run(["g++", "-O2", "-std=c++14", str(src), "-o", str(exe), "-losdCPU"],
                           capture_output=True, text=True)
        if r.returncode != 0:
            print(f"   compiling the OpenSubdiv driver failed:\n{r.stderr[-2000:]}\n   Skipped.")
            return None
    return exe


def _write_osd_input(d, mesh, f, s, t):
    """Binary mesh and points files for the driver (layout read by its main())."""
    flags = int(mesh.options.crease_method == "chaikin") | 2 * int(mesh.options.triangle_subdivision == "smooth")
    bmode = {"none": 0, "edge_only": 1, "edge_and_corner": 2}[mesh.options.boundary]
    cre = list(mesh.edge_sharpness.items())
    cor = list(mesh.vertex_sharpness.items())
    holes = np.flatnonzero(mesh.is_hole_tagged).astype(np.int32)
    hdr = np.array([mesh.n_vertices, mesh.n_faces, mesh.indices.size, len(cre), len(cor), holes.size, bmode, flags],
                   dtype=np.int32)
    with open(d / "mesh.bin", "wb") as fh:
        fh.write(hdr.tobytes())
        fh.write(np.ascontiguousarray(mesh.vertices, dtype=np.float64).tobytes())
        fh.write(mesh.sizes.astype(np.int32).tobytes())
        fh.write(mesh.indices.astype(np.int32).tobytes())
        fh.write(np.array([e for e, _ in cre], dtype=np.int32).reshape(-1).tobytes())
        fh.write(np.array([min(x, 10.0) for _, x in cre], dtype=np.float32).tobytes())
        fh.write(np.array([v for v, _ in cor], dtype=np.int32).tobytes())
        fh.write(np.array([min(x, 10.0) for _, x in cor], dtype=np.float32).tobytes())
        fh.write(holes.tobytes())
    with open(d / "points.bin", "wb") as fh:
        fh.write(np.array([f.size], dtype=np.int64).tobytes())
        fh.write(f.astype(np.int32).tobytes())
        fh.write(np.ascontiguousarray(s, dtype=np.float64).tobytes())
        fh.write(np.ascontiguousarray(t, dtype=np.float64).tobytes())


def run_osd(exe, mesh, f, s, t, level=10):
    """(setup seconds, evaluation seconds, P, Ps, Pt) of OpenSubdiv Far on one thread."""
    import subprocess
    import tempfile

    with tempfile.TemporaryDirectory() as tmp:
        d = Path(tmp)
        _write_osd_input(d, mesh, f, s, t)
        r = subprocess.run([str(exe), str(d / "mesh.bin"), str(d / "points.bin"), str(d / "out.bin"), str(level)],
                           capture_output=True, text=True)
        if r.returncode != 0:
            raise RuntimeError(f"OpenSubdiv driver failed: {r.stderr}")
        words = r.stdout.split()
        out = np.fromfile(d / "out.bin", dtype=np.float64).reshape(-1, 9)
    return float(words[1]), float(words[3]), out[:, :3], out[:, 3:6], out[:, 6:9]


def irregular_corners(S):
    """(ptex face, corner) pairs whose corner is an irregular (self-similar corner) vertex."""
    P = S.n_faces
    out = []
    for i, (cu, cv) in enumerate(CORNERS):
        f = np.arange(P)
        _, _, kind = S._vface_of(f, np.full(P, float(cu)), np.full(P, float(cv)))
        out.extend((int(p), i) for p in f[kind == _CORNER])
    return out


def near_points(S, n, rng):
    """n points at distance 2^-(12 x) (x uniform) from irregular corners, in the face."""
    pairs = irregular_corners(S)
    pick = rng.integers(0, len(pairs), n)
    f = np.array([pairs[k][0] for k in pick], dtype=np.int64)
    c = np.array([CORNERS[pairs[k][1]] for k in pick], dtype=np.float64)
    r = 2.0 ** (-12 * rng.random(n))
    a, b = rng.random(n) * r, rng.random(n) * r
    s = np.where(c[:, 0] > 0, 1.0 - a, a)
    t = np.where(c[:, 1] > 0, 1.0 - b, b)
    return f, s, t, len(pairs)


def osd_side_by_side(n, rng, quick=False, setup_only=False):
    print("\n5. side by side with OpenSubdiv Far (positions + first derivatives)")
    exe = build_osd_driver()
    if exe is None:
        return None
    import os

    shapes = [("bunny_quads", REPO / "tests" / "data" / "meshes" / "bunny_quads.obj"),
              ("crease: catmark_cubes_infsharp", REPO / "tests" / "data" / "osd_features" / "meshes"
               / "catmark_cubes_infsharp.obj"),
              ("triangles: catmark_smoothtris1", REPO / "tests" / "data" / "osd_features" / "meshes"
               / "catmark_smoothtris1.obj")]
    threads = os.cpu_count() or 1
    if threads > 1 and _has_numba() and not setup_only:
        machine_ceiling(threads, quick)
    rows = []
    for label, path in shapes:
        mesh = read_mesh(path)
        w0 = time.perf_counter()
        S = limit_surface(mesh)
        setup = time.perf_counter() - w0
        P = S.n_faces
        if setup_only:
            w0 = time.perf_counter()
            limit_surface(mesh)
            again = time.perf_counter() - w0
            one = (np.zeros(1, dtype=np.int64), np.full(1, 0.5), np.full(1, 0.5))
            osd_setup = min(run_osd(exe, mesh, *one)[0] for _ in range(3))
            cold, warm = fresh_process_setups(path)
            rows.append((label, setup, again, osd_setup, cold, warm))
            print(f"   {label}: OpenSubdiv {osd_setup:.4f} s; ours, first build in a fresh process: disk cache "
                  f"empty {cold:.3f} s ({cold / osd_setup:.1f}x), disk cache filled {warm:.3f} s "
                  f"({warm / osd_setup:.1f}x); in this process {setup:.3f} s ({setup / osd_setup:.1f}x), "
                  f"again {again:.3f} s ({again / osd_setup:.1f}x)")
            continue
        uni = (rng.integers(0, P, n), rng.random(n), rng.random(n))
        fn, sn, tn, npairs = near_points(S, n, rng)
        for dist, (f, s, t) in (("uniform", uni), ("near irregular", (fn, sn, tn))):
            runs = [run_osd(exe, mesh, f, s, t) for _ in range(1 if quick else 3)]  # best of 3, as ours
            osd_setup = min(r[0] for r in runs)
            osd_eval = min(r[1] for r in runs)
            _, _, oP, oPs, oPt = runs[0]
            rate_osd = n / osd_eval
            res = {}
            configs = [("numpy", 1)] + ([("numba", 1), ("numba", threads)] if _has_numba() else [])
            outs = {c: {k: np.empty((n, 3)) for k in ("P", "Pu", "Pv")} for c in configs}
            for be, _ in configs:
                S.evaluate(f[:10], s[:10], t[:10], 1, backend=be)  # compile / warm up
            times = {c: [] for c in configs}
            # the configurations take turns, so that each sees the same machine; best of 5 (quick: 1)
            for _ in range(1 if quick else 5):
                for be, th in configs:
                    w0 = time.perf_counter()
                    S.evaluate(f, s, t, 1, out=outs[(be, th)], backend=be, threads=th)
                    times[(be, th)].append(time.perf_counter() - w0)
            for c in configs:
                res[c] = (n / min(times[c]), outs[c])
            out = res[("numpy", 1)][1]
            ok = np.isfinite(oP).all(axis=1)
            dP = np.abs(out["P"][ok] - oP[ok]).max() / mesh.bounding_box_diagonal
            dD = np.abs(out["Pu"][ok] - oPs[ok]).max() / mesh.bounding_box_diagonal
            rows.append((label, dist, setup, osd_setup, rate_osd, res, dP, dD))
            extra = f", {npairs} irregular corners" if dist != "uniform" else ""
            print(f"   {label}, {dist} ({n:,} points{extra}): setup ours {setup:.3f} s, "
                  f"OpenSubdiv {osd_setup:.3f} s ({setup / osd_setup:.1f}x)")
            print(f"      OpenSubdiv Far, 1 thread: {rate_osd / 1e6:6.2f} M points/s")
            for (be, th), (rate, _) in res.items():
                print(f"      ours {be:5s} {th} thread{'s' if th > 1 else ' '}: {rate / 1e6:6.2f} M points/s"
                      f"  = {rate / rate_osd:5.2f} x OpenSubdiv")
            if ("numba", threads) in res and threads > 1:
                gain = res[("numba", threads)][0] / res[("numba", 1)][0]
                med = float(np.median(times[("numba", 1)]) / np.median(times[("numba", threads)]))
                print(f"      {threads} threads / 1 thread: {gain:.2f}x best, {med:.2f}x median (target >= 1.8x "
                      f"with 2 threads; this machine's ceiling above)")
            print(f"      max |P ours - P OpenSubdiv| / diagonal {dP:.1e}, |Ps| {dD:.1e} (OpenSubdiv's end caps"
                  f" near irregular vertices are approximations)")
    return rows


def fresh_process_setups(path):
    """Setup seconds of the first build in a fresh process (imports excluded), with the per-configuration
    disk cache empty (a new folder: every exact layer table computed) and then filled by that run."""
    import os
    import subprocess
    import tempfile

    code = ("import sys, time; from ccproof.mesh.io import read_mesh; "
            "from ccproof.evaluate import natural_limit_surface as ls; m = read_mesh(sys.argv[1]); "
            "w0 = time.perf_counter(); ls(m); print(time.perf_counter() - w0)")
    with tempfile.TemporaryDirectory() as d:
        env = dict(os.environ, CCPROOF_CACHE=d)
        out = [float(subprocess.run([sys.executable, "-c", code, str(path)], env=env, check=True,
                                    capture_output=True, text=True).stdout) for _ in range(2)]
    return out[0], out[1]


def machine_ceiling(threads, quick=False):
    """What this machine gives ``threads`` threads on ideal work: a compiled loop of arithmetic in
    registers (no memory traffic, no shared data), split into equal parts; interleaved, best of 5
    and median, as for the evaluator. Clock boost with one busy core and neighbours on shared
    hardware lower it below ``threads``."""
    from concurrent.futures import ThreadPoolExecutor

    import numba

    @numba.njit(nogil=True)
    def work(m, x):
        acc = 0.0
        for i in range(m):
            acc += (x * i) % 1.7 + 1.0 / (1.0 + i)
        return acc

    m = 2_000_000 if quick else 30_000_000
    work(10, 1.0)
    t1, tn = [], []
    with ThreadPoolExecutor(threads) as ex:
        for _ in range(1 if quick else 5):
            w0 = time.perf_counter()
            work(m, 1.1)
            t1.append(time.perf_counter() - w0)
            w0 = time.perf_counter()
            list(ex.map(lambda x: work(m // threads, x), [1.1 + 0.01 * i for i in range(threads)]))
            tn.append(time.perf_counter() - w0)
    print(f"   this machine's ceiling: {threads} threads / 1 thread on ideal compiled work: "
          f"{min(t1) / min(tn):.2f}x best, {float(np.median(t1) / np.median(tn)):.2f}x median")


def _has_numba():
    try:
        import numba  # noqa: F401

        return True
    except ImportError:
        return False


def timed(fn, repeat=3):
    """Best wall and CPU seconds over ``repeat`` runs."""
    best_w, best_c = math.inf, math.inf
    for _ in range(repeat):
        w0, c0 = time.perf_counter(), time.process_time()
        fn()
        best_w = min(best_w, time.perf_counter() - w0)
        best_c = min(best_c, time.process_time() - c0)
    return best_w, best_c


# ------------------------------------------------------------------ (a) per-point implementation
def _basis(x):
    t = 1.0 - x
    B = (t * t * t / 6, (3 * x**3 - 6 * x * x + 4) / 6, (-3 * x**3 + 3 * x * x + 3 * x + 1) / 6, x**3 / 6)
    D = (-0.5 * t * t, 1.5 * x * x - 2 * x, -1.5 * x * x + x + 0.5, 0.5 * x * x)
    return B, D


def naive_point(S, f, u, v):
    """One point at a time, plain Python on the same tables: locate, net, basis, 16-term sums."""
    T = S._table
    job = int(T.top[f, int(u >= 0.5) + 2 * int(v >= 0.5)])
    vf = int(T.job_root[job])
    for _ in range(T.split_depth):
        if T.kind[vf] != _SPLIT:
            break
        half = T.h[vf] * 0.5
        vf = int(T.child[vf, int(u >= T.u0[vf] + half) + 2 * int(v >= T.v0[vf] + half)])
    if T.kind[vf] == _CORNER:
        U0, V0, H = T.u0[vf], T.v0[vf], T.h[vf]
        du = ((U0 + H) - u if T.cu[vf] else u - U0) / H
        dv = ((V0 + H) - v if T.cv[vf] else v - V0) / H
        mx = max(du, dv)
        cfg = int(T.cfg[vf])
        nmax = int(T.n_layers[cfg]) - 1
        n = min(max(-math.frexp(mx)[1], 0), nmax) if mx > 0 else nmax
        du, dv = math.ldexp(du, n), math.ldexp(dv, n)
        a, b = du >= 0.5, dv >= 0.5
        code = 0 if (a and not b) else 1 if (a and b) else 2 if b else 1
        Nc = int(T.op_size[cfg])
        o = int(T.op_start[cfg]) + (3 * n + code) * 16 * Nc
        q0 = int(T.job_pts[job] + T.pts[vf])
        ring = [[0.0] * 3] + T.ring[q0:q0 + Nc - 1].tolist()  # row 0 (the vertex) is not stored
        ops = T.ops[o:o + 16 * Nc].tolist()
        net = [[sum(ops[16 * k + i] * ring[k][c] for k in range(Nc)) for c in range(3)] for i in range(16)]
        origin = T.origin[int(T.job_corner[job] + T.leaf[vf])].tolist()
        sc = math.ldexp(H, -n)
        pu0 = T.unit[cfg, code, 0] * sc + (U0 + H if T.cu[vf] else U0)
        pv0 = T.unit[cfg, code, 1] * sc + (V0 + H if T.cv[vf] else V0)
        h = T.unit[cfg, code, 2] * sc
    else:
        p = int(T.job_net[job] + T.leaf[vf])
        net, origin = T.nets[p, :16].tolist(), T.nets[p, 16].tolist()
        pu0, pv0, h = T.u0[vf], T.v0[vf], T.h[vf]
    s = min(max((u - pu0) / h, 0.0), 1.0)
    t = min(max((v - pv0) / h, 0.0), 1.0)
    Bs, Ds = _basis(s)
    Bt, Dt = _basis(t)
    P, Pu, Pv = list(origin), [0.0] * 3, [0.0] * 3
    for j in range(4):
        for i in range(4):
            w = net[i + 4 * j]
            for c in range(3):
                P[c] += Bs[i] * Bt[j] * w[c]
                Pu[c] += Ds[i] * Bt[j] * w[c] / h
                Pv[c] += Bs[i] * Dt[j] * w[c] / h
    return P, Pu, Pv


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--points", type=int, default=1_000_000)
    ap.add_argument("--memory-points", type=int, default=10_000_000)
    ap.add_argument("--naive-points", type=int, default=2000)
    ap.add_argument("--pygel-levels", type=int, default=5)
    ap.add_argument("--quick", action="store_true", help="small sizes (smoke test)")
    ap.add_argument("--osd-points", type=int, default=1_000_000)
    ap.add_argument("--osd-only", action="store_true", help="only part 5 (OpenSubdiv side by side)")
    ap.add_argument("--setup-only", action="store_true", help="only the setup times of part 5")
    args = ap.parse_args(argv)
    if args.setup_only:
        osd_side_by_side(0, np.random.default_rng(2024), setup_only=True)
        return 0
    if args.osd_only:
        osd_side_by_side(args.osd_points if not args.quick else 20_000, np.random.default_rng(2024), args.quick)
        return 0
    if args.quick:
        args.points, args.memory_points, args.naive_points, args.pygel_levels = 20_000, 50_000, 200, 2

    path = REPO / "tests" / "data" / "meshes" / "bunny_quads.obj"
    mesh = read_obj(path)
    diag = mesh.bounding_box_diagonal
    print(f"mesh: {path.name}: {mesh.n_vertices} vertices, {mesh.n_faces} quads, "
          f"{mesh.extraordinary_vertices.size} extraordinary vertices (valences "
          f"{sorted(set(mesh.valence[mesh.extraordinary_vertices].tolist()))}), bbox diagonal {diag:.4g}")
    w0 = time.perf_counter()
    S = limit_surface(mesh)
    print(f"prepare (exact corner tables, local splits): {time.perf_counter() - w0:.2f} s; "
          f"{S.n_patches} stored patches, patch table {S.table_bytes / 2**20:.1f} MiB, deepest layer table "
          f"{S.max_layers}, split depth {S.split_depth}")

    rng = np.random.default_rng(2024)
    n = args.points
    f = rng.integers(0, mesh.n_faces, n)
    u, v = rng.random(n), rng.random(n)
    backends = ["numpy"]
    try:
        import numba  # noqa: F401

        backends.append("numba")
        S.evaluate(f[:10], u[:10], v[:10], 1, backend="numba")  # compile (cached on disk)
    except ImportError:
        print("numba not installed: compiled kernel skipped")
    rates = {}
    ref = None
    print(f"\n1. positions + first derivatives at {n:,} random points (best of 3)")
    for be in backends:
        out = {k: np.empty((n, 3)) for k in ("P", "Pu", "Pv")}
        w, c = timed(lambda be=be, out=out: S.evaluate(f, u, v, 1, out=out, backend=be))
        rates[be] = (n / w, n / c)
        print(f"   {be:6s}: {n / w / 1e6:6.2f} M points/s wall, {n / c / 1e6:6.2f} M points/s per CPU second")
        if ref is None:
            ref = {k: a.copy() for k, a in out.items()}
        else:
            dev = max(np.abs(out[k] - ref[k]).max() for k in out)
            print(f"           max |{be} - numpy| = {dev:.1e}")
    best = max(backends, key=lambda b: rates[b][1])

    # (a) per-point implementation
    m = args.naive_points
    c0 = time.process_time()
    res = [naive_point(S, int(f[i]), float(u[i]), float(v[i])) for i in range(m)]
    cn = time.process_time() - c0
    err = max(np.abs(np.array([r[0] for r in res]) - ref["P"][:m]).max(),
              np.abs(np.array([r[1] for r in res]) - ref["Pu"][:m]).max())
    print(f"\n2. (a) straightforward per-point loop on {m} points: {m / cn:,.0f} points per CPU second "
          f"(agrees to {err:.1e}); extrapolated to {n:,} points: {n / (m / cn):.1f} s CPU")
    for be in backends:
        print(f"       ratio {be} / per-point: {rates[be][1] / (m / cn):,.0f}x")

    # (b) uniform subdivision with pygel3d
    print("\n3. (b) uniform Catmull-Clark subdivision")
    try:
        from pygel3d import hmesh
    except ImportError:
        hmesh = None
        print("   pygel3d not installed (pip install pygel3d): library timings skipped")
    levels = []
    mm = mesh
    for L in range(1, args.pygel_levels + 1):
        mm = subdivide(mm)
        dev = mm.vertices - limit_positions(mm)
        drift = np.abs(dev).max() / diag  # distance to the own limit point (mostly tangential)
        acc = np.abs((dev * limit_normals(mm)).sum(axis=1)).max() / diag  # distance across the surface
        tg = None
        if hmesh is not None:
            g = hmesh.obj_load(str(path))
            c0 = time.process_time()
            for _ in range(L):
                hmesh.cc_subdivide(g)
            tg = time.process_time() - c0
            pos = g.positions()
            if L <= 3:  # same scheme: pygel3d's level-L points are ours
                from scipy.spatial import cKDTree

                d = cKDTree(mm.vertices).query(pos)[0].max() / diag
                if d > 1e-12:
                    print(f"   warning: pygel3d level {L} differs from the reference step by {d:.1e}")
        levels.append((L, mm.n_vertices, mm.n_faces, acc, tg))
        tg_s = f"{tg:7.3f} s" if tg is not None else "    n/a"
        ours = mm.n_vertices / rates[best][1]
        print(f"   level {L}: {mm.n_faces:>9,} quads, {mm.n_vertices:>9,} points, pygel3d {tg_s}; "
              f"control points {acc:.1e} x diagonal off the limit surface along the normal "
              f"({drift:.1e} from their limit points); exact evaluation of as many points: {ours:.3f} s")
    L, nv, nf, acc, tg = levels[-1]
    rate = math.log(levels[-2][3] / acc, 4) if len(levels) > 1 else 1.0
    target = 1e-13
    Lstar = L + math.log(acc / target, 4) / max(rate, 1e-9)
    print(f"   the normal distance shrinks by 4^{rate:.2f} at the last level; reaching {target:g} x diagonal "
          f"(exact evaluation is below it) needs level ~{Lstar:.1f}: ~{nf * 4 ** (Lstar - L):.2e} quads")
    if tg is not None:
        t_star = tg * 4 ** (Lstar - L)
        print(f"   extrapolated pygel3d time {t_star:.2e} s vs exact evaluation of 10^6 points "
              f"{1e6 / rates[best][1]:.3f} s: ratio {t_star / (1e6 / rates[best][1]):.1e}")
        ratio_same = tg / (nv / rates[best][1])
        print(f"   at level {L} ({nv:,} points, accuracy {acc:.0e}): pygel3d / exact evaluation time = "
              f"{ratio_same:.2f}")

    # 4. memory
    nm = args.memory_points
    print(f"\n4. peak memory beyond inputs and outputs for {nm:,} points (tracemalloc)")
    fm = rng.integers(0, mesh.n_faces, nm)
    um, vm = rng.random(nm), rng.random(nm)
    outm = {k: np.empty((nm, 3)) for k in ("P", "Pu", "Pv")}
    for be in backends:
        tracemalloc.start()
        S.evaluate(fm, um, vm, 1, out=outm, backend=be)
        _, peak = tracemalloc.get_traced_memory()
        tracemalloc.stop()
        io = sum(a.nbytes for a in (fm, um, vm)) + sum(a.nbytes for a in outm.values())
        print(f"   {be:6s}: {peak / 2**20:8.1f} MiB extra (inputs + outputs: {io / 2**20:.0f} MiB; "
              f"patch table {S.table_bytes / 2**20:.1f} MiB)")
    osd = osd_side_by_side(args.osd_points if not args.quick else 20_000, rng, args.quick)
    print("\nsummary:")
    for be in backends:
        print(f"   {be}: {rates[be][1] / 1e6:.2f} M points/s (P + first derivatives, single thread, CPU time)")
    if osd:
        print("   ours / OpenSubdiv Far (1 thread), points/s:")
        for label, dist, setup, osd_setup, rate_osd, res, _, _ in osd:
            parts = ", ".join(f"{be} {th}t {rate / rate_osd:.2f}x" for (be, th), (rate, _) in res.items())
            print(f"      {label:32s} {dist:15s} {parts}; setup {setup / osd_setup:.1f}x OpenSubdiv's")
    return 0


if __name__ == "__main__":
    sys.exit(main())
