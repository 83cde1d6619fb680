"""The valence of an extraordinary vertex as a value: one k >= 3, or every k >= k0 (an interval).

The one place where a valence is parsed and printed. The spellings it reads and writes:

=====================  =========================  =============================
where                  single valence k = 7       interval k >= 40
=====================  =========================  =============================
text (command line)    ``"7"``                    ``">=40"`` (also ``"k>=40"``)
JSON (tables, certs)   ``7``                      ``{"min": 40}``
file names             ``k007.json``              ``k_ge_40.json``
=====================  =========================  =============================

:meth:`Valence.parse` reads any of them (and an ``int`` or another :class:`Valence`); ``str``,
:meth:`Valence.to_json` and :meth:`Valence.stem` write them. :func:`lam_from_c` is the one formula of the
subdominant eigenvalue lam(k) outside the verifier, in any arithmetic. Imports nothing from ccproof but
:mod:`ccproof.errors` (bottom layer). The trusted verifier (``ccproof.certify.verify``) keeps its own
reader on purpose (it imports nothing of the package outside the trusted base, docs/trusted_base.md).

>>> Valence.parse(">=40"), Valence.parse({"min": 40}) == Valence.parse("k_ge_40.json")
(Valence('>=40'), True)
>>> v = Valence.parse(7)
>>> str(v), v.to_json(), v.stem, v.contains(7), Valence.parse(">=40").contains(1000)
('7', 7, 'k007', True, True)
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from numbers import Integral
from typing import Any, SupportsIndex, TypeAlias

from ccproof.errors import ValenceError, check_valence

_TEXT_INTERVAL = re.compile(r"^\s*k?\s*>=\s*(\S+)\s*$")
_STEM = re.compile(r"^k(?:_ge_(\d+)|(\d+))(?:\.json)?$")


@dataclass(frozen=True, order=True)
class Valence:
    """A single valence ``k`` (``interval=False``) or the interval of every valence >= ``k``.

    Parameters
    ----------
    k : int
        The valence, or the smallest valence of the interval; an integer >= 3.
    interval : bool
        True for "every valence >= k".

    Examples
    --------
    >>> Valence(5), Valence(40, interval=True)
    (Valence('5'), Valence('>=40'))
    >>> sorted([Valence(40, True), Valence(7), Valence(3)])      # single valences first, then intervals
    [Valence('3'), Valence('7'), Valence('>=40')]
    >>> Valence.parse(">=2")
    Traceback (most recent call last):
    ...
    ccproof.errors.ValenceError: valence must be an integer >= 3, got '2'
    """

    interval: bool
    k: int

    def __init__(self, k: SupportsIndex | str, interval: bool = False) -> None:
        object.__setattr__(self, "interval", bool(interval))
        object.__setattr__(self, "k", check_valence(k))

    @classmethod
    def parse(cls, value: ValenceLike) -> Valence:
        """Read a valence in any spelling of the module table; raises :class:`~ccproof.errors.ValenceError`.

        >>> [str(Valence.parse(x)) for x in (5, "5", " >= 40 ", {"min": 41}, "k_ge_42", "k007.json")]
        ['5', '5', '>=40', '>=41', '>=42', '7']
        >>> Valence.parse({"max": 3})
        Traceback (most recent call last):
        ...
        ccproof.errors.ValenceError: a valence interval must be {"min": k0}, got {'max': 3}
        """
        if isinstance(value, Valence):
            return value
        if isinstance(value, Mapping):
            return cls.from_json(value)
        if isinstance(value, str):
            text = value.strip()
            m = _TEXT_INTERVAL.match(text)
            if m:
                return cls(m.group(1), interval=True)
            m = _STEM.match(text)
            if m:
                return cls(int(m.group(1) or m.group(2)), interval=m.group(1) is not None)
            return cls(text)
        return cls(value)

    @classmethod
    def from_json(cls, value: object) -> Valence:
        """Read the JSON spelling only (the ``valence`` field of tables and certificates): an int k >= 3
        or ``{"min": k0}`` with an int k0 >= 3; anything else (a string, a bool, a float) raises
        :class:`~ccproof.errors.ValenceError`.

        >>> Valence.from_json(7), Valence.from_json({"min": 40})
        (Valence('7'), Valence('>=40'))
        >>> Valence.from_json("7")
        Traceback (most recent call last):
        ...
        ccproof.errors.ValenceError: a valence field must be an int k >= 3 or {"min": k0}, got '7'
        """
        if isinstance(value, Mapping):
            if set(value) != {"min"} or isinstance(value["min"], bool) or not isinstance(value["min"], Integral):
                raise ValenceError(f'a valence interval must be {{"min": k0}}, got {value!r}')
            return cls(value["min"], interval=True)
        if isinstance(value, bool) or not isinstance(value, Integral):
            raise ValenceError(f'a valence field must be an int k >= 3 or {{"min": k0}}, got {value!r}')
        return cls(value)

    def __str__(self) -> str:
        return f">={self.k}" if self.interval else str(self.k)

    def __repr__(self) -> str:
        return f"Valence({str(self)!r})"

    def to_json(self) -> int | dict[str, int]:
        """``k`` (int) or ``{"min": k0}``: the spelling of tables and certificates.

        >>> Valence.parse(">=40").to_json()
        {'min': 40}
        """
        return {"min": self.k} if self.interval else self.k

    @property
    def stem(self) -> str:
        """File name stem: ``k007`` or ``k_ge_40``.

        >>> Valence(12).stem, Valence(40, True).stem
        ('k012', 'k_ge_40')
        """
        return f"k_ge_{self.k}" if self.interval else f"k{self.k:03d}"

    def contains(self, k: int) -> bool:
        """Whether the single valence ``k`` is this valence or lies in this interval.

        >>> Valence.parse(">=40").contains(39), Valence(5).contains(5)
        (False, True)
        """
        k = check_valence(k)
        return k >= self.k if self.interval else k == self.k


#: every spelling :meth:`Valence.parse` reads: an int, a text (``"7"``, ``">=40"``, ``"k_ge_40.json"``), the
#: JSON ``{"min": k0}`` or a :class:`Valence`
ValenceLike: TypeAlias = "int | str | Mapping[str, int] | Valence"


def parse_valence(value: ValenceLike) -> Valence:
    """:meth:`Valence.parse` as a function (for argparse ``type=``: ``ccproof table '>=40'``).

    Parameters
    ----------
    value : int or str or Mapping[str, int] or Valence
        A single valence (``7``, ``"7"``), an interval ``">=40"`` / ``"k_ge_40.json"`` / ``{"min": 40}``,
        or a :class:`Valence` (returned unchanged).

    Returns
    -------
    Valence

    Raises
    ------
    ValenceError
        If ``value`` names no valence >= 3.

    Examples
    --------

    >>> parse_valence(">=40")
    Valence('>=40')
    >>> parse_valence({"min": 40}) == parse_valence("k_ge_40.json"), parse_valence("7").k
    (True, 7)
    """
    return Valence.parse(value)


def lam_from_c(c: Any, sqrt: Callable[[Any], Any] = math.sqrt) -> Any:
    """The subdominant eigenvalue lam = (5 + c + sqrt((1 + c)(9 + c)))/16 of valence k, c = cos(2 pi/k).

    The larger root of 16 lam^2 - 2(5 + c) lam + 1 = 0, the double eigenvalue lam_1 = lam_2 of the
    Catmull-Clark subdivision matrix (bmz04 section 3, Definition 4; docs/readings.md R2). The one copy
    of the formula outside the trusted verifier (which keeps its own, docs/trusted_base.md), written once
    for every arithmetic: ``sqrt`` is the square root of the arithmetic of ``c``.

    Parameters
    ----------
    c : float or ndarray or flint.arb or sympy.Expr
        cos(2 pi/k), or an enclosure of it (an arb ball), or an array of values.
    sqrt : callable
        ``math.sqrt`` (default, floats), ``numpy.sqrt`` (arrays), ``flint.arb.sqrt`` (balls: the result
        encloses lam(c) for every c in the ball) or ``sympy.sqrt`` (exact).

    Returns
    -------
    same type as ``c``

    Examples
    --------
    >>> lam_from_c(0.0)                         # k = 4
    0.5
    >>> import sympy
    >>> lam_from_c(sympy.Rational(-1, 2), sympy.sqrt)      # k = 3: lam = (9 + sqrt 17)/32
    sqrt(17)/32 + 9/32
    >>> from flint import arb
    >>> lam_from_c(arb(1), arb.sqrt).contains((3 + arb(5).sqrt()) / 8)    # the limit k -> infinity
    True
    """
    return (5 + c + sqrt((1 + c) * (9 + c))) / 16
