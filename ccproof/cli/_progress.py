"""``--progress`` / ``--no-progress`` and when a command shows progress bars (tqdm, on stderr).

A bar is shown when stderr is a terminal or ``--progress`` was given, and never with ``--no-progress``, so that
logs, pipes and tests get no bar lines unless asked for. A phase without steps to count (reading a mesh, building
a search structure) shows its name and the seconds spent, refreshed while it runs (:func:`phase`).

>>> import argparse
>>> p = argparse.ArgumentParser()
>>> add_progress_argument(p)
>>> progress_enabled(p.parse_args(["--no-progress"])), progress_enabled(p.parse_args(["--progress"]))
(False, True)
"""

from __future__ import annotations

import contextlib
import sys
import threading

#: seconds between two refreshes of a :func:`phase` bar
PHASE_REFRESH = 0.5


def add_progress_argument(parser):
    """Add ``--progress`` and ``--no-progress`` (exclusive) to a command's parser."""
    group = parser.add_mutually_exclusive_group()
    group.add_argument("--progress", action="store_true",
                       help="progress bars on stderr for every long phase even when it is not a terminal")
    group.add_argument("--no-progress", action="store_true",
                       help="no progress bar (bars are shown only when stderr is a terminal, or with --progress)")


def stderr_is_terminal() -> bool:
    """Whether stderr is a terminal (False for a pipe, a file, a closed or replaced stream)."""
    try:
        return sys.stderr.isatty()
    except (AttributeError, ValueError):  # a closed or replaced stderr
        return False


def progress_enabled(args) -> bool:
    """True when a progress bar should be drawn: ``--progress``, or stderr is a terminal and no ``--no-progress``."""
    if getattr(args, "no_progress", False):
        return False
    return bool(getattr(args, "progress", False)) or stderr_is_terminal()


@contextlib.contextmanager
def phase(desc, enabled):
    """A bar for a phase without countable steps: ``desc`` and the elapsed seconds, refreshed every
    :data:`PHASE_REFRESH` s while the block runs (nothing when not ``enabled``).

    >>> import io, contextlib
    >>> err = io.StringIO()
    >>> with contextlib.redirect_stderr(err), phase("read mesh.obj", True):
    ...     pass
    >>> "read mesh.obj" in err.getvalue()
    True
    """
    if not enabled:
        yield
        return
    from tqdm import tqdm

    bar = tqdm(total=None, desc=desc, bar_format="{desc}: {elapsed}", file=sys.stderr)
    done = threading.Event()

    def refresh():
        while not done.wait(PHASE_REFRESH):
            bar.refresh()

    ticker = threading.Thread(target=refresh, daemon=True)
    ticker.start()
    try:
        yield
    finally:
        done.set()
        ticker.join()
        bar.close()
