"""OpenSubdiv (Far and Bfr) in this process, for the benchmarks: builds ``scripts/osd_capi.cpp`` against
the system's OpenSubdiv (Debian: ``apt-get install -y libosd-dev g++``) and loads it with ctypes.

>>> lib = load()                                             # doctest: +SKIP
>>> far = Evaluator(lib, "far", mesh, level=10)              # doctest: +SKIP
>>> P, Ps, Pt = far.evaluate(face, s, t)                     # doctest: +SKIP

``Evaluator.evaluate`` runs OpenSubdiv's loop over the points on the calling thread (one thread), writing
into preallocated arrays; the timing of a call is OpenSubdiv's work plus one ctypes call.
"""

from __future__ import annotations

import ctypes
import hashlib
import shutil
import subprocess
import tempfile
from pathlib import Path

import numpy as np

SOURCE = Path(__file__).with_name("osd_capi.cpp")
HEADER = Path("/usr/include/opensubdiv/bfr/surface.h")

_dp = ctypes.POINTER(ctypes.c_double)
_ip = ctypes.POINTER(ctypes.c_int)
_fp = ctypes.POINTER(ctypes.c_float)
_MESH_ARGS = [ctypes.c_int, _dp, ctypes.c_int, _ip, _ip, ctypes.c_int, _ip, _fp, ctypes.c_int, _ip, _fp,
              ctypes.c_int, _ip, ctypes.c_int, ctypes.c_int]
_EVAL_ARGS = [ctypes.c_void_p, ctypes.c_int64, ctypes.POINTER(ctypes.c_int32), _dp, _dp, _dp, _dp, _dp]


def why_unavailable():
    """None if the library can be built here, else what to install."""
    if not HEADER.exists() or shutil.which("g++") is None:
        return ("OpenSubdiv 3.5+ headers (with Bfr) or g++ not found: apt-get update && apt-get install -y "
                "libosd-dev g++")
    return None


def load():
    """The compiled C API (built once per source version into the temp folder), or RuntimeError."""
    why = why_unavailable()
    if why:
        raise RuntimeError(why)
    code = SOURCE.read_bytes()
    d = Path(tempfile.gettempdir()) / "ccproof_osd_capi"
    d.mkdir(exist_ok=True)
    so = d / f"libosdcapi-{hashlib.sha256(code).hexdigest()[:16]}.so"
    if not so.exists():
        tmp = so.with_suffix(".tmp.so")
        r = subprocess.run(["g++", "-O2", "-std=c++14", "-shared", "-fPIC", str(SOURCE), "-o", str(tmp),
                            "-losdCPU"], capture_output=True, text=True)
        if r.returncode != 0:
            raise RuntimeError(f"compiling {SOURCE.name} failed:\n{r.stderr[-2000:]}")
        tmp.replace(so)
    lib = ctypes.CDLL(str(so))
    lib.far_create.argtypes = _MESH_ARGS + [ctypes.c_int]
    lib.far_create.restype = ctypes.c_void_p
    lib.bfr_create.argtypes = _MESH_ARGS + [ctypes.c_int]
    lib.bfr_create.restype = ctypes.c_void_p
    for name in ("far_eval", "bfr_eval"):
        getattr(lib, name).argtypes = _EVAL_ARGS
        getattr(lib, name).restype = ctypes.c_int64
    lib.far_patch_types.argtypes = _EVAL_ARGS[:5] + [ctypes.POINTER(ctypes.c_int32)]
    lib.far_patch_types.restype = None
    for name in ("far_free", "bfr_free"):
        getattr(lib, name).argtypes = [ctypes.c_void_p]
        getattr(lib, name).restype = None
    return lib


DRIVER = Path(__file__).with_name("osd_setup_driver.cpp")


def setup_driver():
    """Path of the compiled ``scripts/osd_setup_driver.cpp`` (Far's setup as a program: a fresh process
    reading an OBJ file), built once per source version into the temp folder; RuntimeError without
    OpenSubdiv or g++."""
    why = why_unavailable()
    if why:
        raise RuntimeError(why)
    code = DRIVER.read_bytes()
    d = Path(tempfile.gettempdir()) / "ccproof_osd_capi"
    d.mkdir(exist_ok=True)
    exe = d / f"osd_setup_driver-{hashlib.sha256(code).hexdigest()[:16]}"
    if not exe.exists():
        tmp = exe.with_suffix(".tmp")
        r = subprocess.run(["g++", "-O2", "-std=c++14", str(DRIVER), "-o", str(tmp), "-losdCPU"],
                           capture_output=True, text=True)
        if r.returncode != 0:
            raise RuntimeError(f"compiling {DRIVER.name} failed:\n{r.stderr[-2000:]}")
        tmp.replace(exe)
    return exe


def _ptr(a, typ):
    return a.ctypes.data_as(ctypes.POINTER(typ))


