"""Per-level data of the puzzle state machine, and its position keys
(:mod:`chaingeo.envs.machines.puzzle`)."""

from __future__ import annotations

from collections.abc import Sequence

from chaingeo.core.geometry import Cell, Shape
from chaingeo.core.kinematics import Assembly, disassembly_of_assembly_plan
from chaingeo.core.level import Level, PuzzleSolution
from chaingeo.core.rules import PuzzleRules
from chaingeo.envs.machines.puzzle_turns import PartKey, turned_part_key
from chaingeo.solvers.motion.partsearch import PieceTable
from chaingeo.solvers.motion.turns_kernel import TurnTable

PositionKey = tuple[PartKey, ...]


def part_key(asm: Assembly, part: frozenset[str]) -> PartKey:
    """One part as (name, offset relative to the part's first piece); where turns left pieces
    turned, see :func:`chaingeo.envs.machines.puzzle_turns.turned_part_key`."""
    names = sorted(part)
    if asm.rotations and any(asm.rotation_of(n) for n in names):  # most states turn nothing
        return turned_part_key(asm, names)
    offsets = asm.offsets
    bx, by, bz = offsets[names[0]]
    return tuple((n, (x - bx, y - by, z - bz)) for n in names for x, y, z in (offsets[n],))


def normal_key(asm: Assembly) -> PositionKey:
    """Each part's :func:`part_key`, parts sorted."""
    return tuple(sorted(part_key(asm, part) for part in asm.parts))


def join_shifts(
    asm: Assembly, part: frozenset[str], into: frozenset[str], keys: Sequence[PartKey]
) -> list[tuple[Cell, PartKey]]:
    """The shifts of ``part`` for which :func:`joined_part_key` is one of ``keys`` (part keys
    of ``part | into``), with that key: a piece on the far side of the first name fixes it."""
    names = sorted(part | into)
    far = next(n for n in names if (n in part) != (names[0] in part))
    sign = 1 if far in part else -1
    zero = joined_part_key(asm, part, into, (0, 0, 0))
    if zero is None:
        return []
    at = dict((e[0], e[1]) for e in zero)[far]
    out: list[tuple[Cell, PartKey]] = []
    for key in keys:
        rel = dict((e[0], e[1]) for e in key)[far]
        shift = (sign * (rel[0] - at[0]), sign * (rel[1] - at[1]), sign * (rel[2] - at[2]))
        if joined_part_key(asm, part, into, shift) == key:
            out.append((shift, key))
    return out


def joined_part_key(
    asm: Assembly, part: frozenset[str], into: frozenset[str], shift: Cell
) -> PartKey | None:
    """:func:`part_key` of ``part | into`` once ``part`` is translated by ``shift``, without
    building that assembly; None where a piece is turned (then build it)."""
    names = sorted(part | into)
    if any(asm.rotation_of(n) for n in names):
        return None
    offs = asm.offsets

    def at(n: str) -> Cell:
        x, y, z = offs[n]
        return (x + shift[0], y + shift[1], z + shift[2]) if n in part else (x, y, z)

    bx, by, bz = at(names[0])
    out = []
    for n in names:
        x, y, z = at(n)
        out.append((n, (x - bx, y - by, z - bz)))
    return tuple(out)


class PuzzleTables:
    """Per-level data shared by every state of that level."""

    def __init__(self, level: Level) -> None:
        if not isinstance(level.rules, PuzzleRules) or not isinstance(
            level.solution, PuzzleSolution
        ):
            raise ValueError(f"level {level.id} is not a puzzle level")
        self.mode: str = level.goal
        self.shapes: dict[str, Shape] = {p.name: p.shape for p in level.pieces}
        self.names: tuple[str, ...] = tuple(sorted(self.shapes))
        self.max_group: int | None = level.rules.max_group
        self.turns: bool = level.rules.turns
        self.rods = level.rods
        self.target_key: PositionKey = normal_key(Assembly.assembled(self.shapes, self.rods))
        self.piece_table = PieceTable(self.shapes)
        self.turn_table = TurnTable(self.shapes, self.rods) if self.turns else None
        #: translation tables of the pieces as turned, by orientations (see oriented_table)
        self.oriented: dict[object, PieceTable] = {}
        #: assembly only: normalised states on the recorded plan -> how far along they are.
        self.path: dict[PositionKey, int] = {}
        #: assembly only: the orientations the plan leaves the pieces in (where they start)
        self.start_rotations: dict[str, int] = {}
        if self.mode == "assemble":
            forward = disassembly_of_assembly_plan(level.solution.moves)
            states = [Assembly.assembled(self.shapes, self.rods)]
            for m in forward:
                states.append(states[-1].apply(m))
            n = len(states) - 1
            for i, s in enumerate(states):
                self.path.setdefault(normal_key(s), n - i)
            self.start_rotations = dict(states[-1].rotations)
        #: every part of every position on the plan, by its pieces' names
        self.path_parts: dict[tuple[str, ...], list[PartKey]] = {}
        for p in sorted({p for k in self.path for p in k}):
            self.path_parts.setdefault(tuple(e[0] for e in p), []).append(p)
