"""The trusted verifier of ccproof certificates (``ccproof verify``).

A certificate is a statement plus hints. The statement is fixed by the schema and the valence alone:
this package derives c = cos(2 pi/k), lam(k), the subdominant eigenvector, the characteristic map's
nets, the spectrum and every hypothesis the proofs use from k and the Catmull-Clark rules
(:mod:`.rules`, :mod:`.statement`, :mod:`.spectrum`), reads no table, and replays the hints (dyadic
boxes with claimed bounds, :mod:`.replay`) without searching. It imports only python-flint, the
standard library and :mod:`ccproof.rigorous`; docs/trusted_base.md lists the modules it consists of.

>>> from ccproof.certify.verify import verify_file, certificate_files
>>> from ccproof.tables.format import certificates_dir
>>> res = verify_file(certificate_files(certificates_dir())[0], log=lambda line: None)  # c1/k003.json
>>> bool(res), res.valence, res.parts[0].name
(True, 3, 'S statement derived from the rules')
"""

from __future__ import annotations

import json
import os
import stat
import time
from collections.abc import Callable
from pathlib import Path

from .c1 import C1_SCHEMA, verify_c1
from .dart_tail import verify_dart_tail
from .errors import CertificateError
from .injectivity import SCHEMA, verify_injectivity
from .record import Part, Recorder, VerifyResult, field_of, read_valence
from .replay import check_size, close_budget
from .tagged import parse_configuration
from .tagged_c1 import TAGGED_SCHEMA, verify_tagged
from .tagged_limit import verify_tail

__all__ = ["SCHEMA", "C1_SCHEMA", "TAGGED_SCHEMA", "CertificateError", "Part", "VerifyResult", "verify_certificate",
           "verify_file", "check_coverage", "certificate_files", "read_certificate_bytes"]

MAX_FILE_BYTES = 4 * 2**20  # the published certificates: at most 64 KB; MAX_BOXES boxes take at most ~1 MB
_KINDS = {SCHEMA: verify_injectivity, C1_SCHEMA: verify_c1}  # certificates of a valence
_SCHEMAS = (*_KINDS, TAGGED_SCHEMA)
#: what a malformed file can raise while it is being read; each ends in FAIL with the reason
_MALFORMED = (CertificateError, ValueError, TypeError, KeyError, IndexError, AttributeError, RecursionError,
              OverflowError, ZeroDivisionError)


def verify_certificate(cert, log=print, path=None):
    """Check a parsed certificate (a dict). Returns a :class:`VerifyResult`; never raises for bad input.

    Parameters
    ----------
    cert : object
        The parsed JSON (docs/certificates.md); anything else fails with a reason.
    log : callable (str) -> None
        Receives a PASS/FAIL line per part.
    path : str or Path, optional
        Recorded in the result.

    Returns
    -------
    VerifyResult

    Examples
    --------
    The C1 certificate of valence 5 (Reif's criterion, docs/certificates.md), then a forged precision:

    >>> import json
    >>> from ccproof.tables.format import certificates_dir
    >>> cert = json.loads((certificates_dir() / "c1" / "k005.json").read_text())
    >>> bool(verify_certificate(cert, log=lambda line: None))
    True
    >>> verify_certificate(dict(cert, prec=32), log=lambda line: None).error
    'prec must lie in 64..1024'
    """
    res = VerifyResult(path=None if path is None else str(path))
    t0 = time.perf_counter()
    part = Recorder(res, log)
    try:
        if not isinstance(cert, dict) or cert.get("schema") not in _SCHEMAS:
            got = cert.get("schema") if isinstance(cert, dict) else None
            raise CertificateError(f"unknown certificate schema {str(got)[:60]!r} (expected one of "
                                   f"{', '.join(map(repr, _SCHEMAS))})")
        res.schema = cert["schema"]
        check_size(cert)
        if res.schema == TAGGED_SCHEMA:  # a configuration name instead of a valence (docs/tagged_c1.md)
            fam, n = parse_configuration(field_of(cert, "configuration", str, "certificate"))
            if not isinstance(n, dict):
                res.valence = verify_tagged(cert, part, log)
            elif fam == "dart":  # every K >= K0 at once, "C1" (dart_tail)
                res.valence = verify_dart_tail(cert, n["min"], part, log)
            else:  # every N >= N0 at once, "not C1" (tagged_limit)
                res.valence = verify_tail(cert, fam, n["min"], part, log)
            res.seconds = time.perf_counter() - t0
            return res
        res.valence = read_valence(cert)
        res.N = cert.get("N") if isinstance(cert.get("N"), int) else None
        _KINDS[res.schema](cert, res.valence, part, log)
    except _MALFORMED as exc:
        res.error = f"{type(exc).__name__}: {exc}" if not isinstance(exc, CertificateError) else str(exc)
    finally:
        close_budget()  # the replay budget that check_size opened for this certificate
    res.seconds = time.perf_counter() - t0
    return res


