"""The rows of the limit surface at many points (``DynamicSurface.basis``: the surface -> data springs of a fit hold
16 samples per face) are written in place: the same matrices as through scipy's triplet (COO) path, built within
about twice their own size (measured 1.7 times at 1,538 vertices; the triplet path took 3.4 times, and at 24,578
control vertices that was the fit's peak)."""

import tracemalloc

import numpy as np
import scipy.sparse as sp

from ccproof.apps.dynamics.meshes import paper_initial_model
from ccproof.apps.dynamics.model import DynamicSurface


def _samples(model, per_face, seed=0):
    faces = np.repeat(np.flatnonzero(model.layout.face_kind > 0), per_face)
    rng = np.random.default_rng(seed)
    u, v = rng.random(faces.size), rng.random(faces.size)
    u[::5], v[::7] = 0.0, 1.0  # patch edges too
    return faces, u, v


def _triplets(model, faces, u, v, derivatives):
    """The reference: every (row, column, value) of the element rows, summed by scipy."""
    out = {}
    for pts, ids, rows in model._rows(faces, u, v, derivatives):
        for k, W in rows.items():
            out.setdefault(k, []).append((np.repeat(pts, ids.shape[1]), np.asarray(ids).reshape(-1), W.reshape(-1)))
    return {k: sp.coo_matrix((np.concatenate([p[2] for p in parts]), (np.concatenate([p[0] for p in parts]),
                                                                      np.concatenate([p[1] for p in parts]))),
                             shape=(faces.size, model.n_vertices)).tocsr() for k, parts in out.items()}


def test_basis_equals_the_triplet_matrices_bit_for_bit():
    model = DynamicSurface(paper_initial_model())  # regular and special (extraordinary) elements
    faces, u, v = _samples(model, 9)
    for d in (0, 1, 2):
        ref = _triplets(model, faces, u, v, d)
        got = model.basis(faces, u, v, derivatives=d)
        assert len(got) == len(ref) == (1, 3, 6)[d]
        names = {"P": "P", "Pu": "Du", "Pv": "Dv", "Puu": "Duu", "Puv": "Duv", "Pvv": "Dvv"}
        for k, A in ref.items():
            B = got[names[k]]
            assert np.array_equal(A.indptr, B.indptr) and np.array_equal(A.indices, B.indices)
            assert np.array_equal(A.data, B.data), k


def test_basis_is_built_within_about_twice_its_size():
    model, _ = DynamicSurface(paper_initial_model()).refine()
    model, _ = model.refine()  # 1,538 vertices
    faces, u, v = _samples(model, 16)
    tracemalloc.start()
    try:
        out = model.basis(faces, u, v, derivatives=1)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    size = sum(M.data.nbytes + M.indices.nbytes + M.indptr.nbytes for M in out.values())
    assert peak < 3.0 * size, f"peak {peak / 1e6:.1f} MB for matrices of {size / 1e6:.1f} MB"
