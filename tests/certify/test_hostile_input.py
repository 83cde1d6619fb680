"""The verifier on hostile input: it reads only regular files, with a byte cap; it checks that the boxes
partition the domain before replaying any; it replays depth-first, one split per inner node of the tree;
every certificate FAILs with a reason within stated bounds (10 s of CPU and 1 GB resident per file,
measured with getrusage in a fresh process), and ``ccproof verify --all`` goes on past each bad file.

The bounds are asserted loosely (the hostile files below fail in about a second and 100 MB); the
verifier before these checks waited forever on the FIFO, read ``/dev/zero`` until MemoryError and spent
minutes, then FLINT's memory, on the random deep paths.
"""

import json
import os
import random
import subprocess
import sys
from pathlib import Path

import pytest

import ccproof
from ccproof.certify import verify as V
from ccproof.tables.format import certificates_dir

REPO = Path(ccproof.__file__).resolve().parents[1]
CPU_S, RSS_BYTES = 10.0, 2**30  # the stated bounds: 10 s and 1 GB per hostile file (docs/certificates.md, "Bounds")
HARD_TIMEOUT_S = 90  # the parent gives up (and the test fails) after this
# the child's address space is capped so that a runaway read or replay fails here, not on the machine
CHILD = r"""
import json, resource, sys
resource.setrlimit(resource.RLIMIT_AS, (3 * 2**30, 3 * 2**30))
from ccproof.certify.verify import verify_file
lines = []
res = verify_file(sys.argv[1], log=lines.append)
use = resource.getrusage(resource.RUSAGE_SELF)
# peak resident bytes of this process image: Linux's VmHWM (ru_maxrss keeps the forking parent's peak
# across exec, so under a large pytest process it reports the parent's size)
try:
    hwm = next(int(l.split()[1]) * 1024 for l in open("/proc/self/status") if l.startswith("VmHWM:"))
except (OSError, StopIteration):
    hwm = use.ru_maxrss * 1024
print(json.dumps({"ok": bool(res), "error": res.error, "lines": lines, "cpu": use.ru_utime + use.ru_stime,
                  "rss": hwm}))
"""


def load(name, kind="injectivity"):
    return json.loads((certificates_dir() / kind / name).read_text())


def verify_in_child(path):
    """verify_file(path) in a fresh process; its verdict, CPU seconds and peak resident bytes."""
    env = dict(os.environ, PYTHONPATH=str(REPO))
    try:
        out = subprocess.run([sys.executable, "-c", CHILD, str(path)], capture_output=True, text=True, env=env,
                             timeout=HARD_TIMEOUT_S)
    except subprocess.TimeoutExpired:
        pytest.fail(f"verify_file({path}) did not end within {HARD_TIMEOUT_S} s")
    assert out.returncode == 0, out.stderr[-2000:]
    return json.loads(out.stdout.splitlines()[-1])


def random_path(rng, tokens, axes=4):
    return "".join(f"{rng.randrange(axes)}{rng.choice('LH')}" for _ in range(tokens))


def complete_tree(depth, axes):
    """The 2^depth leaves of the complete split tree, splitting the axes cyclically (as the prover does)."""
    paths = [""]
    for d in range(depth):
        paths = [p + f"{axes[d % len(axes)]}{s}" for p in paths for s in "LH"]
    return paths


def split_further(cert, depth):
    """Every box split into 2^depth boxes that keep its claimed bound: de Casteljau's coefficients of a
    sub-box are convex combinations of the box's, so their minimum does not decrease (the published
    bounds are rounded down to 6 digits, far more than the arb balls widen)."""
    for sec, axes in (("regularity", (0, 1)), ("cells", (0, 1)), ("corner", (2, 3, 0, 1))):
        for key, boxes in cert["parts"][sec].items():
            cert["parts"][sec][key] = [{"path": b["path"] + p, "bound": b["bound"]}
                                       for b in boxes for p in complete_tree(depth, axes)]
    return cert


def count_boxes(cert):
    return sum(len(boxes) for sec in cert["parts"].values() for boxes in sec.values())


