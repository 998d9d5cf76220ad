"""Hostile calls into the game doors (issue #37, items 7 and 12): a Gymnasium step either
applies its action or refuses it without consuming the step, and never raises on the agent's
action; the agent's text is bounded before the observation echoes it. Wrong call shapes are
typed errors (``reset(options='x')``), and a chat reply that is not a string reads as text."""

from __future__ import annotations

from typing import Any

import gymnasium
import pytest

from chaingeo.core.errors import ChainGeoError
from chaingeo.core.limits import MAX_OBSERVATION_CHARS
from chaingeo.envs.gym import ACTION_MAX_LENGTH, EnvError, PuzzleEnv, StackingEnv
from chaingeo.integrations.game import Game
from tests.support.env_levels import puzzle_levels, soma_level, tiny_level


def _env(family: str) -> StackingEnv | PuzzleEnv:
    if family == "stacking":
        return StackingEnv([tiny_level(), soma_level()], images=False)
    return PuzzleEnv(list(puzzle_levels()), images=False)


HOSTILE: list[Any] = [
    "x" * 100_000,
    "place red (1,1,1) " * 10_000,
    "x" * (ACTION_MAX_LENGTH + 1),
    None,
    5,
    b"finish",
    ["finish"],
    {"action": "finish"},
]


@pytest.mark.parametrize("family", ["stacking", "puzzle"])
@pytest.mark.parametrize("action", HOSTILE, ids=lambda a: type(a).__name__ + str(len(str(a))))
def test_an_action_outside_the_space_is_refused_without_using_the_step(
    family: str, action: Any
) -> None:
    env = _env(family)
    env.reset(seed=0)
    before = env.state.key(), env.state.steps_used
    obs, reward, terminated, _, info = env.step(action)
    assert (env.state.key(), env.state.steps_used) == before
    assert info["legal"] is False and info["error"] == "refused" and reward == 0.0
    assert not terminated and len(obs["text"]) <= MAX_OBSERVATION_CHARS
    for _ in range(5):  # the next steps are ordinary ones
        obs, _, terminated, _, info = env.step("nonsense")
        assert info["error"] == "unparseable" and len(obs["text"]) <= MAX_OBSERVATION_CHARS
        if terminated:
            break


def test_the_longest_action_of_the_space_echoes_within_the_observation_limit() -> None:
    env = StackingEnv([soma_level()], images=False, text_state=True, history_window=16)
    env.reset(seed=0)
    for _ in range(16):
        obs, *_ = env.step("(" * ACTION_MAX_LENGTH)
        assert len(obs["text"]) <= MAX_OBSERVATION_CHARS


def test_a_vector_environment_takes_hostile_actions() -> None:
    envs = gymnasium.vector.SyncVectorEnv([lambda: _env("stacking") for _ in range(2)])
    envs.reset(seed=1)
    _, _, _, _, info = envs.step(("x" * 100_000, "finish"))
    assert list(info["error"]) == ["refused", None] or info["error"][0] == "refused"
    envs.close()


@pytest.mark.parametrize("options", ["x", 5, ["level"], {"level": "nope"}, {"level": ["x"]}])
def test_bad_reset_options_are_a_typed_error(options: Any) -> None:
    env = _env("stacking")
    with pytest.raises(EnvError):
        env.reset(options=options)


def test_a_history_window_past_its_bound_is_refused() -> None:
    with pytest.raises(ChainGeoError):
        StackingEnv([tiny_level()], images=False, history_window=10_000)


@pytest.mark.parametrize(
    "reply",
    [["finish"], [{"type": "text", "text": "<action>finish</action>"}], None, 5, {"a": 1}],
)
def test_a_game_reply_that_is_not_a_string_reads_as_text(reply: Any) -> None:
    game = Game(tiny_level(), images=False)
    game.opening()
    game.answer(reply)
    assert game.outcome().actions == 1


def test_a_game_takes_malformed_tool_calls() -> None:
    game = Game(tiny_level(), images=False, tools=True)
    game.opening()
    out = game.answer("", [("id", "place"), 5, ("c", None, None)])  # type: ignore[list-item]
    assert out is None or out[-1]["role"] == "user"
