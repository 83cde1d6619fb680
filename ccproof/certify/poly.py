"""Dense multivariate polynomials (1 to 4 variables) with exact ``fmpq`` or ball ``arb`` coefficients: the power
basis of the prover and of the tests' exact references, and their Bernstein and Taylor forms (not trusted: the
verifier never imports this module, an import-linter contract in pyproject.toml says so).

A :class:`Poly` is either *exact* (``prec is None``, every coefficient an ``fmpq``) or a *ball*
polynomial (``prec`` an int, every coefficient an ``arb``).  A ball polynomial stands for the set of
real polynomials whose coefficients lie in the balls; every operation returns balls that contain
the exact result for every such choice (flint's ``arb`` arithmetic is outward-rounded), computed at
``prec`` bits inside ``flint.ctx.workprec``.  Mixing exact and ball operands gives a ball result
at the ball operand's precision (the larger one when both are balls).  No Python float is ever
accepted.

>>> from flint import fmpq
>>> x, y = Poly.variable(0, 2), Poly.variable(1, 2)
>>> p = (x + 2 * y) ** 2 - 1
>>> p.degrees
(2, 2)
>>> p(fmpq(1, 2), 1)
21/4
>>> p.diff(1) == 4 * x + 8 * y
True
>>> p.affine(0, 1, 3)(0, 1) == p(1, 1)
True
"""

from math import comb

import flint
from flint import arb, fmpq

from ccproof.rigorous import tensor as T
from ccproof.rigorous.bernstein import BernsteinForm, check_box, unit_box
from ccproof.rigorous.matrices import conversion_matrix, power_to_bernstein_matrix, taylor_shift_matrix
from ccproof.rigorous.taylor import TaylorForm
from ccproof.rigorous.tensor import MAX_VARS


