"""Questions whose answer is a number: min-moves (breadth-first search over the state graph)
and count (pieces, cubes in a piece, empty cells of the box).

The four options are consecutive whole numbers around the answer, the window placed at random,
so neither the smallest nor the middle option is a safe guess.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from chaingeo.core.kinematics import Assembly, SearchLimitError
from chaingeo.core.level import Level
from chaingeo.generator.questions.common import CATEGORIES, jsonable, number_options, pick
from chaingeo.generator.questions.model import Question, draft
from chaingeo.generator.questions.states import puzzle_views, stacking_views
from chaingeo.solvers.analysis import level_max_group, level_turns
from chaingeo.solvers.graphs import piece_free, shortest_to

#: The breadth-first search of one question stops here (the question is then not asked).
MIN_MOVES_STATES = 600
#: States from the end of the solution that min-moves asks about, at most.
MIN_MOVES_VIEWS = 3
#: Pieces per state that min-moves asks to free, at most.
MIN_MOVES_PIECES = 2
_BIG = 16

MOVE_RULE = (
    "A move slides one piece or a group of pieces along one axis by any distance, or out of the "
    "puzzle; it counts as one move whatever the distance."
)
TURN_RULE = " A quarter turn of a piece or group is one move too."


def _rule(level: Level) -> str:
    return MOVE_RULE + (TURN_RULE if level_turns(level) else "")


def _bfs(
    level: Level, state: Assembly, goal: Callable[[Assembly], bool]
) -> dict[str, object] | None:
    try:
        found = shortest_to(state, goal, level_max_group(level), max_states=MIN_MOVES_STATES)
    except SearchLimitError:
        return None
    if found is None:
        return None
    moves, plan, seen = found
    return {"moves": moves, "plan": jsonable(plan), "states_searched": seen}


@CATEGORIES.register("min-moves")
def min_moves_questions(level: Level, rng: np.random.Generator) -> list[Question]:
    """The fewest moves to free one piece, or to take the whole puzzle apart, from a state
    near the end of the solution (small enough for a full breadth-first search)."""
    if level.family != "puzzle" or len(level.pieces) > _BIG or level_turns(level):
        return []  # turned states need the reference kinematics: too slow to search here
    out: list[Question] = []
    for view in list(puzzle_views(level))[-MIN_MOVES_VIEWS:]:
        goals: list[tuple[str, str, Callable[[Assembly], bool]]] = [
            ("apart", "take every piece apart from every other", Assembly.is_separated)
        ]
        stuck = sorted(n for p in view.state.parts if len(p) > 1 for n in p)
        for x in pick(rng, stuck, MIN_MOVES_PIECES):
            goals.append(
                (x, f"free {x} (take it out, apart from every other piece)", piece_free(x))
            )
        for target, words, goal in goals:
            proof = _bfs(level, view.state, goal)
            if proof is None:
                continue
            value = int(proof["moves"])  # type: ignore[call-overload]
            right, wrong, values = number_options(rng, value, 0, "move")
            proof = {"goal": target, **proof, "options": values}
            prompt = (
                f"From the state shown, what is the fewest number of moves needed to "
                f"{words}? {_rule(level)}"
            )
            out.append(draft("min-moves", level, view.step, prompt, right, wrong, proof))
    return out


@CATEGORIES.register("count")
def count_questions(level: Level, rng: np.random.Generator) -> list[Question]:
    """How many pieces; how many unit cubes in a piece; how many empty cells (stacking)."""
    out: list[Question] = []
    n = len(level.pieces)
    right, wrong, values = number_options(rng, n, 1, "piece")
    what = "the puzzle" if level.family == "puzzle" else "this level (in the box and the tray)"
    out.append(
        draft(
            "count",
            level,
            0,
            f"How many pieces does {what} have?",
            right,
            wrong,
            {"count": "pieces", "value": n, "options": values},
        )
    )
    for piece in pick(rng, list(level.pieces), 3):
        k = len(piece.shape)
        right, wrong, values = number_options(rng, k, 1, "cube")
        prompt = f"How many unit cubes make up the {piece.name} piece?"
        out.append(
            draft(
                "count",
                level,
                0,
                prompt,
                right,
                wrong,
                {"count": "cubes", "piece": piece.name, "value": k, "options": values},
            )
        )
    if level.family == "stacking":
        assert level.box is not None
        volume = level.box[0] * level.box[1] * level.box[2]
        for view in list(stacking_views(level))[1:]:
            empty = volume - sum(len(s) for s in view.placed.values())
            right, wrong, values = number_options(rng, empty, 1, "cell")
            prompt = "How many cells of the box are still empty in the state shown?"
            proof = {
                "count": "empty cells",
                "box": list(level.box),
                "value": empty,
                "filled": {k: len(s) for k, s in sorted(view.placed.items())},
                "options": values,
            }
            out.append(draft("count", level, view.step, prompt, right, wrong, proof))
    return out
