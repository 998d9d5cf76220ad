"""A level named on the command line: a level file, or the id of a level in a folder (by
default the shipped suite), through the library's one resolver
(:func:`chaingeo.core.suite.resolve_level`), so every command takes both, and one error names
both possibilities (and the nearest ids) when neither fits."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, ClassVar

from chaingeo.cli.errors import CommandError

if TYPE_CHECKING:
    from chaingeo.core.level import Level

#: The help of a LEVEL argument, the same in every command.
LEVEL_HELP = "a chain-level/1 file or the id of a shipped level"


def add_level(p: argparse.ArgumentParser, name: str = "level", **kwargs: Any) -> None:
    """The positional LEVEL: a file or an id, resolved by :func:`find_level`."""
    kwargs.setdefault("help", LEVEL_HELP)
    p.add_argument(name, **kwargs)


def find_level(spec: str | Path, folder: Path | None = None) -> Level:
    """The level in file ``spec``, else the level whose id is ``spec`` under ``folder``
    (:func:`chaingeo.core.suite.resolve_level`)."""
    return _resolve(spec, folder)[1]


def level_file(spec: str | Path, folder: Path | None = None) -> Path:
    """The file of :func:`find_level`'s level (for commands that report files)."""
    return _resolve(spec, folder)[0]


def _resolve(spec: str | Path, folder: Path | None) -> tuple[Path, Level]:
    from chaingeo.core.suite import UnknownLevelError, resolve_level

    try:
        return resolve_level(spec, folder)
    except UnknownLevelError as e:
        raise CommandError(str(e)) from None


def add_level_list(p: argparse.ArgumentParser) -> None:
    """``[LEVEL...] --levels DIR``: level files or ids, by default every level of the folder
    (``--levels``, as in ``chain play`` and ``chain eval``; ``--folder`` is its old name)."""
    p.add_argument(
        "levels",
        nargs="*",
        metavar="LEVEL",
        help="level files or ids (default: every level under --levels)",
    )
    p.add_argument(
        "--levels",
        dest="folder",
        type=Path,
        default=None,
        metavar="DIR",
        help="folder of levels, where ids are looked up (default: the shipped suite)",
    )
    p.add_argument("--folder", dest="folder", type=Path, action=Renamed, help=argparse.SUPPRESS)


class Renamed(argparse.Action):
    """An option's old name: still taken for a release, with a warning naming the new one."""

    NEW: ClassVar[dict[str, str]] = {"--folder": "--levels"}

    def __call__(
        self,
        parser: argparse.ArgumentParser,
        namespace: argparse.Namespace,
        values: str | Sequence[Any] | None,
        option_string: str | None = None,
    ) -> None:
        new = self.NEW.get(option_string or "", "")
        print(
            f"{parser.prog}: warning: {option_string} is deprecated and goes in the next "
            f"release; write {new}",
            file=sys.stderr,
        )
        setattr(namespace, self.dest, values)


def levels_of(args: argparse.Namespace) -> list[Level]:
    """The levels named by :func:`add_level_list`'s arguments."""
    from chaingeo.core.level import load_levels
    from chaingeo.core.suite import suite_folder

    if args.levels:
        return [find_level(spec, args.folder) for spec in args.levels]
    return load_levels(args.folder if args.folder is not None else suite_folder())
