"""Run independent tasks in process or on a Dask cluster: one function, one scheduler spec.

A *scheduler spec* is one of

* ``"serial"`` (or ``"local:1"``): in this process, one task after the other, as without Dask;
* ``"local"``: a :class:`distributed.LocalCluster` with one single-threaded worker process per core
  (the default), or ``"local:N"`` with N worker processes;
* an address such as ``"tcp://10.0.0.5:8786"``: a running ``dask scheduler`` (for example one started by
  dask-jobqueue or ``dask ssh``, docs/scale-out.md);
* a :class:`distributed.Client` already connected (it is used and left open).

:func:`run_tasks` returns the results in the order of the tasks whatever the order in which they
finish. An exception listed in ``deterministic`` (by default every :class:`ccproof.errors.CCProofError`,
e.g. a proof that fails) is the task's outcome and is not retried; any other exception is retried up
to ``retries`` times (Dask's ``retries=``), a task whose worker died is re-run on another worker by the
scheduler, and both are reported in :attr:`Sweep.retried`. A task that still fails is reported in
:attr:`Sweep.errors` and, by default, raises :class:`TaskFailed` once every other task has finished.
"""

from __future__ import annotations

import contextlib
import os
import time
import uuid
from dataclasses import dataclass, field
from functools import partial

from ccproof.errors import CCProofError
from ccproof.scale.processes import (  # noqa: F401 (re-export)
    check_jobs,
    pid_alive,
    process_pool,
    signals_deferred,
    start_interruptibly,
    stop_cluster_now,
)

MISSING_EXTRA = ("a Dask scheduler needs the optional extra 'scale': pip install 'ccproof[scale]' "
                 "(or run with --serial / --scheduler local:1)")


class TaskFailed(CCProofError):
    """At least one task of a sweep failed after its retries; the message names each one.

    Parameters
    ----------
    message : str
        ``"<m> of <n> task(s) failed: ..."``, one entry per failed task (docs/scale-out.md).

    Examples
    --------
    >>> import math
    >>> run_tasks(math.sqrt, [4.0, -1.0], "serial", deterministic=(ValueError,), progress=False)
    Traceback (most recent call last):
    ...
    ccproof.scale.engine.TaskFailed: 1 of 2 task(s) failed: task 1: FAILED: ValueError: math domain error
    """


def dask_available():
    """True when ``dask.distributed`` can be imported (the optional extra ``scale``).

    >>> import importlib.util
    >>> dask_available() == (importlib.util.find_spec("distributed") is not None)
    True
    """
    try:
        import distributed  # noqa: F401
    except ImportError:
        return False
    return True


@dataclass(frozen=True)
class Scheduler:
    """A parsed scheduler spec (:func:`parse_scheduler`).

    Parameters
    ----------
    kind : {"serial", "local", "address"}
    workers : int, optional
        Worker processes of a local cluster (None: one per core).
    address : str, optional
        Address of a running Dask scheduler (``tcp://host:8786``).
    implicit : bool, optional
        The default, not asked for: falls back to serial without Dask.

    Examples
    --------
    >>> parse_scheduler("local:3")
    Scheduler(kind='local', workers=3, address=None, implicit=False)
    >>> str(Scheduler("address", address="tcp://h:8786"))
    'tcp://h:8786'
    """

    kind: str
    workers: int | None = None
    address: str | None = None
    implicit: bool = False  # the default, not asked for: falls back to serial without Dask

    def __str__(self):
        if self.kind == "local":
            return f"local:{self.workers}"
        return self.address if self.kind == "address" else "serial"


