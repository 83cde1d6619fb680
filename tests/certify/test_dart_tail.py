"""The dart:>=K0 certificate (ccproof.certify.verify.dart_tail): what a forger would change FAILs with a reason.

The fast tests take the published record with its map part cut off (the steps before the map need only the
spectral trees): each forgery must FAIL at the step that reads what it changed, and the honest record must
pass every step before the map. The whole record is a slow test (about a minute).
"""

from __future__ import annotations

import copy
import json

import pytest

from ccproof.certify.verify import verify_certificate
from ccproof.tables.format import certificates_dir

PUBLISHED = certificates_dir() / "c1" / "dart" / "k_ge_101.json"
QUIET = {"log": lambda line: None}


@pytest.fixture(scope="module")
def record():
    return json.loads(PUBLISHED.read_text())


def _tree(n, bound):
    return {"grid": [1] * n, "leaves": [{"cell": [0] * n, "path": "", "bound": bound}]}


def _no_map(cert, sigma_boxes=10, layer=3):
    """The record with its map cut to one root leaf per tree, each claiming a bound its whole region does not
    reach: the map step fails at its first leaf, after the models are built."""
    out = copy.deepcopy(cert)
    pos, neg = ([_tree(n, b)] * sigma_boxes for n, b in ((2, "1e-9"), (2, "-1e-9")))
    lay = {str(q): [_tree(1, "1e-9")] * sigma_boxes for q in range(layer)}
    cover = {"bulk": pos, "middle": pos, "layer": lay}
    out["parts"] = {"regularity": cover, "transversal": cover,
                    "winding": {"Y<0 bulk": neg, "X>0 bulk": pos, "Y>0 bulk": pos, "Y<0 middle": neg,
                                "Y<0 layer": {str(q): [_tree(1, "-1e-9")] * sigma_boxes for q in range(layer)}}}
    return out


def _fails(cert, why, part=None):
    res = verify_certificate(cert, **QUIET)
    assert not res
    text = (res.error or "") + " ".join(f"{p.name}: {p.message}" for p in res.failures())
    assert why in text, text
    if part is not None:
        assert res.failures() and res.failures()[0].name.startswith(part), [p.name for p in res.failures()]
    return res


def test_every_step_before_the_map_passes(record):
    res = verify_certificate(_no_map(record), **QUIET)
    names = [p.name[0] for p in res.parts if p.ok]
    assert names == ["S", "Z", "G", "E"], [(p.name, p.message) for p in res.parts]
    assert res.failures()[0].name.startswith("M") and "R bulk, sigma box 0" in res.failures()[0].message


def test_a_map_without_its_trees_fails_before_any_arithmetic(record):
    cert = copy.deepcopy(record)
    cert["parts"] = {}
    res = _fails(cert, "parts")
    assert not res.parts
    cert = copy.deepcopy(record)
    del cert["parts"]["regularity"]["bulk"][3]["leaves"][-1]
    res = _fails(cert, "R bulk, sigma box 3")
    assert not res.parts


@pytest.mark.parametrize("change, why", [
    (lambda c: c.__setitem__("statement", "not C1"), "\"C1\" only"),
    (lambda c: c["map"].__setitem__("orientation", -1), "orientation +1"),
    (lambda c: c.__setitem__("configuration", "dart:>=100"), "101 <= K0"),
    (lambda c: c.__setitem__("configuration", "crease:>=101"), "\"not C1\" only"),
    (lambda c: c.__setitem__("extra", 1), "extra"),
    (lambda c: c["spectrum"].__setitem__("circle", "4.49"), "sigma_hi < sigma_r"),
    (lambda c: c["spectrum"].__setitem__("sigma", ["3.1", "4.4935"]), "pi < sigma_lo"),
    (lambda c: c["spectrum"]["re"]["N"]["leaves"].pop(), "spectrum re N"),
    (lambda c: c["spectrum"]["re"]["F"]["leaves"][0].__setitem__("bound", "-0.5"), "sign"),
    (lambda c: c["taylor"].__setitem__("r", "0.005"), "1/K0 < r"),
    (lambda c: c["regions"].__setitem__("s0", "0.05"), "fraction"),
    (lambda c: c["spectrum"].__setitem__("sigma_h", 0), "sigma_h"),
    (lambda c: c["spectrum"].__setitem__("mode0_h", "16"), "mode0_h"),
])
def test_record_forgeries_fail_before_any_arithmetic(record, change, why):
    cert = _no_map(record)
    change(cert)
    res = _fails(cert, why)
    assert not res.parts, [p.name for p in res.parts]  # the record step: no part was run


@pytest.mark.parametrize("change", [
    lambda c: c.__setitem__("prec", 256),
    lambda c: c["taylor"].__setitem__("disc_grid", 30),
    lambda c: c["taylor"].__setitem__("order", 20),
    lambda c: c["spectrum"].__setitem__("sigma_h", 4096),
])
def test_each_size_is_priced_and_past_the_budget_fails_before_any_arithmetic(record, change):
    """The published record is inside the work budget; raising one declared size (precision, disc grid, the
    bulk's Taylor order, h-balls) within its grammar takes it past, and it FAILs before any part runs."""
    from ccproof.certify.verify.dart_tail import MAX_WORK, read_record, record_work

    assert record_work(read_record(record, 101)) <= MAX_WORK
    cert = copy.deepcopy(record)
    change(cert)
    res = _fails(cert, "beyond the budget")
    assert not res.parts


def test_a_raised_spectral_bound_fails_the_spectrum(record):
    cert = _no_map(record)
    leaf = cert["spectrum"]["re"]["I"]["leaves"][7]
    leaf["bound"] = "5"
    _fails(cert, "spectrum re I: the leaf", part="G")


def test_another_circle_fails_the_spectrum(record):
    """The trees were made for sigma_r = 5.4; on the circle through 6.2 (still a legal hint) a leaf fails."""
    cert = _no_map(record)
    cert["spectrum"]["circle"] = "6.2"
    _fails(cert, "spectrum re", part="G")


def test_a_bracket_without_sigma_k_fails_the_eigenvector_lemma(record):
    """sigma(K) lies in (4.4848, 4.4935) for K >= 101: a bracket below it has no sign change."""
    cert = _no_map(record)
    cert["spectrum"]["sigma"] = ["4.3", "4.45"]
    _fails(cert, "no certain sign change", part="E")


def test_a_larger_k0_is_a_weaker_statement_and_still_shown(record):
    """The trees' cells are fractions of their roots, so the same record read as K0 = 200 replays on the
    smaller roots [0, 1/200]: every step before the map passes (a true, weaker statement), and K0 = 100
    is refused outright."""
    cert = _no_map(record)
    cert["configuration"] = "dart:>=200"
    res = verify_certificate(cert, **QUIET)
    assert [p.name[0] for p in res.parts if p.ok] == ["S", "Z", "G", "E"]
    cert["configuration"] = "dart:>=100"
    _fails(cert, "101 <= K0")


@pytest.mark.slow
def test_published_record_verifies_with_json_summary():
    from ccproof.certify.verify import verify_file
    from ccproof.cli.verify import summary

    res = verify_file(PUBLISHED, **QUIET)
    assert res, res.error or [(p.name, p.message) for p in res.failures()]
    s = summary(res)
    assert (s["configuration"], s["statement"], s["verdict"]) == ("dart:>=101", "C1", "VERIFIED")
    assert [p["name"][0] for p in s["parts"]] == ["S", "Z", "G", "E", "M", "C"]
