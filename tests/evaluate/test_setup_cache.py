"""The templates of a patch table (virtual faces and leaf operators of one ring configuration) kept in
the disk cache: with the cache filled a setup does no exact local subdivision and imports no flint,
and gives the bits of a setup that built everything; a corrupt cache file is detected and rebuilt.

Exactness itself is checked by the OpenSubdiv and brute-force tests, which run on whatever the cache
holds (filled or not); here the cached and the rebuilt tables are compared bit for bit.
"""

import hashlib
import json
import os
import subprocess
import sys

import numpy as np
import pytest

from ccproof.evaluate import _diskcache, factory, local, template_cache
from ccproof.evaluate.surface import natural_limit_surface
from ccproof.mesh.io import read_mesh

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
NAMES = ("cubes_infsharp", "smoothtris1", "chaikin1", "edgecorner")  # all-quad first: see below

_CHILD = """
import sys, json
import numpy as np
from ccproof.evaluate import factory
from ccproof.evaluate.surface import natural_limit_surface
from ccproof.mesh.io import read_mesh
calls = []
refine = factory.refine_key
factory.refine_key = lambda *a: calls.append(1) or refine(*a)
out, paths = sys.argv[1], sys.argv[2:]
arrays, flint = {}, []
for k, p in enumerate(paths):
    S = natural_limit_surface(read_mesh(p), progress=False)
    for name, a in S._table._asdict().items():
        if isinstance(a, np.ndarray):
            arrays[f"{k}_{name}"] = a
    rng = np.random.default_rng(k)
    f = rng.integers(0, S.n_faces, 500)
    f = f[~S._hole_ptex[f]] if getattr(S, "_hole_ptex", None) is not None else f
    r = S.evaluate(f, rng.random(f.size), rng.random(f.size), 2)
    items = r.items() if isinstance(r, dict) else enumerate(r if isinstance(r, (tuple, list)) else [r])
    for i, a in items:
        arrays[f"{k}_eval{i}"] = np.asarray(a, dtype=np.float64)
    flint.append("flint" in sys.modules)
np.savez(out, **arrays)
print(json.dumps({"flint": flint, "refine_key": len(calls)}))
"""


def _run(cache, out, paths):
    env = dict(os.environ, CCPROOF_CACHE=str(cache),
               PYTHONPATH=ROOT + os.pathsep + os.environ.get("PYTHONPATH", ""))
    res = subprocess.run([sys.executable, "-c", _CHILD, str(out), *map(str, paths)], env=env, check=True,
                         capture_output=True, text=True, timeout=600)
    return json.loads(res.stdout.strip().splitlines()[-1])


def test_second_setup_in_a_fresh_process_does_no_exact_arithmetic(refdir, tmp_path):
    paths = [refdir / "osd_features" / "meshes" / f"catmark_{n}.obj" for n in NAMES]
    cache = tmp_path / "cache"
    first = _run(cache, tmp_path / "a.npz", paths)
    assert first["flint"][0] and first["refine_key"] > 0  # an empty cache: the exact steps ran
    assert list(cache.glob("*.tpl"))
    second = _run(cache, tmp_path / "b.npz", paths)
    # no exact local step; no flint on the all-quad mesh (the others take one exact global step of
    # the whole mesh first, PolyMesh.refine, which is not per configuration and not cached)
    assert second["refine_key"] == 0 and second["flint"][0] is False
    with np.load(tmp_path / "a.npz") as a, np.load(tmp_path / "b.npz") as b:
        assert sorted(a.files) == sorted(b.files) and any("eval" in k for k in a.files)
        for k in a.files:
            assert a[k].dtype == b[k].dtype and np.array_equal(a[k], b[k], equal_nan=True), k


def _tables(mesh):
    local.corner_scheme.cache_clear()
    calls = []
    refine = factory.refine_key

    def counting(*a):
        calls.append(1)
        return refine(*a)

    factory.refine_key = counting
    try:
        S = natural_limit_surface(mesh, progress=False)
    finally:
        factory.refine_key = refine
    return S._table, len(calls)


def _same(T, U):
    for x, y in zip(T, U):
        if isinstance(x, np.ndarray):
            assert x.dtype == y.dtype and np.array_equal(x, y, equal_nan=True)
        else:
            assert x == y


def test_corrupt_template_file_is_detected_and_rebuilt(refdir, tmp_path, monkeypatch):
    monkeypatch.setenv("CCPROOF_CACHE", str(tmp_path))
    mesh = read_mesh(refdir / "osd_features" / "meshes" / "catmark_cubes_infsharp.obj")
    T0, n0 = _tables(mesh)
    files = sorted(tmp_path.glob("*.tpl"))
    assert n0 > 0 and len(files) > 3
    T1, n1 = _tables(mesh)
    assert n1 == 0  # all read back
    _same(T0, T1)

    # 1. one byte of the operators changed: caught by the digest
    b = bytearray(files[0].read_bytes())
    b[len(b) // 2] ^= 0x10
    files[0].write_bytes(bytes(b))
    with pytest.raises(ValueError, match="digest"):
        template_cache.read_template(files[0], files[0].stem)
    # 1b. a file whose digest matches but whose header does not (one value appended): caught by the sizes
    body = files[3].read_bytes()[:-32]
    n_js = int(np.frombuffer(body, dtype="<f8", count=7)[6])
    body = body[:len(body) - n_js] + bytes(8) + body[len(body) - n_js:]
    name = files[3].stem
    files[3].write_bytes(body + hashlib.sha256(name.encode() + b"\0" + body).digest())
    with pytest.raises(ValueError, match="sizes"):
        template_cache.read_template(files[3], name)
    # 2. a truncated file; 3. garbage
    files[1].write_bytes(files[1].read_bytes()[:100])
    files[2].write_bytes(b"not a template")
    monkeypatch.setattr(_diskcache, "_reported", [])  # reported once per process: this test's
    with pytest.warns(UserWarning, match="corrupt"):
        T2, n2 = _tables(mesh)
    assert n2 > 0  # rebuilt with the exact steps
    _same(T0, T2)
    for f in files[:4]:  # rewritten, and now read back
        template_cache.read_template(f, f.stem)
    T3, n3 = _tables(mesh)
    assert n3 == 0
    _same(T0, T3)


def test_cache_off_builds_without_files(refdir, tmp_path, monkeypatch):
    monkeypatch.setenv("CCPROOF_CACHE", "off")
    monkeypatch.chdir(tmp_path)
    mesh = read_mesh(refdir / "osd_features" / "meshes" / "catmark_chaikin1.obj")
    T, n = _tables(mesh)
    assert n > 0 and not list(tmp_path.rglob("*"))