class Poly:
    """Polynomial ``sum c[e] x_0^e_0 ... x_{n-1}^e_{n-1}`` stored as a dense row-major tensor.

    ``Poly(terms, nvars=None, prec=None)``: ``terms`` maps exponent tuples to coefficients
    (int, fmpz, fmpq, ``"p/q"`` strings, or arb when ``prec`` is given).  With ``prec=None`` the
    polynomial is exact and arb coefficients are refused; with ``prec`` every coefficient is
    converted to an arb ball at ``prec`` bits.

    Parameters
    ----------
    terms : dict[tuple of int, number]
        Exponent tuple (length nvars, 1..4) -> coefficient.
    nvars : int, optional
        Default: the length of the exponent tuples.
    prec : int, optional
        Bits of the arb balls; None for exact coefficients.

    Notes
    -----
    The dense tensor has shape ``degrees + 1`` (row-major); docs/rigorous.md "API".

    Examples
    --------
    >>> Poly({(1, 0): 3, (0, 2): "1/2"})
    Poly(exact, degrees=(1, 2), {(0, 2): 1/2, (1, 0): 3})
    """

    __slots__ = ("shape", "coeffs", "prec")
    __hash__ = None

    def __init__(self, terms, nvars=None, prec=None):
        prec = T.check_prec(prec)
        terms = dict(terms)
        if nvars is None:
            if not terms:
                raise ValueError("nvars is required for a polynomial without terms")
            nvars = len(next(iter(terms)))
        _check_nvars(nvars)
        for e in terms:
            if len(e) != nvars or any(isinstance(k, bool) or not isinstance(k, int) or k < 0 for k in e):
                raise ValueError(f"exponent {e!r} is not a tuple of {nvars} non-negative ints")
        shape = tuple(max([e[i] for e in terms], default=0) + 1 for i in range(nvars))
        strides = T.row_major_strides(shape)
        coeffs = [T.zero(prec)] * T.size(shape)
        with flint.ctx.workprec(prec or flint.ctx.prec):
            for e, c in terms.items():
                c = T.scalar(c)
                if prec is None and isinstance(c, arb):
                    raise TypeError("arb coefficient in an exact polynomial: pass prec=... for balls")
                coeffs[sum(k * s for k, s in zip(e, strides))] = T.to_kind(c, prec)
        self.shape, self.coeffs, self.prec = shape, coeffs, prec

    # ------------------------------------------------------------------ construction

    @classmethod
    def from_raw(cls, shape, coeffs, prec):
        """From coefficients already of the form's kind and precision (no conversion, no checks)."""
        p = object.__new__(cls)
        p.shape, p.coeffs, p.prec = tuple(shape), coeffs, prec
        return p

    @classmethod
    def from_dense(cls, shape, coeffs, prec=None):
        """From a row-major flat list of ``prod(shape)`` coefficients (``shape[i]`` = degree + 1)."""
        shape = tuple(shape)
        _check_nvars(len(shape))
        if any(isinstance(n, bool) or not isinstance(n, int) or n < 1 for n in shape):
            raise ValueError(f"shape must be positive ints, got {shape!r}")
        coeffs = list(coeffs)
        if len(coeffs) != T.size(shape):
            raise ValueError(f"{len(coeffs)} coefficients for shape {shape}")
        prec = T.check_prec(prec)
        coeffs = [T.scalar(c) for c in coeffs]
        if prec is None and any(isinstance(c, arb) for c in coeffs):
            raise TypeError("arb coefficient in an exact polynomial: pass prec=... for balls")
        return cls.from_raw(shape, T.convert(coeffs, prec), prec)

    @classmethod
    def constant(cls, c, nvars, prec=None):
        """The constant ``c`` as a polynomial in ``nvars`` variables."""
        return cls({(0,) * nvars: c}, nvars, prec)

    @classmethod
    def variable(cls, i, nvars, prec=None):
        """The coordinate ``x_i`` in ``nvars`` variables."""
        if not 0 <= i < nvars:
            raise ValueError(f"variable index {i} out of range for {nvars} variables")
        return cls({tuple(int(k == i) for k in range(nvars)): 1}, nvars, prec)

    # ------------------------------------------------------------------ inspection

    @property
    def nvars(self):
        return len(self.shape)

    @property
    def degrees(self):
        """Degree bound per variable (the stored shape minus one)."""
        return tuple(n - 1 for n in self.shape)

    @property
    def is_exact(self):
        return self.prec is None

    def coefficient(self, exps):
        """Coefficient of ``x^exps`` (zero outside the stored shape)."""
        exps = tuple(exps)
        if len(exps) != self.nvars:
            raise ValueError(f"exponent {exps!r} for {self.nvars} variables")
        if any(k < 0 or k >= n for k, n in zip(exps, self.shape)):
            return T.zero(self.prec)
        strides = T.row_major_strides(self.shape)
        return self.coeffs[sum(k * s for k, s in zip(exps, strides))]

    def terms(self):
        """``{exponents: coefficient}`` for the coefficients that are not exactly zero."""
        return {e: c for e, c in zip(multi_indices(self.shape), self.coeffs) if not _is_exact_zero(c)}

    def __repr__(self):
        kind = "exact" if self.prec is None else f"arb {self.prec} bits"
        terms = ", ".join(f"{e}: {c}" for e, c in sorted(self.terms().items()))
        return f"Poly({kind}, degrees={self.degrees}, {{{terms}}})"

    # ------------------------------------------------------------------ kind conversion

    def to_arb(self, prec):
        """Ball version at ``prec`` bits (exact coefficients are enclosed; balls are kept)."""
        prec = T.check_prec(prec)
        if prec is None:
            raise ValueError("to_arb needs a precision in bits")
        return Poly.from_raw(self.shape, T.convert(self.coeffs, prec), prec)

    def midpoint(self):
        """Exact polynomial of the balls' midpoints (a representative, *not* an enclosure)."""
        if self.prec is None:
            return self
        return Poly.from_raw(self.shape, [T.exact_fmpq(c.mid()) for c in self.coeffs], None)

    def contains(self, other):
        """True when every coefficient ball contains the matching coefficient of ``other``."""
        if self.prec is None:
            raise TypeError("contains() is for ball polynomials; compare exact ones with ==")
        shape = tuple(max(p, q) for p, q in zip(self.shape, other.shape))
        a = T.pad(self.coeffs, self.shape, shape, self.prec)
        b = T.pad(other.coeffs, other.shape, shape, other.prec)
        return all(ball_contains(x, y) for x, y in zip(a, b))

    def __eq__(self, other):
        """Exact equality of exact polynomials (ball polynomials refuse ``==``)."""
        if isinstance(other, (int, fmpq, flint.fmpz)) and not isinstance(other, bool):
            other = Poly.constant(other, self.nvars)
        if not isinstance(other, Poly):
            return NotImplemented
        if self.prec is not None or other.prec is not None:
            raise TypeError("== is exact equality; use contains()/overlaps for ball polynomials")
        if self.nvars != other.nvars:
            return False
        return self.terms() == other.terms()

    # ------------------------------------------------------------------ arithmetic

    def _coerce(self, other):
        if isinstance(other, Poly):
            if other.nvars != self.nvars:
                raise ValueError(f"polynomials in {self.nvars} and {other.nvars} variables")
            return other
        c = T.scalar(other)
        if isinstance(c, arb) and self.prec is None:
            raise TypeError("arb scalar with an exact polynomial: convert it with .to_arb(prec) first")
        return Poly.constant(c, self.nvars, self.prec)

    def _binary_add(self, other, sign):
        other = self._coerce(other)
        prec = T.join_prec(self.prec, other.prec)
        shape = tuple(max(p, q) for p, q in zip(self.shape, other.shape))
        a = T.pad(T.convert(self.coeffs, prec), self.shape, shape, prec)
        b = T.pad(T.convert(other.coeffs, prec), other.shape, shape, prec)
        with flint.ctx.workprec(prec or flint.ctx.prec):
            c = [x + y for x, y in zip(a, b)] if sign > 0 else [x - y for x, y in zip(a, b)]
        return Poly.from_raw(shape, c, prec)

    def __add__(self, other):
        return self._binary_add(other, 1)

    __radd__ = __add__

    def __sub__(self, other):
        return self._binary_add(other, -1)

    def __rsub__(self, other):
        return self._coerce(other)._binary_add(self, -1)

    def __neg__(self):
        return Poly.from_raw(self.shape, [-c for c in self.coeffs], self.prec)

    def __pos__(self):
        return self

    def __mul__(self, other):
        if not isinstance(other, Poly):
            c = T.scalar(other)
            if isinstance(c, arb) and self.prec is None:
                raise TypeError(
                    "arb scalar with an exact polynomial: convert it with .to_arb(prec) first"
                )
            with flint.ctx.workprec(self.prec or flint.ctx.prec):
                return Poly.from_raw(self.shape, [x * c for x in self.coeffs], self.prec)
        other = self._coerce(other)
        prec = T.join_prec(self.prec, other.prec)
        c, shape = T.multiply(
            T.convert(self.coeffs, prec), self.shape, T.convert(other.coeffs, prec), other.shape, prec
        )
        return Poly.from_raw(shape, c, prec)

    __rmul__ = __mul__

    def __truediv__(self, c):
        """Division by a non-zero scalar."""
        c = T.scalar(c)
        if isinstance(c, arb):
            if self.prec is None:
                raise TypeError(
                    "arb scalar with an exact polynomial: convert it with .to_arb(prec) first"
                )
            with flint.ctx.workprec(self.prec):
                return Poly.from_raw(self.shape, [x / c for x in self.coeffs], self.prec)
        if c == 0:
            raise ZeroDivisionError("polynomial divided by zero")
        return self * (1 / c)

    def __pow__(self, n):
        if isinstance(n, bool) or not isinstance(n, int) or n < 0:
            raise ValueError(f"exponent must be a non-negative int, got {n!r}")
        result = Poly.constant(1, self.nvars, self.prec)
        base = self
        while n:
            if n & 1:
                result = result * base
            n >>= 1
            if n:
                base = base * base
        return result

    # ------------------------------------------------------------------ calculus and substitution

    def diff(self, axis):
        """Partial derivative with respect to ``x_axis``."""
        axis = self._axis(axis)
        n = self.shape[axis]
        if n == 1:
            return Poly.from_raw(self.shape, [T.zero(self.prec)] * T.size(self.shape), self.prec)
        pre = T.size(self.shape[:axis])
        post = T.size(self.shape[axis + 1 :])
        c = self.coeffs
        with flint.ctx.workprec(self.prec or flint.ctx.prec):
            out = [
                c[(p * n + i + 1) * post + q] * (i + 1)
                for p in range(pre)
                for i in range(n - 1)
                for q in range(post)
            ]
        shape = self.shape[:axis] + (n - 1,) + self.shape[axis + 1 :]
        return Poly.from_raw(shape, out, self.prec)

    def evaluate(self, point, prec=None):
        """Value at ``point`` (ints, fmpq, ``"p/q"`` strings or arb balls), by nested Horner.

        Exact polynomial at exact point: exact ``fmpq``.  Otherwise an ``arb`` enclosing the
        value for every choice in the balls, computed at ``prec`` bits (default: ``self.prec``).
        """
        point = [T.scalar(x) for x in point]
        if len(point) != self.nvars:
            raise ValueError(f"point with {len(point)} coordinates for {self.nvars} variables")
        prec = T.check_prec(prec) or self.prec
        if prec is None and any(isinstance(x, arb) for x in point):
            raise ValueError("evaluating an exact polynomial at a ball needs prec=...")
        coeffs = T.convert(self.coeffs, prec)
        shape = self.shape
        with flint.ctx.workprec(prec or flint.ctx.prec):
            if prec is not None:
                point = [x if isinstance(x, arb) else arb(x) for x in point]
            for axis in range(self.nvars - 1, -1, -1):
                n, x = shape[axis], point[axis]
                reduced = []
                for start in range(0, len(coeffs), n):
                    acc = coeffs[start + n - 1]
                    for k in range(start + n - 2, start - 1, -1):
                        acc = acc * x + coeffs[k]
                    reduced.append(acc)
                coeffs = reduced
        return coeffs[0]

    def __call__(self, *point):
        return self.evaluate(point)

    def compose(self, polys):
        """Substitute ``polys[i]`` for ``x_i``; all of ``polys`` share one number of variables.

        >>> x, y = Poly.variable(0, 2), Poly.variable(1, 2)
        >>> w = Poly({(1, 1): 1, (0, 0): 1})                  # 1 + u v
        >>> w.compose([x + y, x - y]) == 1 + x**2 - y**2
        True
        """
        polys = list(polys)
        if len(polys) != self.nvars or not all(isinstance(q, Poly) for q in polys):
            raise ValueError(f"compose needs {self.nvars} Poly objects")
        m = polys[0].nvars
        if any(q.nvars != m for q in polys):
            raise ValueError("the substituted polynomials must have the same number of variables")

        def rec(offset, axis):
            # polynomial of the sub-tensor starting at ``offset`` over axes >= axis
            if axis == self.nvars:
                return Poly.constant(self.coeffs[offset], m, self.prec)
            n = self.shape[axis]
            stride = T.size(self.shape[axis + 1 :])
            acc = rec(offset + (n - 1) * stride, axis + 1)
            for k in range(n - 2, -1, -1):
                acc = acc * polys[axis] + rec(offset + k * stride, axis + 1)
            return acc

        return rec(0, 0)

    def affine(self, axis, a, b):
        """``p`` with ``x_axis`` replaced by ``a + (b - a) x_axis`` (``a``, ``b`` exact rationals)."""
        axis = self._axis(axis)
        a, b = T.exact_scalar(a), T.exact_scalar(b)
        mat = taylor_shift_matrix(self.shape[axis] - 1, a, b - a)
        c, shape = T.apply_along_axis(self.coeffs, self.shape, axis, mat, self.prec)
        return Poly.from_raw(shape, c, self.prec)

    def truncate(self, degree, axis=0):
        """Ball polynomial of degree <= ``degree`` in ``x_axis`` that encloses ``self`` for
        ``x_axis`` in [-1, 1] *pointwise in that variable* (a Taylor model with a remainder).

        Every term ``c x_axis^j x'^e`` with ``j > degree`` is absorbed into the ball of the
        coefficient of ``x_axis^0 x'^e`` (radius += ``|c|``, as ``|x_axis^j| <= 1``).  So for each
        fixed ``a`` in [-1, 1], the polynomial ``self(x_axis = a)`` in the other variables belongs
        to the family ``result(x_axis = a)``; this survives products, sums and derivatives in the
        *other* variables (not in ``x_axis``), and a Bernstein lower bound of the result on a box
        with ``x_axis`` in [-1, 1] bounds ``self`` there.

        >>> z, s = Poly.variable(0, 2, 64), Poly.variable(1, 2, 64)
        >>> r = (1 + z * s + z**2 * s**2).truncate(1)
        >>> r.degrees, r.coefficient((0, 2)).contains(0), r.coefficient((0, 2)).rad() >= 1
        ((1, 2), True, True)
        >>> (1 + arb(0, fmpq(1, 10**6)) * z**2).truncate(1).coefficient((0, 0)).rad() >= fmpq(1, 10**6)
        True
        """
        axis = self._axis(axis)
        if isinstance(degree, bool) or not isinstance(degree, int) or degree < 0:
            raise ValueError(f"degree must be a non-negative int, got {degree!r}")
        n = self.shape[axis]
        if n <= degree + 1:
            return self
        if self.prec is None:
            raise TypeError("truncate() makes balls: convert with .to_arb(prec) first")
        c, shape = T.truncate(self.coeffs, self.shape, axis, degree, self.prec)
        return Poly.from_raw(shape, c, self.prec)

    def _axis(self, axis):
        if isinstance(axis, bool) or not isinstance(axis, int) or not 0 <= axis < self.nvars:
            raise ValueError(f"axis {axis!r} out of range for {self.nvars} variables")
        return axis


