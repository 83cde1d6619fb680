"""A one-line notice before the first run compiles the numba kernels (they are cached on disk afterwards).

Where the install built the C evaluation kernel (``ccproof/evaluate/_clib.c``) and the backend is the
automatic one or ``c``, evaluation compiles nothing: ``eval`` prints no notice, and ``project`` and ``fit``
count only their other kernels (the closest points' Newton descent and search structure stay numba)."""

from __future__ import annotations

import glob
import importlib.util
import os
import sys

__all__ = ["compile_notice", "kernels_cached", "c_kernel_evaluates", "KERNEL_MODULES", "FIRST_COMPILE_SECONDS",
           "COMMAND_KERNELS"]

#: the modules whose numba kernels (``cache=True``) the closest-point search and evaluation compile
KERNEL_MODULES = ("ccproof.evaluate._numba_kernel", "ccproof.evaluate._bvh")
#: the first run's compilation, seconds (docs/qmv98.md: ``ccproof fit`` on 500 points took 391 s with an empty
#: numba cache and 139 s with it filled, on a loaded 2-core machine): the notice says "a few minutes"
FIRST_COMPILE_SECONDS = (120, 300)
_EVAL = "ccproof.evaluate._numba_kernel:_evaluate_points"
#: per command, the kernels its first run compiles (``module`` or ``module:function``) and the expected
#: compile time in seconds (measured with an empty ``NUMBA_CACHE_DIR`` on a loaded 2-core machine:
#: docs/evaluate.md "First run"; ``project``'s with the C kernel built: 29 and 37 s, 2 and 7 s of them its
#: run with the cache filled, so its kernels compile in 27 to 31 s; the Newton descent compiles the numba
#: evaluation kernel it calls in either case)
COMMAND_KERNELS = {
    "fit": (KERNEL_MODULES, FIRST_COMPILE_SECONDS),
    "eval": ((_EVAL,), (30, 90)),
    "project": ((_EVAL, "ccproof.evaluate._numba_kernel:_newton_points", "ccproof.evaluate._bvh"), (25, 60)),
}


def kernels_cached(modules=KERNEL_MODULES):
    """Whether numba's on-disk cache holds an index for every kernel module (without importing numba).

    Looks in ``NUMBA_CACHE_DIR`` when set, else in the modules' ``__pycache__`` folders (numba's default).

    Parameters
    ----------
    modules : sequence of str
        Module names (any cached kernel of the module counts) or ``module:function`` (that function's).

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
    for entry in modules:
        name, _, func = entry.partition(":")
        spec = importlib.util.find_spec(name)
        if spec is None or spec.origin is None:
            continue
        stem = name.rsplit(".", 1)[-1]
        pattern = f"{stem}.{func}-*.nbi" if func else f"{stem}.*.nbi"
        if root:
            hits = glob.glob(os.path.join(glob.escape(root), "**", pattern), recursive=True)
        else:
            hits = glob.glob(os.path.join(glob.escape(os.path.dirname(spec.origin)), "__pycache__", pattern))
        if not hits:
            return False
    return True


def c_kernel_evaluates():
    """Whether evaluation runs on the C kernel (compiled at install: nothing to compile at run time).

    True when the backend (``CCPROOF_BACKEND``, default automatic) is the automatic one or ``c`` and the
    install built the kernel.

    Examples
    --------
    >>> isinstance(c_kernel_evaluates(), bool)
    True
    """
    if os.environ.get("CCPROOF_BACKEND", "auto") not in ("auto", "c"):
        return False
    from ccproof.evaluate.backend import available_backends

    return "c" in available_backends()


def compile_notice(command, stream=None):
    """Print one line to stderr when the kernels are not compiled yet (first run after install).

    Like the progress bars, the line goes to a terminal only: with ``stream=None`` and a stderr that is not
    a terminal (a pipe, a log file, a test) nothing is printed, so that a command's stderr holds only its
    verdict, warnings and errors.

    Parameters
    ----------
    command : str
        The subcommand, for the message; its kernels and expected time from :data:`COMMAND_KERNELS`
        (another name: every kernel module, a few minutes), less the numba evaluation kernel when
        :func:`c_kernel_evaluates`.
    stream : file, optional
        Default ``sys.stderr`` when it is a terminal.

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
    from ccproof.cli._progress import stderr_is_terminal

    if stream is None and not stderr_is_terminal():
        return False
    modules, (lo, hi) = COMMAND_KERNELS.get(command, (KERNEL_MODULES, FIRST_COMPILE_SECONDS))
    if c_kernel_evaluates():
        modules = tuple(m for m in modules if m != _EVAL)
    if kernels_cached(modules):
        return False
    about = "under a minute" if hi <= 60 else "about a minute" if hi <= 120 else "a few minutes"
    print(f"ccproof {command}: first run: compiling the numba kernels once ({about}, {lo}-{hi} s on 2 cores; "
          f"cached on disk for later runs)", file=sys.stderr if stream is None else stream, flush=True)
    return True
