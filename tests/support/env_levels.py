"""Levels built in the tests: from the piece sets, by hand, and small random puzzles.

Puzzle plans are found here by breadth-first search over the disassembly state machine itself,
so they are optimal by construction; the assembly level of a puzzle stores that plan reversed
with every move inverted, as the format prescribes.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Hashable, Sequence
from functools import cache

from chaingeo.core.colors import assign_colors
from chaingeo.core.geometry import Cell, Shape, box_cells, puzzle_signature
from chaingeo.core.kinematics import Move, disassembly_of_assembly_plan
from chaingeo.core.level import (
    Level,
    Piece,
    Provenance,
    PuzzleSolution,
    default_step_budget,
    revalidate,
    stacking_level,
)
from chaingeo.core.piecesets import BEDLAM_SOLUTION, SOMA
from chaingeo.core.rules import PuzzleRules, StackingRules
from chaingeo.envs.actions.types import MoveAction
from chaingeo.envs.machines.puzzle import PuzzleState

# ---------------------------------------------------------------------------------------------
# Stacking
# ---------------------------------------------------------------------------------------------


def first_packing(pieces: Sequence[Shape], box: tuple[int, int, int]) -> list[Shape]:
    """The first exact packing found by plain backtracking (fill the smallest empty cell)."""
    cells = box_cells(box).cells
    inside = set(cells)
    # each orientation as offsets from its smallest cell, which goes on the smallest empty cell
    orients = [
        [
            tuple((x - o.cells[0][0], y - o.cells[0][1], z - o.cells[0][2]) for x, y, z in o.cells)
            for o in shape.orientations()
        ]
        for shape in pieces
    ]
    filled: set[Cell] = set()
    chosen: list[tuple[Cell, ...] | None] = [None] * len(pieces)

    def solve() -> bool:
        target = next((c for c in cells if c not in filled), None)
        if target is None:
            return True
        tx, ty, tz = target
        for i, opts in enumerate(orients):
            if chosen[i] is not None:
                continue
            for rel in opts:
                placed = tuple((tx + x, ty + y, tz + z) for x, y, z in rel)
                if all(c in inside and c not in filled for c in placed):
                    chosen[i] = placed
                    filled.update(placed)
                    if solve():
                        return True
                    filled.difference_update(placed)
                    chosen[i] = None
        return False

    if not solve():
        raise ValueError("no packing")
    return [Shape(c) for c in chosen if c is not None]


@cache
def soma_level() -> Level:
    handed = list(SOMA.pieces.values())[::-1]  # the tripod first: the search is instant
    placements = first_packing(handed, (3, 3, 3))
    return stacking_level("soma-test", "easy", (3, 3, 3), placements, handed=handed)


@cache
def bedlam_level() -> Level:
    return stacking_level("bedlam-test", "hard", (4, 4, 4), list(BEDLAM_SOLUTION.values()))


@cache
def drop_level() -> Level:
    """Two columns and a lid: under the drop rule the lid must go last."""
    placements = [
        Shape([(0, 0, 2), (1, 0, 2)]),
        Shape([(0, 0, 0), (0, 0, 1)]),
        Shape([(1, 0, 0), (1, 0, 1)]),
    ]
    return stacking_level("drop-test", "easy", (2, 1, 3), placements, rules=StackingRules("drop"))


@cache
def tiny_level() -> Level:
    """A 2x2x2 box from two L tricubes and a domino: small enough to enumerate."""
    placements = [
        Shape([(0, 0, 0), (1, 0, 0), (0, 1, 0)]),
        Shape([(1, 1, 0), (1, 1, 1)]),
        Shape([(0, 0, 1), (1, 0, 1), (0, 1, 1)]),
    ]
    return stacking_level("tiny-test", "easy", (2, 2, 2), placements)


def stacking_levels() -> list[Level]:
    return [tiny_level(), drop_level(), soma_level(), bedlam_level()]


# ---------------------------------------------------------------------------------------------
# Puzzles
# ---------------------------------------------------------------------------------------------

#: Three pieces: blue stops red moving +x, green lies on red and blue (as in test_level).
LOCK3 = {
    "red": Shape([(0, 0, 0), (1, 0, 0), (2, 0, 0)]),
    "blue": Shape([(0, 1, 0), (1, 1, 0), (2, 1, 0), (3, 1, 0), (3, 0, 0)]),
    "green": Shape([(0, 0, 1), (1, 0, 1), (2, 0, 1), (3, 0, 1)]),
}


def bfs_plan(
    shapes: dict[str, Shape], max_group: int | None = None, limit: int = 20000
) -> list[Move] | None:
    """An optimal disassembly (fewest moves) found by BFS over the state machine, or None."""
    level = puzzle_level("bfs-probe", shapes, [], "disassemble", max_group, check=False)
    start = PuzzleState(level)
    seen: dict[Hashable, tuple[Hashable, Move] | None] = {start.key(): None}
    queue = deque([start])
    while queue:
        state = queue.popleft()
        if state.is_success():
            plan: list[Move] = []
            k: Hashable = state.key()
            while seen[k] is not None:
                parent, move = seen[k]  # type: ignore[misc]
                plan.append(move)
                k = parent
            return plan[::-1]
        for action in state.legal_actions():
            if not isinstance(action, MoveAction):
                continue
            nxt = state.clone()
            nxt.apply(action)
            key = nxt.key()
            if key not in seen:
                seen[key] = (state.key(), action.move)
                queue.append(nxt)
                if len(seen) > limit:
                    return None
    return None


def puzzle_level(
    level_id: str,
    shapes: dict[str, Shape],
    disassembly: Sequence[Move],
    goal: str,
    max_group: int | None = None,
    check: bool = True,
) -> Level:
    """A puzzle level whose stored plan is ``disassembly`` (reversed and inverted to assemble)."""
    moves = (
        list(disassembly) if goal == "disassemble" else disassembly_of_assembly_plan(disassembly)
    )
    colors = {c.name: c.hex for c in assign_colors(48)}
    steps = len(moves)
    level = Level(
        id=level_id,
        family="puzzle",
        difficulty="easy",
        goal=goal,  # type: ignore[arg-type]
        box=None,
        pieces=tuple(Piece(n, colors[n], s) for n, s in shapes.items()),
        solution=PuzzleSolution(tuple(moves)),
        optimal_steps=steps,
        max_steps=default_step_budget(steps),
        rules=PuzzleRules(max_group),
        provenance=Provenance("tests", "1", None, None, puzzle_signature(shapes.values())),
    )
    return revalidate(level) if check else level


def tube(length: int, cubes: int) -> dict[str, Shape]:
    """A closed tube (blue) with a channel along x and a hole in its roof above the channel's
    far end; ``cubes`` single cubes (red, green, ...) sit in the channel from its near end.
    Each cube must slide along the channel to below the hole before it can leave upwards."""
    channel = [(x, 1, 1) for x in range(1, length + 1)]
    hole = (length, 1, 2)
    box = [(x, y, z) for x in range(length + 2) for y in range(3) for z in range(3)]
    names = [c.name for c in assign_colors(cubes + 4) if c.name != "blue"][:cubes]
    shapes = {"blue": Shape([c for c in box if c not in channel and c != hole])}
    for name, cell in zip(names, channel, strict=False):
        shapes[name] = Shape([cell])
    return shapes


@cache
def puzzle_levels() -> tuple[Level, ...]:
    levels: list[Level] = []
    hand = [
        ("lock3", LOCK3, None),
        ("lock3-single", LOCK3, 1),
        ("tube1", tube(2, 1), None),
        ("tube2", tube(3, 2), None),
        ("tube2-single", tube(3, 2), 1),
    ]
    plans: list[tuple[str, dict[str, Shape], list[Move], int | None]] = []
    for name, shapes, mg in hand:
        plan = bfs_plan(dict(shapes), mg)
        assert plan is not None
        plans.append((name, dict(shapes), plan, mg))
    # a stored plan may take a piece out by a finite move long enough to clear the rest
    plans.append(
        ("lock3-finite", dict(LOCK3), [Move(("green",), "+z", 3), Move(("red",), "-x", 4)], None)
    )
    for name, shapes, plan, mg in plans:
        for goal in ("disassemble", "assemble"):
            levels.append(puzzle_level(f"{name}-{goal}", shapes, plan, goal, mg))
    return tuple(levels)


def design_of(level: Level) -> str:
    """What a shipped puzzle level is made of: the generator's shape (``burr6``, ``cube4``, ...)
    or, for a level imported from CHAIN's models, ``chain/`` and the model's name."""
    source = level.stats.get("source")
    if isinstance(source, dict):
        return f"chain/{source['model']}"
    return str(level.stats["shape"])
