"""Processes of ours: worker counts, process pools, signals while workers start, workers that end with their parent.

* :func:`check_jobs`: ``--jobs N`` validated the same way by every command, capped by the cores and the tasks;
* :func:`process_pool`: a pool whose workers are all started at once, born ignoring Ctrl-C (left to this
  process), stopped at once on an interrupt, and ended with this process (SIGKILL included);
* :func:`signals_deferred`: SIGINT and SIGTERM recorded while a pool's worker processes start (milliseconds)
  and honoured once they are up;
* :func:`start_interruptibly`: a Dask cluster's start (seconds) in a thread of its own, given up at once on a
  signal, the processes it spawned killed;
* :func:`stop_cluster_now`: a local Dask cluster stopped at once on an interrupt (its busy workers killed);
* :func:`pid_alive`: whether the writer of a temporary file is still running.

Used by :mod:`ccproof.scale.engine` and the commands (``table --all``, ``report --jobs``).
"""

from __future__ import annotations

import contextlib
import os
import time

from ccproof.errors import CCProofError

__all__ = ["pid_alive", "usable_cores", "check_jobs", "signals_deferred", "DEFERRED_SIGNALS", "process_pool",
           "PARENT_POLL_SECONDS", "stop_cluster_now", "STOP_SECONDS", "start_interruptibly", "Spawned"]


def pid_alive(pid) -> bool:
    """Is process ``pid`` alive (or not ours to signal)? The writers of temporary files are judged by it.

    >>> pid_alive(os.getpid())
    True
    """
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OverflowError):
        return True
    return True


def usable_cores():
    """The cores this process may run on (its CPU affinity where the system has one).

    >>> usable_cores() >= 1
    True
    """
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except (AttributeError, OSError):
        return max(1, os.cpu_count() or 1)


def check_jobs(n, option="--jobs", tasks=None):
    """The worker processes of ``option N``, validated the same way by every command.

    Parameters
    ----------
    n : int
    option : str
        How the message names it (``--jobs``, ``--scheduler local:N``).
    tasks : int, optional
        The number of tasks, when known: more workers than tasks would idle.

    Returns
    -------
    int
        ``n``, capped at :func:`usable_cores` and at ``tasks`` (a warning says so when it caps).

    Raises
    ------
    CCProofError
        For ``n < 1`` (0 and -1 are not "the default").

    Examples
    --------
    >>> check_jobs(1), check_jobs(1, tasks=1)
    (1, 1)
    >>> check_jobs(0)
    Traceback (most recent call last):
    ...
    ccproof.errors.CCProofError: --jobs must be an integer >= 1 (1 runs in this process), got 0
    """
    import warnings

    if isinstance(n, bool) or not isinstance(n, int) or n < 1:
        raise CCProofError(f"{option} must be an integer >= 1 (1 runs in this process), got {n}")
    cores = usable_cores()
    cap = cores if tasks is None else max(1, min(cores, tasks))
    if n > cap:
        why = f"the {cores} cores of this machine" if cap == cores else f"the {tasks} tasks"
        warnings.warn(f"{option} {n}: {cap} worker process{'es' if cap > 1 else ''} ({why})", stacklevel=2)
        return cap
    return n


@contextlib.contextmanager
def _sigint_ignored():
    """Ignore SIGINT while worker processes are started: they inherit the disposition, so a Ctrl-C (sent
    to the whole process group by a terminal) reaches only this process, which stops them cleanly,
    instead of a traceback from every worker. Does nothing outside the main thread."""
    import signal
    import threading

    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


class Spawned:
    """The processes that multiprocessing spawned from this process (any thread) while a
    :func:`_children_ignore_sigint` hook was installed: their pids, and whether more may be spawned
    (:meth:`stop` kills them all and refuses the next ones: a start given up on leaves nothing behind)."""

    def __init__(self):
        import threading

        self.pids: list = []
        self.stopped = False
        self.finished = False  # the thread that spawns them is done
        self.restore = None  # removes the hook (left installed after stop until that thread is done)
        self.lock = threading.Lock()

    def leave_hook(self, restore):
        """The hook's context is over: remove it now, or, once stopped, when the spawning thread is done."""
        with self.lock:
            if self.stopped and not self.finished:
                self.restore = restore
                return
        restore()

    def done(self):
        """The spawning thread is done: remove a hook left installed for it."""
        with self.lock:
            self.finished = True
            restore, self.restore = self.restore, None
        if restore is not None:
            restore()

    def stop(self):
        """SIGKILL every process spawned so far (and refuse further spawns); returns their pids."""
        import signal

        with self.lock:
            self.stopped = True
            for pid in self.pids:
                with contextlib.suppress(OSError):
                    os.kill(pid, signal.SIGKILL)
            return list(self.pids)


