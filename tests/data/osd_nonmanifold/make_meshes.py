"""Write the small test meshes of this folder (run once; the files are committed).

python tests/data/osd_nonmanifold/make_meshes.py   (numpy only; fixed seed)
"""

import math
import os

import numpy as np

HERE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "meshes")
rng = np.random.default_rng(20261202)


def jitter(V, a=0.05):
    return np.asarray(V, dtype=float) + a * rng.uniform(-1, 1, np.shape(V))


def write_obj(name, V, F, comment):
    with open(os.path.join(HERE, name), "w") as fh:
        for c in comment.strip().splitlines():
            fh.write(f"# {c}\n")
        for x, y, z in np.asarray(V, dtype=float).tolist():
            fh.write(f"v {x:.17g} {y:.17g} {z:.17g}\n")
        for f in F:
            fh.write("f " + " ".join(str(i + 1) for i in f) + "\n")


def write_off(name, V, F, comment):
    with open(os.path.join(HERE, name), "w") as fh:
        fh.write("OFF\n")
        for c in comment.strip().splitlines():
            fh.write(f"# {c}\n")
        fh.write(f"{len(V)} {len(F)} 0\n")
        for x, y, z in np.asarray(V, dtype=float).tolist():
            fh.write(f"{x:.17g} {y:.17g} {z:.17g}\n")
        for f in F:
            fh.write(f"{len(f)} " + " ".join(str(i) for i in f) + "\n")


def book(pages=4, rows=2, cols=2):
    """`pages` quad grids (cols x rows) hinged on a common spine of `rows` edges along z."""
    V = [[0.0, 0.0, float(j)] for j in range(rows + 1)]  # spine
    F = []
    for p in range(pages):
        a = 2 * math.pi * p / pages + 0.3
        base = len(V)
        for i in range(1, cols + 1):
            for j in range(rows + 1):
                V.append([i * math.cos(a), i * math.sin(a), float(j)])

        def vid(i, j, base=base):
            return j if i == 0 else base + (i - 1) * (rows + 1) + j

        for i in range(cols):
            for j in range(rows):
                q = [vid(i, j), vid(i + 1, j), vid(i + 1, j + 1), vid(i, j + 1)]
                F.append(q if p % 2 == 0 else q[::-1])
    return jitter(V), F


def cube_grid(n=2, lo=(0.0, 0.0, 0.0), size=1.0):
    """A closed cube [lo, lo + size]^3 with n x n quads per side (outward)."""
    pts, index = [], {}

    def vid(p):
        k = tuple(int(round(c)) for c in p)
        if k not in index:
            index[k] = len(pts)
            pts.append([lo[d] + size * k[d] / n for d in range(3)])
        return index[k]

    F = []
    for axis in range(3):
        for side in (0, n):
            u, w = (axis + 1) % 3, (axis + 2) % 3
            for i in range(n):
                for j in range(n):
                    quad = []
                    for di, dj in ((0, 0), (1, 0), (1, 1), (0, 1)):
                        p = [0, 0, 0]
                        p[axis], p[u], p[w] = side, i + di, j + dj
                        quad.append(vid(p))
                    F.append(quad if side == n else quad[::-1])
    return np.array(pts), F


def two_cubes():
    """Two closed cubes (2 x 2 quads per side) that touch at one vertex: a non-manifold vertex."""
    V1, F1 = cube_grid(2, (0.0, 0.0, 0.0))
    V2, F2 = cube_grid(2, (-1.0, -1.0, -1.0))
    shared = int(np.flatnonzero((np.abs(V1) < 1e-12).all(axis=1))[0])  # (0,0,0) of cube 1
    other = int(np.flatnonzero((np.abs(V2) < 1e-12).all(axis=1))[0])  # (0,0,0) of cube 2
    remap = {}
    V = [*V1.tolist()]
    for i, p in enumerate(V2.tolist()):
        if i == other:
            remap[i] = shared
        else:
            remap[i] = len(V)
            V.append(p)
    F = F1 + [[remap[i] for i in f] for f in F2]
    V = jitter(V, 0.04)
    return V, F


def bowtie():
    """Two 2 x 2 quad grids that touch at one corner (two open fans at a vertex) plus a triangle fan."""
    V, F = [], []
    for sx, sy in ((1, 1), (-1, -1)):
        base = len(V)
        for j in range(3):
            for i in range(3):
                V.append([sx * i * 0.5, sy * j * 0.5, 0.3 * (i * j) / 4])
        F += [[base + j * 3 + i, base + j * 3 + i + 1, base + (j + 1) * 3 + i + 1, base + (j + 1) * 3 + i]
              for j in range(2) for i in range(2)]
    # identify the two (0, 0) corners
    V = np.array(V)
    second = 9
    F = [[0 if v == second else (v - 1 if v > second else v) for v in f] for f in F]
    V = np.delete(V, second, axis=0)
    return jitter(V, 0.03), F


