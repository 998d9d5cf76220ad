"""The original CHAIN stacking format: ``{"box": [A, B, C], "pieces": [[[x, y, z], ...], ...]}``.

Voxels are 0-based cells of the packed box; a piece's id is its list index (as a string). On
import, piece ``i`` gets palette colour ``i``, and the original ids are kept in ``stats``.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

from chaingeo.core import canonical_json
from chaingeo.core.geometry import Shape
from chaingeo.core.level import Level, LevelError, StackingSolution, stacking_level


def import_chain_stacking(
    data: Any, level_id: str, difficulty: str = "easy", source: str = "<chain json>"
) -> Level:
    """Build a verified level from a decoded original-format object."""
    if not isinstance(data, dict):
        raise LevelError(source, "(top level)", "expected an object with 'box' and 'pieces'")
    box = data.get("box")
    pieces = data.get("pieces")
    if not (
        isinstance(box, list)
        and len(box) == 3
        and all(isinstance(v, int) and not isinstance(v, bool) and v > 0 for v in box)
    ):
        raise LevelError(source, "box", f"expected three positive integers, got {box!r}")
    if not (isinstance(pieces, list) and pieces):
        raise LevelError(source, "pieces", "expected a non-empty list of voxel lists")
    shapes: list[Shape] = []
    for i, cells in enumerate(pieces):
        ok = (
            isinstance(cells, list)
            and cells
            and all(
                isinstance(c, list)
                and len(c) == 3
                and all(isinstance(v, int) and not isinstance(v, bool) for v in c)
                for c in cells
            )
        )
        if not ok:
            raise LevelError(
                source, f"pieces[{i}]", "expected a non-empty list of [x, y, z] integers"
            )
        shapes.append(Shape(cells))
    if difficulty not in ("easy", "mid", "hard"):
        raise LevelError(source, "difficulty", f"{difficulty!r} is not easy, mid or hard")
    try:
        return stacking_level(
            level_id,
            difficulty,  # type: ignore[arg-type]
            box,
            shapes,
            generator="chain-json-import",
            stats={"chain_ids": [str(i) for i in range(len(shapes))]},
        )
    except LevelError as e:
        raise LevelError(source, e.field, e.reason) from None


def export_chain_stacking(level: Level) -> dict[str, Any]:
    """The packed solution in the original format, pieces in the level's piece order."""
    if (
        level.family != "stacking"
        or level.box is None
        or not isinstance(level.solution, StackingSolution)
    ):
        raise ValueError(f"level {level.id} is not a stacking level")
    placements = level.solution.placements
    return {
        "box": list(level.box),
        "pieces": [[list(c) for c in placements[p.name].cells] for p in level.pieces],
    }


def read_chain_stacking(
    path: str | os.PathLike[str], level_id: str | None = None, difficulty: str = "easy"
) -> Level:
    source = str(path)
    try:
        data = json.loads(Path(path).read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as e:
        raise LevelError(source, "(file)", f"cannot read as JSON: {e}") from None
    return import_chain_stacking(data, level_id or Path(path).stem, difficulty, source)


def write_chain_stacking(level: Level, path: str | os.PathLike[str]) -> None:
    Path(path).write_text(canonical_json.dumps(export_chain_stacking(level)), encoding="utf-8")