def parse_scheduler(spec=None, *, serial=False):
    """Parse ``"serial" | "local" | "local:N" | ADDRESS`` (None: "local", one worker per core).

    docs/scale-out.md, "Choosing where tasks run".

    Parameters
    ----------
    spec : str or Scheduler or None, optional
        The spelling of ``--scheduler``; ``"local:1"`` is serial.
    serial : bool, optional
        Force the serial scheduler (``--serial``).

    Returns
    -------
    Scheduler

    Raises
    ------
    CCProofError
        For a malformed spec, quoting it.

    Examples
    --------
    >>> [str(parse_scheduler(s)) for s in ("local:3", "local:1", "serial", "tcp://h:8786")]
    ['local:3', 'serial', 'serial', 'tcp://h:8786']
    >>> parse_scheduler("local:0")
    Traceback (most recent call last):
    ...
    ccproof.errors.CCProofError: --scheduler: local:N needs an integer N >= 1, got 'local:0'
    """
    if isinstance(spec, Scheduler):
        return Scheduler("serial") if serial else spec
    if serial:
        return Scheduler("serial")
    implicit = spec is None
    text = "local" if spec is None else str(spec).strip()
    if text in ("serial", ""):
        return Scheduler("serial")
    if text == "local":
        return Scheduler("local", workers=max(1, os.cpu_count() or 1), implicit=implicit)
    if text.startswith("local:"):
        n = text[6:]
        if not n.isdigit() or int(n) < 1:
            raise CCProofError(f"--scheduler: local:N needs an integer N >= 1, got {text!r}")
        return Scheduler("serial") if int(n) == 1 else Scheduler("local", workers=int(n))
    if "://" in text or ":" in text:
        return Scheduler("address", address=_checked_address(text))
    raise CCProofError(f"--scheduler: expected serial, local, local:N or a scheduler address such as "
                       f"tcp://host:8786, got {text!r}")


def _checked_address(text):
    """A scheduler address ``[PROTOCOL://]HOST:PORT``, refused by name without a port (Dask would fail
    later with a traceback of its own).

    >>> _checked_address("tcp://h:8786")
    'tcp://h:8786'
    >>> _checked_address("tcp://localhost")
    Traceback (most recent call last):
    ...
    ccproof.errors.CCProofError: --scheduler tcp://localhost: a scheduler address needs a port, as in tcp://localhost:8786
    """
    proto, sep, rest = text.rpartition("://")
    host, colon, port = rest.rpartition(":")
    if not colon or not host or not port.isdigit() or not 0 < int(port) < 65536:
        base = rest if not colon else host or rest
        raise CCProofError(f"--scheduler {text}: a scheduler address needs a port, as in "
                           f"{proto + sep if sep else 'tcp://'}{base.strip(':') or 'host'}:8786")
    return text


def add_scheduler_arguments(p):
    """Add ``--scheduler`` and ``--serial`` to an argparse parser.

    Parameters
    ----------
    p : argparse.ArgumentParser

    Returns
    -------
    None

    Examples
    --------
    >>> import argparse
    >>> p = argparse.ArgumentParser()
    >>> add_scheduler_arguments(p)
    >>> str(scheduler_from_args(p.parse_args(["--scheduler", "local:2"])))
    'local:2'
    """
    p.add_argument("--scheduler", default=None, metavar="local[:N]|ADDRESS",
                   help="where the tasks run: local (default: a local Dask cluster with one worker process per "
                        "core), local:N (N worker processes; local:1 runs in process) or the address of a "
                        "running Dask scheduler (tcp://host:8786); needs the extra 'scale' (pip install "
                        "'ccproof[scale]'), without it the default runs in process")
    p.add_argument("--serial", action="store_true", help="run every task in this process (same as local:1)")


