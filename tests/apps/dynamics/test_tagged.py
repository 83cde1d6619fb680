"""Tagged elements (creases, corners, boundaries, holes, non-manifold meshes): the model's surface is the one
``ccproof eval`` evaluates, its matrices are the special elements' where both apply, and its mass converges to
brute-force quadrature on the globally subdivided mesh."""

import numpy as np
import pytest
import scipy.sparse as sp

from ccproof.apps.control_file import read_control_mesh
from ccproof.apps.control_mesh import TaggedQuadMesh, subdivide_control, tagged_step, tags_of
from ccproof.apps.dynamics.meshes import paper_initial_model
from ccproof.apps.dynamics.model import DynamicSurface, Material
from ccproof.apps.dynamics.tagged import TaggedElement
from ccproof.evaluate import LimitSurface
from ccproof.mesh.io import read_mesh

ANISO = Material(mu=1.0, gamma=1.0, a11=1.0, a22=2.0, b11=3.0, b12=5.0, b22=7.0)


def _embed(n, ids, X):
    out = np.zeros((n, n))
    out[np.ix_(ids, ids)] += X
    return out


def test_tagged_element_is_the_special_element_without_tags():
    """On the untagged cube x2, the tagged elements of the three faces around a valence-3 vertex have the special
    element's matrices: the mass (Stein solution) to 1e-14 and the stiffness truncated at the same level, with
    anisotropic material (the sector rotations exchange a11/a22, b11/b22), to 1e-12 relative."""
    mesh = paper_initial_model()
    L = 4
    model = DynamicSurface(mesh, ANISO, levels=L)
    lay = model.layout
    ring, Ms, Ks = model.special_element_matrices()[0]
    n = mesh.n_vertices
    es, vs = np.zeros(mesh.n_edges), np.zeros(n)
    M = np.zeros((n, n))
    K = np.zeros((n, n))
    for f in lay.special_faces[0].tolist():
        el = TaggedElement(mesh, f, es, vs, levels=L)
        Me, Ke = el.matrices(lambda swap: ANISO.term_coefficients(swap=swap))
        M += _embed(n, el.ids, Me)
        K += _embed(n, el.ids, Ke)
    assert np.abs(M - _embed(n, ring, Ms)).max() <= 1e-14
    assert np.abs(K - _embed(n, ring, Ks)).max() <= 1e-12 * np.abs(Ks).max()


def _points(nf, rng, k=8):
    """k random points per face plus points near (and on) the corners, down to 2^-40."""
    f = np.repeat(np.arange(nf), k + 4)
    u = np.tile(np.r_[rng.random(k), 1e-6, 2.0**-40, 1.0 - 1e-9, 0.5], nf)
    v = np.tile(np.r_[rng.random(k), 3e-6, 0.0, 1.0, 2.0**-30], nf)
    return f, u, v


@pytest.mark.parametrize("path", ["osd_features/meshes/catmark_cube_creases0",
                                  pytest.param("osd_features/meshes/catmark_cubes_infsharp", marks=pytest.mark.slow),
                                  "osd_features/meshes/catmark_dart_edgeonly",
                                  "osd_features/meshes/catmark_hole_test2",
                                  "osd_nonmanifold/meshes/book4", "osd_nonmanifold/meshes/bowtie"])
def test_model_is_the_evaluators_surface(refdir, path):
    """Limit positions and first derivatives of the model (its evaluator and its rows J) at points of every face
    with a patch equal ``LimitSurface`` on the file's mesh (tags, holes, non-manifold edges and vertices) to
    1e-12 of the diagonal (derivatives: of the larger of the diagonal and the gradient); hole faces carry no
    patch."""
    file = refdir / f"{path}.obj"
    poly = read_mesh(file)
    mesh, origin = read_control_mesh(file)
    assert isinstance(mesh, TaggedQuadMesh) and origin is None  # all quads: control face f = ptex face f
    model = DynamicSurface(mesh, levels=3)
    kind = model.layout.face_kind
    assert (kind == 3).any()
    assert ((kind == 0) == mesh.hole).all()
    faces = np.flatnonzero(kind > 0)
    f, u, v = _points(faces.size, np.random.default_rng(7))
    f = faces[f]
    ref = LimitSurface(poly).evaluate(np.array([poly.ptex_of(x) for x in f]), u, v, 1)
    got = model.evaluate(f, u, v, 1)
    J = model.basis(f, u, v, 1)
    # derivatives: relative to the gradient where it exceeds the diagonal (at some corners of
    # catmark_cubes_infsharp it is unbounded: |Pu| = 2e4 at 2^-40 from one, where both evaluators round)
    grad = np.linalg.norm(ref["Pu"], axis=1) + np.linalg.norm(ref["Pv"], axis=1)
    diag = poly.bounding_box_diagonal
    corner = (u == 2.0**-40) & (v == 0.0)  # 2^-40 from a corner: the derivatives need depth 40
    for k in ("P", "Pu", "Pv"):
        tol = 1e-12 * (diag if k == "P" else np.maximum(diag, grad))
        assert (np.abs(got[k] - ref[k]).max(axis=1) <= tol).all(), k
        rows = J["D" + k[1:] if k != "P" else "P"]  # the basis rows' keys: Du, Dv
        assert (np.abs(rows @ mesh.vertices - ref[k]).max(axis=1) <= tol).all(), k
    assert corner.any()


