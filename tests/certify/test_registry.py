"""The registry of certificate families (ccproof/certify/verify/registry.py): one dispatch, the verdict's
configuration and statement recorded by the verifier, coverage decided from the verdicts alone (never from
a file read again), and the prover's routes over the same table."""

import argparse
import json
import os
import threading

import pytest

from ccproof.certify import prover as P
from ccproof.certify.verify import Part, VerifyResult, coverage, verify_certificate, verify_file
from ccproof.certify.verify.registry import ROUTES, UNDECIDED, family_coverage, route_of, routes_for
from ccproof.cli import verify as cli_verify
from ccproof.tables.format import certificates_dir

QUIET = {"log": lambda line: None}
C = certificates_dir()


def _ok(name, statement):
    """A verified result as the verifier records it (family, size, statement), for the coverage."""
    fam, n = name.split(":")
    n = {"min": int(n[2:])} if n.startswith(">=") else int(n)
    return VerifyResult(family=fam, valence=n, statement=statement, parts=[Part("S", True)])


def _line(results, fam):
    return next(s for s in coverage(results)[1] if s.startswith(fam + ":"))


def test_coverage_counts_the_interval():
    singles = [_ok(f"crease:{n}", "not C1") for n in range(5, 101)] + [_ok(f"crease:{n}", "C1") for n in (2, 3)]
    assert _line(singles, "crease").startswith("crease: INCOMPLETE: no certificate for >= 101")
    tail = _ok("crease:>=101", "not C1")
    assert _line(singles + [tail], "crease").startswith("crease: OK (crease:1-100, every N)")
    assert "not C1 for 5-100, >= 101" in _line(singles + [tail], "crease")
    assert _line(singles[1:] + [_ok("crease:>=5", "not C1")], "crease").startswith("crease: OK")  # 5 by the tail
    assert _line(singles[:-2] + [tail], "crease").startswith("crease: INCOMPLETE: no certificate for 2-3")
    clash = _line([_ok("crease:40", "C1"), _ok("crease:>=16", "not C1")], "crease")
    assert clash.startswith("crease: CONTRADICTORY: certified twice: [40]")


def test_coverage_contradictory_incomplete_and_failed_results():
    r = _ok("crease:5", "not C1")
    ok, lines = coverage([r, r])
    assert not ok and _line([r, r], "crease").startswith("crease: CONTRADICTORY: certified twice: [5]")
    assert _line([r, _ok("crease:5", "C1")], "crease").startswith("crease: CONTRADICTORY")
    assert _line([r], "crease").startswith("crease: INCOMPLETE: no certificate for 2-3, 6-100, >= 101")
    failed = VerifyResult(family="crease", valence=6, statement="not C1", parts=[Part("S", False, "no")])
    assert "6-100" in _line([r, failed], "crease")  # a failed result counts for nothing
    smooth = [_ok(f"smooth:{k}", "C1") for k in (3, 4)] + [_ok("smooth:>=5", "C1")]
    assert coverage(smooth)[1][0] == "C1 (Reif) coverage: OK: every k >= 3 covered (3..4 one by one, k >= 5)"
    assert coverage(smooth)[1][1].startswith("injectivity (Appendix A) coverage: INCOMPLETE")
    assert coverage(smooth[1:])[1][0] == "C1 (Reif) coverage: INCOMPLETE: missing valences [3]"


def _complete(fam, lo, extra=()):
    decided = [n for n in range(lo, 101) if f"{fam}:{n}" not in UNDECIDED]
    return [_ok(f"{fam}:{n}", "not C1") for n in [*decided, *extra]] + [_ok(f"{fam}:>=101", "not C1")]


def test_an_undecided_configuration_with_a_verified_certificate_counts_as_certified():
    line = _line(_complete("crease", 1), "crease")
    assert line.startswith("crease: OK") and line.endswith(
        "undecided: 1 (lam2 = 1/4 in a Jordan block), 4 (lam2 = 1/2 in a Jordan block)")
    line = _line(_complete("crease", 1, extra=(4,)), "crease")
    assert line.startswith("crease: OK") and "not C1 for 2-100, >= 101" in line
    assert line.endswith("undecided: 1 (lam2 = 1/4 in a Jordan block)")
    # dart:2 and corner:4 have refutations: no longer undecided, so a family without them is incomplete
    line = _line([r for r in _complete("corner", 1) if r.configuration != "corner:4"], "corner")
    assert line.startswith("corner: INCOMPLETE: no certificate for 4;")
    assert line.endswith("undecided: 2 (lam1 = 1/2 triple with a Jordan block)")
    line = _line(_complete("dart", 2), "dart")
    assert line.startswith("dart: OK") and line.endswith("undecided: none") and "not C1 for 2-100, >= 101" in line
    ok, line = family_coverage("dart", [(n, "C1") for n in range(3, 101)])
    assert not ok and "no certificate for 2, >= 101" in line


