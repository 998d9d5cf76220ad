"""Puzzle questions from the blocking graphs: can-slide, first-move, blocks.

Every answer is read off :func:`chaingeo.solvers.graphs.blocking_graph` (edge ``a -> b``: a
unit step of ``a`` alone would hit ``b``); the wrong options are pieces of the same part that
are blocked, or groups that leave a blocker behind: legal-looking, one relation away.
"""

from __future__ import annotations

from collections.abc import Iterator

import networkx as nx
import numpy as np

from chaingeo.core.kinematics import DIRECTIONS, Assembly
from chaingeo.core.level import Level
from chaingeo.generator.questions.common import CATEGORIES, names_text, pick
from chaingeo.generator.questions.model import Option, Question, draft
from chaingeo.generator.questions.states import ShownPuzzle, puzzle_views
from chaingeo.solvers.graphs import blocking_graphs, closure, contact_graph, minimal_groups

#: Questions of one kind asked about one state, at most.
PER_STATE = 2
#: Puzzles with more pieces than this are asked about their last states only.
_BIG = 16

SLIDE = "slide one unit along {d} on its own (every other piece stays where it is)"


def _states(level: Level) -> Iterator[tuple[ShownPuzzle, dict[str, nx.DiGraph]]]:
    """The states every category asks about, with their blocking graphs: a puzzle's (a big
    one's last four only); none of a stacking level."""
    if level.family != "puzzle":
        return
    views = list(puzzle_views(level))
    for view in views[-4:] if len(level.pieces) > _BIG else views:
        yield view, blocking_graphs(view.state)


def _in_parts(state: Assembly) -> list[str]:
    return sorted(n for p in state.parts if len(p) > 1 for n in p)


def _free_and_stuck(
    rng: np.random.Generator, items: list[str], free: set[str]
) -> tuple[str, list[str]] | None:
    """One of ``items`` in ``free`` and three not, drawn in that order (None: too few)."""
    right = [i for i in items if i in free]
    wrong = [i for i in items if i not in free]
    if not right or len(wrong) < 3:
        return None
    return pick(rng, right, 1)[0], pick(rng, wrong, 3)


@CATEGORIES.register("can-slide")
def can_slide_questions(level: Level, rng: np.random.Generator) -> list[Question]:
    """Which piece can slide along D; along which direction can piece X slide."""
    out: list[Question] = []
    for view, graphs in _states(level):
        state = view.state
        names = _in_parts(state)
        for d in pick(rng, sorted(DIRECTIONS), PER_STATE):
            g = graphs[d]
            drawn = _free_and_stuck(rng, names, {n for n in names if g.out_degree(n) == 0})
            if drawn is None:
                continue
            right, wrong = drawn
            proof = {
                "kind": "piece",
                "direction": d,
                "blockers": {n: sorted(g.successors(n)) for n in sorted([right, *wrong])},
            }
            prompt = f"In the state shown, which of these pieces can {SLIDE.format(d=d)}?"
            answer, decoys = Option(right), [Option(w) for w in wrong]
            out.append(draft("can-slide", level, view.step, prompt, answer, decoys, proof))
        for x in pick(rng, names, PER_STATE):
            free = {d for d in DIRECTIONS if graphs[d].out_degree(x) == 0}
            drawn = _free_and_stuck(rng, sorted(DIRECTIONS), free)
            if drawn is None:
                continue
            right, wrong = drawn
            proof = {
                "kind": "direction",
                "piece": x,
                "blockers": {d: sorted(graphs[d].successors(x)) for d in sorted([right, *wrong])},
            }
            prompt = (
                f"In the state shown, along which of these directions can {x} slide one "
                "unit on its own (every other piece stays where it is)?"
            )
            answer, decoys = Option(right), [Option(w) for w in wrong]
            out.append(draft("can-slide", level, view.step, prompt, answer, decoys, proof))
    return out


def _group_option(pieces: tuple[str, ...] | list[str], d: str) -> Option:
    return Option(f"{names_text(pieces)} along {d}")


@CATEGORIES.register("first-move")
def first_move_questions(level: Level, rng: np.random.Generator) -> list[Question]:
    """Which piece or group can move now: a least movable group against groups that leave a
    blocker behind."""
    out: list[Question] = []
    for view, graphs in _states(level):
        state = view.state
        movable = [(grp, d) for d in sorted(DIRECTIONS) for grp in minimal_groups(graphs[d])]
        stuck: list[tuple[tuple[str, ...], str]] = []
        for d in sorted(DIRECTIONS):
            g = graphs[d]
            for n in _in_parts(state):
                if g.out_degree(n) > 0:
                    stuck.append(((n,), d))
            for grp in minimal_groups(g):
                if len(grp) > 1:
                    stuck.extend(((grp[:i] + grp[i + 1 :]), d) for i in range(len(grp)))
        stuck = sorted(set(s for s in stuck if closure(graphs[s[1]], s[0]) != frozenset(s[0])))
        if not movable or len(stuck) < 3:
            continue
        for right in pick(rng, movable, 1):
            wrong = pick(rng, stuck, 3)
            proof = {
                "options": [
                    {
                        "pieces": list(grp),
                        "direction": d,
                        "left_behind": sorted(closure(graphs[d], grp) - set(grp)),
                    }
                    for grp, d in [right, *wrong]
                ]
            }
            prompt = (
                "In the state shown, which of these pieces or groups can move now: slide "
                "one unit together along the direction given, every other piece staying "
                "where it is?"
            )
            answer, decoys = _group_option(*right), [_group_option(*w) for w in wrong]
            out.append(draft("first-move", level, view.step, prompt, answer, decoys, proof))
    return out


@CATEGORIES.register("blocks")
def blocks_questions(level: Level, rng: np.random.Generator) -> list[Question]:
    """Which piece stops X from sliding along D (X has exactly one blocker there)."""
    out: list[Question] = []
    for view, graphs in _states(level):
        state = view.state
        touching = contact_graph({n: state.cells_of(n) for n in _in_parts(state)}, floor=False)
        cases = [
            (x, d)
            for d in sorted(DIRECTIONS)
            for x in _in_parts(state)
            if graphs[d].out_degree(x) == 1
        ]
        for x, d in pick(rng, cases, PER_STATE):
            blocker = next(iter(graphs[d].successors(x)))
            others = sorted(state.part_of(x) - {x, blocker})
            near = [o for o in others if touching.has_edge(x, o)]
            far = [o for o in others if not touching.has_edge(x, o)]
            wrong_names = (pick(rng, near, 3) + pick(rng, far, 3))[:3]
            wrong = [Option(w) for w in wrong_names]
            if len(wrong) == 2:
                wrong.append(Option(f"nothing: {x} can slide along {d}"))
            if len(wrong) < 3:
                continue
            proof = {
                "piece": x,
                "direction": d,
                "blockers": [blocker],
                "options_blocking": {o: graphs[d].has_edge(x, o) for o in wrong_names},
            }
            prompt = (
                f"In the state shown, which piece stops {x} from sliding one unit along "
                f"{d} on its own?"
            )
            out.append(draft("blocks", level, view.step, prompt, Option(blocker), wrong, proof))
    return out
