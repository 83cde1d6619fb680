"""Frames: where a (virtual) face sits in its ptex face, and the orientation of nets and layers in it.

A frame maps a face's own parameter (s, t) to the base face's (u, v): (u, v) = o + s a + t b, with a, b
axis-aligned of the same length (a power of 2). Frames are tuples of three float pairs (o, a, b): they are
composed once per virtual face, so plain floats (every value dyadic, every operation exact) instead of small
arrays. The factory (:mod:`ccproof.evaluate.factory`) composes them; the patch table
(:mod:`ccproof.evaluate.patch_table`) stores their domains and the layer operators in their orientation.

The child at corner 0 of the child at corner 2 (corner (1, 1), its axes pointing to -u and -v) is the
square of side 1/4 at that corner:

>>> domain(compose(child_frame(2), child_frame(0)))
(0.75, 0.75, 0.25)
"""

from __future__ import annotations

import functools

import numpy as np

from ccproof.evaluate.local import CORNERS

_C = tuple((float(x), float(y)) for x, y in CORNERS)


def compose(frame, sub):
    """Frame ``sub`` (given in the coordinates of ``frame``) in the coordinates ``frame`` is given in."""
    (ox, oy), (ax, ay), (bx, by) = frame
    (p, q), (sa0, sa1), (sb0, sb1) = sub
    return ((ox + ax * p + bx * q, oy + ay * p + by * q), (ax * sa0 + bx * sa1, ay * sa0 + by * sa1),
            (ax * sb0 + bx * sb1, ay * sb0 + by * sb1))


def corner_frame(i, scale=1.0):
    """Frame of the square at corner i of [0,1]^2, rotated so that corner i is its origin."""
    c, c1, c3 = _C[i], _C[(i + 1) % 4], _C[(i + 3) % 4]
    return (c, ((c1[0] - c[0]) * scale, (c1[1] - c[1]) * scale), ((c3[0] - c[0]) * scale, (c3[1] - c[1]) * scale))


def child_frame(i):
    """Frame of the half-size child square at corner ``i`` of [0,1]^2 (corner ``i`` its origin)."""
    return corner_frame(i, 0.5)


def _layer_frame(n, j):
    """Frame of patch P_j of layer n in the corner frame (corner at the origin), bmz04 Fig. 3."""
    h = 2.0 ** -(n + 1)
    o, a, b = corner_frame(j, h)
    return ((o[0] * 2.0 * h, o[1] * 2.0 * h), a, b)


def domain(frame):
    """``(u0, v0, size)``: the axis-aligned square a frame covers, its lower-left corner and side."""
    (ox, oy), (ax, ay), (bx, by) = frame
    return ox + min(ax, 0.0) + min(bx, 0.0), oy + min(ay, 0.0) + min(by, 0.0), max(abs(ax), abs(ay))


@functools.lru_cache(maxsize=64)
def _permutation(ah, bh):
    perm = np.empty(16, dtype=np.int64)
    for q in range(4):
        for p in range(4):
            i = int(round(1.5 + (p - 1.5) * ah[0] + (q - 1.5) * bh[0]))
            j = int(round(1.5 + (p - 1.5) * ah[1] + (q - 1.5) * bh[1]))
            perm[i + 4 * j] = p + 4 * q
    perm.setflags(write=False)
    return perm


def net_permutation(frame):
    """Index map sending a net in the frame's own orientation to the base orientation."""
    _, a, b = frame
    return _permutation(axis_signs(a), axis_signs(b))


def axis_signs(x):
    return (int(x[0] > 0) - int(x[0] < 0), int(x[1] > 0) - int(x[1] < 0))


@functools.lru_cache(maxsize=16)
def _corner_orientation(orient):
    """Rows of a scheme's layer nets and layer-0 domains for a corner frame with axis directions
    ``orient``: ``rows`` (48,), row ``16 code + i`` of a layer in the base orientation is row
    ``rows[16 code + i]`` of its ``3 x 16`` nets ``D[n, j-1]``; ``unit`` (3, 3), the domains of the
    three patches of layer 0 for a unit frame at the origin."""
    a, b = orient
    unit_rot = ((0.0, 0.0), (float(a[0]), float(a[1])), (float(b[0]), float(b[1])))
    # P_1 lies along the frame's a-axis: code 0 (u-distance >= 1/2, v-distance < 1/2) if a is
    # along u, else code 2; P_2 (diagonal) is code 1; P_3 the other one
    a_along_u = a[0] != 0
    codes = {1: 0 if a_along_u else 2, 2: 1, 3: 2 if a_along_u else 0}
    rows = np.empty(48, dtype=np.int64)
    unit = np.empty((3, 3))
    for j in (1, 2, 3):
        f0 = compose(unit_rot, _layer_frame(0, j))
        rows[16 * codes[j]:16 * codes[j] + 16] = 16 * (j - 1) + net_permutation(f0)
        unit[codes[j]] = domain(f0)
    rows.setflags(write=False)
    unit.setflags(write=False)
    return rows, unit


def oriented_layers(scheme, orient):
    """The layer operators of ``scheme`` for a corner frame with axis directions ``orient``:
    ``L`` (n_layers * 3 * 16, N), row ``(n, code, i)`` entry i of the net of layer n, patch ``code``,
    in the base orientation, and ``unit`` (3, 3) (see :func:`_corner_orientation`)."""
    rows, unit = _corner_orientation(orient)
    Ls = scheme.layers
    nl, N = Ls.shape[0], Ls.shape[-1]
    return np.take(Ls.reshape(nl, 48, N), rows, axis=1).reshape(-1, N), unit
