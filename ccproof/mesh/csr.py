"""Sparse operators as plain CSR arrays ``(indptr, indices, data)`` (the steps of :mod:`ccproof.mesh.step`):
:func:`apply_csr` computes ``S @ X`` with scipy's summation order and without scipy, :class:`PackedCSR`
(:func:`pack_csr`) holds them compactly (32-bit indices, weights coded into their few distinct values).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

__all__ = ["apply_csr", "PackedCSR", "pack_csr", "csr_matrix_with_empty_rows"]


def apply_csr(csr, X, out=None):
    """``S @ X`` for ``S`` given as CSR arrays (:attr:`ccproof.mesh.step.Step.csr`), summed as scipy's sparse
    product does.

    Each row is summed over its stored entries in order (increasing columns), from 0: the bits of
    ``S @ X``, without scipy; only the stored entries' rows of ``X`` are read (an unused vertex may
    hold NaN).

    Parameters
    ----------
    csr : (indptr (N + 1,), indices (nnz,), data (nnz,))
    X : ndarray, shape (n_columns, d)
    out : ndarray, shape (N, d), optional
        Written into (zeroed first).

    Returns
    -------
    ndarray of float64, shape (N, d)
    """
    indptr, indices, data = csr
    X = np.asarray(X, dtype=np.float64)
    N = indptr.size - 1
    size = np.diff(indptr)
    if out is None:
        out = np.zeros((N, X.shape[1]))
    else:
        out[...] = 0.0
    rows = np.flatnonzero(size > 0)
    for k in range(int(size.max()) if N else 0):
        rows = rows[size[rows] > k]
        j = indptr[rows] + k
        out[rows] += data[j, None] * X[indices[j]]
    return out


class PackedCSR(NamedTuple):
    """CSR arrays (:attr:`ccproof.mesh.step.Step.csr`) held compactly: 32-bit indices where they fit, and each stored
    weight as a code into the table of the distinct weights (a step has few: they depend on valences
    and tags). :func:`pack_csr` builds it; :meth:`apply` computes :func:`apply_csr` of the unpacked arrays.

    Attributes
    ----------
    indptr : ndarray of int32 or int64, shape (N + 1,)
    indices : ndarray of int32 or int64, shape (nnz,)
    codes : ndarray of uint8, uint16 or uint32, shape (nnz,)
    weights : ndarray of float64, shape (k,)
        ``data == weights[codes]`` bit for bit.
    """

    indptr: np.ndarray
    indices: np.ndarray
    codes: np.ndarray
    weights: np.ndarray

    @property
    def nbytes(self):
        """Bytes held by the four arrays."""
        return sum(a.nbytes for a in self)

    @property
    def csr(self):
        """The CSR arrays ``(indptr, indices, data)`` (data float64, the packed bits)."""
        return self.indptr, self.indices, self.weights[self.codes]

    def apply(self, X):
        """``S @ X``, bit for bit as :func:`apply_csr` computes it, in scipy's sparse product.

        Each row summed over its stored entries in order, from 0 (what :func:`apply_csr` reproduces
        without scipy; tested equal); the scipy matrix wraps the unpacked arrays for this product only.

        Parameters
        ----------
        X : ndarray, shape (n_columns, d)

        Returns
        -------
        ndarray of float64, shape (N, d)
        """
        import scipy.sparse as sp

        X = np.asarray(X, dtype=np.float64)
        S = sp.csr_matrix((self.weights[self.codes], self.indices, self.indptr),
                          shape=(self.indptr.size - 1, X.shape[0]))
        return np.asarray(S @ X)


def pack_csr(csr):
    """The CSR arrays ``csr = (indptr, indices, data)`` as a :class:`PackedCSR`.

    The weights are told apart by their bits (``-0.0`` and ``0.0``, or two NaNs, stay distinct), so that
    unpacking restores ``data`` exactly.

    Parameters
    ----------
    csr : (indptr (N + 1,), indices (nnz,), data (nnz,))

    Returns
    -------
    PackedCSR

    Examples
    --------
    >>> from ccproof.mesh.step import StepOptions, catmark_operator
    >>> st = catmark_operator(4, [0, 1, 2, 3], [4], options=StepOptions(sparse=False))
    >>> p = pack_csr(st.csr)
    >>> p.weights.tolist(), p.codes.dtype.name, p.indices.dtype.name, p.nbytes < sum(a.nbytes for a in st.csr)
    ([0.125, 0.25, 0.5, 0.75], 'uint8', 'int32', True)
    >>> X = np.arange(12.0).reshape(4, 3)
    >>> np.array_equal(p.apply(X), apply_csr(st.csr, X))
    True
    """
    indptr, indices, data = csr
    bits, codes = np.unique(np.asarray(data, dtype=np.float64).view(np.int64), return_inverse=True)
    k = bits.size
    ctype = np.uint8 if k <= 2**8 else np.uint16 if k <= 2**16 else np.uint32
    small = max(int(indptr[-1]) if len(indptr) else 0, int(indices.max()) + 1 if len(indices) else 0) < 2**31
    itype = np.int32 if small else np.int64
    return PackedCSR(np.asarray(indptr, dtype=itype), np.asarray(indices, dtype=itype),
                     codes.reshape(-1).astype(ctype), bits.view(np.float64))


def csr_matrix_with_empty_rows(csr, unused, ncols):
    """The scipy CSR matrix of the CSR arrays ``csr`` with NaN at column 0 of the (empty) rows ``unused``
    (an unused vertex has no vertex point)."""
    import scipy.sparse as sp

    indptr, indices, data = csr
    N = indptr.size - 1
    if unused.size:  # empty rows: the NaN entries go after the entries of the rows before them
        rows = np.r_[np.repeat(np.arange(N), np.diff(indptr)), unused]
        o = np.argsort(rows, kind="stable")
        indices = np.r_[indices, np.zeros(unused.size, dtype=np.int64)][o]
        data = np.r_[data, np.full(unused.size, np.nan)][o]
        indptr = np.r_[0, np.cumsum(np.bincount(rows, minlength=N))]
    return sp.csr_matrix((data, indices, indptr), shape=(N, ncols))
