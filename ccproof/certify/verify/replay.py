"""Replaying the hints of a certificate (trusted): one format, a split tree given by its leaves, each a box named by
halvings (:func:`parse_path`) with a claimed bound; a box list (:func:`read_boxes`) is one tree, a grid tree
(:func:`read_tree`) one per grid cell. Each tree must partition its root (:func:`box_tree`) before any arithmetic,
its cost is charged against the certificate's budget, and it is replayed without search (docs/certificates.md)."""

import re
from contextvars import ContextVar
from decimal import Decimal
from math import prod

from flint import arb, fmpq

from .errors import CertificateError

_TOKEN = re.compile(r"([0-3])([LH])")
_DECIMAL = re.compile(r"(-?)([0-9]+)(?:\.([0-9]+))?(?:e(-?[0-9]+))?")
MAX_DECIMAL_CHARS = 64  # the prover writes at most ~20
MAX_EXPONENT = 400
MAX_PATH_TOKENS = 32  # the prover splits at most 14 times (prover.MAX_DEPTH)
MAX_BOXES = 8192  # per certificate; the published ones hold at most 707
MAX_GRID = 64  # cells per axis of a grid tree
MAX_JSON_VALUES = 8 * MAX_BOXES  # every JSON value of a certificate (a box is 3); the published: at most 2,863
MAX_REPLAY_WORK = 250_000_000  # per certificate, about 4 s of CPU (:func:`replay_work`; the published: 81 million)
_SPENT = ContextVar("replay work spent on the current certificate", default=None)
_PARTITION = "the boxes do not partition the domain exactly"


