"""The text state: every piece's cells (1-based), where it is or, in the tray, its own shape.

Shown by the ``state`` action's feedback (:mod:`chaingeo.envs.machines.state`), by observations with
``text_state=True`` (:mod:`chaingeo.envs.observation`) and by ``chain play``. It reads a state
machine through the small views below, so the state machines can use it without an import
cycle. Pieces of a level converted from CHAIN show CHAIN's id beside the colour name.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Protocol, cast

from chaingeo.core.geometry import Cell, Shape
from chaingeo.core.level import Level, Piece
from chaingeo.envs.actions.types import cells_text


class _Shapes(Protocol):
    @property
    def shapes(self) -> Mapping[str, Shape]: ...


class StackingView(Protocol):
    """What the text needs of :class:`chaingeo.envs.machines.stacking.StackingState`."""

    @property
    def level(self) -> Level: ...
    @property
    def box(self) -> tuple[int, int, int]: ...
    @property
    def placed(self) -> dict[str, tuple[Cell, ...]]: ...
    @property
    def tray(self) -> list[str]: ...
    @property
    def tables(self) -> _Shapes: ...
    def empty_cells(self) -> int: ...


class _Parts(Protocol):
    @property
    def parts(self) -> tuple[frozenset[str], ...]: ...


class PuzzleView(Protocol):
    """What the text needs of :class:`chaingeo.envs.machines.puzzle.PuzzleState`."""

    @property
    def level(self) -> Level: ...
    @property
    def mode(self) -> str: ...
    @property
    def assembly(self) -> _Parts: ...
    def cells_of(self, name: str) -> tuple[Cell, ...]: ...


class _HasLevel(Protocol):
    @property
    def level(self) -> Level: ...


def label(piece: Piece) -> str:
    """A piece as the text state names it: ``red``, or ``red (id 0)`` with a CHAIN id."""
    return piece.name if piece.chain_id is None else f"{piece.name} (id {piece.chain_id})"


def state_text(state: _HasLevel) -> str:
    """Every piece's cells (1-based): where it is, or its shape in the tray."""
    if state.level.family == "stacking":
        return stacking_text(cast(StackingView, state))
    return puzzle_text(cast(PuzzleView, state))


def stacking_text(state: StackingView) -> str:
    a, b, c = state.box
    lines = [f"Box {a}x{b}x{c}: {a * b * c - state.empty_cells()} of {a * b * c} cells filled."]
    placed = state.placed
    lines.append("In the box:" if placed else "In the box: nothing yet.")
    for p in state.level.pieces:
        if p.name in placed:
            lines.append(f"  {label(p)}: {cells_text(placed[p.name])}")
    tray = state.tray
    if tray:
        lines.append("In the tray (the piece's own cells, counted from 1):")
        for name in tray:
            shape = state.tables.shapes[name].normalized()
            lines.append(f"  {label(state.level.piece(name))}: {cells_text(shape)}")
    return "\n".join(lines)


def ordered_parts(state: PuzzleView) -> list[frozenset[str]]:
    """A puzzle's parts, largest first (then by name)."""
    return sorted(state.assembly.parts, key=lambda p: (-len(p), sorted(p)))


def puzzle_text(state: PuzzleView) -> str:
    lines = []
    parts = ordered_parts(state)
    if len(parts) == 1:
        lines.append(f"One part: {', '.join(sorted(parts[0]))}.")
    else:
        lines.append(f"{len(parts)} parts (pieces of different parts never touch again):")
    for i, part in enumerate(parts, 1):
        if len(parts) > 1:
            kind = "apart" if len(part) == 1 else "held together"
            lines.append(f"  part {i} ({kind}): {', '.join(sorted(part))}")
        for name in sorted(part):
            lines.append(f"    {name}: {cells_text(state.cells_of(name))}")
    if state.mode == "assemble":
        lines.append("Target (every piece in its place):")
        for p in state.level.pieces:
            lines.append(f"    {p.name}: {cells_text(p.shape)}")
    return "\n".join(lines)
