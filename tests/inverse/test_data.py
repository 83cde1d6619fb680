"""The per-valence data of ccproof.inverse.data comes from the certified tables, never from sympy.

Cross-checks: the implicit boundary polynomials interpolated in arb from the tables' nets against the
symbolic Sylvester resultants of ccproof.inverse.implicit (an independent computation over Q(c, lam));
the nets of a valence without its own table (evaluated from the tables' exact forms) against the
published table of that valence; and a fresh interpreter running a characteristic-parameterization
evaluation never imports sympy, ccproof.algebra or the resultant code.
"""

import json
import subprocess
import sys

import numpy as np
import pytest

from ccproof.inverse.data import implicit_boundary, inside_sign, valence_data
from ccproof.tables import numeric


@pytest.mark.parametrize("k", [3, 4, 5, 8, 29])
@pytest.mark.parametrize("edge", ["P1:s=0", "P1:t=1"])
def test_implicit_boundary_contains_the_symbolic_resultant(k, edge):
    from ccproof.inverse import implicit

    ours = implicit_boundary(k, edge)
    exact = implicit.implicit_polynomial(k, edge, "arb")
    assert set(exact) <= set(ours)
    # same polynomial up to a positive factor and the orientation: compare oriented and normalized
    s_ours, s_exact = inside_sign(k, edge, ours), implicit.inside_sign(k, edge)
    m_ours = max(abs(float(x.mid())) for x in ours.values())
    m_exact = max(abs(float(x.mid())) for x in exact.values())
    for ab, x in ours.items():
        e = float(exact[ab].mid()) / m_exact * s_exact if ab in exact else 0.0
        assert abs(float(x.mid()) / m_ours * s_ours - e) < 1e-14, (k, edge, ab)


def test_untabulated_valence_matches_its_table():
    # evaluate k = 7 from the exact forms (as for a valence without a table) and compare with its table
    evaluated = numeric.characteristic_arb(7, 200)      # prec above the table's 128 bits: the evaluated path
    published = numeric.characteristic_arb(7)
    assert evaluated.hash is None and published.hash is not None
    assert evaluated.lam.overlaps(published.lam)
    for name in ("P1", "P2", "P3"):
        for i in range(4):
            for j in range(4):
                for c in range(2):
                    assert evaluated.bezier[name][i][j][c].overlaps(published.bezier[name][i][j][c]), (name, i, j)


def test_untabulated_float_nets_are_the_bspline_to_bezier_image():
    t = numeric.characteristic_nets(1000)
    assert t.hash is None
    M = np.array(numeric.BSPLINE_TO_BEZIER_6) / 6.0
    np.testing.assert_allclose(np.einsum("ia,jb,pabc->pijc", M, M, t.bspline), t.bezier, atol=1e-15)
    c = np.cos(2 * np.pi / 1000)
    assert abs(t.lam - (5 + c + np.sqrt((1 + c) * (9 + c))) / 16) < 1e-15


def test_valence_data_for_a_valence_without_table():
    D = valence_data(1000)
    assert D.k == 1000 and np.isfinite(D.G).all() and D.gamma_sign in (-1, 1)


def test_numerics_never_import_sympy_or_the_resultant_code():
    code = (
        "import sys, json\n"
        "from ccproof.reparam import limit_surface\n"
        "from ccproof.mesh.examples import k_regular_disk\n"
        "from ccproof.inverse import inverse_characteristic_map, characteristic_map\n"
        "for k in (3, 5):\n"
        "    S = limit_surface(k_regular_disk(k, 2))\n"
        "    S.evaluate([0, 1, 2, 3], [0.1, 0.3, 0.5, 0.7], [0.2, 0.4, 0.6, 0.1], 1,"
        " parameterization='characteristic')\n"
        "for k in (3, 5, 1000):  # 1000: no table of its own\n"
        "    inverse_characteristic_map(k, [0.3], [0.1])\n"
        "    characteristic_map(k, [0.3], [0.1])\n"
        "print(json.dumps(sorted(m for m in sys.modules if m.split('.')[0] == 'sympy'"
        " or m.startswith('ccproof.algebra') or m == 'ccproof.inverse.implicit')))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], check=True, capture_output=True, text=True,
                         timeout=300).stdout
    assert json.loads(out.strip().splitlines()[-1]) == []


@pytest.mark.parametrize("k", [3, 13, 1000])
def test_first_guess_fit_agrees_with_numpy_lstsq(k):
    from ccproof.inverse import data

    D = valence_data(k)
    g = np.linspace(-0.03, 1.03, 90)
    ss, tt = (a.ravel() for a in np.meshgrid(g, g))
    for p in range(2):
        s, t = (ss, tt) if p == 0 else (ss[ss >= tt - 0.03], tt[ss >= tt - 0.03])
        xy = data._eval_power(D.power[p], s, t)
        V = data.monomials(xy[0], xy[1], data.FIT_DEGREE).T
        ref, *_ = np.linalg.lstsq(V, np.stack([s, t], 1), rcond=None)
        assert np.abs(V @ ref - V @ D.fit[p].T).max() < 1e-9
