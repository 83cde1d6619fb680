"""File format of the certified characteristic-map tables (schema ``ccproof.table/1``).

It uses only the standard library, python-flint and :mod:`ccproof.valence` (no numpy, no sympy, no
float arithmetic in decisions). The trusted verifier does not import it: it reads certificates
with its own reader (docs/trusted_base.md).

A table is a JSON object; ``docs/tables.md`` has the full grammar and a worked example. The fields
read by the verifier are:

* ``schema`` = ``"ccproof.table/1"``; ``valence``: an int k >= 3, or ``{"min": k0}`` for the interval
  of valences k >= k0;
* ``prec``: bits of the arb enclosures;
* ``c``, ``lam``: arb balls (``{"mid": str, "rad": str}``, decimal strings) enclosing c = cos(2 pi/k)
  and lam(k) (for an interval: every value for k >= k0);
* ``exact.bspline.P1..P3``: 4x4 nets of points, each coordinate an integer form ``[A, B, D]`` (integer
  coefficient lists in c, constant term first) meaning (A(c) + B(c) lam)/D(c);
* ``arb.bezier.P1..P3`` and ``arb.bspline.P1..P3``: the same nets as balls;
* ``hash``: ``"sha256:<hex>"`` of the canonical JSON of every other field.

An arb ball is written as decimal strings ``mid`` and ``rad`` such that the closed decimal interval
[mid - rad, mid + rad] contains the ball; :func:`arb_from_json` reads it back into a ball containing
that interval, so a round trip never loses an enclosure.
"""

from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path

from ccproof.errors import CCProofError

SCHEMA = "ccproof.table/1"
PATCHES = ("P1", "P2", "P3")


class TableFormatError(CCProofError):
    """A table file that is malformed, of an unknown schema, or whose hash does not match (a
    :class:`~ccproof.errors.CCProofError`, hence a ``ValueError``).

    Parameters
    ----------
    message : str
        What is wrong, naming the file or the field (docs/tables.md).

    Examples
    --------
    >>> arb_from_json({"mid": "1"}, 53)
    Traceback (most recent call last):
    ...
    ccproof.tables.format.TableFormatError: a ball must be {'mid': str, 'rad': str}, got {'mid': '1'}
    """


# ----------------------------------------------------------------------------- JSON + hash
def _canonical_json(obj):
    """Canonical serialization used for hashing: sorted keys, no whitespace, ASCII."""
    return json.dumps(obj, sort_keys=True, separators=(",", ":"), ensure_ascii=True)


def content_hash(obj, *, exclude=("hash",)):
    """``"sha256:<hex>"`` of the canonical JSON of ``obj`` without the ``exclude`` keys.

    The canonical JSON has sorted keys, no whitespace and ASCII only; it is the ``hash`` field of
    tables and certificates (docs/tables.md, docs/certificates.md).

    Parameters
    ----------
    obj : dict
        A JSON-serializable mapping.
    exclude : tuple of str, optional
        Top-level keys left out (default: the ``hash`` field itself).

    Returns
    -------
    str

    Examples
    --------
    >>> import hashlib
    >>> content_hash({"a": 1, "hash": "x"}) == "sha256:" + hashlib.sha256(b'{"a":1}').hexdigest()
    True
    """
    body = {k: v for k, v in obj.items() if k not in exclude}
    return "sha256:" + hashlib.sha256(_canonical_json(body).encode("ascii")).hexdigest()


# ----------------------------------------------------------------------------- arb <-> JSON
def arb_to_json(x, digits=40):
    """Decimal ``{"mid", "rad"}`` whose interval contains the ball ``x`` (outward).

    The ball spelling of the tables' ``arb`` fields (docs/tables.md).

    Parameters
    ----------
    x : flint.arb
        A finite ball.
    digits : int, optional
        Decimal digits of the midpoint (default 40).

    Returns
    -------
    dict
        ``{"mid": str, "rad": str}``, decimal strings.

    Raises
    ------
    TableFormatError
        If ``x`` is not a finite ball.

    Examples
    --------
    >>> from flint import arb
    >>> arb_to_json(arb(1) / 3, 10)
    {'mid': '333333333333333e-15', 'rad': '2e-15'}
    """
    from flint import arb, ctx

    if not isinstance(x, arb) or not x.is_finite():
        raise TableFormatError(f"cannot write a non-finite ball {x!r}")
    with ctx.workprec(max(ctx.prec, 4 * digits)):
        m, r, e = x.mid_rad_10exp(digits)
    return {"mid": f"{m}e{e}", "rad": f"{r}e{e}"}


