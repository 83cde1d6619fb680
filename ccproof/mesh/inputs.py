"""The gate of every input file (meshes, point clouds, point CSVs, chart labels): what may be read, and how much.

An input is opened non-blocking (a FIFO without a writer does not wait) and judged by ``fstat`` of the open
descriptor, so a symbolic link is judged by what it points to:

* a regular file is read by its reader if it holds at most :func:`input_cap` bytes;
* a FIFO (a pipe, ``<(command)``) is read once, up to the cap, into a private temporary copy with the same
  name, which the reader then reads (errors still name the FIFO); it waits for a writer, as ``cat`` does;
* anything else (``/dev/zero``, ``/dev/random``, a folder, a socket, a device) is refused at once, by name.

The cap (default :data:`MAX_INPUT_BYTES`, 2 GB) bounds the memory of the readers (they hold the text and
its parsed numbers); the commands' ``--max-input GB`` raises it (:func:`set_input_cap`).

Examples
--------
>>> with checked_input("/dev/zero") as p:
...     pass
Traceback (most recent call last):
...
ccproof.errors.CCProofError: /dev/zero: not a regular file (a character device); ccproof reads regular files and pipes
"""

from __future__ import annotations

import contextlib
import os
import shutil
import stat
import tempfile

from ccproof.errors import CCProofError

__all__ = ["checked_input", "check_regular_file", "read_input_text", "decode_text", "input_cap", "set_input_cap",
           "MAX_INPUT_BYTES", "polygon_cap", "set_polygon_cap", "check_polygon_sizes"]

#: default largest input file, bytes (``--max-input`` raises it)
MAX_INPUT_BYTES = 2 * 10**9
_cap = [MAX_INPUT_BYTES]


def input_cap() -> int:
    """The largest input file read now, bytes."""
    return _cap[0]


def set_input_cap(nbytes):
    """Set the largest input file (bytes, > 0); returns the previous cap."""
    if not (nbytes > 0 and nbytes < float("inf")):  # NaN too
        raise CCProofError(f"the input size limit must be a positive number of bytes, got {nbytes}")
    old, _cap[0] = _cap[0], int(nbytes)
    return old


def _kind(mode):
    return ("a directory" if stat.S_ISDIR(mode) else "a character device" if stat.S_ISCHR(mode) else
            "a block device" if stat.S_ISBLK(mode) else "a socket" if stat.S_ISSOCK(mode) else "not a file")


def _too_big(path, size, cap, error):
    return error(f"{path}: {size} bytes or more, above the input limit of {cap} bytes ({cap / 1e9:g} GB); "
                 f"--max-input GB raises it")


def check_regular_file(path, error=CCProofError):
    """Refuse, without opening it, a file that is not regular or above :func:`input_cap` (for a file another
    layer reads, such as a shard folder's index); a missing file is left to that reader.

    >>> check_regular_file("/dev/null")
    Traceback (most recent call last):
    ...
    ccproof.errors.CCProofError: /dev/null: not a regular file (a character device); ccproof reads regular files here
    """
    p = os.fspath(path)
    try:
        st = os.stat(p)
    except FileNotFoundError:
        return
    if not stat.S_ISREG(st.st_mode):
        to = f" -> {os.path.realpath(p)}" if os.path.islink(p) else ""
        raise error(f"{p}{to}: not a regular file ({_kind(st.st_mode)}); ccproof reads regular files here")
    if st.st_size > input_cap():
        raise _too_big(p, st.st_size, input_cap(), error)


def _read_fifo(fd, path, cap, error):
    import fcntl
    import select

    poller = select.poll()  # until a writer has written or closed (a read before would see an end of file)
    poller.register(fd, select.POLLIN)
    poller.poll()
    fcntl.fcntl(fd, fcntl.F_SETFL, fcntl.fcntl(fd, fcntl.F_GETFL) & ~os.O_NONBLOCK)  # then read to its end
    chunks, n = [], 0
    while n <= cap:
        chunk = os.read(fd, min(cap + 1 - n, 1 << 20))
        if not chunk:
            break
        chunks.append(chunk)
        n += len(chunk)
    if n > cap:
        raise _too_big(path, n, cap, error)
    return b"".join(chunks)


