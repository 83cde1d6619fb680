"""The quartic blocks of the box-spline patches of a whole mesh in one compiled pass (numba), at setup.

A block is what :mod:`ccproof.evaluate.loop.kernel` evaluates: the 3 x 15 monomial coefficients of a patch,
``K @ net`` with ``K`` the box spline's (15, 12) coefficient matrix and ``net`` the patch's 12 control points.
For the regular triangles of a mesh the nets are rows of the vertex array (``X[labels[r]]``): here the blocks
are summed from the vertices directly, without the nets as an array of their own, into the kernel's table.
"""

from __future__ import annotations

import numba
import numpy as np

__all__ = ["quartic_blocks"]


@numba.njit(cache=True)
def _blocks(X, labels, K, out):
    for r in range(labels.shape[0]):
        for c in range(3):
            for m in range(15):
                out[r, c, m] = 0.0
        for k in range(12):
            v = labels[r, k]
            for c in range(3):
                x = X[v, c]
                for m in range(15):
                    out[r, c, m] += K[m, k] * x


def quartic_blocks(X, labels, K, out):
    """``out[r] = (K @ X[labels[r]]).T`` for every row r of ``labels`` (R, 12): the blocks (R, 3, 15) of the
    patches whose 12 control points are the vertices ``labels[r]`` of ``X`` (n, 3), in NET order.

    >>> X = np.arange(36.0).reshape(12, 3)
    >>> K = np.arange(180.0).reshape(15, 12)
    >>> out = np.empty((1, 3, 15))
    >>> quartic_blocks(X, np.arange(12)[None], K, out)
    >>> bool(np.array_equal(out[0], (K @ X).T))
    True
    """
    if labels.shape[0]:
        _blocks(np.ascontiguousarray(X, dtype=np.float64), np.ascontiguousarray(labels, dtype=np.int64),
                np.ascontiguousarray(K, dtype=np.float64), out)
