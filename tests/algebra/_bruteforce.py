"""An independent, deliberately naive Catmull-Clark implementation used as a test oracle.

It knows nothing of ccproof: a mesh is a list of quads over vertex ids; one step applies the rules
of bmz04 Fig. 1 (R1) literally (face point = mean, edge point = mean of the two ends and the two
new face points, vertex point = (F + 2R + (n-3)V)/n), with boundary edges -> midpoints.
"""

from fractions import Fraction


def ring_mesh(k, n):
    """k-regular complex: k sectors of n x n quads around vertex 'c'. Vertex (j, a, b) is grid point
    (a, b) of sector j (a >= 1, b >= 0); grid point (0, b) of sector j is (j+1, b, 0)."""

    def vid(j, a, b):
        if a == 0 and b == 0:
            return "c"
        if a == 0:
            return ((j + 1) % k, b, 0)
        return (j % k, a, b)

    faces = []
    for j in range(k):
        for a in range(n):
            for b in range(n):
                faces.append((vid(j, a, b), vid(j, a + 1, b), vid(j, a + 1, b + 1), vid(j, a, b + 1)))
    return faces, vid


def cc_step(faces, values, zero):
    """One Catmull-Clark step. ``values``: vertex id -> value (supports + and * Fraction).

    Returns (face_pt, edge_pt, vert_pt): dicts keyed by face index, frozenset edge, vertex id.
    Vertex points are computed for interior vertices only.
    """
    face_pt = {}
    for i, f in enumerate(faces):
        acc = zero
        for v in f:
            acc = acc + values[v]
        face_pt[i] = acc * Fraction(1, 4)
    edge_faces = {}
    for i, f in enumerate(faces):
        for t in range(4):
            e = frozenset((f[t], f[(t + 1) % 4]))
            edge_faces.setdefault(e, []).append(i)
    edge_pt = {}
    for e, fl in edge_faces.items():
        a, b = tuple(e)
        if len(fl) == 2:
            edge_pt[e] = (values[a] + values[b] + face_pt[fl[0]] + face_pt[fl[1]]) * Fraction(1, 4)
        else:
            edge_pt[e] = (values[a] + values[b]) * Fraction(1, 2)
    vert_pt = {}
    vfaces, vedges = {}, {}
    for i, f in enumerate(faces):
        for v in f:
            vfaces.setdefault(v, []).append(i)
    for e in edge_faces:
        for v in e:
            vedges.setdefault(v, []).append(e)
    for v, fl in vfaces.items():
        es = vedges[v]
        if any(len(edge_faces[e]) != 2 for e in es):
            continue
        n = len(es)
        F = zero
        for i in fl:
            F = F + face_pt[i]
        F = F * Fraction(1, n)
        R = zero
        for e in es:
            a, b = tuple(e)
            R = R + (values[a] + values[b]) * Fraction(1, 2)
        R = R * Fraction(1, n)
        vert_pt[v] = (F + R * 2 + values[v] * (n - 3)) * Fraction(1, n)
    return face_pt, edge_pt, vert_pt


def level1_value(faces, vid, step, j, A, B):
    """Value of the level-1 vertex at grid position (A, B) of sector j (A >= 1 or centre)."""
    face_pt, edge_pt, vert_pt = step
    if A % 2 == 0 and B % 2 == 0:
        return vert_pt[vid(j, A // 2, B // 2)]
    if A % 2 == 1 and B % 2 == 1:
        a, b = (A - 1) // 2, (B - 1) // 2
        corners = {vid(j, a, b), vid(j, a + 1, b), vid(j, a + 1, b + 1), vid(j, a, b + 1)}
        idx = next(i for i, f in enumerate(faces) if set(f) == corners)
        return face_pt[idx]
    if A % 2 == 1:
        a, b = (A - 1) // 2, B // 2
        return edge_pt[frozenset((vid(j, a, b), vid(j, a + 1, b)))]
    a, b = A // 2, (B - 1) // 2
    return edge_pt[frozenset((vid(j, a, b), vid(j, a, b + 1)))]