def scheduler_from_args(args):
    """The :class:`Scheduler` of parsed CLI arguments (``--serial``, ``--scheduler``, the older ``--jobs N``).

    Parameters
    ----------
    args : argparse.Namespace
        Any of the attributes ``scheduler``, ``serial``, ``jobs`` (missing ones count as unset).

    Returns
    -------
    Scheduler

    Examples
    --------
    >>> import argparse
    >>> str(scheduler_from_args(argparse.Namespace(jobs=1))), str(scheduler_from_args(argparse.Namespace(serial=True)))
    ('serial', 'serial')
    >>> scheduler_from_args(argparse.Namespace(jobs=-1))
    Traceback (most recent call last):
    ...
    ccproof.errors.CCProofError: --jobs must be an integer >= 1 (1 runs in this process), got -1
    """
    spec = getattr(args, "scheduler", None)
    jobs = getattr(args, "jobs", None)
    s = parse_scheduler(spec, serial=bool(getattr(args, "serial", False)))
    if spec is not None and s.kind == "local" and not s.implicit:  # local:N: the same check as --jobs
        n = check_jobs(s.workers, f"--scheduler {spec}")
        s = Scheduler("local", workers=n) if n > 1 else Scheduler("serial")
    if jobs is not None:
        jobs = check_jobs(jobs)
        if spec is None and not s.kind == "serial":
            s = parse_scheduler(f"local:{jobs}")
    return s


@contextlib.contextmanager
def client_for(scheduler):
    """A connected :class:`distributed.Client` for a local or address scheduler ``scheduler`` (str,
    :class:`Scheduler`, or a Client, yielded unchanged); a context manager. A local scheduler starts a
    ``LocalCluster`` of worker processes (one thread each), closed gracefully when the block ends, at once
    (:func:`~ccproof.scale.processes.stop_cluster_now`) when it raises (Ctrl-C); a signal during the start gives it
    up at once (:func:`~ccproof.scale.processes.start_interruptibly`). :class:`CCProofError` for the
    serial scheduler or without the extra ``scale``. Starting a cluster takes seconds; the example is the refusal:

    >>> with client_for("serial"):
    ...     pass
    Traceback (most recent call last):
    ...
    ccproof.errors.CCProofError: client_for needs a local or address scheduler, not 'serial'
    """
    try:
        from distributed import Client, LocalCluster
    except ImportError:
        raise CCProofError(MISSING_EXTRA) from None
    if scheduler.__class__.__name__ == "Client":
        yield scheduler
        return
    s = parse_scheduler(scheduler)
    if s.kind == "local":
        try:  # a Ctrl-C or SIGTERM during the start: the start given up at once, its processes killed, one line
            cluster, client = start_interruptibly(partial(_start_local_cluster, LocalCluster, Client, s.workers))
        except BaseException as exc:
            part = getattr(exc, "ccproof_partial", {})
            stop_cluster_now(part.get("client"), part.get("cluster"))
            raise
        try:
            yield client
        except BaseException:  # an interrupt (or a failure) while tasks run: the busy workers are not waited for
            stop_cluster_now(client, cluster)
            raise
        with cluster, client:  # the work is done: a graceful close
            pass
    elif s.kind == "address":
        with Client(s.address, timeout="30s") as client:
            yield client
    else:
        raise CCProofError("client_for needs a local or address scheduler, not 'serial'")


def _start_local_cluster(LocalCluster, Client, workers, keep):
    """A local cluster of ``workers`` single-threaded worker processes and its client, each stored in ``keep`` as
    soon as it exists (an interrupted start closes what is there). No dashboard; the scheduler's small HTTP server
    on a free port (its default 8787 may be taken: a warning line); the workers' own logs silenced below CRITICAL
    (a run stopped by Ctrl-C closes the scheduler under their heartbeats: 30 lines of tracebacks), the tasks'
    errors come back through their results."""
    import logging

    cluster = keep["cluster"] = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                             dashboard_address=None, scheduler_kwargs={"dashboard_address": ":0"},
                                             silence_logs=logging.CRITICAL)
    client = keep["client"] = Client(cluster)
    return cluster, client


def _capped(s, n_tasks):
    """A local scheduler with no more workers than tasks (None: unknown)."""
    if s.kind == "local" and n_tasks is not None and s.workers is not None and s.workers > max(n_tasks, 1):
        return Scheduler("local", workers=max(n_tasks, 1), implicit=s.implicit)
    return s