def arb_from_json(obj, prec):
    """Ball at ``prec`` bits containing the decimal interval of ``obj`` (see :func:`arb_to_json`).

    Parameters
    ----------
    obj : dict
        ``{"mid": str, "rad": str}``.
    prec : int
        Bits of precision of the ball.

    Returns
    -------
    flint.arb

    Raises
    ------
    TableFormatError
        If ``obj`` is not a ball of that spelling.

    Examples
    --------
    >>> from flint import arb
    >>> x = arb(1) / 3
    >>> arb_from_json(arb_to_json(x), 128).contains(x)
    True
    """
    from flint import arb, ctx

    if not isinstance(obj, dict) or set(obj) != {"mid", "rad"}:
        raise TableFormatError(f"a ball must be {{'mid': str, 'rad': str}}, got {obj!r}")
    mid, rad = obj["mid"], obj["rad"]
    for s in (mid, rad):
        if not isinstance(s, str) or not _is_decimal(s):
            raise TableFormatError(f"ball component {s!r} is not a decimal string")
    if rad.startswith("-"):
        raise TableFormatError(f"negative radius {rad!r}")
    with ctx.workprec(prec):
        x = arb(f"[{mid} +/- {rad}]")
    if not x.is_finite():
        raise TableFormatError(f"ball {obj!r} is not finite")
    return x


def _is_decimal(s):
    import re

    return re.fullmatch(r"-?[0-9]+(\.[0-9]+)?(e-?[0-9]+)?", s) is not None


# ----------------------------------------------------------------------------- integer forms
def _check_integer_form(form, where):
    """Validate ``[A, B, D]`` with integer lists and D not the zero polynomial."""
    if not (isinstance(form, list) and len(form) == 3):
        raise TableFormatError(f"{where}: an exact entry must be [A, B, D]")
    for lst in form:
        if not (isinstance(lst, list) and lst and all(isinstance(a, int) and not isinstance(a, bool) for a in lst)):
            raise TableFormatError(f"{where}: coefficient lists must be non-empty lists of integers")
    if all(a == 0 for a in form[2]):
        raise TableFormatError(f"{where}: zero denominator")
    return form


def eval_form_arb(form, c, lam):
    """(A(c) + B(c) lam)/D(c) in ball arithmetic (Horner); encloses the value for all c, lam in
    the balls (the caller sets the working precision)."""

    def horner(coeffs):
        acc = 0
        for a in reversed(coeffs):
            acc = acc * c + a
        return acc

    return (horner(form[0]) + horner(form[1]) * lam) / horner(form[2])


# ----------------------------------------------------------------------------- locations
def certificates_dir():
    """The published certificates (``tables/``, ``injectivity/``, ``c1/``), read-only for the package.

    ``$CCPROOF_CERTIFICATES`` if set; else the repository's top-level ``certificates/`` when this
    module runs from a checkout (also an editable install): the folder beside ``pyproject.toml``
    two levels above the package; else the copy the wheel ships as package data,
    ``ccproof/_certificates`` (written by the build hook in ``setup.py``).

    Returns
    -------
    pathlib.Path

    Examples
    --------
    >>> (certificates_dir() / "tables" / "k004.json").is_file()
    True
    """
    env = os.environ.get("CCPROOF_CERTIFICATES")
    if env:
        return Path(env)
    package = Path(__file__).resolve().parents[1]
    checkout = package.parent
    if (checkout / "pyproject.toml").is_file() and (checkout / "certificates" / "tables").is_dir():
        return checkout / "certificates"
    return package / "_certificates"


def output_dir():
    """Where ``ccproof certify`` writes new certificates by default (never inside site-packages).

    In a checkout (or with ``$CCPROOF_CERTIFICATES``): :func:`certificates_dir`. For an installed
    package: ``$XDG_DATA_HOME/ccproof/certificates`` (``~/.local/share/ccproof/certificates`` when
    ``XDG_DATA_HOME`` is unset). A certificate needs no other file: ``ccproof verify`` checks it wherever
    it is written.

    Returns
    -------
    pathlib.Path

    Examples
    --------
    >>> import os
    >>> "CCPROOF_CERTIFICATES" in os.environ or output_dir().name == "certificates"
    True
    """
    published = certificates_dir()
    if published != Path(__file__).resolve().parents[1] / "_certificates":
        return published
    data_home = os.environ.get("XDG_DATA_HOME") or str(Path.home() / ".local" / "share")
    return Path(data_home) / "ccproof" / "certificates"


