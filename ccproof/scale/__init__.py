"""Scale-out: the same task sweeps and batch evaluations in process, on a local Dask cluster or on a
remote one (``dask.distributed``), with results identical to the serial run (docs/scale-out.md).

* :func:`run_tasks` maps a function over independent tasks (a valence, a certificate file, a lam
  piece, a chunk of points) on a scheduler given as ``"serial"``, ``"local"``, ``"local:N"`` or a
  scheduler address; it shows a progress bar of finished tasks, retries a failed or lost task and
  reports every retry; a task is never dropped.
* :func:`ship` / :func:`rebuild` send a mesh (or any object built from picklable arguments) to the
  workers once, keyed by the SHA-256 of its pickled content, and build it once per worker process;
  :func:`share` sends an object built here (its arrays in shared memory for the workers of this machine,
  by value to a remote cluster), so that no worker builds it again.
* :func:`evaluate_dask` evaluates dask arrays of (face, u, v) chunk-wise (``map_blocks``);
  :func:`write_shards` / :func:`read_shards` keep point sets and results that do not fit in memory as
  a folder of ``.npz`` shards.

The layer imports nothing else of ccproof (only :mod:`ccproof.errors`): it sits below every layer
that runs sweeps (certify) or evaluations (reparam, evaluate), which pass it their own functions.
Dask is the optional extra ``scale`` (``pip install 'ccproof[scale]'``); without it only the serial
scheduler is available. Names are loaded lazily so that ``ccproof --help`` imports neither numpy
nor dask.
"""

_NAMES = {
    "Scheduler": "engine", "parse_scheduler": "engine", "run_tasks": "engine", "Sweep": "engine",
    "TaskFailed": "engine", "client_for": "engine", "add_scheduler_arguments": "engine",
    "scheduler_from_args": "engine", "dask_available": "engine", "MISSING_EXTRA": "engine",
    "ship": "shipping", "rebuild": "shipping", "Shipped": "shipping", "build_counts": "shipping",
    "evaluate_dask": "arrays", "evaluate_chunks": "arrays", "write_shards": "arrays", "read_shards": "arrays",
    "output_names": "arrays", "point_chunks": "arrays", "evaluate_points": "arrays", "open_scheduler": "engine",
    "process_pool": "engine", "runs_in_process": "engine", "share": "shipping", "attach": "shipping",
    "shared_memory_available": "shipping", "release_freed_memory": "shipping",
}
__all__ = sorted(_NAMES)


def __getattr__(name):
    if name in _NAMES:
        import importlib

        return getattr(importlib.import_module(f"ccproof.scale.{_NAMES[name]}"), name)
    raise AttributeError(f"module 'ccproof.scale' has no attribute {name!r}")
