"""Every comparison in the trusted base whose arb meaning could differ from the intended one is reviewed.

On arb balls ``==``, ``!=``, ``<``, ``>`` mean "certainly": ``x != 0`` is False for a ball containing 0,
so ``if x != 0`` silently drops it; ``not (x < y)`` is not ``x >= y``; ``.contains(0)`` is "possibly 0".
This scans the trusted modules for the three risky shapes (``!=``, ``not`` applied to a comparison,
``.contains(``) and fails on any that is not on the reviewed list below, with the reason it is sound.
"""

import ast
from pathlib import Path

import ccproof

ROOT = Path(ccproof.__file__).parent
TRUSTED = sorted([*(ROOT / "certify" / "verify").glob("*.py"), *(ROOT / "rigorous").glob("*.py")])

#: names that hold ints, strings or exact fmpq in the trusted modules (sizes, precisions, axes, keys)
EXACT_NAMES = {"prec", "N", "D", "deg", "k", "k0", "n", "i", "r", "d", "axis", "section", "t", "ints", "lo_hi",
               "piece_list", "pieces", "b", "mats", "shape", "coeffs", "point", "box", "exps", "axes", "degrees"}
EXACT_ATTRS = {"nvars", "shape", "box", "MAX_VARS", "ncols"}

#: (file, source text of the node) -> why its meaning on balls is the intended one
REVIEWED = {
    ("registry.py", 'fam != "smooth"'): "str (family names)",
    ("registry.py", "schema != TAGGED_SCHEMA"): "str (schema names)",
    ("registry.py", "st != st_t"): "str (statements)",
    ("dart_tail.py", "not z < L + 2"): "refuses unless |omega s| < L + 2 certainly: conservative",
    ("dart_family.py", "B * Ms[-1] + c[0] * eye != fmpq_mat(n, n)"): "fmpq_mat (exact)",
    ("dart_spectrum.py", "_X * N[i] - sum((B_AT_1[i, k] * N[k] for k in range(6)), fmpq_poly(0)) != p * kap[i]"):
        "fmpq_poly (exact)",
    ("dart_spectrum.py", "not box.cos() < 0"): "refuses unless cos sigma < 0 certainly on the bracket: conservative",
    ("dart_spectrum.py", "sum((psi[i] * adj[i][j] for i in range(6)), fmpq_poly(0)) % q != 0"): "fmpq_poly (exact)",
    # a guard that the family's code matches the lemma's identities (it FAILs a flipped alpha); the lemma is
    # proved by the exact checks and the sign change, not by this test
    ("dart_spectrum.py", "z.contains(0)"): "a guard (above), never the proof",
    ("tagged.py", "a != b"): "dicts of fmpq rows (exact)",
    ("dart_spectrum.py", "det2 != w * w * lam * lam - (5 * w * w + c2) * lam / 8 + w * w / 16"): "fmpq_mpoly (exact)",
    ("dart_spectrum.py", "64 * lam * g_num != 64 * lam * det2 + n2 * w * w"): "fmpq_mpoly (exact)",
    ("dart_spectrum.py", "8 * P * 2 != -(2 * lam - lc)"): "fmpq_mpoly (exact)",
    ("dart_spectrum.py", "not abs(y) < fmpq(9, 10)"): "refuses unless |y| < 9/10 certainly: conservative",
    ("dart_spectrum.py", "not T > 0"): "refuses unless T > 0 certainly: conservative",
    ("dart_spectrum.py", "not 4 * arb(sig_r) < pi * k0"): "refuses unless certainly: conservative",
    ("dart_spectrum.py", "_det3(b0(lam, h)) != (lam - 1) * P + h * mode0_parts(lam, h)[1]"): "fmpq_mpoly (exact)",
    ("dart_spectrum.py", "rem != 0"): "fmpq_poly (exact)",
    ("dart_spectrum.py", "key != _C"): "tuples",
    # the sign of a square root is a choice (the expressions are even in it); _cot_far then refuses unless
    # the imaginary part is certainly positive
    ("dart_spectrum.py", "not psi.imag > 0"): "a choice of root, re-checked by _cot_far: conservative",
    ("dart_spectrum.py", "not phi.imag > 0"): "a choice of root, re-checked by _cot_far: conservative",
    ("dart_spectrum.py", "x != 0"): "fmpq weights (exact)",
    ("dart_spectrum.py", "not tau1 > 0"): "fmpq (exact)",
    ("dart_spectrum.py", "not m > 0"): "refuses unless m > 0 certainly: conservative",
    ("dart_spectrum.py", "not -1 <= key[1] <= 1"): "ints",
    ("tagged.py", "not spec[0] <= obj <= spec[1]"): "ints",
    ("dart_tail.py", 'field_of(cert, "statement", str, "certificate") != "C1"'): "strings",
    ("dart_tail.py", 'g["map"]["orientation"] != 1'): "ints",
    ("dart_tail.py", "not fmpq(1, k0) < hints.r <= fmpq(1, 8)"): "fmpq (exact)",
    ("dart_family.py", "got != n_at(x)"): "lists of fmpq (exact)",
    ("tagged_modes.py", "not ((1 + c) * (9 + c)).real > 0"): "refuses unless certainly off the cut: conservative",
    ("dart_zeros.py", "(s * p) % _M3 != 1"): "fmpq_poly (exact)",
    ("dart_zeros.py", "w != 0"): "fmpq Bernstein weights (exact)",
    ("injectivity.py", 'param["variable"] != "lam"'): "strings",
    ("replay.py", '_TOKEN.sub("", path) != ""'): "strings",
    ("bernstein.py", "not lo < hi"): "box endpoints are exact fmpq (check_box converts them)",
    ("statement.py", "den.contains(0)"): "refuses to divide when the denominator may vanish (possibly 0 is intended)",
    ("replay.py", "not bound > 0"): "bound is an exact fmpq",
    ("bernstein.py", "not 0 < t < 1"): "t is an exact split fraction",
    ("taylor.py", "other.prec != self.prec"): "precisions are ints",
    ("interval.py", "(l, m) != (0, 0)"): "ints",
    ("injectivity.py", "ends[i][1] != ends[i + 1][0]"): "fmpq (exact decimals)",
    ("injectivity.py", "not a < b"): "fmpq (exact decimals)",
    ("interval.py", "not (all(c > 0 for c in db) or all(c < 0 for c in db))"): "fmpq Bernstein coefficients",
    ("tagged.py", "S[i, j] != 0"): "fmpq_mat entries (exact)",
    ("tagged.py", "out.setdefault(key, rel) != rel"): "dicts of fmpq rows (exact)",
    ("tagged.py", "not abs(t[0]) < 1"): "fails unless every eigenvalue is certainly inside the unit disc: conservative",
    ("tagged_c1.py", "g != max(below)"): "fmpq (exact roots of the crease block)",
    ("tagged_c1.py", "not arb(g) < beta"): "fails unless gamma < beta certainly: conservative",
    ("tagged_c1.py", 'c != "x"'): "strings",
    ("tagged_c1.py", "leave != 0"): "fmpq (exact crease values)",
    ("tagged_c1.py", 'fam != "dart"'): "strings",
    ("tagged_c1.py", "v != 0"): "fmpq (exact decimals; (S - lam) v in Q)",
    ("tagged_c1.py", "not abs(t[0]) < beta"): "counts as a Jordan block that could reach beta unless certainly "
                                                     "below (or as an eigenvalue not below beta): conservative",
    ("tagged_c1.py", "ev[ia][2] != 1"): "ints (multiplicities)",
    ("tagged_c1.py", "sum(1 for t in ev if t[1] == tg.ONE) != 1"): "ints (a count of exact factors)",
    ("tagged_c1.py", "ev[ib][2] != 1"): "ints (multiplicities)",
    ("tagged_c1.py", "not abs(t[0]) < 1"): "collects every eigenvalue possibly on or outside the unit circle; "
                                               "one (the exact 1 of the crease block or S_E) is allowed: conservative",
    ("tagged_c1.py", "u[i, 0] != 0"): "fmpq_mat entries (exact)",
    ("tagged_c1.py", "not 0 <= pivot < m"): "ints",
    ("tagged_c1.py", "not arb(g) < ev[ib][0].real"): "fails unless gamma < beta certainly: conservative",
    ("tagged_map.py", 'fam != "dart"'): "strings",
    ("tagged.py", "w != 0"): "fmpq rule weights (exact)",
    ("tagged_modes.py", "not abs(f[pivot]) > 0"): "fails unless the pivot value is certainly non-zero: conservative",
    ("spectrum.py", "w != 0"): "fmpq rule weights (exact)",
    ("tagged_c1.py", "one[0][1] != 1"): "fmpq or None (the exact value of a rational eigenvalue)",
    ("tagged_c1.py", "not ev[ia][0].real >= beta"): "fails unless alpha >= beta certainly: conservative",
    ("tagged_modes.py", "B * K != K * out[-1]"): "fmpq_mat (exact)",
    ("tagged_modes.py", "image != {_reflect(d, q): x for (d, q), x in ring_stencil()[i].items()}"):
        "dicts of fmpq weights with tuple keys (exact)",
    ("tagged_modes.py", "_ring_row(p[1], p[2:], fold) != {j: x for j, x in rows[i].items() if j not in cp}"):
        "dicts of fmpq weights (exact)",
    ("tagged_modes.py", "ring != {j: x for j, x in rows[i].items() if j != 0}"): "dicts of fmpq weights (exact)",
    ("tagged_modes.py", "R[r, c] != 0"): "fmpq_mat entries (exact)",
    ("tagged_modes.py", "x != 0"): "fmpq folded weights (exact)",
    ("tagged_c1.py", "not l1.real > l2.real"): "fails unless lam1 > lam2 certainly: conservative",
    ("tagged_modes.py", "rows[refl[i]] != {refl[j]: x for j, x in rows[i].items()}"): "dicts of fmpq weights (exact)",
    ("tagged_modes.py", "j != 0"): "ints (column indices)",
    ("tagged_modes.py", "SE[a, b] != 0"): "fmpq_mat entries (exact)",
    ("maps.py", "not (hi < BREAKS[p] or (p < 3 and lo > BREAKS[p + 1]))"): (
        "keeps a piece unless the hull is certainly outside it: conservative"),
    ("tagged_limit.py", "C != crease_block(fam, WINDOW[1])"): "fmpq_mat (exact)",
    ("tagged_limit.py", "blocks[0] != blocks[1]"): "tuples of fmpq_mat (exact)",
    ("tagged_limit.py", "Bi * R != R * B"): "fmpq_mat (w is an exact rational)",
    ("tagged_limit.py", "not step < abs(h0)"): "fails unless the arc's image certainly misses 0: "
                                                         "conservative",
    ("tagged_limit.py", "g != 0"): "fmpq (exact decimal)",
    ("tagged_limit.py", "sum(row.values(), fmpq(0)) != 1"): "fmpq (exact)",
    ("tagged_limit.py", "croots.count(1) != 1"): "ints (fmpq roots compared exactly)",
    ("tagged_limit.py", "not lam_of(arb(1)) < 1"): "fails unless lam(1) < 1 certainly: conservative",
    ("tagged_limit.py", "not arb(g) < b0"): "fails unless gamma < beta certainly: conservative",
}


