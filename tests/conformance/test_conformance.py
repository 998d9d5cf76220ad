"""One test over every level: the stored optimal plan, played through the state machine as an
agent plays it (its canonical text), reaches success in exactly ``optimal_steps`` steps.

The levels are every file under ``levels/``, the golden playthroughs' levels, and levels built
here from the piece sets and small hand-made puzzles (so the test means something whatever
``levels/`` holds).
"""

from __future__ import annotations

import pytest

from chaingeo.core.level import Level, PuzzleSolution, StackingSolution, load_levels
from chaingeo.envs.actions.parse import parse_action
from chaingeo.envs.actions.types import Action, PlaceAction, action_of_move
from chaingeo.envs.machines import new_state
from chaingeo.envs.machines.state import BaseState
from tests.support.env_levels import puzzle_levels, stacking_levels
from tests.support.paths import GOLDEN as GOLDEN_DIR
from tests.support.shipped import shipped

SHIPPED: list[Level] = shipped()
#: The golden playthroughs' levels (hand-made, and a generated six-piece burr in both goals).
GOLDEN: list[Level] = load_levels(GOLDEN_DIR / "levels")
#: Shipped assembly levels are checked against the full legal-action list only up to this many
#: pieces (a six-piece burr has ~40 000 insertions at the start, 0.25 s to list); every level
#: is replayed regardless, and the golden burr is checked in full.
ENUMERATE_UP_TO = 4


def all_levels() -> list[Level]:
    return [*SHIPPED, *GOLDEN, *stacking_levels(), *puzzle_levels()]


def oracle_actions(level: Level) -> list[Action]:
    """The stored plan as actions: ``place`` in the solution's order, or the stored moves."""
    sol = level.solution
    if isinstance(sol, StackingSolution):
        return [PlaceAction(n, sol.placements[n].cells) for n in sol.order]
    assert isinstance(sol, PuzzleSolution)
    return [action_of_move(m) for m in sol.moves]


def same_as_a_legal_action(state: BaseState, action: Action) -> bool:
    """``legal_actions`` lists one action per outcome: a finite move long enough to clear the
    rest is listed as its removal to infinity, so compare outcomes when the action is not
    listed itself."""
    legal = state.legal_actions()
    if action in legal:
        return True
    after = state.clone()
    after.apply(action)
    for other in legal:
        probe = state.clone()
        probe.apply(other)
        if probe.key() == after.key():
            return True
    return False


@pytest.mark.parametrize("level", all_levels(), ids=lambda lv: lv.id)
def test_optimal_plan_replays_through_agent_text(level: Level) -> None:
    state = new_state(level)
    enumerate_all = (
        level.goal != "assemble"
        or len(level.pieces) <= ENUMERATE_UP_TO
        or level.id not in {lv.id for lv in SHIPPED}
    )
    for i, action in enumerate(oracle_actions(level)):
        assert not state.is_success(), f"solved early, before step {i + 1}"
        text = action.to_text()
        resolved = parse_action(text, state)
        if enumerate_all:
            assert same_as_a_legal_action(state, resolved), text
        result = state.step_text(text)
        assert result.legal, f"step {i + 1} {text!r}: {result.feedback}"
        assert result.action == resolved
    assert state.is_success()
    assert state.steps_used == level.optimal_steps
    assert not state.is_truncated() or level.max_steps == level.optimal_steps


@pytest.mark.parametrize("level", all_levels(), ids=lambda lv: lv.id)
def test_optimal_plan_replays_through_apply_and_undoes(level: Level) -> None:
    state = new_state(level)
    start = state.key()
    for action in oracle_actions(level):
        state.apply(action)
    assert state.is_success() and state.steps_used == level.optimal_steps
    for _ in range(level.optimal_steps):
        state.pop()
    assert state.key() == start and state.steps_used == 0
