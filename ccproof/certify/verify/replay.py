"""Replaying the hints of a certificate: decimals, box paths, partitions, claimed bounds (trusted).

Every cover in a certificate is one format, a split tree given by its leaves (docs/certificates.md has the
grammar): a leaf names a box by halvings (a path, :func:`parse_path`) and claims a bound (a decimal). A box
list ``[{"path", "bound"}]`` is the leaves of one tree over its root box; a dart tree ``{"grid", "leaves"}``
cuts its root box into equal cells first and holds one tree per cell. Each tree is checked to partition its
root exactly (:func:`box_tree`) before any arithmetic, its cost charged against the certificate's budget
(:func:`charge_replay`), and replayed depth-first by :func:`walk`: on a Bernstein form (:func:`check_boxes`,
de Casteljau halvings) or on exact boxes handed to an evaluator (:func:`read_tree`, :func:`replay_tree`).
Sizes are bounded, so no input can make the verifier hang or crash. It never searches.
"""

from __future__ import annotations

import re
from contextvars import ContextVar

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
MAX_REPLAY_WORK = 400_000_000  # per certificate, about 6.5 s of CPU (:func:`replay_work`; the published: 81 million)
_SPENT = ContextVar("replay work spent on the current certificate", default=None)


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
    _SPENT.set([0])  # a new certificate: its box lists share one budget until close_budget()
    return boxes


def close_budget():
    """End the current certificate's replay budget (opened by :func:`check_size`): a box list checked
    afterwards, outside a certificate, has the whole budget alone."""
    _SPENT.set(None)


def replay_work(form, nboxes):
    """The cost of replaying ``nboxes`` boxes on ``form``, known before any split, in coefficient products
    of a split (about 60 million a second at 128 bits on the machine of docs/certificates.md, "Bounds"):
    B - 1 splits (each two halves of S (d + 1) products, S the form's size, d its largest degree) and B
    checks of S coefficients (a comparison in Python costs about 16 products), doubled above 512 bits.

    Examples
    --------
    >>> from ccproof.rigorous import BernsteinForm
    >>> replay_work(BernsteinForm((6, 6), [1] * 36, prec=128), 3)  # 2 splits of 2 x 36 x 6, 3 checks of 36
    2592
    """
    size = len(form.coeffs)
    ops = (nboxes - 1) * 2 * size * (max(form.degrees) + 1) + 16 * nboxes * size
    return ops * (2 if (form.prec or 0) > 512 else 1)


def charge_replay(work, what):
    """Add ``work`` (:func:`replay_work`) to the current certificate's spending and refuse, before any
    split, when the total passes :data:`MAX_REPLAY_WORK` (a list checked alone has the whole budget)."""
    spent = _SPENT.get()
    total = work + (spent[0] if spent is not None else 0)
    if total > MAX_REPLAY_WORK:
        raise CertificateError(f"{what}: the box lists need {total:,} coefficient operations in all, beyond the "
                               f"budget of {MAX_REPLAY_WORK:,} (docs/certificates.md, \"Bounds\")")
    if spent is not None:
        spent[0] = total


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

    def leaf(i, f):
        if not all(c.is_finite() and c > bounds[i] for c in f.coeffs):
            worst = min(f.coeffs, key=lambda c: c.lower())
            return (f"{what}: box {boxes[i]['path']!r}: a Bernstein coefficient ({worst.str(8)}) is not above the "
                    f"claimed bound {boxes[i]['bound']}")
        return None
    failure = walk(tree, root, lambda f, axis: f.split(axis), leaf)
    return (False, failure, None) if failure else (True, "", min(bounds))


def walk(tree, root, split, leaf):
    """Depth-first over a split tree (:func:`box_tree`) from the state ``root`` (a form, a box): each inner
    node splits its state once (``split(state, axis)`` -> (low half, high half)), a state is dropped once
    split, and the stack holds at most one pending sibling per level. ``leaf(index, state)`` returns None
    to go on, anything else to stop: it is returned.

    Examples
    --------
    >>> seen = []
    >>> walk(box_tree(["0L", "0H0L", "0H0H"], 1), [(fmpq(0), fmpq(1))], halve, lambda i, b: seen.append((i, b)))
    >>> seen
    [(0, [(0, 1/2)]), (1, [(1/2, 3/4)]), (2, [(3/4, 1)])]
    """
    stack = [(tree, root)]
    while stack:
        node, state = stack.pop()
        if "leaf" in node:
            out = leaf(node["leaf"], state)
            if out is not None:
                return out
            continue
        lo, hi = split(state, node["axis"])
        stack.append((node["H"], hi))
        stack.append((node["L"], lo))
    return None


def halve(box, axis):
    """The two halves of an exact box (a list of (fmpq, fmpq)) along ``axis``."""
    lo, hi = box[axis]
    mid = (lo + hi) / 2
    return [*box[:axis], (lo, mid), *box[axis + 1:]], [*box[:axis], (mid, hi), *box[axis + 1:]]


def _cell_box(root, grid, cell):
    return [(lo + (hi - lo) * fmpq(c, g), lo + (hi - lo) * fmpq(c + 1, g)) for (lo, hi), g, c in zip(root, grid, cell)]


