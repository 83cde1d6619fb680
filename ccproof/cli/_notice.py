"""A one-line notice before the first run compiles the numba kernels (they are cached on disk afterwards)."""

from __future__ import annotations

import glob
import importlib.util
import os
import sys

__all__ = ["compile_notice", "kernels_cached", "KERNEL_MODULES", "FIRST_COMPILE_SECONDS"]

#: the modules whose numba kernels (``cache=True``) the closest-point search and evaluation compile
KERNEL_MODULES = ("ccproof.evaluate._numba_kernel", "ccproof.evaluate._bvh")
#: the first run's compilation, seconds (docs/qmv98.md: ``ccproof fit`` on 500 points took 391 s with an empty
#: numba cache and 139 s with it filled, on a loaded 2-core machine): the notice says "a few minutes"
FIRST_COMPILE_SECONDS = (120, 300)


def kernels_cached(modules=KERNEL_MODULES):
    """Whether numba's on-disk cache holds an index for every kernel module (without importing numba).

    Looks in ``NUMBA_CACHE_DIR`` when set, else in the modules' ``__pycache__`` folders (numba's default).

    Parameters
    ----------
    modules : sequence of str

    Returns
    -------
    bool
        True also when numba is not installed (nothing to compile).

    Examples
    --------
    >>> isinstance(kernels_cached(), bool), kernels_cached(())
    (True, True)
    """
    if importlib.util.find_spec("numba") is None:
        return True
    root = os.environ.get("NUMBA_CACHE_DIR")
    for name in modules:
        spec = importlib.util.find_spec(name)
        if spec is None or spec.origin is None:
            continue
        stem = name.rsplit(".", 1)[-1]
        if root:
            hits = glob.glob(os.path.join(glob.escape(root), "**", f"{stem}.*.nbi"), recursive=True)
        else:
            hits = glob.glob(os.path.join(glob.escape(os.path.dirname(spec.origin)), "__pycache__", f"{stem}.*.nbi"))
        if not hits:
            return False
    return True


def compile_notice(command, stream=None):
    """Print one line to stderr when the kernels are not compiled yet (first run after install).

    Parameters
    ----------
    command : str
        The subcommand, for the message.
    stream : file, optional
        Default ``sys.stderr``.

    Returns
    -------
    bool
        Whether the notice was printed.

    Examples
    --------
    >>> import io
    >>> compile_notice("fit", io.StringIO()) in (True, False)
    True
    """
    if kernels_cached():
        return False
    lo, hi = FIRST_COMPILE_SECONDS
    print(f"ccproof {command}: first run: compiling the numba kernels once (a few minutes, {lo}-{hi} s on 2 cores; "
          f"cached on disk for later runs)", file=stream or sys.stderr, flush=True)
    return True
