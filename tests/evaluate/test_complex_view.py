"""The setup reads rings and keys on the mesh's half-edges (``halfedge_views.ComplexView``) instead of a Python
complex of the whole mesh: on tagged level-1 meshes, every face, corner and depth gives the ring, faces,
rule count and ``ring_key`` that the whole mesh's :class:`ccproof.mesh.rules.Complex` (``PolyMesh.complex``,
the reference) gives."""

from pathlib import Path

import numpy as np
import pytest

from ccproof.evaluate.halfedge_views import ComplexView, TaggedHalfEdges
from ccproof.evaluate.local import canonical_ring, ring_key
from ccproof.mesh.io import read_mesh, read_obj_tagged

DATA = Path(__file__).resolve().parents[1] / "data"


@pytest.mark.parametrize("path", [
    DATA / "osd_features" / "meshes" / "catmark_cubes_infsharp.obj",
    DATA / "osd_features" / "meshes" / "catmark_chaikin1.obj",
    DATA / "osd_features" / "meshes" / "catmark_hole_test2.obj",
    DATA / "osd_features" / "meshes" / "catmark_edgecorner.obj",
    DATA / "osd_features" / "meshes" / "catmark_pyramid_creases1.obj",
    DATA / "osd_nonmanifold" / "meshes" / "book4_semipage.obj",
], ids=lambda p: p.stem)
def test_the_view_gives_the_whole_mesh_rings_and_keys(path):
    mesh = read_obj_tagged(path) if "osd_features" in str(path) else read_mesh(path)
    m1 = mesh.manifold.refine(operator=False)[0]
    assert m1.is_all_quads and m1.has_tags
    cx = m1.complex()  # the reference: the whole level-1 mesh
    view = ComplexView(TaggedHalfEdges.of(m1.halfedges))
    rng = np.random.default_rng(0)
    faces = range(m1.n_faces) if m1.n_faces <= 200 else rng.choice(m1.n_faces, 200, replace=False).tolist()
    tagged = 0
    for g in faces:
        for r in range(4):
            for depth in (1, 2):
                ring, fk, nr = canonical_ring(cx, g, r, depth)
                key = ring_key(cx, ring, fk, nr)
                assert canonical_ring(view, g, r, depth) == (ring, fk, nr), (g, r, depth)
                assert ring_key(view, ring, fk, nr) == key, (g, r, depth)
                tagged += bool(key[1] or key[2])
    assert tagged > 0  # rings with tags were compared
