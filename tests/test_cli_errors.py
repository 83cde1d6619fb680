"""Every expected failure of the command line ends in one line ``ccproof CMD: error: ...`` naming the
culprit, exit status 2, no traceback and no file at the output path; Ctrl-C ends in one line and exit
130; an interrupted or killed write leaves nothing under the final name.

Each case runs ``python -m ccproof.cli`` in a subprocess, as a user would; the cases run concurrently
(a few at a time) once per session, and each test reads its own outcome.
"""

import json
import os
import signal
import subprocess
import sys
import textwrap
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]

CUBE = """v -1 -1 -1
v 1 -1 -1
v 1 1 -1
v -1 1 -1
v -1 -1 1
v 1 -1 1
v 1 1 1
v -1 1 1
f 1 4 3 2
f 5 6 7 8
f 1 2 6 5
f 2 3 7 6
f 3 4 8 7
f 4 1 5 8
"""

#: input files of the cases (name -> text); folders and links are made in the fixture
FILES = {
    "cube.obj": CUBE,
    "empty.obj": "",
    "garbage.obj": "this is not a mesh\n",
    "badindex.obj": CUBE + "f 1 2 3 99\n",
    "nan.obj": CUBE.replace("v -1 -1 -1", "v nan -1 -1", 1),
    "zeroarea.obj": "v 0 0 0\nv 1 0 0\nv 1 0 0\nv 0 0 0\nf 1 2 3 4\n",
    "triangle.obj": "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    "uv.csv": "face,u,v\n0,0.5,0.5\n",
    "badface.csv": "face,u,v\n0,0.5,0.5\n99,0.5,0.5\n",
    "badu.csv": "face,u,v\n0,1.5,0.5\n",
    "badheader.csv": "f,u,v\n0,0.5,0.5\n",
    "badnumber.csv": "face,u,v\n0,abc,0.5\n",
    "xyz.csv": "x,y,z\n0,0,3\n",
    "far.csv": "x,y,z\n0,0,3\n1e200,0,0\n",
    "farther.csv": "x,y,z\n1e300,0,0\n",
    "nanpoint.csv": "x,y,z\nnan,0,0\n",
    "points.xyz": "0 0 0\n1 0 0\n0 1 0\n0 0 1\n",
    "afile": "not a folder\n",
    # two quads, the first one a hole (OpenSubdiv's tag line), and all of them holes
    "holes.obj": "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nv 1 1 0\nv 2 1 0\nf 1 2 5 4\nf 2 3 6 5\nt hole 1/0/0 0\n",
    "allholes.obj": "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\nt hole 1/0/0 0\n",
    "inhole.csv": "face,u,v\n1,0.5,0.5\n0,0.5,0.5\n",
    "semisharp.obj": "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nv 1 1 0\nv 2 1 0\nf 1 2 5 4\nf 2 3 6 5\n"
                     "t crease 2/1/0 1 4 9.5\nt creasemethod 0/0/1 chaikin\n",
    "tables/k005.json": '{"schema": "ccproof.table/1"',
}

