"""Per-level data of the puzzle state machine, and its position keys
(:mod:`chaingeo.envs.puzzle`)."""

from __future__ import annotations

from chaingeo.core.geometry import Shape
from chaingeo.core.kinematics import Assembly, disassembly_of_assembly_plan
from chaingeo.core.level import Level, PuzzleSolution
from chaingeo.core.rules import PuzzleRules
from chaingeo.envs.puzzle_turns import PartKey, turned_part_key
from solvers.partsearch import PieceTable
from solvers.turnmoves import TurnTable

PositionKey = tuple[PartKey, ...]


def normal_key(asm: Assembly) -> PositionKey:
    """Each part as (name, offset relative to the part's first piece), parts sorted. Where
    turns left pieces turned, see :func:`chaingeo.envs.puzzle_turns.turned_part_key`."""
    parts: list[PartKey] = []
    for part in asm.parts:
        names = sorted(part)
        if any(asm.rotation_of(n) for n in names):
            parts.append(turned_part_key(asm, names))
            continue
        bx, by, bz = asm.offsets[names[0]]
        parts.append(
            tuple(
                (n, (asm.offsets[n][0] - bx, asm.offsets[n][1] - by, asm.offsets[n][2] - bz))
                for n in names
            )
        )
    return tuple(sorted(parts))


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
