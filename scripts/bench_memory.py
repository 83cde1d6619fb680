"""Memory of the patch table and of ``ccproof eval`` on scan-like triangle meshes, against OpenSubdiv Far.

The script writes the meshes itself: an icosphere refined L times (20 4^L triangles: L = 3..7 gives
1,280 / 5,120 / 20,480 / 81,920 / 327,680 triangles), every vertex moved radially by 1% Gaussian
noise (a closed "scan": every vertex of valence 6 except 12 of valence 5, and after the evaluator's
Catmull-Clark step every quad has two extraordinary corners). For each mesh, each in a fresh process:

* the table: ``natural_limit_surface(path)``; setup time (wall, imports excluded) and per 1k
  triangles, the table's bytes (``LimitSurface.table_bytes``: kernel arrays, rings, operators) per ptex
  face, of which per configuration (``configuration_bytes``), and the process's peak RSS;
* the command line: ``python -m ccproof.cli eval MESH --samples N --out ...`` (N = 10^6 by default),
  its peak RSS (``resource.getrusage`` of that process) and wall time;
* OpenSubdiv Far (if g++ and libosd-dev are installed): a small C++ driver, built here into a temp
  folder, reads the OBJ and builds a ``TopologyRefiner`` refined adaptively to level 10 and the
  ``PatchTable`` (Gregory end caps, as Far's defaults): the heap bytes they hold (glibc ``mallinfo2``
  before and after) per ptex face, and its peak RSS; meshes up to --osd-max-triangles only (Far's
  adaptive table at level 10 holds ~75 kB per ptex face of these meshes).

Usage::

    python scripts/bench_memory.py                 # levels 3..7 (the last one needs ~3 GB)
    python scripts/bench_memory.py --levels 3 4 5 --samples 100000
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _bench import load, missing, ratio_line  # noqa: E402

REPO = Path(__file__).resolve().parents[1]


def icosphere(level, noise=0.01, seed=0):
    """Vertices (n, 3) and triangles (m, 3) of an icosahedron refined ``level`` times (1-to-4 splits,
    projected to the unit sphere), each vertex scaled by ``1 + noise N(0, 1)``."""
    t = (1 + 5**0.5) / 2
    V = np.array([[-1, t, 0], [1, t, 0], [-1, -t, 0], [1, -t, 0], [0, -1, t], [0, 1, t], [0, -1, -t], [0, 1, -t],
                  [t, 0, -1], [t, 0, 1], [-t, 0, -1], [-t, 0, 1]], dtype=float)
    F = np.array([[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9], [5, 11, 4], [11, 10, 2],
                  [10, 7, 6], [7, 1, 8], [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8], [3, 8, 9], [4, 9, 5],
                  [2, 4, 11], [6, 2, 10], [8, 6, 7], [9, 8, 1]], dtype=np.int64)
    for _ in range(level):
        e = np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1)
        uniq, inv = np.unique(e, axis=0, return_inverse=True)
        mid = V.shape[0] + inv.reshape(3, -1).T  # midpoints of edges (a, b), (b, c), (c, a)
        V = np.vstack([V, 0.5 * (V[uniq[:, 0]] + V[uniq[:, 1]])])
        a, b, c = F.T
        ab, bc, ca = mid.T
        F = np.concatenate([np.stack(x, 1) for x in ((a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca))])
    V /= np.linalg.norm(V, axis=1)[:, None]
    V *= 1 + noise * np.random.default_rng(seed).standard_normal((V.shape[0], 1))
    return V, F


def write_obj(path, V, F):
    with open(path, "w") as fh:
        np.savetxt(fh, V, fmt="v %.17g %.17g %.17g")
        np.savetxt(fh, F + 1, fmt="f %d %d %d")


# the child processes (fresh interpreters: peak RSS of one job each)
_TABLE_JOB = r"""
import json, resource, sys, time
t0 = time.perf_counter()
from ccproof.evaluate.surface import natural_limit_surface
t1 = time.perf_counter()
S = natural_limit_surface(sys.argv[1], progress=False)
t2 = time.perf_counter()
print(json.dumps({"import_s": t1 - t0, "setup_s": t2 - t1, "n_ptex": int(S.n_faces),
                  "table_bytes": int(S.table_bytes), "configuration_bytes": int(S.configuration_bytes),
                  "peak_rss": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024}))
"""

_EVAL_JOB = r"""
import resource, runpy, sys
out = sys.argv[1]
sys.argv = ["ccproof"] + sys.argv[2:]
try:
    runpy.run_module("ccproof.cli", run_name="__main__")
except SystemExit as e:
    code = e.code
else:
    code = 0
with open(out, "w") as fh:
    fh.write(f"{resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024} {code or 0}")
