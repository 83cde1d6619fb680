"""The blended reparameterization F_b of a face, bmz04 eq. (4) (docs/readings.md R6):

    F_b(t) = sum_i w_i(T_i^-1 t) T_i F_i T_i^-1 t + (1 - sum_i w_i(T_i^-1 t)) t,

over the four corners i of the face [0,1]^2 (corner i at (0,0), (1,0), (1,1), (0,1)). T_i maps the
quadrant frame of corner i to the face: ``T_i(s, t) = c_i + s a_i + t b_i`` with ``a_i`` along the
edge to corner i+1 and ``b_i`` along the edge to corner i-1 (a rotation by i quarter turns; the
evaluator's corner frames). The weights w_i vanish outside the open quarter [0, 1/2)^2 of their
corner, so at most one term is active at a point and F_b is, on the quarter of corner i,
``G_i(t) = w(t) F_i(t) + (1 - w(t)) t`` in local coordinates (R7), and the identity elsewhere.

F_i: Phi^-1 of the corner's valence ("characteristic", w = b(s) b(t)) or F^alpha
("vanishing", w = b(|t|)); the identity at valence-4 corners and at boundary vertices (code 0).
"""

from __future__ import annotations

import numpy as np

from ccproof.errors import CCProofError
from ccproof.reparam.quadrant import default_alpha, inverse_characteristic_map_derivatives, vanishing_map
from ccproof.reparam.weights import weight_complement, weight_radial, weight_tensor

__all__ = ["PARAMETERIZATIONS", "CORNER_FRAMES", "to_local", "from_local", "quarter_map", "active_points",
           "blend_points", "face_map"]

#: names accepted by ``parameterization=``
PARAMETERIZATIONS = ("natural", "vanishing", "characteristic")

#: linear parts A_i = [a_i b_i] of the corner transforms T_i (columns), shape (4, 2, 2)
CORNER_FRAMES = np.array([
    [[1.0, 0.0], [0.0, 1.0]],
    [[0.0, -1.0], [1.0, 0.0]],
    [[-1.0, 0.0], [0.0, -1.0]],
    [[0.0, 1.0], [-1.0, 0.0]],
])


def quarter(u, v):
    """Index of the corner whose closed quarter contains (u, v) (ties towards the larger index).

    The four corner quarters of the face on which the blend of bmz04 eq. 4 acts (docs/readings.md R6).

    Parameters
    ----------
    u, v : ndarray, shape (n,) float64
        Face parameters in [0, 1]^2.

    Returns
    -------
    ndarray, shape (n,) int64
        0: [0, 1/2]^2 (corner 0), 1: u >= 1/2, v < 1/2, 2: both >= 1/2, 3: u < 1/2, v >= 1/2.

    Examples
    --------
    >>> quarter(np.array([0.25, 0.75, 0.75, 0.25, 0.5]), np.array([0.25, 0.25, 0.75, 0.75, 0.5])).tolist()
    [0, 1, 2, 3, 2]
    """
    cu = u >= 0.5
    cv = v >= 0.5
    return np.where(cv, np.where(cu, 2, 3), np.where(cu, 1, 0)).astype(np.int64)


def to_local(q, u, v):
    """T_q^-1: face parameter (u, v) -> local (s, t) of corner q (exact in floating point).

    Parameters
    ----------
    q : ndarray, shape (n,) int64
        Corner index (:func:`quarter`).
    u, v : ndarray, shape (n,) float64

    Returns
    -------
    s, t : ndarray, shape (n,) float64

    Examples
    --------
    >>> to_local(np.array([1]), np.array([0.75]), np.array([0.25]))
    (array([0.25]), array([0.25]))
    """
    s = np.where(q == 0, u, np.where(q == 1, v, np.where(q == 2, 1.0 - u, 1.0 - v)))
    t = np.where(q == 0, v, np.where(q == 1, 1.0 - u, np.where(q == 2, 1.0 - v, u)))
    return s, t


def from_local(q, s, t):
    """T_q: local (s, t) of corner q -> face parameter (u, v).

    Parameters
    ----------
    q : ndarray, shape (n,) int64
        Corner index (:func:`quarter`).
    s, t : ndarray, shape (n,) float64

    Returns
    -------
    u, v : ndarray, shape (n,) float64

    Examples
    --------
    >>> from_local(np.array([3]), np.array([0.25]), np.array([0.125]))
    (array([0.125]), array([0.75]))
    >>> u, v = from_local(np.array([2]), *to_local(np.array([2]), np.array([0.9]), np.array([0.7])))
    >>> np.round([u[0], v[0]], 15).tolist()
    [0.9, 0.7]
    """
    u = np.where(q == 0, s, np.where(q == 1, 1.0 - t, np.where(q == 2, 1.0 - s, t)))
    v = np.where(q == 0, t, np.where(q == 1, s, np.where(q == 2, 1.0 - t, 1.0 - s)))
    return u, v


