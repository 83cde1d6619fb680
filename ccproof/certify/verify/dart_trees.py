"""The trees of a ``dart:>=K0`` record: read, check they partition their roots, replay them (trusted).

docs/certificates.md, "Every dart K >= K0 in one certificate", writes a cover of a region as

    tree := { "grid":   [INT, ...],      -- the root box cut into equal cells first (<= 64 per axis)
              "leaves": [ { "cell": [INT, ...], "path": PATH, "bound": DECIMAL }
                        | { "cell": [INT, ...], "path": PATH, "outside": true } ] }

A PATH names a box inside its cell by halvings (:func:`.replay.parse_path`). :func:`read_tree` checks,
before any arithmetic, that the leaves of every cell partition it exactly (:func:`.replay.box_tree`, per
cell), that every cell has leaves, that every bound has the sign its claim needs, and that an ``outside``
leaf (the middle region only, variables (s, w) with h = s w) lies where s_lo w_lo > 1/K0 exactly, so that no
K >= K0 meets it. :func:`replay_tree` then evaluates each leaf with the region's evaluator (an arb
enclosing the region's scaled quantity on the box, :class:`.dart_regularity.RegularityBox`,
:class:`.dart_curves.CurveBox`) and accepts the bound only when the enclosure certainly lies beyond it.
It never searches.
"""

from __future__ import annotations

from flint import arb, fmpq

from .dart_curves import CurveModels
from .dart_regularity import RegularityModels
from .errors import CertificateError
from .record import exact_keys
from .replay import box_tree, parse_decimal, parse_path

MAX_GRID = 64  # cells per axis
MAX_LEAVES = 8192  # leaves per record (docs/certificates.md, "Bounds")


def _cell_box(root, grid, cell):
    return [(lo + (hi - lo) * fmpq(c, g), lo + (hi - lo) * fmpq(c + 1, g)) for (lo, hi), g, c in zip(root, grid, cell)]


def leaf_box(root, grid, cell, path):
    """The exact box of a leaf: its grid cell of the root, then the path's halvings.

    Parameters
    ----------
    root : list of (fmpq, fmpq)
    grid, cell : list of int
    path : str

    Returns
    -------
    list of (fmpq, fmpq)

    Examples
    --------
    >>> from flint import fmpq
    >>> leaf_box([(fmpq(0), fmpq(1)), (fmpq(0), fmpq(1, 2))], [4, 1], [1, 0], "0H1L")
    [(3/8, 1/2), (0, 1/4)]
    """
    box = _cell_box(root, grid, cell)
    for axis, side in parse_path(path, len(root)):
        lo, hi = box[axis]
        mid = (lo + hi) / 2
        box[axis] = (lo, mid) if side == "L" else (mid, hi)
    return box


