"""Non-manifold meshes as OpenSubdiv takes them: the fans of every non-manifold vertex split apart into copies
(:func:`split_nonmanifold_vertices`), the non-manifold edges infinitely sharp, the sharpened vertices infinitely sharp
corners, an interior non-manifold crease following the crease rule. :attr:`ccproof.mesh.PolyMesh.manifold` is the
result; every rule then acts on the copies as OpenSubdiv's acts on the vertex.
"""

from __future__ import annotations

import math
import warnings

import numpy as np

from ccproof.errors import MeshError
from ccproof.mesh.rules import Options

__all__ = ["split_nonmanifold_vertices", "fans_off_the_crease"]


def split_nonmanifold_vertices(mesh):
    """The manifold mesh on which the limit surface is evaluated, and its vertex map.

    OpenSubdiv (``Far::TopologyRefinerFactory::prepareComponentTagsAndSharpness``) makes every
    non-manifold edge infinitely sharp and every non-manifold vertex an infinitely sharp corner,
    except on an interior non-manifold crease (two non-manifold edges, no boundary edge, more
    faces than edges), whose vertex follows the crease rule along the two non-manifold edges.
    Its patches (``Far::PatchBuilder``) see, at a non-manifold vertex, only the fan of faces
    between two singular edges. Both say that each fan of a non-manifold vertex may be a
    vertex of its own: the fans are split apart into copies (the first fan keeps the vertex
    index, the others get indices n, n+1, ...), the non-manifold edges become boundary edges,
    sharpened vertices get infinite vertex sharpness. Every rule then acts on the copies as
    OpenSubdiv's acts on the vertex. A crease vertex with other semi-sharp edges is a corner
    until the last of them has decayed: its copies get that edge's sharpness as vertex sharpness
    (same rule at every level, same fractional weight). A crease vertex's fan not bounded by both
    non-manifold edges (a fin, a closed fan) cannot see both crease neighbours: its copy is made
    an infinitely sharp corner (:func:`fans_off_the_crease`; the one surface here that is not
    OpenSubdiv's, documented in docs/evaluate.md). Cases where no split comes close are refused
    by name: a crease vertex whose last semi-sharp features have different values, and Chaikin
    creases with semi-sharp edges in more than one fan of a non-manifold vertex or at a crease
    vertex.

    Returns
    -------
    PolyMesh
        Same faces, in order (same ptex faces), vertices ``vertices[vmap]``, all-infinite tags
        on the split edges, the tags of the mesh and boundary mode ``edge_only`` (the mesh's
        mode applied: ``edge_and_corner`` corners as vertex sharpness, ``none`` holes as holes).
    vmap : ndarray of int, shape (n',)
        Vertex of this mesh of every vertex of the split mesh (``vmap[:n] = arange(n)``).
    """
    n = mesh.n_vertices
    label, vmap, new = _fan_copies(mesh)
    vsharp = {int(v): s for v, s in mesh.vertex_sharpness.items()}
    sharp_fans, fin_vertices = _sharpen_nonmanifold(mesh, vsharp)
    if fin_vertices:
        warnings.warn(f"non-manifold crease vertices {fin_vertices[:10]}{' ...' if len(fin_vertices) > 10 else ''}"
                      f" ({len(fin_vertices)}): a fan not bounded by both non-manifold edges (a fin) is made a "
                      "sharp corner; OpenSubdiv's crease rule there needs a vertex outside the fan, so near "
                      "these vertices the surface differs from OpenSubdiv's (docs/evaluate.md)", stacklevel=2)
    if mesh.options.boundary == "edge_and_corner":
        corner = (mesh.face_count == 1) & mesh.is_boundary_vertex & ~mesh.is_nonmanifold_vertex
        for v in np.flatnonzero(corner).tolist():
            vsharp[v] = math.inf
    creases = _split_creases(mesh, new)
    corners = _split_corners(vsharp, vmap, n, sharp_fans, label)
    opts = Options("edge_only", mesh.options.crease_method, mesh.options.triangle_subdivision)
    try:
        m = type(mesh)(mesh.vertices[vmap], np.asarray(new, dtype=np.int64), sizes=mesh.sizes,
                     creases=creases or None, corners=corners or None,
                     holes=np.flatnonzero(mesh.is_hole), options=opts, _split=False)
    except MeshError as exc:
        raise MeshError(f"non-manifold mesh not supported after splitting its non-manifold vertices: "
                        f"{exc}") from None
    m.level = mesh.level
    return m, vmap


