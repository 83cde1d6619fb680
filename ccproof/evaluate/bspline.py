"""Uniform cubic B-spline basis and the evaluation of bicubic patches on batches of points.

A regular Catmull-Clark patch is the tensor-product uniform cubic B-spline on its 4 x 4 control
net (the face and its one-ring); the face [0,1]^2 is the middle knot span.
``P(s, t) = sum_{i,j} B_i(s) B_j(t) net[i + 4 j]`` with

    B_0 = (1 - s)^3 / 6,           B_1 = (3 s^3 - 6 s^2 + 4) / 6,
    B_2 = (-3 s^3 + 3 s^2 + 3 s + 1) / 6,   B_3 = s^3 / 6.
"""

from __future__ import annotations

import numpy as np

__all__ = ["bspline_basis", "eval_patches"]


def bspline_basis(s, derivatives=0):
    """Uniform cubic B-spline basis functions at ``s`` and their derivatives.

    Parameters
    ----------
    s : ndarray, shape (n,)
    derivatives : int, 0, 1 or 2

    Returns
    -------
    list of ndarray, shape (n, 4)
        ``[B, B', B'']`` up to the requested order.

    Examples
    --------
    >>> import numpy as np
    >>> B, dB = bspline_basis(np.array([0.0, 1.0]), 1)
    >>> (np.round(B * 6, 12) + 0.0).tolist(), (np.round(dB * 2, 12) + 0.0).tolist()
    ([[1.0, 4.0, 1.0, 0.0], [0.0, 1.0, 4.0, 1.0]], [[-1.0, 0.0, 1.0, 0.0], [0.0, -1.0, 0.0, 1.0]])
    """
    s = np.asarray(s, dtype=np.float64)
    t = 1.0 - s
    s2 = s * s
    s3 = s2 * s
    B = np.empty(s.shape + (4,))
    B[..., 0] = t * t * t / 6
    B[..., 1] = (3 * s3 - 6 * s2 + 4) / 6
    B[..., 2] = (-3 * s3 + 3 * s2 + 3 * s + 1) / 6
    B[..., 3] = s3 / 6
    out = [B]
    if derivatives >= 1:
        D = np.empty_like(B)
        D[..., 0] = -0.5 * t * t
        D[..., 1] = 1.5 * s2 - 2 * s
        D[..., 2] = -1.5 * s2 + s + 0.5
        D[..., 3] = 0.5 * s2
        out.append(D)
    if derivatives >= 2:
        D2 = np.empty_like(B)
        D2[..., 0] = t
        D2[..., 1] = 3 * s - 2
        D2[..., 2] = -3 * s + 1
        D2[..., 3] = s
        out.append(D2)
    return out


def eval_patches(nets, s, t, derivatives=0):
    """Evaluate bicubic B-spline patches, one per point.

    Parameters
    ----------
    nets : ndarray, shape (n, 16, 3)
        Control net of the patch of each point, ``net[i + 4 j]`` (i along s).
    s, t : ndarray, shape (n,)
    derivatives : int, 0, 1 or 2

    Returns
    -------
    dict of ndarray, shape (n, 3)
        ``P`` and, as requested, ``Ps, Pt`` and ``Pss, Pst, Ptt`` (derivatives in (s, t)).

    Notes
    -----
    The tensor product of :func:`bspline_basis` (a regular Catmull-Clark patch is the uniform bicubic
    B-spline on its one-ring); docs/evaluate.md "Method", item 1 (regular faces).

    Examples
    --------
    Uniform B-splines reproduce linear functions: the net ``(i, j, 0)`` gives ``(1 + s, 1 + t, 0)``.

    >>> import numpy as np
    >>> j, i = np.mgrid[0:4, 0:4]
    >>> net = np.stack([i.ravel(), j.ravel(), np.zeros(16)], axis=1)[None].astype(float)
    >>> out = eval_patches(net, np.array([0.25]), np.array([0.5]), derivatives=1)
    >>> [(np.round(out[d], 12) + 0.0).tolist() for d in ("P", "Ps", "Pt")]
    [[[1.25, 1.5, 0.0]], [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]]]
    """
    bs = bspline_basis(s, derivatives)
    bt = bspline_basis(t, derivatives)
    N = nets.reshape(-1, 4, 4, 3)  # [n, j, i, c]
    T = [np.einsum("nj,njic->nic", b, N) for b in bt]  # contract over j (the t direction) first
    out = {"P": np.einsum("ni,nic->nc", bs[0], T[0])}
    if derivatives >= 1:
        out["Ps"] = np.einsum("ni,nic->nc", bs[1], T[0])
        out["Pt"] = np.einsum("ni,nic->nc", bs[0], T[1])
    if derivatives >= 2:
        out["Pss"] = np.einsum("ni,nic->nc", bs[2], T[0])
        out["Pst"] = np.einsum("ni,nic->nc", bs[1], T[1])
        out["Ptt"] = np.einsum("ni,nic->nc", bs[0], T[2])
    return out
