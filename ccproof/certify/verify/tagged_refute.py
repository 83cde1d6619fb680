"""Part G of the two "not C1" witnesses that need more than a generic pair of eigenvectors (trusted).

:mod:`.tagged_c1` reads a witness net P = (x, y, z) and derives its coordinates (parts x, y, z); this
module derives, from the exact spectrum of :mod:`.tagged` alone, the spectral facts that make the net
generic, for two configurations the plain witness cannot refute (docs/tagged_c1.md, "not C1"):

* **Flip** (a dart, ``dart:2``): x, y eigenvectors of simple real eigenvalues alpha, beta of opposite
  signs, larger in modulus than every other eigenvalue but 1 (simple). S^m (x, y) = (alpha^m x,
  beta^m y), so the normal at the level-m copy p_m of a quadrant's vertex (1, 1), divided by
  |alpha beta|^m, is (-1)^m J_xy e_z + o(1) for any third coordinate of smaller eigenvalue: with
  J_xy != 0 (part F) the unit normals at p_m -> v tend to (-1)^m sign(J_xy) e_z. They have no limit
  (not normal continuous at v), and the projection onto the tangent plane has local degree
  (-1)^m sign(J_xy) at p_m, so it is injective on no neighbourhood of v (not single-sheeted). The
  same holds for every net whose alpha- and beta-coefficients a1, a2 have a1 x a2 != 0.
* **Chain** (``corner:4``): y is a generalized eigenvector of a rational beta, e = (S - beta) y != 0
  an eigenvector vanishing on the crease points, z an eigenvector of gamma = beta. Then
  S^m y = beta^m y + m beta^(m-1) e exactly, and the normal at p_m divided by m alpha^m beta^(m-1) tends
  to J_xe e_z (the other components are O(1/m) and O((beta/alpha)^m m)); with part B (ray r's limit
  curve a segment of the z-axis) a C1 surface would have n_z = 0. Generic: alpha simple and real,
  alpha > beta > 0, every Jordan block at beta of size <= 2 (dim ker (S - beta)^2 is beta's algebraic
  multiplicity; the chain's top spans (S - beta) of beta's generalized eigenspace), every other
  eigenvalue but 1 (simple) certainly smaller than beta in modulus, beta the crease block's largest
  eigenvalue below 1. A net with alpha-coefficient a1, chain coefficient b and ray-r tangent a3
  linearly independent has normals tending to +-(a1 x b)/|a1 x b|, which misses a3.
"""

from __future__ import annotations

from flint import arb, fmpq, fmpq_mat, fmpq_poly

from .tagged import crease_block, crease_points, eigenvalues, kernel_dim, sector_matrix

_ONE = fmpq_poly([-1, 1])


def same_root(t, v):
    """Is v (an fmpq, or the arb ball of an irrational root) the root t[0] of the factor t[1]?

    Examples
    --------
    >>> from ccproof.certify.verify.tagged import eigenvalues
    >>> ev = eigenvalues("dart", 2, 64)
    >>> [same_root(t, fmpq(1, 4)) for t in ev].count(True)
    1
    """
    if isinstance(v, fmpq):
        return t[1].degree() == 1 and -t[1][0] / t[1][1] == v
    return t[1].degree() > 1 and t[0].real.overlaps(v) and t[0].imag.is_zero()


def _find(ev, v, skip=()):
    return next((i for i, t in enumerate(ev) if i not in skip and same_root(t, v)), None)


def chain_top(fam, n, lam, vec):
    """(S - lam) vec exactly, or None when vec is an eigenvector (or lam is not rational).

    Examples
    --------
    >>> from ccproof.certify.verify.tagged import labels
    >>> chain_top("corner", 4, fmpq(1, 2), [fmpq(0)] * len(labels("corner", 4))) is None
    True
    """
    if not isinstance(lam, fmpq) or any(not isinstance(v, fmpq) for v in vec):
        return None
    u = sector_matrix(fam, n) * fmpq_mat([[v] for v in vec])
    top = [u[i, 0] - lam * vec[i] for i in range(len(vec))]
    return top if any(v != 0 for v in top) else None


