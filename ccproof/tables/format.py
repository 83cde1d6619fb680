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

SCHEMA = "ccproof.table/1"
PATCHES = ("P1", "P2", "P3")


class TableFormatError(ValueError):
    """A table file that is malformed, of an unknown schema, or whose hash does not match."""


# ----------------------------------------------------------------------------- JSON + hash
def _canonical_json(obj):
    """Canonical serialization used for hashing: sorted keys, no whitespace, ASCII."""
    return json.dumps(obj, sort_keys=True, separators=(",", ":"), ensure_ascii=True)


def content_hash(obj, *, exclude=("hash",)):
    """``"sha256:<hex>"`` of the canonical JSON of ``obj`` without the ``exclude`` keys."""
    body = {k: v for k, v in obj.items() if k not in exclude}
    return "sha256:" + hashlib.sha256(_canonical_json(body).encode("ascii")).hexdigest()


# ----------------------------------------------------------------------------- arb <-> JSON
def arb_to_json(x, digits=40):
    """Decimal ``{"mid", "rad"}`` whose interval contains the ball ``x`` (outward)."""
    from flint import arb, ctx

    if not isinstance(x, arb) or not x.is_finite():
        raise TableFormatError(f"cannot write a non-finite ball {x!r}")
    with ctx.workprec(max(ctx.prec, 4 * digits)):
        m, r, e = x.mid_rad_10exp(digits)
    return {"mid": f"{m}e{e}", "rad": f"{r}e{e}"}


def arb_from_json(obj, prec):
    """Ball at ``prec`` bits containing the decimal interval of ``obj`` (see :func:`arb_to_json`)."""
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


def _eval_form_arb(form, c, lam):
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
    return Path(directory or certificates_dir() / "tables") / _table_filename(valence)


def available_tables(directory=None):
    """Sorted list of the valences (ints) and intervals (``">=K0"``) with a table file."""
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
    """Read and validate a table file; returns the dict. Raises :class:`TableFormatError` naming
    the problem (unknown schema, missing field, hash mismatch)."""
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
    """The ``arb`` nets of a validated table: ``{"P1": net, ...}``, ``net[i][j] = (x, y)`` balls."""
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
    """The exact B-spline nets of a validated table: ``net[i][j] = ([A,B,D], [A,B,D])``."""
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
