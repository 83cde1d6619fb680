"""Scale-out on Dask: a LocalCluster of 2 worker processes gives the serial results to the byte.

Needs the optional extra ``scale`` (``pip install 'ccproof[scale]'``); skipped without it. One cluster
is shared by the module (its start-up costs seconds on a loaded machine).
"""

import json
import os
import re
import signal
import sys
import time
from pathlib import Path

import numpy as np
import pytest

distributed = pytest.importorskip("distributed",
                                  reason="needs the optional extra 'scale': pip install 'ccproof[scale]'")

from ccproof.cli import main  # noqa: E402
from ccproof.errors import CCProofError  # noqa: E402
from ccproof.scale import build_counts, evaluate_dask, read_shards, run_tasks, ship  # noqa: E402
from ccproof.scale.engine import TaskFailed, parse_scheduler  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def cluster():
    import logging

    import cloudpickle

    # the workers cannot import this test module by name: ship its helper functions by value
    cloudpickle.register_pickle_by_value(sys.modules[__name__])
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None,
                                  silence_logs=logging.ERROR) as c, distributed.Client(c) as client:
        client.wait_for_workers(2)
        yield c, client
    cloudpickle.unregister_pickle_by_value(sys.modules[__name__])


def test_scheduler_spec_errors_name_the_option():
    assert parse_scheduler("local:2").workers == 2 and parse_scheduler(None).kind == "local"
    assert parse_scheduler("local:1").kind == parse_scheduler("local:4", serial=True).kind == "serial"
    for bad in ("local:x", "local:-1", "nonsense"):
        with pytest.raises(CCProofError, match="--scheduler"):
            parse_scheduler(bad)


def test_certify_on_the_cluster_is_byte_identical_to_serial(cluster, tmp_path):
    serial, dist = tmp_path / "serial", tmp_path / "dist"
    assert main(["certify", "3-4", "--serial", "--no-verify", "--out", str(serial)]) == 0
    assert main(["certify", "3-4", "--scheduler", cluster[0].scheduler_address, "--no-verify",
                 "--out", str(dist)]) == 0
    for name in ("k003.json", "k004.json"):
        a, b = (serial / name).read_bytes(), (dist / name).read_bytes()
        assert a == b and len(a) > 1000
    # and both equal the published certificates (written by the serial prover when they were made)
    for name in ("k003.json", "k004.json"):
        assert (serial / name).read_bytes() == (ROOT / "certificates" / "injectivity" / name).read_bytes()


def _forged(tmp_path):
    cert = json.loads((ROOT / "certificates" / "c1" / "k004.json").read_text())
    cert["parts"]["regularity"]["P1"][0]["bound"] = "26e-2"  # the true minimum is 1/4: not certifiable
    bad = tmp_path / "forged_k004.json"
    bad.write_text(json.dumps(cert))
    return bad


def test_verify_verdicts_equal_on_the_cluster(cluster, tmp_path, capsys):
    from ccproof.cli.verify import verify_task

    files = [ROOT / "certificates" / "c1" / "k003.json", ROOT / "certificates" / "c1" / "k004.json",
             _forged(tmp_path), ROOT / "certificates" / "c1" / "k005.json"]
    work = [(str(f), True) for f in files]
    serial = run_tasks(verify_task, work, "serial", progress=False)
    dist = run_tasks(verify_task, work, cluster[1], progress=False)
    verdicts = [bool(r) for r, _ in serial.results]
    assert verdicts == [True, True, False, True]
    assert [bool(r) for r, _ in dist.results] == verdicts
    assert [r.failures()[0].name for r, _ in dist.results if not r] == [
        r.failures()[0].name for r, _ in serial.results if not r]
    # the command line on the cluster: same verdicts, exit status 1 for the forged file
    capsys.readouterr()
    assert main(["verify", *map(str, files), "--quiet", "--scheduler", cluster[0].scheduler_address]) == 1
    out = capsys.readouterr().out
    assert "3 of 4 certificates verified" in out and f"FAILED {files[2]}" in out


def test_dask_evaluation_equals_numpy_to_the_bit_and_builds_once_per_worker(cluster, refdir):
    import dask.array as da

    from ccproof.mesh import read_obj
    from ccproof.reparam.surface import limit_surface

    mesh = read_obj(refdir / "meshes" / "sector_k5.obj")
    rng = np.random.default_rng(7)
    n = 6000
    f, u, v = rng.integers(0, mesh.n_faces, n), rng.random(n), rng.random(n)
    u[:50] = 0.0  # at the extraordinary corners and on edges too
    v[:50] = rng.choice([0.0, 1.0], 50)
    shipped = ship(limit_surface, mesh)
    local = limit_surface(mesh)
    for par in ("natural", "characteristic"):
        out = evaluate_dask(shipped, da.from_array(f, chunks=(1000, 2000, 3000)), u, v, derivatives=2,
                            parameterization=par)
        got = cluster[1].compute(out, sync=True)
        assert set(got) == {"P", "Pu", "Pv", "Puu", "Puv", "Pvv"}
        # a point's bits do not depend on the other points of its chunk: one numpy call on all points
        ref = local.evaluate(f, u, v, derivatives=2, parameterization=par)
        for name in got:
            a, b = np.ascontiguousarray(got[name]), np.ascontiguousarray(ref[name])
            if a.tobytes() != b.tobytes():  # say which points differ and by how much (not a byte dump)
                rows = np.flatnonzero((a.view(np.uint64) != b.view(np.uint64)).any(axis=1))
                pytest.fail(f"{par} {name}: {rows.size} of {len(a)} points differ in their bits, first "
                            f"{rows[:8].tolist()}: dask {a[rows[:3]].tolist()} numpy {b[rows[:3]].tolist()}")
    counts = cluster[1].run(build_counts)
    per_worker = [c.get(shipped.digest, 0) for c in counts.values()]
    assert max(per_worker) == 1 and sum(per_worker) >= 1  # 6 chunks, at most one build per worker