"""

OSD_DRIVER = r"""
// OpenSubdiv Far memory driver for scripts/bench_memory.py (written by the script): reads an OBJ
// (v / f lines), builds a TopologyRefiner refined adaptively to level 10 and a PatchTable (Gregory end
// caps), prints the heap bytes they hold (mallinfo2 before/after), the ptex faces and the patches.
#include <opensubdiv/far/topologyDescriptor.h>
#include <opensubdiv/far/patchTableFactory.h>
#include <opensubdiv/far/ptexIndices.h>
#include <malloc.h>
#include <sys/resource.h>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

using namespace OpenSubdiv;

int main(int argc, char **argv) {
    FILE *f = fopen(argv[1], "r");
    if (!f) return 2;
    std::vector<double> verts;
    std::vector<int> nv, idx;
    char line[4096];
    while (fgets(line, sizeof line, f)) {
        if (line[0] == 'v' && line[1] == ' ') {
            double x, y, z;
            sscanf(line + 2, "%lf %lf %lf", &x, &y, &z);
            verts.push_back(x); verts.push_back(y); verts.push_back(z);
        } else if (line[0] == 'f' && line[1] == ' ') {
            int n = 0;
            char *p = line + 2, *e;
            for (;;) {
                long v = strtol(p, &e, 10);
                if (e == p) break;
                idx.push_back((int)v - 1); ++n;
                p = e;
                while (*p && *p != ' ' && *p != '\t' && *p != '\n') ++p;
            }
            nv.push_back(n);
        }
    }
    fclose(f);
    struct mallinfo2 m0 = mallinfo2();
    Far::TopologyDescriptor desc;
    desc.numVertices = (int)(verts.size() / 3);
    desc.numFaces = (int)nv.size();
    desc.numVertsPerFace = nv.data();
    desc.vertIndicesPerFace = idx.data();
    Sdc::Options sdc;
    sdc.SetVtxBoundaryInterpolation(Sdc::Options::VTX_BOUNDARY_EDGE_ONLY);
    typedef Far::TopologyRefinerFactory<Far::TopologyDescriptor> RF;
    Far::TopologyRefiner *r = RF::Create(desc, RF::Options(Sdc::SCHEME_CATMARK, sdc));
    Far::PatchTableFactory::Options po(10);
    po.SetEndCapType(Far::PatchTableFactory::Options::ENDCAP_GREGORY_BASIS);
    r->RefineAdaptive(po.GetRefineAdaptiveOptions());
    Far::PatchTable *pt = Far::PatchTableFactory::Create(*r, po);
    struct mallinfo2 m1 = mallinfo2();
    size_t bytes = (m1.uordblks + m1.hblkhd) - (m0.uordblks + m0.hblkhd);
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    printf("%zu %d %d %ld\n", bytes, Far::PtexIndices(*r).GetNumFaces(), pt->GetNumPatchesTotal(),
           ru.ru_maxrss * 1024L);
    delete pt;
    delete r;
    return 0;
}
"""


def build_osd_driver():
    """Compile the driver into a temp folder; None (with a message) without g++ or OpenSubdiv."""
    if not Path("/usr/include/opensubdiv/far/patchTable.h").exists() or shutil.which("g++") is None:
        print("OpenSubdiv headers or g++ not found (Debian: apt-get install libosd-dev g++): Far skipped.")
        return None
    d = Path(tempfile.gettempdir()) / "ccproof_bench_memory_osd"
    d.mkdir(exist_ok=True)
    src, exe = d / "driver.cpp", d / "driver"
    if not exe.exists() or not src.exists() or src.read_text() != OSD_DRIVER:
        src.write_text(OSD_DRIVER)
        r = subprocess.run(["g++", "-O2", "-std=c++14", str(src), "-o", str(exe), "-losdCPU"],
                           capture_output=True, text=True)
        if r.returncode != 0:
            print(f"compiling the OpenSubdiv driver failed:\n{r.stderr[-2000:]}\nFar skipped.")
            return None
    return exe


def _env():
    env = dict(os.environ)
    env["PYTHONPATH"] = str(REPO) + os.pathsep + env.get("PYTHONPATH", "")
    return env


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--levels", type=int, nargs="+", default=[3, 4, 5, 6, 7], help="icosphere levels (default 3..7)")
    ap.add_argument("--samples", type=int, default=1_000_000, help="points of `ccproof eval` (default 10^6)")
    ap.add_argument("--no-eval", action="store_true", help="skip the `ccproof eval` runs")
    ap.add_argument("--no-osd", action="store_true", help="skip OpenSubdiv")
    ap.add_argument("--osd-max-triangles", type=int, default=5120,
                    help="largest mesh given to OpenSubdiv (default 5120: at level 10 Far holds ~75 kB per ptex "
                    "face of these meshes, 1.2 GB at 5,120 triangles)")
    ap.add_argument("--smoke", action="store_true", help="level 1 and 1,000 samples (the test suite's run)")
    args = ap.parse_args(argv)
    if args.smoke:
        args.levels, args.samples = [1], 1000
    print(f"python {sys.version.split()[0]}, load {os.getloadavg()}, {os.cpu_count()} cores")
    exe = None if args.no_osd else build_osd_driver()
    if exe is None:
        missing("OpenSubdiv Far", "--no-osd, or libosd-dev / g++ not installed")
    rows, loads = [], []
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        for L in args.levels:
            V, F = icosphere(L)
            mesh = tmp / f"icosphere{L}.obj"
            write_obj(mesh, V, F)
            row = {"level": L, "triangles": F.shape[0]}
            loads.append(load())
            r = subprocess.run([sys.executable, "-c", _TABLE_JOB, str(mesh)], capture_output=True, text=True,
                               env=_env())
            if r.returncode != 0:
                print(r.stderr[-3000:])
                raise SystemExit(f"table job failed on level {L}")
            row.update(json.loads(r.stdout.strip().splitlines()[-1]))
            if not args.no_eval:
                rss = tmp / "rss.txt"
                t0 = time.perf_counter()
                r = subprocess.run([sys.executable, "-c", _EVAL_JOB, str(rss), "eval", str(mesh), "--samples",
                                    str(args.samples), "--out", str(tmp / "out.npz")], capture_output=True, text=True,
                                   env=_env())
                row["eval_s"] = time.perf_counter() - t0
                peak, code = rss.read_text().split()
                if int(code) != 0:
                    print(r.stdout[-2000:], r.stderr[-2000:])
                    raise SystemExit(f"ccproof eval failed on level {L}")
                row["eval_peak_rss"] = int(peak)
            if exe is not None and F.shape[0] <= args.osd_max_triangles:
                r = subprocess.run([str(exe), str(mesh)], capture_output=True, text=True)
                b, nptex, npatch, peak = (int(x) for x in r.stdout.split())
                row.update(osd_bytes=b, osd_ptex=nptex, osd_patches=npatch, osd_peak_rss=peak)
            rows.append(row)
            _print_row(row)
    print("\nsummary (bytes per ptex face: ours = the table less its per-configuration operators; Far = refiner "
          "+ patch table heap)")
    print(f"{'triangles':>10} {'ptex':>8} {'setup s':>8} {'s/1k tri':>8} {'B/ptex':>7} {'cfg MB':>7} "
          f"{'Far B/ptex':>10} {'ours/Far':>8} {'eval peak GB':>12} {'eval s':>7}")
    for row in rows:
        per = (row["table_bytes"] - row["configuration_bytes"]) / row["n_ptex"]
        osd = row.get("osd_bytes")
        osd_per = osd / row["osd_ptex"] if osd else float("nan")
        print(f"{row['triangles']:>10} {row['n_ptex']:>8} {row['setup_s']:>8.2f} "
              f"{1000 * row['setup_s'] / row['triangles']:>8.3f} {per:>7.0f} {row['configuration_bytes'] / 1e6:>7.1f} "
              f"{osd_per:>10.0f} {per / osd_per:>8.2f} {row.get('eval_peak_rss', float('nan')) / 1e9:>12.2f} "
              f"{row.get('eval_s', float('nan')):>7.1f}")
    ratios = [(r["table_bytes"] - r["configuration_bytes"]) / r["n_ptex"] / (r["osd_bytes"] / r["osd_ptex"])
              for r in rows if r.get("osd_bytes")]
    if ratios:
        print(ratio_line("bytes per ptex face ours/Far over the meshes:", ratios, loads + [load()]))
    print(f"load after: {os.getloadavg()}")
    return 0


def _print_row(row):
    print(f"level {row['level']}: {row['triangles']} triangles, {row['n_ptex']} ptex faces; "
          f"setup {row['setup_s']:.2f} s "
          f"(imports {row['import_s']:.2f} s); table {row['table_bytes'] / 1e6:.1f} MB "
          f"(of which {row['configuration_bytes'] / 1e6:.1f} MB held once per configuration); peak RSS of the build "
          f"{row['peak_rss'] / 1e9:.2f} GB"
          + (f"; ccproof eval: peak RSS {row['eval_peak_rss'] / 1e9:.2f} GB, {row['eval_s']:.1f} s"
             if "eval_peak_rss" in row else "")
          + (f"; Far: {row['osd_bytes'] / 1e6:.1f} MB ({row['osd_patches']} patches), peak RSS "
             f"{row['osd_peak_rss'] / 1e9:.2f} GB" if "osd_bytes" in row else ""), flush=True)


if __name__ == "__main__":
    sys.exit(main())
