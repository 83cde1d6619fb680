"""The trusted verifier of ccproof certificates (``ccproof verify``): the statement is derived from the schema and
the valence, the hints replayed without search; docs/trusted_base.md lists the modules and their guarantees."""

import json
import os
import stat
import time
from collections.abc import Callable
from pathlib import Path

from .errors import CertificateError
from .record import Part, Recorder, VerifyResult
from .registry import C1_SCHEMA, ROUTES, SCHEMA, TAGGED, TAGGED_SCHEMA, check_coverage, coverage, route_of
from .replay import check_size, close_budget

__all__ = ["SCHEMA", "C1_SCHEMA", "TAGGED_SCHEMA", "CertificateError", "Part", "VerifyResult", "verify_certificate",
           "verify_file", "check_coverage", "coverage", "certificate_files", "read_certificate_bytes", "ROUTES"]

MAX_FILE_BYTES = 4 * 2**20  # the published certificates: at most 64 KB; MAX_BOXES boxes take at most ~1 MB
#: what a malformed file can raise while it is being read; each ends in FAIL with the reason
_MALFORMED = (CertificateError, ValueError, TypeError, KeyError, IndexError, AttributeError, RecursionError,
              OverflowError, ZeroDivisionError)
#: what a file that is not a regular one is, by its type bits
_NOT_REGULAR = {stat.S_IFIFO: "a FIFO", stat.S_IFDIR: "a directory", stat.S_IFCHR: "a character device",
                stat.S_IFBLK: "a block device", stat.S_IFSOCK: "a socket"}


def verify_certificate(cert, log=print, path=None):
    """Check a parsed certificate through the one route of the registry that takes its schema, configuration and
    statement (:func:`.registry.route_of`); a :class:`VerifyResult`, never an exception on bad input.

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
    try:
        route, res.family, res.valence = route_of(cert)
        res.schema, res.statement = route.schema, route.statement
        check_size(cert)
        res.N = cert["N"] if type(cert.get("N")) is int else None
        route.check(cert, res.family, res.valence, Recorder(res, log), log)
    except _MALFORMED as exc:
        res.error = f"{type(exc).__name__}: {exc}" if not isinstance(exc, CertificateError) else str(exc)
    finally:
        close_budget()  # the replay budget that check_size opened for this certificate
    res.seconds = time.perf_counter() - t0
    return res


def verify_file(path: str | Path, log: Callable[[str], object] = print) -> VerifyResult:
    """Verify one certificate file (a regular file of at most :data:`MAX_FILE_BYTES`: :func:`read_certificate_bytes`);
    logs PASS/FAIL per part, then VERIFIED or FAILED with the reason.

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
    """The bytes of a regular file of at most ``cap`` bytes: opened non-blocking (a FIFO does not wait), judged by
    ``fstat`` of the descriptor (a FIFO, directory, device or link to one is refused), at most ``cap + 1`` bytes read.

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
            raise CertificateError(f"{path}: not a regular file ({_NOT_REGULAR.get(stat.S_IFMT(mode), 'not a file')})")
        chunks, left = [], cap + 1
        while left > 0 and (chunk := os.read(fd, min(left, 2**20))):
            chunks.append(chunk)
            left -= len(chunk)
    finally:
        os.close(fd)
    data = b"".join(chunks)
    if len(data) > cap:
        raise CertificateError(f"{path}: larger than {cap} bytes")
    return data


def certificate_files(directory):
    """The certificate files under ``directory``: ``c1/k*.json``, ``c1/{dart,crease,corner}/*.json``, then
    ``injectivity/k*.json``, each folder sorted by name.

    >>> from ccproof.tables.format import certificates_dir
    >>> files = certificate_files(certificates_dir())
    >>> files[0].parent.name, files[0].name, files[-1].parent.name
    ('c1', 'k003.json', 'injectivity')
    """
    d = Path(directory)
    tagged = sorted(f for fam in TAGGED for f in (d / "c1" / fam).glob("[kn]*.json"))
    return sorted((d / "c1").glob("k*.json")) + tagged + sorted((d / "injectivity").glob("k*.json"))