def test_dask_evaluations_of_one_surface_never_take_each_others_blocks(cluster, refdir):
    """While the result of an evaluation is held, the scheduler keeps its tasks (``compute(sync=True)``
    releases its result asynchronously, after it returns); a later evaluation of the same surface on the
    same chunks (other parameterization, derivatives or points) must not get them. The blocks of both
    had the same keys, and the characteristic evaluation returned the natural values."""
    import dask.array as da

    from ccproof.mesh import read_obj
    from ccproof.reparam.surface import limit_surface

    mesh = read_obj(refdir / "meshes" / "sector_k5.obj")
    rng = np.random.default_rng(11)
    n = 3000
    f, u, v = rng.integers(0, mesh.n_faces, n), rng.random(n) * 0.5, rng.random(n) * 0.5
    shipped = ship(limit_surface, mesh)
    local = limit_surface(mesh)
    client = cluster[1]
    face = da.from_array(f, chunks=1000)
    held = client.compute(evaluate_dask(shipped, face, u, v, derivatives=1, parameterization="natural"))
    first = held.result()
    held_p = client.persist(evaluate_dask(shipped, face, u, v, derivatives=0, parameterization="natural")["P"])
    cases = [(u, v, 1, "characteristic"), (u, v, 0, "characteristic"), (v, u, 1, "natural")]
    for uu, vv, d, par in cases:
        got = client.compute(evaluate_dask(shipped, face, uu, vv, derivatives=d, parameterization=par), sync=True)
        ref = local.evaluate(f, uu, vv, derivatives=d, parameterization=par)
        for name in ref:
            assert np.array_equal(got[name], ref[name]), (par, d, name)
    assert np.array_equal(first["Pu"], local.evaluate(f, u, v, derivatives=1)["Pu"])
    assert np.array_equal(client.compute(held_p, sync=True), first["P"])
    del held, held_p


def test_digest_is_content(refdir):
    from ccproof.evaluate import limit_surface
    from ccproof.mesh import QuadMesh, read_obj

    m = read_obj(refdir / "meshes" / "cube.obj")
    same = QuadMesh(m.vertices.copy(), m.faces.copy())
    moved = m.vertices.copy()
    moved[0, 0] += 1e-12
    assert ship(limit_surface, m).digest == ship(limit_surface, same).digest
    assert ship(limit_surface, m).digest != ship(limit_surface, QuadMesh(moved, m.faces)).digest


def test_eval_command_shards_on_the_cluster_equal_serial(cluster, refdir, tmp_path):
    obj = str(refdir / "meshes" / "sector_k3.obj")
    assert main(["eval", obj, "--samples", "5000", "--chunk", "1500", "--derivatives", "2",
                 "--scheduler", cluster[0].scheduler_address, "--out", str(tmp_path / "shards")]) == 0
    assert main(["eval", obj, "--samples", "5000", "--chunk", "1500", "--derivatives", "2", "--serial",
                 "--out", str(tmp_path / "serial.npz")]) == 0
    shards = read_shards(tmp_path / "shards")
    assert [c for c in shards["P"].chunks[0]] == [1500, 1500, 1500, 500]
    with np.load(tmp_path / "serial.npz") as z:
        for name in ("face", "u", "v", "P", "Pu", "Pv", "Puu", "Puv", "Pvv"):
            assert np.array_equal(shards[name].compute(), z[name]), name
        # one chunk reproduces the unchunked draw; independent evaluation of the same points agrees
        from ccproof.mesh import read_obj
        from ccproof.reparam.surface import limit_surface

        f, u, v = z["face"][:1500], z["u"][:1500], z["v"][:1500]
        rng = np.random.default_rng(0)
        assert np.array_equal(f, rng.integers(0, read_obj(obj).n_faces, 1500))
        ref = limit_surface(read_obj(obj)).evaluate(f, u, v, derivatives=0)
        assert np.array_equal(ref["P"], z["P"][:1500])
    # a scheduler address receives the surface by value: unpickled once per worker, never built there
    counts = cluster[1].run(build_counts)
    assert all(c <= 1 for per_worker in counts.values() for c in per_worker.values())
    # the shard folder is a point set for the next evaluation (out of core, chunk by chunk)
    assert main(["eval", obj, "--points", str(tmp_path / "shards"), "--derivatives", "0", "--serial",
                 "--out", str(tmp_path / "again.npz")]) == 0
    with np.load(tmp_path / "again.npz") as z, np.load(tmp_path / "serial.npz") as s:
        assert np.array_equal(z["P"], s["P"])


