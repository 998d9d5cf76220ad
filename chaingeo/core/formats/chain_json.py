"""The original CHAIN stacking format: ``{"box": [A, B, C], "pieces": [[[x, y, z], ...], ...]}``.

Voxels are 0-based; a piece's id is its list index (as a string). CHAIN writes a piece's cells
either where it lies in the packed box (*packed form*) or where it lies in the tray beside the
box (*tray form*); only the shape counts for play. On import, piece ``i`` gets palette colour
``i`` and keeps CHAIN's id ``"i"`` (:attr:`chaingeo.core.level.Piece.chain_id`), so agents may
name it either way, and it is handed out in the orientation the file gives it.

A packed file carries its own solution. A tray file needs a packing found first: that search
(the exact-cover engine) lives above this layer, in ``chain convert --from chain``, which
passes the packing to :func:`chain_level`.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from chaingeo.core import canonical_json, limits
from chaingeo.core.files import UnreadableFile, atomic_write, read_bounded
from chaingeo.core.geometry import Shape, box_cells
from chaingeo.core.level import (
    Difficulty,
    Level,
    LevelError,
    StackingSolution,
    decode_json,
    stacking_level,
)
from chaingeo.core.level_reader import short
from chaingeo.core.rules import StackingRules

DIFFICULTY_NAMES = ("easy", "mid", "hard")


@dataclass(frozen=True)
class ChainStacking:
    """A CHAIN stacking file, checked for form (not yet for solvability)."""

    box: tuple[int, int, int]
    pieces: tuple[Shape, ...]  # as the file gives them, piece ``i`` is CHAIN's id ``"i"``

    @property
    def packed(self) -> bool:
        """True when the cells as given fill the box exactly (packed form)."""
        seen: set[tuple[int, int, int]] = set()
        for shape in self.pieces:
            for c in shape:
                if c in seen:
                    return False
                seen.add(c)
        return seen == box_cells(self.box).cell_set

    @property
    def shapes(self) -> dict[str, Shape]:
        """CHAIN's id -> the piece's shape (normalised), for a packing search."""
        return {str(i): s.normalized() for i, s in enumerate(self.pieces)}


def read_chain_data(data: Any, source: str = "<chain json>") -> ChainStacking:
    """Check a decoded CHAIN file's form (within :mod:`chaingeo.core.limits`)."""
    if not isinstance(data, dict):
        raise LevelError(source, "(top level)", "expected an object with 'box' and 'pieces'")
    box = data.get("box")
    pieces = data.get("pieces")
    if not (
        isinstance(box, list)
        and len(box) == 3
        and all(
            isinstance(v, int) and not isinstance(v, bool) and 0 < v <= limits.MAX_COORD
            for v in box
        )
    ):
        raise LevelError(source, "box", f"expected three positive integers, got {short(box)}")
    if not (isinstance(pieces, list) and pieces):
        raise LevelError(source, "pieces", "expected a non-empty list of voxel lists")
    if len(pieces) > limits.MAX_PIECES:
        raise LevelError(source, "pieces", f"{len(pieces)} pieces; at most {limits.MAX_PIECES}")
    shapes: list[Shape] = []
    total = 0
    for i, cells in enumerate(pieces):
        ok = (
            isinstance(cells, list)
            and 0 < len(cells) <= limits.MAX_PIECE_VOXELS
            and all(
                isinstance(c, list)
                and len(c) == 3
                and all(
                    isinstance(v, int) and not isinstance(v, bool) and abs(v) <= limits.MAX_COORD
                    for v in c
                )
                for c in cells
            )
        )
        if not ok:
            raise LevelError(
                source,
                f"pieces[{i}]",
                f"expected 1 to {limits.MAX_PIECE_VOXELS} cells [x, y, z] of integers of at "
                f"most {limits.MAX_COORD} in size",
            )
        total += len(cells)
        if total > limits.MAX_LEVEL_VOXELS:
            raise LevelError(source, f"pieces[{i}]", f"more than {limits.MAX_LEVEL_VOXELS} voxels")
        if len({tuple(c) for c in cells}) != len(cells):
            raise LevelError(source, f"pieces[{i}]", "a cell is listed twice")
        shapes.append(Shape(cells))
    return ChainStacking((box[0], box[1], box[2]), tuple(shapes))


def chain_level(
    spec: ChainStacking,
    level_id: str,
    difficulty: str = "easy",
    *,
    placements: Sequence[Shape] | None = None,
    rules: StackingRules = StackingRules(),
    source: str = "<chain json>",
) -> Level:
    """A verified level from a CHAIN file and a packing of its pieces (piece ``i`` at
    ``placements[i]``; left out, the file must be in packed form)."""
    if difficulty not in DIFFICULTY_NAMES:
        raise LevelError(source, "difficulty", f"{difficulty!r} is not easy, mid or hard")
    if placements is None:
        if not spec.packed:
            raise LevelError(
                source,
                "pieces",
                "the pieces do not fill the box as given (tray form?): find a packing first, "
                "e.g. with `chain convert --from chain`",
            )
        placements = spec.pieces
    diff: Difficulty = difficulty  # type: ignore[assignment]
    try:
        return stacking_level(
            level_id,
            diff,
            spec.box,
            list(placements),
            rules=rules,
            handed=[s.normalized() for s in spec.pieces],
            generator="chain-json-import",
            chain_ids=[str(i) for i in range(len(spec.pieces))],
        )
    except LevelError as e:
        raise LevelError(source, e.field, e.reason) from None


def import_chain_stacking(
    data: Any,
    level_id: str,
    difficulty: str = "easy",
    source: str = "<chain json>",
    rules: StackingRules = StackingRules(),
) -> Level:
    """Build a verified level from a decoded original-format object in packed form."""
    return chain_level(
        read_chain_data(data, source), level_id, difficulty, rules=rules, source=source
    )


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


def load_chain_file(path: str | os.PathLike[str]) -> ChainStacking:
    """Read and check one CHAIN file (size, JSON nesting and numbers bounded)."""
    source = str(path)
    try:
        text = read_bounded(path, limits.MAX_FILE_BYTES).decode("utf-8")
    except UnreadableFile as e:
        raise LevelError(source, "(file)", e.reason) from None
    except UnicodeDecodeError:
        raise LevelError(source, "(file)", "not UTF-8 text") from None
    return read_chain_data(decode_json(text, source), source)


def read_chain_stacking(
    path: str | os.PathLike[str], level_id: str | None = None, difficulty: str = "easy"
) -> Level:
    """A level from a CHAIN file in packed form."""
    spec = load_chain_file(path)
    return chain_level(spec, level_id or Path(path).stem, difficulty, source=str(path))


def write_chain_stacking(level: Level, path: str | os.PathLike[str]) -> None:
    atomic_write(path, canonical_json.dumps(export_chain_stacking(level)).encode("utf-8"))
