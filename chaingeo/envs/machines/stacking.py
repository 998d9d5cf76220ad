"""The stacking state machine: pack every piece into the box, exactly.

Pieces start in a tray beside the box, in the orientation the level hands them out. ``place``
names a piece and the box cells it should fill; the engine checks that those cells are the
piece in some rotation (it finds the rotation and offset itself) and that the placement obeys
:func:`chaingeo.core.rules.placement_problem` (inside the box, no overlap, no floating piece; under
the ``drop`` rule also lowerable from above). ``pickup`` takes a placed piece back to the tray:
it may not leave another piece floating, and under ``drop`` nothing may rest on top of it.
Success is the box exactly full, i.e. every piece placed.

Under the ``chain`` rules profile the game is CHAIN's exactly: the same placement checks in
the same order (unknown piece, already placed, cell count, shape, box, overlap, support), but a
pickup of a placed piece is always allowed (CHAIN does not re-check the pieces left behind),
and every refusal's reason starts with CHAIN's error name. On every stacking level a refusal
carries that name as its ``code`` (None for our own rules that CHAIN lacks).

Legal placements are enumerated once per level (every orientation at every offset inside the
box) as bit masks over the box cells, so ``legal_actions`` is a few integer ``&`` per candidate;
a test checks that it agrees with ``placement_problem`` exactly.
"""

from __future__ import annotations

from collections.abc import Hashable, Mapping
from dataclasses import dataclass
from typing import Any

from chaingeo.core.geometry import NEIGHBOURS, Cell, Shape
from chaingeo.core.level import Level
from chaingeo.core.rules import Rejection, StackingRules, placement_rejection
from chaingeo.envs.actions.types import (
    Action,
    FinishAction,
    PickupAction,
    PlaceAction,
    cell_text,
    rules_text,
)
from chaingeo.envs.machines.state import BaseState
from chaingeo.envs.machines.text_state import label


@dataclass(frozen=True)
class Placement:
    """One way to put a piece into the empty box, with the masks that decide its legality."""

    action: PlaceAction
    mask: int  # the cells it fills
    around: int  # box cells face-adjacent to it (outside it)
    floor: bool  # touches z = 0
    above: int  # box cells straight above it (the drop rule's lowering path)


class StackingTables:
    """Per-level data shared by every state of that level (built once, read only)."""

    def __init__(self, level: Level) -> None:
        if level.box is None or not isinstance(level.rules, StackingRules):
            raise ValueError(f"level {level.id} is not a stacking level")
        self.box: tuple[int, int, int] = level.box
        self.rules: StackingRules = level.rules
        bx, by, bz = self.box
        self.bit: dict[Cell, int] = {
            (x, y, z): 1 << ((x * by + y) * bz + z)
            for x in range(bx)
            for y in range(by)
            for z in range(bz)
        }
        self.shapes: dict[str, Shape] = {p.name: p.shape for p in level.pieces}
        self.names: tuple[str, ...] = tuple(p.name for p in level.pieces)
        self.orientations: dict[str, frozenset[tuple[Cell, ...]]] = {
            n: frozenset(o.cells for o in s.orientations()) for n, s in self.shapes.items()
        }
        self.placements: dict[str, list[Placement]] = {
            n: self._enumerate(n) for n in sorted(self.shapes)
        }
        self.by_action: dict[PlaceAction, Placement] = {
            p.action: p for ps in self.placements.values() for p in ps
        }

    def mask(self, cells: tuple[Cell, ...]) -> int:
        out = 0
        for c in cells:
            out |= self.bit[c]
        return out

    def _enumerate(self, name: str) -> list[Placement]:
        bx, by, bz = self.box
        out: list[Placement] = []
        for orient in self.shapes[name].orientations():
            ex, ey, ez = orient.extent
            for ox in range(bx - ex + 1):
                for oy in range(by - ey + 1):
                    for oz in range(bz - ez + 1):
                        cells = orient.translate((ox, oy, oz)).cells
                        out.append(self._placement(name, cells))
        return sorted(out, key=lambda p: p.action.cells)

    def _placement(self, name: str, cells: tuple[Cell, ...]) -> Placement:
        own = set(cells)
        around = 0
        above = 0
        for x, y, z in cells:
            for dx, dy, dz in NEIGHBOURS:
                n = (x + dx, y + dy, z + dz)
                if n not in own and n in self.bit:
                    around |= self.bit[n]
            for zz in range(z + 1, self.box[2]):
                if (x, y, zz) not in own:
                    above |= self.bit[(x, y, zz)]
        return Placement(
            action=PlaceAction(name, cells),
            mask=self.mask(cells),
            around=around,
            floor=any(z == 0 for _, _, z in cells),
            above=above,
        )

    def catalogue(self) -> list[Action]:
        """Every action that can ever be legal in this level, sorted: the gym action list."""
        places: list[Action] = [
            p.action for n in sorted(self.placements) for p in self.placements[n]
        ]
        pickups: list[Action] = [PickupAction(n) for n in sorted(self.shapes)]
        return [*places, *pickups, FinishAction()]


@dataclass(frozen=True)
class StackingPosition:
    """Which pieces are in the box and where (sorted by name), and the filled-cell mask."""

    placed: tuple[tuple[str, tuple[Cell, ...]], ...]
    filled: int