def _table_filename(valence):
    """``k007.json`` for k = 7, ``k_ge_40.json`` for the interval k >= 40 (any spelling of
    :meth:`ccproof.valence.Valence.parse`).

    >>> _table_filename(7), _table_filename({"min": 40}), _table_filename(">=40")
    ('k007.json', 'k_ge_40.json', 'k_ge_40.json')
    """
    from ccproof.valence import Valence

    return Valence.parse(valence).stem + ".json"


def table_path(valence, directory=None):
    """The path of the table file of ``valence`` (``k007.json``, ``k_ge_40.json``; docs/tables.md).

    Parameters
    ----------
    valence : int or str or dict or Valence
        Any spelling of :meth:`ccproof.valence.Valence.parse`.
    directory : str or pathlib.Path, optional
        Folder of the tables; default ``certificates_dir() / "tables"``.

    Returns
    -------
    pathlib.Path
        The file need not exist.

    Examples
    --------
    >>> table_path(7, "out").as_posix(), table_path(">=40").name
    ('out/k007.json', 'k_ge_40.json')
    """
    return Path(directory or certificates_dir() / "tables") / _table_filename(valence)


def available_tables(directory=None):
    """Sorted list of the valences (ints) and intervals (``">=K0"``) with a table file.

    Parameters
    ----------
    directory : str or pathlib.Path, optional
        Folder of the tables; default ``certificates_dir() / "tables"``.

    Returns
    -------
    list of int and str
        The single valences in increasing order, then the intervals.

    Examples
    --------
    >>> av = available_tables()
    >>> av[:2], av[-1]
    ([3, 4], '>=40')
    """
    d = Path(directory or certificates_dir() / "tables")
    ks, intervals = [], []
    if d.is_dir():
        from ccproof.errors import ValenceError
        from ccproof.valence import Valence

        for p in d.glob("k*.json"):
            try:
                v = Valence.parse(p.name)
            except ValenceError:
                continue
            if v.interval:
                intervals.append(str(v))
            else:
                ks.append(v.k)
    return sorted(ks) + sorted(intervals)


def describe_available(directory=None):
    """One line naming the tables that exist (for error messages: :class:`~ccproof.errors.TableNotFoundError`).

    Parameters
    ----------
    directory : str or pathlib.Path, optional
        Folder of the tables; default ``certificates_dir() / "tables"``.

    Returns
    -------
    str

    Examples
    --------
    >>> describe_available("no-such-folder")
    'no tables exist yet (run `ccproof table --all`)'
    >>> describe_available().startswith("tables exist for k = 3..")
    True
    """
    av = available_tables(directory)
    ints = [a for a in av if isinstance(a, int)]
    rest = [a for a in av if not isinstance(a, int)]
    if not av:
        return "no tables exist yet (run `ccproof table --all`)"
    parts = []
    if ints:
        parts.append(f"k = {ints[0]}..{ints[-1]}" if ints == list(range(ints[0], ints[-1] + 1)) else
                     "k in " + ", ".join(map(str, ints)))
    parts += [f"k {r}" for r in rest]
    return "tables exist for " + "; ".join(parts)


# ----------------------------------------------------------------------------- loading
def read_table_json(path, *, check_hash=True):
    """Read and validate a table file; returns the dict.

    The schema is documented in docs/tables.md.

    Parameters
    ----------
    path : str or pathlib.Path
        A table file (:func:`table_path`).
    check_hash : bool, optional
        Recompute :func:`content_hash` and compare it with the file's ``hash`` field (default True).

    Returns
    -------
    dict
        The validated table.

    Raises
    ------
    TableFormatError
        Naming the problem (unknown schema, missing field, hash mismatch).
    FileNotFoundError
        If ``path`` does not exist.

    Examples
    --------
    >>> t = read_table_json(table_path(4))
    >>> t["valence"], t["hash"] == content_hash(t)
    (4, True)
    """
    path = Path(path)
    try:
        with open(path, encoding="ascii") as fh:
            obj = json.load(fh)
    except FileNotFoundError:
        raise
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise TableFormatError(f"{path}: not a readable JSON table ({exc})") from None
    if not isinstance(obj, dict):
        raise TableFormatError(f"{path}: a table must be a JSON object")
    if obj.get("schema") != SCHEMA:
        raise TableFormatError(f"{path}: unknown schema {obj.get('schema')!r}, expected {SCHEMA!r}")
    for key in ("valence", "prec", "c", "lam", "exact", "arb", "hash"):
        if key not in obj:
            raise TableFormatError(f"{path}: missing field {key!r}")
    from ccproof.errors import ValenceError
    from ccproof.valence import Valence

    try:
        Valence.from_json(obj["valence"])
    except ValenceError:
        raise TableFormatError(f"{path}: bad valence field {obj['valence']!r}") from None
    if not isinstance(obj["prec"], int) or isinstance(obj["prec"], bool) or not 32 <= obj["prec"] <= 4096:
        raise TableFormatError(f"{path}: bad precision {obj['prec']!r}")
    if check_hash:
        h = content_hash(obj)
        if obj["hash"] != h:
            raise TableFormatError(f"{path}: table hash mismatch (file says {obj['hash']}, content is {h})")
    return obj


