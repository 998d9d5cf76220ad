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

import weakref
from collections.abc import Hashable, Mapping
from dataclasses import dataclass
from typing import Any, Final

import numpy as np
import numpy.typing as npt

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
        turned = {n: s.orientations() for n, s in self.shapes.items()}
        self.orientations: dict[str, frozenset[tuple[Cell, ...]]] = {
            n: frozenset(o.cells for o in os) for n, os in turned.items()
        }
        self.placements: dict[str, list[Placement]] = {
            n: _placements(n, turned[n], self.box) for n in sorted(self.shapes)
        }
        self.by_action: dict[PlaceAction, Placement] = {
            p.action: p for ps in self.placements.values() for p in ps
        }

    def mask(self, cells: tuple[Cell, ...]) -> int:
        out = 0
        for c in cells:
            out |= self.bit[c]
        return out

    def catalogue(self) -> list[Action]:
        """Every action that can ever be legal in this level, sorted: the gym action list."""
        places: list[Action] = [
            p.action for n in sorted(self.placements) for p in self.placements[n]
        ]
        pickups: list[Action] = [PickupAction(n) for n in sorted(self.shapes)]
        return [*places, *pickups, FinishAction()]


#: Tables of the levels in use, by the level object's id (an entry leaves with its level).
_BUILT: dict[int, tuple[weakref.ref[Level], StackingTables]] = {}


def tables_of(level: Level) -> StackingTables:
    """The level's tables, built on first use and shared while the level object lives: every
    state, clone and environment reset of one level reads the same (read-only) tables."""
    key = id(level)
    hit = _BUILT.get(key)
    if hit is not None and hit[0]() is level:
        return hit[1]
    tables = StackingTables(level)
    _BUILT[key] = (weakref.ref(level), tables)
    weakref.finalize(level, _BUILT.pop, key, None)
    return tables


def _placements(
    name: str, orients: tuple[Shape, ...], box: tuple[int, int, int]
) -> list[Placement]:
    """Every (normalised) orientation at every offset inside the box, sorted by cells; the
    masks of all of them computed at once on boolean box grids and packed into integers."""
    bx, by, bz = box
    rows = []
    for orient in orients:
        ex, ey, ez = orient.extent
        if ex <= bx and ey <= by and ez <= bz:
            axes = (np.arange(bx - ex + 1), np.arange(by - ey + 1), np.arange(bz - ez + 1))
            offsets = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
            rows.append(orient.voxels[None, :, :] + offsets[:, None, :])
    if not rows:
        return []
    cells = np.concatenate(rows)  # (placements, cells, 3)
    step = max(1, _GRID_BYTES // (bx * by * bz))
    found = [p for i in range(0, len(cells), step) for p in _masks(name, cells[i : i + step], box)]
    return sorted(found, key=lambda p: p.action.cells)


#: Boolean box grids are built for at most this many bytes of placements at a time.
_GRID_BYTES: Final = 1 << 22


def _masks(name: str, cells: npt.NDArray[np.int64], box: tuple[int, int, int]) -> list[Placement]:
    """The placements of ``cells`` (placements, cells, 3), each with its masks."""
    own = np.zeros((len(cells), *box), dtype=np.bool_)
    x, y, z = np.moveaxis(cells, 2, 0)
    own[np.arange(len(cells))[:, None], x, y, z] = True
    around = _face_neighbours(own) & ~own
    above = np.logical_or.accumulate(own, axis=3) & ~own  # not own, an own cell under it
    floor: list[bool] = np.any(own[..., 0], axis=(1, 2)).tolist()
    masks, arounds, aboves = (_as_ints(g) for g in (own, around, above))
    return [
        Placement(PlaceAction.trusted(name, tuple(map(tuple, c))), m, a, f, up)
        for c, m, a, f, up in zip(cells.tolist(), masks, arounds, floor, aboves, strict=True)
    ]


def _face_neighbours(grids: npt.NDArray[np.bool_]) -> npt.NDArray[np.bool_]:
    """Per grid, the cells face-adjacent to one of its cells (inside the box)."""
    out = np.zeros_like(grids)
    for axis in (1, 2, 3):
        head = [slice(None)] * 4
        tail = [slice(None)] * 4
        head[axis], tail[axis] = slice(1, None), slice(None, -1)
        out[tuple(head)] |= grids[tuple(tail)]
        out[tuple(tail)] |= grids[tuple(head)]
    return out


def _as_ints(grids: npt.NDArray[np.bool_]) -> list[int]:
    """Each grid as the integer whose bit ``(x * by + y) * bz + z`` is cell (x, y, z)."""
    packed = np.packbits(grids.reshape(len(grids), -1), axis=1, bitorder="little")
    return [int.from_bytes(row.tobytes(), "little") for row in packed]


@dataclass(frozen=True)
class StackingPosition:
    """Which pieces are in the box and where (sorted by name), and the filled-cell mask."""

    placed: tuple[tuple[str, tuple[Cell, ...]], ...]
    filled: int


class StackingState(BaseState):
    """One stacking level being played (see the module docstring)."""

    def __init__(self, level: Level, tables: StackingTables | None = None) -> None:
        super().__init__(level)
        self.tables = tables if tables is not None else tables_of(level)
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
