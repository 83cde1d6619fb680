"""Replaying the hints of a certificate: decimals, box paths, partitions, claimed bounds (trusted).

A certificate's hints are lists of boxes ``{"path", "bound"}`` (docs/certificates.md has the grammar):
the path names a box by de Casteljau halvings, the bound is a decimal. This module parses them with
bounded sizes (so no input can make the verifier hang or crash) and replays them on a Bernstein form.
It never searches.
"""

from __future__ import annotations

import re

from flint import fmpq

from .errors import CertificateError

_TOKEN = re.compile(r"([0-3])([LH])")
_DECIMAL = re.compile(r"(-?)([0-9]+)(?:\.([0-9]+))?(?:e(-?[0-9]+))?")
MAX_DECIMAL_CHARS = 64  # the prover writes at most ~20
MAX_EXPONENT = 400
MAX_PATH_TOKENS = 64


def parse_decimal(s):
    """Exact fmpq of a decimal string like ``'0.1234'`` or ``'-15e-4'``, of at most
    :data:`MAX_DECIMAL_CHARS` characters and an exponent of at most :data:`MAX_EXPONENT` in magnitude.

    Parameters
    ----------
    s : str

    Returns
    -------
    fmpq

    Examples
    --------

    >>> parse_decimal("-15e-4"), parse_decimal("0.25")
    (-3/2000, 1/4)
    """
    if not isinstance(s, str) or len(s) > MAX_DECIMAL_CHARS:
        raise CertificateError(f"a decimal must be a string of at most {MAX_DECIMAL_CHARS} characters: "
                               f"{str(s)[:40]!r}")
    m = _DECIMAL.fullmatch(s)
    if m is None:
        raise CertificateError(f"{s!r} is not a decimal string")
    sign, intpart, frac, exp = m.group(1), m.group(2), m.group(3) or "", m.group(4)
    e = int(exp) if exp else 0
    if abs(e) > MAX_EXPONENT:
        raise CertificateError(f"decimal {s!r}: exponent beyond +-{MAX_EXPONENT}")
    q = fmpq(int(intpart + frac), 10 ** len(frac))
    q = q * fmpq(10) ** e if e >= 0 else q / fmpq(10) ** (-e)
    return -q if sign else q


def parse_path(path, nvars):
    """The halvings of a box path: ``"0L1H"`` is the low half along axis 0, then the high half along 1.

    Parameters
    ----------
    path : str
        At most :data:`MAX_PATH_TOKENS` tokens ``[0-3][LH]`` (docs/certificates.md).
    nvars : int
        Axes must be below it.

    Returns
    -------
    list of (int, str)

    Examples
    --------
    >>> parse_path("0L1H", 2)
    [(0, 'L'), (1, 'H')]
    """
    if not isinstance(path, str) or len(path) > 2 * MAX_PATH_TOKENS or _TOKEN.sub("", path) != "":
        raise CertificateError(f"malformed box path {path!r}")
    toks = [(int(a), side) for a, side in _TOKEN.findall(path)]
    if any(a >= nvars for a, _ in toks):
        raise CertificateError(f"box path {path!r} splits an axis >= {nvars}")
    return toks


def check_partition(paths, nvars):
    """True iff the leaf paths partition the root box exactly (no gap, no overlap).

    Parameters
    ----------
    paths : sequence of str
        Box paths (:func:`parse_path`).
    nvars : int

    Returns
    -------
    bool

    Examples
    --------
    >>> check_partition(["0L", "0H1L", "0H1H"], 2), check_partition(["0L", "0H1L"], 2)
    (True, False)
    """
    parsed = [parse_path(p, nvars) for p in paths]
    if len({tuple(p) for p in parsed}) != len(parsed):
        return False

    def rec(group, depth):
        if any(len(p) == depth for p in group):
            return len(group) == 1
        axes = {p[depth][0] for p in group}
        if len(axes) != 1:
            return False
        lo = [p for p in group if p[depth][1] == "L"]
        hi = [p for p in group if p[depth][1] == "H"]
        return bool(lo) and bool(hi) and rec(lo, depth + 1) and rec(hi, depth + 1)

    return bool(parsed) and rec(parsed, 0)


def check_boxes(root, boxes, what):
    """Replay the split paths on the Bernstein form ``root``; each box's coefficients must all be
    certainly > its claimed bound > 0 (de Casteljau halvings of :class:`ccproof.rigorous.BernsteinForm`).

    Parameters
    ----------
    root : BernsteinForm
        Ball coefficients on the root box.
    boxes : list of dict ``{"path": str, "bound": decimal str}``
        Must partition the root box (:func:`check_partition`).
    what : str
        Named in the messages.

    Returns
    -------
    (bool, str, fmpq or None)
        ok, the reason when not, and the smallest bound.

    Examples
    --------
    1 + x on [0, 1]: the halves have Bernstein coefficients (1, 3/2) and (3/2, 2):

    >>> from ccproof.rigorous import Poly, bernstein_coefficients
    >>> f = bernstein_coefficients(1 + Poly.variable(0, 1)).to_arb(53)
    >>> check_boxes(f, [{"path": "0L", "bound": "0.9"}, {"path": "0H", "bound": "1.4"}], "test")
    (True, '', 9/10)
    >>> check_boxes(f, [{"path": "0L", "bound": "1.1"}, {"path": "0H", "bound": "1.4"}], "test")[0]
    False
    """
    if not isinstance(boxes, list) or not boxes:
        return False, f"{what}: no boxes", None
    paths = []
    min_bound = None
    cache = {"": root}
    for b in boxes:
        if not isinstance(b, dict) or set(b) != {"path", "bound"}:
            return False, f"{what}: a box must be {{'path', 'bound'}}", None
        toks = parse_path(b["path"], root.nvars)
        bound = parse_decimal(b["bound"])
        if not bound > 0:
            return False, f"{what}: box {b['path']!r} claims a non-positive bound", None
        key, f = "", root
        for a, side in toks:
            key += f"{a}{side}"
            if key not in cache:
                lo, hi = f.split(a)
                pre = key[:-2]
                cache[pre + f"{a}L"], cache[pre + f"{a}H"] = lo, hi
            f = cache[key]
        if not all(c.is_finite() and c > bound for c in f.coeffs):
            worst = min(f.coeffs, key=lambda c: c.lower())
            return False, (f"{what}: box {b['path']!r}: a Bernstein coefficient ({worst.str(8)}) is not "
                           f"above the claimed bound {b['bound']}"), None
        paths.append(b["path"])
        min_bound = bound if min_bound is None or bound < min_bound else min_bound
    if not check_partition(paths, root.nvars):
        return False, f"{what}: the boxes do not partition the domain exactly (gap or overlap)", None
    return True, "", min_bound
