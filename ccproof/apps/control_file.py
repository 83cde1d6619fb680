"""The control mesh file of the applications: :func:`read_control_mesh` (any mesh ``ccproof eval`` reads, as an
all-quad mesh, :mod:`ccproof.apps.control_mesh`), the vertex copies of non-manifold input merged back
(:func:`merged_copies`, :func:`merge_labels`), chart labels carried to the quads
(:func:`children_labels`) and :func:`write_control_obj`.
"""

from __future__ import annotations

import math
import os

import numpy as np

from ccproof.apps.control_mesh import MAX_TAGGED_FACES, TaggedQuadMesh, copy_labels
from ccproof.errors import MeshError
from ccproof.mesh import QuadMesh

__all__ = ["read_control_mesh", "children_labels", "merged_copies", "merge_labels", "write_control_obj"]


def _sharpest_semi_sharp(poly):
    """``(words, s)`` of the largest semi-sharp tag (0 < s < 10) of a PolyMesh, or None."""
    bnd = set(map(tuple, poly.edges[poly.is_boundary_edge].tolist()))  # sharp anyway: the tag does nothing
    tags = [(s, f"edge ({a}, {b})") for (a, b), s in sorted(poly.edge_sharpness.items())
            if 0.0 < s < 10.0 and (a, b) not in bnd]
    tags += [(s, f"vertex {v}") for v, s in sorted(poly.vertex_sharpness.items()) if 0.0 < s < 10.0]
    if not tags:
        return None
    s, what = max(tags, key=lambda t: t[0])
    return f"{what} of sharpness {s:g}", s


def read_control_mesh(path: str | os.PathLike[str]) -> tuple[QuadMesh, np.ndarray | None]:
    """Read a polygon mesh and make it all quads (module docstring).

    Parameters
    ----------
    path : str or os.PathLike
        Any file :func:`ccproof.mesh.io.read_mesh` reads.

    Returns
    -------
    mesh : QuadMesh or TaggedQuadMesh
        The mesh itself when it is all quads, else the mesh subdivided once (the same limit surface; with
        ``CREASE_CHAIKIN`` semi-sharp tags ceil(s) times for the largest sharpness s); without unused
        vertices. A :class:`TaggedQuadMesh` when the file has OpenSubdiv tags or is not manifold.
    origin : ndarray of int64, shape (mesh.n_faces,), or None
        None when the file's faces are kept; else the face of the file every control face lies on
        (children in order: :func:`children_labels`).

    Raises
    ------
    MeshError
        What :func:`~ccproof.mesh.io.read_mesh` raises; semi-sharp ``CREASE_CHAIKIN`` tags that would need
        more than :data:`MAX_TAGGED_FACES` faces (names the sharpest one).

    Examples
    --------
    A square pyramid (one quad, four triangles) as ASCII PLY: 5 + 8 + 5 = 18 vertices and 4 + 4 * 3 = 16
    quads after one step:

    >>> import os, tempfile
    >>> tmp = tempfile.TemporaryDirectory()          # removed when the example ends
    >>> p = os.path.join(tmp.name, "pyramid.ply")
    >>> with open(p, "w") as fh:
    ...     _ = fh.write("ply\\nformat ascii 1.0\\nelement vertex 5\\nproperty float x\\nproperty float y\\n"
    ...                  "property float z\\nelement face 5\\nproperty list uchar int vertex_indices\\nend_header\\n"
    ...                  "0 0 0\\n1 0 0\\n1 1 0\\n0 1 0\\n0.5 0.5 1\\n"
    ...                  "4 0 3 2 1\\n3 0 1 4\\n3 1 2 4\\n3 2 3 4\\n3 3 0 4\\n")
    >>> mesh, origin = read_control_mesh(p)
    >>> mesh.n_vertices, mesh.n_faces, origin.tolist()
    (18, 16, [0, 0, 0, 0, 1, 1, 1, 2, 2, 2, 3, 3, 3, 4, 4, 4])

    An unused vertex (the sixth) is dropped:

    >>> with open(p, "w") as fh:
    ...     _ = fh.write("ply\\nformat ascii 1.0\\nelement vertex 6\\nproperty float x\\nproperty float y\\n"
    ...                  "property float z\\nelement face 1\\nproperty list uchar int vertex_indices\\nend_header\\n"
    ...                  "0 0 0\\n1 0 0\\n1 1 0\\n0 1 0\\n0.5 0.5 1\\n9 9 9\\n4 0 1 2 3\\n")
    >>> mesh, origin = read_control_mesh(p)
    >>> mesh.n_vertices, mesh.n_faces, origin
    (4, 1, None)

    A cube with a crease of sharpness 2 keeps it as a tag (``CREASE_UNIFORM``; with ``CREASE_CHAIKIN`` it
    would be subdivided twice, after which the crease is smooth):

    >>> p = os.path.join(tmp.name, "cube.obj")
    >>> cube = ("v -1 -1 1\\nv 1 -1 1\\nv -1 1 1\\nv 1 1 1\\nv -1 1 -1\\nv 1 1 -1\\nv -1 -1 -1\\nv 1 -1 -1\\n"
    ...         "f 1 2 4 3\\nf 3 4 6 5\\nf 5 6 8 7\\nf 7 8 2 1\\nf 2 8 6 4\\nf 7 1 3 5\\n")
    >>> with open(p, "w") as fh:
    ...     _ = fh.write(cube + "t crease 2/1/0 0 1 2.0\\n")
    >>> mesh, origin = read_control_mesh(p)
    >>> type(mesh).__name__, mesh.n_faces, float(mesh.edge_sharpness.max()), origin
    ('TaggedQuadMesh', 6, 2.0, None)
    >>> with open(p, "w") as fh:
    ...     _ = fh.write(cube + "t crease 2/1/0 0 1 2.0\\nt creasemethod 0/0/1 chaikin\\n")
    >>> mesh, origin = read_control_mesh(p)
    >>> mesh.n_faces, float(mesh.edge_sharpness.max()), origin[:17].tolist()[::4]
    (96, 0.0, [0, 0, 0, 0, 1])
    """
    from ccproof.mesh.io import read_mesh

    poly = read_mesh(path)
    if poly.has_tags or not poly.is_manifold:
        return _tagged_control_mesh(poly, os.fspath(path))
    sizes = np.asarray(poly.sizes, dtype=np.int64)
    poly = _drop_unused_vertices(poly, sizes)
    # the PolyMesh's half-edges are the QuadMesh's (QuadMesh.from_polymesh): each topology built once
    if poly.is_all_quads:
        return QuadMesh.from_polymesh(poly), None
    fine, _ = poly.refine(operator=False)
    return QuadMesh.from_polymesh(fine), np.repeat(np.arange(sizes.size, dtype=np.int64), sizes)