def _alpha_for(alpha, k):
    if alpha is None:
        return default_alpha(k)
    if isinstance(alpha, dict):
        return float(alpha[k]) if k in alpha else default_alpha(k)
    return float(alpha)


def quarter_map(k, s, t, parameterization, alpha=None, derivatives=1):
    """G(t) = w(t) F(t) + (1 - w(t)) t on the quarter of a corner of valence k (local coordinates).

    Parameters
    ----------
    k : int
        Valence of the corner (!= 4, interior).
    s, t : ndarray, shape (n,)
        Local coordinates in [0, 1/2]^2.
    parameterization : {"vanishing", "characteristic"}
    alpha : float or dict or None
        Exponent of F^alpha ("vanishing" only); None: :func:`~ccproof.reparam.quadrant.default_alpha`.
    derivatives : int, 0, 1 or 2

    Returns
    -------
    G : ndarray, shape (n, 2)
    DG : ndarray, shape (n, 2, 2)
        ``DG[:, a, i] = dG_a / dt_i`` (with ``derivatives >= 1``).
    D2G : ndarray, shape (n, 2, 2, 2)
        With 2.

    Notes
    -----
    bmz04 eq. 4 (docs/readings.md R5, R6): the weight w vanishes at distance >= 1/2 from the corner
    (the radial weight of "vanishing"), where G is the identity.

    Examples
    --------
    >>> G, DG = quarter_map(5, np.array([0.0, 0.4]), np.array([0.0, 0.45]), "vanishing")
    >>> G.tolist(), DG[1].tolist()
    ([[0.0, 0.0], [0.4, 0.45]], [[1.0, 0.0], [0.0, 1.0]])
    """
    if parameterization == "characteristic":
        Fo = inverse_characteristic_map_derivatives(k, s, t, derivatives)
        W = weight_tensor(s, t, derivatives)
    elif parameterization == "vanishing":
        Fo = vanishing_map(s, t, _alpha_for(alpha, k), derivatives)
        W = weight_radial(s, t, derivatives)
    else:
        raise CCProofError(f"unknown parameterization {parameterization!r}; use one of {', '.join(PARAMETERIZATIONS)}")
    w = W[0]
    w1 = weight_complement(s, t, parameterization == "vanishing")  # 1 - w, relatively exact near 0
    F = Fo[0]
    d0, d1 = F[:, 0] - s, F[:, 1] - t
    G = np.empty_like(F)
    G[:, 0] = w * F[:, 0] + w1 * s  # (not s + w (F - s): F << s near the corner for k >= 5)
    G[:, 1] = w * F[:, 1] + w1 * t
    out = [G]
    if derivatives >= 1:
        JF = Fo[1]
        eye = np.eye(2)
        DG = np.empty_like(JF)  # w DF + (1 - w) I + (F - t) grad(w)^T
        DG[:, 0, 0] = w * JF[:, 0, 0] + w1 + d0 * W[1]
        DG[:, 0, 1] = w * JF[:, 0, 1] + d0 * W[2]
        DG[:, 1, 0] = w * JF[:, 1, 0] + d1 * W[1]
        DG[:, 1, 1] = w * JF[:, 1, 1] + w1 + d1 * W[2]
        out.append(DG)
    if derivatives >= 2:
        w = w[:, None]
        d = np.stack([d0, d1], axis=1)
        gw = np.stack(W[1:3], axis=1)  # (n, 2)
        HF = Fo[2]
        hw = np.empty((s.shape[0], 2, 2))
        hw[:, 0, 0], hw[:, 0, 1], hw[:, 1, 1] = W[3], W[4], W[5]
        hw[:, 1, 0] = W[4]
        JmI = JF - eye
        D2G = (w[:, :, None, None] * HF + gw[:, None, :, None] * JmI[:, :, None, :]
               + gw[:, None, None, :] * JmI[:, :, :, None] + d[:, :, None, None] * hw[:, None, :, :])
        out.append(D2G)
    return tuple(out)


