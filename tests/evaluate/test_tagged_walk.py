"""The compiled ring walk on tagged meshes (creases, corners, holes, boundary modes, non-manifold,
semi-sharp) classifies every ptex face as the Python walk does: the same template keys (faces and
tags, :func:`ccproof.evaluate.local.ring_key`), each with the same jobs and the same rings.

The Python walk (:func:`ccproof.evaluate.local.canonical_ring` and ``ring_key`` face by face) is the
one checked against OpenSubdiv (test_osd_features.py) and brute-force subdivision
(test_tagged_bruteforce.py); here the compiled walk is switched off to compare.
"""

import math
from pathlib import Path

import numpy as np
import pytest

from ccproof.evaluate import backend, factory
from ccproof.evaluate._ckernel import load
from ccproof.evaluate.factory import Builder
from ccproof.evaluate.halfedge_views import TaggedHalfEdges
from ccproof.evaluate.tagged import build_tagged
from ccproof.mesh.examples import k_regular_disk
from ccproof.mesh.halfedges import HalfEdges
from ccproof.mesh.io import read_mesh, read_obj_tagged
from ccproof.mesh.polymesh import PolyMesh
from ccproof.mesh.rules import Options

MESHES = Path(__file__).resolve().parents[1] / "data" / "osd_features" / "meshes"
NAMES = sorted(p.stem for p in MESHES.glob("*.obj"))
NONMANIFOLD = Path(__file__).resolve().parents[1] / "data" / "osd_nonmanifold" / "meshes"


def _classification(b):
    """Per template key: {job: ring} (the job's ring as a tuple of complex vertices)."""
    out = {}
    for key, t in b.templates.items():
        jobs = list(t.jobs)
        rings = np.asarray(t.rings, dtype=np.int64).reshape(len(jobs), -1) if jobs else np.zeros((0, 0))
        out[key] = {j: tuple(r) for j, r in zip(jobs, rings.tolist())}
    return out


def _both(mesh, monkeypatch):
    walked = []
    walk_all, face = Builder._walk_all, Builder.face

    def counting(self, he, *args):
        walked.append(type(he).__name__)
        return walk_all(self, he, *args)

    def python_face(self, *args, **kwargs):
        walked.append("python")
        return face(self, *args, **kwargs)

    with monkeypatch.context() as m:
        m.setattr(backend, "COMPILED_WALK_MIN", 0)
        m.setattr(Builder, "_walk_all", counting)
        m.setattr(Builder, "face", python_face)
        compiled = build_tagged(mesh)
    with monkeypatch.context() as m:
        m.setattr(backend, "compiled_ring_walk", lambda n: None)  # the Python walk, face by face
        python = build_tagged(mesh)
    return compiled, python, walked


def _needs_walk():
    if backend.compiled_ring_walk(1 << 20) is None:
        pytest.skip("no compiled ring walk (neither the C kernel nor numba)")


@pytest.mark.parametrize("name", NAMES)
def test_compiled_walk_gives_the_python_keys_and_rings(name, monkeypatch):
    _needs_walk()
    mesh = read_obj_tagged(MESHES / f"{name}.obj")
    (bc, topc, holec, _), (bp, topp, holep, _), walked = _both(mesh, monkeypatch)
    assert np.array_equal(topc, topp) and np.array_equal(holec, holep)
    assert bc.n_jobs == bp.n_jobs
    assert _classification(bc) == _classification(bp)
    if mesh.has_tags or mesh.manifold is not mesh:
        assert "TaggedHalfEdges" in walked or all(k[0] == "smooth" for k in bc.templates)
    if mesh.options.crease_method != "chaikin":  # no ring left to the Python walk (no hash collision)
        assert "python" not in walked


@pytest.mark.parametrize("name", sorted(p.name for p in NONMANIFOLD.iterdir() if p.suffix in (".obj", ".off")))
def test_compiled_walk_on_nonmanifold_meshes(name, monkeypatch):
    """Non-manifold edges and vertices, unused vertices, duplicated and flipped faces: walked on the
    split (the same faces and ptex faces), the same classification both ways."""
    _needs_walk()
    mesh = read_mesh(NONMANIFOLD / name)
    (bc, topc, *_), (bp, topp, *_), walked = _both(mesh, monkeypatch)
    assert np.array_equal(topc, topp)
    assert _classification(bc) == _classification(bp)
    if mesh.options.crease_method != "chaikin":
        assert "python" not in walked