# (id, argv, text the message must contain (the culprit), output path that must not exist or None)
CASES = [
    ("missing-mesh", "eval missing.obj --samples 3 --out o1.npz", "missing.obj", "o1.npz"),
    ("missing-points", "eval cube.obj --points missing.csv --out o2.npz", "missing.csv", "o2.npz"),
    ("out-missing-folder", "eval cube.obj --samples 3 --out nodir/o.npz", "nodir", "nodir/o.npz"),
    ("out-under-a-file", "eval cube.obj --samples 3 --out afile/o.npz", "afile", None),
    ("out-bad-suffix", "eval cube.obj --samples 3 --out o.csv", "'.csv'", "o.csv"),
    ("mesh-is-a-folder", "eval meshdir --samples 3 --out o3.npz", "meshdir", "o3.npz"),
    ("empty-mesh", "eval empty.obj --samples 3 --out o4.npz", "empty.obj", "o4.npz"),
    ("unreadable-mesh", "eval garbage.obj --samples 3 --out o5.npz", "garbage.obj", "o5.npz"),
    ("vertex-id-out-of-range", "eval badindex.obj --samples 3 --out o6.npz", "vertex 99", "o6.npz"),
    ("nan-coordinate", "eval nan.obj --samples 3 --out o7.npz", "vertex 0", "o7.npz"),
    ("face-id-out-of-range", "eval cube.obj --points badface.csv --out o8.npz", "face id 99", "o8.npz"),
    ("u-outside-0-1", "eval cube.obj --points badu.csv --out o9.npz", "u = 1.5", "o9.npz"),
    ("points-header", "eval cube.obj --points badheader.csv --out o10.npz", "badheader.csv", "o10.npz"),
    ("points-number", "eval cube.obj --points badnumber.csv --out o11.npz", "badnumber.csv:2", "o11.npz"),
    ("points-not-a-shard-folder", "eval cube.obj --points emptydir --out o12.npz", "emptydir", "o12.npz"),
    ("negative-samples", "eval cube.obj --samples -3 --out o13.npz", "--samples", "o13.npz"),
    ("chunk-zero", "eval cube.obj --samples 3 --chunk 0 --out o14.npz", "--chunk", "o14.npz"),
    ("bad-scheduler", "eval cube.obj --samples 3 --scheduler bogus --out o15.npz", "bogus", "o15.npz"),
    ("plot-bad-suffix", "eval cube.obj --samples 3 --out o16.npz --plot p.txt", "p.txt", "o16.npz"),
    ("parameterization-on-triangles", "eval triangle.obj --samples 3 --parameterization vanishing --out o17.npz",
     "triangle.obj", "o17.npz"),
    ("point-in-a-hole", "eval holes.obj --points inhole.csv --out o18.npz", "inhole.csv:3", "o18.npz"),
    ("every-face-a-hole", "eval allholes.obj --samples 3 --out o19.npz", "allholes.obj", "o19.npz"),
    ("alpha-without-vanishing", "eval cube.obj --samples 3 --alpha 3 --out o20.npz", "--alpha", "o20.npz"),
    ("threads-zero", "eval cube.obj --samples 3 --threads 0 --out o21.npz", "--threads", "o21.npz"),
    ("plot-vertex-out-of-range", "eval cube.obj --samples 3 --plot p.png --plot-vertex 8 --out o22.npz",
     "--plot-vertex 8", "o22.npz"),
    ("project-missing-mesh", "project missing.obj xyz.csv --out p1.npz", "missing.obj", "p1.npz"),
    ("project-header", "project cube.obj uv.csv --out p2.npz", "uv.csv", "p2.npz"),
    ("project-point-1e200", "project cube.obj far.csv --out p3.npz", "point 1", "p3.npz"),
    ("project-point-1e300", "project cube.obj farther.csv --out p4.npz", "point 0", "p4.npz"),
    ("project-nan-point", "project cube.obj nanpoint.csv --out p5.npz", "point 0", "p5.npz"),
    ("project-out-suffix", "project cube.obj xyz.csv --out p6.csv", "'.csv'", "p6.csv"),
    ("project-out-is-a-folder", "project cube.obj xyz.csv --out meshdir", "meshdir", None),
    ("project-cells-zero", "project cube.obj xyz.csv --cells 0 --out p7.npz", "--cells", "p7.npz"),
    ("project-certify-tagged", "project holes.obj xyz.csv --certify --out p8.npz", "--certify", "p8.npz"),
    ("arap-missing-mesh", "arap missing.obj --out a1.obj", "missing.obj", "a1.obj"),
    ("arap-out-suffix", "arap cube.obj --out a2.txt", "'.txt'", "a2.txt"),
    ("arap-zero-area-face", "arap zeroarea.obj --no-progress --out a3.obj", "face 0", "a3.obj"),
    ("arap-missing-charts", "arap cube.obj --charts missing.txt --out a4.obj", "missing.txt", "a4.obj"),
    ("arap-preview-suffix", "arap cube.obj --preview a5.txt", "a5.txt", "a5.txt"),
    ("arap-levels-below-start", "arap cube.obj --levels 0 --out a6.obj", "--levels 0", "a6.obj"),
    ("arap-refine-negative", "arap cube.obj --refine -1 --out a7.obj", "--refine", "a7.obj"),
    ("arap-refine-above-default-eval-level", "arap cube.obj --segment normals --refine 7 --out a8.obj",
     "--eval-level", "a8.obj"),
    ("arap-semi-sharp-beyond-the-cap", "arap semisharp.obj --out a9.obj", "edge (1, 4) of sharpness 9.5", "a9.obj"),
    ("fit-missing-points", "fit missing.xyz --out f1.obj", "missing.xyz", "f1.obj"),
    ("fit-init-every-face-a-hole", "fit points.xyz --init allholes.obj --out f4.obj", "allholes.obj", "f4.obj"),
    ("fit-out-suffix", "fit points.xyz --out f2.ply", "'.ply'", "f2.ply"),
    ("fit-errors-missing-folder", "fit points.xyz --out f3.obj --errors nodir/e.csv", "nodir", "f3.obj"),
    ("certify-valence-2", "certify 2 --no-verify --out c1", "got '2'", "c1"),
    ("certify-beyond-the-verifier", "certify 1000000000 --out c2", "10^6", "c2"),
    ("certify-out-is-a-file", "certify 5 --out afile", "afile", None),
    ("certify-out-under-a-file", "certify 5 --out afile/certs", "afile", None),
    ("certify-empty-range", "certify 5-3 --out c3", "5-3", "c3"),
    ("certify-prec-the-verifier-rejects", "certify 5 --prec 32 --out c4", "--prec 32", "c4"),
    ("certify-truncation-degree", "certify >=40 --truncation-degree 9 --out c5", "--truncation-degree 9", "c5"),
    ("certify-tagged-without-c1", "certify dart:7 --out c6", "dart:7", "c6"),
    ("certify-tagged-size", "certify crease:0 --c1 --out c7",
     "error: configuration 'crease:0': crease:N needs 1 <= N", "c7"),
    ("certify-tagged-family", "certify foo:3 --c1 --out c8", "error: configuration 'foo:3' is not dart:K", "c8"),
    ("certify-tagged-not-a-number", "certify crease:x --c1 --out c9", "FAMILY:N", "c9"),
    ("table-valence", "table 2", "got '2'", None),
    ("table-corrupt", "table 5 --dir tables", "k005.json", None),
    ("table-dir-under-a-file", "table --all --dir afile/t", "afile", "afile/t"),
    ("table-kmax-below-3", "table --all --kmax 2 --dir t2", "--kmax", "t2"),
    ("table-jobs-zero", "table --all --jobs 0 --dir t3", "--jobs", "t3"),
    ("report-jobs-zero", "report --jobs 0", "--jobs", None),
    ("report-tagged-plot", "report --tagged --plot r2.png", "--plot", "r2.png"),
    ("report-plot-suffix", "report --plot r.txt", "r.txt", "r.txt"),
    ("invert-not-a-number", "invert 5 x 0.1", "'x'", None),
    # the way out named as the command line spells it (not the Python keyword)
    ("invert-outside-the-face", "invert 5 5 5 --domain face", "--domain quadrant", None),
]


