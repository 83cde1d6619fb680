"""Ship an object to the workers by content digest and build it once per worker process.

:func:`ship` pickles a builder and its arguments (e.g. ``limit_surface`` and a mesh) and names the
bytes by their SHA-256. On a cluster the :class:`Shipped` object travels once to each worker (it is
one shared dependency of every task, see :func:`ccproof.scale.engine.run_tasks` and
:func:`ccproof.scale.arrays.evaluate_dask`); :func:`rebuild` then builds the object on the first task
of a worker that needs it and keeps it in a per-process cache keyed by the digest, so the expensive
precomputation (e.g. the eigenstructure of every extraordinary valence of a limit surface) happens
once per worker, not once per task.
"""

from __future__ import annotations

import hashlib
import pickle
from collections import Counter

_CACHE: dict = {}
_BUILDS: Counter = Counter()
#: at most this many built objects are kept per process (oldest dropped first)
MAX_CACHED = 8


class Shipped:
    """A builder call ``builder(*args, **kwargs)`` pickled once and named by the SHA-256 of the bytes.

    Made by :func:`ship`, built by :func:`rebuild` (docs/scale-out.md, "A real cluster").

    Parameters
    ----------
    payload : bytes
        The pickled ``(builder, args, kwargs)``.

    Examples
    --------
    >>> from fractions import Fraction
    >>> ship(Fraction, 1, 3).digest == ship(Fraction, 1, 3).digest != ship(Fraction, 1, 4).digest
    True
    """

    __slots__ = ("digest", "payload")

    def __init__(self, payload: bytes):
        self.payload = payload
        self.digest = hashlib.sha256(payload).hexdigest()

    def __reduce__(self):
        return (Shipped, (self.payload,))

    def __repr__(self):
        return f"Shipped(sha256={self.digest[:16]}..., {len(self.payload)} bytes)"


def ship(builder, *args, **kwargs):
    """A :class:`Shipped` for ``builder(*args, **kwargs)``; equal content gives the same digest.

    ``builder`` must be importable by name (a module-level function or class).

    Parameters
    ----------
    builder : callable
    args, kwargs
        Picklable arguments.

    Returns
    -------
    Shipped

    Examples
    --------
    >>> from fractions import Fraction
    >>> rebuild(ship(Fraction, 2, 6))
    Fraction(1, 3)
    """
    return Shipped(pickle.dumps((builder, args, kwargs), protocol=5))


def rebuild(shipped, local=None):
    """The object a :class:`Shipped` describes, built at most once per process (cached by digest).

    Parameters
    ----------
    shipped : Shipped
    local : object, optional
        The object already built in this process, registered under the digest so that a serial run
        does not build it twice.

    Returns
    -------
    object
        ``builder(*args, **kwargs)``, the same object on every call in this process.

    Examples
    --------
    >>> s = ship(dict, a=1)
    >>> rebuild(s) is rebuild(s), rebuild(s)
    (True, {'a': 1})
    """
    obj = _CACHE.get(shipped.digest)
    if obj is None:
        if local is not None:
            obj = local
        else:
            builder, args, kwargs = pickle.loads(shipped.payload)
            obj = builder(*args, **kwargs)
            _BUILDS[shipped.digest] += 1
        while len(_CACHE) >= MAX_CACHED:
            _CACHE.pop(next(iter(_CACHE)))
        _CACHE[shipped.digest] = obj
    return obj


def build_counts():
    """digest -> how many times this process built it (for tests and the benchmark).

    Returns
    -------
    dict of str -> int

    Examples
    --------
    >>> s = ship(dict, b=2)
    >>> _ = rebuild(s), rebuild(s)
    >>> build_counts()[s.digest]
    1
    """
    return dict(_BUILDS)