def verify_file(path: str | Path, log: Callable[[str], object] = print) -> VerifyResult:
    """Verify one certificate file; logs PASS/FAIL per part, then VERIFIED or FAILED with the reason.

    Only a regular file of at most :data:`MAX_FILE_BYTES` is read (:func:`read_certificate_bytes`); a
    FIFO, a device, a directory or a larger file FAILs at once, naming the file.

    Parameters
    ----------
    path : str or Path
        A certificate file (JSON, schema ``ccproof.injectivity/3`` or ``ccproof.c1/2``).
    log : callable
        Receives each output line (default ``print``).

    Returns
    -------
    VerifyResult
        True as a bool exactly when every part passed; ``parts`` with their reasons, ``margins``.

    >>> from ccproof.tables.format import certificates_dir
    >>> res = verify_file(certificates_dir() / "c1" / "k005.json", log=lambda line: None)
    >>> bool(res), res.schema, res.failures()
    (True, 'ccproof.c1/2', [])
    """
    t0 = time.perf_counter()
    path = Path(path)
    try:
        cert = json.loads(read_certificate_bytes(path).decode("ascii"))
    except (OSError, UnicodeDecodeError, ValueError, RecursionError, CertificateError) as exc:
        res = VerifyResult(path=str(path), error=f"not a readable certificate ({exc})")
    else:
        res = verify_certificate(cert, log, path)
    res.seconds = time.perf_counter() - t0
    if res.error:
        log(f"FAILED {path}: {res.error}")
    else:
        why = "" if res.ok else ": " + "; ".join(f"{p.name}: {p.message}" if p.message else p.name
                                                 for p in res.failures())
        log(f"{'VERIFIED' if res.ok else 'FAILED'} {path} ({res.seconds:.1f} s){why}")
    return res


def read_certificate_bytes(path, cap=MAX_FILE_BYTES):
    """The bytes of a regular file of at most ``cap`` bytes; anything else is refused, without blocking.

    The file is opened non-blocking (a FIFO with no writer does not wait), the open descriptor is
    checked with ``fstat`` (so a symbolic link is judged by what it points to: ``/dev/zero``, a FIFO,
    a directory or a device is refused), and at most ``cap + 1`` bytes are read (a file that grows, or
    reports a wrong size, is still refused above the cap).

    Parameters
    ----------
    path : str or Path
    cap : int
        Bytes; default :data:`MAX_FILE_BYTES`.

    Returns
    -------
    bytes

    Raises
    ------
    CertificateError
        Naming the file and the reason; OSError when it cannot be opened.

    Examples
    --------
    >>> from ccproof.tables.format import certificates_dir
    >>> len(read_certificate_bytes(certificates_dir() / "c1" / "k005.json")) > 100
    True
    >>> read_certificate_bytes("/dev/zero")
    Traceback (most recent call last):
    ...
    ccproof.certify.verify.errors.CertificateError: /dev/zero: not a regular file (a character device)
    """
    fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_NOCTTY", 0))  # POSIX flags
    try:
        mode = os.fstat(fd).st_mode
        if not stat.S_ISREG(mode):
            kind = ("a FIFO" if stat.S_ISFIFO(mode) else "a directory" if stat.S_ISDIR(mode) else
                    "a character device" if stat.S_ISCHR(mode) else "a block device" if stat.S_ISBLK(mode) else
                    "a socket" if stat.S_ISSOCK(mode) else "not a file")
            raise CertificateError(f"{path}: not a regular file ({kind})")
        chunks, left = [], cap + 1
        while left > 0:
            chunk = os.read(fd, min(left, 2**20))
            if not chunk:
                break
            chunks.append(chunk)
            left -= len(chunk)
    finally:
        os.close(fd)
    data = b"".join(chunks)
    if len(data) > cap:
        raise CertificateError(f"{path}: larger than {cap} bytes")
    return data


def certificate_files(directory):
    """The certificate files under ``directory``: ``c1/k*.json``, the tagged configurations'
    ``c1/{dart,crease,corner}/*.json``, then ``injectivity/k*.json``.

    Parameters
    ----------
    directory : str or Path

    Returns
    -------
    list of Path
        Sorted by name within each folder.

    Examples
    --------
    >>> from ccproof.tables.format import certificates_dir
    >>> files = certificate_files(certificates_dir())
    >>> files[0].parent.name, files[0].name, files[-1].parent.name
    ('c1', 'k003.json', 'injectivity')
    """
    d = Path(directory)
    tagged = sorted(f for fam in ("dart", "crease", "corner") for f in (d / "c1" / fam).glob("[kn]*.json"))
    return sorted((d / "c1").glob("k*.json")) + tagged + sorted((d / "injectivity").glob("k*.json"))


def check_coverage(valences):
    """Do the valences (ints and {'min': k0}) cover every k >= 3? Returns (ok, message).

    Every k >= 3 must be covered at least once: k = 3..k0-1 each by its own certificate, where k0 is the
    smallest interval certificate {'min': k0}. Interval certificates may overlap each other and single
    valences (a k >= k0 certificate next to the k >= 40 one, or k = 39 next to k >= 10), since a
    statement proved twice is still proved; a single valence may appear at most once (a second file
    for the same k is a publishing mistake).

    Parameters
    ----------
    valences : iterable of int or dict ``{"min": k0}``

    Returns
    -------
    (bool, str)

    Examples
    --------
    >>> check_coverage([3, 4, {"min": 5}])
    (True, 'every k >= 3 covered (3..4 one by one, k >= 5)')
    >>> check_coverage([3, {"min": 5}])
    (False, 'missing valences [4]')
    """
    ints = sorted(v for v in valences if isinstance(v, int))
    tails = sorted({v["min"] for v in valences if isinstance(v, dict)})
    if len(set(ints)) != len(ints):
        return False, "a valence is claimed twice"
    if not tails:
        return False, "no interval k >= k0"
    k0 = tails[0]
    missing = sorted(set(range(3, k0)) - set(ints))
    if missing:
        return False, f"missing valences {missing}"
    over = [k for k in ints if k >= k0]
    return True, (f"every k >= 3 covered (3..{k0 - 1} one by one, k >= {k0}"
                  + ("".join(f", k >= {t}" for t in tails[1:]))
                  + (f"; covered twice: {over[0]}..{over[-1]}" if over else "") + ")")