def _pdeathsig_prefix():
    """``setpriv --pdeathsig KILL`` (util-linux) where it works: the child is killed by the kernel the moment the
    thread that spawned it ends, even while it is still importing (a Dask worker watches its parent only once
    it runs; a parent SIGKILLed during the start left its workers 1 to 2.5 s)."""
    global _PDEATHSIG
    if _PDEATHSIG is None:
        import shutil
        import subprocess

        exe = shutil.which("setpriv")
        ok = False
        if exe is not None:
            with contextlib.suppress(OSError, subprocess.SubprocessError):
                ok = subprocess.run([exe, "--pdeathsig", "KILL", "true"], capture_output=True,
                                    timeout=10).returncode == 0
        _PDEATHSIG = [exe, "--pdeathsig", "KILL"] if ok else []
    return _PDEATHSIG


_PDEATHSIG: list | None = None


@contextlib.contextmanager
def _children_ignore_sigint(spawned=None):
    """Processes that multiprocessing spawns meanwhile (from any thread: a cluster's workers and their
    helpers) start with SIGINT ignored, as they would if it were ignored here: their command runs through
    ``/bin/sh -c 'trap "" INT; exec ...'`` (an ignored signal stays ignored across exec, and Python keeps an
    ignored SIGINT ignored). A Ctrl-C sent by a terminal to the whole process group then reaches only this
    process. Where ``setpriv`` is found, a worker (not multiprocessing's resource tracker, which ends by itself
    when the last process that uses it ends) also gets a parent-death signal: SIGKILL when the thread that
    spawned it ends (the process killed, SIGKILL included). ``spawned`` (a :class:`Spawned`) records their pids
    and, once stopped, refuses new spawns; while it is not stopped the hook is removed on exit, else it stays
    until the thread that starts the processes removes it (:meth:`_remove`). Yields False (does nothing) where
    there is no such spawn (not POSIX, no /bin/sh)."""
    import multiprocessing.util as mpu

    original = getattr(mpu, "spawnv_passfds", None)
    if original is None or not os.path.exists("/bin/sh"):
        yield False
        return
    prefix = _pdeathsig_prefix()

    def spawn(path, args, passfds):
        # (the resource tracker is left alone: it ends when the last process using it ends, and the finalizers
        # of this process may start it again at exit)
        tracker = any("resource_tracker" in str(a) for a in args)
        sh = os.fsencode("/bin/sh") if isinstance(path, bytes) else "/bin/sh"
        pre = [] if tracker or not prefix else [os.fsencode(a) if isinstance(path, bytes) else a for a in prefix]
        argv = [*pre, sh, "-c", 'trap "" INT; exec "$@"', "sh", path, *args[1:]]
        if spawned is None or tracker:
            return original(argv[0], argv, passfds)
        with spawned.lock:  # (a process spawned while stop() runs would escape it)
            if spawned.stopped:
                raise OSError("the start of these worker processes was given up (interrupted)")
            pid = original(argv[0], argv, passfds)
            spawned.pids.append(pid)
        return pid

    def restore():
        if mpu.spawnv_passfds is spawn:
            mpu.spawnv_passfds = original

    mpu.spawnv_passfds = spawn
    try:
        yield True
    finally:
        if spawned is None:
            restore()
        else:
            spawned.leave_hook(restore)


