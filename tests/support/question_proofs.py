"""Re-proving a question's answer by a route independent of the generator: the state is
replayed through the environment's state machine from the option texts alone, moves come from
the reference kinematics (:mod:`chaingeo.core.kinematics`), fewest moves from a plain
breadth-first search over them, placements from the stacking machine's own rules, and packings
from the naive exact-cover counter of :mod:`tests.support.cover_reference`.

Each ``truth_*`` returns, per option, whether it is a right answer; a question is proven when
exactly its answer letter is."""

from __future__ import annotations

import re
from collections.abc import Callable
from typing import Any

import numpy as np

from chaingeo.core.geometry import SYMMETRIES, Cell, box_cells
from chaingeo.core.kinematics import Assembly, legal_steps, state_key
from chaingeo.core.level import Level, StackingSolution
from chaingeo.envs.actions.types import PlaceAction
from chaingeo.envs.demos import plan_texts
from chaingeo.envs.machines import new_state
from chaingeo.envs.machines.puzzle import PuzzleState
from chaingeo.envs.machines.stacking import StackingState
from chaingeo.generator.questions import Question
from chaingeo.solvers.analysis import level_max_group, level_turns
from tests.support import cover_reference

Truth = list[bool]


def replayed(level: Level, step: int) -> PuzzleState | StackingState:
    state = new_state(level)
    for text in plan_texts(level)[:step]:
        state.step_text(text)
    assert isinstance(state, PuzzleState | StackingState)
    return state


def _moves_alone(asm: Assembly, pieces: list[str], d: str) -> bool:
    part = asm.part_of(pieces[0])
    if len(part) < 2 or set(pieces) == part or not set(pieces) <= part:
        return False
    return asm.free_distance(pieces, d) != 0


def truth_can_slide(q: Question, asm: Assembly) -> Truth:
    texts = [o.text for o in q.options]
    if q.proof["kind"] == "piece":
        return [_moves_alone(asm, [t], str(q.proof["direction"])) for t in texts]
    return [_moves_alone(asm, [str(q.proof["piece"])], t) for t in texts]


def truth_first_move(q: Question, asm: Assembly) -> Truth:
    out = []
    for o in q.options:
        group, d = re.fullmatch(r"(\S+) along ([+-][xyz])", o.text).groups()  # type: ignore[union-attr]
        out.append(_moves_alone(asm, group.split("+"), d))
    return out


def truth_blocks(q: Question, asm: Assembly) -> Truth:
    """Right: the only piece whose removal lets X step (X blocked with it there)."""
    x, d = re.search(r"stops (\S+) from sliding one unit along ([+-][xyz])", q.prompt).groups()  # type: ignore[union-attr]
    blocked = not _moves_alone(asm, [x], d)
    out = []
    for o in q.options:
        if o.text.startswith("nothing"):
            out.append(not blocked)
            continue
        rest = {n: asm.shapes[n] for n in asm.part_of(x) if n != o.text}
        without = Assembly(
            rest,
            {n: asm.offsets[n] for n in rest},
            (frozenset(rest),),
            {n: r for n, r in asm.rotations.items() if n in rest},
        )
        out.append(blocked and without.free_distance([x], d) != 0)
    return out


def reference_bfs(
    level: Level, start: Assembly, goal: Callable[[Assembly], bool], cap: int = 20_000
) -> int:
    """Fewest moves to ``goal`` by plain breadth-first search on the reference kinematics."""
    seen = {state_key(start)}
    layer, depth = [start], 0
    while layer:
        if any(goal(s) for s in layer):
            return depth
        depth += 1
        nxt = []
        for s in layer:
            for m in legal_steps(s, level_max_group(level), level_turns(level)):
                c = s.apply(m)
                k = state_key(c)
                if k not in seen:
                    seen.add(k)
                    nxt.append(c)
        assert len(seen) < cap, "reference BFS too large for a test"
        layer = nxt
    raise AssertionError("goal unreachable")


def truth_min_moves(q: Question, level: Level, asm: Assembly) -> Truth:
    goal_piece = re.search(r"needed to free (\S+) ", q.prompt)
    if goal_piece:
        name = goal_piece.group(1)
        value = reference_bfs(level, asm, lambda s: len(s.part_of(name)) == 1)
    else:
        value = reference_bfs(level, asm, Assembly.is_separated)
    return [int(o.text.split()[0]) == value for o in q.options]


