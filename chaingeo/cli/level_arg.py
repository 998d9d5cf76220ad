"""A level named on the command line: a level file, or the id of a level in a folder (by
default the shipped suite). One resolver, so every command that takes a level takes both."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import TYPE_CHECKING

from chaingeo.cli.errors import CommandError

if TYPE_CHECKING:
    from chaingeo.core.level import Level


def is_level_file(spec: str | Path) -> bool:
    path = Path(spec)
    return path.suffix == ".json" or path.is_file()


def find_level(spec: str | Path, folder: Path | None = None) -> Level:
    """The level in file ``spec``, else the level whose id is ``spec`` under ``folder``."""
    from chaingeo.core.level import load_level, load_levels
    from chaingeo.core.suite import suite_folder

    if is_level_file(spec):
        return load_level(spec)
    root = folder if folder is not None else suite_folder()
    if not root.is_dir():
        raise CommandError(f"no level file or level id {str(spec)!r} ({root} is no folder)")
    for path in sorted(root.rglob(f"{Path(spec).name}.json")):  # files are named by id
        level = load_level(path)
        if level.id == str(spec):
            return level
    for level in load_levels(root):
        if level.id == str(spec):
            return level
    raise CommandError(f"no level file or level id {str(spec)!r} (looked in {root})")


def add_level_list(p: argparse.ArgumentParser) -> None:
    """``[LEVELS...] --folder DIR``: level files or ids, by default every level of the folder."""
    p.add_argument(
        "levels", nargs="*", help="level files or ids (default: every level under --folder)"
    )
    p.add_argument("--folder", type=Path, default=None, help="levels folder (default: shipped)")


def levels_of(args: argparse.Namespace) -> list[Level]:
    """The levels named by :func:`add_level_list`'s arguments."""
    from chaingeo.core.level import load_levels
    from chaingeo.core.suite import suite_folder

    if args.levels:
        return [find_level(spec, args.folder) for spec in args.levels]
    return load_levels(args.folder if args.folder is not None else suite_folder())
