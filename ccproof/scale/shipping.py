"""Ship an object to the workers by content digest and build it once per worker process.

:func:`ship` pickles a builder and its arguments (e.g. ``limit_surface`` and a mesh) and names the
bytes by their SHA-256. On a cluster the :class:`Shipped` object travels once to each worker (it is
one shared dependency of every task, see :func:`ccproof.scale.engine.run_tasks` and
:func:`ccproof.scale.arrays.evaluate_dask`); :func:`rebuild` then builds the object on the first task
of a worker that needs it and keeps it in a per-process cache keyed by the digest, so the expensive
precomputation (e.g. the eigenstructure of every extraordinary valence of a limit surface) happens
once per worker, not once per task.

:func:`share` ships an object already built here instead: by value (pickled once, received once per worker
of a remote cluster), or, for the worker processes of this machine, as a few kB naming an anonymous shared
memory file (Linux ``memfd``) into which its arrays were written once: every worker maps the same pages
read-only (:func:`attach`), and this process evaluates from them too, so one copy serves all. The file has no
name: the system frees it when the last process holding it ends, however it ends (SIGKILL included).
"""

from __future__ import annotations

import contextlib
import hashlib
import os
import pickle
from collections import Counter

from ccproof.errors import CCProofError

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


#: buffers (numpy arrays) of at least this many bytes go to the shared file; smaller ones stay in the pickle
SHARED_MIN = 1 << 12
_ALIGN = 64


class SharedRef:
    """Where :func:`attach` finds an object that :func:`share` wrote to shared memory: the writer's process
    id and file descriptor (opened again as ``/proc/PID/fd/FD``), a random token (the file's first 16 bytes),
    the file's size, the pickle of the object less its large buffers, and each buffer's (offset, bytes).

    >>> r = SharedRef(1, 3, b"t" * 16, 64, b"", ())
    >>> r.size, len(pickle.dumps(r)) < 200
    (64, True)
    """

    __slots__ = ("pid", "fd", "token", "size", "inband", "spans")

    def __init__(self, pid, fd, token, size, inband, spans):
        self.pid, self.fd, self.token, self.size, self.inband, self.spans = pid, fd, token, size, inband, spans

    def __reduce__(self):
        return (SharedRef, (self.pid, self.fd, self.token, self.size, self.inband, self.spans))


def _unpickle_from(ref, view):
    """The object of ``ref`` with its buffers read from ``view`` (a memoryview of the whole file)."""
    return pickle.loads(ref.inband, buffers=[view[a:a + n] for a, n in ref.spans])


def attach(ref):
    """The object :func:`share` wrote, its arrays mapped read-only from the writer's shared file (no copy).

    Raises
    ------
    CCProofError
        When the file cannot be opened (another machine, the writer gone, a system without ``/proc``),
        naming the writer's process.
    """
    import mmap

    path = f"/proc/{ref.pid}/fd/{ref.fd}"
    try:
        with open(path, "rb") as fh:
            mm = mmap.mmap(fh.fileno(), ref.size, access=mmap.ACCESS_READ)
    except (OSError, ValueError) as exc:
        raise CCProofError(f"cannot map the shared table of process {ref.pid} ({path}: {exc}); a worker on "
                           "another machine needs the table by value (a scheduler address ships it so)") from None
    if mm[:16] != ref.token:
        mm.close()
        raise CCProofError(f"{path} is not the shared table of process {ref.pid} (its token differs)")
    return _unpickle_from(ref, memoryview(mm))


def shared_memory_available():
    """Whether :func:`share` can write shared memory here (Linux: ``os.memfd_create`` and ``/proc``).

    >>> isinstance(shared_memory_available(), bool)
    True
    """
    return hasattr(os, "memfd_create") and os.path.isdir(f"/proc/{os.getpid()}/fd")