def runs_in_process(scheduler, n_tasks=None):
    """Whether :func:`open_scheduler` runs the tasks in this process: the serial scheduler, a single local
    task, or the default without Dask (a Client or a scheduler address: never).

    >>> runs_in_process("local:4", 1), runs_in_process("local:4", 2), runs_in_process("serial")
    (True, False, True)
    """
    if scheduler.__class__.__name__ == "Client":
        return False
    s = parse_scheduler(scheduler)
    return s.kind == "serial" or s.kind == "local" and n_tasks is not None and n_tasks <= 1 or (
        s.implicit and not dask_available())


@contextlib.contextmanager
def open_scheduler(scheduler=None, n_tasks=None):
    """A scheduler kept open for several sweeps: yields a connected Client, or the serial :class:`Scheduler`.

    Serial for "serial", for a single local task, or for the default without Dask.

    Parameters
    ----------
    scheduler : str or Scheduler or distributed.Client, optional
        See :func:`parse_scheduler`.
    n_tasks : int, optional
        Number of tasks; a single task runs in process.

    Yields
    ------
    distributed.Client or Scheduler

    Examples
    --------
    >>> with open_scheduler("local:4", n_tasks=1) as s:
    ...     print(s)
    serial
    """
    if scheduler.__class__.__name__ == "Client":
        yield scheduler
        return
    s = _capped(parse_scheduler(scheduler), n_tasks)
    if runs_in_process(s, n_tasks):
        yield Scheduler("serial")
        return
    if s.kind == "local" and not dask_available():  # worker processes without Dask (run_tasks)
        yield s
        return
    with client_for(s) as client:
        yield client


@dataclass
class Sweep:
    """The outcome of :func:`run_tasks`: one entry of ``results`` per task, in task order.

    Parameters
    ----------
    results : list
        One result per task (None for a failed task).
    errors : dict of int -> Exception
        Task index -> the exception it ended with.
    retried : dict of int -> str
        Task index -> what happened to it (an exception retried, a worker lost under it).
    scheduler : str
        The scheduler that ran the sweep.
    seconds : float
        Wall-clock time.

    Examples
    --------
    >>> import math
    >>> sw = run_tasks(math.sqrt, [4.0, -1.0], "serial", deterministic=(ValueError,), progress=False,
    ...                raise_errors=False)
    >>> sw.results, sorted(sw.errors), sw.scheduler
    ([2.0, None], [1], 'serial')
    """

    results: list
    errors: dict = field(default_factory=dict)
    retried: dict = field(default_factory=dict)
    scheduler: str = "serial"
    seconds: float = 0.0

    def report(self, names=None):
        """Lines describing retries and failures (empty when every task succeeded at once)."""
        name = (lambda i: names[i]) if names is not None else (lambda i: f"task {i}")
        lines = [f"{name(i)}: {what}" for i, what in sorted(self.retried.items())]
        if self.retried:
            lines.insert(0, f"{len(self.retried)} task(s) retried; every result is in")
        lines += [f"{name(i)}: FAILED: {type(e).__name__}: {e}" for i, e in sorted(self.errors.items())]
        return lines


def _call(fn, deterministic, task, *shared):
    """Run one task; an expected (deterministic) exception becomes its outcome instead of a retry."""
    try:
        return True, fn(task, *shared)
    except deterministic as exc:
        return False, exc


def _identity(x):
    return x


def _retry_info(keys, retries, dask_scheduler=None):
    """(on the scheduler) key -> (exception retries used, times its worker was lost under it)."""
    out = {}
    for key in keys:
        ts = dask_scheduler.tasks.get(key)
        if ts is not None:
            out[key] = (retries - (ts.retries or 0), int(ts.suspicious or 0))
    return out


