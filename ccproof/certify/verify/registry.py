"""The certificate families: the one registry every entry point dispatches through, and the coverage of what the
verifier proved, decided from its own verdicts, never from a file (trusted; docs/trusted_base.md).

>>> [r.name for r in routes_for("crease:5")]
['tagged not C1', 'tagged C1']
>>> [r.name for r in routes_for("smooth:>=40")]
['smooth injective', 'smooth C1']
"""

from dataclasses import dataclass
from importlib import import_module

from .errors import CertificateError
from .record import field_of, read_valence

#: the schemas, one per kind of hints (docs/certificates.md)
SCHEMA = "ccproof.injectivity/3"
C1_SCHEMA = "ccproof.c1/2"
TAGGED_SCHEMA = "ccproof.tagged-c1/1"
TAGGED = ("dart", "crease", "corner")
#: the arguments a checker takes after the certificate, before (part, log): n, or nothing, or N0 (with the family)
_ARGS = {"n": lambda fam, n: (n,), "": lambda fam, n: (), "n0": lambda fam, n: (n["min"],),
         "family n0": lambda fam, n: (fam, n["min"])}


@dataclass(frozen=True)
class Route:
    """One family of certificates: the ``schema``, the ``families`` (``("smooth",)`` or some of :data:`TAGGED`) and
    ``sizes`` (``"one"`` N, ``"every"`` N >= N0) it speaks about, its ``statement`` (injective, C1, not C1) and its
    checker ``"module:function"`` with the arguments of :data:`_ARGS`, imported when the route is taken (verifying
    one kind of certificate loads that kind's modules only)."""

    name: str
    schema: str
    families: tuple
    sizes: tuple
    statement: str
    checker: str
    args: str

    def takes(self, family, n):
        """Does this route speak about ``family`` with size ``n`` (an int or ``{"min": N0}``)?"""
        return family in self.families and ("every" if isinstance(n, dict) else "one") in self.sizes

    def check(self, cert, family, n, part, log):
        """Run the checker: it records its parts into ``part``, raises :class:`CertificateError` if malformed."""
        module, function = self.checker.split(":")
        getattr(import_module(f".{module}", __package__), function)(cert, *_ARGS[self.args](family, n), part, log)


#: every family of certificates the verifier checks, in the order the prover tries them for a configuration
ROUTES = (
    Route("smooth injective", SCHEMA, ("smooth",), ("one", "every"), "injective", "injectivity:verify_injectivity",
          "n"),
    Route("smooth C1", C1_SCHEMA, ("smooth",), ("one", "every"), "C1", "c1:verify_c1", "n"),
    Route("tagged not C1", TAGGED_SCHEMA, TAGGED, ("one",), "not C1", "tagged_c1:verify_tagged", ""),
    Route("tagged C1", TAGGED_SCHEMA, TAGGED, ("one",), "C1", "tagged_c1:verify_tagged", ""),
    Route("dart:>=K0 C1", TAGGED_SCHEMA, ("dart",), ("every",), "C1", "dart_tail:verify_dart_tail", "n0"),
    Route("crease, corner:>=N0 not C1", TAGGED_SCHEMA, ("crease", "corner"), ("every",), "not C1",
          "tagged_limit:verify_tail", "family n0"),
)
SCHEMAS = tuple(dict.fromkeys(r.schema for r in ROUTES))


def configuration_of(name):
    """``(family, n)`` of ``smooth:K``, ``smooth:>=K0`` or a tagged name (:func:`.tagged.parse_configuration`).

    >>> configuration_of("smooth:>=40"), configuration_of("dart:7")
    (('smooth', {'min': 40}), ('dart', 7))
    """
    from .tagged import parse_configuration

    fam, _, size = str(name).partition(":")
    if fam != "smooth":
        return parse_configuration(name)
    digits = size.removeprefix(">=")
    if not (digits.isascii() and digits.isdigit()) or len(digits) > 7:
        raise CertificateError(f"configuration {str(name)[:40]!r} is not smooth:K or smooth:>=K0")
    return fam, read_valence({"valence": {"min": int(digits)} if size.startswith(">=") else int(digits)})


