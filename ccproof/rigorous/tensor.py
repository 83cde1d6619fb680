"""Dense coefficient tensors: a row-major list of ``fmpq`` (``prec`` None) or ``arb`` (``prec`` bits, computed inside
``flint.ctx.workprec``) with its ``shape``; exact basis changes along an axis (``fmpq_mat``, or the ``arb_mat`` that
encloses it), Kronecker products. Shared by :mod:`.bernstein` and ``ccproof.certify.poly``."""

from functools import lru_cache
from math import prod

import flint
from flint import arb, arb_mat, arb_poly, fmpq, fmpq_mat, fmpq_poly, fmpz

MAX_VARS = 4


def check_prec(prec):
    """``prec`` if None or an int >= 2 (bits), else ``ValueError``."""
    if prec is not None and (isinstance(prec, bool) or not isinstance(prec, int) or prec < 2):
        raise ValueError(f"precision must be an int >= 2 (bits) or None, got {prec!r}")
    return prec


def join_prec(p, q):
    """Precision of a result combining kinds ``p`` and ``q`` (``None`` = exact)."""
    return q if p is None else p if q is None else max(p, q)


def exact_scalar(x):
    """int, fmpz, fmpq or a string ``"p/q"`` as an ``fmpq``; floats and the rest refused."""
    if isinstance(x, fmpq):
        return x
    if isinstance(x, (int, fmpz)) and not isinstance(x, bool):
        return fmpq(x)
    if not isinstance(x, str):
        raise TypeError(f"expected an exact number (int, fmpz, fmpq or 'p/q' string), got {type(x).__name__}")
    try:
        return fmpq(x)
    except (ValueError, TypeError):
        raise ValueError(f"not a rational number: {x!r}") from None


def scalar(x):
    """An ``arb`` kept, anything else through :func:`exact_scalar`."""
    return x if isinstance(x, arb) else exact_scalar(x)


def to_kind(x, prec):
    """``x`` (fmpq or arb) as an element of the kind ``prec`` (caller holds the workprec)."""
    if prec is not None:
        return x if isinstance(x, arb) else arb(x)
    if isinstance(x, arb):
        raise TypeError("cannot convert an arb ball to an exact fmpq coefficient")
    return x


def convert(coeffs, prec):
    """Coefficients converted to kind ``prec`` (exact fmpq -> arb balls at ``prec`` bits)."""
    with flint.ctx.workprec(prec or flint.ctx.prec):
        return [to_kind(c, prec) for c in coeffs]


def exact_fmpq(x):
    """The exact rational value of a zero-radius finite ``arb`` (e.g. an endpoint); else ``None``."""
    if not x.is_finite() or not x.is_exact():
        return None
    man, exp = x.man_exp()
    return fmpq(man) * fmpq(2) ** int(exp)


def zero(prec):
    return fmpq(0) if prec is None else arb(0)


size = prod  # the number of entries of a shape
_ARB_MATS = {}


def to_matrix(mat, prec):
    """The exact ``fmpq_mat`` ``mat`` for kind ``prec``: itself, or an enclosing ``arb_mat`` (cached on the identity
    of ``mat``, kept alive in the entry so that its id is not reused)."""
    if prec is None:
        return mat
    hit = _ARB_MATS.get((id(mat), prec))
    if hit is None or hit[0] is not mat:
        with flint.ctx.workprec(prec):
            hit = (mat, arb_mat(mat))
        if len(_ARB_MATS) > 4096:
            _ARB_MATS.clear()
        _ARB_MATS[id(mat), prec] = hit
    return hit[1]


def new_matrix(rows, cols, entries, prec):
    return fmpq_mat(rows, cols, entries) if prec is None else arb_mat(rows, cols, entries)