def _run_pool(call, tasks, shared, workers, retries, priority, sweep, outcomes, label):
    """A local scheduler without Dask: ``workers`` processes of :mod:`concurrent.futures` (spawned, so no
    thread state of this process is copied), with the same retries and report as on a Dask cluster. A
    task whose worker died (``BrokenProcessPool``: every task still running in that pool) is re-run in
    a fresh pool, at most ``retries`` times; ``label`` = (desc, unit, show a bar)."""
    from concurrent.futures import as_completed
    from concurrent.futures.process import BrokenProcessPool

    order = list(range(len(tasks))) if priority is None else sorted(range(len(tasks)), key=lambda i: -priority[i])
    used = dict.fromkeys(order, 0)
    lost = dict.fromkeys(order, 0)
    desc, unit, show = label
    bar = None
    if show:
        from tqdm import tqdm

        bar = tqdm(total=len(tasks), desc=desc, unit=unit)
    pending = order
    while pending:
        again = []
        with process_pool(min(workers, len(pending))) as ex:
            futs = {ex.submit(call, tasks[i], *shared): i for i in pending}
            for fut in as_completed(futs):
                i = futs[fut]
                try:
                    outcomes[i] = fut.result()
                except BrokenProcessPool as exc:
                    lost[i] += 1
                    if lost[i] + used[i] > retries:
                        outcomes[i] = (False, exc)
                    else:
                        again.append(i)
                except Exception as exc:  # an unexpected error: retried like on a cluster
                    used[i] += 1
                    if lost[i] + used[i] > retries:
                        outcomes[i] = (False, exc)
                    else:
                        again.append(i)
                if bar is not None and i in outcomes:
                    bar.update(1)
        pending = again
    if bar is not None:
        bar.close()
    for i in order:
        what = []
        if lost[i]:
            what.append(f"its worker was lost {lost[i]} time(s); re-run in a new worker")
        if used[i]:
            what.append(f"raised an exception {used[i]} time(s); retried")
        if what:
            sweep.retried[i] = "; ".join(what)


def run_tasks(fn, tasks, scheduler=None, *, shared=(), retries=2, deterministic=(CCProofError,), desc="tasks",
              unit="task", progress=True, priority=None, raise_errors=True, names=None):
    """Map ``fn(task, *shared)`` over ``tasks`` on a scheduler; returns a :class:`Sweep`.

    Parameters
    ----------
    fn : callable
        A module-level function (it is pickled by reference for the workers).
    tasks : sequence
        Picklable task descriptions (a valence, a path, a chunk of points ...).
    scheduler : str or Scheduler or distributed.Client or None
        See :func:`parse_scheduler`; None is "local". A single task always runs in process.
    shared : sequence
        Objects every task needs (e.g. a :func:`~ccproof.scale.shipping.ship`-ped mesh): on a cluster each
        is sent to the scheduler once and fetched once per worker, not with every task.
    retries : int
        How often a task that raised an exception not in ``deterministic`` is run again.
    priority : sequence of int, optional
        Higher runs first (e.g. the longest tasks first, so that the workers finish together).
    raise_errors : bool
        Raise :class:`TaskFailed` naming the failed tasks (after all others finished).
    names : sequence of str, optional
        A name per task for the report (default "task i").

    Returns
    -------
    Sweep

    Examples
    --------
    >>> import math
    >>> run_tasks(math.factorial, [3, 4, 5], "serial", progress=False).results
    [6, 24, 120]
    """
    tasks = list(tasks)
    s = scheduler if scheduler.__class__.__name__ == "Client" else _capped(parse_scheduler(scheduler), len(tasks))
    if isinstance(s, Scheduler) and (s.kind == "local" and len(tasks) <= 1
                                     or s.implicit and not dask_available()):
        s = Scheduler("serial")
    call = partial(_call, fn, tuple(deterministic))
    t0 = time.perf_counter()
    sweep = Sweep(results=[None] * len(tasks), scheduler=str(s) if isinstance(s, Scheduler) else "client")
    outcomes = {}
    if isinstance(s, Scheduler) and s.kind == "local" and not dask_available():
        _run_pool(call, tasks, shared, s.workers, retries, priority, sweep, outcomes,
                  (desc, unit, progress and len(tasks) > 1))
    elif isinstance(s, Scheduler) and s.kind == "serial":
        _run_serial(call, tasks, shared, retries, sweep, outcomes, (desc, unit, progress and len(tasks) > 1))
    else:
        _run_dask(call, tasks, shared, s, retries, priority, sweep, outcomes, (desc, unit, progress))
    for i, (ok, value) in outcomes.items():
        if ok:
            sweep.results[i] = value
        else:
            sweep.errors[i] = value
    sweep.seconds = time.perf_counter() - t0
    if sweep.errors and raise_errors:
        lines = [ln for ln in sweep.report(names) if "FAILED" in ln]
        raise TaskFailed(f"{len(sweep.errors)} of {len(tasks)} task(s) failed: " + "; ".join(lines))
    return sweep


