"""Brute-force Loop subdivision for the tests (independent of ccproof.evaluate.loop and ccproof.mesh.scheme).

Global subdivision of the whole mesh L levels with Loop's rules as OpenSubdiv's Sdc states them (smooth
vertex ``(1 - k beta) V + beta sum``, ``beta = (5/8 - (3/8 + cos(2 pi / k) / 4)^2) / k``; smooth edge
3/8 3/8 1/8 1/8; crease and boundary vertex 3/4 1/8 1/8; sharp edge midpoint; corners fixed), the
limit position of a level-L vertex by the limit mask, and at a vertex whose neighbourhood is regular
the exact derivatives of the quartic box spline from its one-ring: ``D_x = (1/3) sum_j <x, e_j> p_j``
with the unit vectors e_j of the equilateral lattice (the cos / sin tangent masks, scaled so that
linear functions are reproduced), and the second derivatives as second differences (the box spline's
second derivatives at a lattice point are supported on the one-ring and even; the three-direction
quartic box spline reproduces quadratics up to a constant, which fixes them).
"""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np

DIRS = ((1, 0), (0, 1), (-1, 1), (-1, 0), (0, -1), (1, -1))


def _beta(k):
    c = 3 / 8 + math.cos(2 * math.pi / k) / 4
    return (5 / 8 - c * c) / k


class Level:
    """One level of the global subdivision: vertices, triangles, tags."""

    def __init__(self, V, F, sharp=(), corners=(), boundary="edge_only"):
        """``sharp``, ``corners``: dicts of sharpness, or iterables (infinitely sharp)."""
        self.V = np.asarray(V, dtype=float)
        self.F = [tuple(int(x) for x in f) for f in F]
        sharp = sharp if isinstance(sharp, dict) else dict.fromkeys(sharp, math.inf)
        self.sharp = {(min(a, b), max(a, b)): x for (a, b), x in sharp.items() if x > 0}
        corners = corners if isinstance(corners, dict) else dict.fromkeys(corners, math.inf)
        self.corners = {v: x for v, x in corners.items() if x > 0}
        self.boundary = boundary
        self.opp = {}
        for a, b, c in self.F:
            self.opp[(a, b)], self.opp[(b, c)], self.opp[(c, a)] = c, a, b
        self.nbrs = {}
        for a, b in self.opp:
            self.nbrs.setdefault(a, set()).add(b)
            self.nbrs.setdefault(b, set()).add(a)

    def s(self, a, b):
        if (a, b) not in self.opp or (b, a) not in self.opp:
            return math.inf
        return self.sharp.get((min(a, b), max(a, b)), 0.0)

    def is_sharp(self, a, b):
        return self.s(a, b) > 0

    def kind(self, v, down=0):
        """Sdc rule of v with every sharpness lowered by ``down`` (1: the child's), and its sharp neighbours."""
        def dec(x):
            return x if x == math.inf else x - down
        ns = [w for w in self.nbrs[v] if dec(self.s(v, w)) > 0]
        boundary = any((v, w) not in self.opp or (w, v) not in self.opp for w in self.nbrs[v])
        if dec(self.corners.get(v, 0.0)) > 0 or len(ns) > 2 or (boundary and len(self.nbrs[v]) == 2
                                                                and self.boundary == "edge_and_corner"):
            return "corner", ns
        return ("crease" if len(ns) == 2 else "smooth"), ns

    def _mask_point(self, v, kind, ns):
        V = self.V
        if kind == "corner":
            return V[v]
        if kind == "crease":
            return 0.75 * V[v] + 0.125 * (V[ns[0]] + V[ns[1]])
        k = len(self.nbrs[v])
        b = _beta(k)
        return (1 - k * b) * V[v] + b * sum(V[w] for w in self.nbrs[v])

    def vertex_point(self, v):
        """Sdc's vertex point with semi-sharp transitions: parent rule, child rule, blended by the mean
        parent sharpness of the tags that become smooth."""
        kind, ns = self.kind(v)
        if kind == "smooth":
            return self._mask_point(v, kind, ns)
        ckind, cns = self.kind(v, 1)
        if ckind == kind:
            return self._mask_point(v, kind, ns)
        tags = [self.corners.get(v, 0.0)] + [self.s(v, w) for w in self.nbrs[v]]
        gone = [x for x in tags if 0 < x <= 1]
        # OpenSubdiv computes this weight and 1 - w in float32
        total = np.float32(0)
        for x in sorted(gone):
            total = np.float32(total + np.float32(x))
        w = min(float(np.float32(total / np.float32(len(gone)))), 1.0) if gone else 0.0
        return w * self._mask_point(v, kind, ns) + float(np.float32(1 - w)) * self._mask_point(v, ckind, cns)

    def subdivide(self):
        V, n = self.V, len(self.V)
        newV = np.array([self.vertex_point(v) for v in range(n)])
        emap, pts = {}, []
        for a, b, c in self.F:
            for x, y in ((a, b), (b, c), (c, a)):
                e = (min(x, y), max(x, y))
                if e not in emap:
                    emap[e] = n + len(pts)
                    mid = 0.5 * (V[x] + V[y])
                    sh = self.s(x, y)
                    if sh > 1:
                        pts.append(mid)
                        continue
                    smooth = 0.375 * (V[x] + V[y]) + 0.125 * (V[self.opp[(x, y)]] + V[self.opp[(y, x)]])
                    pts.append(sh * mid + float(np.float32(1 - sh)) * smooth)
        F = []
        for a, b, c in self.F:
            ab, bc, ca = emap[(min(a, b), max(a, b))], emap[(min(b, c), max(b, c))], emap[(min(c, a), max(c, a))]
            F += [(a, ab, ca), (ab, b, bc), (ca, bc, c), (bc, ca, ab)]
        sharp = {}
        for (a, b), x in self.sharp.items():
            e = emap[(a, b)]
            if x - 1 > 0:
                sharp[(a, e)] = sharp[(e, b)] = x - 1
        corners = {v: x - 1 for v, x in self.corners.items() if x - 1 > 0}
        return Level(np.vstack([newV, pts]), F, sharp, corners, self.boundary)

    def fan(self, v, start):
        out, w = [start], start
        while True:
            w = self.opp.get((v, w))
            if w is None or w == start:
                return out
            out.append(w)

    def limit(self, v):
        kind, ns = self.kind(v)
        if kind == "corner":
            return self.V[v]
        if kind == "crease":
            return (4 * self.V[v] + self.V[ns[0]] + self.V[ns[1]]) / 6
        if ns:  # a dart: the left eigenvector of its one-ring's subdivision matrix (one edge point a midpoint)
            return self._dart_limit(v)
        k = len(self.nbrs[v])
        eps = 1 / (k + 3 / (8 * _beta(k)))
        return (1 - k * eps) * self.V[v] + eps * sum(self.V[w] for w in self.nbrs[v])

    def _dart_limit(self, v):
        fan = self.fan(v, sorted(self.nbrs[v])[0])
        k = len(fan)
        S = np.zeros((k + 1, k + 1))
        b = _beta(k)
        S[0, 0], S[0, 1:] = 1 - k * b, b
        for j, w in enumerate(fan):
            if self.is_sharp(v, w):
                S[1 + j, 0] = S[1 + j, 1 + j] = 0.5
            else:
                S[1 + j, 0] = S[1 + j, 1 + j] = 0.375
                S[1 + j, 1 + (j + 1) % k] += 0.125
                S[1 + j, 1 + (j - 1) % k] += 0.125
        vals, vecs = np.linalg.eig(S.T)
        x = np.real(vecs[:, np.argmin(abs(vals - 1))])
        x /= x.sum()
        return x[0] * self.V[v] + sum(x[1 + j] * self.V[w] for j, w in enumerate(fan))

    def regular_around(self, v):
        """v and its neighbours: smooth interior valence 6, no sharp edge (the surface there is a box spline)."""
        for x in [v] + sorted(self.nbrs[v]):
            if self.kind(x)[0] != "smooth" or len(self.nbrs[x]) != 6:
                return False
            if any(self.is_sharp(x, w) for w in self.nbrs[x]):
                return False
        return True


