"""The shipped level suite, in a checkout and in an installed wheel alike: its folder, its ids,
and a level by id or by path.

The repository keeps the suite in ``levels/``; the wheel carries the same files as the package
data of ``chaingeo.levels`` (``pyproject.toml`` maps the folder), so code never looks for it
relative to the source tree. Files are named by level id (``tests/conformance/test_api.py`` checks).
"""

from __future__ import annotations

import os
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
    """No level file at that path and no shipped level of that id."""

    def __init__(self, spec: str) -> None:
        super().__init__(
            f"no level file or shipped level id {spec!r}; chaingeo.shipped_levels() lists the "
            "ids (chaingeo.shipped_levels('puzzle') those of one family)"
        )
        self.spec = spec


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
    from chaingeo.core.level import load_level as load_file

    for path in sorted(suite_folder().rglob("*.json")):
        if path.stem == level_id:
            return load_file(path)
    raise UnknownLevelError(level_id)


def load_level(source: str | os.PathLike[str]) -> Level:
    """A level from a file (``chaingeo.core.level.load_level``) or, when ``source`` names no
    file, the shipped level of that id: one call for both, as the command line takes both."""
    from chaingeo.core.level import load_level as load_file

    path = Path(source)
    if path.suffix == ".json" or path.is_file():
        return load_file(path)
    if isinstance(source, str) and os.sep not in source:
        return shipped_level(source)
    raise UnknownLevelError(str(source))
