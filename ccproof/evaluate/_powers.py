"""Exact powers of a sparse subdivision matrix at a cost that follows its symmetry, not its size.

The corner scheme of a face whose irregular corner has valence n (the centre of an n-gon after one step
has valence n) needs the rounded deviations ``D_t = M A^t - 1 l^T`` for about a hundred layers t, with
``A`` the (2n + 8) x (2n + 8) matrix of one step of the face's one-ring and ``M`` the 48 stencils of the
nets of the three regular children. Dense exact products cost 48 (2n + 8)^2 big-integer operations per
layer (26 minutes at n = 1000). Here the same exact integers are computed on *classes of equal columns*:

* columns of ``M A^t`` that are equal are computed once. Two columns ``j, j'`` of ``R A`` are equal when
  their *signatures* are: the sums ``sum_{i in C} A[i, j]`` over the classes ``C`` of equal columns of
  ``R`` (sorted, zero sums left out). Far from the face, the spokes of a valence-n vertex are all
  alike: after t steps only about 4 t + 40 classes exist (the rest of the n spokes share one class each),
  so a layer costs O(n) small-integer work for the signatures and O(t) big-integer column operations.
* the limit mask ``l`` (the left eigenvector of ``A`` for 1, summing to 1) is computed on the quotient of
  an *equitable partition* of the rows that the corner vertex depends on (colour refinement: classes
  whose column sums per class agree); for the n-gon centre that is three classes (the centre, the edge
  points, the face points), so the exact solve is 3 x 3 instead of (2n + 1) x (2n + 1).

Both are exact: the integers are those of the dense products, and the rounding (one correctly rounded
quotient per entry) is the same, so the layers are bit for bit those of the dense computation.
"""

from __future__ import annotations

import bisect
import math

import numpy as np

from ccproof.errors import MeshError

__all__ = ["integer_rows", "closure", "limit_mask", "class_layers"]


def _num_den(w):
    """Numerator and denominator (Python ints) of an int or a ``flint.fmpq``."""
    if isinstance(w, int):
        return w, 1
    return int(w.p), int(w.q)