def table_nets_arb(obj, form="bezier", prec=None):
    """The ``arb`` nets of a validated table: ``{"P1": net, ...}``, ``net[i][j] = (x, y)`` balls.

    The Bezier (or B-spline) nets of the three layer-0 pieces of the characteristic map
    (bmz04 section 4.3; docs/readings.md R3, R4).

    Parameters
    ----------
    obj : dict
        A table read by :func:`read_table_json`.
    form : {"bezier", "bspline"}, optional
        Which nets (default Bezier).
    prec : int, optional
        Bits of precision of the balls (default: the table's ``prec``).

    Returns
    -------
    dict
        ``{"P1": net, "P2": net, "P3": net}``, ``net`` 4 x 4 nested lists of ``(x, y)`` pairs of
        ``flint.arb``.

    Examples
    --------
    For k = 4 the characteristic map is the identity: the last Bezier point of P2 is (1, 1):

    >>> x, y = table_nets_arb(read_table_json(table_path(4)))["P2"][3][3]
    >>> x.contains(1) and y.contains(1)
    True
    """
    prec = prec or obj["prec"]
    try:
        nets = obj["arb"][form]
    except (KeyError, TypeError):
        raise TableFormatError(f"table has no arb {form} nets") from None
    out = {}
    for name in PATCHES:
        net = nets.get(name) if isinstance(nets, dict) else None
        if not (isinstance(net, list) and len(net) == 4 and all(isinstance(r, list) and len(r) == 4 for r in net)):
            raise TableFormatError(f"arb {form} net {name} must be 4x4")
        out[name] = [[_point(p, prec, f"{form} {name}[{i}][{j}]") for j, p in enumerate(row)]
                     for i, row in enumerate(net)]
    return out


def _point(p, prec, where):
    if not (isinstance(p, list) and len(p) == 2):
        raise TableFormatError(f"{where}: a point must be [x, y]")
    return tuple(arb_from_json(q, prec) for q in p)


def table_nets_exact(obj):
    """The exact B-spline nets of a validated table: ``net[i][j] = ([A,B,D], [A,B,D])``.

    Each coordinate is an integer form (A(c) + B(c) lam)/D(c) of
    :meth:`ccproof.algebra.field.QcLam.integer_form` (docs/tables.md; docs/readings.md R3).

    Parameters
    ----------
    obj : dict
        A table read by :func:`read_table_json`.

    Returns
    -------
    dict
        ``{"P1": net, "P2": net, "P3": net}``, ``net`` 4 x 4 nested lists of pairs of forms.

    Examples
    --------
    For k = 4 the B-spline net of P1 is the grid of spacing 1/2: point (1, 1) is (1/2, 0):

    >>> from fractions import Fraction
    >>> from ccproof.algebra.field import eval_integer_form
    >>> fx, fy = table_nets_exact(read_table_json(table_path(4)))["P1"][1][1]
    >>> [eval_integer_form(f, Fraction(0), Fraction(1, 2)) for f in (fx, fy)]
    [Fraction(1, 2), Fraction(0, 1)]
    """
    try:
        nets = obj["exact"]["bspline"]
    except (KeyError, TypeError):
        raise TableFormatError("table has no exact bspline nets") from None
    out = {}
    for name in PATCHES:
        net = nets.get(name) if isinstance(nets, dict) else None
        if not (isinstance(net, list) and len(net) == 4 and all(isinstance(r, list) and len(r) == 4 for r in net)):
            raise TableFormatError(f"exact net {name} must be 4x4")
        out[name] = [
            [tuple(_check_integer_form(q, f"exact {name}[{i}][{j}]") for q in _pair(p, f"{name}[{i}][{j}]"))
             for j, p in enumerate(row)]
            for i, row in enumerate(net)
        ]
    return out


def _pair(p, where):
    if not (isinstance(p, list) and len(p) == 2 and all(isinstance(q, dict) and "form" in q for q in p)):
        raise TableFormatError(f"exact {where}: a point must be [{{'form': ...}}, {{'form': ...}}]")
    return [q["form"] for q in p]
