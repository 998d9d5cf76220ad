"""The states a question shows: those the level's stored solution passes through.

Why those: each is reached by a prefix of the solution (the ``state`` the exports give as
action texts), so the picture and the question agree with what an agent playing the level
sees. A puzzle state is a :class:`~chaingeo.core.kinematics.Assembly` seen as a disassembly
(an assembly level's state after ``j`` of its ``n`` actions is the disassembly's after
``n - j``); a stacking state is the pieces placed so far.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass

from chaingeo.core.geometry import Cell, Shape
from chaingeo.core.kinematics import Assembly, disassembly_of_assembly_plan
from chaingeo.core.level import Level, PuzzleSolution, StackingSolution


@dataclass(frozen=True)
class ShownPuzzle:
    step: int
    state: Assembly


@dataclass(frozen=True)
class ShownStacking:
    step: int
    placed: dict[str, Shape]
    tray: tuple[str, ...]

    @property
    def occupied(self) -> dict[Cell, str]:
        return {c: n for n, s in sorted(self.placed.items()) for c in s.cells}


def puzzle_views(level: Level) -> Iterator[ShownPuzzle]:
    """Every state of the solution with a part of two pieces or more, start first."""
    assert isinstance(level.solution, PuzzleSolution)
    moves = list(level.solution.moves)
    assemble = level.goal == "assemble"
    plan = disassembly_of_assembly_plan(moves) if assemble else moves
    state = Assembly.assembled(level.shapes, level.rods)
    by_step: dict[int, Assembly] = {}
    for j in range(len(plan) + 1):
        if j:
            state = state.apply(plan[j - 1])
        if not state.is_separated():
            by_step[len(plan) - j if assemble else j] = state
    for step in sorted(by_step):
        yield ShownPuzzle(step, by_step[step])


def stacking_views(level: Level) -> Iterator[ShownStacking]:
    """The box after each prefix of the solution's placing order (empty first, full never)."""
    assert isinstance(level.solution, StackingSolution)
    sol = level.solution
    for j in range(len(sol.order)):
        placed = {n: sol.placements[n] for n in sol.order[:j]}
        tray = tuple(p.name for p in level.pieces if p.name not in placed)
        yield ShownStacking(j, placed, tray)