def test_tagged_mass_converges_to_quadrature(refdir):
    """x^T M x of the tagged elements of catmark_dart_edgeonly (a dart, a crease, boundaries and corners) for a
    random scalar field x against the bilinear quadrature of the globally subdivided mesh (tagged steps, level
    k): the error falls by about 4 per level (O(h^2)) and is below 1e-3 relative at k = 5."""
    mesh, _ = read_control_mesh(refdir / "osd_features/meshes/catmark_dart_edgeonly.obj")
    model = DynamicSurface(mesh, levels=2)
    x = np.random.default_rng(3).random(mesh.n_vertices)
    exact = float(x @ (model.assemble(1.0, 0.0) @ x))
    Mb = np.array([[4, 2, 1, 2], [2, 4, 2, 1], [1, 2, 4, 2], [2, 1, 2, 4]]) / 36.0
    m, X, errs = mesh, x, []
    for k in range(1, 6):
        S, _, _ = tagged_step(m, *tags_of(m))
        X = S @ X
        m = subdivide_control(m)
        keep = ~np.repeat(mesh.hole, 4**k)
        Q = X[m.faces[keep]]
        errs.append(abs(4.0**-k * float(np.einsum("fi,ij,fj->", Q, Mb, Q)) - exact))
    ratios = [errs[i] / errs[i + 1] for i in range(len(errs) - 1)]
    assert all(3.8 < r < 4.3 for r in ratios[1:]), ratios
    assert errs[-1] < 1e-3 * exact


def test_refine_keeps_the_tagged_surface(refdir):
    """One tagged step and a rebuild (DynamicSurface.refine) leave the limit surface unchanged (child 4 f + i at
    corner i, half the parameter), and the child model is tagged too."""
    mesh, _ = read_control_mesh(refdir / "osd_features/meshes/catmark_dart_edgeonly.obj")
    model = DynamicSurface(mesh, levels=2)
    fine, A = model.refine()
    assert isinstance(fine.mesh, TaggedQuadMesh) and sp.issparse(A)
    rng = np.random.default_rng(5)
    s, t = rng.random(20), rng.random(20)
    f = rng.integers(0, mesh.n_faces, 20)
    P = model.evaluate(f, 0.5 * s, 0.5 * t)["P"]  # child 0 of face f: corner 0, same axes, half size
    Q = fine.evaluate(4 * f, s, t)["P"]
    assert np.abs(P - Q).max() <= 1e-12


@pytest.mark.parametrize("path,levels", [("osd_features/meshes/catmark_dart_edgeonly", 1),
                                         ("osd_nonmanifold/meshes/book4", 0)])
def test_cli_fit_on_a_tagged_start_mesh(refdir, tmp_path, capsys, path, levels):
    """``ccproof fit --init TAGGED.obj`` runs to completion (a dart, creases and boundaries refined once; a
    non-manifold book), reports finite errors and writes a control mesh that reads back with the same faces and
    tags, its limit surface and the per-point errors."""
    from ccproof.apps.dynamics.shapes import synthetic_range_data
    from ccproof.cli import main

    init = refdir / f"{path}.obj"
    start, _ = read_control_mesh(init)
    X = synthetic_range_data("ellipsoid", 200, seed=1) * 2.0
    pts = tmp_path / "pts.xyz"
    np.savetxt(pts, X)
    out, errs = tmp_path / "fit.obj", tmp_path / "errors.csv"
    rc = main(["fit", str(pts), "--init", str(init), "--levels", str(levels), "--max-steps", "3", "--out", str(out),
               "--errors", str(errs), "--no-progress"])
    cap = capsys.readouterr()
    assert rc == 0, cap.err
    back, _ = read_control_mesh(out)
    assert isinstance(back, TaggedQuadMesh) and back.n_faces == start.n_faces * 4**levels
    n_sharp = int((start.edge_sharpness > 0).sum()) * 2**levels
    assert int((back.edge_sharpness > 0).sum()) == n_sharp
    assert int((back.vertex_sharpness > 0).sum()) >= int((start.vertex_sharpness > 0).sum())
    E = np.loadtxt(errs, delimiter=",", skiprows=1)
    assert E.shape[0] == X.shape[0] and np.isfinite(E).all()
    assert read_mesh(tmp_path / "fit_limit.obj").n_vertices > 0
    assert "fit error" in cap.out


