"""The setup shortcuts (smooth regular quads in one vectorized pass, corner faces tried directly at
their one irregular corner, rings walked by the compiled kernel) give the surfaces of the face-by-face
classification.

The face-by-face path is the one checked against OpenSubdiv (test_osd_features.py) and brute-force
subdivision (test_tagged_bruteforce.py); here the shortcuts are switched off to compare.
"""

import numpy as np

from ccproof.evaluate import backend
from ccproof.evaluate.factory import Builder
from ccproof.evaluate.surface import LimitSurface
from ccproof.mesh.io import read_mesh


def _points(S, n=4000, seed=0):
    rng = np.random.default_rng(seed)
    faces = np.flatnonzero(~S._hole_ptex)
    return faces[rng.integers(0, faces.size, n)], rng.random(n), rng.random(n)


def _compare(mesh, monkeypatch):
    handled, at_corner = [], []
    shortcut, corner_at = Builder.smooth_regular_patches, Builder.corner_at

    def counting(self, cx, X, jobs):
        done = shortcut(self, cx, X, jobs)
        handled.append(int(done.sum()))
        return done

    def counting_corner(self, *args, **kwargs):
        hit = corner_at(self, *args, **kwargs)
        at_corner.append(hit)
        return hit

    with monkeypatch.context() as m:
        m.setattr(backend, "COMPILED_WALK_MIN", 0)
        compiled = LimitSurface(mesh)  # untagged rings walked by the compiled kernel (with numba)
    with monkeypatch.context() as m:
        m.setattr(backend, "compiled_ring_walk", lambda n: None)  # the Python walk, face by face
        m.setattr(Builder, "smooth_regular_patches", counting)
        m.setattr(Builder, "corner_at", counting_corner)
        fast = LimitSurface(mesh)
    assert sum(handled) > 0  # the shortcut is exercised
    with monkeypatch.context() as m:
        m.setattr(backend, "compiled_ring_walk", lambda n: None)
        m.setattr(Builder, "smooth_regular_patches", lambda self, cx, X, jobs: np.zeros(len(jobs), bool))
        m.setattr(Builder, "corner_at", lambda self, *args, **kwargs: False)
        slow = LimitSurface(mesh)
    assert fast.n_patches == slow.n_patches
    f, u, v = _points(fast)
    a, b = fast.evaluate(f, u, v, 2), slow.evaluate(f, u, v, 2)
    c = compiled.evaluate(f, u, v, 2)
    for k in a:  # the same rings, keys and templates: the same numbers
        assert np.array_equal(a[k], c[k]), k
    diag = mesh.bounding_box_diagonal
    for k in a:
        assert np.abs(a[k] - b[k]).max() <= 1e-14 * diag, k
    return fast, sum(at_corner)


def test_smooth_regular_shortcut_on_quads(bunny_path, monkeypatch):
    S, corner_faces = _compare(read_mesh(bunny_path), monkeypatch)
    assert S.n_patches > 1500 and corner_faces > 300  # regular patches stored; corner faces


def test_smooth_regular_shortcut_on_polygons_with_tags(refdir, monkeypatch):
    """n-gons (level-1 sub-faces and quad children in four orientations), holes, boundary modes."""
    corner_faces = 0
    for name in ("catmark_nonquads", "catmark_hole_test2", "catmark_edgecorner", "catmark_edgenone"):
        corner_faces += _compare(read_mesh(refdir / "osd_features" / "meshes" / f"{name}.obj"), monkeypatch)[1]
    assert corner_faces > 0


def test_setup_in_a_fresh_process_loads_no_heavy_module(bunny_path, refdir):
    """What `ccproof eval` does before evaluating (imports, read, build) loads neither scipy, numba, tqdm nor
    meshio on an OBJ (the lazy imports that keep its setup near the floor of a Python process)."""
    import json
    import os
    import subprocess
    import sys

    code = ("import sys, json; from ccproof.mesh.io import read_mesh; "
            "from ccproof.evaluate import natural_limit_surface as ls\n"
            "for p in sys.argv[1:]: ls(read_mesh(p), progress=False)\n"
            "print(json.dumps(sorted({m.split('.')[0] for m in sys.modules} & "
            "{'scipy', 'numba', 'llvmlite', 'tqdm', 'meshio', 'sympy', 'matplotlib'})))")
    root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    env = dict(os.environ, PYTHONPATH=root + os.pathsep + os.environ.get("PYTHONPATH", ""))
    paths = [str(bunny_path)] + [str(refdir / "osd_features" / "meshes" / f"catmark_{name}.obj")
                                 for name in ("cubes_infsharp", "smoothtris1", "chaikin1", "nonquads")]
    out = subprocess.run([sys.executable, "-c", code, *paths], env=env, check=True, capture_output=True,
                         text=True, timeout=600).stdout
    assert json.loads(out.strip().splitlines()[-1]) == []