def leaf_box(root, grid, cell, path):
    """The exact box of a leaf: its grid cell of the root, then the path's halvings.

    Examples
    --------
    >>> leaf_box([(fmpq(0), fmpq(1)), (fmpq(0), fmpq(1, 2))], [4, 1], [1, 0], "0H1L")
    [(3/8, 1/2), (0, 1/4)]
    """
    box = _cell_box(root, grid, cell)
    for axis, side in parse_path(path, len(root)):
        box = halve(box, axis)[side == "H"]
    return box


def _read_grid(tree, n, where):
    if not isinstance(tree, dict) or set(tree) != {"grid", "leaves"}:
        raise CertificateError(f"{where}: a tree must be {{'grid', 'leaves'}}")
    grid, leaves = tree["grid"], tree["leaves"]
    if not isinstance(grid, list) or len(grid) != n or not all(type(g) is int and 1 <= g <= MAX_GRID for g in grid):
        raise CertificateError(f"{where}: grid must be {n} ints in 1..{MAX_GRID}")
    if not isinstance(leaves, list) or not leaves or len(leaves) > MAX_BOXES:
        raise CertificateError(f"{where}: leaves must be a non-empty list of at most {MAX_BOXES}")
    cells = {}
    for i, leaf in enumerate(leaves):
        cells.setdefault(_leaf_cell(leaf, grid, where), []).append(i)
    total = 1
    for g in grid:
        total *= g
    if len(cells) != total:
        raise CertificateError(f"{where}: {total - len(cells)} of the {total} grid cells have no leaf (gap)")
    return grid, leaves, cells


def _leaf_cell(leaf, grid, where):
    """The grid cell (a tuple) a leaf of a grid tree names, its keys and indices checked."""
    if not isinstance(leaf, dict) or set(leaf) not in ({"cell", "path", "bound"}, {"cell", "path", "outside"}):
        raise CertificateError(f"{where}: a leaf must be {{'cell', 'path', 'bound'}} or {{'cell', 'path', "
                               "'outside'}}")
    cell = leaf["cell"]
    if not isinstance(cell, list) or len(cell) != len(grid) or not all(type(c) is int and 0 <= c < g
                                                                        for c, g in zip(cell, grid)):
        raise CertificateError(f"{where}: cell {str(cell)[:40]} is not a cell of the grid {grid}")
    return tuple(cell)


def _claim(leaf, box, where, sign, k0, outside):
    """A leaf's claim: None for an ``outside`` leaf (checked to lie beyond h = 1/k0), else its bound."""
    if "outside" in leaf:
        if leaf["outside"] is not True or not outside:
            raise CertificateError(f"{where}: an 'outside' leaf is allowed only in the middle region, as true")
        if not box[0][0] * box[1][0] > fmpq(1, k0):
            raise CertificateError(f"{where}: 'outside' leaf {leaf['path']!r} of cell {leaf['cell']} meets "
                                   f"h = s w <= 1/{k0} (s_lo w_lo = {box[0][0] * box[1][0]})")
        return None
    bound = parse_decimal(leaf["bound"])
    if not (bound > 0 if sign > 0 else bound < 0):
        raise CertificateError(f"{where}: leaf {leaf['path']!r} of cell {leaf['cell']} claims a bound of the "
                               f"wrong sign ({bound}; the claim is {'> 0' if sign > 0 else '< 0'})")
    return bound


def read_tree(tree, root, where, sign, k0=None, outside=False):
    """Check a grid tree against its root before any arithmetic; its leaves as (box, bound or None).

    Every grid cell must hold leaves whose paths partition it (:func:`box_tree`); the boxes come from one
    :func:`walk` of each cell's tree over exact boxes. A bound must have the sign its claim needs (``sign``
    +1: > 0, -1: < 0); an ``outside`` leaf (only where ``outside``: the middle region, axes (s, w), h = s w)
    must lie where s_lo w_lo > 1/k0 exactly, so that no K >= k0 meets it. ``root`` is fixed by the region,
    never by the file; ``where`` is named in every error.

    Examples
    --------
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
    grid, leaves, cells = _read_grid(tree, len(root), where)
    boxes = [None] * len(leaves)
    for cell, idx in cells.items():
        try:
            tree_ = box_tree([leaves[i]["path"] for i in idx], len(root))
        except CertificateError as exc:
            raise CertificateError(f"{where}: cell {list(cell)}: {exc}") from None
        walk(tree_, _cell_box(root, grid, cell), halve, lambda j, box, idx=idx: boxes.__setitem__(idx[j], box))
    return [(box, _claim(leaf, box, where, sign, k0, outside)) for leaf, box in zip(leaves, boxes)]


def replay_tree(leaves, evaluate, sign, where):
    """Evaluate every leaf of :func:`read_tree` (``None`` bounds: ``outside``, skipped) and accept its bound
    only when the enclosure ``evaluate(box)`` (an arb) certainly lies beyond it (``sign`` +1: >=, -1: <=).
    Returns (leaves evaluated, the least bound in absolute value); raises CertificateError naming the first
    leaf whose bound is not reached or whose evaluation fails.

    Examples
    --------
    >>> from flint import arb
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
