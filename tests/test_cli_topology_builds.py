"""Every command builds the topology of its mesh once: ``HalfEdges`` constructions counted per command.

A counter wraps :meth:`ccproof.mesh.halfedges.HalfEdges.__init__` and
:meth:`~ccproof.mesh.halfedges.HalfEdges.refined` (a refined mesh's topology derived from its parent's; views
made by ``with_tags`` or ``TaggedHalfEdges.of`` share the arrays and are not constructions) and records the
topology of every construction (vertex count, face corners, offsets). The file's topology (read from the OBJ
text here, not by ccproof) must be built exactly once per command, and so must the all-quad control mesh of ``arap`` and
``fit`` (the level-1 mesh of a triangle mesh: a new mesh, +1). ``eval`` and ``project`` build nothing else
(a triangle mesh: +1, the evaluator's level-1 step). Before sharing, a quad mesh's topology was built twice
by eval and project (a PolyMesh, then a QuadMesh of the same faces); the counts are in docs/evaluate.md.

``arap`` and ``fit`` build no topology twice either: ``arap`` checks each chart once (its verdict kept by
the chart's local faces), and a tagged element of ``fit`` builds the small mesh of a local topology once (the
same local faces and tags at another node, level or element reuse it). Before, ``arap`` built 3 to 5 chart
topologies twice and ``fit`` on the creased cube 1,754 of its 1,948 small meshes repeated one of 194. The
caches start empty in each test, so the counts do not depend on the tests run before.
"""

import collections
import os

import numpy as np
import pytest

from ccproof.mesh.halfedges import HalfEdges

TETRA = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 3 1 4\n"


def _key(n, org, offsets):
    return (int(n), np.asarray(org, dtype=np.int64).tobytes(), np.asarray(offsets, dtype=np.int64).tobytes())


def _obj_topology(path):
    """The key of an OBJ file's faces, parsed here (``v`` and ``f`` lines, 1-based, ``v/vt/vn`` allowed)."""
    n, faces = 0, []
    for line in open(path).read().splitlines():
        w = line.split()
        if w and w[0] == "v":
            n += 1
        elif w and w[0] == "f":
            faces.append([int(x.split("/")[0]) - 1 for x in w[1:]])
    return _key(n, np.concatenate(faces), np.r_[0, np.cumsum([len(f) for f in faces])])


@pytest.fixture
def builds(monkeypatch):
    """The list of topology keys of every HalfEdges construction while the test runs."""
    seen = []
    init = HalfEdges.__init__

    def counted(self, *args, **kwargs):
        init(self, *args, **kwargs)
        seen.append(_key(self.n_vertices, self.org, self.offsets))

    monkeypatch.setattr(HalfEdges, "__init__", counted)
    refined = HalfEdges.refined.__func__

    def counted_refined(cls, *args, **kwargs):  # a refined mesh's topology derived from its parent's: built too
        he = refined(cls, *args, **kwargs)
        seen.append(_key(he.n_vertices, he.org, he.offsets))
        return he

    monkeypatch.setattr(HalfEdges, "refined", classmethod(counted_refined))
    from ccproof.apps.arap import charts
    from ccproof.apps.dynamics import tagged

    monkeypatch.setattr(charts, "_DISKS", {}, raising=False)  # (raising=False: the code before the caches)
    monkeypatch.setattr(tagged, "_LOCALS", {}, raising=False)
    return seen


@pytest.fixture
def meshes(refdir, tmp_path):
    tri = tmp_path / "tetra.obj"
    tri.write_text(TETRA)
    return {"quad": refdir / "meshes" / "cube.obj",
            "tagged": refdir / "osd_features" / "meshes" / "catmark_cube_creases0.obj", "tri": tri}


def _run(argv, capsys):
    from ccproof.cli import main

    rc = main(argv)
    out = capsys.readouterr()
    assert rc == 0, out.err


@pytest.mark.parametrize("command", ["eval", "project"])
@pytest.mark.parametrize("kind", ["quad", "tagged", "tri"])
def test_eval_and_project_build_the_topology_once(builds, meshes, tmp_path, capsys, command, kind):
    mesh = str(meshes[kind])
    if command == "eval":
        argv = ["eval", mesh, "--samples", "20", "--out", str(tmp_path / "o.npz"), "--no-progress"]
    else:
        pts = tmp_path / "p.csv"
        pts.write_text("x,y,z\n0.1,0.2,1.5\n1.2,0,0\n")
        argv = ["project", mesh, str(pts), "--out", str(tmp_path / "p.npz"), "--no-progress"]
    _run(argv, capsys)
    count = collections.Counter(builds)
    assert count[_obj_topology(meshes[kind])] == 1
    assert max(count.values()) == 1  # no topology built twice
    assert len(builds) == (2 if kind == "tri" else 1)  # the triangle mesh: + the evaluator's level-1 step


@pytest.mark.parametrize("command", ["arap", "fit"])
@pytest.mark.parametrize("kind", ["quad", "tagged", "tri"])
def test_arap_and_fit_build_the_control_topology_once(builds, meshes, tmp_path, capsys, command, kind):
    from ccproof.apps.control_file import read_control_mesh

    control, _ = read_control_mesh(meshes[kind])  # (before the counting)
    control_key = _key(control.n_vertices, control.faces, 4 * np.arange(control.n_faces + 1))
    if kind != "tri":
        assert control_key == _obj_topology(meshes[kind])  # the file's faces are the control mesh's
    del builds[:]
    mesh = str(meshes[kind])
    if command == "arap":
        argv = ["arap", mesh, "--segment", "normals", "--levels", "1", "--eval-level", "2", "--refine", "0",
                "--out", str(tmp_path / "uv.obj"), "--allow-folds", "--no-progress"]  # (these fold at refine 0)
    else:
        from ccproof.apps.dynamics.shapes import synthetic_range_data

        xyz = tmp_path / "s.xyz"
        np.savetxt(xyz, synthetic_range_data("bulb", 200, seed=1))
        argv = ["fit", str(xyz), "--init", mesh, "--levels", "0", "--max-steps", "2",
                "--out", str(tmp_path / "f.obj"), "--no-progress"]
    _run(argv, capsys)
    count = collections.Counter(builds)
    assert count[_obj_topology(meshes[kind])] == 1, os.fspath(mesh)
    assert count[control_key] == 1  # the tetrahedron: its level-1 mesh, built once (a new mesh)
    assert max(count.values()) == 1, count.most_common(1)[0][1]  # no topology built twice (charts, elements)