def _square_or_fail(task, marker_dir):
    """Task i -> i*i; task 1 raises OSError on its first attempt, task 7 is a deterministic error."""
    marker = Path(marker_dir) / f"once-{task}"
    if task == 1 and not marker.exists():
        marker.touch()
        raise OSError("a transient failure")
    if task == 7:
        raise CCProofError("task 7 is wrong input")
    return task * task


def test_retries_are_reported_and_deterministic_errors_are_not_retried(cluster, tmp_path):
    for sched in ("serial", cluster[1]):
        d = tmp_path / str(id(sched))
        d.mkdir()
        sweep = run_tasks(_square_or_fail, range(8), sched, shared=[str(d)], progress=False, raise_errors=False)
        assert sweep.results[:7] == [i * i for i in range(7)] and sweep.results[7] is None
        assert list(sweep.retried) == [1] and "retried" in sweep.retried[1]
        assert list(sweep.errors) == [7] and "wrong input" in str(sweep.errors[7])
        assert any("1 task(s) retried" in line for line in sweep.report())
        with pytest.raises(TaskFailed, match="task 7"):
            run_tasks(_square_or_fail, [7, 2], sched, shared=[str(d)], progress=False)


def _slow_square_kill_once(task, marker_dir):
    """Task i -> i*i after 0.3 s; task 3 kills its own worker process (SIGKILL) on its first attempt."""
    marker = Path(marker_dir) / "killed"
    if task == 3 and not marker.exists():
        marker.touch()
        os.kill(os.getpid(), signal.SIGKILL)
    time.sleep(0.3)
    return task * task


def test_a_killed_worker_loses_no_task(cluster, tmp_path, capsys):
    t0 = time.perf_counter()
    sweep = run_tasks(_slow_square_kill_once, range(10), cluster[1], shared=[str(tmp_path)], progress=False)
    assert (tmp_path / "killed").exists()
    assert sweep.results == [i * i for i in range(10)]
    # task 3 died with its worker; the tasks the scheduler had already assigned to that worker are re-run
    # elsewhere too and reported the same way (how many depends on dask's queueing)
    assert 3 in sweep.retried, sweep.retried
    assert all("worker was lost 1 time(s)" in what for what in sweep.retried.values())
    assert "task(s) retried; every result is in" in sweep.report()[0]
    assert time.perf_counter() - t0 < 60


def test_eval_on_its_own_local_workers_maps_one_shared_surface_and_equals_serial(refdir, tmp_path, capsys):
    """The default scheduler's path: a local cluster started by the command, the surface built once here and
    mapped by the workers from shared memory (tests/scale/test_share.py checks the mapping itself)."""
    obj = str(refdir / "meshes" / "sector_k5.obj")
    argv = ["eval", obj, "--samples", "3000", "--chunk", "1000", "--derivatives", "2", "--no-progress"]
    assert main(argv + ["--scheduler", "local:2", "--out", str(tmp_path / "a.npz")]) == 0
    line = capsys.readouterr().out
    assert re.search(r"setup [\d.]+ s, workers ready in [\d.]+ s \(surface taken in [\d.]+ s\)", line), line
    assert main(argv + ["--serial", "--out", str(tmp_path / "b.npz")]) == 0
    with np.load(tmp_path / "a.npz") as a, np.load(tmp_path / "b.npz") as b:
        for name in ("face", "u", "v", "P", "Pu", "Pv", "Puu", "Puv", "Pvv"):
            assert a[name].tobytes() == b[name].tobytes(), name


def test_eval_by_default_runs_its_chunks_in_process_with_the_compiled_kernel(refdir, tmp_path, capsys):
    """Several chunks, no scheduler asked for: with the compiled kernel (threads on every core) the points are
    evaluated in this process, not on a local cluster whose worker processes would add memory (1.37 x --serial
    on 81,920 triangles, scripts/bench_eval_scheduler.py); the report says so, and the result is --serial's."""
    from ccproof.evaluate.backend import evaluation_kernel

    if evaluation_kernel(None)[1] is None:
        pytest.skip("no compiled kernel: the default keeps the local cluster")
    obj = str(refdir / "meshes" / "sector_k5.obj")
    argv = ["eval", obj, "--samples", "3000", "--chunk", "1000", "--no-progress"]
    assert main(argv + ["--out", str(tmp_path / "a.npz")]) == 0
    out = capsys.readouterr().out
    assert "default scheduler: the 3 chunks evaluated in this process" in out and "workers ready" not in out, out
    assert main(argv + ["--serial", "--out", str(tmp_path / "b.npz")]) == 0
    assert "default scheduler" not in capsys.readouterr().out
    with np.load(tmp_path / "a.npz") as a, np.load(tmp_path / "b.npz") as b:
        for name in ("face", "u", "v", "P", "Pu", "Pv"):
            assert a[name].tobytes() == b[name].tobytes(), name