def _drop_unused_vertices(poly, sizes):
    """``poly`` without the vertices no face uses (a subdivision step cannot even place them), renumbered in
    order; ``poly`` itself when every vertex is used."""
    idx = np.asarray(poly.indices, dtype=np.int64)
    used = np.unique(idx)
    if used.size < poly.n_vertices:
        from ccproof.mesh.polymesh import PolyMesh

        new = np.full(poly.n_vertices, -1, dtype=np.int64)
        new[used] = np.arange(used.size)
        poly = PolyMesh(np.asarray(poly.vertices)[used], new[idx], sizes=sizes)
    return poly


def _tagged_control_mesh(poly, name):
    """:func:`read_control_mesh` of a tagged or non-manifold mesh."""
    pm = poly.manifold  # non-manifold edges and vertices: infinitely sharp (same faces, split vertices)
    chaikin = pm.options.crease_method == "chaikin"
    semi = _sharpest_semi_sharp(pm) if chaikin else None
    need = max(math.ceil(semi[1]) if semi else 0, 0 if pm.is_all_quads else 1)
    faces = pm.n_faces if need == 0 else int(np.asarray(pm.sizes).sum()) * 4 ** (need - 1)
    if faces > MAX_TAGGED_FACES:
        raise MeshError(f"{name}: {semi[0]} with CREASE_CHAIKIN decays in {need} Catmull-Clark steps, which make "
                        f"{faces:,} faces (the applications take at most {MAX_TAGGED_FACES:,}: Chaikin's rule at a "
                        "vertex needs all its edges, so its semi-sharp tags are resolved by global steps there); "
                        "`ccproof eval` evaluates it, or make the tag smaller or infinite (>= 10)")
    origin = np.arange(pm.n_faces, dtype=np.int64)
    steps = 0
    split = pm is not poly  # copies of the file's vertices (their labels: file_vertex below)
    if split:
        import scipy.sparse as sp

        vm = np.asarray(poly.manifold_vertex_map, dtype=np.int64)
        C = sp.csr_matrix((np.ones(vm.size), (np.arange(vm.size), vm)), shape=(vm.size, poly.n_vertices))
        kinds = None
    while not pm.is_all_quads or (chaikin and _sharpest_semi_sharp(pm) is not None):
        origin = np.repeat(origin, np.asarray(pm.sizes, dtype=np.int64))
        if split:
            kinds = (pm.n_vertices, pm.n_vertices + len(pm.edges))
        pm, S = pm.refine(operator=split)
        if split:
            C = (S @ C).tocsr()
        steps += 1
    corners = dict(pm.vertex_sharpness)
    if steps == 0 and pm.options.boundary == "edge_and_corner":  # its level-0 corners, made explicit
        corners.update(dict.fromkeys(np.flatnonzero(pm.is_boundary_vertex & (pm.face_count == 1)).tolist(),
                                     math.inf))
    idx = np.asarray(pm.indices, dtype=np.int64)
    used = np.unique(idx)
    new = np.full(pm.n_vertices, -1, dtype=np.int64)
    new[used] = np.arange(used.size)
    se = new[np.asarray(list(pm.edge_sharpness), dtype=np.int64).reshape(-1, 2)]
    es = np.asarray(list(pm.edge_sharpness.values()), dtype=np.float64)
    cv = new[np.asarray(list(corners), dtype=np.int64)]
    cs = np.asarray(list(corners.values()), dtype=np.float64)
    ok, okv = (se >= 0).all(axis=1), cv >= 0
    tags = {"creases": (se[ok], es[ok]), "corners": (cv[okv], cs[okv]), "holes": np.flatnonzero(pm.is_hole)}
    if used.size == pm.n_vertices:  # the same vertices and faces: pm's half-edges shared (built once)
        mesh = TaggedQuadMesh.from_polymesh(pm, **tags)
    else:
        mesh = TaggedQuadMesh(np.asarray(pm.vertices)[used], new[idx].reshape(-1, 4), **tags)
    mesh.global_steps = steps
    if split and steps == 0:  # the file's used vertices, in the file's order
        mesh.file_vertex = np.unique(vm[used], return_inverse=True)[1].astype(np.int64)
    elif split:
        mesh.file_vertex = copy_labels(C[used], kinds=kinds, rows=used)
    return mesh, (origin if steps else None)