def test_truncation_report_of_tagged_elements(refdir):
    """Every tagged element has a record; its depth-L increment is the difference of the stiffness energies
    truncated at L and L - 1 (two models), and the truncated energies are >= 0."""
    mesh, _ = read_control_mesh(refdir / "osd_features/meshes/catmark_dart_edgeonly.obj")
    P = np.asarray(mesh.vertices)
    a = [r for r in DynamicSurface(mesh, levels=3).truncation_report(P) if "face" in r]
    b = [r for r in DynamicSurface(mesh, levels=4).truncation_report(P) if "face" in r]
    assert len(a) == len(b) == mesh.n_faces
    for ra, rb in zip(a, b):
        sa, sb = ra["stiffness"], rb["stiffness"]
        assert sa["truncated"] >= 0 and sb["truncated"] >= 0
        assert abs(sb["truncated"] - sa["truncated"] - sb["last_level"]) <= 1e-12 * max(sb["truncated"], 1e-300)


def test_model_on_a_tagged_mesh_with_triangles(refdir):
    """catmark_pyramid_creases1 (triangles, creases, corners) is subdivided once by read_control_mesh; the model's
    limit points equal ``LimitSurface`` on the file at the ptex coordinates of the quads (a quad's child k is the
    corner-k quarter of its ptex face, a triangle's child k is ptex face ``ptex_start + k``) to 1e-12."""
    file = refdir / "osd_features/meshes/catmark_pyramid_creases1.obj"
    poly = read_mesh(file)
    mesh, origin = read_control_mesh(file)
    assert isinstance(mesh, TaggedQuadMesh) and origin is not None and mesh.global_steps == 1
    model = DynamicSurface(mesh, levels=3)
    C = np.array([(0, 0), (1, 0), (1, 1), (0, 1)], dtype=float)
    rng = np.random.default_rng(2)
    f = np.repeat(np.arange(mesh.n_faces), 6)
    u, v = rng.random(f.size), rng.random(f.size)
    offsets, sizes = np.asarray(poly.offsets), np.asarray(poly.sizes)
    pt, pu, pv = [], [], []
    for c, a, b in zip(f.tolist(), u, v):
        g = int(origin[c])
        k = c - int(offsets[g])
        if sizes[g] == 4:
            w = C[k] + (C[(k + 1) % 4] - C[k]) / 2 * a + (C[(k + 3) % 4] - C[k]) / 2 * b
            pt.append(int(poly.ptex_start[g]))
        else:
            w = np.array([a, b])
            pt.append(int(poly.ptex_start[g]) + k)
        pu.append(w[0])
        pv.append(w[1])
    ref = LimitSurface(poly).evaluate(pt, pu, pv, 0)["P"]
    assert np.abs(model.evaluate(f, u, v)["P"] - ref).max() <= 1e-12 * poly.bounding_box_diagonal


@pytest.mark.parametrize("crease, regular", [
    ([[10, 11], [11, 12], [12, 13], [13, 14]], [True, True, True, True]),  # a straight crease through corners 2, 3
    ([[11, 12], [12, 17]], [True, True, False, False]),  # bent at corner 2 (12); corner 3 (11) the end of a dart
    ([[1, 6], [6, 11], [11, 16], [16, 21]], [True, True, True, True]),  # straight, along the face's side 3
    ([[1, 6], [6, 11], [11, 12], [12, 13], [13, 14]], [True, True, True, False]),  # bent at corner 3 (11)
    ([[6, 11], [11, 16]], [False, True, True, True]),  # corner 0 (6) the end of a crease (a dart)
])
def test_regular_corners_by_hand(crease, regular):
    """Face 5 = (6, 7, 12, 11) of a 4 x 4 grid (vertex x + 5 y) with an infinitely sharp crease: a corner on a
    straight crease is regular, on a bent one or at a dart's end not (the module docstring's rule, by hand)."""
    from ccproof.apps.dynamics.tagged import _Local, regular_corners
    from ccproof.mesh.examples import grid

    g = grid(4, 4)
    assert g.faces[5].tolist() == [6, 7, 12, 11]
    loc = _Local(g.faces, (np.array(crease), np.full(len(crease), np.inf)), ([], []))
    reg, side = regular_corners(loc, 5)
    sides = [{6, 7}, {7, 12}, {12, 11}, {11, 6}]
    assert reg.tolist() == regular
    assert side.tolist() == [any(set(e) == s for e in crease) for s in sides]