def flip_generic(n, a, b, prec):
    """(ok, message): part G of a dart's flip witness: 1 simple; alpha and beta simple eigenvalues,
    certainly of opposite signs, each certainly larger in modulus than every other eigenvalue.

    Examples
    --------
    >>> ev = sorted(eigenvalues("dart", 2, 128), key=lambda t: -abs(t[0]).mid())
    >>> flip_generic(2, ev[1][0].real, ev[2][0].real, 128)[1][:56]
    'alpha = 0.38784688, beta = -0.28114257: alpha beta < 0, '
    >>> flip_generic(2, ev[1][0].real, fmpq(1, 4), 128)
    (False, 'alpha beta < 0 is not certain')
    """
    ev = eigenvalues("dart", n, prec)
    if sum(1 for t in ev if t[1] == _ONE) != 1:
        return False, "eigenvalue 1 is not simple"
    ia = _find(ev, a)
    ib = None if ia is None else _find(ev, b, (ia,))
    if ib is None:
        return False, "alpha or beta is not an eigenvalue (distinct from the other)"
    if ev[ia][2] != 1 or ev[ib][2] != 1:
        return False, "alpha or beta is not a simple eigenvalue"
    A, B = ev[ia][0].real, ev[ib][0].real
    if not (A > 0 and B < 0 or A < 0 and B > 0):
        return False, "alpha beta < 0 is not certain"
    others = [t for i, t in enumerate(ev) if i not in (ia, ib) and t[1] != _ONE]
    bad = [t for t in others if not (abs(t[0]) < abs(A) and abs(t[0]) < abs(B))]
    if bad:
        return False, f"an eigenvalue ({bad[0][0].str(6)}) is not certainly smaller in modulus than alpha and beta"
    top = max(others, key=lambda t: abs(t[0]).mid())[0]
    return True, (f"alpha = {A.str(8, radius=False)}, beta = {B.str(8, radius=False)}: alpha beta < 0, each simple, "
                  f"> |every other| (at most {abs(top).str(6, radius=False)}); 1 simple")


def chain_generic(fam, n, vals, tops, prec):
    """(ok, message): part G of a Jordan-chain witness (module docstring). ``vals``: the eigenvalues of
    x, y, z; ``tops``: (S - lam) applied to x, y, z (None for an eigenvector), from :func:`chain_top`.

    Examples
    --------
    >>> ev = sorted(eigenvalues("corner", 4, 128), key=lambda t: -abs(t[0]).mid())
    >>> vals = {"x": ev[1][0].real, "y": fmpq(1, 2), "z": fmpq(1, 2)}
    >>> chain_generic("corner", 4, vals, {"x": None, "y": None, "z": None}, 128)
    (False, 'y is no generalized eigenvector of a rational beta, or z or x is one')
    """
    a, b, g = vals["x"], vals["y"], vals["z"]
    if tops["y"] is None or tops["z"] is not None or tops["x"] is not None or not isinstance(b, fmpq):
        return False, "y is no generalized eigenvector of a rational beta, or z or x is one"
    if any(tops["y"][i] != 0 for i in crease_points(fam, n)):
        return False, "e = (S - beta) y is not 0 on the crease points"
    ev = eigenvalues(fam, n, prec)
    ia = _find(ev, a)
    at_b = [i for i, t in enumerate(ev) if same_root(t, b)]
    why = _chain_order(ev, ia, at_b, b) or (
        _blocks_at(fam, n, b, len(at_b)) or _below(ev, [ia, *at_b], b) or crease_top_why(crease_block(fam, n), g) or
        ("gamma is not beta" if g != b else None))
    if why:
        return False, why
    return True, (f"alpha = {ev[ia][0].real.str(8, radius=False)} > beta = {b} = gamma > |every other|, 1 simple; "
                  f"beta: algebraic multiplicity {len(at_b)}, geometric {ev[at_b[0]][3]}, Jordan blocks of size <= 2 "
                  "(dim ker (S - beta)^2 = algebraic multiplicity); e = (S - beta) y != 0, 0 on the crease points")


def _chain_order(ev, ia, at_b, b):
    """The reason 1 is not simple, alpha (index ``ia``) not simple, or alpha > beta > 0 not certain; or None."""
    return ("eigenvalue 1 is not simple" if sum(1 for t in ev if t[1] == _ONE) != 1 else
            "alpha is not a simple eigenvalue" if ia is None or ev[ia][2] != 1 or ia in at_b else
            "alpha > beta > 0 is not certain" if not (b > 0 and ev[ia][0].real > b) else None)


def _blocks_at(fam, n, b, alg):
    """None if beta's Jordan blocks have size <= 2 (dim ker (S - beta)^2 = alg, exact), else the reason."""
    return None if kernel_dim(fam, n, fmpq_poly([-b, 1]) ** 2) == alg else f"a Jordan block of size > 2 at beta = {b}"


def _below(ev, skip, b):
    bad = [t for i, t in enumerate(ev) if i not in skip and t[1] != _ONE and not abs(t[0]) < b]
    return f"an eigenvalue ({bad[0][0].str(6)}) is not certainly below beta in modulus" if bad else None