def levels(V, F, L, **tags):
    out = [Level(V, F, **tags)]
    for _ in range(L):
        out.append(out[-1].subdivide())
    return out


def locate(u, v, L):
    """(child path, final corner, sign) of the dyadic point (u, v) (Fractions, denominator 2^L)."""
    path, sign = [], 1
    for _ in range(L):
        if u >= Fraction(1, 2):
            c, u, v = 1, 2 * u - 1, 2 * v
        elif v >= Fraction(1, 2):
            c, u, v = 2, 2 * u, 2 * v - 1
        elif u + v <= Fraction(1, 2):
            c, u, v = 0, 2 * u, 2 * v
        else:
            c, u, v, sign = 3, 1 - 2 * u, 1 - 2 * v, -sign
        path.append(c)
    corner = {(0, 0): 0, (1, 0): 1, (0, 1): 2}[(u, v)]
    return path, corner, sign


def brute(lv, face, u, v):
    """Exact values at dyadic (u, v) of a level-0 face: dict P (and Pu, Pv, Puu, Puv, Pvv at regular vertices)."""
    L = len(lv) - 1
    path, corner, sign = locate(Fraction(u), Fraction(v), L)
    f = face
    for c in path:
        f = 4 * f + c
    top = lv[L]
    tri = top.F[f]
    x = tri[corner]
    out = {"P": top.limit(x)}
    if not top.regular_around(x):
        return out
    fan = top.fan(x, tri[(corner + 1) % 3])
    d = [DIRS[(2 * corner + j) % 6] for j in range(6)]
    p = {di: top.V[w] for di, w in zip(d, fan)}
    p0 = top.V[x]
    # equilateral lattice: e_j at angles 60 j; d/du = <(1, 0), .>, d/dv = <(1/2, sqrt 3 / 2), .>
    ang = {DIRS[j]: math.pi * j / 3 for j in range(6)}
    h = 2.0**L * sign
    out["Pu"] = h * sum(math.cos(ang[q]) * p[q] for q in DIRS) / 3
    out["Pv"] = h * sum(math.cos(ang[q] - math.pi / 3) * p[q] for q in DIRS) / 3
    h2 = 4.0**L
    out["Puu"] = h2 * (p[(1, 0)] + p[(-1, 0)] - 2 * p0)
    out["Pvv"] = h2 * (p[(0, 1)] + p[(0, -1)] - 2 * p0)
    out["Puv"] = h2 * (0.5 * (p[(1, 0)] + p[(-1, 0)] + p[(0, 1)] + p[(0, -1)] - p[(-1, 1)] - p[(1, -1)]) - p0)
    return out