def _aligned(n):
    return -(-n // _ALIGN) * _ALIGN


@contextlib.contextmanager
def share(obj, where="machine"):
    """Ship ``obj`` (built here) to the workers without building it again: yields ``(shipped, local)``.

    ``shipped`` is a :class:`Shipped` whose :func:`rebuild` gives the object on a worker, ``local`` the object
    this process should use from now on (``obj`` itself, or the same object read from the shared pages: drop
    ``obj`` to free its memory).

    ``where``: ``"here"`` (the tasks run in this process: ``shipped`` names ``obj``, registered for
    :func:`rebuild`, nothing is copied); ``"anywhere"`` (a remote cluster), or ``"machine"`` where shared memory
    is missing: pickled once by value, each worker receives and unpickles it once; ``"machine"`` (worker
    processes of this machine): its buffers (numpy arrays of at least :data:`SHARED_MIN` bytes) are written
    once to an anonymous shared file, mapped here, and ``shipped`` names it (:class:`SharedRef`,
    :func:`attach`): the workers map the same pages. On exit the file is closed here; the system frees it
    when the last process that maps it ends.

    Examples
    --------
    >>> import numpy as np
    >>> with share({"a": np.arange(10_000)}) as (shipped, local):
    ...     b = attach(pickle.loads(shipped.payload)[1][0]) if shared_memory_available() else local
    ...     int(b["a"].sum()), b["a"].flags.writeable == (not shared_memory_available())
    (49995000, True)
    """
    import secrets

    if where not in ("here", "machine", "anywhere"):
        raise CCProofError(f"share: where must be 'here', 'machine' or 'anywhere', got {where!r}")
    if where == "here":
        shipped, local = Shipped(pickle.dumps((_not_here, (os.getpid(), secrets.token_hex(8)), {}))), obj
    elif where == "anywhere" or not shared_memory_available():
        shipped, local = Shipped(pickle.dumps((_identity, (obj,), {}), protocol=5)), obj
    else:
        fd, ref, local = _write_shared(obj)
        del obj  # (the caller drops its copy for ``local``: its memory is freed)
        shipped = Shipped(pickle.dumps((attach, (ref,), {}), protocol=5))
    rebuild(shipped, local=local)  # (this process never builds it)
    try:
        yield shipped, local
    finally:
        _CACHE.pop(shipped.digest, None)
        if where == "machine" and shared_memory_available():
            os.close(fd)  # the mappings (here and the workers') keep the pages while they last


def _write_shared(obj):
    """(fd, :class:`SharedRef`, the object read back from the mapping) of ``obj`` pickled with its large buffers
    written once to a new anonymous shared file ``fd``."""
    import mmap
    import secrets

    buffers = []

    def keep(buf):
        try:
            raw = buf.raw()
        except BufferError:  # not contiguous: in the pickle
            return True
        if raw.nbytes < SHARED_MIN:
            return True
        buffers.append(raw)
        return False

    inband = pickle.dumps(obj, protocol=5, buffer_callback=keep)
    spans, at = [], _ALIGN
    for buf in buffers:
        spans.append((at, buf.nbytes))
        at = _aligned(at + buf.nbytes)
    token = secrets.token_bytes(16)
    fd = os.memfd_create("ccproof-shared", os.MFD_CLOEXEC)
    try:
        os.ftruncate(fd, at)
        mm = mmap.mmap(fd, at)  # shared, read-write here; every page written once (counted in this process)
        mm[:16] = token
        while buffers:  # (no view of the caller's arrays is kept: they are freed when the caller drops them)
            a, n = spans[len(spans) - len(buffers)]
            mm[a:a + n] = buffers.pop(0).cast("B")
        ref = SharedRef(os.getpid(), fd, token, at, inband, tuple(spans))
        return fd, ref, _unpickle_from(ref, memoryview(mm).toreadonly())
    except BaseException:
        os.close(fd)
        raise


def release_freed_memory():
    """Return the memory of freed objects to the system: a garbage collection, then (glibc) ``malloc_trim``,
    without which the pages of many freed mid-size arrays stay with the process. Call it after dropping a
    large object, e.g. the original of a :func:`share`-d one.

    >>> release_freed_memory() in (True, False)
    True
    """
    import ctypes
    import ctypes.util
    import gc

    gc.collect()
    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6")
        return bool(libc.malloc_trim(0))
    except (OSError, AttributeError):  # not glibc
        return False


def _identity(obj):
    """The builder of an object shipped by value."""
    return obj


def _not_here(pid, token):
    """The builder of an object shared ``"here"``: only process ``pid`` holds it."""
    raise CCProofError(f"an object shared only within process {pid} was asked for in process {os.getpid()}")