def integer_rows(rows):
    """``(rows_int, d)``: exact stencils (dict column -> int or fmpq) over one common denominator ``d``.

    >>> import flint
    >>> integer_rows([{0: flint.fmpq(1, 2), 3: flint.fmpq(1, 3)}, {1: 1}])
    ([{0: 3, 3: 2}, {1: 6}], 6)
    """
    d = 1
    for s in rows:
        for w in s.values():
            d = math.lcm(d, _num_den(w)[1])
    out = []
    for s in rows:
        r = {}
        for j, w in s.items():
            p, q = _num_den(w)
            r[j] = p * (d // q)
        out.append(r)
    return out, d


def closure(rows, start):
    """The rows reachable from ``start`` through the supports of ``rows`` (sorted)."""
    seen = set(start)
    todo = list(start)
    while todo:
        for j in rows[todo.pop()]:
            if j not in seen:
                seen.add(j)
                todo.append(j)
    return sorted(seen)


def _equitable_classes(rows, T, max_rounds):
    """Colour refinement of the rows ``T`` (closed under ``rows``) for the left action, or None.

    Returns the class of every member of ``T`` (dict) such that for every class ``C`` the column sums
    ``sum_{i in C} A[i, j]`` agree on each class of ``j``; None if not stable within ``max_rounds``.
    """
    cols = {j: [] for j in T}
    for i in T:
        for j, w in rows[i].items():
            cols[j].append((i, w))
    cls = dict.fromkeys(T, 0)
    count = 1
    for _ in range(max_rounds):
        sig = {}
        for j in T:
            acc = {}
            for i, w in cols[j]:
                acc[cls[i]] = acc.get(cls[i], 0) + w
            key = (cls[j], tuple(sorted((c, w) for c, w in acc.items() if w != 0)))
            sig[j] = key
        ids = {}
        new = {j: ids.setdefault(sig[j], len(ids)) for j in T}
        if len(ids) == count:
            return new
        cls, count = new, len(ids)
    return None


def limit_mask(rows, N, corner=0, max_rounds=12):
    """The exact limit mask of ring vertex ``corner``: ``l A = l``, ``sum l = 1`` (``A``: the rows).

    Parameters
    ----------
    rows : list of dict
        Exact stencils (column -> int or ``flint.fmpq``), row i the new point i: the matrix ``A``.
    N : int
        Number of columns.
    corner : int
        The vertex whose limit is meant; the mask is supported on the rows it depends on.
    max_rounds : int
        Rounds of colour refinement before giving up (None is returned: use a dense solve).

    Returns
    -------
    list of flint.fmpq or None

    Examples
    --------
    The centre of a valence-5 star (Catmull-Clark, one step): the mask is ``(k^2, 4, ..., 1, ...)``
    over ``k (k + 5)``, here 25/50, 4/50, 1/50:

    >>> from ccproof.mesh.examples import k_regular_disk
    >>> from ccproof.evaluate.local import quad_ring, refine_key
    >>> from ccproof.evaluate.local import canonical_ring, ring_key
    >>> key = quad_ring(k_regular_disk(5, 3).faces, 0, 0)[1]
    >>> _, st, child = refine_key(key, 4)
    >>> ring1, faces1, nr = canonical_ring(child, 0, 0, 1)
    >>> l = limit_mask([st[v] for v in ring1], len(ring1))
    >>> [str(x) for x in l[:3]], str(sum(l))
    (['1/2', '2/25', '1/50'], '1')
    """
    import flint  # exact data are built here: imported only when computed

    T = closure(rows, [corner])
    cls = _equitable_classes(rows, T, max_rounds)
    if cls is None:
        return None
    k = max(cls.values()) + 1
    size = [0] * k
    rep = [None] * k
    for j in T:
        size[cls[j]] += 1
        rep[cls[j]] = j
    # the quotient B[C, C'] = sum_{i in C} A[i, j], any j in C'; y (B - I) = 0, sum_C |C| y_C = 1
    Bt = flint.fmpq_mat(k, k)
    for i in T:
        for j, w in rows[i].items():
            if rep[cls[j]] == j:
                Bt[cls[j], cls[i]] += w
    for c in range(k):
        Bt[c, c] -= 1
    for c in range(k):
        Bt[k - 1, c] = size[c]
    rhs = flint.fmpq_mat(k, 1, [0] * (k - 1) + [1])
    try:
        y = Bt.solve(rhs)
    except ZeroDivisionError:
        raise MeshError("corner configuration whose subdivision matrix has a multiple eigenvalue 1") from None
    out = [flint.fmpq(0)] * N
    for j in T:
        out[j] = y[cls[j], 0]
    return out


def _column_classes(rows_int, N):
    """Classes of equal columns of the integer rows: ``(cls (N,), values (n_rows, K) object)``."""
    ids, vals = {}, []
    cls = np.empty(N, dtype=np.int64)
    for j in range(N):
        col = tuple(r.get(j, 0) for r in rows_int)
        k = ids.get(col)
        if k is None:
            k = ids[col] = len(vals)
            vals.append(col)
        cls[j] = k
    V = np.empty((len(rows_int), len(vals)), dtype=object)
    for k, col in enumerate(vals):
        V[:, k] = col
    return cls, V


class _Coo:
    """The integer matrix ``A`` as coordinates (row, column, weight), weights int64 where they fit."""

    def __init__(self, rows_int):
        r, c, w = [], [], []
        for i, s in enumerate(rows_int):
            for j, x in s.items():
                r.append(i)
                c.append(j)
                w.append(x)
        self.r = np.array(r, dtype=np.int64)
        self.c = np.array(c, dtype=np.int64)
        big = max((abs(x) for x in w), default=0) * max(len(w), 1) >= 2**62
        self.w = np.array(w, dtype=object if big else np.int64)


def _signatures(coo, cls, K, N):
    """Per column j of ``R A`` (R with column classes ``cls``, K of them): the sorted (class, summed weight)
    pairs, zero sums left out."""
    key = coo.c * K + cls[coo.r]
    order = np.argsort(key, kind="stable")
    ks = key[order]
    starts = np.flatnonzero(np.r_[True, ks[1:] != ks[:-1]])
    sums = np.add.reduceat(coo.w[order], starts)
    uk = ks[starts]
    keep = sums != 0
    uk, sums = uk[keep], sums[keep]
    col, old = uk // K, uk % K
    bounds = np.searchsorted(col, np.arange(N + 1))
    pairs = list(zip(old.tolist(), sums.tolist()))
    return [tuple(pairs[bounds[j]:bounds[j + 1]]) for j in range(N)]


def _step(coo, cls, V, N):
    """Column classes and values of ``R A`` from those of ``R`` (exact integers)."""
    sigs = _signatures(coo, cls, V.shape[1], N)
    ids = {}
    new_cls = np.fromiter((ids.setdefault(s, len(ids)) for s in sigs), dtype=np.int64, count=N)
    order = list(ids)  # signatures by class id
    W = np.zeros((V.shape[0], len(order)), dtype=object)
    by_len = sorted(range(len(order)), key=lambda k: -len(order[k]))
    neg = [-len(order[k]) for k in by_len]  # ascending
    for p in range(-neg[0] if neg else 0):  # slot p of every signature at once (longest first)
        ks = by_len[:bisect.bisect_left(neg, -p)]
        src = [order[k][p][0] for k in ks]
        w = np.array([order[k][p][1] for k in ks], dtype=object)
        W[:, ks] += V[:, src] * w
    return new_cls, W


def class_layers(nets, rows, lmask, N, tolerance, max_layers):
    """Rounded deviations ``M A^n - 1 l^T`` for n = 0, 1, ... until below ``tolerance`` (exact, on classes).

    Parameters
    ----------
    nets : list of dict
        The 48 exact stencils of ``M`` (column -> int or ``flint.fmpq``).
    rows : list of dict
        The exact rows of ``A`` (N of them).
    lmask : list of flint.fmpq
        The exact limit mask ``l`` (:func:`limit_mask`).
    N : int
    tolerance : float
        Stop at the first layer whose largest deviation is below it.
    max_layers : int

    Returns
    -------
    ndarray, shape (n_layers, 48, N), or None if ``max_layers`` layers do not reach the tolerance

    Notes
    -----
    With ``A = Ai / a``, ``M = Mi / m`` and ``l = li / c`` the n-th deviation is
    ``(c Mi Ai^n - m a^n 1 li^T) / (c m a^n)``, each entry one correctly rounded quotient of integers:
    the numbers of the dense computation. Equal rows of ``M`` are computed once.

    Examples
    --------
    Point 1 moves halfway to point 0 at each step (limit mask ``l = (1, 0)``):

    >>> import flint
    >>> half = flint.fmpq(1, 2)
    >>> D = class_layers([{1: 1}] * 48, [{0: 1}, {0: half, 1: half}], [1, 0], 2, 2.0**-60, 400)
    >>> D.shape, D[3, 0].tolist()
    ((62, 48, 2), [-0.125, 0.125])
    """
    ukeys, row_of = {}, []
    for s in nets:
        row_of.append(ukeys.setdefault(tuple(sorted(s.items())), len(ukeys)))
    Mi, m = integer_rows([dict(k) for k in ukeys])
    Ai, a = integer_rows(rows)
    (li,), c = integer_rows([{j: w for j, w in enumerate(lmask) if w != 0}])
    lid, lvals = _value_classes([li.get(j, 0) for j in range(N)])
    coo = _Coo(Ai)
    cls, V = _column_classes(Mi, N)
    row_of = np.array(row_of)
    den = m
    layers = []
    for _ in range(max_layers):
        D = _rounded(V, cls, lid, lvals, c, den)[row_of]
        layers.append(D)
        if np.abs(D).max() < tolerance:
            return np.array(layers)
        cls, V = _step(coo, cls, V, N)
        den *= a
    return None


def _value_classes(values):
    """``(ids (N,), distinct values)`` of a list of Python ints."""
    seen = {}
    ids = np.fromiter((seen.setdefault(v, len(seen)) for v in values), dtype=np.int64, count=len(values))
    return ids, list(seen)


def _rounded(V, cls, lid, lvals, c, den):
    """The float matrix ``(c R - den 1 li^T) / (c den)`` of R's column classes, one quotient per entry."""
    pair = cls * len(lvals) + lid
    upair, inv = np.unique(pair, return_inverse=True)
    uc, ul = upair // len(lvals), upair % len(lvals)
    L = np.array([lvals[i] * den for i in ul.tolist()], dtype=object)
    num = V[:, uc] * c - L
    q = c * den
    F = np.array([[p / q for p in row] for row in num.tolist()], dtype=np.float64).reshape(num.shape)
    return F[:, inv.reshape(-1)]
