"""The vectorized step (ccproof.mesh.step) against the exact stencils of ccproof.mesh.rules.refine_complex.

refine_complex states every Sdc rule as exact rationals, one vertex and one edge at a time (Python loops,
python-flint); catmark_operator assembles them over the whole mesh with numpy in floats. On every mesh of
tests/data/osd_features and tests/data/osd_nonmanifold (creases, corners, semi-sharp and Chaikin tags,
boundary modes, triangle rules, holes, n-gons, non-manifold splits), at levels 0, 1 and 2 (each level the
exact PolyMesh.refine of the one before): the same child faces, the same child tags, and every row equal, bit for bit,
to the correctly rounded exact stencil.
"""

import math

import numpy as np
import pytest

from ccproof.mesh.io import read_mesh
from ccproof.mesh.rules import refine_complex, to_float
from ccproof.mesh.step import catmark_operator

FEATURES = ["catmark_chaikin1.obj", "catmark_cube_corner2.obj", "catmark_cube_corner4.obj",
            "catmark_cube_creases0.obj", "catmark_cubes_infsharp.obj", "catmark_dart_edgeonly.obj",
            "catmark_edgecorner.obj", "catmark_edgenone.obj", "catmark_helmet.obj", "catmark_hole_test2.obj",
            "catmark_inf_crease1.obj", "catmark_nonquads.obj", "catmark_pyramid_creases1.obj",
            "catmark_smoothtris1.obj", "catmark_xord_boundary.obj"]
NONMANIFOLD = ["book4.obj", "two_cubes.obj", "bowtie.obj", "dupface.obj", "flipped.obj", "unused.obj", "prism.off",
               "book4_tags.obj", "book4_infpage.obj", "book4_semipage.obj", "bowtie_none.obj",
               "two_cubes_creases.obj", "two_cubes_chaikin.obj", "collapsed.obj"]
CASES = [("osd_features", m) for m in FEATURES] + [("osd_nonmanifold", m) for m in NONMANIFOLD]


def _operator(pm):
    return catmark_operator(pm.n_vertices, pm.indices, pm.sizes, edge_sharpness=dict(pm.edge_sharpness),
                            vertex_sharpness=dict(pm.vertex_sharpness), options=pm.options, level=pm.level,
                            holes=pm.is_hole)


def _check_level(pm):
    cx = pm.complex()
    stencils, children, ces, cvs = refine_complex(cx)
    st = _operator(pm)
    assert np.array_equal(st.faces, np.array(children, dtype=np.int64))
    S = st.S.tocsr()
    checked = 0
    for r, ref in enumerate(stencils):
        row = S.getrow(r)
        got = dict(zip(row.indices.tolist(), row.data.tolist()))
        if ref is None:  # an unused vertex: no stencil, no row
            assert not got, r
            continue
        want = {c: to_float(w) for c, w in ref.items() if w != 0}
        assert set(got) == set(want), (r, got, want)
        assert got == want, (r, got, want)  # bit for bit: the correctly rounded exact weights
        checked += 1
    got_ces = dict(zip(map(tuple, st.child_creases[0].tolist()), st.child_creases[1].tolist()))
    assert got_ces == ces
    got_cvs = dict(zip(st.child_corners[0].tolist(), st.child_corners[1].tolist()))
    assert got_cvs == {v: s for v, s in cvs.items() if cx.corners[v]}
    assert np.array_equal(st.child_holes, np.repeat(pm.is_hole, pm.sizes))
    return checked


@pytest.mark.parametrize("folder,name", CASES)
def test_rows_equal_the_exact_stencils(refdir, folder, name):
    pm = read_mesh(refdir / folder / "meshes" / name).manifold
    for _ in range(3):
        assert _check_level(pm) > 0
        if pm.n_faces > 2000:
            break
        pm, _ = pm.refine(operator=False)


def test_a_forged_weight_is_caught(refdir):
    """The comparison can fail: a stencil with one weight moved by 1 ulp is told apart."""
    pm = read_mesh(refdir / "osd_features" / "meshes" / "catmark_pyramid_creases1.obj").manifold
    S = _operator(pm).S.tocsr()
    stencils = refine_complex(pm.complex())[0]
    c, w = next(iter(stencils[0].items()))
    x = to_float(w)
    forged = x + math.ulp(x)
    assert S[0, c] == x != forged


@pytest.mark.slow
def test_bench_step_runs(capsys):
    """Smoke test of scripts/bench_step.py (one round, a small icosphere): it prints every ratio."""
    import importlib.util
    import sys
    from pathlib import Path

    path = Path(__file__).resolve().parents[2] / "scripts" / "bench_step.py"
    spec = importlib.util.spec_from_file_location("bench_step", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    argv = sys.argv
    sys.argv = ["bench_step.py", "--rounds", "1", "--tri-levels", "1"]
    try:
        mod.main()
    finally:
        sys.argv = argv
    out = capsys.readouterr().out
    assert out.count("new/old") == 8
