"""The ``ccproof`` command line: one thin module per command in this package.

Each command module defines ``add_arguments(parser)`` and ``run(args) -> int``: it parses, calls the
library (imported inside ``run``, so that ``ccproof --help`` stays fast) and prints. No library
package imports argparse or this package (tests/test_cli_package.py).
"""

from __future__ import annotations

import argparse
import importlib
import importlib.util
import sys

#: name -> (module, one-line help)
COMMANDS: dict[str, tuple[str, str]] = {
    "table": ("ccproof.cli.table", "print or regenerate the certified characteristic-map tables"),
    "certify": ("ccproof.cli.certify", "prove injectivity or C1 (smooth, dart, crease, corner)"),
    "verify": ("ccproof.cli.verify", "re-check certificates with the trusted verifier"),
    "report": ("ccproof.cli.report", "table of every certified valence (or --tagged)"),
    "eval": ("ccproof.cli.eval", "evaluate the limit surface of any mesh (bmz04's on quads)"),
    "project": ("ccproof.cli.project", "nearest points of the limit surface to 3-D points (closest points)"),
    "invert": ("ccproof.cli.invert", "invert the characteristic map at a point"),
    "arap": ("ccproof.cli.arap", "ARAP parameterization of a subdivision surface (hsh10)"),
    "fit": ("ccproof.cli.fit", "fit a dynamic Catmull-Clark surface to points (qmv98)"),
}


#: the commands that read meshes, point files or chart labels: they take --max-input (ccproof/mesh/inputs.py)
INPUT_COMMANDS = ("eval", "project", "fit", "arap")
#: the command line's default --max-polygon (the library reads any polygon); a constant here, so that
#: ``ccproof --help`` imports nothing of the mesh package (no numpy)
MAX_POLYGON = 1024


def _add_input_limit(p):
    p.add_argument("--max-input", type=float, default=None, metavar="GB",
                   help="largest input file read, in GB (default 2); inputs are regular files or pipes (read "
                        "once): a folder, a device such as /dev/zero or a socket is refused by name")
    p.add_argument("--max-polygon", type=int, default=MAX_POLYGON, metavar="N",
                   help=f"largest polygon of a mesh (default {MAX_POLYGON}; the exact data of an n-gon cost about "
                        "n^2 in time and memory: one 1000-gon 5 s and 0.5 GB, two 2048-gons 31 s and 2 GB)")


def _apply_input_limit(args):
    """Set the input cap of ``--max-input`` (refused unless a positive number); returns the previous cap."""
    from ccproof.mesh.inputs import input_cap, set_input_cap, set_polygon_cap

    n = getattr(args, "max_polygon", None)
    if n is not None:
        if n < 3:
            from ccproof.errors import CCProofError

            raise CCProofError(f"--max-polygon must be an integer >= 3, got {n}")
        set_polygon_cap(n)
    gb = getattr(args, "max_input", None)
    if gb is None:
        return input_cap()
    if not (gb > 0 and gb * 1e9 < float("inf")):
        from ccproof.errors import CCProofError

        raise CCProofError(f"--max-input must be a positive number of GB, got {gb}")
    return set_input_cap(gb * 1e9)