def active_points(corner_valence, f, u, v, parameterization):
    """The points of a batch where a blending weight is positive, and their corner data.

    Parameters
    ----------
    corner_valence : ndarray of int, shape (m, 4)
        Per face: the valence of each corner, 0 (or 4) for an identity corner.
    f : ndarray of int, shape (n,)
        Face of each point (row of ``corner_valence``).
    u, v : ndarray, shape (n,)
    parameterization : {"natural", "vanishing", "characteristic"}

    Returns
    -------
    idx : ndarray of int, shape (a,)
        Indices of the active points.
    q : ndarray of int, shape (a,)
        Their quarter (corner index).
    s, t : ndarray, shape (a,)
        Their local coordinates in the corner frame.
    k : ndarray of int, shape (a,)
        The corner's valence.

    Examples
    --------
    One face whose corner 0 has valence 3: the points near corner 0 are active, the one near the
    identity corner 2 is not:

    >>> idx, q, s, t, k = active_points(np.array([[3, 0, 0, 0]]), np.array([0, 0, 0]), np.array([0.1, 0.9, 0.3]),
    ...                                 np.array([0.1, 0.9, 0.4]), "characteristic")
    >>> idx.tolist(), q.tolist(), s.tolist(), t.tolist(), k.tolist()
    ([0, 2], [0, 0], [0.1, 0.3], [0.1, 0.4], [3, 3])
    """
    if parameterization not in PARAMETERIZATIONS:
        raise CCProofError(f"unknown parameterization {parameterization!r}; use one of {', '.join(PARAMETERIZATIONS)}")
    empty = np.zeros(0, dtype=np.int64)
    if parameterization == "natural":
        return empty, empty, np.zeros(0), np.zeros(0), empty
    cv = np.asarray(corner_valence, dtype=np.int64)
    cv = np.where(cv == 4, 0, cv)[:, [0, 1, 3, 2]]  # column = (u >= 1/2) + 2 (v >= 1/2)
    bits = (u >= 0.5).view(np.int8) + 2 * (v >= 0.5).view(np.int8)
    kk = cv.ravel()[4 * f + bits]
    idx = np.flatnonzero(kk)
    q = np.array([0, 1, 3, 2], dtype=np.int64)[bits[idx]]
    s, t = to_local(q, u[idx], v[idx])
    ok = (s < 0.5) & (t < 0.5) if parameterization == "characteristic" else (s * s + t * t < 0.25)
    return idx[ok], q[ok], s[ok], t[ok], kk[idx][ok]


def blend_points(q, s, t, k, parameterization, alpha=None, derivatives=1):
    """F_b at active points (output of :func:`active_points`), grouped by valence.

    The blended reparameterization of bmz04 eq. 4 (docs/readings.md R6), :func:`quarter_map` of
    each corner mapped back to the face frame.

    Parameters
    ----------
    q, s, t, k : ndarray, shape (a,)
        Quarter, local coordinates and valence of the active points (:func:`active_points`).
    parameterization : {"vanishing", "characteristic"}
    alpha : float or dict or None, optional
        Exponent of F^alpha ("vanishing" only).
    derivatives : int, optional
        0, 1 or 2.

    Returns
    -------
    dict
        ``local`` (a, 2): F_b in the corner frame; ``u``, ``v`` (a,): F_b as a face parameter;
        ``J_local``, ``H_local``: derivatives in the corner frame; ``J``, ``H``: in the face frame;
        ``corner`` (a,) bool: the points at the corner itself.

    Examples
    --------
    The corner is fixed; in the frame of corner 0 (the identity) local and face coordinates agree:

    >>> q, s, t, k = np.array([0, 0]), np.array([0.0, 0.3]), np.array([0.0, 0.2]), np.array([3, 3])
    >>> b = blend_points(q, s, t, k, "vanishing")
    >>> b["corner"].tolist(), b["local"][0].tolist(), bool(np.all(b["local"][:, 0] == b["u"]))
    ([True, False], [0.0, 0.0], True)
    """
    a = q.shape[0]
    out = {"local": np.empty((a, 2)), "corner": (s == 0) & (t == 0)}
    if derivatives >= 1:
        out["J_local"] = np.empty((a, 2, 2))
    if derivatives >= 2:
        out["H_local"] = np.empty((a, 2, 2, 2))
    for kv in np.unique(k):
        sel = np.flatnonzero(k == kv)
        res = quarter_map(int(kv), s[sel], t[sel], parameterization, alpha, derivatives)
        out["local"][sel] = res[0]
        if derivatives >= 1:
            out["J_local"][sel] = res[1]
        if derivatives >= 2:
            out["H_local"][sel] = res[2]
    G = out["local"]
    out["u"], out["v"] = from_local(q, np.clip(G[:, 0], 0.0, 1.0), np.clip(G[:, 1], 0.0, 1.0))
    if derivatives >= 1:
        # J_face = A J A^T (t_local = A^T (t - c_i)); A = +-I for even q, +-[[0, -1], [1, 0]] for odd q
        Jl = out["J_local"]
        odd = (q & 1).astype(bool)
        J = Jl.copy()
        J[odd, 0, 0], J[odd, 1, 1] = Jl[odd, 1, 1], Jl[odd, 0, 0]
        J[odd, 0, 1], J[odd, 1, 0] = -Jl[odd, 1, 0], -Jl[odd, 0, 1]
        out["J"] = J
    if derivatives >= 2:
        A = CORNER_FRAMES[q]
        At = A.transpose(0, 2, 1)
        H = np.einsum("nab,nbcd->nacd", A, out["H_local"], optimize=False)
        out["H"] = A[:, None] @ H @ At[:, None]
    return out