def _run_serial(call, tasks, shared, retries, sweep, outcomes, label):
    """:func:`run_tasks` in this process, one task after the other; ``label`` = (desc, unit, show a bar)."""
    desc, unit, show = label
    it = range(len(tasks))
    if show:
        from tqdm import tqdm

        it = tqdm(it, desc=desc, unit=unit)
    for i in it:
        for attempt in range(retries + 1):
            try:
                outcomes[i] = call(tasks[i], *shared)
                break
            except Exception as exc:  # an unexpected error: retried like on a cluster
                if attempt == retries:
                    outcomes[i] = (False, exc)
                else:
                    sweep.retried[i] = f"raised {type(exc).__name__}: {exc}; retried"


def _run_dask(call, tasks, shared, s, retries, priority, sweep, outcomes, label):
    """:func:`run_tasks` on a Dask client or cluster ``s``; ``label`` = (desc, unit, show a bar)."""
    desc, unit, show = label
    with client_for(s) as client:
        from distributed import as_completed

        run = uuid.uuid4().hex[:8]
        shared_f = [client.submit(_identity, obj, key=f"shared-{getattr(obj, 'digest', uuid.uuid4().hex)[:16]}",
                                  pure=False) for obj in shared]
        order = range(len(tasks)) if priority is None else sorted(range(len(tasks)), key=lambda i: -priority[i])
        futs, index = {}, {}
        for i in order:
            key = f"{desc.replace(' ', '_')}-{i}-{run}"
            index[key] = i
            futs[key] = client.submit(call, tasks[i], *shared_f, key=key, retries=retries, pure=False,
                                      priority=0 if priority is None else int(priority[i]))
        done = as_completed(list(futs.values()))
        bar = None
        if show:
            from tqdm import tqdm

            bar = tqdm(total=len(futs), desc=desc, unit=unit)
        for batch in done.batches():
            for fut in batch:
                i = index[fut.key]
                try:
                    outcomes[i] = fut.result()
                except Exception as exc:  # retries exhausted, or KilledWorker: reported, not dropped
                    outcomes[i] = (False, exc)
            _note_retries(client, batch, index, retries, sweep)
            for fut in batch:
                futs.pop(fut.key).release()
            if bar is not None:
                bar.update(len(batch))
        if bar is not None:
            bar.close()
        del futs, shared_f


def _note_retries(client, batch, index, retries, sweep):
    """Record in ``sweep.retried`` how each finished task of ``batch`` got there, asked of the scheduler before
    the task is released (a released result is not recomputed when a worker that held it dies later)."""
    info = client.run_on_scheduler(_retry_info, [f.key for f in batch], retries)
    for key, (used, lost) in info.items():
        what = []
        if lost:
            what.append(f"its worker was lost {lost} time(s); re-run on another worker")
        if used > 0:
            what.append(f"raised an exception {used} time(s); retried")
        if what:
            sweep.retried[index[key]] = "; ".join(what)
