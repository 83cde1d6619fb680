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
    "certify": ("ccproof.cli.certify", "prove injectivity for a valence and write a certificate"),
    "verify": ("ccproof.cli.verify", "re-check certificates with the trusted verifier"),
    "report": ("ccproof.cli.report", "table of every certified valence"),
    "eval": ("ccproof.cli.eval", "evaluate the limit surface of a quad mesh (natural or bmz04 parameterizations)"),
    "project": ("ccproof.cli.project", "nearest points of the limit surface to 3-D points (closest points)"),
    "invert": ("ccproof.cli.invert", "invert the characteristic map at a point"),
    "arap": ("ccproof.cli.arap", "ARAP parameterization of a subdivision surface (hsh10)"),
    "fit": ("ccproof.cli.fit", "fit a dynamic Catmull-Clark surface to points (qmv98)"),
}


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
        p.set_defaults(_run=mod.run)
    return parser


def main(argv=None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if not getattr(args, "command", None):
        parser.print_help()
        return 2
    from ccproof.errors import CCProofError

    try:
        return int(args._run(args) or 0)
    except CCProofError as exc:
        print(f"ccproof {args.command}: error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
