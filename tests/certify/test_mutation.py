"""Property test: any mutation of a valid certificate ends in VERIFIED or FAIL with a reason, quickly,
never in an exception (hypothesis drives delete / duplicate / retype / alter of any field or entry)."""

import copy
import json
import time

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from ccproof.certify import verify as V
from ccproof.tables.format import certificates_dir

BASES = [json.loads((certificates_dir() / sub / "k004.json").read_text()) for sub in ("c1", "injectivity")]
ODD_VALUES = [None, True, -1, 0, 2**70, 1.5, "", "x", "1e-999999999", "9" * 100, [], {}, [[]], {"a": 1}, "0L" * 200]


def _paths(obj, prefix=()):
    yield prefix
    if isinstance(obj, dict):
        for k, v in obj.items():
            yield from _paths(v, prefix + (k,))
    elif isinstance(obj, list):
        for i, v in enumerate(obj):
            yield from _paths(v, prefix + (i,))


def _mutate(cert, path, op, value):
    c = copy.deepcopy(cert)
    if not path:
        return value if op == "retype" else c
    parent = c
    for key in path[:-1]:
        parent = parent[key]
    last = path[-1]
    if op == "delete":
        del parent[last]
    elif op == "duplicate" and isinstance(parent, list):
        parent.insert(last, copy.deepcopy(parent[last]))
    elif op == "duplicate":
        parent[f"{last}_copy"] = copy.deepcopy(parent[last])
    elif op == "alter" and isinstance(parent[last], str):
        parent[last] = parent[last][::-1] + "1"
    elif op == "alter" and isinstance(parent[last], int) and not isinstance(parent[last], bool):
        parent[last] += 1
    else:
        parent[last] = value
    return c


@st.composite
def mutations(draw):
    base = draw(st.sampled_from(BASES))
    paths = list(_paths(base))
    path = draw(st.sampled_from(paths))
    op = draw(st.sampled_from(["delete", "duplicate", "retype", "alter"]))
    if not path and op == "delete":
        op = "retype"
    return _mutate(base, path, op, draw(st.sampled_from(ODD_VALUES)))


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(mutations())
def test_mutated_certificates_end_in_a_verdict(cert):
    t = time.perf_counter()
    res = V.verify_certificate(cert, log=lambda s: None)  # must not raise
    assert time.perf_counter() - t < 20
    if not res:
        assert res.error or any(not p.ok and p.name for p in res.parts)
        assert all(p.message for p in res.failures() if p.name.startswith(("D cell", "B ", "E "))) or res.error