def _args(files, **kw):
    return argparse.Namespace(files=[str(f) for f in files], all=False, serial=True, quiet=True, json=True,
                              no_progress=True, scheduler=None, jobs=None, **kw)


def _tamper_after_verification(tmp_path, monkeypatch):
    """Two published certificates copied to ``tmp_path``; once each is verified, crease:5's statement is
    swapped ("not C1" -> "C1") and corner:3's file replaced by a FIFO with no writer."""
    swapped, fifo = tmp_path / "n005.json", tmp_path / "n003.json"
    cert5 = json.loads((C / "c1" / "crease" / "n005.json").read_text())
    swapped.write_text(json.dumps(cert5))
    fifo.write_text((C / "c1" / "corner" / "n003.json").read_text())
    real = cli_verify.verify_task

    def check_then_tamper(args):
        out = real(args)
        if args[0].endswith("n005.json"):
            swapped.write_text(json.dumps(dict(cert5, statement="C1")))
        else:
            fifo.unlink()
            os.mkfifo(fifo)
        return out

    monkeypatch.setattr(cli_verify, "verify_task", check_then_tamper)
    return swapped, fifo


def _run_without_hanging(args, fifo):
    """``ccproof verify`` in a thread; fails (after releasing the reader) if it waits on the FIFO."""
    rc = []
    worker = threading.Thread(target=lambda: rc.append(cli_verify.run(args)), daemon=True)
    worker.start()
    worker.join(60)
    hung = worker.is_alive()
    if hung:  # release the reader blocked on the FIFO, then fail
        os.close(os.open(fifo, os.O_WRONLY | os.O_NONBLOCK))
        worker.join(60)
    assert not hung, "the report waited on a FIFO that replaced a verified file"
    return rc[0]


def test_a_file_changed_or_replaced_by_a_fifo_after_verification_changes_nothing(tmp_path, monkeypatch, capsys):
    """--json reports what was verified, and nothing waits on the FIFO."""
    swapped, fifo = _tamper_after_verification(tmp_path, monkeypatch)
    assert _run_without_hanging(_args([swapped, fifo]), fifo) == 0
    rows = [json.loads(s) for s in capsys.readouterr().out.splitlines()]
    assert [(r["configuration"], r["statement"], r["verdict"]) for r in rows] == [
        ("crease:5", "not C1", "VERIFIED"), ("corner:3", "not C1", "VERIFIED")]


def test_the_coverage_of_verify_all_ignores_files_changed_after_verification(tmp_path, monkeypatch, capsys):
    """--all (here over the two files alone): the coverage lines count crease:5 and corner:3 as verified."""
    import ccproof.certify.verify as V

    swapped, fifo = _tamper_after_verification(tmp_path, monkeypatch)
    monkeypatch.setattr(V, "certificate_files", lambda d: [])
    args = _args([swapped, fifo])
    args.all, args.json = True, False
    assert _run_without_hanging(args, fifo) == 1  # incomplete, of course
    out = capsys.readouterr().out
    assert "2 of 2 certificates verified" in out
    assert "crease: INCOMPLETE: no certificate for 2-3, 6-100, >= 101; C1 for none, not C1 for 5;" in out
    assert "corner: INCOMPLETE: no certificate for 1, 4-100, >= 101; C1 for none, not C1 for 3;" in out


def test_coverage_reads_no_file(tmp_path):
    """The results of files that are then changed on disk, or removed, give the same coverage."""
    path = tmp_path / "n005.json"
    path.write_text((C / "c1" / "crease" / "n005.json").read_text())
    res = verify_file(path, **QUIET)
    before = coverage([res])
    path.write_text(json.dumps(dict(json.loads(path.read_text()), statement="C1")))
    assert coverage([res]) == before
    path.unlink()
    assert coverage([res]) == before and "not C1 for 5;" in _line([res], "crease")


# (configuration, statement, verdict) of `ccproof verify --json` on these published files before the registry
PUBLISHED = {
    "c1/k003.json": ("smooth:3", "C1"), "c1/k_ge_40.json": ("smooth:>=40", "C1"),
    "injectivity/k003.json": ("smooth:3", "injective"), "c1/crease/n002.json": ("crease:2", "C1"),
    "c1/crease/n005.json": ("crease:5", "not C1"), "c1/corner/n001.json": ("corner:1", "C1"),
    "c1/corner/n003.json": ("corner:3", "not C1"), "c1/dart/k003.json": ("dart:3", "C1"),
    "c1/dart/k040.json": ("dart:40", "C1"), "c1/crease/n_ge_101.json": ("crease:>=101", "not C1"),
    "c1/corner/n_ge_101.json": ("corner:>=101", "not C1"),
}