def _available():
    out = {}
    for name, (modname, helptext) in COMMANDS.items():
        try:
            spec = importlib.util.find_spec(modname)
        except ModuleNotFoundError:
            spec = None
        if spec is not None:
            out[name] = (modname, helptext)
    return out


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="ccproof",
        description=(
            "Catmull-Clark subdivision surfaces as certified parametric surfaces. "
            "Exact characteristic maps (bmz04), injectivity certificates re-checkable by a small "
            "verifier, and reference numerics."
        ),
        epilog="Run `ccproof COMMAND --help` for the options of one command.",
    )
    from ccproof import __version__

    parser.add_argument("--version", action="version", version=f"ccproof {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name, (modname, helptext) in _available().items():
        mod = importlib.import_module(modname)
        p = sub.add_parser(
            name,
            help=helptext,
            description=(mod.__doc__ or helptext).strip(),
            formatter_class=argparse.RawDescriptionHelpFormatter,
        )
        mod.add_arguments(p)
        if name in INPUT_COMMANDS:
            _add_input_limit(p)
        p.set_defaults(_run=mod.run)
    return parser


def _expected_errors():
    """The exception types that are a user's mistake or a refusal, not a bug: every
    :class:`~ccproof.errors.CCProofError`, ``OSError`` (a missing file, a permission, a full disk), the
    trusted verifier's ``CertificateError`` and meshio's reader and writer errors. A module that was
    never imported cannot have raised, so only the loaded ones are looked up (``--help`` stays fast)."""
    from ccproof.errors import CCProofError

    types = [CCProofError, OSError]
    for modname, names in (("ccproof.certify.verify.errors", ("CertificateError",)),
                           ("meshio._exceptions", ("ReadError", "WriteError"))):
        mod = sys.modules.get(modname)
        types += [getattr(mod, n) for n in names if mod is not None and hasattr(mod, n)]
    return tuple(types)


def error_message(exc) -> str:
    """One line for an expected failure, naming the file for an ``OSError``.

    >>> error_message(FileNotFoundError(2, "No such file or directory", "mesh.obj"))
    'mesh.obj: no such file or directory'
    >>> error_message(ValueError("two\\nlines"))
    'two; lines'
    """
    if isinstance(exc, OSError) and exc.strerror:
        what = exc.strerror[:1].lower() + exc.strerror[1:]
        if exc.filename is not None and exc.filename2 is not None:
            text = f"{exc.filename} -> {exc.filename2}: {what}"
        elif exc.filename is not None:
            text = f"{exc.filename}: {what}"
        else:
            text = what
    else:
        text = str(exc) or type(exc).__name__
    return "; ".join(line.strip() for line in text.splitlines() if line.strip())


def _stdout_closed():
    """Whether the process started with its standard output closed (``>&-``: Python's ``sys.stdout`` is None);
    then the report goes to the null device, so that the command still writes its files."""
    import os

    if sys.stdout is not None:
        return False
    sys.stdout = open(os.devnull, "w")  # noqa: SIM115 - lives as long as the command
    return True


class _Terminated(KeyboardInterrupt):
    """SIGTERM, raised like Ctrl-C so that every ``finally`` runs (temporary output files are removed)."""


def _terminate(signum, frame):  # pragma: no cover - exercised through a subprocess
    raise _Terminated


def _stopped(command, exc) -> int:
    """The one line and exit status of an interrupt (130) or a SIGTERM (143)."""
    terminated = isinstance(exc, _Terminated)
    print(f"ccproof {command}: {'terminated' if terminated else 'interrupted'}", file=sys.stderr)
    return 143 if terminated else 130


def _interrupt_behind(exc):
    """The KeyboardInterrupt (Ctrl-C or our SIGTERM) in the context chain of ``exc``, or None: a library that
    raised its own error while the interrupt unwound it (numba's "no compiled object yet" when stopped during a
    compilation) ends the command as the interrupt would, without a traceback.

    >>> try:
    ...     try:
    ...         raise KeyboardInterrupt
    ...     except KeyboardInterrupt:
    ...         raise RuntimeError("cleanup failed")
    ... except RuntimeError as e:
    ...     type(_interrupt_behind(e)).__name__, _interrupt_behind(RuntimeError("a bug"))
    ('KeyboardInterrupt', None)
    """
    seen = set()
    while exc is not None and id(exc) not in seen:
        if isinstance(exc, KeyboardInterrupt):
            return exc
        seen.add(id(exc))
        exc = exc.__context__
    return None


def main(argv=None) -> int:
    """Run one ``ccproof`` command; returns the exit status.

    0: done; 1: a negative verdict (a certificate that fails, an uncertified point); 2: bad input or an
    expected failure, reported in one line ``ccproof CMD: error: ...`` on stderr; 130: interrupted
    (Ctrl-C; 143: SIGTERM), no partial output file left. Any other exception is a bug and keeps its traceback.
    """
    parser = build_parser()
    args = parser.parse_args(argv)
    if not getattr(args, "command", None):
        parser.print_help()
        return 2
    import signal
    import threading

    if threading.current_thread() is threading.main_thread():
        previous = signal.signal(signal.SIGTERM, _terminate)
    else:  # pragma: no cover - main() called from a thread: no handler can be installed
        previous = None
    import warnings

    def one_line_warning(message, category, filename, lineno, file=None, line=None):
        print(f"ccproof {args.command}: warning: {error_message(message)}", file=sys.stderr)

    closed = _stdout_closed()
    if closed:
        print(f"ccproof {args.command}: warning: standard output is closed: the printed report is discarded "
              f"(output files are written)", file=sys.stderr)
    cap = None
    try:
        with warnings.catch_warnings():
            warnings.showwarning = one_line_warning
            cap = _apply_input_limit(args) if args.command in INPUT_COMMANDS else None
            return int(args._run(args) or 0)
    except KeyboardInterrupt as exc:
        return _stopped(args.command, exc)
    except Exception as exc:
        stop = _interrupt_behind(exc)
        if stop is not None:  # a library failed while our Ctrl-C/SIGTERM unwound it (numba mid-compile)
            return _stopped(args.command, stop)
        if not isinstance(exc, _expected_errors()):
            raise
        print(f"ccproof {args.command}: error: {error_message(exc)}", file=sys.stderr)
        return 2
    finally:
        if closed:
            sys.stdout.close()
            sys.stdout = None  # as it was
        if previous is not None:
            signal.signal(signal.SIGTERM, previous)
        if cap is not None:
            from ccproof.mesh.inputs import set_input_cap, set_polygon_cap

            set_input_cap(cap)
            set_polygon_cap(None)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