def hostile(kind, tmp_path):
    """Write one hostile file named injectivity/k099.json; return its path and the expected reason."""
    d = tmp_path / "injectivity"
    d.mkdir(exist_ok=True)
    p = d / "k099.json"
    rng = random.Random(27)
    if kind == "fifo":
        os.mkfifo(p)
        return p, "not a regular file (a FIFO)"
    if kind == "link to /dev/zero":
        p.symlink_to("/dev/zero")
        return p, "not a regular file (a character device)"
    if kind == "directory":
        p.mkdir()
        return p, "not a regular file (a directory)"
    c = load("k005.json")
    if kind == "over the cap":  # a valid certificate padded with blanks beyond the documented 4 MiB
        p.write_text(json.dumps(c) + " " * 4 * 2**20)
        return p, "larger than"
    if kind == "400 random 64-token corner paths":
        c["parts"]["corner"]["P2"] = [{"path": random_path(rng, 64), "bound": "0.01"} for _ in range(400)]
        reason = "malformed box path"
    elif kind == "400 random 32-token corner paths":
        c["parts"]["corner"]["P2"] = [{"path": random_path(rng, 32), "bound": "0.01"} for _ in range(400)]
        reason = "do not partition"
    elif kind == "a 2000-token path":
        c["parts"]["corner"]["P3"] = [{"path": random_path(rng, 2000), "bound": "0.01"}]
        reason = "malformed box path"
    elif kind == "every list: random 32-token paths":
        for sec, nv in (("regularity", 2), ("cells", 2), ("corner", 4)):
            for key in c["parts"][sec]:
                c["parts"][sec][key] = [{"path": random_path(rng, 32, nv), "bound": "0.01"} for _ in range(40)]
        reason = "do not partition"
    elif kind == "C1: random star paths":
        c = load("k005.json", "c1")
        c["parts"]["star"]["P2s1"] = [{"path": random_path(rng, 32, 1), "bound": "0.01"} for _ in range(400)]
        reason = "parts.star.P2s1: the boxes do not partition"
    elif kind == "k >= 40: random cell paths":
        c = load("k_ge_40.json")
        cells = c["pieces"][-1]["parts"]["cells"]
        for key in cells:
            cells[key] = [{"path": random_path(rng, 32, 3), "bound": "0.01"} for _ in range(20)]
        reason = "do not partition"
    elif kind == "level N = 8":  # a 2.6 KB file that made the verifier list 2^15 cells before failing
        c["N"] = 8
        reason = "N must lie in 1..6"
    elif kind == "too many boxes":  # a valid partition of 2^14 boxes: above the per-certificate limit
        c["parts"]["cells"]["0,1,0,0"] = [{"path": q, "bound": "0.01"} for q in complete_tree(14, (0, 1))]
        reason = "boxes"
    else:
        raise AssertionError(kind)
    p.write_text(json.dumps(c))
    return p, reason


KINDS = ["fifo", "link to /dev/zero", "directory", "over the cap", "400 random 64-token corner paths",
         "400 random 32-token corner paths", "a 2000-token path", "every list: random 32-token paths",
         "C1: random star paths", "k >= 40: random cell paths", "level N = 8", "too many boxes"]


@pytest.mark.parametrize("kind", KINDS)
def test_a_hostile_file_fails_with_a_reason_within_the_bounds(kind, tmp_path):
    p, reason = hostile(kind, tmp_path)
    out = verify_in_child(p)
    assert not out["ok"]
    assert reason in out["error"], out["error"]
    assert out["lines"][-1].startswith(f"FAILED {p}"), out["lines"]  # the FAILED line names the file
    assert out["cpu"] < CPU_S, out
    assert out["rss"] < RSS_BYTES, out


def test_verify_all_goes_on_past_every_hostile_file(tmp_path):
    root = tmp_path / "certificates"
    (root / "c1").mkdir(parents=True)
    (root / "c1" / "k003.json").write_text(json.dumps(load("k003.json", "c1")))
    bad = {}
    for i, kind in enumerate(["fifo", "link to /dev/zero", "over the cap", "400 random 64-token corner paths",
                              "every list: random 32-token paths"]):
        sub = tmp_path / f"h{i}"
        sub.mkdir()
        p, reason = hostile(kind, sub)
        target = root / "injectivity" / f"k{95 + i:03d}.json"
        target.parent.mkdir(exist_ok=True)
        os.rename(p, target)
        bad[target] = reason
    good = root / "injectivity" / "k100.json"
    good.write_text(json.dumps(load("k005.json")))
    env = dict(os.environ, PYTHONPATH=str(REPO), CCPROOF_CERTIFICATES=str(root))
    try:
        out = subprocess.run([sys.executable, "-m", "ccproof.cli", "verify", "--all", "--serial", "--quiet"],
                             capture_output=True, text=True, env=env, timeout=HARD_TIMEOUT_S)
    except subprocess.TimeoutExpired:
        pytest.fail(f"verify --all did not end within {HARD_TIMEOUT_S} s")
    lines = out.stdout.splitlines()
    for p, reason in bad.items():
        assert any(s.startswith(f"FAILED {p}") and reason in s for s in lines), (p, out.stdout, out.stderr)
    assert f"VERIFIED {good}" in out.stdout and f"VERIFIED {root / 'c1' / 'k003.json'}" in out.stdout
    assert "2 of 7 certificates verified" in out.stdout
    assert out.returncode == 1  # failures (and an incomplete coverage), but no crash
    assert "Traceback" not in out.stderr