def _fan_copies(mesh):
    """(label, vmap, new) of :func:`split_nonmanifold_vertices`: the split vertex of every fan (the first fan of a
    vertex keeps its index, the others get n, n+1, ...), the vertex of every split vertex, the split
    vertex of every corner."""
    n, H = mesh.n_vertices, mesh.indices.size
    org, comp = mesh.indices, mesh.halfedges.fan_of_corner
    ncomp = int(comp.max()) + 1
    first_corner = np.full(ncomp, H, dtype=np.int64)
    np.minimum.at(first_corner, comp, np.arange(H))
    cv = org[first_corner]
    o = np.lexsort((first_corner, cv))
    lead = np.r_[True, cv[o][1:] != cv[o][:-1]]
    label = np.empty(ncomp, dtype=np.int64)
    label[o[lead]] = cv[o[lead]]
    extra = o[~lead]
    label[extra] = n + np.arange(extra.size)
    vmap = np.r_[np.arange(n), cv[extra]].astype(np.int64)
    new = label[comp]
    return label, vmap, new


def _sharpen_nonmanifold(mesh, vsharp):
    """OpenSubdiv's sharpening of the non-manifold vertices into ``vsharp`` (see :func:`split_nonmanifold_vertices`);
    returns (the fans made corners, the non-manifold crease vertices with such a fan)."""
    org, prv, comp = mesh.indices, mesh.prev, mesh.halfedges.fan_of_corner
    he = mesh.halfedges
    degenerate = np.zeros(mesh.n_vertices, dtype=bool)  # ends of a degenerate edge (a face repeating a vertex)
    degenerate[he.edges[he.repeat_edge].reshape(-1)] = True
    edge_of, nm_e, nm_v = mesh.edge_of_halfedge, mesh.is_nonmanifold_edge, mesh.is_nonmanifold_vertex
    chaikin = mesh.options.crease_method == "chaikin"
    by_vertex = np.argsort(org, kind="stable")  # corners grouped by vertex
    ptr = np.r_[0, np.cumsum(mesh.face_count)]
    sharp_fans = set()  # fans of crease vertices not bounded by both non-manifold edges: corners
    fin_vertices = []  # the non-manifold crease vertices with such a fan (one warning names them)
    for v in np.flatnonzero(nm_v).tolist():
        cs = by_vertex[ptr[v] : ptr[v + 1]]
        es = np.unique(np.r_[edge_of[cs], edge_of[prv[cs]]])
        nm_count = int(nm_e[es].sum())
        bnd = int(mesh.is_boundary_edge[es].sum())
        other = [mesh.edge_sharpness.get(tuple(mesh.edges[e].tolist()), 0.0) for e in es if not nm_e[e]]
        sharpened = not (nm_count == 2 and bnd == 0 and cs.size > es.size) or degenerate[v]
        if chaikin and any(0.0 < x < math.inf for x in other):
            # Chaikin: the child sharpness at v depends on all semi-sharp edges at v; a copy sees those
            # of its own fan only, so they must all be in one fan (and v a corner for ever)
            semi_e = {e for e in es if not nm_e[e]
                      and 0.0 < mesh.edge_sharpness.get(tuple(mesh.edges[e].tolist()), 0.0) < math.inf}
            fans = {int(comp[c]) for c in cs if edge_of[c] in semi_e or edge_of[prv[c]] in semi_e}
            if not sharpened or len(fans) > 1:
                raise MeshError(f"non-manifold vertex {v}: Chaikin creases with semi-sharp edges at a "
                                "non-manifold vertex are supported only in one of its fans, at a corner")
        if sharpened:
            vsharp[v] = math.inf
            continue
        # an interior non-manifold crease: the crease rule along its two non-manifold edges
        if any(x == math.inf for x in other):
            vsharp[v] = math.inf  # three or more infinitely sharp edges: a corner for ever
            continue
        semi = [x for x in other if x > 0.0]
        if semi:
            # a corner while any of these is sharp (three sharp edges), then the crease rule, blended
            # with the mean of the features that end at that step: the vertex sharpness T = the
            # largest of them on every copy gives each copy that schedule and that weight (uniform
            # decay), provided the features ending last all have T
            feats = semi + ([vsharp[v]] if vsharp.get(v, 0.0) > 0.0 else [])
            top = max(feats)
            last = {x for x in feats if math.ceil(x) == math.ceil(top)}
            if len(last) > 1:
                raise MeshError(
                    f"non-manifold crease vertex {v}: semi-sharp edges or vertex sharpness {sorted(last)} "
                    "ending at the same level with different values are not supported")
            vsharp[v] = top
        fins = fans_off_the_crease(mesh, cs)
        sharp_fans.update(fins)
        if fins:
            fin_vertices.append(v)
    return sharp_fans, fin_vertices


