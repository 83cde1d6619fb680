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
MAX_PATH_TOKENS = 32  # the prover splits at most 14 times (prover.MAX_DEPTH)
MAX_BOXES = 8192  # per certificate; the published ones hold at most 707
MAX_JSON_VALUES = 8 * MAX_BOXES  # every JSON value of a certificate (a box is 3); the published: at most 2,863


def check_size(cert):
    """Refuse a parsed certificate above the size limits before anything else is read from it: at most
    :data:`MAX_JSON_VALUES` JSON values and :data:`MAX_BOXES` boxes (dicts with a ``path``) in all.
    With paths of at most :data:`MAX_PATH_TOKENS` halvings, these bound the verifier's time and memory
    (docs/certificates.md, "Bounds").

    Parameters
    ----------
    cert : object (parsed JSON)

    Returns
    -------
    int
        The number of boxes.

    Raises
    ------
    CertificateError

    Examples
    --------
    >>> check_size({"parts": {"P2": [{"path": "", "bound": "1"}]}})
    1
    >>> check_size([[0] * 9] * MAX_BOXES)
    Traceback (most recent call last):
    ...
    ccproof.certify.verify.errors.CertificateError: certificate: more than 65536 JSON values
    """
    values, boxes, stack = 0, 0, [cert]
    while stack:
        v = stack.pop()
        values += 1
        if values > MAX_JSON_VALUES:
            raise CertificateError(f"certificate: more than {MAX_JSON_VALUES} JSON values")
        if isinstance(v, dict):
            boxes += "path" in v
            stack.extend(v.values())
        elif isinstance(v, list):
            stack.extend(v)
    if boxes > MAX_BOXES:
        raise CertificateError(f"certificate: more than {MAX_BOXES} boxes")
    return boxes


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


def box_tree(paths, nvars):
    """The split tree of the leaf paths, when they partition the root box exactly; else a
    :class:`CertificateError` naming the path (no gap, no overlap, no duplicate, one axis per node).

    A cheap combinatorial check, done before any arithmetic. Nodes are dicts: a leaf ``{"leaf": i}``
    (index into ``paths``), an inner node ``{"axis": a, "L": node, "H": node}``. A valid tree of B
    leaves has B - 1 inner nodes, so replaying it (:func:`check_boxes`) splits B - 1 times.

    Parameters
    ----------
    paths : sequence of str
        Box paths (:func:`parse_path`).
    nvars : int

    Returns
    -------
    dict
        The root node.

    Examples
    --------
    >>> box_tree(["0L", "0H1L", "0H1H"], 2)["H"]["axis"]
    1
    >>> box_tree(["0L", "0H1L"], 2)
    Traceback (most recent call last):
    ...
    ccproof.certify.verify.errors.CertificateError: the boxes do not partition ...: no box covers '0H1H' (gap)
    """
    if not paths:
        raise CertificateError("no boxes")
    root = {}
    for i, p in enumerate(paths):
        node = root
        for a, side in parse_path(p, nvars):
            if "leaf" in node:
                raise CertificateError(f"the boxes do not partition the domain exactly: {p!r} lies inside "
                                       f"{paths[node['leaf']]!r} (overlap)")
            if node.setdefault("axis", a) == a:  # ints
                node = node.setdefault(side, {})
            else:
                raise CertificateError(f"the boxes do not partition the domain exactly: {p!r} splits axis {a} "
                                       f"where another box splits axis {node['axis']} (overlap)")
        if node:
            raise CertificateError(f"the boxes do not partition the domain exactly: {p!r} contains or repeats "
                                   "another box (overlap)")
        node["leaf"] = i
    stack = [(root, "")]
    while stack:
        node, prefix = stack.pop()
        if "leaf" not in node:
            for side in "LH":
                key = f"{prefix}{node['axis']}{side}"
                if side not in node:
                    raise CertificateError(f"the boxes do not partition the domain exactly: no box covers {key!r} "
                                           "(gap)")
                stack.append((node[side], key))
    return root


def check_partition(paths, nvars):
    """True iff the leaf paths partition the root box exactly (no gap, no overlap): :func:`box_tree`.

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
    try:
        box_tree(paths, nvars)
    except CertificateError:
        return False
    return True


def read_boxes(boxes, nvars, where):
    """Check a box list before any arithmetic: a non-empty list of ``{"path", "bound"}`` with bounded
    paths and decimals, each bound > 0, the paths partitioning the root box (:func:`box_tree`).

    Parameters
    ----------
    boxes : object (a list from JSON)
    nvars : int
    where : str
        Named in the error.

    Returns
    -------
    (dict, list of fmpq)
        The split tree and the bounds, in the order of ``boxes``.

    Raises
    ------
    CertificateError

    Examples
    --------
    >>> tree, bounds = read_boxes([{"path": "0L", "bound": "0.5"}, {"path": "0H", "bound": "1e-3"}], 1, "star")
    >>> tree["axis"], bounds
    (0, [1/2, 1/1000])
    >>> read_boxes([{"path": "0L", "bound": "0.5"}], 1, "star")
    Traceback (most recent call last):
    ...
    ccproof.certify.verify.errors.CertificateError: star: the boxes do not partition ...: no box covers '0H' (gap)
    """
    if not isinstance(boxes, list) or not boxes:
        raise CertificateError(f"{where}: boxes must be a non-empty list")
    if len(boxes) > MAX_BOXES:
        raise CertificateError(f"{where}: more than {MAX_BOXES} boxes")
    bounds = []
    for b in boxes:
        if not isinstance(b, dict) or set(b) != {"path", "bound"}:
            raise CertificateError(f"{where}: a box must be {{'path', 'bound'}}")
        bound = parse_decimal(b["bound"])
        if not bound > 0:
            raise CertificateError(f"{where}: box {str(b['path'])[:40]!r} claims a non-positive bound")
        bounds.append(bound)
    try:
        tree = box_tree([b["path"] for b in boxes], nvars)
    except CertificateError as exc:
        raise CertificateError(f"{where}: {exc}") from None
    return tree, bounds


def check_boxes(root, boxes, what):
    """Replay the split paths on the Bernstein form ``root``; each box's coefficients must all be
    certainly > its claimed bound > 0 (de Casteljau halvings of :class:`ccproof.rigorous.BernsteinForm`).

    The partition is checked first (:func:`read_boxes`), then the split tree is replayed depth-first with
    a stack: each inner node is split once (shared prefixes once), a form is dropped as soon as it is
    split, and the stack holds at most one pending sibling per level, so the memory is O(depth x form
    size) and the time O(number of boxes x (one split + one check)).

    Parameters
    ----------
    root : BernsteinForm
        Ball coefficients on the root box.
    boxes : list of dict ``{"path": str, "bound": decimal str}``
        Must partition the root box (:func:`box_tree`).
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
    try:
        tree, bounds = read_boxes(boxes, root.nvars, what)
    except CertificateError as exc:
        return False, str(exc), None
    stack = [(tree, root)]
    while stack:
        node, f = stack.pop()
        if "leaf" not in node:
            lo, hi = f.split(node["axis"])
            stack.append((node["H"], hi))
            stack.append((node["L"], lo))
            continue
        b, bound = boxes[node["leaf"]], bounds[node["leaf"]]
        if not all(c.is_finite() and c > bound for c in f.coeffs):
            worst = min(f.coeffs, key=lambda c: c.lower())
            return False, (f"{what}: box {b['path']!r}: a Bernstein coefficient ({worst.str(8)}) is not "
                           f"above the claimed bound {b['bound']}"), None
    return True, "", min(bounds)