def read_tree(tree, root, where, sign, k0=None, outside=False):
    """Check a tree against its root before any arithmetic; its leaves as (box, bound or None).

    Parameters
    ----------
    tree : object (parsed JSON)
    root : list of (fmpq, fmpq)
        The region's root box, fixed by the region (never by the file).
    where : str
        Named in every error.
    sign : int
        +1: every bound must be > 0 (a lower bound); -1: < 0 (an upper bound).
    k0 : int, optional
        K0, for ``outside`` leaves.
    outside : bool
        Whether the region admits ``outside`` leaves (the middle: axes (s, w), h = s w).

    Returns
    -------
    list of (list of (fmpq, fmpq), fmpq or None)

    Raises
    ------
    CertificateError

    Examples
    --------
    >>> from flint import fmpq
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
    n = len(root)
    if not isinstance(tree, dict) or set(tree) != {"grid", "leaves"}:
        raise CertificateError(f"{where}: a tree must be {{'grid', 'leaves'}}")
    grid, leaves = tree["grid"], tree["leaves"]
    if (not isinstance(grid, list) or len(grid) != n
            or not all(type(g) is int and 1 <= g <= MAX_GRID for g in grid)):
        raise CertificateError(f"{where}: grid must be {n} ints in 1..{MAX_GRID}")
    if not isinstance(leaves, list) or not leaves or len(leaves) > MAX_LEAVES:
        raise CertificateError(f"{where}: leaves must be a non-empty list of at most {MAX_LEAVES}")
    cells = {}
    for leaf in leaves:
        if not isinstance(leaf, dict) or set(leaf) not in ({"cell", "path", "bound"}, {"cell", "path", "outside"}):
            raise CertificateError(f"{where}: a leaf must be {{'cell', 'path', 'bound'}} or {{'cell', 'path', "
                                   "'outside'}}")
        cell = leaf["cell"]
        if (not isinstance(cell, list) or len(cell) != n
                or not all(type(c) is int and 0 <= c < g for c, g in zip(cell, grid))):
            raise CertificateError(f"{where}: cell {str(cell)[:40]} is not a cell of the grid {grid}")
        if not isinstance(leaf["path"], str):
            raise CertificateError(f"{where}: a path must be a string")
        cells.setdefault(tuple(cell), []).append(leaf["path"])
    total = 1
    for g in grid:
        total *= g
    if len(cells) != total:
        raise CertificateError(f"{where}: {total - len(cells)} of the {total} grid cells have no leaf (gap)")
    for cell, paths in cells.items():
        try:
            box_tree(paths, n)
        except CertificateError as exc:
            raise CertificateError(f"{where}: cell {list(cell)}: {exc}") from None
    out = []
    h0 = fmpq(1, k0) if k0 is not None else None
    for leaf in leaves:
        box = leaf_box(root, grid, leaf["cell"], leaf["path"])
        if "outside" in leaf:
            if leaf["outside"] is not True or not outside:
                raise CertificateError(f"{where}: an 'outside' leaf is allowed only in the middle region, as true")
            if not box[0][0] * box[1][0] > h0:
                raise CertificateError(f"{where}: 'outside' leaf {leaf['path']!r} of cell {leaf['cell']} meets "
                                       f"h = s w <= 1/{k0} (s_lo w_lo = {box[0][0] * box[1][0]})")
            out.append((box, None))
            continue
        bound = parse_decimal(leaf["bound"])
        if not (bound > 0 if sign > 0 else bound < 0):
            raise CertificateError(f"{where}: leaf {leaf['path']!r} of cell {leaf['cell']} claims a bound of the "
                                   f"wrong sign ({bound}; the claim is {'> 0' if sign > 0 else '< 0'})")
        out.append((box, bound))
    return out


def replay_tree(leaves, evaluate, sign, where):
    """Evaluate every leaf and accept its bound only when the enclosure certainly lies beyond it.

    Parameters
    ----------
    leaves : list of (box, fmpq or None)
        From :func:`read_tree` (``None``: an ``outside`` leaf, not evaluated).
    evaluate : callable (box) -> arb
        The region's evaluator.
    sign : int
        +1: the enclosure must be >= the bound; -1: <= the bound.
    where : str

    Returns
    -------
    (int, fmpq or None)
        The leaves evaluated, and the least bound in absolute value.

    Raises
    ------
    CertificateError
        Naming the first leaf whose bound is not reached (or whose evaluation fails).

    Examples
    --------
    >>> from flint import arb, fmpq
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
        ok = val >= arb(bound) if sign > 0 else val <= arb(bound)
        if not ok:
            raise CertificateError(f"{where}: the leaf {box} claims {bound}, the enclosure is {val}")
        count += 1
        least = bound if least is None or abs(bound) < abs(least) else least
    return count, least