@contextlib.contextmanager
def checked_input(path, error=CCProofError):
    """Yield a path from which the input ``path`` may be read (itself for a regular file; a FIFO's copy).

    Parameters
    ----------
    path : str or os.PathLike
    error : type
        The :class:`~ccproof.errors.CCProofError` subclass raised (``MeshError`` for meshes).

    Raises
    ------
    error
        Naming ``path``: no such file, a folder, a device or socket, or above :func:`input_cap` bytes.
    OSError
        When it cannot be opened otherwise (a permission).
    """
    p = os.fspath(path)
    cap = input_cap()
    try:
        fd = os.open(p, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_NOCTTY", 0))
    except FileNotFoundError:
        raise error(f"{p}: no such file") from None
    except IsADirectoryError:
        raise error(f"{p}: is a folder, not a file") from None
    try:
        st = os.fstat(fd)
        if stat.S_ISREG(st.st_mode):
            if st.st_size > cap:
                raise _too_big(p, st.st_size, cap, error)
            data = None
        elif stat.S_ISFIFO(st.st_mode):
            data = _read_fifo(fd, p, cap, error)
        else:
            to = f" -> {os.path.realpath(p)}" if os.path.islink(p) else ""
            raise error(f"{p}{to}: not a regular file ({_kind(st.st_mode)}); ccproof reads regular files and pipes")
    finally:
        os.close(fd)
    if data is None:
        yield p
        return
    folder = tempfile.mkdtemp(prefix="ccproof-pipe-")
    copy = os.path.join(folder, os.path.basename(p) or "input")
    try:
        with open(copy, "wb") as fh:
            fh.write(data)
        del data
        try:
            yield copy
        except CCProofError as exc:  # errors name the FIFO, not the copy
            text = str(exc)
            if copy not in text:
                raise
            raise type(exc)(text.replace(copy, p)) from None
    finally:
        shutil.rmtree(folder, ignore_errors=True)


def decode_text(data, path, error=CCProofError, expect="lines of text"):
    """The UTF-8 text of an input's bytes, a byte-order mark dropped (CRLF line ends are split as LF by
    ``splitlines``); a binary or non-UTF-8 file refused, naming the file and line.

    >>> decode_text(b"\\xef\\xbb\\xbfface,u,v\\r\\n0,0.5,0.5\\r\\n", "p.csv").splitlines()
    ['face,u,v', '0,0.5,0.5']
    >>> decode_text(b"1 2 3\\n\\x00\\x01", "c.xyz", expect="x y z per line")
    Traceback (most recent call last):
    ...
    ccproof.errors.CCProofError: c.xyz: a binary file, not text (x y z per line)
    """
    if b"\0" in data[:1 << 16]:
        raise error(f"{path}: a binary file, not text ({expect})")
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = data[:exc.start].count(b"\n") + 1
        raise error(f"{path}:{line}: not UTF-8 text (byte {exc.start}; {expect})") from None


def read_input_text(path, error=CCProofError, expect="lines of text"):
    """The text of the input ``path`` (:func:`checked_input`, :func:`decode_text`)."""
    with checked_input(path, error) as q, open(q, "rb") as fh:
        return decode_text(fh.read(), path, error, expect)


#: the largest polygon a command evaluates by default (``--max-polygon`` raises it): the exact data of an
#: n-gon (the corner scheme of its centre, valence n: linear in n) and the patch table around it (a ring of
#: 2n + 8 points per sub-face: about n^2) cost, measured with an empty cache on a loaded 2-core machine
#: (CPU time, peak memory): one 1000-gon and 100 points 5 s, 0.5 GB; a drum of two n-gons 1.8 s, 0.19 GB
#: at n = 256, 8.9 s, 0.69 GB at 1024 and 31 s, 2.0 GB at 2048
_polygon_cap = [None]  # the library reads any polygon; the command line sets its --max-polygon


def polygon_cap():
    """The largest polygon accepted now (None: any)."""
    return _polygon_cap[0]


def set_polygon_cap(n):
    """Set the largest polygon accepted (an int >= 3, or None: any); returns the previous cap."""
    if n is not None and (isinstance(n, bool) or not isinstance(n, int) or n < 3):
        raise CCProofError(f"the polygon size limit must be an integer >= 3, got {n}")
    old, _polygon_cap[0] = _polygon_cap[0], n
    return old


def check_polygon_sizes(polygons, path, error=CCProofError):
    """Refuse a polygon above :func:`polygon_cap`, naming the file, the face and the option that raises it.

    >>> old = set_polygon_cap(4)
    >>> check_polygon_sizes([[0, 1, 2], [0, 1, 2, 3, 4]], "m.obj")
    Traceback (most recent call last):
    ...
    ccproof.errors.CCProofError: m.obj: face 1 has 5 vertices, above --max-polygon 4 (the exact data of ...
    >>> _ = set_polygon_cap(old)
    """
    cap = polygon_cap()
    if cap is None:
        return
    for f, poly in enumerate(polygons):
        if len(poly) > cap:
            raise error(f"{path}: face {f} has {len(poly)} vertices, above --max-polygon {cap} (the exact data of "
                        f"an n-gon cost about n^2 in time and memory: one 1000-gon 5 s and 0.5 GB, two 2048-gons 31 s "
                        f"and 2 GB); raise --max-polygon to evaluate it")
