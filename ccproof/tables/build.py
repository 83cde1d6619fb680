"""Build the characteristic-map tables (writer side; docs/readings.md R2-R8, R10).

For a valence k (or the interval k >= k0) a table holds the exact nets of P1, P2, P3 (integer forms
in c and lam, valence-independent), their arb enclosures and float64 copies, and quantities derived
from them with Bernstein bounds in arb (never from floats):

* ``N``: the smallest N with Phi([0, 2^-N]^2) inside [0, 1/6)^2 (R8), with the certified upper bound
  of max Phi_x over the face used for it and, when certain, the evidence that N - 1 fails;
* ``det_jacobian_phi``: an enclosure [lower, upper] of min det J_Phi (w.r.t. the face parameter
  (u, v)) over layer 0, from Bernstein coefficients of the degree-(5,5) Jacobian (adaptive split);
* ``max_coordinate``: enclosure of max Phi_x (= max Phi_y by symmetry) over the face;
* ``square_inside_image``: certified True when the image of the outer boundary u = 1, v = 1 avoids
  [0, 1/2]^2 (with injectivity of Phi on the face this puts [0,1/2]^2 inside Phi([0,1]^2), R7);
* ``max_norm_outer_boundary``: upper bound of |Phi| on the outer boundary;
* ``spectral``: the certified gap of 1 > lam = lam > |lam_3| (see :mod:`ccproof.algebra.spectrum`).
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

from ccproof.algebra.characteristic_map import symbolic_bspline_nets
from ccproof.algebra.field import integer_form_string
from ccproof.algebra.specialize import characteristic_map_patches, valence_interval
from ccproof.tables.format import PATCHES, SCHEMA, arb_to_json, content_hash, table_path
from ccproof.valence import Valence, ValenceLike

DEFAULT_PREC = 128
DEFAULT_K_RANGE = range(3, 101)
DEFAULT_INTERVAL_K0 = 40


def _forms(x, y):
    return [{"form": list(map(list, x.integer_form())), "text": integer_form_string(x.integer_form())},
            {"form": list(map(list, y.integer_form())), "text": integer_form_string(y.integer_form())}]


def _exact_section():
    # only the B-spline nets: the Bezier nets are the fixed rational linear image of them
    sym = symbolic_bspline_nets()
    return {"bspline": {n: [[_forms(*p) for p in row] for row in net] for n, net in sym.items()}}


def _derived(nets_bez, lam, prec):
    """Certified derived quantities from the arb Bezier nets (see module docstring)."""
    from flint import arb, ctx, fmpq

    from ccproof.rigorous import BernsteinForm, jacobian_determinant, range_enclosure

    with ctx.workprec(prec):
        det_lo: Any = None  # arb balls, once the first patch is done
        det_hi: Any = None
        max_lo: Any = None
        max_hi: Any = None
        for name in PATCHES:
            net = nets_bez[name]
            X = BernsteinForm((4, 4), [net[i][j][0] for i in range(4) for j in range(4)], prec=prec)
            Y = BernsteinForm((4, 4), [net[i][j][1] for i in range(4) for j in range(4)], prec=prec)
            det = jacobian_determinant([X, Y]) * arb(4)  # d(s,t)/d(u,v) = 2 * 2
            lo, hi = _refine_min(det, depth=6)
            det_lo = lo if det_lo is None else min(det_lo, lo, key=_key)
            det_hi = hi if det_hi is None else min(det_hi, hi, key=_key)
            mlo, mhi = _refine_max(X, depth=6)
            max_lo = mlo if max_lo is None else max(max_lo, mlo, key=_key)
            max_hi = mhi if max_hi is None else max(max_hi, mhi, key=_key)
        # N (R8): smallest N >= 1 with lam^N * max_hi < 1/6
        sixth = arb(fmpq(1, 6))
        N = 1
        while not (lam**N * max_hi < sixth):
            N += 1
            if N > 64:
                raise AssertionError("no N found: enclosures too wide")
        minimal = N == 1 or bool(lam ** (N - 1) * max_lo >= sixth)
        # outer boundary curves: P1 s=1, P2 s=1, P2 t=1, P3 t=1 (Bezier rows of the nets)
        curves = [
            [nets_bez["P1"][3][j] for j in range(4)],
            [nets_bez["P2"][3][j] for j in range(4)],
            [nets_bez["P2"][i][3] for i in range(4)],
            [nets_bez["P3"][i][3] for i in range(4)],
        ]
        half = arb(fmpq(1, 2))
        inside = all(_curve_avoids_square(cv, half, depth=12) for cv in curves)
        norm_hi: Any = None
        for cv in curves:
            xs = BernsteinForm((4,), [p[0] for p in cv], prec=prec)
            ys = BernsteinForm((4,), [p[1] for p in cv], prec=prec)
            hi = range_enclosure(xs * xs + ys * ys)[1].sqrt()
            norm_hi = hi if norm_hi is None else max(norm_hi, hi, key=_key)
    return {
        "N": N,
        "N_is_minimal": bool(minimal),
        "N_condition": "lam^N * max_face(Phi_x) < 1/6  (so Phi([0,2^-N]^2) lies in [0,1/6)^2)",
        "det_jacobian_phi": {"min_lower": arb_to_json(det_lo), "min_upper": arb_to_json(det_hi),
                             "positive": bool(det_lo > 0)},
        "max_coordinate": {"lower": arb_to_json(max_lo), "upper": arb_to_json(max_hi)},
        "square_inside_image": bool(inside),
        "max_norm_outer_boundary": {"upper": arb_to_json(norm_hi)},
    }


def _key(x):
    return x.mid()


def _refine_min(form, depth):
    """Enclosure (lo, hi) of the minimum of a Bernstein form over its box (adaptive split).

    lo: min over leaves of the smallest coefficient's lower end (certified lower bound);
    hi: the smallest corner coefficient (a true value of the polynomial), an upper bound."""
    from ccproof.rigorous import range_enclosure

    leaves = [(form, 0)]
    best_hi = None
    lo_all = None
    while leaves:
        f, d = leaves.pop()
        lo, _ = range_enclosure(f)
        corners = _corner_values(f)
        chi = min(corners, key=_key)
        best_hi = chi if best_hi is None else min(best_hi, chi, key=_key)
        if d < depth and not _close(lo, best_hi):
            axis = d % 2
            a, b = f.split(axis)
            leaves += [(a, d + 1), (b, d + 1)]
        else:
            lo_all = lo if lo_all is None else min(lo_all, lo, key=_key)
    return lo_all, best_hi


def _refine_max(form, depth):
    from ccproof.rigorous import range_enclosure

    leaves = [(form, 0)]
    best_lo = None
    hi_all = None
    while leaves:
        f, d = leaves.pop()
        _, hi = range_enclosure(f)
        cmax = max(_corner_values(f), key=_key)
        best_lo = cmax if best_lo is None else max(best_lo, cmax, key=_key)
        if d < depth and not _close(best_lo, hi):
            a, b = f.split(d % 2)
            leaves += [(a, d + 1), (b, d + 1)]
        else:
            hi_all = hi if hi_all is None else max(hi_all, hi, key=_key)
    return best_lo, hi_all


def _close(lo, hi):
    """Stop refining when the bracket is within 1e-4 (relative to max(1, |hi|))."""
    from flint import arb

    gap = (arb(hi) - arb(lo)).upper()
    scale = max(abs(arb(hi)).upper(), arb(1), key=lambda z: z.mid())
    return bool(gap <= scale * arb("1e-4"))


def _corner_values(f):
    """The Bernstein coefficients at the box corners (values of the polynomial there)."""
    import itertools

    shape = f.shape
    vals = []
    for corner in itertools.product(*[(0, n - 1) for n in shape]):
        idx = 0
        for c, n in zip(corner, shape):
            idx = idx * n + c
        vals.append(f.coeffs[idx])
    return vals


def _curve_avoids_square(curve, half, depth):
    """True when the cubic Bezier curve certainly has max(x, y) > 1/2 everywhere."""
    from flint import arb, fmpq

    if all(p[0] > half for p in curve) or all(p[1] > half for p in curve):
        return True
    if depth == 0:
        return False
    h = arb(fmpq(1, 2))
    b = [list(p) for p in curve]
    left, right = [b[0]], [b[3]]
    pts = b
    for _ in range(3):
        pts = [[(p[i] + q[i]) * h for i in range(2)] for p, q in zip(pts, pts[1:])]
        left.append(pts[0])
        right.append(pts[-1])
    right.reverse()
    return _curve_avoids_square(left, half, depth - 1) and _curve_avoids_square(right, half, depth - 1)


def build_table(k: ValenceLike, prec: int = DEFAULT_PREC) -> dict[str, Any]:
    """Build the certified characteristic-map table of a valence (see module docstring, docs/tables.md).

    Parameters
    ----------
    k : int or str or dict or Valence
        A valence k >= 3, or an interval in any spelling of :class:`ccproof.valence.Valence`
        (``">=40"``, ``{"min": 40}``).
    prec : int
        Bits of the arb enclosures (default 128).

    Returns
    -------
    dict
        The table (schema ``ccproof.table/1``), hashed; :func:`write_table` writes it and
        :func:`ccproof.tables.numeric.load_table` reads it back.

    Examples
    --------
    >>> t = build_table(4, prec=64)
    >>> t["valence"], t["derived"]["N"], t["float64"]["lam"], t["hash"] == content_hash(t)
    (4, 3, 0.5, True)
    """
    from flint import arb, ctx, fmpq

    from ccproof.algebra.specialize import subdominant_eigenvalue
    from ccproof.algebra.spectrum import spectral_conditions

    v = Valence.parse(k)
    interval = v.interval
    bez = characteristic_map_patches(v, "bezier", "arb", prec)
    bsp = characteristic_map_patches(v, "bspline", "arb", prec)
    if interval:
        k0 = v.k
        c, lam = valence_interval(k0, prec)
        with ctx.workprec(prec):
            # all k >= k0: (28 lam - 3)/k - 2(1 - c) lam > 0 follows from 28 lam - 3 > 4 pi^2 lam / k0
            ok = bool(28 * lam - 3 > 4 * arb.pi() ** 2 * lam / k0)
        spectral = {"argument": "Fourier blocks for all k >= k0 (docs/readings.md R2)",
                    "mode0_inequality_certified": ok, "ok": ok}
    else:
        from ccproof.algebra.specialize import cos_2pi_over_k

        c = cos_2pi_over_k(v.k, "arb", prec)
        lam = subdominant_eigenvalue(v.k, "arb", prec)
        sc = spectral_conditions(v.k, prec)
        spectral = {"argument": "Fourier blocks (exact charpoly check in tests)", "gap": arb_to_json(sc["gap"]),
                    "ok": sc["ok"]}
    derived = _derived(bez, lam, prec)
    with ctx.workprec(prec):
        assert bool(lam > arb(fmpq(1, 3)))

    def arb_net(nets):
        return {n: [[[arb_to_json(p[0]), arb_to_json(p[1])] for p in row] for row in net]
                for n, net in nets.items()}

    def float_net(nets):
        return {n: [[[float(p[0].mid()), float(p[1].mid())] for p in row] for row in net]
                for n, net in nets.items()}

    table = {
        "schema": SCHEMA,
        "valence": v.to_json(),
        "c_definition": "cos(2*pi/k)" + (" for every integer k >= k0" if interval else ""),
        "lam_definition": "(5 + c + sqrt((1 + c)*(9 + c)))/16, the larger root of 16 lam^2 - 2(5 + c) lam + 1",
        "frame": "normalized: e0 -> (1,0), e1 -> (0,1), Phi(1,0) = (1,0) (docs/readings.md R3)",
        "patches": {"P1": "[1/2,1]x[0,1/2]", "P2": "[1/2,1]x[1/2,1]", "P3": "[0,1/2]x[1/2,1]",
                    "local_parameters": "s along u, t along v, net[i][j] with i along s"},
        "prec": prec,
        "c": arb_to_json(c),
        "lam": arb_to_json(lam),
        "exact": _exact_section(),
        "arb": {"bezier": arb_net(bez), "bspline": arb_net(bsp)},
        "float64": {"bezier": float_net(bez), "bspline": float_net(bsp), "lam": float(lam.mid())},
        "derived": derived,
        "spectral": spectral,
    }
    table["hash"] = content_hash(table)
    return table


def write_table(k, directory=None, prec=DEFAULT_PREC):
    """Build and write the table of ``k`` (:func:`build_table`); returns the path.

    The file is the JSON of docs/tables.md, keys sorted, ASCII.

    Parameters
    ----------
    k : int or str or dict or Valence
        Valence k >= 3 or an interval ``">=K0"``.
    directory : str or pathlib.Path, optional
        Target folder (default ``certificates_dir() / "tables"``, see
        :func:`ccproof.tables.format.table_path`).
    prec : int, optional
        Bits of precision of the arb data.

    Returns
    -------
    pathlib.Path

    Examples
    --------
    Building a table takes seconds (exact symbolic arithmetic), so this example is not run:

    >>> p = write_table(5, "tables")                                    # doctest: +SKIP
    >>> read_table_json(p)["hash"] == load_table(5).hash                 # doctest: +SKIP
    True
    """
    table = build_table(k, prec)
    path = table_path(table["valence"], directory)
    path.parent.mkdir(parents=True, exist_ok=True)
    # under a temporary name first, renamed when complete: an interrupted write leaves no partial table
    tmp = Path(path).with_name(f".tmp-{os.getpid()}-{Path(path).name}")
    try:
        tmp.write_text(json.dumps(table, indent=1, sort_keys=True) + "\n", encoding="ascii")
        os.replace(tmp, path)
    finally:
        tmp.unlink(missing_ok=True)
    return path