class StackingState(BaseState):
    """One stacking level being played (see the module docstring)."""

    def __init__(self, level: Level, tables: StackingTables | None = None) -> None:
        super().__init__(level)
        self.tables = tables if tables is not None else StackingTables(level)
        self._pos = StackingPosition((), 0)

    # -- position -----------------------------------------------------------------------------
    @property
    def _position(self) -> Any:
        return self._pos

    @_position.setter
    def _position(self, value: Any) -> None:
        self._pos = value

    def _position_key(self) -> Hashable:
        return self._pos.placed

    @property
    def box(self) -> tuple[int, int, int]:
        return self.tables.box

    @property
    def placed(self) -> dict[str, tuple[Cell, ...]]:
        """Pieces in the box and the (0-based) cells they fill."""
        return dict(self._pos.placed)

    @property
    def tray(self) -> list[str]:
        """Pieces not in the box, in the level's order."""
        inside = self.placed
        return [n for n in self.tables.names if n not in inside]

    def occupied(self) -> dict[Cell, str]:
        return {c: n for n, cells in self._pos.placed for c in cells}

    def empty_cells(self) -> int:
        bx, by, bz = self.box
        return bx * by * bz - sum(len(c) for _, c in self._pos.placed)

    def is_success(self) -> bool:
        return len(self._pos.placed) == len(self.tables.names)

    # -- rules --------------------------------------------------------------------------------
    def _legal_moves(self) -> list[Action]:
        filled = self._pos.filled
        drop = self.tables.rules.support == "drop"
        inside = self.placed
        out: list[Action] = []
        for name in sorted(self.tables.placements):
            if name in inside:
                continue
            for p in self.tables.placements[name]:
                if p.mask & filled or not (p.floor or p.around & filled):
                    continue
                if drop and p.above & filled:
                    continue
                out.append(p.action)
        out.extend(PickupAction(n) for n in sorted(inside) if self._pickup_problem(n) is None)
        return out

    def _move_problem(self, action: Action) -> str | None:
        why = self._move_rejection(action)
        return None if why is None else why.reason

    def _move_rejection(self, action: Action) -> Rejection | None:
        if isinstance(action, PlaceAction):
            why = self._place_problem(action)
        elif isinstance(action, PickupAction):
            if action.piece not in self.tables.shapes:
                why = Rejection(f"unknown piece {action.piece!r}", "PieceNotFound")
            else:
                why = self._pickup_problem(action.piece)
        else:
            why = Rejection("this is a stacking level: use place, pickup or finish")
        return None if why is None else self.tables.rules.tag(why)

    def _place_problem(self, action: PlaceAction) -> Rejection | None:
        """CHAIN's checks in CHAIN's order (then our ``drop`` rule)."""
        name = action.piece
        if name not in self.tables.shapes:
            return Rejection(f"unknown piece {name!r}", "PieceNotFound")
        if name in self.placed:
            return Rejection(
                f"{name} is already in the box; pick it up first to put it elsewhere",
                "PieceAlreadyPlaced",
            )
        size = len(self.tables.shapes[name])
        if len(action.cells) != size:
            return Rejection(
                f"{name} has {size} cubes but {len(action.cells)} cells were given", "WrongCount"
            )
        if Shape(action.cells).normalized().cells not in self.tables.orientations[name]:
            return Rejection(
                f"those cells are not the shape of {name} in any rotation", "ShapeMismatch"
            )
        why = placement_rejection(Shape(action.cells), self.occupied(), self.box, self.tables.rules)
        return None if why is None else Rejection(rules_text(why.reason), why.code)

    def _pickup_problem(self, name: str) -> Rejection | None:
        inside = self.placed
        if name not in inside:
            return Rejection(f"{name} is not in the box", "PieceNotFound")
        if self.tables.rules.profile == "chain":
            return None  # CHAIN takes any placed piece out, whatever it leaves behind
        cells = set(inside[name])
        occupied = self.occupied()
        if self.tables.rules.support == "drop":
            for x, y, z in sorted(cells):
                for zz in range(z + 1, self.box[2]):
                    who = occupied.get((x, y, zz))
                    if who is not None and who != name:
                        return Rejection(f"{who} rests on top of it at {cell_text((x, y, zz))}")
        rest = {c: n for c, n in occupied.items() if n != name}
        for other in sorted(inside):
            if other == name:
                continue
            if not _supported(inside[other], rest, other):
                return Rejection(f"{other} would be left floating")
        return None

    def _after(self, action: Action) -> Any:
        placed = dict(self._pos.placed)
        filled = self._pos.filled
        if isinstance(action, PlaceAction):
            placed[action.piece] = action.cells
            filled |= self.tables.mask(action.cells)
        else:
            assert isinstance(action, PickupAction)
            filled &= ~self.tables.mask(placed.pop(action.piece))
        return StackingPosition(tuple(sorted(placed.items())), filled)

    def describe(self, action: Action) -> str:
        n = len(self.tables.names)
        k = len(self._pos.placed)
        progress = f"{k} of {n} pieces in the box, {self.empty_cells()} empty cells left."
        if isinstance(action, PlaceAction):
            return f"OK: {label(self.level.piece(action.piece))} placed. {progress}"
        if isinstance(action, PickupAction):
            return f"OK: {label(self.level.piece(action.piece))} is back in the tray. {progress}"
        if self.is_success():
            return "Finished: the box is full."
        return f"Finished without solving: {progress} Still in the tray: {', '.join(self.tray)}."

    def catalogue(self) -> list[Action]:
        return self.tables.catalogue()


def _supported(cells: tuple[Cell, ...], occupied: Mapping[Cell, str], name: str) -> bool:
    """The contact rule for a piece already in place: on the floor or touching another piece."""
    if any(z == 0 for _, _, z in cells):
        return True
    return any(
        occupied.get((x + dx, y + dy, z + dz), name) != name
        for x, y, z in cells
        for dx, dy, dz in NEIGHBOURS
    )
