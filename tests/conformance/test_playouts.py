"""Random playouts over every shipped level, OpenSpiel style: from the start, seeded random
legal actions, and at every state the contracts an agent and a search rely on: listed actions
are accepted (the one played and a seeded sample of the others), a clone has the same key and
stays independent, push / pop restores the key, the same actions from a fresh start reach the
same key (keys are stable, not tied to one object's history), an action's canonical text (what
an agent types) does exactly what the action does, and ``step_text`` never raises, whatever
the text."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from chaingeo.core.level import Level
from chaingeo.core.rules import PuzzleRules, StackingRules
from chaingeo.envs.actions.types import Action
from chaingeo.envs.machines import new_state
from chaingeo.envs.machines.state import BaseState
from tests.support.shipped import shipped

SHIPPED: list[Level] = shipped()
#: Steps of one playout, and the texts no state may raise on (odd, empty, hostile).
STEPS = 8
#: Listed actions checked for acceptance at each state besides the one played.
SAMPLED = 4
JUNK = ("", "   ", "place", "move ??? +x 1", "\x00\udcff", "move red +q 99999999999", "{" * 300)


def _playout(level: Level, seed: int) -> None:
    rng = np.random.default_rng(np.random.SeedSequence([seed, len(level.id)]))
    state = new_state(level)
    played: list[Action] = []
    for _ in range(STEPS):
        legal = state.legal_actions()
        if state.finished or len(legal) == 0:
            break
        for i in rng.choice(len(legal), size=min(SAMPLED, len(legal)), replace=False):
            assert state.problem(legal[int(i)]) is None, state.describe(legal[int(i)])
        action = legal[int(rng.integers(len(legal)))]
        assert state.problem(action) is None, state.describe(action)
        _check_clone_and_undo(state, action)
        _check_text_does_what_the_action_does(state, action)
        _check_junk_text(state, rng)
        state.apply(action)
        played.append(action)
    _check_stable_key(level, played, state)


def _check_clone_and_undo(state: BaseState, action: Action) -> None:
    before = state.key()
    twin = state.clone()
    assert twin.key() == before and hash(twin.key()) == hash(before)
    twin.push(action)
    assert state.key() == before  # the clone is independent
    twin.pop()
    assert twin.key() == before


def _check_stable_key(level: Level, played: list[Action], state: BaseState) -> None:
    again = new_state(level)
    for action in played:
        again.apply(action)
    assert again.key() == state.key() and hash(again.key()) == hash(state.key())


def _check_text_does_what_the_action_does(state: BaseState, action: Action) -> None:
    by_action, by_text = state.clone(), state.clone()
    by_action.apply(action)
    result = by_text.step_text(action.to_text())
    assert result.legal and result.error is None, result
    assert by_text.key() == by_action.key()


def _check_junk_text(state: BaseState, rng: np.random.Generator) -> None:
    probe = state.clone()
    text = JUNK[int(rng.integers(len(JUNK)))]
    probe.step_text(text)  # refused or counted, never an exception


@pytest.mark.parametrize("level", SHIPPED, ids=lambda lv: lv.id)
def test_random_playout_keeps_every_contract(level: Level) -> None:
    _playout(level, 2026)


def _variants() -> list[tuple[str, Level]]:
    """Rule variants the suite does not ship (every fifth level of a family, to keep it quick):
    stacking with pieces lowered straight down, and under CHAIN's own profile; puzzles moving
    one piece at a time, and with turns."""
    out: list[tuple[str, Level]] = []
    stacking = [lv for lv in SHIPPED if lv.family == "stacking"][::5]
    puzzles = [lv for lv in SHIPPED if lv.family == "puzzle" and len(lv.pieces) <= 12][::5]
    for lv in stacking:
        out.append(("drop", replace(lv, rules=StackingRules(support="drop"))))
        out.append(("chain", replace(lv, rules=StackingRules(profile="chain"))))
    for lv in puzzles:
        out.append(("single", replace(lv, rules=PuzzleRules(max_group=1))))
        if len(lv.pieces) <= 4:  # listing turns of a 6-8 piece burr takes 1-2.5 s a state
            out.append(("turns", replace(lv, rules=PuzzleRules(turns=True))))
    return out


@pytest.mark.parametrize(("variant", "level"), _variants(), ids=lambda v: getattr(v, "id", v))
def test_random_playout_under_other_rules(variant: str, level: Level) -> None:
    _playout(level, 7)