def face_map(corner_valence, u, v, parameterization, alpha=None, derivatives=1):
    """F_b of bmz04 eq. (4) at points (u, v) of faces with the given corner valences.

    Parameters
    ----------
    corner_valence : array_like of int, shape (4,) or (n, 4)
        Valence of corner i of the face of each point; 0 (or 4) for an identity corner (valence
        4 or a boundary vertex).
    u, v : ndarray, shape (n,)
        Face parameters in [0, 1].
    parameterization : {"natural", "vanishing", "characteristic"}
    alpha : float or dict or None
        See :func:`quarter_map`.
    derivatives : int, 0, 1 or 2

    Returns
    -------
    dict
        ``u``, ``v``: F_b(u, v), shape (n,); ``J`` (n, 2, 2) with ``J[:, a, i] = dF_b,a / dt_i`` and
        ``H`` (n, 2, 2, 2) with ``derivatives`` >= 1, 2; ``active`` (n,) bool: points where a
        weight is positive (elsewhere F_b is the identity); ``quarter`` (n,), ``local`` (n, 2)
        the local coordinates of F_b(u, v) in the quarter's corner frame (full relative precision
        near the corner, unlike ``u``, ``v`` near a corner at 1), ``J_local``, ``H_local`` the
        derivatives in that frame, ``corner`` (n,) bool: the points exactly at a non-identity
        corner (where J is not defined: see
        :meth:`ccproof.reparam.surface.Parameterization.evaluate_on`).

    Examples
    --------
    >>> r = face_map([5, 4, 4, 4], np.array([0.0, 0.5, 0.2]), np.array([0.0, 0.0, 0.6]), "characteristic")
    >>> r["u"].tolist(), r["v"].tolist()          # corner, side and the quarter of a regular corner: fixed
    ([0.0, 0.5, 0.2], [0.0, 0.0, 0.6])
    """
    u = np.asarray(u, dtype=np.float64).reshape(-1)
    v = np.asarray(v, dtype=np.float64).reshape(-1)
    n = u.shape[0]
    cv = np.asarray(corner_valence, dtype=np.int64)
    if cv.ndim == 1:
        cv = cv[None, :]
        f = np.zeros(n, dtype=np.int64)
    else:
        f = np.arange(n)
    idx, qa, s, t, k = active_points(cv, f, u, v, parameterization)
    q = quarter(u, v)
    out = {"u": u.copy(), "v": v.copy(), "active": np.zeros(n, dtype=bool), "quarter": q,
           "local": np.stack(to_local(q, u, v), axis=1), "corner": np.zeros(n, dtype=bool)}
    out["active"][idx] = True
    eye = np.broadcast_to(np.eye(2), (n, 2, 2))
    if derivatives >= 1:
        out["J"], out["J_local"] = eye.copy(), eye.copy()
    if derivatives >= 2:
        out["H"], out["H_local"] = np.zeros((n, 2, 2, 2)), np.zeros((n, 2, 2, 2))
    if idx.size == 0:
        return out
    res = blend_points(qa, s, t, k, parameterization, alpha, derivatives)
    for key in ("u", "v", "local", "corner", "J", "H", "J_local", "H_local"):
        if key in res:
            out[key][idx] = res[key]
    return out
