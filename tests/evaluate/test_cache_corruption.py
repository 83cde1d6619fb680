"""A corrupted disk cache never changes a surface: every kind of cache file (corner scheme ``.f64``, its
exact matrix ``.A``, patch-table template ``.tpl``) is flipped, truncated, given a wrong digest or copied
under another entry's name, and the surface is compared bit for bit with a run without any cache (the
independent reference: ``CCPROOF_CACHE=off`` computes everything from the exact rules). The template is
also rebuilt from the damaged scheme files (templates deleted), which is how a wrong template used to
be written with a valid digest. The rebuild is reported once, as one line of ``ccproof eval``.
"""

import hashlib
import os
import subprocess
import sys
import warnings

import numpy as np
import pytest

from ccproof.evaluate import _diskcache, local
from ccproof.evaluate.surface import natural_limit_surface
from ccproof.mesh.polymesh import PolyMesh

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def _fan(shift=0.0):
    """A fan of 5 triangles: after the first step, corners of valence 5, 3 and boundary corners."""
    ring = [[np.cos(a), np.sin(a), 0.1 * np.cos(3 * a) + shift] for a in np.linspace(0, 2 * np.pi, 5, endpoint=False)]
    return [[0, 0, 0.3]] + ring, [[0, 1 + i, 1 + (i + 1) % 5] for i in range(5)]


def _mesh(shift=0.0):
    return PolyMesh(*_fan(shift))


def _points(S):
    rng = np.random.default_rng(7)
    f = rng.integers(0, S.n_faces, 400)
    u = np.concatenate([rng.random(200), 10.0 ** -rng.uniform(1, 12, 200)])  # deep layers too
    v = np.concatenate([rng.random(200), 10.0 ** -rng.uniform(1, 12, 200)])
    return f, u, v


def _evaluate(mesh):
    """P, Pu, Pv at fixed points (deep layers at the corners included), the corner schemes' exact ``A`` and
    tangent masks, and the CorruptCacheWarnings issued."""
    local.corner_scheme.cache_clear()
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        S = natural_limit_surface(mesh, progress=False)
        out = S.evaluate(*_points(S), 1)
        schemes = S._schemes
        extra = [(sch.A, sch.tangent_masks) for sch in schemes]
    arrays = [np.asarray(a) for a in (out.values() if isinstance(out, dict) else out)]
    corrupt = [x for x in w if type(x.message).__name__ == "CorruptCacheWarning"]
    return arrays, extra, corrupt


def _same(a, b):
    assert len(a) == len(b)
    for x, y in zip(a, b):
        assert x.dtype == y.dtype and np.array_equal(x, y, equal_nan=True), np.nanmax(np.abs(x - y))


def _flip40(p):
    b = bytearray(p.read_bytes())
    i = len(b) // 2
    b[i:i + 40] = bytes(x ^ 0x5A for x in b[i:i + 40])
    p.write_bytes(bytes(b))


def _truncate(p):
    p.write_bytes(p.read_bytes()[: p.stat().st_size // 2])


def _plain_digest(p):
    """The body followed by a digest of the body alone (not of the entry's name): a forger's seal."""
    body = p.read_bytes()[:-32]
    p.write_bytes(body + hashlib.sha256(body).digest())


def _grow(p):
    """One float64 of plausible data appended: the size check of a header-only format would miss a
    consistent header, the digest does not."""
    b = p.read_bytes()
    p.write_bytes(b[:-32] + np.float64(0.25).tobytes() + b[-32:])


@pytest.fixture(scope="module")
def cold():
    os.environ["CCPROOF_CACHE"] = "off"
    try:
        return _evaluate(_mesh(0.2))
    finally:
        del os.environ["CCPROOF_CACHE"]


@pytest.mark.parametrize("suffix", [".f64", ".A", ".tpl"])
@pytest.mark.parametrize("damage", [_flip40, _truncate, _plain_digest, _grow, "swap"])
def test_corrupt_cache_file_is_rebuilt_never_used(cold, tmp_path, monkeypatch, suffix, damage):
    monkeypatch.setenv("CCPROOF_CACHE", str(tmp_path))
    _evaluate(_mesh())  # another mesh of the same configurations fills the cache
    files = sorted(tmp_path.glob(f"*{suffix}"))
    assert len(files) >= 2, sorted(tmp_path.iterdir())
    for p in files:
        if damage == "swap":  # an intact file of another entry under this entry's name
            other = files[(files.index(p) + 1) % len(files)]
            p.write_bytes(other.read_bytes() if p != other else b"")
        else:
            damage(p)
    if suffix != ".tpl":  # templates rebuilt from the damaged scheme files
        for t in tmp_path.glob("*.tpl"):
            t.unlink()
    monkeypatch.setattr(_diskcache, "_reported", [])  # reported once per process: this test's
    arrays, extra, corrupt = _evaluate(_mesh(0.2))
    _same(cold[0], arrays)
    for (A0, T0), (A1, T1) in zip(cold[1], extra):
        assert A0 == A1 and np.array_equal(T0, T1)
    assert len(corrupt) == 1 and "corrupt" in str(corrupt[0].message)
    # the rebuilt files are read back without a word
    arrays2, _, corrupt2 = _evaluate(_mesh(0.2))
    _same(cold[0], arrays2)
    assert not corrupt2


def test_eval_reports_a_corrupt_cache_once_and_matches_a_cold_run(tmp_path):
    mesh = tmp_path / "fan.obj"
    V, F = _fan()
    mesh.write_text("".join(f"v {float(x)!r} {float(y)!r} {float(z)!r}\n" for x, y, z in V)
                    + "".join("f " + " ".join(str(i + 1) for i in f) + "\n" for f in F))
    env = dict(os.environ, PYTHONPATH=ROOT + os.pathsep + os.environ.get("PYTHONPATH", ""))

    def run(cache, out):
        r = subprocess.run([sys.executable, "-m", "ccproof.cli", "eval", str(mesh), "--samples", "2000", "--out",
                            str(out)], env=dict(env, CCPROOF_CACHE=str(cache)), capture_output=True, text=True,
                           timeout=120)
        assert r.returncode == 0, r.stderr
        with np.load(out) as z:
            return {k: z[k] for k in z.files}, r.stderr

    ref, _ = run("off", tmp_path / "cold.npz")
    run(tmp_path / "c", tmp_path / "fill.npz")
    for p in (tmp_path / "c").iterdir():
        _flip40(p)
    got, err = run(tmp_path / "c", tmp_path / "bad.npz")
    assert ref.keys() == got.keys() and all(np.array_equal(ref[k], got[k]) for k in ref)
    lines = [ln for ln in err.splitlines() if "corrupt" in ln]
    assert len(lines) == 1 and "cache file" in lines[0] and "Traceback" not in err, err


def test_temporary_files_of_a_killed_writer_are_removed(tmp_path, monkeypatch):
    monkeypatch.setenv("CCPROOF_CACHE", str(tmp_path))
    monkeypatch.setattr(_diskcache, "_swept", set())
    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()
    stale = [tmp_path / f".{'a' * 64}.{dead.pid}.tmp", tmp_path / f".{'b' * 64}.{dead.pid}.f64"]
    alive = tmp_path / f".{'c' * 64}.{os.getppid()}.tmp"  # a live writer's: kept
    mine = tmp_path / "notes.txt"  # not ours: kept
    for p in (*stale, alive, mine):
        p.write_bytes(b"half written")
        os.utime(p, (1e9, 1e9))
    _evaluate(_mesh())
    assert not any(p.exists() for p in stale) and alive.exists() and mine.exists()
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".") and p not in (alive,)]