def _split_creases(mesh, new):
    """The crease tags ``{(a, b): s}`` of the split mesh whose corner vertices are ``new``: the non-manifold
    edges infinitely sharp, the other tagged edges as tagged."""
    H, nxt = mesh.indices.size, mesh.next
    edge_of, nm_e = mesh.edge_of_halfedge, mesh.is_nonmanifold_edge
    creases = {}
    hs = np.arange(H)
    for h in hs[nm_e[edge_of]].tolist():
        a, b = int(new[h]), int(new[nxt[h]])
        creases[(min(a, b), max(a, b))] = math.inf
    tagged = list(mesh.edge_sharpness.items())
    eids = mesh.halfedges.edge_index_of([a for (a, _), _ in tagged], [b for (_, b), _ in tagged]).tolist()
    for (_, x), e in zip(tagged, eids):
        if nm_e[e]:
            continue
        h = int(mesh.halfedges.edge_halfedge[e])
        p, q = int(new[h]), int(new[nxt[h]])
        creases[(min(p, q), max(p, q))] = x
    return creases


def fans_off_the_crease(mesh, cs):
    """The fans (ids of ``mesh.halfedges.fan_of_corner``) of a non-manifold crease vertex, given its corners
    ``cs``, that are not bounded by both of its non-manifold edges: a fin (a fan that leaves and comes back
    to the same non-manifold edge) or a closed fan.

    OpenSubdiv gives the vertex the crease rule along its two non-manifold edges (ends a, b:
    ``3/4 v + 1/8 (a + b)`` at every level); a fan bounded by both edges sees both ends, its split
    copy's crease rule is that one. A copy of any other fan sees at most one of them: no rule of
    the copy's own fan reproduces OpenSubdiv's vertex point there (it needs a vertex outside the
    fan). Such a copy is made an infinitely sharp corner: the sharp vertex of a sharpened
    non-manifold vertex, the closest exact surface the split can give (exact on every fan bounded
    by both edges; on the others the vertex stays at its position, where OpenSubdiv's moves along
    the crease curve of a, v, b: the fin's limit point is v instead of (a + 4 v + b) / 6).
    """
    comp, twin, prv, edge_of = mesh.halfedges.fan_of_corner, mesh.twin, mesh.prev, mesh.edge_of_halfedge
    out = []
    for c in sorted(set(comp[cs].tolist())):
        members = cs[comp[cs] == c]
        lead_c = members[twin[members] < 0]  # outgoing half-edge on a singular edge
        trail_c = members[twin[prv[members]] < 0]
        if lead_c.size != 1 or trail_c.size != 1 or edge_of[lead_c[0]] == edge_of[prv[trail_c[0]]]:
            out.append(c)
    return out


def _split_corners(vsharp, vmap, n, sharp_fans, label):
    """The vertex sharpness ``{u: s}`` of the split mesh: each vertex's value on all its copies, then the fans
    made corners (``label``: the split vertex of every fan)."""
    copies = {}
    for u in range(n, len(vmap)):
        copies.setdefault(int(vmap[u]), []).append(u)
    corners = {}
    for v, x in vsharp.items():
        for u in [v, *copies.get(v, [])]:
            corners[u] = x
    for c in sorted(sharp_fans):  # (after the vertex's own value: these copies are corners for ever)
        corners[int(label[c])] = math.inf
    return corners
