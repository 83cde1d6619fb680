"""Sealed files of the disk cache of exact evaluation data (corner schemes, patch-table templates).

Every cache file is its body followed by the SHA-256 of the *name* it was stored under and of the
body; the name is itself the SHA-256 of the inputs the entry was built from (the configuration key
and the sources that compute it), so a file is used only if it holds, byte for byte, what was
written for exactly those inputs: a flipped byte, a truncation, a file copied under another entry's
name or a digest that does not match are all refused. A refused entry is rebuilt from the exact data
and rewritten; the first one of a process is reported by a :class:`CorruptCacheWarning` (one line on
the command line's stderr). Files are written under a temporary name and renamed (atomic); the
temporary files left by a killed process are removed by the next write to the folder.

Examples
--------
>>> body = b"exact data"
>>> unseal(seal("abc", body), "abc") == body
True
>>> unseal(seal("abc", body), "abd")
Traceback (most recent call last):
...
ValueError: digest mismatch
"""

from __future__ import annotations

import functools
import hashlib
import os
import re
import time
import warnings
from pathlib import Path

from ccproof.scale.engine import pid_alive

__all__ = ["cache_dir", "seal", "unseal", "read_entry", "store", "report_bad", "CorruptCacheWarning"]

#: bytes of the trailing digest of a cache file
DIGEST_BYTES = 32
#: a temporary file of a writer whose process is gone is removed when older than this (seconds)
STALE_SECONDS = 60.0
_TMP = re.compile(r"^\.([0-9a-f]{64})\.(\d+)\.(tmp|f64|A\.npz|tpl)$")  # ours, and those of older versions
_reported = []
_swept = set()


class CorruptCacheWarning(UserWarning):
    """A cache file did not hold what was written for its inputs: it was rebuilt, not used."""


def cache_dir():
    """The cache folder: ``CCPROOF_CACHE`` (``off``, ``none``, ``no``, ``0`` or empty: None), default
    ``~/.cache/ccproof/corner_schemes``.

    >>> from unittest import mock
    >>> with mock.patch.dict(os.environ, {"CCPROOF_CACHE": "off"}):
    ...     cache_dir() is None
    True
    """
    return _cache_dir(os.environ.get("CCPROOF_CACHE"), os.environ.get("HOME"))


@functools.lru_cache(maxsize=16)
def _cache_dir(d, home):
    """:func:`cache_dir` of these values of ``CCPROOF_CACHE`` and ``HOME`` (a setup asks once per template)."""
    if d is not None and d.strip().lower() in ("", "0", "off", "none", "no"):
        return None
    return Path(d) if d else Path.home() / ".cache" / "ccproof" / "corner_schemes"


def _digest(name, body):
    return hashlib.sha256(name.encode() + b"\0" + bytes(body)).digest()


def seal(name, body):
    """``body`` followed by the digest of ``name`` and ``body`` (the bytes of a cache file)."""
    return bytes(body) + _digest(name, body)


def unseal(data, name):
    """The body of the cache-file bytes ``data`` written for ``name``; ValueError unless they are exactly
    what :func:`seal` produced for that name."""
    if len(data) < DIGEST_BYTES:
        raise ValueError("digest mismatch")
    body = memoryview(data)[:-DIGEST_BYTES]
    if _digest(name, body) != bytes(data[-DIGEST_BYTES:]):
        raise ValueError("digest mismatch")
    return body


def report_bad(path, why):
    """Report a refused cache file (the first one of the process; the others are rebuilt silently)."""
    if not _reported:
        _reported.append(str(path))
        warnings.warn(f"cache file {path} is corrupt ({why}): not used, rebuilt from the exact data "
                      f"(further corrupt cache files of this run are rebuilt without a word)",
                      CorruptCacheWarning, stacklevel=3)


def read_entry(path, name, parse, data=None):
    """``parse(body)`` of the verified cache file ``path`` written for ``name``, or None: missing or
    unreadable (silently), or corrupt (reported by :func:`report_bad`), including a ``parse`` that
    raises ValueError or KeyError. ``data``: the file's bytes when already read."""
    if data is None:
        try:
            data = path.read_bytes()
        except OSError:
            return None
    try:
        return parse(unseal(data, name))
    except (ValueError, KeyError, UnicodeDecodeError) as e:
        report_bad(path, str(e) or type(e).__name__)
        return None


def _sweep(d):
    """Remove the temporary files of dead writers in ``d`` (once per folder and process)."""
    if d in _swept:
        return
    _swept.add(d)
    now = time.time()
    try:
        names = os.listdir(d)
    except OSError:
        return
    for n in names:
        m = _TMP.match(n)
        if m is None or int(m.group(2)) == os.getpid() or pid_alive(int(m.group(2))):
            continue
        try:
            p = d / n
            if now - p.stat().st_mtime > STALE_SECONDS:
                p.unlink()
        except OSError:
            pass


def store(d, name, suffix, body):
    """Write the sealed ``body`` to ``d / (name + suffix)`` atomically; False if the folder is not
    writable (the cache is then skipped)."""
    tmp = d / f".{hashlib.sha256((name + suffix).encode()).hexdigest()}.{os.getpid()}.tmp"
    try:
        d.mkdir(parents=True, exist_ok=True)
        _sweep(d)
        tmp.write_bytes(seal(name, body))
        os.replace(tmp, d / f"{name}{suffix}")
        return True
    except OSError:
        try:
            tmp.unlink()
        except OSError:
            pass
        return False
