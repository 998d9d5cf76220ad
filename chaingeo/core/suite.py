"""Where the shipped level suite is, in a checkout and in an installed wheel alike.

The repository keeps the suite in ``levels/``; the wheel carries the same files as the package
data of ``chaingeo.levels`` (``pyproject.toml`` maps the folder), so code never looks for it
relative to the source tree.
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path
from typing import Final

from chaingeo.core.level import LevelError

#: The package the suite is installed as.
SUITE_PACKAGE: Final = "chaingeo.levels"
FAMILIES: Final = ("puzzle", "stacking")


def shipped_levels(family: str | None = None) -> Path:
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