def routes_for(name):
    """The routes that can certify the configuration ``name``, in :data:`ROUTES` order (the prover's)."""
    fam, n = configuration_of(name)
    return [r for r in ROUTES if r.takes(fam, n)]


def route_of(cert):
    """``(route, family, n)`` of a parsed certificate: its schema, its configuration (a smooth certificate's
    ``valence``, a tagged one's ``configuration``) and a tagged one's ``statement`` pick the one route.

    >>> route, fam, n = route_of({"schema": TAGGED_SCHEMA, "configuration": "corner:>=101", "statement": "not C1"})
    >>> route.name, fam, n
    ('crease, corner:>=N0 not C1', 'corner', {'min': 101})
    >>> route_of({"schema": TAGGED_SCHEMA, "configuration": "dart:>=101", "statement": "not C1"})
    Traceback (most recent call last):
    ...
    ccproof.certify.verify.errors.CertificateError: dart:>=K0 is certified "C1" only (its statement is fixed ...)
    """
    schema = cert.get("schema") if isinstance(cert, dict) else None
    if schema not in SCHEMAS:
        raise CertificateError(f"unknown certificate schema {str(schema)[:60]!r} (expected one of "
                               f"{', '.join(map(repr, SCHEMAS))})")
    if schema != TAGGED_SCHEMA:
        return next(r for r in ROUTES if r.schema == schema), "smooth", read_valence(cert)
    from .tagged import parse_configuration

    fam, n = parse_configuration(field_of(cert, "configuration", str, "certificate"))
    routes = [r for r in ROUTES if r.schema == schema and r.takes(fam, n)]
    statement = field_of(cert, "statement", str, "certificate")
    for r in routes:
        if r.statement == statement:
            return r, fam, n
    if isinstance(n, dict):
        said = " or ".join(f'"{r.statement}"' for r in routes)
        raise CertificateError(f"{fam}:>={'K0' if fam == 'dart' else 'N0'} is certified {said} only (its statement "
                               "is fixed by the configuration)")
    raise CertificateError(f"statement must be one of {tuple(r.statement for r in routes)}, got {statement[:20]!r}")


#: per tagged family, the configurations a complete run accounts for one by one (each certified or undecided);
#: every N above the range needs a verified ``FAMILY:>=N0`` with N0 at most the range's end + 1
TAGGED_RANGE = {"dart": (2, 100), "crease": (1, 100), "corner": (1, 100)}
#: the configurations of the ranges that no certificate decides yet, with the reason (docs/tagged_c1.md); one
#: that has a verified certificate counts as certified
UNDECIDED = {
    "crease:1": "lam2 = 1/4 in a Jordan block",
    "crease:4": "lam2 = 1/2 in a Jordan block",
    "corner:2": "lam1 = 1/2 triple with a Jordan block",
}


def coverage(results):
    """``(ok, lines)``: what the verified results cover (their family, size and statement, set by the verifier):
    every k >= 3 for smooth C1 and injectivity (:func:`check_coverage`), each tagged family (:func:`family_coverage`).

    >>> from ccproof.certify.verify.record import Part, VerifyResult
    >>> r = VerifyResult(family="smooth", valence={"min": 3}, statement="C1", parts=[Part("S", True)])
    >>> ok, lines = coverage([r, VerifyResult(family="smooth", valence={"min": 3}, statement="injective")])
    >>> ok, lines[0][:29], lines[1]
    (False, 'C1 (Reif) coverage: OK: every', 'injectivity (Appendix A) coverage: INCOMPLETE: no interval k >= k0')
    """
    verified = [r for r in results if r and r.family is not None and r.statement is not None]
    rows = []
    for label, statement in (("C1 (Reif)", "C1"), ("injectivity (Appendix A)", "injective")):
        ok, msg = check_coverage([r.valence for r in verified if r.family == "smooth" and r.statement == statement])
        rows.append((ok, f"{label} coverage: {'OK' if ok else 'INCOMPLETE'}: {msg}"))
    rows += [family_coverage(fam, [(r.valence, r.statement) for r in verified if r.family == fam]) for fam in TAGGED]
    return all(ok for ok, _ in rows), [line for _, line in rows]