def collapsed(n=4):
    """A triangulated n x n grid on a height field in which one interior edge was collapsed the way a
    careless scan pipeline does it: vertex c replaced by vertex a everywhere, the two triangles of edge
    (a, c) kept, now with a repeated vertex (degenerate faces)."""
    V = [[i / n, j / n, 0.2 * math.sin(2.0 * i / n) * math.cos(1.5 * j / n)]
         for j in range(n + 1) for i in range(n + 1)]
    F = []
    for j in range(n):
        for i in range(n):
            a, b, c, d = j * (n + 1) + i, j * (n + 1) + i + 1, (j + 1) * (n + 1) + i + 1, (j + 1) * (n + 1) + i
            F += [[a, b, c], [a, c, d]]
    a, c = 1 * (n + 1) + 1, 1 * (n + 1) + 2  # the interior edge (6, 7) for n = 4
    F = [[a if v == c else v for v in f] for f in F]
    return jitter(V, 0.02), F


def with_unused(V, F):
    """Insert unused vertices (one with NaN coordinates) at indices 0, 5 and the end."""
    V = np.asarray(V, dtype=float)
    n = len(V)
    new_of = {}
    out = [[7.0, 7.0, 7.0]]
    for i in range(n):
        if i == 4:
            out.append([float("nan")] * 3)
        new_of[i] = len(out)
        out.append(V[i].tolist())
    out.append([-3.0, 2.0, 1.0])
    return np.array(out), [[new_of[v] for v in f] for f in F]


def prism(k=5):
    """A closed k-gonal prism: two k-gons and k quads, with a triangle fan roof on one quad."""
    V = [[math.cos(2 * math.pi * i / k), math.sin(2 * math.pi * i / k), z] for z in (0.0, 1.0) for i in range(k)]
    F = [list(range(k))[::-1], list(range(k, 2 * k))]
    for i in range(k):
        j = (i + 1) % k
        F.append([i, j, k + j, k + i])
    # replace the last side quad by four triangles around a new apex
    q = F.pop()
    c = np.mean([V[v] for v in q], axis=0) * 1.3
    V.append(c.tolist())
    a = len(V) - 1
    F += [[q[m], q[(m + 1) % 4], a] for m in range(4)]
    return jitter(V, 0.04), F


def main():
    os.makedirs(HERE, exist_ok=True)
    V, F = book()
    write_obj("book4.obj", V, F, "four 2x2 quad grids on a common spine of two edges: two non-manifold edges\n"
              "(4 faces each), a non-manifold crease vertex in the middle, pages alternately oriented")
    V, F = two_cubes()
    write_obj("two_cubes.obj", V, F, "two closed cubes (2x2 quads per side) touching at one vertex (vertex 0):\n"
              "a non-manifold vertex with two closed fans")
    V, F = bowtie()
    write_obj("bowtie.obj", V, F, "two 2x2 quad grids touching at one corner (vertex 0): two open fans")
    Vc, Fc = cube_grid(2)
    Fd = Fc + [list(Fc[4])]
    write_obj("dupface.obj", jitter(Vc), Fd, "a cube with 2x2 quads per side; face 4 given twice (face 24)")
    Ff = [list(f) for f in Fc]
    Ff[4] = Ff[4][::-1]
    write_obj("flipped.obj", jitter(Vc), Ff, "a cube with 2x2 quads per side; face 4 oriented the other way")
    V, F = with_unused(jitter(Vc), Fc)
    write_obj("unused.obj", V, F, "a cube with 2x2 quads per side; unused vertices 0 (7,7,7), 5 (NaN) and the\n"
              "last one")
    tagged = {
        "book4_tags.obj": ("book4.obj", "book4 with tags: semi-sharp vertex sharpness on the non-manifold crease "
                           "vertex 1,\n"
                           "a semi-sharp edge at the non-manifold corner vertex 0, a semi-sharp page edge, boundary\n"
                           "interpolation edge-and-corner",
                           ["t corner 1/1/0 1 2.5", "t crease 2/1/0 0 3 1.5", "t crease 2/1/0 4 5 3",
                            "t interpolateboundary 1/0/0 1"]),
        "bowtie_none.obj": ("bowtie.obj", "bowtie with boundary interpolation none and the boundary of the first grid\n"
                            "infinitely sharp: OpenSubdiv's implicit holes around the non-manifold vertex 0",
                            ["t crease 16/1/0 0 1 1 2 2 5 5 8 8 7 7 6 6 3 3 0 10", "t interpolateboundary 1/0/0 0"]),
        "book4_infpage.obj": ("book4.obj", "book4 with an infinitely sharp page edge at the non-manifold crease "
                              "vertex 1:\n"
                              "three infinitely sharp edges, a corner", ["t crease 2/1/0 1 4 10"]),
        "book4_semipage.obj": ("book4.obj", "book4 with semi-sharp page edges (1.5 and 0.7) at the non-manifold crease "
                               "vertex 1:\na corner until they decay, then a crease",
                               ["t crease 2/1/0 1 4 1.5", "t crease 2/1/0 1 10 0.7"]),
        "two_cubes_chaikin.obj": ("two_cubes.obj", "two_cubes with Chaikin creases: semi-sharp edges 2.5 and 1.5 at "
                                  "the\n"
                                  "non-manifold vertex 0, both in the fan of the first cube, and 3 next to them",
                                  ["t crease 2/1/0 0 1 2.5", "t crease 2/1/0 0 3 1.5", "t crease 2/1/0 1 2 3",
                                   "t creasemethod 0/0/1 chaikin"]),
        "two_cubes_creases.obj": ("two_cubes.obj", "two_cubes with a semi-sharp and an infinitely sharp edge at the\n"
                                  "non-manifold vertex 0 and a semi-sharp corner elsewhere",
                                  ["t crease 2/1/0 0 1 2.5", "t crease 2/1/0 0 39 10", "t corner 1/1/0 4 1.5",
                                   "t crease 2/1/0 0 3 0.5"]),
    }
    for name, (base, comment, lines) in tagged.items():
        with open(os.path.join(HERE, base)) as fh:
            body = [x for x in fh.read().splitlines() if not x.startswith("#")]
        with open(os.path.join(HERE, name), "w") as fh:
            fh.write("".join(f"# {c}\n" for c in comment.splitlines()))
            fh.write("\n".join(body + lines) + "\n")
    V, F = prism()
    write_off("prism.off", V, F, "a pentagonal prism (two pentagons, four quads) with a four-triangle roof:\n"
              "an OFF file with quads and n-gons")
    V, F = collapsed()
    write_obj("collapsed.obj", V, F, "a triangulated 4x4 grid with the interior edge (6, 7) collapsed: vertex 7\n"
              "replaced by 6 in every face, its two triangles kept with a repeated vertex (7 is now unused)")