def start_interruptibly(build):
    """``build(keep)`` (the start of worker processes: a Dask cluster and its client) run in a daemon thread while
    this (main) thread waits, so that a Ctrl-C or SIGTERM arriving meanwhile acts at once, as at any other
    moment, through this process's own handlers: the start is given up, every process it spawned so far is
    killed (:class:`Spawned`; they start with SIGINT ignored and die with their spawning thread,
    :func:`_children_ignore_sigint`) and the exception is raised carrying ``keep`` (what ``build`` stored of the
    partial start, for the caller to close) as its attribute ``ccproof_partial``. Before, such a signal was
    deferred until the start ended: 1.5 to 5 s under load. Returns ``build``'s value; raises its exception.
    Outside the main thread (no signal can arrive there) ``build`` runs in the calling thread.

    >>> start_interruptibly(lambda keep: keep.setdefault("x", 2) * 3)
    6
    """
    import threading

    keep: dict = {}
    if threading.current_thread() is not threading.main_thread():
        return build(keep)
    spawned = Spawned()
    outcome: dict = {}
    finished = threading.Event()

    def run():
        try:
            outcome["value"] = build(keep)
        except BaseException as exc:  # handed to the waiting thread (a daemon thread's traceback never prints)
            outcome["error"] = exc
        finally:
            finished.set()
            spawned.done()

    with _children_ignore_sigint(spawned):
        thread = threading.Thread(target=run, daemon=True, name="ccproof-start-workers")
        try:
            thread.start()
            while not finished.wait(0.05):  # a signal's handler runs here, in the main thread
                pass
        except BaseException as exc:
            if not finished.is_set():
                spawned.stop()
            exc.ccproof_partial = keep
            raise
    if "error" in outcome:
        raise outcome["error"]
    return outcome["value"]


#: the signals a cluster's start defers (recorded, then honoured once the start is over)
DEFERRED_SIGNALS = ("SIGINT", "SIGTERM")


@contextlib.contextmanager
def signals_deferred():
    """While a cluster starts: SIGINT and SIGTERM recorded, not acted on, and honoured when the block ends
    (raised by this process's own handlers: one line of the command, exit 130 or 143; no traceback from
    inside the cluster's start-up; the caller closes the half-started cluster). The worker processes started
    meanwhile ignore SIGINT (:func:`_children_ignore_sigint`): a Ctrl-C to the process group is this
    process's alone. Where children cannot be made to ignore it (no POSIX spawn), SIGINT is ignored here
    during the start instead (inherited by the workers; a Ctrl-C in that window is then lost)."""
    import signal
    import threading

    if threading.current_thread() is not threading.main_thread():
        yield
        return
    with _children_ignore_sigint() as children_ignore:
        names = DEFERRED_SIGNALS if children_ignore else ("SIGTERM",)
        got = []
        previous = {}
        for name in names:
            sig = getattr(signal, name)
            previous[sig] = signal.signal(sig, lambda signum, frame: got.append(signum))
        try:
            with contextlib.nullcontext() if children_ignore else _sigint_ignored():
                yield
        finally:
            for sig, handler in previous.items():
                signal.signal(sig, handler)
            if got:
                _honour(got[0], previous[got[0]])


def _honour(signum, handler):
    """Act on a deferred signal as its handler ``handler`` would have."""
    import signal

    if callable(handler):
        handler(signum, None)  # the command's handlers raise (KeyboardInterrupt: one line, exit 130 or 143)
    elif handler == signal.SIG_DFL:
        if signum == signal.SIGINT:
            raise KeyboardInterrupt
        os.kill(os.getpid(), signum)


#: seconds between a pool worker's checks that the process that started it is alive (where the system
#: cannot tell the worker of its parent's death: not Linux, or a pool started from another thread)
PARENT_POLL_SECONDS = 0.5


def _pool_worker_init(parent=None, kill_with_parent=False):  # initializer of the workers of process_pool
    """Ignore Ctrl-C (left to the parent) and end this worker when ``parent`` is gone (SIGKILL included: no
    process of ours outlives its parent, and the resource tracker ends with the last worker).

    ``kill_with_parent``: the pool was started by the parent's main thread, so the kernel may end the worker
    with it (Linux ``PR_SET_PDEATHSIG``: at once, even in a long call that holds the interpreter lock, where
    a watching thread would wait for the call to end); the watching thread is kept everywhere."""
    import signal
    import threading

    signal.signal(signal.SIGINT, signal.SIG_IGN)
    if parent is None:
        return
    if kill_with_parent:
        _die_with_parent()
    threading.Thread(target=_exit_with, args=(parent,), daemon=True, name="ccproof-parent-watch").start()