# ---------------------------------------------------------------------------- helpers


def _check_nvars(nvars):
    if isinstance(nvars, bool) or not isinstance(nvars, int) or not 1 <= nvars <= MAX_VARS:
        raise ValueError(f"number of variables must be 1..{MAX_VARS}, got {nvars!r}")


def _is_exact_zero(c):
    return c == 0 if isinstance(c, fmpq) else c.is_zero()


def bernstein_coefficients(poly, box=None, degrees=None):
    """Bernstein form of ``poly`` on ``box`` (default [0,1]^n) of ``degrees`` (default ``poly.degrees``).

    Per variable, one exact matrix (Taylor shift to the box, then power -> Bernstein basis with
    degree elevation) is applied along the axis; exact input gives exact ``fmpq`` coefficients,
    ball input gives balls at ``poly.prec``.  For tight balls on small sub-boxes prefer converting
    once on a large box and then using :meth:`BernsteinForm.split` / :meth:`BernsteinForm.restrict`
    (both numerically stable) over re-expanding the power form on each sub-box.

    Parameters
    ----------
    poly : Poly
    box : sequence of nvars pairs (lo, hi), optional
    degrees : tuple of int, optional: at least ``poly.degrees`` (higher ones elevate the degree)

    Returns
    -------
    BernsteinForm of shape ``degrees + 1``

    Examples
    --------
    x^2 on [1, 3] is (1 + 2t)^2 = (1 - t)^2 + 3 * 2t(1 - t) + 9 t^2:

    >>> x = Poly.variable(0, 1)
    >>> bernstein_coefficients(x**2, box=[(1, 3)]).coeffs, bernstein_coefficients(x, degrees=(2,)).coeffs
    ([1, 3, 9], [0, 1/2, 1])
    """
    if not isinstance(poly, Poly):
        raise TypeError(f"expected a Poly, got {type(poly).__name__}")
    box = unit_box(poly.nvars) if box is None else check_box(box, poly.nvars)
    degrees = poly.degrees if degrees is None else tuple(degrees)
    if len(degrees) != poly.nvars or any(
        isinstance(d, bool) or not isinstance(d, int) or d < n for d, n in zip(degrees, poly.degrees)
    ):
        raise ValueError(f"Bernstein degrees {degrees} below the polynomial's degrees {poly.degrees}")
    mats = [conversion_matrix(n - 1, d, lo, hi) for n, d, (lo, hi) in zip(poly.shape, degrees, box)]
    c, shape = apply_all_axes(poly.coeffs, poly.shape, mats, poly.prec)
    return BernsteinForm.from_raw(shape, c, box, poly.prec)


