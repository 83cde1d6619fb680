"""Charts of a quad mesh given as per-face labels (hsh10 section 3, docs/hsh10.md A1 and A11.1).

Segmenting a surface into charts is not part of hsh10: the input is one integer label per control
face, and every label defines one chart. Each chart must be a *topological disk*: connected,
manifold (no two fans of chart faces meeting at one vertex) and of Euler characteristic
``V - E + F = 1`` (no handles, exactly one boundary loop). :func:`charts_from_labels` checks this
and raises :class:`ChartError` naming the label and the reason otherwise.

Two simple, documented segmentations are provided for closed meshes and examples (they are not
part of the method): :func:`segment_by_normals` (dominant axis of the face normal, then split into
disks) and :func:`grow_patch` (breadth-first rings of faces around a seed face, holes filled).

>>> from ccproof.mesh.examples import grid
>>> m = grid(2, 1)
>>> [c.tolist() for c in charts_from_labels(m, [0, 1])]
[[0], [1]]
>>> charts_from_labels(m, [0])
Traceback (most recent call last):
...
ccproof.apps.arap.charts.ChartError: chart labels: got 1 labels for a mesh of 2 faces
"""

from __future__ import annotations

import os

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

from ccproof.errors import CCProofError, MeshError
from ccproof.mesh import QuadMesh
from ccproof.mesh.quadmesh import shared_halfedges

__all__ = [
    "ChartError",
    "read_labels",
    "write_labels",
    "charts_from_labels",
    "check_disk",
    "segment_by_normals",
    "grow_by_normal_angle",
    "split_into_disks",
    "merge_small",
    "grow_patch",
    "face_adjacency",
]


class ChartError(CCProofError):
    """A chart that is not a topological disk, or a malformed chart label file.

    Parameters
    ----------
    message : str
        Names the chart (or the file, line and token).

    Examples
    --------
    >>> from ccproof.mesh.examples import cube
    >>> charts_from_labels(cube(), [0, 0, 0, 0, 0, 0])
    Traceback (most recent call last):
    ...
    ccproof.apps.arap.charts.ChartError: chart 0 is not a topological disk: ...
    """


def read_labels(path, n_faces=None):
    """Read one integer label per face (whitespace separated, ``#`` comments allowed).

    The chart file of ``ccproof arap --charts`` (docs/hsh10.md).

    Parameters
    ----------
    path : str or os.PathLike
    n_faces : int, optional
        Expected number of labels.

    Returns
    -------
    ndarray, shape (n_faces,) int64

    Raises
    ------
    ChartError
        If a token is not an integer or (when ``n_faces`` is given) the count is wrong.

    Examples
    --------
    >>> import os, tempfile
    >>> tmp = tempfile.TemporaryDirectory()          # removed when the example ends
    >>> p = os.path.join(tmp.name, "labels.txt")
    >>> write_labels(p, [0, 1, 1])
    >>> read_labels(p).tolist()
    [0, 1, 1]
    >>> read_labels(p, n_faces=4)
    Traceback (most recent call last):
    ...
    ccproof.apps.arap.charts.ChartError: ...
    """
    from ccproof.mesh.inputs import read_input_text

    vals = []
    text = read_input_text(path, ChartError, "one integer label per face")  # at most --max-input bytes
    for no, line in enumerate(text.splitlines(), start=1):
        for tok in line.split("#", 1)[0].split():
            try:
                vals.append(int(tok))
            except ValueError:
                raise ChartError(f"{path}:{no}: chart label {tok!r} is not an integer") from None
    labels = np.array(vals, dtype=np.int64)
    if n_faces is not None and labels.size != n_faces:
        raise ChartError(f"{path}: {labels.size} chart labels for a mesh of {n_faces} faces (need one per face)")
    return labels