def _env():
    env = dict(os.environ, PYTHONPATH=str(REPO) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    env.pop("COLUMNS", None)
    return env


def _ccproof(argv, cwd, **kw):
    return subprocess.run([sys.executable, "-m", "ccproof.cli", *argv], cwd=cwd, env=_env(), capture_output=True,
                          text=True, timeout=300, **kw)


@pytest.fixture(scope="module")
def outcomes(tmp_path_factory):
    """Run every case once (three at a time); id -> (folder, CompletedProcess)."""
    work = tmp_path_factory.mktemp("cli_errors")
    for name, text in FILES.items():
        (work / name).parent.mkdir(parents=True, exist_ok=True)
        (work / name).write_text(text)
    (work / "meshdir").mkdir()
    (work / "emptydir").mkdir()
    with ThreadPoolExecutor(3) as ex:
        runs = list(ex.map(lambda case: _ccproof(case[1].split(), work), CASES))
    return work, {case[0]: run for case, run in zip(CASES, runs)}


def test_there_are_at_least_30_cases():
    assert len(CASES) >= 30 and len({c[0] for c in CASES}) == len(CASES)


@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
def test_bad_input_ends_in_one_line(case, outcomes):
    name, argv, culprit, out = case
    work, runs = outcomes
    run = runs[name]
    command = argv.split()[0]
    lines = run.stderr.strip().splitlines()
    assert run.returncode == 2, (run.returncode, run.stderr)
    assert "Traceback" not in run.stderr, run.stderr
    assert len(lines) == 1, run.stderr
    assert lines[0].startswith(f"ccproof {command}: error: "), lines[0]
    assert culprit in lines[0], (culprit, lines[0])
    if out is not None:
        assert not (work / out).exists()
    # nothing half-written anywhere: no temporary file left in the folder
    assert not [p.name for p in work.rglob(".tmp-*")]


def test_version():
    from ccproof import __version__

    run = _ccproof(["--version"], REPO)
    assert run.returncode == 0 and run.stdout.strip() == f"ccproof {__version__}"


def test_a_bug_keeps_its_traceback(tmp_path):
    """An unexpected exception is not an input error: it keeps its traceback (and is not exit 2)."""
    script = textwrap.dedent("""
        import sys
        import ccproof.cli.table as table
        def run(args):
            raise ZeroDivisionError("a bug")
        table.run = run
        from ccproof.cli import main
        sys.exit(main(["table", "5"]))
    """)
    run = subprocess.run([sys.executable, "-c", script], cwd=tmp_path, env=_env(), capture_output=True, text=True,
                         timeout=120)
    assert run.returncode == 1 and "Traceback" in run.stderr and "ZeroDivisionError: a bug" in run.stderr


def test_a_library_error_while_a_sigterm_unwinds_is_still_one_line(tmp_path):
    """A SIGTERM during a numba compilation ended in numba's own RuntimeError ("no compiled object yet", raised
    while the interrupt unwound it) and its traceback; it is the interrupt that ends the command: one line, 143."""
    script = textwrap.dedent("""
        import os, signal, sys, time
        import ccproof.cli.table as table
        def run(args):
            try:
                os.kill(os.getpid(), signal.SIGTERM)
                time.sleep(30)
            finally:
                raise RuntimeError("no compiled object yet")  # what numba raises when stopped mid-compile
        table.run = run
        from ccproof.cli import main
        sys.exit(main(["table", "5"]))
    """)
    run = subprocess.run([sys.executable, "-c", script], cwd=tmp_path, env=_env(), capture_output=True, text=True,
                         timeout=120)
    assert run.returncode == 143 and run.stderr.strip().splitlines() == ["ccproof table: terminated"], run.stderr


#: a subprocess that runs ``ccproof eval`` with one library function replaced by a stand-in that says
#: "ready" on stdout and then waits; the test signals it at that moment (no sleeps, no races)
_STALL = textwrap.dedent("""
    import signal, sys, time
    signal.signal(signal.SIGINT, signal.default_int_handler)  # as in a terminal (a background job ignores it)
    import {module} as mod
    def stall(*args, **kwargs):
        {before}
        print("ready", flush=True)
        time.sleep(120)
    mod.{name} = stall
    from ccproof.cli import main
    sys.exit(main(sys.argv[1:]))
""")


def _stalled(tmp_path, module, name, argv, before="pass"):
    (tmp_path / "cube.obj").write_text(CUBE)
    if "xyz.csv" in argv:
        (tmp_path / "xyz.csv").write_text(FILES["xyz.csv"])
    script = _STALL.format(module=module, name=name, before=before)
    proc = subprocess.Popen([sys.executable, "-c", script, *argv], cwd=tmp_path, env=_env(), text=True,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    lines = [proc.stdout.readline() for _ in range(1)]
    while lines[-1] and lines[-1].strip() != "ready" and len(lines) < 20:  # (the command's own lines come first)
        lines.append(proc.stdout.readline())
    assert lines[-1].strip() == "ready", (lines, proc.stderr.read() if proc.poll() is not None else "")
    return proc


def test_ctrl_c_during_an_evaluation(tmp_path):
    """SIGINT while the points are evaluated: one line, exit 130, no output file."""
    proc = _stalled(tmp_path, "ccproof.scale.arrays", "_evaluate_chunk",
                    ["eval", "cube.obj", "--samples", "100", "--serial", "--out", "o.npz"])
    proc.send_signal(signal.SIGINT)
    out, err = proc.communicate(timeout=120)
    assert proc.returncode == 130, err
    assert err.strip() == "ccproof eval: interrupted"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["cube.obj"]


# the stand-in for numpy.savez writes half a file under the name it was given, then stalls
_HALF_WRITTEN = "open(args[0], 'wb').write(b'PK half a file')"


@pytest.mark.parametrize("sig", [signal.SIGKILL, signal.SIGTERM, signal.SIGINT], ids=["SIGKILL", "SIGTERM", "SIGINT"])
def test_a_process_stopped_during_the_write_leaves_no_file(tmp_path, sig):
    """``eval --out o.npz`` stopped while numpy writes the file: nothing lies under ``o.npz``; SIGTERM and
    SIGINT also remove the temporary file (SIGKILL cannot, it leaves only a hidden ``.tmp-*`` file)."""
    proc = _stalled(tmp_path, "numpy", "savez", ["eval", "cube.obj", "--samples", "10", "--serial", "--out", "o.npz"],
                    before=_HALF_WRITTEN)
    proc.send_signal(sig)
    _, err = proc.communicate(timeout=120)
    left = sorted(p.name for p in tmp_path.iterdir())
    assert "o.npz" not in left
    if sig == signal.SIGKILL:
        assert proc.returncode == -signal.SIGKILL
        assert all(n == "cube.obj" or n.startswith(".tmp-") for n in left), left
    else:
        assert left == ["cube.obj"], left
        assert proc.returncode == (143 if sig == signal.SIGTERM else 130), err
        assert len(err.strip().splitlines()) == 1 and "Traceback" not in err, err


def test_project_writes_atomically_too(tmp_path):
    proc = _stalled(tmp_path, "numpy", "savez", ["project", "cube.obj", "xyz.csv", "--out", "p.npz"],
                    before=_HALF_WRITTEN)
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 143 and err.strip() == "ccproof project: terminated"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["cube.obj", "xyz.csv"]


def test_a_corrupt_certificate_is_a_failed_verdict_with_its_reason(tmp_path):
    """``verify`` is a checker: a malformed or missing certificate is a FAILED line with the reason and exit
    status 1 (not an input error), and the other files are still checked."""
    (tmp_path / "bad.json").write_text(json.dumps({"schema": "ccproof.injectivity/3", "valence": 5}))
    run = _ccproof(["verify", "bad.json", "missing.json", "--quiet"], tmp_path)
    assert run.returncode == 1 and "Traceback" not in run.stderr
    failed = [ln for ln in run.stdout.splitlines() if ln.startswith("FAILED")]
    assert len(failed) == 2
    assert failed[0].startswith("FAILED bad.json: ") and "missing field" in failed[0]
    assert failed[1].startswith("FAILED missing.json: ") and "No such file" in failed[1]


def test_a_zero_area_face_gives_a_warning_naming_it(tmp_path):
    """A mesh whose four vertices coincide has no normal anywhere: ``project`` still answers (distance and
    point are defined), writes NaN normals and says so in one warning line naming the point and face."""
    (tmp_path / "zero.obj").write_text("v 0 0 0\nv 0 0 0\nv 0 0 0\nv 0 0 0\nf 1 2 3 4\n")
    (tmp_path / "xyz.csv").write_text("x,y,z\n0.5,1,0\n")
    run = _ccproof(["project", "zero.obj", "xyz.csv", "--out", "p.npz"], tmp_path)
    assert run.returncode == 0, run.stderr
    # the one-time compile notice of a first run (an empty numba cache) is not part of the verdict
    lines = [ln for ln in run.stderr.strip().splitlines() if not ln.startswith("ccproof project: first run:")]
    assert len(lines) == 1 and lines[0].startswith("ccproof project: warning: "), run.stderr
    assert "point 0 on face 0" in lines[0] and "no normal" in lines[0]
    import numpy as np

    d = np.load(tmp_path / "p.npz")
    assert np.isnan(d["normal"]).all() and d["distance"][0] == pytest.approx(np.hypot(0.5, 1.0), abs=1e-12)


_SITECUSTOMIZE = '''
import os
if os.environ.get("CCPROOF_TEST_STALL"):
    import pathlib, time
    import ccproof.scale.arrays as arrays
    def stall(*args, **kwargs):  # in every worker process too: they all start through this file
        pathlib.Path(os.environ["CCPROOF_TEST_STALL"], str(os.getpid())).touch()
        time.sleep(120)
    arrays._evaluate_chunk = stall
if os.environ.get("CCPROOF_TEST_NO_DASK"):
    import sys
    sys.modules["distributed"] = None
'''


@pytest.mark.parametrize("workers", ["processes", "dask"])
def test_ctrl_c_to_the_process_group_with_workers(tmp_path, workers, session_processes):
    """A terminal sends Ctrl-C to every process of the foreground group, the workers too: still one line
    from the command, exit 130, no traceback from any worker, and no index.json (the folder is unfinished);
    the command does not wait for the workers' tasks: it ends within 3 s (Dask's graceful close waited 4 s
    for a busy worker before killing it) and leaves no process behind."""
    if workers == "dask":
        pytest.importorskip("distributed")
    site = tmp_path / "site"
    site.mkdir()
    (site / "sitecustomize.py").write_text(_SITECUSTOMIZE)
    marks = tmp_path / "stalled"
    marks.mkdir()
    (tmp_path / "cube.obj").write_text(CUBE)
    env = dict(_env(), CCPROOF_TEST_STALL=str(marks), PYTHONPATH=f"{site}{os.pathsep}{REPO}")
    if workers == "processes":
        env["CCPROOF_TEST_NO_DASK"] = "1"
    code = "import signal, sys; signal.signal(signal.SIGINT, signal.default_int_handler)\n" \
           "from ccproof.cli import main; sys.exit(main(sys.argv[1:]))"
    proc = subprocess.Popen([sys.executable, "-c", code, "eval", "cube.obj", "--samples", "4", "--chunk", "2",
                             "--scheduler", "local:2", "--out", "shards/"], cwd=tmp_path, env=env, text=True,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, start_new_session=True)
    try:
        for _ in range(6000):  # wait (at most 5 min) until a worker is inside a task
            if os.listdir(marks) or proc.poll() is not None:
                break
            time.sleep(0.05)
        assert os.listdir(marks) and proc.poll() is None, "no worker started a task"
        os.killpg(proc.pid, signal.SIGINT)
        start = time.monotonic()
        _, err = proc.communicate(timeout=100)  # < the workers' 120 s stall: they were stopped
        took = time.monotonic() - start
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
    assert proc.returncode == 130, err
    assert took < 3.0, f"{took:.1f} s from Ctrl-C to the end of the command"
    for _ in range(50):  # the workers (killed) and the resource tracker end with the command
        if not session_processes(proc.pid, zombies=False):
            break
        time.sleep(0.1)
    assert not session_processes(proc.pid, zombies=False), "processes of the command outlived it"
    # (Dask may warn first, e.g. that its dashboard port is taken: a one-line warning of the command)
    lines = err.strip().splitlines()
    assert lines[-1] == "ccproof eval: interrupted" and "Traceback" not in err, err
    assert all(ln.startswith("ccproof eval: warning: ") for ln in lines[:-1]), err
    assert not (tmp_path / "shards" / "index.json").exists()


def test_holes_are_skipped_by_samples_and_project(tmp_path):
    """A mesh with a hole face: ``eval --samples`` draws only from the faces that have a surface, and
    ``project`` finds the nearest point on them (the hole face 0 lies nearer to the point)."""
    import numpy as np

    (tmp_path / "holes.obj").write_text(FILES["holes.obj"])
    (tmp_path / "xyz.csv").write_text("x,y,z\n0.2,0.5,0.1\n")
    run = _ccproof(["eval", "holes.obj", "--samples", "50", "--serial", "--out", "o.npz"], tmp_path)
    assert run.returncode == 0, run.stderr
    d = np.load(tmp_path / "o.npz")
    assert d["face"].tolist() == [1] * 50 and np.isfinite(d["P"]).all()
    run = _ccproof(["project", "holes.obj", "xyz.csv", "--out", "p.npz"], tmp_path)
    assert run.returncode == 0, run.stderr
    p = np.load(tmp_path / "p.npz")
    assert p["face"].tolist() == [1]
    # the limit surface of face 1 alone is a patch of the plane z = 0 with x >= 1 (its left edge is the
    # boundary curve next to the hole, x(u=0) >= 1 up to the curve's bulge): the distance is at least 0.8 - a bit
    assert abs(p["P"][0, 2]) < 1e-12 and p["distance"][0] > 0.5


def test_fit_warnings_name_the_command(tmp_path):
    """A warning of ``fit`` (a level stopped at the step cap, a surface that strays from the data) is one line
    ``ccproof fit: warning: ...``, as every warning of the command line."""
    import numpy as np

    g = np.random.default_rng(0).normal(size=(60, 3))
    np.savetxt(tmp_path / "sphere.xyz", g / np.linalg.norm(g, axis=1)[:, None])
    run = _ccproof(["fit", "sphere.xyz", "--out", "f.obj", "--max-steps", "2", "--levels", "0", "--no-progress"],
                   tmp_path)
    assert run.returncode == 0, run.stderr
    lines = run.stderr.strip().splitlines()
    assert lines and all(ln.startswith("ccproof fit: warning: ") for ln in lines), run.stderr
    assert any("step cap (2 steps" in ln for ln in lines)


def test_the_command_list_names_what_each_command_does():
    """``ccproof --help``: certify also writes C1 certificates (smooth and tagged), report has the tagged
    table, eval reads any mesh (the help text of each is the user's first reading)."""
    run = _ccproof(["--help"], REPO)
    assert run.returncode == 0
    lines = {ln.split()[0]: ln for ln in run.stdout.splitlines() if ln.startswith("    ") and ln.split()}
    assert "C1" in lines["certify"] and "crease" in lines["certify"]
    assert "--tagged" in lines["report"]
    assert "any mesh" in lines["eval"]