def apply_along_axis(coeffs, shape, axis, mat, prec):
    """``(coeffs, shape)`` of the tensor multiplied along ``axis`` by the exact m x shape[axis] matrix ``mat``."""
    n = shape[axis]
    m = mat.nrows()
    if mat.ncols() != n:
        raise ValueError(f"matrix with {mat.ncols()} columns applied to an axis of length {n}")
    pre = prod(shape[:axis])
    post = prod(shape[axis + 1 :])
    new_shape = shape[:axis] + (m,) + shape[axis + 1 :]
    with flint.ctx.workprec(prec or flint.ctx.prec):
        M = to_matrix(mat, prec)
        if pre == 1:  # leading axis: the tensor is an n x post matrix
            return (M * new_matrix(n, post, coeffs, prec)).entries(), new_shape
        if post == 1:  # trailing axis: a pre x n matrix, multiplied by M^T on the right
            return (new_matrix(pre, n, coeffs, prec) * M.transpose()).entries(), new_shape
        rest = pre * post
        # X[i, p*post + q] = c[(p*n + i)*post + q]
        x = [coeffs[(p * n + i) * post + q] for i in range(n) for p in range(pre) for q in range(post)]
        y = (M * new_matrix(n, rest, x, prec)).entries()
    out = [y[j * rest + p * post + q] for p in range(pre) for j in range(m) for q in range(post)]
    return out, new_shape


def multiply(a, a_shape, b, b_shape, prec):
    """Product of two polynomial tensors: one flint product of the univariate polynomials that send exponents e to
    sum e_i S_i (S the row-major strides of the product's shape, which no exponent of the product exceeds)."""
    shape = tuple(p + q - 1 for p, q in zip(a_shape, b_shape))
    pa, pb = pad(a, a_shape, shape, prec), pad(b, b_shape, shape, prec)
    if prec is None:
        c = (fmpq_poly(pa) * fmpq_poly(pb)).coeffs()
    else:
        with flint.ctx.workprec(prec):
            c = (arb_poly(pa) * arb_poly(pb)).coeffs()
    return list(c) + [zero(prec)] * (size(shape) - len(c)), shape


def row_major_strides(shape):
    """The row-major strides of a dense array of ``shape``."""
    return tuple(prod(shape[i + 1 :]) for i in range(len(shape)))


@lru_cache(maxsize=1024)
def embed_indices(shape, strides):
    """Positions of the row-major entries of ``shape`` under ``strides``."""
    idx = [0]
    for n, s in zip(shape, strides):
        idx = [i + k * s for i in idx for k in range(n)]
    return tuple(idx)


def weights(shape, per_axis):
    """Row-major tensor of ``prod_i per_axis[i][e_i]`` (exact)."""
    out = [fmpz(1)]
    for n, w in zip(shape, per_axis):
        out = [x * w[k] for x in out for k in range(n)]
    return out


def pad(coeffs, shape, new_shape, prec):
    """Zero-pad a tensor to a larger shape (same number of axes)."""
    out = [zero(prec)] * size(new_shape)
    for c, i in zip(coeffs, embed_indices(shape, row_major_strides(new_shape))):
        out[i] = c
    return out


def truncate(coeffs, shape, axis, degree, prec):
    """(coeffs, shape) of degree <= ``degree`` along ``axis``, each dropped coefficient c added as [-|c|, |c|] to the
    one of x_axis^0 with the same other exponents (a Taylor model's remainder for |x_axis| <= 1)."""
    n, post = shape[axis], size(shape[axis + 1 :])
    out = []
    with flint.ctx.workprec(prec):
        for base in range(0, len(coeffs), n * post):
            head = coeffs[base : base + post]
            for j in range(degree + 1, n):
                for q in range(post):
                    x = coeffs[base + j * post + q]
                    if not x.is_zero():  # exact zero only: a ball that merely contains 0 still counts
                        head[q] = head[q] + arb(0, abs(x).upper())
            out += head + coeffs[base + post : base + (degree + 1) * post]
    return out, shape[:axis] + (degree + 1,) + shape[axis + 1 :]