def write_labels(path, labels):
    """Write one label per line (readable by :func:`read_labels`).

    Parameters
    ----------
    path : str or os.PathLike
    labels : array_like of int, shape (n_faces,)

    Returns
    -------
    None

    Examples
    --------
    >>> import os, tempfile
    >>> tmp = tempfile.TemporaryDirectory()          # removed when the example ends
    >>> p = os.path.join(tmp.name, "labels.txt")
    >>> write_labels(p, [2, 0])
    >>> open(p).read().splitlines()[1:]
    ['2', '0']
    """
    with open(os.fspath(path), "w", encoding="utf-8") as fh:
        fh.write("# ccproof chart labels: one integer per face, in OBJ face order\n")
        fh.writelines(f"{int(x)}\n" for x in np.asarray(labels).ravel())


def face_adjacency(mesh: QuadMesh):
    """Sparse symmetric face-face adjacency through interior edges, shape (m, m).

    Parameters
    ----------
    mesh : QuadMesh

    Returns
    -------
    scipy.sparse matrix, shape (n_faces, n_faces)
        1 where two faces share an interior edge.

    Examples
    --------
    In a 3 x 3 grid the middle face has 4 edge neighbours and the 12 interior edges give 24 entries:

    >>> from ccproof.mesh.examples import grid
    >>> A = face_adjacency(grid(3, 3))
    >>> A.shape, A.nnz, A[4].nnz
    ((9, 9), 24, 4)
    """
    ef = mesh.edge_faces
    it = ef[:, 1] >= 0
    a, b = ef[it, 0], ef[it, 1]
    m = mesh.n_faces
    return sp.coo_matrix((np.ones(2 * a.size), (np.r_[a, b], np.r_[b, a])), shape=(m, m)).tocsr()


def check_disk(mesh: QuadMesh, faces, name="chart"):
    """Raise :class:`ChartError` unless the faces ``faces`` of ``mesh`` form a topological disk.

    Parameters
    ----------
    mesh : QuadMesh
    faces : array_like of int
        Face indices of the chart.
    name : str, optional
        Used in the message.

    Returns
    -------
    None

    Raises
    ------
    ChartError
        If the faces are empty, not edge-connected, or not a disk (Euler characteristic, boundary loops).

    Examples
    --------
    >>> from ccproof.mesh.examples import grid
    >>> m = grid(3, 3)
    >>> check_disk(m, [f for f in range(9) if f != 4], "ring")
    Traceback (most recent call last):
    ...
    ccproof.apps.arap.charts.ChartError: ring is not a topological disk: Euler characteristic V - E + F = 0 ...
    """
    faces = np.asarray(faces, dtype=np.int64)
    if faces.size == 0:
        raise ChartError(f"{name} is empty")
    F = mesh.faces[faces]
    used, local = np.unique(F, return_inverse=True)
    local = local.reshape(F.shape)
    key = (local.shape, local.astype(np.int64).tobytes())
    why = _DISKS.get(key)
    if why is None:
        if len(_DISKS) >= _DISKS_MAX:
            _DISKS.clear()
        why = _DISKS[key] = _not_a_disk(mesh, local, used.size)
    if why:
        raise ChartError(f"{name} is not a topological disk: {why}")


#: the verdicts of :func:`check_disk` by the chart's local faces (its topology): "" for a disk, else the reason
_DISKS: dict = {}
#: how many verdicts :data:`_DISKS` keeps before it is emptied
_DISKS_MAX = 4096


def _not_a_disk(mesh, local, n):
    """Why the quads ``local`` ((k, 4), labels 0..n-1) are not a topological disk, or "" when they are one."""
    try:
        # the whole mesh (a single chart): its topology shared, not built again
        sub = QuadMesh(np.zeros((n, 3)), local, _halfedges=shared_halfedges(mesh, local, n))
    except MeshError as exc:
        return f"{exc} (vertex numbers local to the chart)"
    ncomp, _ = connected_components(face_adjacency(sub), directed=False)
    if ncomp != 1:
        return f"it has {ncomp} connected components"
    chi = sub.n_vertices - sub.n_edges + sub.n_faces
    if chi != 1:
        nb = _boundary_loops(sub)
        return (f"Euler characteristic V - E + F = {chi} "
                f"({sub.n_vertices} - {sub.n_edges} + {sub.n_faces}), {nb} boundary loops")
    return ""


