"""A level named on the command line: a level file, or the id of a level in a folder (by
default the shipped suite). One resolver, so every command that takes a level takes both, and
one error naming both possibilities when neither fits."""

from __future__ import annotations

import argparse
import itertools
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
    """The level in file ``spec``, else the level whose id is ``spec`` under ``folder``."""
    from chaingeo.core.level import load_level

    path = Path(spec)
    if path.is_file():
        return load_level(path)
    return _by_id(str(spec), folder)[1]


def level_file(spec: str | Path, folder: Path | None = None) -> Path:
    """The file of :func:`find_level`'s level (for commands that report files)."""
    path = Path(spec)
    return path if path.is_file() else _by_id(str(spec), folder)[0]


def _by_id(spec: str, folder: Path | None) -> tuple[Path, Level]:
    """The file and level of id ``spec`` under ``folder`` (default: the shipped suite); the
    one error naming both readings of ``spec`` when there is none."""
    from chaingeo.core.suite import suite_folder

    root = folder if folder is not None else suite_folder()
    found = _search(spec, root) if root.is_dir() else None
    if found is None:
        where = f"none in {root}" if root.is_dir() else f"{root} is no folder"
        raise CommandError(f"no level file or level id {spec!r} (no such file; {where})")
    return found


def _search(spec: str, root: Path) -> tuple[Path, Level] | None:
    """Files are named by id, so those are read first; then every file of ``root``."""
    from chaingeo.core.level import load_level

    if "/" in spec or "\\" in spec:  # a path, never an id
        return None
    named = sorted(root.rglob(f"{spec}.json"))
    for path in itertools.chain(named, sorted(root.rglob("*.json"))):
        level = load_level(path)
        if level.id == spec:
            return path, level
    return None


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
