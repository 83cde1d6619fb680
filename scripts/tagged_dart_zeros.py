#!/usr/bin/env python
"""Print the table of the Taylor coefficients that the dart family's models drop, each computed exactly and
found 0 (not trusted; a thin wrapper: the check itself is ccproof.certify.verify.dart_zeros, trusted).

The maths (the rows, the degree argument for the grid a, b in {1, 2, 3}, c, t, l in {1, 2}, the exact
arithmetic in Q(sqrt 5, i)[h]/(h^3)) is in the trusted module's docstring and in docs/tagged_c1.md, item 6,
part Z. ``python scripts/tagged_dart_zeros.py`` prints the number of exact zeros per row
(tagged_dart_charmap.py prints the same line as its part Z). ``stencil`` and ``flip_alpha`` perturb the rule
or the family: the checks must then find non-zero coefficients (tests/certify/test_tagged_dart_charmap_script.py,
tests/certify/test_dart_zeros.py). The ``cm`` arguments (the charmap script's module) are kept for the callers
and not used: the family's assembly is the trusted one.
"""

from __future__ import annotations

import itertools
import time

from ccproof.certify.verify import dart_zeros as _dz
from ccproof.certify.verify.dart_zeros import GRID_AB, GRID_CT  # noqa: F401 (the charmap script prints them)


def ExactFamily(cm, a, b, c, t, stencil=None, flip_alpha=False):  # noqa: N802 (was a class here)
    """The exact family at one grid point (:class:`ccproof.certify.verify.dart_zeros.ExactFamily`)."""
    return _dz.ExactFamily(a, b, c, t, stencil=stencil, flip_alpha=flip_alpha)


def check_point(cm, a, b, c, t, ells=GRID_CT, stencil=None, flip_alpha=False):
    """{row: (coefficients checked, non-zero among them)} at the grid points (a, b, c, t, l), l in ``ells``."""
    return _dz.count_zeros(points=[(a, b, c, t)], ells=ells, stencil=stencil, flip_alpha=flip_alpha)


def check_all(cm=None, stencil=None, flip_alpha=False, grid_ab=GRID_AB, grid_ct=GRID_CT):
    """{row: (coefficients checked, non-zero among them)} over the whole grid."""
    points = list(itertools.product(grid_ab, grid_ab, grid_ct, grid_ct))
    return _dz.count_zeros(points=points, ells=grid_ct, stencil=stencil, flip_alpha=flip_alpha)


def report(total):
    return "; ".join(f"{key}: {n - bad}/{n} exactly 0" for key, (n, bad) in total.items())


def main():
    t0 = time.time()
    total = check_all()
    print(f"Z  the dropped coefficients, exact in Q(sqrt 5, i) on the grid a, b in {GRID_AB}, c, t, l in {GRID_CT}: "
          + report(total) + f" ({time.time() - t0:.1f} s)")
    if any(bad for _, bad in total.values()):
        raise SystemExit("a dropped coefficient is not 0")


if __name__ == "__main__":
    main()