def test_a_deep_valid_partition_verifies_and_one_leaf_past_the_limit_fails(tmp_path):
    """A caterpillar down to the path limit: 32 halvings of the corner form (33 boxes), each box keeping the
    published bound, verifies; the same with 33 halvings is refused by name."""
    c = load("k005.json")
    for name, boxes in c["parts"]["corner"].items():
        (b,) = boxes
        axes = (2, 3, 0, 1)
        paths = [""]
        for d in range(32):
            a = axes[d % 4]
            stem = paths.pop()
            paths += [stem + f"{a}H", stem + f"{a}L"]
        c["parts"]["corner"][name] = [{"path": q, "bound": b["bound"]} for q in paths]
    p = tmp_path / "deep.json"
    p.write_text(json.dumps(c))
    out = verify_in_child(p)
    assert out["ok"], out["lines"][-3:]
    assert out["rss"] < RSS_BYTES
    boxes = c["parts"]["corner"]["P2"]
    stem = boxes[-1]["path"]
    boxes[-1:] = [{"path": stem + "2L", "bound": "0.01"}, {"path": stem + "2H", "bound": "0.01"}]
    res = V.verify_certificate(c, log=lambda s: None)
    assert not res and "malformed box path" in res.error and "parts.corner.P2" in res.error


def test_a_partition_split_further_verifies_and_a_forged_leaf_fails():
    """k = 5 split into 128 boxes (each published box into 4) verifies; raising one deep leaf's bound above
    the published one by a factor 10, or dropping a leaf, fails and names the box."""
    c = split_further(load("k005.json"), 2)
    assert count_boxes(c) == 128
    res = V.verify_certificate(c, log=lambda s: None)
    assert res, [p.message for p in res.failures()] + [res.error]
    leaf = c["parts"]["corner"]["P3"][3]
    leaf["bound"] = str(10 * float(leaf["bound"]))
    lines = []
    assert not V.verify_certificate(c, log=lines.append)
    assert f"box {leaf['path']!r}: a Bernstein coefficient" in "\n".join(lines)
    c = split_further(load("k005.json"), 2)
    dropped = c["parts"]["cells"]["0,1,0,0"].pop(1)["path"]
    res = V.verify_certificate(c, log=lambda s: None)
    assert not res and f"no box covers {dropped!r} (gap)" in res.error


@pytest.mark.slow
def test_a_512_box_partition_verifies_within_the_bounds(tmp_path):
    """k = 5's 32 box lists each split into 16 boxes (512 boxes, paths of 4 halvings) verify."""
    c = split_further(load("k005.json"), 4)
    assert count_boxes(c) == 512
    p = tmp_path / "k005_512.json"
    p.write_text(json.dumps(c))
    out = verify_in_child(p)
    assert out["ok"], out["lines"][-3:]
    assert out["rss"] < RSS_BYTES


def test_the_partition_is_checked_before_any_box_is_replayed(monkeypatch):
    """A gap in the last box list fails before the first Bernstein form is split or built."""
    from ccproof.rigorous.bernstein import BernsteinForm

    def no_split(*args):
        raise AssertionError("a form was split before the partition was checked")

    monkeypatch.setattr(BernsteinForm, "split", no_split)
    c = split_further(load("k005.json"), 1)
    c["parts"]["corner"]["P3"].pop()
    res = V.verify_certificate(c, log=lambda s: None)
    assert not res and "parts.corner.P3" in res.error and "(gap)" in res.error