def to_poly(form):
    """The polynomial of a :class:`~ccproof.rigorous.BernsteinForm` in the original (box) variables, in the power
    basis.

    >>> to_poly(BernsteinForm((3,), [0, 0, 1])) == Poly.variable(0, 1) ** 2
    True
    """
    f = form.bernstein()
    mats = [bernstein_to_power_matrix(n - 1) for n in f.shape]
    c, shape = apply_all_axes(f.coeffs, f.shape, mats, f.prec)
    p = Poly.from_raw(shape, c, f.prec)
    for axis, (lo, hi) in enumerate(f.box):
        if (lo, hi) != (0, 1):
            h = hi - lo
            p = p.affine(axis, -lo / h, (1 - lo) / h)  # t = (x - lo) / h
    return p


def apply_all_axes(coeffs, shape, mats, prec):
    """Apply ``mats[k]`` along every axis ``k`` (a tensor-product basis change).

    Each step multiplies along the leading axis and transposes, which rotates the axes by one;
    after one step per axis the original order is back, with no permutation done in Python.
    """
    if len(mats) != len(shape):
        raise ValueError(f"{len(mats)} matrices for {len(shape)} axes")
    with flint.ctx.workprec(prec or flint.ctx.prec):
        for mat in mats:
            n = shape[0]
            if mat.ncols() != n:
                raise ValueError(f"matrix with {mat.ncols()} columns applied to an axis of length {n}")
            rest = T.size(shape[1:])
            y = T.to_matrix(mat, prec) * T.new_matrix(n, rest, coeffs, prec)
            coeffs = y.transpose().entries()
            shape = shape[1:] + (mat.nrows(),)
    return coeffs, shape


