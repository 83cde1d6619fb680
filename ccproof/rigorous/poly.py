"""Dense multivariate polynomials (1 to 4 variables) with exact ``fmpq`` or ball ``arb`` coefficients.

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
from flint import arb, fmpq, fmpq_mat

from . import _tensor as T
from ._tensor import MAX_VARS


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
        return {e: c for e, c in zip(T.multi_indices(self.shape), self.coeffs) if not _is_exact_zero(c)}

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
        return all(T.ball_contains(x, y) for x, y in zip(a, b))

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


def check_box(box, nvars):
    """``box`` as a tuple of ``nvars`` pairs ``(lo, hi)`` of fmpq with ``lo < hi``.

    Parameters
    ----------
    box : sequence of nvars pairs of exact numbers (int, fmpq, "p/q")
    nvars : int

    Returns
    -------
    tuple of nvars (fmpq, fmpq)

    Raises
    ------
    ValueError
        On a wrong number of intervals or an empty or degenerate one.

    Examples
    --------
    >>> check_box([(0, 1), ("1/2", 1)], 2)
    ((0, 1), (1/2, 1))
    >>> check_box([(1, 1)], 1)
    Traceback (most recent call last):
    ...
    ValueError: empty or degenerate interval [1, 1]
    """
    box = tuple(box)
    if len(box) != nvars:
        raise ValueError(f"box with {len(box)} intervals for {nvars} variables")
    out = []
    for iv in box:
        lo, hi = iv
        lo, hi = T.exact_scalar(lo), T.exact_scalar(hi)
        if not lo < hi:
            raise ValueError(f"empty or degenerate interval [{lo}, {hi}]")
        out.append((lo, hi))
    return tuple(out)


def _check_nvars(nvars):
    if isinstance(nvars, bool) or not isinstance(nvars, int) or not 1 <= nvars <= MAX_VARS:
        raise ValueError(f"number of variables must be 1..{MAX_VARS}, got {nvars!r}")


def _is_exact_zero(c):
    return c == 0 if isinstance(c, fmpq) else c.is_zero()


_SHIFT = {}


def taylor_shift_matrix(n, a, h):
    """Exact matrix sending the coefficients of p(x) (degree n) to those of p(a + h x).

    Parameters
    ----------
    n : int
    a, h : fmpq

    Returns
    -------
    fmpq_mat, shape (n + 1, n + 1)
        Entry (j, i) is ``C(i, j) a^(i-j) h^j``; the Taylor shift to a box before the Bernstein
        conversion (docs/rigorous.md "API").

    Examples
    --------
    x^2 becomes (1 + 2 x)^2 = 1 + 4 x + 4 x^2:

    >>> taylor_shift_matrix(2, fmpq(1), fmpq(2)) * fmpq_mat(3, 1, [0, 0, 1])
    [1]
    [4]
    [4]
    """
    key = (n, a, h)
    mat = _SHIFT.get(key)
    if mat is None:
        entries = [
            fmpq(comb(i, j)) * a ** (i - j) * h**j if i >= j else fmpq(0)
            for j in range(n + 1)
            for i in range(n + 1)
        ]
        mat = fmpq_mat(n + 1, n + 1, entries)
        if len(_SHIFT) > 4096:
            _SHIFT.clear()
        _SHIFT[key] = mat
    return mat


def jacobian_determinant(components, variables=None):
    """det of ``(d components[i] / d x_{variables[j]})`` for 1 to 4 components (Laplace expansion), in the
    components' own arithmetic: power form, Bernstein form on their common box, or Taylor model (z kept).

    ``variables`` defaults to ``0 .. len(components)-1``; extra variables act as parameters.

    Parameters
    ----------
    components : sequence of n Poly, BernsteinForm or TaylorForm (1 <= n <= 4), anything with ``diff``
    variables : tuple of n distinct int, optional (for a TaylorForm, x axes >= 1)

    Returns
    -------
    Poly, BernsteinForm or TaylorForm
        det J, whose sign decides local injectivity (docs/readings.md R7; e.g. det J_Phi of the
        characteristic map).

    Examples
    --------
    For z^2 = (x^2 - y^2, 2 x y) (Cauchy-Riemann: det J = |2 z|^2):

    >>> x, y = Poly.variable(0, 2), Poly.variable(1, 2)
    >>> jacobian_determinant([x**2 - y**2, 2 * x * y]) == 4 * x**2 + 4 * y**2
    True
    """
    components = list(components)
    n = len(components)
    if not 1 <= n <= MAX_VARS:
        raise ValueError(f"Jacobian of {n} components")
    variables = tuple(range(n)) if variables is None else tuple(variables)
    if len(variables) != n or len(set(variables)) != n:
        raise ValueError(f"need {n} distinct variables, got {variables!r}")
    jac = [[g.diff(v) for v in variables] for g in components]
    return _det(jac)


def _det(m):
    n = len(m)
    if n == 1:
        return m[0][0]
    if n == 2:
        return m[0][0] * m[1][1] - m[0][1] * m[1][0]
    total = None
    for j in range(n):
        minor = [row[:j] + row[j + 1 :] for row in m[1:]]
        term = m[0][j] * _det(minor)
        total = term if total is None else (total + term if j % 2 == 0 else total - term)
    return total
