"""float64 view of the certified tables for numerics (evaluation, inversion, reparameterization).

The arrays are the float64 copies stored in each table (the midpoints of its arb balls, i.e. the
nearest doubles to the exact control points up to one rounding). Nothing here is used in a proof.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from ccproof.errors import TableNotFoundError, check_valence
from ccproof.tables.format import PATCHES, describe_available, read_table_json, table_path


@dataclass(frozen=True)
class CharacteristicTable:
    """Per-valence data of the characteristic map in float64.

    Attributes
    ----------
    valence : int
    lam : float
        Subdominant eigenvalue lam(k) (R2).
    N : int
        Number of dyadic subdivisions of bmz04 Appendix A for this valence (R8).
    bspline : ndarray, shape (3, 4, 4, 2)
        B-spline nets of P1, P2, P3 (axis 0), ``[p, i, j]`` = control point i along u, j along v.
    bezier : ndarray, shape (3, 4, 4, 2)
        Bezier nets of the same pieces.
    hash : str or None
        Content hash of the table file the data came from (None when derived on the fly).
    """

    valence: int
    lam: float
    N: int | None
    bspline: np.ndarray
    bezier: np.ndarray
    hash: str | None


def _nets(obj, form):
    arr = np.array([obj["float64"][form][p] for p in PATCHES], dtype=np.float64)
    if arr.shape != (3, 4, 4, 2) or not np.all(np.isfinite(arr)):
        raise ValueError(f"table float64 {form} nets are malformed (shape {arr.shape})")
    arr.setflags(write=False)
    return arr


@lru_cache(maxsize=256)
def load_table(k, directory=None):
    """Load the certified table of valence ``k`` (hash-checked) as float64 arrays.

    Raises :class:`~ccproof.errors.TableNotFoundError` listing the tables that exist.

    >>> t = load_table(4)
    >>> t.lam, t.N, t.bezier.shape
    (0.5, 3, (3, 4, 4, 2))
    """
    k = check_valence(k)
    path = table_path(k, directory)
    try:
        obj = read_table_json(path)
    except FileNotFoundError:
        raise TableNotFoundError(f"no certified table for valence {k}; {describe_available(directory)}") from None
    return CharacteristicTable(k, float(obj["float64"]["lam"]), int(obj["derived"]["N"]),
                               _nets(obj, "bspline"), _nets(obj, "bezier"), obj["hash"])


@lru_cache(maxsize=256)
def characteristic_nets(k):
    """float64 nets of valence ``k``: from the certified table when it exists, otherwise derived
    from the exact symbolic nets (:mod:`ccproof.algebra`) at 128 bits and rounded once (``hash``
    is then None). Use :func:`load_table` when the data must come from a certified table."""
    k = check_valence(k)
    try:
        return load_table(k)
    except TableNotFoundError:
        pass
    from ccproof.algebra.specialize import characteristic_map_patches, subdominant_eigenvalue

    def arr(form):
        nets = characteristic_map_patches(k, form, "float")
        a = np.array([nets[p] for p in PATCHES], dtype=np.float64)
        a.setflags(write=False)
        return a

    return CharacteristicTable(k, subdominant_eigenvalue(k, "float"), None, arr("bspline"), arr("bezier"), None)