def truth_placement(q: Question, state: StackingState) -> Truth:
    """fits: inside the box and on empty cells; supported: the machine accepts it."""
    name = q.options[0].text.split()[0]
    occupied = state.occupied()
    box = state.box
    out = []
    for o in q.options:
        assert o.cells is not None
        inside = all(0 <= c[i] < box[i] for c in o.cells for i in range(3))
        fits = inside and not any(c in occupied for c in o.cells)
        if q.category == "fits":
            out.append(fits)
        else:
            out.append(fits and state.problem(PlaceAction(name, o.cells)) is None)
    return out


def truth_cover(q: Question, level: Level, state: StackingState) -> Truth:
    """completes: the naive counter finds a packing of the rest; dead-end: it finds none."""
    name = q.options[0].text.split()[0]
    filled = set(state.occupied())
    out = []
    for o in q.options:
        assert o.cells is not None and level.box is not None
        assert state.problem(PlaceAction(name, o.cells)) is None  # every option is legal
        empty = frozenset(box_cells(level.box).cell_set - filled - set(o.cells))
        rest = [level.piece(n).shape for n in state.tray if n != name]
        shapes: dict[frozenset[tuple[int, int, int]], int] = {}
        for s in rest:
            key = s.canonical().cell_set
            shapes[key] = shapes.get(key, 0) + 1
        pieces = [(k, n, n) for k, n in shapes.items()]
        ok = sum(len(s) for s in rest) == len(empty) and bool(
            cover_reference.solutions(pieces, empty)
        )
        out.append(ok if q.category == "completes" else not ok)
    return out


def truth_count(q: Question, level: Level, state: PuzzleState | StackingState) -> Truth:
    m = re.search(r"make up the (\S+) piece", q.prompt)
    if m:
        value = len(level.piece(m.group(1)).shape)
    elif "empty" in q.prompt:
        assert isinstance(state, StackingState)
        value = state.empty_cells()
    else:
        value = len(level.pieces)
    return [int(o.text.split()[0]) == value for o in q.options]


def _coloured(level: Level, recipe: dict[str, Any]) -> frozenset[tuple[str, Cell]]:
    """The recipe applied to the solved level by hand: matrices on cell arrays, normalised."""
    sol = level.solution
    where = {
        p.name: np.array(
            sol.placements[p.name].cells if isinstance(sol, StackingSolution) else p.shape.cells
        )
        for p in level.pieces
    }
    if recipe.get("mirror"):
        where = {n: a * np.array([-1, 1, 1]) for n, a in where.items()}
    if "shift" in recipe:
        name, shift = recipe["shift"]
        where[name] = where[name] + np.array(shift)
    if "swap" in recipe:
        first, second = recipe["swap"]
        where[first], where[second] = where[second], where[first]
    r = SYMMETRIES[int(recipe["rotation"])]
    where = {n: a @ r.T for n, a in where.items()}
    lo = np.min(np.concatenate(list(where.values())), axis=0)
    out: set[tuple[str, Cell]] = set()
    for n, arr in where.items():
        for c in arr - lo:
            out.add((n, (int(c[0]), int(c[1]), int(c[2]))))
    return frozenset(out)


def truth_same_assembly(q: Question, level: Level) -> Truth:
    """Right: some proper rotation of the solved level gives exactly the option's cells."""
    from chaingeo.generator.questions.views import recipes

    out = []
    for recipe in recipes(q):
        target = _coloured(level, dict(recipe))
        out.append(any(_coloured(level, {"rotation": r}) == target for r in range(24)))
    return out


def truth(q: Question, level: Level) -> Truth:
    """Which options are right, decided without the generator."""
    if q.category == "same-assembly":
        return truth_same_assembly(q, level)
    state = replayed(level, q.step)
    if isinstance(state, StackingState):
        if q.category in ("fits", "supported"):
            return truth_placement(q, state)
        if q.category in ("completes", "dead-end"):
            return truth_cover(q, level, state)
        return truth_count(q, level, state)
    asm = state.assembly
    table: dict[str, Callable[[], Truth]] = {
        "can-slide": lambda: truth_can_slide(q, asm),
        "first-move": lambda: truth_first_move(q, asm),
        "blocks": lambda: truth_blocks(q, asm),
        "min-moves": lambda: truth_min_moves(q, level, asm),
        "count": lambda: truth_count(q, level, state),
    }
    return table[q.category]()