def merged_copies(mesh, file_vertex):
    """A control mesh with its copies merged: one vertex per label (the file's numbering).

    Parameters
    ----------
    mesh : QuadMesh or TaggedQuadMesh
        n vertices, m faces; copies at the same position.
    file_vertex : array_like of int, shape (n,)
        Labels ``0 .. r-1`` (:attr:`TaggedQuadMesh.file_vertex`).

    Returns
    -------
    vertices : ndarray, shape (r, 3)
        The first copy's position for every label.
    faces : ndarray of int64, shape (m, 4)
    tag_lines : list of str
        OpenSubdiv's OBJ tag lines (:func:`ccproof.mesh.write.obj_tag_lines`) in the merged numbering: a sharp
        edge's largest sharpness over its copies, likewise for vertices; the holes.

    Examples
    --------
    Two quads sharing only vertex 0, split into copies 0 and 4:

    >>> from ccproof.mesh import QuadMesh
    >>> q = QuadMesh([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 0], [-1, 0, 0], [-1, -1, 0],
    ...               [0, -1, 0]], [[0, 1, 2, 3], [4, 5, 6, 7]])
    >>> V, F, t = merged_copies(q, [0, 1, 2, 3, 0, 4, 5, 6])
    >>> V.shape, F.tolist(), t
    ((7, 3), [[0, 1, 2, 3], [0, 4, 5, 6]], [])
    """
    lab = np.asarray(file_vertex, dtype=np.int64)
    _, first = np.unique(lab, return_index=True)
    V = np.asarray(mesh.vertices)[first]
    F = lab[np.asarray(mesh.faces)]
    es = getattr(mesh, "edge_sharpness", None)
    if not isinstance(es, np.ndarray):
        return V, F, []
    lines = []
    e = np.flatnonzero(es > 0)
    pairs = np.sort(lab[mesh.edges[e]], axis=1)
    best: dict = {}
    for (a, b), v in zip(pairs.tolist(), es[e].tolist()):
        best[(a, b)] = max(best.get((a, b), 0.0), v)
    lines += [f"t crease 2/1/0 {a} {b} {min(v, 10.0)!r}\n" for (a, b), v in sorted(best.items())]
    vbest: dict = {}
    vs = mesh.vertex_sharpness
    for v in np.flatnonzero(vs > 0).tolist():
        vbest[int(lab[v])] = max(vbest.get(int(lab[v]), 0.0), float(vs[v]))
    lines += [f"t corner 1/1/0 {v} {min(s, 10.0)!r}\n" for v, s in sorted(vbest.items())]
    holes = np.flatnonzero(mesh.hole).tolist()
    if holes:
        lines.append(f"t hole {len(holes)}/0/0 " + " ".join(map(str, holes)) + "\n")
    return V, F, lines