def multi_indices(shape):
    """All exponent tuples of ``shape`` in row-major order."""
    out = [()]
    for n in shape:
        out = [e + (k,) for e in out for k in range(n)]
    return out


def bernstein_to_power_matrix(n):
    """(n+1) x (n+1) ``fmpq_mat``: Bernstein coefficients of degree n on [0,1] -> power coefficients.

    a_i = sum_k (-1)^(i-k) C(n, i) C(i, k) b_k (the inverse of ``power_to_bernstein_matrix(n, n)``).

    >>> (bernstein_to_power_matrix(2) * flint.fmpq_mat(3, 1, [0, 1, 0])).entries()   # 2 x (1 - x)
    [0, 2, -2]
    """
    return flint.fmpq_mat(n + 1, n + 1, [(-1) ** ((i - k) % 2) * comb(n, i) * comb(i, k) if k <= i else 0
                                         for i in range(n + 1) for k in range(n + 1)])


def taylor_form(poly, prec):
    """The :class:`~ccproof.rigorous.TaylorForm` of the power-basis ``poly`` in (z, x_1, ..., x_d), x in the
    Bernstein basis on [0,1]^d.

    x^2 + z y: z-degree 1, Bernstein coefficients in (x, y) of x^2 (0, 0, 1) and of y (0, 1):

    >>> z, x, y = (Poly.variable(i, 3) for i in range(3))
    >>> f = taylor_form(x * x + z * y, 53)
    >>> f.shape, [c.str(3, radius=False) for c in f.coeffs]
    ((2, 3, 2), ['0', '0', '0', '0', '1.00', '1.00', '0', '1.00', '0', '1.00', '0', '1.00'])
    """
    if not isinstance(poly, Poly) or poly.nvars < 2:
        raise TypeError("expected a Poly in (z, x_1, ...), at least 2 variables")
    coeffs, shape = T.convert(poly.coeffs, prec), poly.shape
    for axis in range(1, len(shape)):
        coeffs, shape = T.apply_along_axis(coeffs, shape, axis,
                                           power_to_bernstein_matrix(shape[axis] - 1, shape[axis] - 1), prec)
    return TaylorForm.from_raw(shape, coeffs, TaylorForm.variable(1, len(shape) - 1, prec).box, prec)


