"""OpenSubdiv's tags of a :class:`~ccproof.mesh.PolyMesh` read and checked: crease (edge) and corner (vertex)
sharpness, float32 as OpenSubdiv stores it, ``>= 10`` infinitely sharp; a bad item named (the edge, the vertex,
the value).
"""

from __future__ import annotations

import math

import numpy as np

from ccproof.errors import MeshError
from ccproof.mesh.rules import INFINITE

__all__ = ["sharpness_value", "crease_tags", "corner_tags"]


def sharpness_value(x, what):
    """A tag's sharpness as OpenSubdiv stores it (float32; ``>= 10`` infinite), checked (``what`` names the tag)."""
    try:
        s = float(x)
    except (TypeError, ValueError):
        raise MeshError(f"{what}: sharpness {x!r} is not a number") from None
    if math.isnan(s):
        raise MeshError(f"{what}: sharpness is NaN")
    if s < 0:
        raise MeshError(f"{what}: negative sharpness {s!r}")
    if s >= INFINITE:
        return math.inf
    return float(np.float32(s))  # OpenSubdiv stores sharpness as float32


def crease_tags(halfedges, creases):
    """The crease tags ``{(lo, hi): sharpness}`` (positive only) of ``creases`` (``(edges, sharpness)`` or a
    dict), every edge looked up in ``halfedges`` and every value checked; the first bad item, in order, named."""
    out = {}
    if creases is None:
        return out
    if isinstance(creases, dict):
        items = list(creases.items())
    else:
        E, S = creases
        E = np.asarray(E).reshape(-1, 2)
        S = np.broadcast_to(np.asarray(S, dtype=object), (E.shape[0],))
        items = [((a, b), s) for (a, b), s in zip(E.tolist(), S.tolist())]
    # the values checked item by item, the edges looked up at once (no dict of all the mesh's edges);
    # the first bad item, in order, named
    ab, sv, err = [], [], None
    try:
        for (a, b), s in items:
            a, b = int(a), int(b)
            x = sharpness_value(s, f"crease on edge ({a}, {b})")
            ab.append((a, b))
            sv.append(x)
    except (MeshError, TypeError, ValueError) as exc:  # raised after any missing edge before it
        err = exc
    n = halfedges.n_vertices  # (a vertex id out of range, even beyond int64, is no edge: -1)
    A = np.array([(a if 0 <= a < n else -1, b if 0 <= b < n else -1) for a, b in ab], dtype=np.int64).reshape(-1, 2)
    missing = np.flatnonzero(halfedges.edge_index_of(A[:, 0], A[:, 1]) < 0)
    if missing.size:
        a, b = ab[int(missing[0])]
        raise MeshError(f"crease on edge ({a}, {b}): no such edge in the mesh")
    if err is not None:
        raise err
    for (a, b), x in zip(ab, sv):
        k = (min(a, b), max(a, b))
        if x > 0:
            out[k] = x
        else:
            out.pop(k, None)
    return out


def corner_tags(n, corners):
    """The corner tags ``{v: sharpness}`` (positive only) of ``corners`` (``(vertices, sharpness)`` or a dict) on
    ``n`` vertices, every vertex and value checked."""
    out = {}
    if corners is None:
        return out
    if isinstance(corners, dict):
        items = list(corners.items())
    else:
        Vs, S = corners
        Vs = np.asarray(Vs).reshape(-1)
        S = np.broadcast_to(np.asarray(S, dtype=object), (Vs.shape[0],))
        items = list(zip(Vs.tolist(), S.tolist()))
    for v, s in items:
        vi = int(v)
        if vi != v or not 0 <= vi < n:
            raise MeshError(f"corner on vertex {v!r}: out of range [0, {n})")
        sv = sharpness_value(s, f"corner on vertex {vi}")
        if sv > 0:
            out[vi] = sv
    return out