def check_size(cert):
    """The number of boxes (dicts with a ``path``) of a parsed certificate, refused above :data:`MAX_JSON_VALUES`
    JSON values or :data:`MAX_BOXES` boxes before anything else is read; opens the certificate's replay budget.

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
    _SPENT.set([0])  # a new certificate: its box lists share one budget until close_budget()
    return boxes


def close_budget():
    """End the replay budget :func:`check_size` opened (a box list checked alone has the whole budget)."""
    _SPENT.set(None)


def replay_work(form, nboxes):
    """The cost of replaying ``nboxes`` boxes on ``form`` in products of a split (docs/certificates.md, "Bounds"):
    B - 1 splits of 2 S (d + 1), B checks of 16 S (S the form's size, d its largest degree), doubled above 512 bits.

    >>> from ccproof.rigorous import BernsteinForm
    >>> replay_work(BernsteinForm((6, 6), [1] * 36, prec=128), 3)  # 2 splits of 2 x 36 x 6, 3 checks of 36
    2592
    """
    size = len(form.coeffs)
    ops = (nboxes - 1) * 2 * size * (max(form.degrees) + 1) + 16 * nboxes * size
    return ops * (2 if (form.prec or 0) > 512 else 1)


def charge_replay(work, what):
    """Add ``work`` to the certificate's spending; refuse, before any split, beyond :data:`MAX_REPLAY_WORK`."""
    spent = _SPENT.get()
    total = work + (spent[0] if spent is not None else 0)
    if total > MAX_REPLAY_WORK:
        raise CertificateError(f"{what}: the box lists need {total:,} coefficient operations in all, beyond the "
                               f"budget of {MAX_REPLAY_WORK:,} (docs/certificates.md, \"Bounds\")")
    if spent is not None:
        spent[0] = total


def parse_decimal(s):
    """The exact fmpq of a decimal string of at most :data:`MAX_DECIMAL_CHARS` characters, exponent within
    +-:data:`MAX_EXPONENT`.

    >>> parse_decimal("-15e-4"), parse_decimal("0.25")
    (-3/2000, 1/4)
    """
    if not isinstance(s, str) or len(s) > MAX_DECIMAL_CHARS:
        raise CertificateError(f"a decimal must be a string of at most {MAX_DECIMAL_CHARS} characters: "
                               f"{str(s)[:40]!r}")
    m = _DECIMAL.fullmatch(s)
    if m is None:
        raise CertificateError(f"{s!r} is not a decimal string")
    if abs(int(m.group(4) or 0)) > MAX_EXPONENT:
        raise CertificateError(f"decimal {s!r}: exponent beyond +-{MAX_EXPONENT}")
    return fmpq(*Decimal(s).as_integer_ratio())


def parse_path(path, nvars):
    """The halvings ``(axis, side)`` of a box path of at most :data:`MAX_PATH_TOKENS` tokens ``[0-3][LH]``.

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
    """The split tree of the leaf paths when they partition the root box exactly (no gap, no overlap, one axis per
    node), else a :class:`CertificateError` naming the path: a leaf ``{"leaf": i}``, an inner node ``{"axis": a,
    "L": node, "H": node}`` (B leaves, B - 1 splits). Combinatorial, before any arithmetic.

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
                raise CertificateError(f"{_PARTITION}: {p!r} lies inside {paths[node['leaf']]!r} (overlap)")
            if node.setdefault("axis", a) == a:  # ints
                node = node.setdefault(side, {})
            else:
                raise CertificateError(f"{_PARTITION}: {p!r} splits axis {a} where another box splits axis "
                                       f"{node['axis']} (overlap)")
        if node:
            raise CertificateError(f"{_PARTITION}: {p!r} contains or repeats another box (overlap)")
        node["leaf"] = i
    stack = [(root, "")]
    while stack:
        node, prefix = stack.pop()
        for side in "LH" if "leaf" not in node else "":
            key = f"{prefix}{node['axis']}{side}"
            if side not in node:
                raise CertificateError(f"{_PARTITION}: no box covers {key!r} (gap)")
            stack.append((node[side], key))
    return root


def check_partition(paths, nvars):
    """Do the leaf paths partition the root box exactly (:func:`box_tree`)?"""
    try:
        return bool(box_tree(paths, nvars))
    except CertificateError:
        return False


def _tree(paths, nvars, where):
    try:
        return box_tree(paths, nvars)
    except CertificateError as exc:
        raise CertificateError(f"{where}: {exc}") from None


def _leaf_list(leaves, keysets, where):
    """``leaves`` if a non-empty list of at most :data:`MAX_BOXES` objects, each with one of the key sets."""
    if not isinstance(leaves, list) or not leaves or len(leaves) > MAX_BOXES:
        raise CertificateError(f"{where}: the boxes must be a non-empty list of at most {MAX_BOXES}")
    if not all(isinstance(b, dict) and set(b) in keysets for b in leaves):
        raise CertificateError(f"{where}: a box must be {' or '.join(map(str, map(sorted, keysets)))}")
    return leaves


def _bound(leaf, where, sign):
    """A leaf's claimed bound, of the sign its claim needs (``sign`` +1: > 0, -1: < 0)."""
    bound = parse_decimal(leaf["bound"])
    if not (bound > 0 if sign > 0 else bound < 0):
        raise CertificateError(f"{where}: box {str(leaf['path'])[:40]!r} claims a "
                               f"{'non-positive' if sign > 0 else 'non-negative'} bound ({bound}): the wrong sign")
    return bound


def read_boxes(boxes, nvars, where):
    """``(split tree, bounds)`` of a box list ``[{"path", "bound"}]``, each bound > 0, checked before any
    arithmetic (the partition: :func:`box_tree`).

    >>> tree, bounds = read_boxes([{"path": "0L", "bound": "0.5"}, {"path": "0H", "bound": "1e-3"}], 1, "star")
    >>> tree["axis"], bounds
    (0, [1/2, 1/1000])
    >>> read_boxes([{"path": "0L", "bound": "0.5"}], 1, "star")
    Traceback (most recent call last):
    ...
    ccproof.certify.verify.errors.CertificateError: star: the boxes do not partition ...: no box covers '0H' (gap)
    """
    bounds = [_bound(b, where, 1) for b in _leaf_list(boxes, [{"path", "bound"}], where)]
    return _tree([b["path"] for b in boxes], nvars, where), bounds


def check_boxes(root, boxes, what):
    """``(ok, reason, least bound)``: on every box of the list (:func:`read_boxes`, then charged) the Bernstein
    form ``root`` split along the box's path has all coefficients certainly above the claimed bound. Depth-first:
    each inner node split once, one pending sibling per level (memory O(depth x form size)).

    1 + x on [0, 1]: the halves have Bernstein coefficients (1, 3/2) and (3/2, 2):

    >>> from ccproof.rigorous import BernsteinForm
    >>> f = BernsteinForm((2,), [1, 2], prec=53)
    >>> check_boxes(f, [{"path": "0L", "bound": "0.9"}, {"path": "0H", "bound": "1.4"}], "test")
    (True, '', 9/10)
    >>> check_boxes(f, [{"path": "0L", "bound": "1.1"}, {"path": "0H", "bound": "1.4"}], "test")[0]
    False
    """
    try:
        tree, bounds = read_boxes(boxes, root.nvars, what)
        charge_replay(replay_work(root, len(boxes)), what)
    except CertificateError as exc:
        return False, str(exc), None
    stack = [(tree, root)]
    while stack:
        node, f = stack.pop()
        if "leaf" not in node:
            low, high = f.split(node["axis"])
            stack += [(node["H"], high), (node["L"], low)]
        elif not all(c.is_finite() and c > bounds[node["leaf"]] for c in f.coeffs):
            box, worst = boxes[node["leaf"]], min(f.coeffs, key=lambda c: c.lower())
            return False, (f"{what}: box {box['path']!r}: a Bernstein coefficient ({worst.str(8)}) is not above the "
                           f"claimed bound {box['bound']}"), None
    return True, "", min(bounds)


def leaf_box(root, grid, cell, path):
    """The exact box of a leaf: its cell of the ``grid`` on the box ``root``, then the path's halvings.

    >>> leaf_box([(fmpq(0), fmpq(1)), (fmpq(0), fmpq(1, 2))], [4, 1], [1, 0], "0H1L")
    [(3/8, 1/2), (0, 1/4)]
    """
    box = [(lo + (hi - lo) * fmpq(c, g), lo + (hi - lo) * fmpq(c + 1, g)) for (lo, hi), g, c in zip(root, grid, cell)]
    for axis, side in parse_path(path, len(root)):
        lo, hi = box[axis]
        box[axis] = (lo, (lo + hi) / 2) if side == "L" else ((lo + hi) / 2, hi)
    return box


def _grid_cells(tree, n, where):
    """The grid, the leaves and {cell: leaf paths} of a grid tree, every key and cell checked, no cell empty."""
    if not isinstance(tree, dict) or set(tree) != {"grid", "leaves"}:
        raise CertificateError(f"{where}: a tree must be {{'grid', 'leaves'}}")
    grid = tree["grid"]
    if not isinstance(grid, list) or len(grid) != n or not all(type(g) is int and 1 <= g <= MAX_GRID for g in grid):
        raise CertificateError(f"{where}: grid must be {n} ints in 1..{MAX_GRID}")
    leaves = _leaf_list(tree["leaves"], [{"cell", "path", "bound"}, {"cell", "path", "outside"}], where)
    cells = {}
    for leaf in leaves:
        cell = leaf["cell"]
        if not isinstance(cell, list) or len(cell) != n or not all(type(c) is int and 0 <= c < g
                                                                    for c, g in zip(cell, grid)):
            raise CertificateError(f"{where}: cell {str(cell)[:40]} is not a cell of the grid {grid}")
        cells.setdefault(tuple(cell), []).append(leaf["path"])
    if len(cells) != prod(grid):
        raise CertificateError(f"{where}: {prod(grid) - len(cells)} of the {prod(grid)} grid cells have no leaf (gap)")
    return grid, leaves, cells


def read_tree(tree, root, where, sign, k0=None, outside=False):
    """The leaves ``(box, bound or None)`` of a grid tree on ``root`` (fixed by the region, never by the file),
    checked before any arithmetic: each cell partitioned by its leaves (:func:`box_tree`), each bound of the sign the
    claim needs (``sign`` +1: > 0, -1: < 0); an ``outside`` leaf (only where ``outside``: axes (s, w), h = s w) must
    have s_lo w_lo > 1/k0 exactly, so that no K >= k0 meets it.

    >>> root = [(fmpq(0), fmpq(1)), (fmpq(0), fmpq(1))]
    >>> t = {"grid": [2, 1], "leaves": [{"cell": [0, 0], "path": "", "bound": "0.5"},
    ...                                 {"cell": [1, 0], "path": "1L", "bound": "0.25"},
    ...                                 {"cell": [1, 0], "path": "1H", "bound": "0.25"}]}
    >>> [box for box, _ in read_tree(t, root, "demo", 1)][2]
    [(1/2, 1), (1/2, 1)]
    >>> del t["leaves"][2]
    >>> read_tree(t, root, "demo", 1)
    Traceback (most recent call last):
    ...
    ccproof.certify.verify.errors.CertificateError: demo: cell [1, 0]: the boxes do not partition ...: no box ... (gap)
    """
    grid, leaves, cells = _grid_cells(tree, len(root), where)
    for cell, paths in cells.items():
        _tree(paths, len(root), f"{where}: cell {list(cell)}")
    out = []
    for leaf in leaves:
        box = leaf_box(root, grid, leaf["cell"], leaf["path"])
        if "bound" in leaf:
            out.append((box, _bound(leaf, f"{where}: cell {leaf['cell']}", sign)))
        elif leaf["outside"] is not True or not outside:
            raise CertificateError(f"{where}: an 'outside' leaf is allowed only in the middle region, as true")
        elif not box[0][0] * box[1][0] > fmpq(1, k0):
            raise CertificateError(f"{where}: 'outside' leaf {leaf['path']!r} of cell {leaf['cell']} meets "
                                   f"h = s w <= 1/{k0} (s_lo w_lo = {box[0][0] * box[1][0]})")
        else:
            out.append((box, None))
    return out


def replay_tree(leaves, evaluate, sign, where):
    """``(leaves evaluated, least |bound|)``: each leaf of :func:`read_tree` (``outside`` ones skipped) whose
    enclosure ``evaluate(box)`` (an arb) certainly lies beyond its bound (``sign`` +1: >=, -1: <=); else a
    :class:`CertificateError` naming the first leaf that fails.

    >>> leaves = [([(fmpq(0), fmpq(1))], fmpq(1, 2)), ([(fmpq(1), fmpq(2))], fmpq(3, 2))]
    >>> replay_tree(leaves, lambda box: arb(box[0][0] + 1).union(arb(box[0][1] + 1)), 1, "demo")
    (2, 1/2)
    >>> replay_tree(leaves, lambda box: arb(box[0][0]).union(arb(box[0][1])), 1, "demo")
    Traceback (most recent call last):
    ...
    ccproof.certify.verify.errors.CertificateError: demo: the leaf [(0, 1)] claims 1/2, the enclosure is ...
    """
    count, least = 0, None
    for box, bound in leaves:
        if bound is None:
            continue
        try:
            val = evaluate(box)
        except (ZeroDivisionError, ValueError, CertificateError) as exc:
            raise CertificateError(f"{where}: the leaf {box} cannot be evaluated: {exc}") from None
        if not isinstance(val, arb):
            raise CertificateError(f"{where}: the evaluator returned no arb")
        if not (val >= arb(bound) if sign > 0 else val <= arb(bound)):
            raise CertificateError(f"{where}: the leaf {box} claims {bound}, the enclosure is {val}")
        count += 1
        least = bound if least is None or abs(bound) < abs(least) else least
    return count, least