def ball_contains(ball, value):
    """Does the ball certainly contain ``value`` (an exact number, compared with the exact endpoints, or a ball)?

    >>> ball_contains(arb(1, fmpq(1, 2)), fmpq(3, 2)), ball_contains(arb(1), 2)
    (True, False)
    """
    if isinstance(value, arb):
        return bool(ball.contains(value))
    value = T.exact_scalar(value)
    if not ball.is_finite():
        return bool(ball.contains(arb(value)))  # nan: False; infinite radius: True
    mid, rad = T.exact_fmpq(ball.mid()), T.exact_fmpq(ball.rad())
    return mid - rad <= value <= mid + rad


def certainly_positive(form):
    """True only when every coefficient is certainly > 0 and finite (so the polynomial is > 0 on the box).

    >>> certainly_positive([arb(1), arb("0 +/- 0.1")]), certainly_positive(arb("nan"))
    (False, False)
    """
    coeffs = form.bernstein().coeffs if isinstance(form, BernsteinForm) else [form] if isinstance(
        form, (arb, fmpq, flint.fmpz, int)) and not isinstance(form, bool) else list(form)
    for c in coeffs:
        if isinstance(c, arb):
            if not (c.is_finite() and c > 0):
                return False
        elif not T.exact_scalar(c) > 0:
            return False
    return bool(coeffs)