def replay_map(parts, k0, sig_lo, sig_hi, hints, s0, layer, winding, prec):
    """Step 6 of a ``dart:>=K0`` record: every tree of R, T and W (``parts``: the record's ``parts``) read
    against the root its region fixes and replayed on the trusted models, sigma box by sigma box.

    Parameters
    ----------
    parts : object (parsed JSON)
        ``{"regularity": cover, "transversal": cover, "winding": signs}`` (docs/certificates.md).
    k0 : int
    sig_lo, sig_hi : fmpq
        The bracket of sigma(K) (shown by the spectrum and the eigenvector lemma, not here).
    hints : TaylorHints
    s0 : fmpq
        The bulk is s in [s0, 1/2]; the middle is (s, w) in [0, s0] x [0, 1/layer].
    layer : int
        T >= 3: the layer quadrants 0..T-1.
    winding : (fmpq, fmpq)
        (s_a, s_b), s0 < s_a < s_b < 1/2.
    prec : int

    Returns
    -------
    dict
        {list name: (leaves evaluated, least bound)}.

    Raises
    ------
    CertificateError
        Naming the list and the leaf.

    Examples
    --------
    >>> from flint import fmpq
    >>> from ccproof.certify.verify.dart_family import TaylorHints
    >>> hints = TaylorHints(fmpq(1, 32), 12, 10, 12, 14, 24)
    >>> replay_map({}, 101, fmpq(4484, 1000), fmpq(44935, 10000), hints, fmpq(1, 20), 3, (fmpq(1, 4), fmpq(7, 20)), 128)
    Traceback (most recent call last):
    ...
    ccproof.certify.verify.errors.CertificateError: parts: ...
    """
    s_a, s_b = winding
    half, h0 = fmpq(1, 2), fmpq(1, k0)
    if not (0 < s0 < s_a < s_b < half and layer >= 3 and h0 < hints.r and s0 / layer < hints.r):
        raise CertificateError("regions: need 0 < s0 < s_a < s_b < 1/2, T >= 3, 1/K0 < r and s0/T < r")
    exact_keys(parts, ("regularity", "transversal", "winding"), "parts")
    reg, tra, win = parts["regularity"], parts["transversal"], parts["winding"]
    for name, obj in (("regularity", reg), ("transversal", tra)):
        exact_keys(obj, ("bulk", "middle", "layer"), name)
    exact_keys(win, ("Y<0 bulk", "X>0 bulk", "Y>0 bulk", "Y<0 middle", "Y<0 layer"), "winding")
    quads = tuple(str(q) for q in range(layer))
    for name, obj in (("regularity layer", reg["layer"]), ("transversal layer", tra["layer"]),
                      ("winding Y<0 layer", win["Y<0 layer"])):
        exact_keys(obj, quads, name)
    bulk, middle = [(s0, half), (fmpq(0), h0)], [(fmpq(0), s0), (fmpq(0), fmpq(1, layer))]
    hroot = [(fmpq(0), h0)]
    lists = [("R bulk", reg["bulk"], bulk, "bulk", 1, False), ("R middle", reg["middle"], middle, "middle", 1, True),
             ("T bulk", tra["bulk"], bulk, "transversal_bulk", 1, False),
             ("T middle", tra["middle"], middle, "transversal_middle", 1, True),
             ("Y<0 bulk", win["Y<0 bulk"], [(s0, s_a), (fmpq(0), h0)], "y_bulk", -1, False),
             ("X>0 bulk", win["X>0 bulk"], [(s_a, s_b), (fmpq(0), h0)], "x_bulk", 1, False),
             ("Y>0 bulk", win["Y>0 bulk"], [(s_b, half), (fmpq(0), h0)], "y_bulk", 1, False),
             ("Y<0 middle", win["Y<0 middle"], middle, "y_middle", -1, True)]
    for q in quads:
        lists += [(f"R layer {q}", reg["layer"][q], hroot, ("layer", int(q)), 1, False),
                  (f"T layer {q}", tra["layer"][q], hroot, ("transversal_layer", int(q)), 1, False),
                  (f"Y<0 layer {q}", win["Y<0 layer"][q], hroot, ("y_layer", int(q)), -1, False)]
    read = {}
    total = 0
    for name, trees, root, _, sign, out in lists:  # every tree checked before any model is built
        if not isinstance(trees, list) or len(trees) != hints.sigma_boxes:
            raise CertificateError(f"{name}: one tree per sigma box ({hints.sigma_boxes}) is needed")
        read[name] = [read_tree(t, root, f"{name}, sigma box {i}", sign, k0=k0, outside=out)
                      for i, t in enumerate(trees)]
        total += sum(len(x) for x in read[name])
    if total > MAX_LEAVES:
        raise CertificateError(f"more than {MAX_LEAVES} leaves in all ({total})")
    models = (RegularityModels(sig_lo, sig_hi, hints, layer, prec), CurveModels(sig_lo, sig_hi, hints, layer, prec))
    summary = {}
    for i in range(hints.sigma_boxes):
        boxes = (models[0].sigma_box(i), models[1].sigma_box(i))
        for name, _, _, method, sign, _ in lists:
            owner = boxes[0] if name.startswith("R ") else boxes[1]
            if isinstance(method, tuple):
                fn, q = getattr(owner, method[0]), method[1]

                def evaluate(box, fn=fn, q=q):
                    return fn(q, box)
            else:
                evaluate = getattr(owner, method)
            count, least = replay_tree(read[name][i], evaluate, sign, f"{name}, sigma box {i}")
            old = summary.get(name, (0, None))
            best = least if old[1] is None or (least is not None and abs(least) < abs(old[1])) else old[1]
            summary[name] = (old[0] + count, best)
    return summary