def cone_fan(V, F, v, a, axis, k=3, radius=1.0, flip=False):
    """A fin: k quads around vertex v that leave the edge (v, a) and come back to it, on a cone with
    apex V[v] and axis `axis` through the direction of a (faces appended to F, ring vertices to V)."""
    c = np.asarray(V[v], dtype=float)
    d = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    da = np.asarray(V[a], dtype=float) - c
    da /= np.linalg.norm(da)
    u = da - (da @ d) * d
    u /= np.linalg.norm(u)
    w = np.cross(d, u)
    cos_h = da @ d
    sin_h = math.sqrt(1.0 - cos_h * cos_h)
    ring = [a]
    for j in range(1, 2 * k):
        t = math.pi * j / k
        r = radius * (1.4 if j % 2 == 0 else 1.0)
        V.append((c + r * (cos_h * d + sin_h * (math.cos(t) * u + math.sin(t) * w))).tolist())
        ring.append(len(V) - 1)
    ring.append(a)
    for j in range(k):
        q = [v, ring[2 * j], ring[2 * j + 1], ring[2 * j + 2]]
        F.append(q[::-1] if flip else q)


def spine_with_fins(pages=1, fins0=1, fins1=1):
    """A spine of two edges (vertices 0, 1, 2 along z), `pages` 2x2 pages on both spine edges, `fins0`
    fins on the edge (1, 0) and `fins1` on the edge (1, 2) (cone_fan)."""
    V, F = book(pages)
    V = np.asarray(V, dtype=float).tolist()
    for i in range(fins0):
        cone_fan(V, F, 1, 0, (math.cos(math.pi + 1.2 * i), math.sin(math.pi + 1.2 * i), -1.0), flip=i % 2 == 1)
    for i in range(fins1):
        cone_fan(V, F, 1, 2, (math.cos(2.0 + 1.2 * i), math.sin(2.0 + 1.2 * i), 1.0), flip=i % 2 == 1)
    return jitter(V, 0.03), F


def triangulated(V, F):
    """Each quad cut along a diagonal chosen at random (a decimated scan's triangles)."""
    out = []
    for q in F:
        if rng.uniform() < 0.5:
            out += [[q[0], q[1], q[2]], [q[0], q[2], q[3]]]
        else:
            out += [[q[0], q[1], q[3]], [q[1], q[2], q[3]]]
    return V, out


def fins_main():
    """The meshes with fans of a non-manifold crease vertex not bounded by both non-manifold edges."""
    V, F = spine_with_fins(1, 1, 1)
    write_obj("fin.obj", V, F, "a 2x2 page on a spine of two edges (vertices 0, 1, 2) and a fin of three quads on\n"
              "each spine edge (a fan at vertex 1 that leaves the edge and comes back to it): both spine edges\n"
              "non-manifold (3 faces), vertex 1 a non-manifold crease whose fins see one spine edge each")
    V, F = spine_with_fins(0, 2, 2)
    write_obj("fins_only.obj", V, F, "a spine of two edges (vertices 0, 1, 2), two fins of three quads on the edge\n"
              "(1, 0) and two on (1, 2) (the second ones reversed), no page: vertex 1 a non-manifold crease with\n"
              "no fan bounded by both spine edges")
    V, F = triangulated(*spine_with_fins(3, 1, 0))
    write_obj("fin_tri.obj", V, F, "three pages and a fin on the edge (1, 0), every quad cut along a random\n"
              "diagonal (a decimated scan's triangles): vertex 1 a non-manifold crease with three pages\n"
              "bounded by both spine edges and a fin")


if __name__ == "__main__":
    main()
    fins_main()