def family_coverage(fam, certified):
    """``(ok, line)`` of one tagged family from the ``(n, statement)`` of its verified certificates: ok unless an N
    is certified twice (two files, or one against a ``FAMILY:>=N0`` of the other statement), an N of
    :data:`TAGGED_RANGE` is neither certified nor in :data:`UNDECIDED`, or no ``FAMILY:>=N0`` reaches past the range.

    >>> family_coverage("crease", [(5, "not C1"), (5, "not C1")])[1][:49]
    'crease: CONTRADICTORY: certified twice: [5]; C1 f'
    >>> family_coverage("crease", [(5, "not C1")])[1][:60]
    'crease: INCOMPLETE: no certificate for 2-3, 6-100, >= 101; C'
    >>> ok, line = family_coverage("corner", [(n, "not C1") for n in (1, 3, 4)] + [({"min": 5}, "not C1")])
    >>> ok, line[:60], line[60:]
    (True, 'corner: OK (corner:1-100, every N): C1 for none, not C1 for ', '1, 3-4, >= 5; undecided: 2 (lam1 ...)')
    """
    rows = [(n, st) for n, st in certified if not isinstance(n, dict)]
    tails = sorted((n["min"], st) for n, st in certified if isinstance(n, dict))
    ns = [n for n, _ in rows]
    twice = _twice(rows, tails)
    lo, hi = TAGGED_RANGE[fam]
    n0 = min((t for t, _ in tails), default=hi + 2)
    open_ = [n for n in range(lo, min(hi, n0 - 1) + 1) if n not in ns]
    undecided = [n for n in open_ if f"{fam}:{n}" in UNDECIDED]
    missing = ", ".join(filter(None, [_ranges([n for n in open_ if n not in undecided])]
                               + ([f">= {hi + 1}"] if n0 > hi + 1 else [])))
    said = {st: _said(rows, tails, st) for st in ("C1", "not C1")}
    status = (f"CONTRADICTORY: certified twice: {twice}; " if twice else f"INCOMPLETE: no certificate for {missing}; "
              if missing else f"OK ({fam}:{lo}-{hi}, every N): ")
    why = ", ".join(f"{n} ({UNDECIDED[f'{fam}:{n}']})" for n in undecided) or "none"
    return not twice and not missing, (f"{fam}: {status}C1 for {said['C1']}, not C1 for {said['not C1']}; "
                                       f"undecided: {why}")


def _twice(rows, tails):
    """The N certified twice: two single certificates, or a single one against a ``FAMILY:>=N0``'s statement."""
    ns = [n for n, _ in rows]
    return sorted({n for n in ns if ns.count(n) > 1}) or sorted(
        n for n, st in rows for t, st_t in tails if n >= t and st != st_t)


def _said(rows, tails, statement):
    """The N certified with ``statement``, as ranges, then the tails ``>= N0``; ``none`` if there are none."""
    return ", ".join(filter(None, [_ranges(sorted(n for n, s in rows if s == statement))]
                            + [f">= {t}" for t, s in tails if s == statement])) or "none"


def check_coverage(valences):
    """``(ok, message)``: do the valences (ints, ``{"min": k0}``) cover every k >= 3? Each k below the least k0 by
    its own certificate, at most once (a second file for one k is a publishing mistake); intervals may overlap.

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
    missing = sorted(set(range(3, tails[0])) - set(ints))
    if missing:
        return False, f"missing valences {missing}"
    over = [k for k in ints if k >= tails[0]]
    return True, (f"every k >= 3 covered (3..{tails[0] - 1} one by one, k >= {tails[0]}"
                  + "".join(f", k >= {t}" for t in tails[1:])
                  + (f"; covered twice: {over[0]}..{over[-1]}" if over else "") + ")")


def _ranges(ns):
    """``[1, 2, 3, 5]`` -> ``'1-3, 5'``."""
    runs = []
    for n in ns:
        if runs and runs[-1][1] == n - 1:
            runs[-1][1] = n
        else:
            runs.append([n, n])
    return ", ".join(str(a) if a == b else f"{a}-{b}" for a, b in runs)
