"""What the benchmarks of scripts/bench_*.py print alike: the per-round ratios and the machine's load.

Every benchmark measures ours against a baseline in one run, taking turns round by round, and prints per
measurement one line with the ratio of each round summarized as ``min X  median Y  max Z`` and the 1-minute
load average (``load A-B``); where a baseline is not installed it says so with :func:`missing` and still
measures our side. tests/test_benchmarks.py runs every script with ``--smoke`` and looks for those lines.

>>> ratio_stats([2.0, 1.0, 4.0])
'min 1.000  median 2.000  max 4.000'
"""

import os
import statistics


def load() -> float:
    """The 1-minute load average (0.0 where the system has none)."""
    return os.getloadavg()[0] if hasattr(os, "getloadavg") else 0.0


def ratio_stats(ratios) -> str:
    """``min X  median Y  max Z`` of per-round ratios."""
    r = list(ratios)
    return f"min {min(r):.3f}  median {statistics.median(r):.3f}  max {max(r):.3f}"


def ratio_line(label: str, ratios, loads) -> str:
    """One printed line: ``label`` (e.g. ``ours/baseline``), the ratios' summary, the rounds and the load."""
    loads = list(loads)
    return f"{label} {ratio_stats(ratios)}  ({len(list(ratios))} rounds; load {min(loads):.2f}-{max(loads):.2f})"


def missing(baseline: str, why: str) -> None:
    """Say that a baseline is missing (its part skipped; our side is still measured)."""
    print(f"baseline missing: {baseline} ({why}); our side measured alone", flush=True)
