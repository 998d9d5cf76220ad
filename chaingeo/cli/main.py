"""The ``chain`` command: a thin face over the toolkit.

Each subcommand lives in its own module under :mod:`chaingeo.cli.commands` and exposes
``register(subparsers)``; modules are discovered, so adding a command touches no shared file.
Heavy imports happen inside each command, so ``chain --help`` stays fast.
"""

from __future__ import annotations

import argparse
import atexit
import gc
import importlib
import pkgutil
import sys
from collections.abc import Sequence

import chaingeo.cli.commands
from chaingeo import __version__
from chaingeo.cli.help_format import CommandParser, HelpFormatter
from chaingeo.core.errors import ChainGeoError

# At exit, the interpreter's last collections walk every object numba and numpy created (about
# 0.15 s of a 1 s ``chain analyze``); the process ends anyway, so freeze them instead.
atexit.register(gc.freeze)

#: Subcommand modules, alphabetical (the order ``chain --help`` lists them).
COMMANDS: tuple[str, ...] = tuple(
    f"chaingeo.cli.commands.{m.name}"
    for m in sorted(pkgutil.iter_modules(chaingeo.cli.commands.__path__), key=lambda m: m.name)
)


def build_parser(only: str | None = None) -> argparse.ArgumentParser:
    """The ``chain`` parser with every subcommand, or with only the one of module ``only``."""
    parser = argparse.ArgumentParser(
        prog="chain",
        description="CHAIN-geo: exact discrete-geometry levels, solvers and agent evaluation.",
        formatter_class=HelpFormatter,
    )
    parser.add_argument(
        "--version",
        action="version",
        version=f"chain {__version__}",
        help="print chaingeo's version",
    )
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=CommandParser)
    for name in COMMANDS if only is None else (only,):
        importlib.import_module(name).register(sub)
    return parser


def _parser_for(argv: Sequence[str]) -> argparse.ArgumentParser:
    """The parser for this command line: when its first word is a subcommand whose module has
    its name, only that module is imported (the others' imports are ~0.03 s of a short command
    such as ``chain analyze``); anything else gets the whole parser."""
    module = f"chaingeo.cli.commands.{argv[0].replace('-', '_')}" if argv else ""
    if module in COMMANDS:
        parser = build_parser(only=module)
        sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
        if argv[0] in sub.choices:
            return parser
    return build_parser()


def main(argv: Sequence[str] | None = None) -> int:
    words = list(sys.argv[1:] if argv is None else argv)
    parser = _parser_for(words)
    args = parser.parse_args(words)
    # The process' own command line, for a command that starts itself again (analyze); None
    # when main() is called from Python.
    args.command_line = list(sys.argv[1:]) if argv is None else None
    if not getattr(args, "func", None):
        parser.print_help()
        return 0
    try:
        return int(args.func(args) or 0)
    except (ChainGeoError, FileNotFoundError, ValueError) as e:
        print(f"chain {args.command}: error: {e}", file=sys.stderr)
        return 2
    except OSError as e:  # a full disk, a folder not ours: one line naming the path
        print(f"chain {args.command}: error: {os_error(e)}", file=sys.stderr)
        return 2


def os_error(e: OSError) -> str:
    """``PATH: reason`` of an ``OSError`` (both paths of a rename), without a traceback."""
    where = " -> ".join(str(f) for f in (e.filename, e.filename2) if f is not None)
    reason = e.strerror or str(e)
    return f"{where}: {reason}" if where else reason


if __name__ == "__main__":
    sys.exit(main())