def crease_top_why(C, g):
    """None if g is the largest eigenvalue below 1 of the crease block C (its factors all linear), else the reason.

    Examples
    --------
    >>> from ccproof.certify.verify.tagged import crease_block
    >>> crease_top_why(crease_block("crease", 3), fmpq(1, 2)), crease_top_why(crease_block("crease", 3), fmpq(1, 4))
    (None, "gamma is not the crease block's largest eigenvalue below 1 (1/2)")
    """
    fac = [p for p, _ in C.charpoly().factor()[1]]
    if any(p.degree() > 1 for p in fac):
        return "the crease block has irrational eigenvalues"
    below = [-p[0] / p[1] for p in fac if -p[0] / p[1] < 1]
    if not isinstance(g, fmpq) or not below or g != max(below):
        return f"gamma is not the crease block's largest eigenvalue below 1 ({max(below) if below else None})"
    return None


def mode_lead_why(ev, ia, ib):
    """The reason 1 (from the crease block, or a dart's even part) is not simple or the entries ia, ib of the
    mode list (:func:`.tagged_modes.mode_spectrum`) do not lead (alpha >= beta > |every other|), or None."""
    one = [t for t in ev if not abs(t[0]) < 1]
    beta = ev[ib][0].real
    others = [t for i, t in enumerate(ev) if i not in (ia, ib) and t[1] != 1]
    return ("x and y are the same eigenvector (beta is not an eigenvalue distinct from alpha)" if ia == ib else
            "eigenvalue 1 is not simple" if len(one) != 1 or one[0][1] != 1 or one[0][2] not in ("C", "E") else
            "alpha >= beta is not certain" if not ev[ia][0].real >= beta else
            "an eigenvalue is not certainly below beta (lam1, lam2 not alpha, beta)"
            if not all(abs(t[0]) < beta for t in others) else None)


def mode_generic(ev, ia, ib, g, C):
    """The reason part G fails on the mode list (C the crease block), or None."""
    beta = ev[ib][0].real
    return mode_lead_why(ev, ia, ib) or crease_top_why(C, g) or (
        "gamma < beta is not certain" if not arb(g) < beta else None)


def ordering(fam, n, a, b, g, prec, generalized):
    """(ok, message): a = lam1 >= b = lam2 >= every other |lam| (1 simple, ties only with b itself), g the
    largest eigenvalue below 1 of the crease block, every eigenvalue of modulus possibly >= b non-defective,
    and g < b when z is a generalized eigenvector."""
    ev = eigenvalues(fam, n, prec)  # each root once per unit of algebraic multiplicity
    if sum(1 for t in ev if t[1] == _ONE) != 1:
        return False, "eigenvalue 1 is not simple"
    rest = [t for t in ev if t[1] != _ONE]
    ib, why = _alpha_beta(rest, a, b)
    beta = None if why else abs(rest[ib][0])
    why = why or crease_top_why(crease_block(fam, n), g) or _jordan_at(rest, beta) or (
        "z is a generalized eigenvector but gamma < beta is not certain" if generalized and not arb(g) < beta else None)
    if why:
        return False, why
    return True, (f"alpha = {_str(a)}, beta = {_str(b)}, gamma = {g}{' (Jordan chain)' if generalized else ''}; "
                  "1 simple; no Jordan block at |lam| >= beta")


def _alpha_beta(rest, a, b):
    """(index of beta in ``rest``, None), or (None, the reason): a, b eigenvalues (distinct copies),
    |a| >= |b| (or the same root), every other entry certainly below |b| or b itself."""
    ia = _find(rest, a)
    if ia is None:
        return None, "alpha is not an eigenvalue"
    ib = _find(rest, b, (ia,))
    if ib is None:
        return None, "beta is not an eigenvalue (distinct from alpha's copy)"
    if not (abs(rest[ia][0]) >= abs(rest[ib][0]) or rest[ia][1] == rest[ib][1]):
        return None, "alpha >= beta is not certain"
    beta = abs(rest[ib][0])
    bad = [t for i, t in enumerate(rest) if i not in (ia, ib) and not (same_root(t, b) or abs(t[0]) < beta)]
    if bad:
        return None, f"an eigenvalue ({bad[0][0].str(6)}) is not certainly below beta (lam1, lam2 not alpha, beta)"
    return ib, None


def _jordan_at(rest, beta):
    """The reason if an eigenvalue of modulus possibly >= beta is defective, else None."""
    defective = [t for t in rest if t[3] < t[2] and not abs(t[0]) < beta]  # Jordan blocks that could reach beta
    if defective:
        return (f"a Jordan block at |lam| >= beta: {defective[0][1]} (algebraic multiplicity {defective[0][2]}, "
                f"geometric {defective[0][3]})")
    return None


def _str(v):
    return str(v) if isinstance(v, fmpq) else v.str(8)


__all__ = ["chain_generic", "chain_top", "crease_top_why", "flip_generic", "mode_generic", "mode_lead_why",
           "ordering", "same_root"]
