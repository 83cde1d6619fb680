"""``--no-progress`` and when a command shows progress bars (tqdm, on stderr).

A bar is shown only when stderr is a terminal and ``--no-progress`` was not given, so that logs,
pipes and tests get no bar lines.

>>> import argparse
>>> p = argparse.ArgumentParser()
>>> add_progress_argument(p)
>>> progress_enabled(p.parse_args(["--no-progress"]))
False
"""

from __future__ import annotations

import sys


def add_progress_argument(parser):
    """Add ``--no-progress`` to a command's parser."""
    parser.add_argument("--no-progress", action="store_true",
                        help="no progress bar (bars are shown only when stderr is a terminal)")


def stderr_is_terminal() -> bool:
    """Whether stderr is a terminal (False for a pipe, a file, a closed or replaced stream)."""
    try:
        return sys.stderr.isatty()
    except (AttributeError, ValueError):  # a closed or replaced stderr
        return False


def progress_enabled(args) -> bool:
    """True when a progress bar should be drawn: stderr is a terminal and no ``--no-progress``."""
    return not getattr(args, "no_progress", False) and stderr_is_terminal()