def mesh_arrays(mesh, scheme="catmark"):
    """The C API's mesh arguments of a :class:`ccproof.mesh.PolyMesh` (kept alive by the caller); ``scheme``:
    "catmark" or "loop" (OpenSubdiv's Sdc::SCHEME_LOOP; triangles)."""
    if scheme not in ("catmark", "loop"):
        raise ValueError(f"scheme must be 'catmark' or 'loop', got {scheme!r}")
    flags = int(mesh.options.crease_method == "chaikin") | 2 * int(mesh.options.triangle_subdivision == "smooth") \
        | 4 * int(scheme == "loop")
    bmode = {"none": 0, "edge_only": 1, "edge_and_corner": 2}[mesh.options.boundary]
    cre = list(mesh.edge_sharpness.items())
    cor = list(mesh.vertex_sharpness.items())
    return dict(
        X=np.ascontiguousarray(mesh.vertices, dtype=np.float64),
        sizes=np.ascontiguousarray(mesh.sizes, dtype=np.int32),
        idx=np.ascontiguousarray(mesh.indices, dtype=np.int32),
        cre=np.array([e for e, _ in cre], dtype=np.int32).reshape(-1),
        cw=np.array([min(x, 10.0) for _, x in cre], dtype=np.float32),
        cor=np.array([v for v, _ in cor], dtype=np.int32),
        kw=np.array([min(x, 10.0) for _, x in cor], dtype=np.float32),
        holes=np.flatnonzero(mesh.is_hole_tagged).astype(np.int32),
        boundary=bmode, flags=flags, nv=mesh.n_vertices, nf=mesh.n_faces,
    )


class Evaluator:
    """OpenSubdiv ``kind`` ("far": adaptive PatchTable at ``level`` with Gregory end caps, PatchMap,
    EvaluateBasis; "bfr": Bfr::RefinerSurfaceFactory, one prepared Surface per face, approximation levels
    ``approx`` (0: Bfr's defaults, smooth 2 and sharp 6)) of one mesh."""

    def __init__(self, lib, kind, mesh, level=10, approx=0, scheme="catmark"):
        self.lib, self.kind = lib, kind
        a = self._arrays = mesh if isinstance(mesh, dict) else mesh_arrays(mesh, scheme)  # a dict: mesh_arrays'

        args = [a["nv"], _ptr(a["X"], ctypes.c_double), a["nf"], _ptr(a["sizes"], ctypes.c_int),
                _ptr(a["idx"], ctypes.c_int), a["cw"].size, _ptr(a["cre"], ctypes.c_int),
                _ptr(a["cw"], ctypes.c_float), a["cor"].size, _ptr(a["cor"], ctypes.c_int),
                _ptr(a["kw"], ctypes.c_float), a["holes"].size, _ptr(a["holes"], ctypes.c_int),
                a["boundary"], a["flags"]]
        if kind == "far":
            self.h = lib.far_create(*args, level)
        elif kind == "bfr":
            self.h = lib.bfr_create(*args, approx)
        else:
            raise ValueError(f"kind must be 'far' or 'bfr', got {kind!r}")
        if not self.h:
            raise RuntimeError(f"OpenSubdiv refused the mesh ({kind})")
        self._eval = lib.far_eval if kind == "far" else lib.bfr_eval

    def evaluate(self, f, s, t, out=None):
        """(P, Ps, Pt), each (n, 3), at ptex faces ``f`` and (s, t); points OpenSubdiv does not find
        (holes) are 0 and counted in ``self.missing``."""
        f = np.ascontiguousarray(f, dtype=np.int32)
        s = np.ascontiguousarray(s, dtype=np.float64)
        t = np.ascontiguousarray(t, dtype=np.float64)
        n = f.size
        if out is None:
            out = tuple(np.empty((n, 3)) for _ in range(3))
        self.missing = self._eval(self.h, n, _ptr(f, ctypes.c_int32), _ptr(s, ctypes.c_double),
                                  _ptr(t, ctypes.c_double), *(_ptr(o, ctypes.c_double) for o in out))
        return out

    def patch_types(self, f, s, t):
        """Far's ``PatchDescriptor::Type`` of the patch holding each point (int32 (n,), -1: none): 5 LOOP and
        6 REGULAR are exact, 9 GREGORY_BASIS and 10 GREGORY_TRIANGLE end caps ("far" only)."""
        if self.kind != "far":
            raise ValueError("patch types are Far's")
        f = np.ascontiguousarray(f, dtype=np.int32)
        s = np.ascontiguousarray(s, dtype=np.float64)
        t = np.ascontiguousarray(t, dtype=np.float64)
        out = np.empty(f.size, dtype=np.int32)
        self.lib.far_patch_types(self.h, f.size, _ptr(f, ctypes.c_int32), _ptr(s, ctypes.c_double),
                                 _ptr(t, ctypes.c_double), _ptr(out, ctypes.c_int32))
        return out

    def close(self):
        if self.h:
            (self.lib.far_free if self.kind == "far" else self.lib.bfr_free)(self.h)
            self.h = None

    def __del__(self):
        try:
            self.close()
        except Exception:  # noqa: BLE001 - interpreter shutdown
            pass
