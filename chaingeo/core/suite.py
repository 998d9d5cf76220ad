"""The shipped level suite, in a checkout and in an installed wheel alike: its folder, its ids,
and a level by id or by path.

The repository keeps the suite in ``levels/``; the wheel carries the same files as the package
data of ``chaingeo.levels`` (``pyproject.toml`` maps the folder), so code never looks for it
relative to the source tree. Files are named by level id (``tests/conformance/test_api.py`` checks).
"""

from __future__ import annotations

import itertools
import os
from collections.abc import Sequence
from importlib import resources
from pathlib import Path
from typing import TYPE_CHECKING, Final

from chaingeo.core.errors import ChainGeoError
from chaingeo.core.level_reader import LevelError

if TYPE_CHECKING:
    from chaingeo.core.level import Level

__all__ = [
    "EXAMPLES",
    "FAMILIES",
    "SUITE_PACKAGE",
    "UnknownLevelError",
    "load_level",
    "resolve_level",
    "shipped_level",
    "shipped_levels",
    "suite_folder",
]

#: The package the suite is installed as.
SUITE_PACKAGE: Final = "chaingeo.levels"
FAMILIES: Final = ("puzzle", "stacking")
#: Example files shipped with the package (a BurrTools ``.xmpuzzle`` made by
#: :mod:`chaingeo.generator.bt_examples`), for the quick start and the docs.
EXAMPLES: Final = Path(__file__).resolve().parent.parent / "examples"


class UnknownLevelError(ChainGeoError, LookupError):
    """No level file at that path and no level of that id in the folder searched; the message
    names the nearest ids ("did you mean") when there are some."""

    def __init__(self, spec: str, where: str = "", near: Sequence[str] = ()) -> None:
        hint = f"; did you mean {' or '.join(repr(n) for n in near)}?" if near else ""
        place = where or (
            "the shipped suite; chaingeo.shipped_levels() lists its ids "
            "(chaingeo.shipped_levels('puzzle') those of one family)"
        )
        super().__init__(
            f"no level file or level id {spec!r} (no such file; none in {place}){hint}"
        )
        self.spec = spec
        self.near = tuple(near)


def suite_folder(family: str | None = None) -> Path:
    """The folder of the shipped suite (or of one family's levels in it)."""
    if family is not None and family not in FAMILIES:
        raise ValueError(f"unknown family {family!r}; the suite has {', '.join(FAMILIES)}")
    try:
        root = resources.files(SUITE_PACKAGE)
    except ModuleNotFoundError:
        raise LevelError(SUITE_PACKAGE, "package", "the shipped suite is not installed") from None
    if not isinstance(root, Path):
        raise LevelError(SUITE_PACKAGE, "package", f"not on the file system: {root}")
    return root / family if family is not None else root


def shipped_levels(family: str | None = None) -> list[str]:
    """The ids of the shipped levels (of one family: ``"puzzle"`` or ``"stacking"``), sorted;
    read from the file names, so listing loads no level."""
    return sorted(p.stem for p in suite_folder(family).rglob("*.json"))


def shipped_level(level_id: str) -> Level:
    """The shipped level of id ``level_id`` (:class:`UnknownLevelError` if there is none)."""
    return resolve_level(level_id, file_first=False)[1]


def resolve_level(
    spec: str | os.PathLike[str], folder: Path | None = None, *, file_first: bool = True
) -> tuple[Path, Level]:
    """The one level resolver, used by the library and every command: ``spec`` is a level file
    or the id of a level under ``folder`` (default: the shipped suite); the file and the level.
    Files are named by id, so those are read first, then every file of the folder. Neither
    found: :class:`UnknownLevelError`, naming the nearest ids."""
    from chaingeo.core.level import load_level as read_file

    path = Path(spec)
    if file_first and (path.is_file() or path.suffix == ".json"):
        return path, read_file(path)
    text = str(spec)
    root = folder if folder is not None else suite_folder()
    where = "" if folder is None else str(root)
    if not root.is_dir():
        raise UnknownLevelError(text, f"{root}, which is no folder")
    if "/" not in text and "\\" not in text and text == text.strip():
        named = sorted(root.rglob(f"{text}.json")) if _glob_safe(text) else []
        for candidate in itertools.chain(named, sorted(root.rglob("*.json"))):
            level = read_file(candidate)
            if level.id == text:
                return candidate, level
    ids = sorted(p.stem for p in root.rglob("*.json"))
    raise UnknownLevelError(text, where, nearest(text, ids))


#: At most this many ids are suggested for a near miss.
MAX_SUGGESTIONS: Final = 5


def nearest(text: str, ids: Sequence[str]) -> list[str]:
    """The ids fewest edits (insertions, deletions, substitutions) away from ``text``, when
    that is at most a fifth of its length (at least 2); sorted, at most
    :data:`MAX_SUGGESTIONS`."""
    limit = max(2, len(text) // 5)
    scored = [(d, i) for i in ids if (d := _edits(text, i, limit)) <= limit]
    best = min((d for d, _ in scored), default=None)
    return sorted(i for d, i in scored if d == best)[:MAX_SUGGESTIONS]


def _edits(a: str, b: str, limit: int) -> int:
    """Levenshtein distance of ``a`` and ``b``, or ``limit + 1`` once it must exceed ``limit``."""
    if abs(len(a) - len(b)) > limit:
        return limit + 1
    row = list(range(len(b) + 1))
    for i, ca in enumerate(a, 1):
        prev, row[0] = row[0], i
        for j, cb in enumerate(b, 1):
            prev, row[j] = row[j], min(row[j] + 1, row[j - 1] + 1, prev + (ca != cb))
        if min(row) > limit:
            return limit + 1
    return row[-1]


def _glob_safe(text: str) -> bool:
    """Whether ``text`` can stand in a glob pattern as itself."""
    return not any(c in text for c in "*?[]")


def load_level(source: str | os.PathLike[str], folder: Path | None = None) -> Level:
    """A level from a file or, when ``source`` names no file, the level of that id (in the
    shipped suite, or under ``folder``): :func:`resolve_level`'s level."""
    return resolve_level(source, folder)[1]