def test_json_fields_of_published_certificates_are_unchanged(capsys):
    files = [C / f for f in PUBLISHED]
    assert cli_verify.run(_args(files)) == 0
    rows = [json.loads(s) for s in capsys.readouterr().out.splitlines()]
    assert [(r["configuration"], r["statement"], r["verdict"]) for r in rows] == [
        (*v, "VERIFIED") for v in PUBLISHED.values()]


@pytest.mark.parametrize("rel, route", [
    ("injectivity/k004.json", "smooth injective"), ("c1/k_ge_40.json", "smooth C1"),
    ("c1/crease/n005.json", "tagged not C1"), ("c1/dart/k004.json", "tagged C1"),
    ("c1/dart/k_ge_101.json", "dart:>=K0 C1"), ("c1/corner/n_ge_101.json", "crease, corner:>=N0 not C1")])
def test_each_published_kind_takes_its_route(rel, route):
    cert = json.loads((C / rel).read_text())
    r, fam, n = route_of(cert)
    assert r.name == route and r.schema == cert["schema"]
    assert sum(x.takes(fam, n) and x.schema == cert["schema"] for x in ROUTES) == (1 if fam == "smooth" else 2 - (
        isinstance(n, dict)))


@pytest.mark.parametrize("change, why", [
    ({"statement": "injective"}, "statement must be one of ('not C1', 'C1')"),
    ({"statement": "C1", "configuration": "corner:>=101"}, 'corner:>=N0 is certified "not C1" only'),
    ({"configuration": "smooth:5"}, "is not dart:K, crease:N or corner:N"),
    ({"schema": "ccproof.c1/1"}, "unknown certificate schema"),
])
def test_a_statement_or_configuration_no_route_takes_fails_with_the_reason(change, why):
    cert = json.loads((C / "c1" / "crease" / "n005.json").read_text())
    res = verify_certificate(dict(cert, **change), **QUIET)
    assert not res and why in res.error, res.error


def test_the_verdict_carries_what_was_checked():
    cert = json.loads((C / "c1" / "crease" / "n005.json").read_text())
    res = verify_certificate(cert, **QUIET)
    assert res and (res.configuration, res.statement, res.family, res.valence) == ("crease:5", "not C1", "crease", 5)
    res = verify_certificate(dict(cert, statement="C1"), **QUIET)  # the C1 route: no map, so it fails
    assert not res and res.statement == "C1" and "unknown field(s) 'witness'" in res.error


def test_the_prover_has_one_route_per_family_of_the_registry():
    assert list(P.PROVERS) == [r.name for r in ROUTES]
    assert [r.name for r in routes_for("dart:>=101")] == ["dart:>=K0 C1"]
    assert [r.name for r in routes_for("corner:>=101")] == ["crease, corner:>=N0 not C1"]
    cert, why = P.prove_configuration("crease:5")
    assert cert["statement"] == "not C1" and verify_certificate(cert, **QUIET)
    cert, why = P.prove_configuration("crease:4")
    assert cert is None and why.startswith("undecided: ") and "Jordan" in why


def test_report_tagged_prints_the_coverage_the_verifier_decides(monkeypatch):
    import ccproof.certify.verify as V
    from ccproof.cli.report import tagged_table

    files = [C / "c1" / "crease" / "n005.json", C / "c1" / "corner" / "n003.json", C / "injectivity" / "k003.json"]
    monkeypatch.setattr(V, "certificate_files", lambda d: files)
    table = tagged_table()
    assert "| crease:5 | not C1 | VERIFIED |" in table and "| corner:3 | not C1 | VERIFIED |" in table
    assert "smooth" not in table
    assert "* crease: INCOMPLETE: no certificate for 2-3, 6-100, >= 101; C1 for none, not C1 for 5; undecided: " \
           "1 (lam2 = 1/4 in a Jordan block), 4 (lam2 = 1/2 in a Jordan block)" in table
    assert "* dart: INCOMPLETE: no certificate for 2-100, >= 101" in table


def test_each_configuration_statement_pair_has_at_most_one_route():
    keys = [(r.schema, fam, size, r.statement) for r in ROUTES for fam in r.families for size in r.sizes]
    assert len(keys) == len(set(keys))
    # and one schema per statement of a smooth valence, so the schema alone picks a smooth route
    assert sorted(r.statement for r in ROUTES if r.families == ("smooth",)) == ["C1", "injective"]


@pytest.mark.parametrize("name", ["smooth:4", "smooth:>=40"])
def test_the_smooth_c1_route_proves_what_the_verifier_accepts(name):
    cert, why = P.prove_configuration(name, statement="C1")
    res = verify_certificate(cert, **QUIET)
    assert why == "C1" and res and (res.configuration, res.statement) == (name, "C1")
