"""Verdicts: the parts of a check with their reasons, and strict reading of certificate fields (trusted)."""

from __future__ import annotations

from dataclasses import dataclass, field

from flint import fmpq

from .errors import CertificateError


@dataclass
class Part:
    """One checked claim: ``name``, ``ok``, a ``message`` (the reason when it failed) and, for box parts,
    the smallest claimed bound that was re-checked (``bound``, an exact fmpq) in local coordinates.

    Attributes
    ----------
    name : str
    ok : bool
    message : str
    bound : fmpq or None

    Examples
    --------
    >>> Part("S", False, "not an eigenvector")
    Part(name='S', ok=False, message='not an eigenvector', bound=None)
    """

    name: str
    ok: bool
    message: str = ""
    bound: fmpq | None = None


@dataclass
class VerifyResult:
    """The verdict on one certificate: ``ok`` only when every part passed; ``parts`` in order; ``error``
    names why the file could not be checked at all (malformed, unknown field), else None. True as a bool
    exactly when ``ok``. ``margins`` maps a section (``regularity``, ``cells``, ``corner``, ``star``) to the
    smallest bound re-checked in this run. ``family``, ``valence`` and ``statement`` are what the verifier
    checked (set by :func:`ccproof.certify.verify.verify_certificate` from the bytes it verified, before the
    checks: a failed result may carry them too); ``configuration`` names the two first.

    Attributes
    ----------
    path, schema : str or None
    family : str or None
        ``"smooth"``, ``"dart"``, ``"crease"`` or ``"corner"``.
    valence : int or dict or None
        k (N, K), or ``{"min": k0}`` for every k >= k0.
    statement : str or None
        ``"injective"``, ``"C1"`` or ``"not C1"``.
    N : int or None
    parts : list of Part
    error : str or None
    seconds : float
    margins : dict[str, fmpq]

    Examples
    --------

    >>> r = VerifyResult(parts=[Part("A", True), Part("B", False, "a coefficient is not above the bound")])
    >>> bool(r), [p.name for p in r.failures()]
    (False, ['B'])
    >>> VerifyResult(family="crease", valence={"min": 101}, statement="not C1").configuration
    'crease:>=101'
    """

    path: str | None = None
    schema: str | None = None
    family: str | None = None
    valence: object = None
    statement: str | None = None
    N: int | None = None
    parts: list = field(default_factory=list)
    error: str | None = None
    seconds: float = 0.0
    margins: dict = field(default_factory=dict)

    @property
    def configuration(self):
        return None if self.family is None or self.valence is None else f"{self.family}:{kname(self.valence)}"

    @property
    def ok(self):
        return self.error is None and bool(self.parts) and all(p.ok for p in self.parts)

    def __bool__(self):
        return self.ok

    def failures(self):
        return [p for p in self.parts if not p.ok]


class Recorder:
    """Collects the parts of a :class:`VerifyResult` and prints each as PASS/FAIL through ``log``.

    Parameters
    ----------
    result : VerifyResult
    log : callable (str) -> None

    Examples
    --------
    >>> r = VerifyResult()
    >>> rec = Recorder(r, print)
    >>> rec("A", True, bound=fmpq(1, 3), section="cells"); rec("B", False, "too small")
      PASS  A
      FAIL  B: too small
    >>> rec.failed, r.margins
    (True, {'cells': 1/3})
    """

    def __init__(self, result, log):
        self.result, self.log = result, log

    def __call__(self, name, ok, msg="", bound=None, section=None):
        self.result.parts.append(Part(name, bool(ok), msg, bound))
        if ok and bound is not None and section is not None:
            old = self.result.margins.get(section)
            self.result.margins[section] = bound if old is None or bound < old else old
        self.log(f"  {'PASS' if ok else 'FAIL'}  {name}{(': ' + msg) if msg else ''}")

    @property
    def failed(self):
        return any(not p.ok for p in self.result.parts)


def field_of(obj, key, kind, where):
    """``obj[key]`` of type ``kind`` (bool is never an int here), else :class:`CertificateError`.

    Parameters
    ----------
    obj : object (a dict from JSON)
    key : str
    kind : type or tuple of types
    where : str
        Named in the error.

    Returns
    -------
    The value.

    Examples
    --------
    >>> field_of({"N": 3}, "N", int, "hints")
    3
    >>> field_of({"N": True}, "N", int, "hints")
    Traceback (most recent call last):
    ...
    ccproof.certify.verify.errors.CertificateError: hints: field 'N' has the wrong type
    """
    if not isinstance(obj, dict) or key not in obj:
        raise CertificateError(f"{where}: missing field {key!r}")
    val = obj[key]
    if not isinstance(val, kind) or isinstance(val, bool):
        raise CertificateError(f"{where}: field {key!r} has the wrong type")
    return val


def exact_keys(obj, keys, where):
    """Reject unknown and missing keys: nothing in a certificate goes unchecked.

    Parameters
    ----------
    obj : object (a dict from JSON)
    keys : sequence of str
    where : str
        Named in the error.

    Raises
    ------
    CertificateError

    Examples
    --------
    >>> exact_keys({"path": "0L", "bound": "1", "x": 0}, ("path", "bound"), "box")
    Traceback (most recent call last):
    ...
    ccproof.certify.verify.errors.CertificateError: box: unknown field(s) 'x' (nothing unchecked ...)
    """
    if not isinstance(obj, dict):
        raise CertificateError(f"{where} must be an object")
    extra, missing = sorted(set(obj) - set(keys)), sorted(set(keys) - set(obj))
    if extra:
        raise CertificateError(f"{where}: unknown field(s) {', '.join(map(repr, extra))} (nothing unchecked "
                               "is allowed in a certificate)")
    if missing:
        raise CertificateError(f"{where}: missing field(s) {', '.join(map(repr, missing))}")


def read_valence(cert):
    """An int k >= 3 or ``{"min": k0}`` with k0 >= 3 (at most 10^6, so every derived check stays fast).

    Parameters
    ----------
    cert : dict
        The certificate (its ``valence`` field is read).

    Returns
    -------
    int or dict

    Examples
    --------
    >>> read_valence({"valence": 5}), read_valence({"valence": {"min": 7}})
    (5, {'min': 7})
    """
    k = field_of(cert, "valence", (int, dict), "certificate")
    if isinstance(k, dict):
        exact_keys(k, ("min",), "valence")
        k0 = k["min"]
        if not isinstance(k0, int) or isinstance(k0, bool) or not 3 <= k0 <= 10**6:
            raise CertificateError(f"valence interval must be {{'min': K0}} with 3 <= K0 <= 10^6, got {k!r}")
    elif not 3 <= k <= 10**6:
        raise CertificateError(f"valence {k} outside 3..10^6")
    return k


def kname(k):
    """Display name of a valence: ``"5"`` or ``">=7"``.

    Parameters
    ----------
    k : int or dict ``{"min": k0}``

    Returns
    -------
    str

    Examples
    --------
    >>> kname(5), kname({"min": 7})
    ('5', '>=7')
    """
    return f">={k['min']}" if isinstance(k, dict) else str(k)