def _obviously_exact(node):
    if isinstance(node, (ast.Constant, ast.Tuple, ast.Set, ast.List, ast.SetComp)):
        return True
    if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id in {"len", "set", "list"}:
        return True
    if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) and node.func.attr in EXACT_ATTRS:
        return True
    if isinstance(node, ast.Attribute) and node.attr in EXACT_ATTRS:
        return True
    if isinstance(node, ast.BinOp):
        return _obviously_exact(node.left) and _obviously_exact(node.right)
    if isinstance(node, ast.Subscript):
        return _obviously_exact(node.value)
    return isinstance(node, ast.Name) and node.id in EXACT_NAMES


def _compare_is_exact(node):
    return any(_obviously_exact(x) and not isinstance(x, ast.Constant) for x in [node.left, *node.comparators]) or (
        all(isinstance(x, ast.Constant) or _obviously_exact(x) for x in [node.left, *node.comparators]))


def _risky(tree, src):
    for node in ast.walk(tree):
        if isinstance(node, ast.Compare) and any(isinstance(op, ast.NotEq) for op in node.ops):
            if not _compare_is_exact(node):
                yield ast.get_source_segment(src, node)
        elif isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.Not) and isinstance(node.operand, ast.Compare):
            if not _compare_is_exact(node.operand):
                yield ast.get_source_segment(src, node)
        elif isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) and node.func.attr == "contains":
            yield ast.get_source_segment(src, node)


def test_every_risky_comparison_in_the_trusted_base_is_reviewed():
    unreviewed = []
    for f in TRUSTED:
        src = f.read_text()
        for seg in _risky(ast.parse(src), src):
            if (f.name, seg) not in REVIEWED:
                unreviewed.append(f"{f.relative_to(ROOT)}: {seg}")
    assert not unreviewed, "review these comparisons on arb balls (add them to REVIEWED):\n" + "\n".join(unreviewed)


def test_the_scanner_finds_the_truncate_bug_shape():
    src = ("def f(x):\n    if x != 0:\n        return 1\n    if not (x < 1):\n        return 2\n"
           "    return x.contains(0)\n")
    assert len(list(_risky(ast.parse(src), src))) == 3
