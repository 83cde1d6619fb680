"""A surface built once and shared: pickled by value it evaluates to the same bits; shared on this machine,
another process maps its arrays read-only from the one shared file (no build, no copy) and gets the same bits;
the file is gone for new processes once the writer closed it."""

import os
import pickle
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from ccproof.errors import CCProofError
from ccproof.evaluate import limit_surface
from ccproof.mesh.examples import cube
from ccproof.mesh.polymesh import PolyMesh
from ccproof.scale.shipping import attach, rebuild, share, shared_memory_available

ROOT = Path(__file__).resolve().parents[2]


def _surfaces():
    c = cube()
    tagged = PolyMesh(c.vertices, c.faces.tolist(), corners={0: 10}, creases={(1, 2): 2.5})
    tri = PolyMesh([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 1]],
                   [[0, 2, 1], [0, 1, 3], [1, 2, 4], [0, 3, 2], [1, 4, 3], [2, 3, 4]])
    return {"cube": limit_surface(c), "tagged cube": limit_surface(tagged), "triangles": limit_surface(tri)}


def _points(S, n=3000, seed=3):
    rng = np.random.default_rng(seed)
    f, u, v = rng.integers(0, S.n_faces, n), rng.random(n), rng.random(n)
    k = min(n, 40)
    u[:k], v[:k] = 0.0, rng.choice([0.0, 1.0, 2.0**-40], k)  # at and near the corners
    return f, u, v


def _same_bits(a, b):
    return all(np.ascontiguousarray(a[k]).tobytes() == np.ascontiguousarray(b[k]).tobytes() for k in a)


@pytest.mark.parametrize("name", ["cube", "tagged cube", "triangles"])
def test_a_pickled_surface_evaluates_to_the_same_bits(name):
    S = _surfaces()[name]
    f, u, v = _points(S)
    ref = S.evaluate(f, u, v, derivatives=2)
    normals = S.vertex_normals()
    for T in (pickle.loads(pickle.dumps(S, protocol=5)), pickle.loads(pickle.dumps(S, protocol=2))):
        assert _same_bits(T.evaluate(f, u, v, derivatives=2), ref)
        assert np.array_equal(T.vertex_normals(), normals, equal_nan=True)
        assert np.array_equal(T.vertex_limits(), S.vertex_limits(), equal_nan=True)


def test_the_bmz04_parameterizations_pickle_with_the_surface():
    from ccproof.reparam.surface import limit_surface as reparam_surface

    S = reparam_surface(cube())
    f, u, v = _points(S, 2000)
    T = pickle.loads(pickle.dumps(S, protocol=5))
    for p in ("vanishing", "characteristic"):
        assert _same_bits(T.evaluate(f, u, v, 1, parameterization=p), S.evaluate(f, u, v, 1, parameterization=p))


def test_a_scheme_whose_exact_matrix_was_built_pickles_with_it():
    from ccproof.evaluate.local import corner_scheme, quad_ring
    from ccproof.mesh.examples import k_regular_disk

    sch = corner_scheme(quad_ring(k_regular_disk(5, 3).faces, 0, 0)[1])
    A = sch.A  # built (a flint matrix, which does not pickle itself)
    again = pickle.loads(pickle.dumps(sch))
    assert again.A == A and np.array_equal(again.tangent_masks, sch.tangent_masks)


_CHILD = r"""
import pickle, sys
import numpy as np
from ccproof.scale.shipping import rebuild
with open(sys.argv[1], "rb") as fh:
    shipped, f, u, v = pickle.load(fh)
try:
    S = rebuild(shipped)
except Exception as exc:
    print("ERROR", type(exc).__name__, exc)
    raise SystemExit(0)
r = S.evaluate(f, u, v, derivatives=2)
maps = open("/proc/self/maps").read()
np.savez(sys.argv[2], writeable=S._table.rings.flags.writeable, memfd="memfd:ccproof-shared" in maps, **r)
print("OK")
"""


def _in_child(tmp_path, shipped, pts):
    arg = tmp_path / "in.pkl"
    arg.write_bytes(pickle.dumps((shipped, *pts)))
    env = dict(os.environ, PYTHONPATH=str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    r = subprocess.run([sys.executable, "-c", _CHILD, str(arg), str(tmp_path / "out.npz")], capture_output=True,
                       text=True, env=env, timeout=120)
    assert r.returncode == 0, r.stderr[-2000:]
    return r.stdout.strip().splitlines()[-1]


@pytest.mark.skipif(not shared_memory_available(), reason="shared memory needs Linux (memfd_create, /proc)")
def test_another_process_maps_the_shared_surface_and_gets_the_same_bits(tmp_path, monkeypatch):
    from ccproof.scale import shipping

    monkeypatch.setattr(shipping, "SHARED_MIN", 1)  # every array of this small surface in the shared file
    S = _surfaces()["tagged cube"]
    pts = _points(S)
    ref = S.evaluate(*pts, derivatives=2)
    with share(S, "machine") as (shipped, local):
        assert len(shipped.payload) < 100_000  # a name and a small pickle, not the table
        assert not local._table.rings.flags.writeable  # this process reads the shared pages too
        assert _same_bits(local.evaluate(*pts, derivatives=2), ref)
        assert _in_child(tmp_path, shipped, pts) == "OK"
        with np.load(tmp_path / "out.npz") as z:
            assert bool(z["memfd"]) and not bool(z["writeable"])  # mapped read-only, not built
            assert _same_bits({k: z[k] for k in ref}, ref)
        ref_local = pickle.loads(shipped.payload)[1][0]
    # closed by the writer: a process started now cannot map it (its workers keep what they mapped)
    with pytest.raises(CCProofError, match=f"process {os.getpid()}"):
        attach(ref_local)


def test_a_surface_shared_here_is_refused_in_another_process(tmp_path):
    S = _surfaces()["cube"]
    with share(S, "here") as (shipped, local):
        assert local is S and rebuild(shipped) is S
        assert _in_child(tmp_path, shipped, _points(S, 10)).startswith(
            f"ERROR CCProofError an object shared only within process {os.getpid()}")


def test_share_by_value_and_a_bad_place():
    S = _surfaces()["cube"]
    with share(S, "anywhere") as (shipped, local):
        assert local is S
        T = pickle.loads(shipped.payload)
        assert _same_bits(T[0](*T[1]).evaluate(*_points(S), 1), S.evaluate(*_points(S), 1))
    with pytest.raises(CCProofError, match="where must be"), share(S, "there"):
        pass
