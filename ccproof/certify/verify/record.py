"""Verdicts (the parts of a check with their reasons) and strict reading of certificate fields (trusted)."""

from dataclasses import dataclass, field

from flint import fmpq

from .errors import CertificateError


@dataclass
class Part:
    """One checked claim; ``bound``: the smallest claimed bound re-checked (exact), for box parts."""

    name: str
    ok: bool
    message: str = ""
    bound: fmpq | None = None


@dataclass
class VerifyResult:
    """The verdict on one certificate, True exactly when every part passed and ``error`` (why the file could not
    be checked) is None. ``family`` (smooth, dart, crease, corner), ``valence`` (k, N, or ``{"min": k0}``) and
    ``statement`` (injective, C1, not C1) are what the verifier checked, set from the bytes it verified;
    ``margins``: per section, the smallest bound re-checked.

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
    """Collects the parts of a :class:`VerifyResult` and logs each as PASS/FAIL.

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
        if ok and bound is not None and section is not None:  # exact bounds: min is exact
            self.result.margins[section] = min(bound, self.result.margins.get(section, bound))
        self.log(f"  {'PASS' if ok else 'FAIL'}  {name}{(': ' + msg) if msg else ''}")

    @property
    def failed(self):
        return any(not p.ok for p in self.result.parts)


def field_of(obj, key, kind, where):
    """``obj[key]`` of type ``kind`` (a bool is never an int here), else a :class:`CertificateError` naming ``where``.

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
    """Refuse an object with unknown or missing keys: nothing in a certificate goes unchecked.

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


def bounded_int(obj, key, lo, hi, where="certificate"):
    """``obj[key]``, an int in lo..hi (:func:`field_of`), else a :class:`CertificateError` naming the range."""
    val = field_of(obj, key, int, where)
    if val < lo or val > hi:
        raise CertificateError(f"{key} must lie in {lo}..{hi}")
    return val


def read_prec(cert):
    """The working precision in bits of a certificate (``prec``, 64..1024)."""
    return bounded_int(cert, "prec", 64, 1024)


def read_valence(cert):
    """``cert["valence"]``: an int k or ``{"min": k0}``, within 3..10^6 (so every derived check stays fast).

    >>> read_valence({"valence": 5}), read_valence({"valence": {"min": 7}})
    (5, {'min': 7})
    """
    k = field_of(cert, "valence", (int, dict), "certificate")
    if isinstance(k, dict):
        exact_keys(k, ("min",), "valence")
        bounded_int(k, "min", 3, 10**6, "valence")
    elif not 3 <= k <= 10**6:
        raise CertificateError(f"valence {k} outside 3..10^6")
    return k


def kname(k):
    """``"5"`` or ``">=7"`` (:attr:`VerifyResult.configuration`'s example)."""
    return f">={k['min']}" if isinstance(k, dict) else str(k)