def merge_labels(mesh):
    """The ``file_vertex`` labels a writer merges a control mesh's copies by, or None (write it as it is).

    None also when a merged face would repeat a vertex (a file with degenerate faces, e.g. an edge collapsed to a
    point: its split mesh, read back, is not split the same way again); such a mesh is written split.

    Parameters
    ----------
    mesh : QuadMesh or TaggedQuadMesh

    Returns
    -------
    ndarray of int64, shape (n,), or None

    Examples
    --------
    Two quads sharing only vertex 0 (split into copies 0 and 4); a labelling that would merge two corners of
    one face is refused:

    >>> t = TaggedQuadMesh([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 0], [-1, 0, 0], [-1, -1, 0],
    ...                     [0, -1, 0]], [[0, 1, 2, 3], [4, 5, 6, 7]])
    >>> merge_labels(t) is None
    True
    >>> t.file_vertex = np.array([0, 1, 2, 3, 0, 4, 5, 6])
    >>> merge_labels(t).tolist()
    [0, 1, 2, 3, 0, 4, 5, 6]
    >>> t.file_vertex = np.array([0, 1, 2, 0, 3, 4, 5, 6])
    >>> merge_labels(t) is None
    True
    """
    lab = getattr(mesh, "file_vertex", None)
    if lab is None:
        return None
    F = np.sort(lab[np.asarray(mesh.faces)], axis=1)
    return None if (F[:, 1:] == F[:, :-1]).any() else lab


def write_control_obj(path, mesh, *, comment=None):
    """Write a control mesh as OBJ (:func:`ccproof.mesh.write_obj`), its copies merged
    (:func:`merged_copies`) when it has a ``file_vertex`` labelling (:func:`merge_labels`): a non-manifold
    file's fitted mesh gets the file's vertices and faces back.

    Parameters
    ----------
    path : str or os.PathLike
    mesh : QuadMesh or TaggedQuadMesh
    comment : str, optional

    Returns
    -------
    None
    """
    from ccproof.mesh import write_obj

    lab = merge_labels(mesh)
    if lab is None:
        write_obj(path, mesh, comment=comment)
        return
    V, F, lines = merged_copies(mesh, lab)
    write_obj(path, (V, F), comment=comment)
    with open(path, "a", encoding="utf-8") as fh:
        fh.writelines(lines)


def children_labels(labels, origin):
    """Per-face labels of the file's faces carried to the quads of :func:`read_control_mesh`.

    Parameters
    ----------
    labels : array_like of int, shape (n,)
    origin : array_like of int, shape (m,), or None
        The file's face of every control face (None: the same faces).

    Returns
    -------
    ndarray of int64

    Examples
    --------
    >>> children_labels([7, 8], [0, 0, 0, 1, 1, 1, 1]).tolist(), children_labels([7, 8], None).tolist()
    ([7, 7, 7, 8, 8, 8, 8], [7, 8])
    """
    labels = np.asarray(labels, dtype=np.int64)
    return labels if origin is None else labels[np.asarray(origin, dtype=np.int64)]