def _boundary_loops(mesh: QuadMesh):
    be = mesh.boundary_edges
    if be.size == 0:
        return 0
    n = mesh.n_vertices
    g = sp.coo_matrix((np.ones(len(be)), (be[:, 0], be[:, 1])), shape=(n, n))
    _, lab = connected_components(g, directed=False)
    return int(np.unique(lab[np.unique(be)]).size)


def charts_from_labels(mesh: QuadMesh, labels):
    """One array of face indices per distinct label (sorted labels), each checked to be a disk.

    Parameters
    ----------
    mesh : QuadMesh
    labels : array_like of int, shape (m,)
        Label of every face, in face order. Negative labels mean "in no chart" (such faces are
        still part of the surface; they are not parameterized).

    Returns
    -------
    list of ndarray of int

    Raises
    ------
    ChartError
        Naming the first label whose faces are not a topological disk.

    Examples
    --------
    >>> from ccproof.mesh.examples import grid
    >>> [c.tolist() for c in charts_from_labels(grid(3, 3), [0, 0, 0, 1, 1, 1, -1, -1, -1])]
    [[0, 1, 2], [3, 4, 5]]
    """
    labels = np.asarray(labels)
    if labels.ndim != 1 or labels.size != mesh.n_faces:
        raise ChartError(f"chart labels: got {labels.size} labels for a mesh of {mesh.n_faces} faces")
    if not np.issubdtype(labels.dtype, np.integer):
        li = labels.astype(np.int64)
        if not np.array_equal(li, labels):
            raise ChartError("chart labels must be integers")
        labels = li
    out = []
    for lab in np.unique(labels[labels >= 0]):
        fc = np.flatnonzero(labels == lab)
        check_disk(mesh, fc, f"chart {int(lab)}")
        out.append(fc)
    if not out:
        raise ChartError("chart labels: no face has a non-negative label")
    return out


# --------------------------------------------------------------------------- segmentations
def _face_normals(mesh):
    V, F = mesh.vertices, mesh.faces
    n = np.cross(V[F[:, 2]] - V[F[:, 0]], V[F[:, 3]] - V[F[:, 1]])
    return n / np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-300)


def _is_disk(mesh, faces):
    try:
        check_disk(mesh, faces)
    except ChartError:
        return False
    return True


def split_into_disks(mesh: QuadMesh, labels, min_faces=1):
    """Refine a labelling until every label is a topological disk.

    Each label is split into its connected components (through edges); a component that is not a
    disk is cut in two by the median plane orthogonal to its longest principal axis (face centroids),
    recursively. Labels are renumbered 0, 1, ... in order of their smallest face (docs/hsh10.md).

    Parameters
    ----------
    mesh : QuadMesh
    labels : array_like of int, shape (n_faces,)
    min_faces : int, optional

    Returns
    -------
    ndarray, shape (n_faces,) int64

    Examples
    --------
    The closed cube is cut into two disks; a planar grid is one already:

    >>> from ccproof.mesh.examples import cube, grid
    >>> lab = split_into_disks(cube(), [0] * 6)
    >>> sorted(set(lab.tolist())), split_into_disks(grid(3, 3), [0] * 9).tolist() == [0] * 9
    ([0, 1], True)
    """
    labels = np.asarray(labels, dtype=np.int64)
    adj = face_adjacency(mesh)
    cent = mesh.vertices[mesh.faces].mean(axis=1)
    todo = [np.flatnonzero(labels == lab) for lab in np.unique(labels[labels >= 0])]
    done = []
    while todo:
        fc = todo.pop()
        ncomp, lab = connected_components(adj[fc][:, fc], directed=False)
        if ncomp > 1:
            todo.extend(fc[lab == c] for c in range(ncomp))
            continue
        if fc.size <= min_faces or _is_disk(mesh, fc):
            done.append(fc)
            continue
        x = cent[fc] - cent[fc].mean(axis=0)
        axis = np.linalg.svd(x, full_matrices=False)[2][0]
        s = x @ axis
        cut = s <= np.median(s)
        if cut.all() or not cut.any():
            cut = np.arange(fc.size) < fc.size // 2
        todo.extend([fc[cut], fc[~cut]])
    done.sort(key=lambda a: int(a.min()))
    out = np.full(mesh.n_faces, -1, dtype=np.int64)  # negative labels (no chart, holes) stay -1
    for i, fc in enumerate(done):
        out[fc] = i
    return out