def _dart_at_the_grammars_limits():
    """The published dart:>=101 record with the largest hints its grammar allows (disc grid 64, orders 24, 24,
    64, 64 layer quadrants, 1,024 bits) and one root leaf per tree: about 45 KB, and on the verifier before its
    work budget some 26 minutes of CPU before it FAILed."""
    c = json.loads((certificates_dir() / "c1" / "dart" / "k_ge_101.json").read_text())
    layer, one = 64, 1
    c["prec"] = 1024
    c["taylor"] = {"r": "0.03125", "disc_grid": 64, "sigma_boxes": one, "order": 24, "layer_order": 24,
                   "exp_order": 64}
    c["regions"]["layer"] = layer

    def tree(n, bound):
        return [{"grid": [1] * n, "leaves": [{"cell": [0] * n, "path": "", "bound": bound}]}] * one
    lay = {str(q): tree(1, "1e-9") for q in range(layer)}
    cover = {"bulk": tree(2, "1e-9"), "middle": tree(2, "1e-9"), "layer": lay}
    c["parts"] = {"regularity": cover, "transversal": cover,
                  "winding": {"Y<0 bulk": tree(2, "-1e-9"), "X>0 bulk": tree(2, "1e-9"), "Y>0 bulk": tree(2, "1e-9"),
                              "Y<0 middle": tree(2, "-1e-9"), "Y<0 layer": {str(q): tree(1, "-1e-9") for q in lay}}}
    return c


def _dart_at_the_budget(key):
    """The published dart:>=101 record with one declared size (the disc grid, or the h-balls of the eigenvector
    lemma) raised to the largest value the work budget admits, and its last map leaf (the last one replayed)
    false: every step runs to the end before it FAILs."""
    from ccproof.certify.verify.dart_tail import MAX_WORK, read_record, record_work

    c = json.loads((certificates_dir() / "c1" / "dart" / "k_ge_101.json").read_text())
    section = c["taylor"] if key == "disc_grid" else c["spectrum"]

    def work(v):  # the declared work, or past the budget where the record is refused for it
        section[key] = v
        try:
            return record_work(read_record(c, 101))
        except V.CertificateError as exc:
            assert "beyond the budget" in str(exc)
            return MAX_WORK + 1

    v = section[key]
    while work(v + 1) <= MAX_WORK:
        v += 1 if key == "disc_grid" else 50
    while work(v) > MAX_WORK:
        v -= 1
    assert MAX_WORK < work(v + 1) and work(v) <= MAX_WORK  # the record left at v, the largest within
    c["parts"]["winding"]["Y<0 layer"]["2"][-1]["leaves"][-1]["bound"] = "-1e3"
    return c


@pytest.mark.slow
@pytest.mark.parametrize("key", ["disc_grid", "sigma_h"])
def test_the_costliest_dart_record_within_the_budget_fails_in_under_10_s(key, tmp_path):
    """Within the budget a hostile ``dart:>=K0`` record costs what its declared sizes do: the costliest ones
    (a size at the budget's edge, the last leaf false) still end FAILED, at that leaf, within 10 s of CPU in a
    fresh process (docs/certificates.md, "Bounds"; about 8.5 s each on the loaded reference machine, about
    13.7 s for the disc grid before the budget was re-priced). About 10 s each: slow."""
    p = tmp_path / "record.json"
    p.write_text(json.dumps(_dart_at_the_budget(key)))
    out = verify_in_child(p)
    assert not out["ok"]
    last = "Y<0 layer 2, sigma box 9: the leaf [(0, 1/101)] claims -1000"
    assert any(last in line for line in out["lines"]), out["lines"][-3:]
    assert out["cpu"] < CPU_S, out


@pytest.mark.parametrize("kind", ["dart:>=101 at the grammar's limits", "8,192 boxes, the last bound false"])
def test_a_record_beyond_the_work_budget_fails_with_the_reason_in_seconds(kind, tmp_path):
    """The work a record declares is refused before the arithmetic it would take (docs/certificates.md,
    "Bounds"): the dart record at its grammar's limits before any model is built, the 8,192-box split of
    k = 5 (every box of the published certificate into 256, the last bound raised past its box) once the box
    lists' splits pass the certificate's budget, about 5 CPU-minutes before the budget (3.7 s CPU now)."""
    if kind.startswith("dart"):
        c, reason = _dart_at_the_grammars_limits(), "beyond the budget of 10 s"
    else:
        c = split_further(load("k005.json"), 8)
        assert count_boxes(c) == 8192
        c["parts"]["corner"]["P3"][-1]["bound"] = "1e6"
        reason = "coefficient operations in all, beyond the budget"
    p = tmp_path / "record.json"
    p.write_text(json.dumps(c))
    out = verify_in_child(p)
    assert not out["ok"]
    assert any(reason in line for line in [out["error"] or "", *out["lines"]]), out["lines"][-3:]
    assert out["lines"][-1].startswith(f"FAILED {p}"), out["lines"][-3:]
    assert out["cpu"] < CPU_S, out