def _die_with_parent():
    """Ask Linux to SIGKILL this process when the thread that started it ends; False where it cannot."""
    import ctypes
    import signal
    import sys

    if not sys.platform.startswith("linux"):
        return False
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        return libc.prctl(1, int(signal.SIGKILL), 0, 0, 0) == 0  # 1: PR_SET_PDEATHSIG
    except (OSError, AttributeError):
        return False


def _exit_with(parent):
    while os.getppid() == parent:  # also closes the race of a parent dead before _die_with_parent
        time.sleep(PARENT_POLL_SECONDS)
    os._exit(1)  # reparented: the parent died without stopping us


def _launch_workers(ex):
    """Start every worker of a fresh executor now (they start on demand otherwise, at any later moment)."""
    launch = getattr(ex, "_launch_processes", None)
    if launch is not None and not getattr(ex, "_executor_manager_thread", None):
        launch()


@contextlib.contextmanager
def process_pool(workers, context="spawn"):
    """A :class:`concurrent.futures.ProcessPoolExecutor` whose workers leave Ctrl-C to this process.

    Every worker is started on entry, in a window where SIGINT and SIGTERM are deferred
    (:func:`signals_deferred`: honoured once the workers are up) and the workers are born ignoring
    SIGINT, so a Ctrl-C to the process group at any moment is this process's alone (no traceback of a
    worker still starting). When the block ends with an exception (Ctrl-C, SIGTERM raised as one, an
    error) the workers are terminated at once instead of finishing their tasks, and the pending tasks are
    cancelled. No worker outlives this process, SIGKILL included (:func:`_pool_worker_init`).

    Parameters
    ----------
    workers : int
        Worker processes (>= 1).
    context : str, optional
        The multiprocessing start method (default "spawn": no thread state of this process is copied).

    Yields
    ------
    concurrent.futures.ProcessPoolExecutor

    Examples
    --------
    >>> import math
    >>> with process_pool(2) as ex:
    ...     list(ex.map(math.factorial, [3, 4]))
    [6, 24]
    """
    import multiprocessing
    import threading
    from concurrent.futures import ProcessPoolExecutor

    ex = None
    try:
        with signals_deferred():
            main = threading.current_thread() is threading.main_thread()
            ex = ProcessPoolExecutor(max_workers=workers, initializer=_pool_worker_init,
                                     initargs=(os.getpid(), main), mp_context=multiprocessing.get_context(context))
            _launch_workers(ex)
        yield ex
    except BaseException:
        if ex is not None:
            _stop_pool(ex)
        raise
    ex.shutdown(wait=True)


def _stop_pool(ex):
    """Terminate the workers of ``ex`` now and cancel its pending tasks."""
    manager = getattr(ex, "_executor_manager_thread", None)
    for proc in list((getattr(ex, "_processes", None) or {}).values()):
        proc.terminate()
    ex.shutdown(wait=False, cancel_futures=True)
    # The pool's manager thread sees the terminated workers, marks the pool broken and closes its
    # wake-up pipe. Wait for it here (a few ms): Python 3.11's exit hook would otherwise race it and
    # write to the closing pipe ("Exception ignored ... Bad file descriptor" after our one line).
    if manager is not None:
        manager.join(timeout=30)
    for proc in list((getattr(ex, "_processes", None) or {}).values()):
        proc.join(timeout=5)  # a manager never started (stopped before the first task) joins none


#: seconds a local worker is given to stop when the run is interrupted (then killed by its nanny); Dask's own
#: default waits 4 s for a worker busy with a task (a Ctrl-C took 4 s to end the command)
STOP_SECONDS = 0.5


def stop_cluster_now(client, cluster):
    """Close a local cluster at once: every nanny stops its worker within :data:`STOP_SECONDS` (a task still
    running is killed with its process), then the client and the cluster close (the scheduler, in process)."""
    import asyncio

    async def stop(nannies):
        await asyncio.gather(*(n.close(timeout=STOP_SECONDS) for n in nannies), return_exceptions=True)

    if cluster is not None:
        with contextlib.suppress(Exception):
            cluster.sync(stop, list(cluster.workers.values()))
    for part in (client, cluster):
        if part is not None:
            part.close()