def merge_small(mesh: QuadMesh, labels, min_faces):
    """Merge every chart with fewer than ``min_faces`` faces into its best neighbour.

    The neighbour is the chart with which it shares the most edges, when the union is a disk
    (smallest charts first; repeated until no merge applies). Labels are renumbered as in
    :func:`split_into_disks` (docs/hsh10.md).

    Parameters
    ----------
    mesh : QuadMesh
    labels : array_like of int, shape (n_faces,)
    min_faces : int

    Returns
    -------
    ndarray, shape (n_faces,) int64

    Examples
    --------
    The six one-face charts of the cube merge into two disks (five faces cannot close up; the sixth
    stays):

    >>> from ccproof.mesh.examples import cube
    >>> sorted(set(merge_small(cube(), range(6), 2).tolist()))
    [0, 1]
    """
    labels = np.asarray(labels, dtype=np.int64).copy()
    ef = mesh.edge_faces
    it = ef[:, 1] >= 0
    a, b = ef[it, 0], ef[it, 1]
    changed = True
    while changed:
        changed = False
        sizes = np.bincount(labels[labels >= 0])
        for lab in np.argsort(sizes, kind="stable"):
            if sizes[lab] == 0 or sizes[lab] >= min_faces:
                continue
            la, lb = labels[a], labels[b]
            nb = np.r_[lb[la == lab], la[lb == lab]]
            nb = nb[(nb != lab) & (nb >= 0)]
            if nb.size == 0:
                continue
            cand, cnt = np.unique(nb, return_counts=True)
            for c in cand[np.argsort(-cnt, kind="stable")]:
                union = np.flatnonzero((labels == lab) | (labels == c))
                if _is_disk(mesh, union):
                    labels[labels == lab] = c
                    changed = True
                    break
            if changed:
                break
    uniq = sorted(np.unique(labels[labels >= 0]), key=lambda x: int(np.flatnonzero(labels == x).min()))
    out = np.full_like(labels, -1)
    for i, lab in enumerate(uniq):
        out[labels == lab] = i
    return out


def segment_by_normals(mesh: QuadMesh, smooth=3, min_faces=20, max_angle=None):
    """Six-direction segmentation: label = dominant signed axis of the face normal (+x, -x, ...); with
    ``max_angle`` (degrees) region growing instead (:func:`grow_by_normal_angle`).

    Then ``smooth`` rounds of majority vote (a face takes the label of more than half of its edge
    neighbours, if there is one),
    :func:`split_into_disks` and :func:`merge_small` (``min_faces``). Deterministic; documented in
    docs/hsh10.md.

    Parameters
    ----------
    mesh : QuadMesh
    smooth : int, optional
        Rounds of majority vote.
    min_faces : int, optional
        Charts smaller than this are merged (:func:`merge_small`).
    max_angle : float, optional
        Degrees in (0, 180]: a chart holds faces whose normals are within this angle of its first face's
        normal (larger: fewer, larger charts), then split into disks and small charts merged as above.

    Returns
    -------
    ndarray, shape (n_faces,) int64
        Chart labels 0, 1, ...

    Examples
    --------
    >>> from ccproof.mesh.examples import cube
    >>> segment_by_normals(cube(), min_faces=1).tolist()
    [0, 1, 2, 3, 4, 5]
    """
    if max_angle is not None:
        lab = grow_by_normal_angle(mesh, max_angle)
        return merge_small(mesh, split_into_disks(mesh, lab), min_faces)
    nrm = _face_normals(mesh)
    ax = np.argmax(np.abs(nrm), axis=1)
    sign = nrm[np.arange(mesh.n_faces), ax] < 0
    lab = 2 * ax + sign
    hole = getattr(mesh, "hole", None)  # a TaggedQuadMesh's hole faces: in no chart
    adj = face_adjacency(mesh)
    deg = np.asarray(adj.sum(axis=1)).ravel()
    for _ in range(int(smooth)):
        votes = np.stack([adj @ (lab == c) for c in range(6)], axis=1)
        best = np.argmax(votes, axis=1)
        lab = np.where(votes[np.arange(lab.size), best] > deg / 2, best, lab)
    if hole is not None and hole.any():
        lab = np.where(hole, -1, lab)
    return merge_small(mesh, split_into_disks(mesh, lab), min_faces)