def test_tagged_meshes_take_the_compiled_walk(monkeypatch):
    """Creases with infinite sharpness (cubes_infsharp) and tagged triangles are walked compiled."""
    _needs_walk()
    for name in ("catmark_cubes_infsharp", "catmark_cube_corner4", "catmark_pyramid_creases1"):
        mesh = read_obj_tagged(MESHES / f"{name}.obj")
        assert mesh.has_tags, name
        *_, walked = _both(mesh, monkeypatch)
        assert "TaggedHalfEdges" in walked, name


def test_ring_tags_separate_the_keys():
    """Two rings with the same faces and different crease sharpness get different tag rows; the
    row lists the sharpness (inf from 10 on) of the edges at the rule vertices only."""
    if load() is None:
        pytest.skip("no C kernel")
    disk = k_regular_disk(5, 3)
    rows = []
    for s in (2.0, 12.0, 0.0):
        base = HalfEdges.from_quads(disk.faces, disk.n_vertices, Options())
        he = TaggedHalfEdges.of(base.with_tags({(0, 1): s} if s else {}))
        k, maxn, maxf = 1, 64, 48
        rings = np.full((k, maxn), -1, dtype=np.int32)
        fc = np.zeros((k, maxf, 4), dtype=np.int64)
        nring, nfaces, hashes = np.empty(k, np.int64), np.empty(k, np.int64), np.empty(k, np.uint64)
        pos = np.full(he.n_vertices, -1, dtype=np.int64)
        seen = np.zeros(he.faces.shape[0], dtype=np.bool_)
        walk = backend.compiled_ring_walk(k)
        walk((he.org, he.nxt, he.prv, he.twin), (pos, seen), np.zeros(1, np.int64), np.zeros(1, np.int64),
             (rings, nring, fc, nfaces, hashes))
        rows.append(he.ring_tags(rings, nring, fc, nfaces)[0])
    nz = [sorted(set(r[r != 0].tolist())) for r in rows]
    assert nz == [[2.0], [math.inf], []]


def test_row_hash_separates_permuted_tags():
    """Rows that differ only by where the same sharpness values sit hash apart."""
    rows = np.zeros((3, 8))
    rows[0, 1], rows[0, 5] = 2.0, math.inf
    rows[1, 5], rows[1, 1] = 2.0, math.inf
    rows[2, 1] = 1.0
    h = factory._row_hash(rows)
    assert len(set(h.tolist())) == 3


def test_semi_sharp_chaikin_rings_fall_back(monkeypatch):
    """A Chaikin mesh with semi-sharp creases: the two-ring rings go to the Python walk, the same
    classification comes out."""
    _needs_walk()
    mesh = read_obj_tagged(MESHES / "catmark_chaikin1.obj")
    assert mesh.options.crease_method == "chaikin"
    (bc, *_), (bp, *_), _ = _both(mesh, monkeypatch)
    assert _classification(bc) == _classification(bp)


def test_polymesh_with_vertex_tags(monkeypatch):
    """A quad disk with a corner vertex and a crease: same classification both ways."""
    _needs_walk()
    d = k_regular_disk(5, 3)
    mesh = PolyMesh(d.vertices, d.faces.tolist(), creases={(0, 1): 3.0}, corners={0: 10.0})
    (bc, *_), (bp, *_), walked = _both(mesh, monkeypatch)
    assert "TaggedHalfEdges" in walked
    assert _classification(bc) == _classification(bp)


@pytest.mark.parametrize("name", ["catmark_pyramid_creases1", "catmark_xord_boundary", "catmark_hole_test2"])
def test_compiled_walk_on_refined_tagged_meshes(name, monkeypatch):
    """Refined three times (the tags carried by the tagged step): hundreds of rings sharing keys, grouped."""
    _needs_walk()
    mesh = read_obj_tagged(MESHES / f"{name}.obj")
    for _ in range(3):
        mesh = mesh.refine(operator=False)[0]
    (bc, *_), (bp, *_), walked = _both(mesh, monkeypatch)
    assert bc.n_jobs > 200
    assert "TaggedHalfEdges" in walked and "python" not in walked
    assert _classification(bc) == _classification(bp)


@pytest.mark.parametrize("name", ["catmark_cubes_infsharp", "catmark_inf_crease1", "catmark_pyramid_creases1"])
def test_rings_of_colliding_hashes_go_to_the_python_walk(name, monkeypatch):
    """With every ring's tag hash made equal (a forced hash collision), the rings of one group whose tags are
    not those of its first ring are walked by Python: the classification is still the Python walk's."""
    _needs_walk()
    mesh = read_obj_tagged(MESHES / f"{name}.obj")
    monkeypatch.setattr(factory, "_row_hash", lambda a: np.zeros(a.shape[0], dtype=np.int64))
    (bc, *_), (bp, *_), walked = _both(mesh, monkeypatch)
    assert "python" in walked  # the collision was seen
    assert _classification(bc) == _classification(bp)
