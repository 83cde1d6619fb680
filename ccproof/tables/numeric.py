"""Numeric view of the certified tables for numerics (evaluation, inversion, reparameterization).

The arrays are the float64 copies stored in each table (the midpoints of its arb balls, i.e. the
nearest doubles to the exact control points up to one rounding); :func:`characteristic_arb` gives
the arb balls themselves. A valence without a table of its own is served from the exact nets that
every table holds (integer forms in c and lam, the same for every valence, docs/tables.md) evaluated
in ball arithmetic at c = cos(2 pi/k): no symbolic computation, no sympy. Nothing here is used in a
proof.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from ccproof.errors import TableNotFoundError, check_valence
from ccproof.tables.format import (
    PATCHES,
    arb_from_json,
    available_tables,
    describe_available,
    eval_form_arb,
    read_table_json,
    table_nets_arb,
    table_nets_exact,
    table_path,
)
from ccproof.valence import lam_from_c


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

    Examples
    --------
    For k = 4 the characteristic map is the identity: the last Bezier point of P2 is (1, 1).

    >>> t = load_table(4)
    >>> t.lam, t.bezier.shape, t.bezier[1, 3, 3].tolist()
    (0.5, (3, 4, 4, 2), [1.0, 1.0])
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


def load_table(k: int, directory: str | os.PathLike[str] | None = None) -> CharacteristicTable:
    """Load the certified table of valence ``k`` (hash-checked) as float64 arrays (cached).

    Parameters
    ----------
    k : int
        Valence >= 3.
    directory : str or os.PathLike, optional
        Folder of the tables (default: the published ``tables`` folder).

    Returns
    -------
    CharacteristicTable
        ``lam``, ``N`` and the read-only nets ``bspline``, ``bezier`` of shape (3, 4, 4, 2) (patch P1..P3,
        i, j, coordinate).

    Raises :class:`~ccproof.errors.TableNotFoundError` listing the tables that exist.

    >>> t = load_table(4)
    >>> t.lam, t.N, t.bezier.shape
    (0.5, 3, (3, 4, 4, 2))
    """
    return _load_table(check_valence(k), None if directory is None else os.fspath(directory))


@lru_cache(maxsize=256)
def _load_table(k: int, directory: str | None) -> CharacteristicTable:
    path = table_path(k, directory)
    try:
        obj = read_table_json(path)
    except FileNotFoundError:
        raise TableNotFoundError(f"no certified table for valence {k}; {describe_available(directory)}") from None
    return CharacteristicTable(k, float(obj["float64"]["lam"]), int(obj["derived"]["N"]),
                               _nets(obj, "bspline"), _nets(obj, "bezier"), obj["hash"])


@dataclass(frozen=True)
class ArbCharacteristic:
    """Ball enclosures of the characteristic map data of one valence (python-flint ``arb``).

    Attributes
    ----------
    valence : int
    prec : int
        Working precision (bits) of the balls.
    c, lam : arb
        Balls containing c = cos(2 pi/k) and lam(k) (docs/readings.md R2).
    bezier : dict
        ``{"P1": net, "P2": net, "P3": net}``, ``net[i][j] = (x, y)`` balls of the Bezier control
        points (i along s, j along t).
    hash : str or None
        Hash of the table of valence k when the balls are that table's, else None (evaluated from
        the exact nets of a table, whose hash is then ``source_hash``).
    source_hash : str
        Hash of the table file the data came from.

    Examples
    --------
    >>> a = characteristic_arb(4)
    >>> a.lam.contains(0.5), a.bezier["P2"][3][3][0].contains(1), a.hash == load_table(4).hash
    (True, True, True)
    """

    valence: int
    prec: int
    c: object
    lam: object
    bezier: dict
    hash: str | None
    source_hash: str


#: one uniform cubic B-spline segment -> its Bezier points, times 6 (bmz04 eq. (1); docs/readings.md R4)
BSPLINE_TO_BEZIER_6 = ((1, 4, 1, 0), (0, 4, 2, 0), (0, 2, 4, 0), (0, 1, 4, 1))


@lru_cache(maxsize=8)
def _exact_source(directory=None):
    """(exact B-spline nets, hash) of a table: the integer forms are the same in every table."""
    for v in available_tables(directory):
        obj = read_table_json(table_path(v, directory))
        return table_nets_exact(obj), obj["hash"]
    raise TableNotFoundError(f"no certified table at all; {describe_available(directory)}")


@lru_cache(maxsize=256)
def characteristic_arb(k, prec=128):
    """Ball enclosures of c, lam and the Bezier nets of P1, P2, P3 for valence ``k``.

    From the certified table of valence k when it exists and ``prec`` does not exceed its
    precision; otherwise from the exact nets of a table, evaluated in arb at ``prec`` bits with
    c = cos(2 pi/k) and lam from :func:`ccproof.valence.lam_from_c` (the table's ``lam_definition``),
    then converted to Bezier form with :data:`BSPLINE_TO_BEZIER_6` (no symbolic computation). Raises
    :class:`~ccproof.errors.TableNotFoundError` when no table exists at all.

    Parameters
    ----------
    k : int
        Valence >= 3.
    prec : int
        Bits of the balls (default 128, the precision of the published tables).

    Returns
    -------
    ArbCharacteristic

    Examples
    --------
    >>> a = characteristic_arb(5)
    >>> a.hash == load_table(5).hash, abs(float(a.lam.mid()) - load_table(5).lam) < 1e-16
    (True, True)
    >>> b = characteristic_arb(1000)        # no table: evaluated from the exact nets
    >>> b.hash is None, round(float(b.lam.mid()), 4)   # -> (6 + sqrt(20))/16 = 0.6545... as k -> inf
    (True, 0.6545)
    """
    from flint import arb, ctx, fmpq

    k = check_valence(k)
    path = table_path(k)
    if path.is_file():
        obj = read_table_json(path)
        if prec <= obj["prec"]:
            with ctx.workprec(obj["prec"]):
                return ArbCharacteristic(k, obj["prec"], arb_from_json(obj["c"], obj["prec"]),
                                         arb_from_json(obj["lam"], obj["prec"]), table_nets_arb(obj, "bezier"),
                                         obj["hash"], obj["hash"])
    exact, source = _exact_source()
    with ctx.workprec(prec + 32):
        c = arb(fmpq(2, k)).cos_pi()
        lam = lam_from_c(c, arb.sqrt)
        nets = {}
        for name in PATCHES:
            bs = [[tuple(eval_form_arb(q, c, lam) for q in p) for p in row] for row in exact[name]]
            rows = [[tuple(sum((M[a] * bs[a][j][comp] for a in range(4)), arb(0)) / 6 for comp in range(2))
                     for j in range(4)] for M in BSPLINE_TO_BEZIER_6]
            nets[name] = [[tuple(sum((M[b] * rows[i][b][comp] for b in range(4)), arb(0)) / 6 for comp in range(2))
                           for M in BSPLINE_TO_BEZIER_6] for i in range(4)]
    with ctx.workprec(prec):
        nets = {n: [[(+x, +y) for x, y in row] for row in net] for n, net in nets.items()}
        return ArbCharacteristic(k, prec, +c, +lam, nets, None, source)


@lru_cache(maxsize=256)
def characteristic_nets(k):
    """float64 nets of valence ``k``: from the certified table when it exists, otherwise the
    midpoints of :func:`characteristic_arb` (the exact nets of the tables evaluated in arb and
    rounded once; ``hash`` is then None). Use :func:`load_table` when the data must come from the
    certified table of k itself.

    Parameters
    ----------
    k : int
        Valence, k >= 3.

    Returns
    -------
    CharacteristicTable
        Nets of shape (3, 4, 4, 2) float64 (docs/readings.md R3, R4).

    Examples
    --------
    >>> characteristic_nets(4).lam, characteristic_nets(1000).hash
    (0.5, None)
    """
    k = check_valence(k)
    try:
        return load_table(k)
    except TableNotFoundError:
        pass
    a = characteristic_arb(k)

    def arr(nets):
        out = np.array([[[[float(x.mid()) for x in p] for p in row] for row in nets[n]] for n in PATCHES])
        out.setflags(write=False)
        return out

    bez = arr(a.bezier)
    with np.errstate(all="raise"):
        bsp = np.einsum("ia,jb,pabc->pijc", np.linalg.inv(np.array(BSPLINE_TO_BEZIER_6) / 6.0),
                        np.linalg.inv(np.array(BSPLINE_TO_BEZIER_6) / 6.0), bez)
    bsp.setflags(write=False)
    return CharacteristicTable(k, float(a.lam.mid()), None, bsp, bez, None)