def grow_by_normal_angle(mesh: QuadMesh, max_angle):
    """Charts grown through edges: faces in index order seed a chart, which takes every edge-connected face whose
    normal is within ``max_angle`` degrees of the seed's; hole faces (a TaggedQuadMesh's) get -1.

    Parameters
    ----------
    mesh : QuadMesh
    max_angle : float
        Degrees, in (0, 180].

    Returns
    -------
    ndarray, shape (n_faces,) int64

    Examples
    --------
    The cube's neighbouring faces are 90 degrees apart, its faces 0 and 1 opposite (180):

    >>> from ccproof.mesh.examples import cube
    >>> [grow_by_normal_angle(cube(), a).tolist() for a in (89, 90, 180)]
    [[0, 1, 2, 3, 4, 5], [0, 1, 0, 0, 0, 0], [0, 0, 0, 0, 0, 0]]
    """
    from collections import deque

    if not (0 < max_angle <= 180):  # NaN too
        raise CCProofError(f"the normal angle of a chart must be in (0, 180] degrees, got {max_angle}")
    nrm = _face_normals(mesh)
    cos = np.cos(np.radians(max_angle)) - 1e-12  # 90 degrees: cos 0 up to rounding
    adj = face_adjacency(mesh).tocsr()
    hole = getattr(mesh, "hole", None)
    lab = np.full(mesh.n_faces, -1, dtype=np.int64)
    free = np.ones(mesh.n_faces, dtype=bool) if hole is None else ~np.asarray(hole, dtype=bool)
    n = 0
    for seed in range(mesh.n_faces):
        if not free[seed]:
            continue
        free[seed], lab[seed], queue = False, n, deque([seed])
        while queue:
            f = queue.popleft()
            for g in adj.indices[adj.indptr[f]:adj.indptr[f + 1]]:
                if free[g] and nrm[g] @ nrm[seed] >= cos:
                    free[g], lab[g] = False, n
                    queue.append(g)
        n += 1
    return lab


def grow_patch(mesh: QuadMesh, seed_face, rings):
    """Faces within ``rings`` steps (through shared vertices) of ``seed_face``, holes filled.

    Parameters
    ----------
    mesh : QuadMesh
    seed_face : int
    rings : int

    Returns
    -------
    ndarray of int64
        The sorted face indices of a topological disk.

    Raises
    ------
    ChartError
        If the grown region is not a disk (e.g. when it wraps around a handle).

    Examples
    --------
    >>> from ccproof.mesh.examples import grid
    >>> grow_patch(grid(3, 3), 0, 1).tolist(), grow_patch(grid(3, 3), 4, 1).size
    ([0, 1, 3, 4], 9)
    """
    F = mesh.faces
    m, n = mesh.n_faces, mesh.n_vertices
    fv = sp.coo_matrix((np.ones(4 * m), (np.repeat(np.arange(m), 4), F.ravel())), shape=(m, n)).tocsr()
    sel = np.zeros(m, dtype=bool)
    sel[int(seed_face)] = True
    for _ in range(int(rings)):
        verts = np.asarray(fv[sel].sum(axis=0)).ravel() > 0
        sel |= np.asarray(fv @ verts).ravel() > 0
    # fill holes: keep the largest component of the complement, add the rest
    rest = np.flatnonzero(~sel)
    if rest.size:
        adj = face_adjacency(mesh)
        ncomp, lab = connected_components(adj[rest][:, rest], directed=False)
        if ncomp > 1:
            big = np.argmax(np.bincount(lab))
            sel[rest[lab != big]] = True
    faces = np.flatnonzero(sel)
    check_disk(mesh, faces, f"patch around face {int(seed_face)}")
    return faces
