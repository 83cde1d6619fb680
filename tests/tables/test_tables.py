import json

import mpmath
import numpy as np
import pytest

from ccproof.errors import TableNotFoundError, ValenceError
from ccproof.tables.build import build_table
from ccproof.tables.format import (
    TableFormatError,
    arb_from_json,
    available_tables,
    read_table_json,
    table_path,
)
from ccproof.tables.numeric import load_table


def test_all_published_tables_present_and_hash_valid():
    av = available_tables()
    assert [k for k in av if isinstance(k, int)] == list(range(3, 101))
    assert ">=40" in av
    for k in (3, 17, 100):
        obj = read_table_json(table_path(k))
        assert obj["valence"] == k


@pytest.mark.parametrize("k", [3, 5, 8, 40])
def test_committed_tables_are_what_the_code_builds(k):
    """The committed table files are in sync with the derivation (regenerated bit for bit)."""
    built = build_table(k)
    stored = read_table_json(table_path(k))
    assert built["hash"] == stored["hash"]


def test_N_matches_the_prototype_readings_R8():
    """Reading R8 of docs/readings.md (independent double-precision prototype): N = 3 for k <= 5, 4 for 6..13,
    5 for k >= 14; the paper's N = 3 fails from k = 6 on."""
    for k in range(3, 101):
        N = load_table(k).N
        want = 3 if k <= 5 else (4 if k <= 13 else 5)
        assert N == want, k
    obj = read_table_json(table_path({"min": 40}))
    assert obj["derived"]["N"] == 5


def _exact_phi_mp(k, name, s, t, dps=50):
    """Evaluate a piece at (s, t) from the *exact* B-spline forms with mpmath (independent path:
    string integer forms -> mpmath, de Boor by explicit basis functions)."""
    mpmath.mp.dps = dps
    obj = read_table_json(table_path(k))
    c = mpmath.cos(2 * mpmath.pi / k)
    lam = (5 + c + mpmath.sqrt((1 + c) * (9 + c))) / 16

    def val(form):
        A, B, D = form
        ev = lambda co: sum(mpmath.mpf(a) * c**i for i, a in enumerate(co))
        return (ev(A) + ev(B) * lam) / ev(D)

    def basis(x):
        return [(1 - x) ** 3 / 6, (3 * x**3 - 6 * x**2 + 4) / 6, (-3 * x**3 + 3 * x**2 + 3 * x + 1) / 6, x**3 / 6]

    net = obj["exact"]["bspline"][name]
    bs, bt = basis(mpmath.mpf(s)), basis(mpmath.mpf(t))
    return [sum(bs[i] * bt[j] * val(net[i][j][d]["form"]) for i in range(4) for j in range(4)) for d in range(2)]


@pytest.mark.parametrize("k", [3, 7, 29])
def test_arb_bezier_nets_enclose_the_exact_patch(k):
    """Bezier corner control points are patch values: compare arb balls with the exact value."""
    obj = read_table_json(table_path(k))
    for name in ("P1", "P2", "P3"):
        for (i, j), (s, t) in {(0, 0): (0, 0), (3, 0): (1, 0), (0, 3): (0, 1), (3, 3): (1, 1)}.items():
            want = _exact_phi_mp(k, name, s, t)
            for d in range(2):
                ball = arb_from_json(obj["arb"]["bezier"][name][i][j][d], obj["prec"])
                lo, hi = mpmath.mpf(ball.lower().str(60, radius=False)), mpmath.mpf(ball.upper().str(60, radius=False))
                assert lo - mpmath.mpf("1e-45") <= want[d] <= hi + mpmath.mpf("1e-45")
                assert ball.rad() < 1e-30  # tight


def _bezier_eval(net, s, t):
    from math import comb

    bs = np.array([comb(3, i) * s**i * (1 - s) ** (3 - i) for i in range(4)])
    bt = np.array([comb(3, i) * t**i * (1 - t) ** (3 - i) for i in range(4)])
    return np.einsum("i...,j...,ijd->...d", bs, bt, net)


@pytest.mark.parametrize("k", [3, 4, 5, 6, 13, 50, 100])
def test_det_jacobian_bound_against_dense_sampling(k):
    tab = load_table(k)
    obj = read_table_json(table_path(k))
    lo = float(arb_from_json(obj["derived"]["det_jacobian_phi"]["min_lower"], 128).lower().mid())
    s, t = np.meshgrid(np.linspace(0, 1, 201), np.linspace(0, 1, 201), indexing="ij")
    h = 1e-6
    mins = []
    for p in range(3):
        net = tab.bezier[p]
        du = (_bezier_eval(net, np.clip(s + h, 0, 1), t) - _bezier_eval(net, np.clip(s - h, 0, 1), t))
        du /= (np.clip(s + h, 0, 1) - np.clip(s - h, 0, 1))[..., None]
        dv = (_bezier_eval(net, s, np.clip(t + h, 0, 1)) - _bezier_eval(net, s, np.clip(t - h, 0, 1)))
        dv /= (np.clip(t + h, 0, 1) - np.clip(t - h, 0, 1))[..., None]
        mins.append((4 * (du[..., 0] * dv[..., 1] - du[..., 1] * dv[..., 0])).min())
    sampled = min(mins)
    assert lo > 0
    assert lo <= sampled + 1e-7
    assert sampled - lo < 1e-3 * max(1, sampled)


def test_valence_four_table_is_the_identity():
    tab = load_table(4)
    assert tab.lam == 0.5
    from fractions import Fraction as F

    u0 = {0: F(1, 2), 1: F(1, 2), 2: F(0)}
    v0 = {0: F(0), 1: F(1, 2), 2: F(1, 2)}
    for p in range(3):
        for i in range(4):
            for j in range(4):  # the nearest doubles to the exact identity control points
                assert tuple(tab.bezier[p, i, j]) == (float(u0[p] + F(i, 6)), float(v0[p] + F(j, 6)))


def test_tampered_table_is_rejected(tmp_path):
    obj = json.loads(table_path(5).read_text())
    obj["float64"]["lam"] = 0.55
    bad = tmp_path / "k005.json"
    bad.write_text(json.dumps(obj))
    with pytest.raises(TableFormatError, match="hash mismatch"):
        read_table_json(bad)
    obj["schema"] = "ccproof.table/0"
    bad.write_text(json.dumps(obj))
    with pytest.raises(TableFormatError, match="unknown schema"):
        read_table_json(bad)
    bad.write_text("{not json")
    with pytest.raises(TableFormatError, match="not a readable JSON"):
        read_table_json(bad)


def test_missing_table_lists_what_exists():
    with pytest.raises(TableNotFoundError, match=r"k = 3\.\.100"):
        load_table(200)
    with pytest.raises(ValenceError):
        load_table(2)
    with pytest.raises(ValenceError):
        load_table(float("nan"))


def test_arb_json_round_trip_encloses():
    from flint import arb, ctx

    from ccproof.tables.format import arb_to_json

    with ctx.workprec(128):
        x = arb(1) / 3 + arb("0 +/- 1e-35")
        y = arb_from_json(arb_to_json(x), 128)
        assert y.contains(x)
        assert y.rad() < 2 * x.rad() + arb("1e-38")
