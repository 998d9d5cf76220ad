"""Two doors, one episode: ``chain eval``'s loop (an agent asked turn by turn) and the chat game
behind verifiers (replies pushed in from outside) play the same scripted model replies and must
end with the same :class:`~chaingeo.evaluation.episode.Outcome`, field for field."""

from __future__ import annotations

import random
from functools import cache

import pytest

from chaingeo.core.level import Level
from chaingeo.evaluation.agents.base import Agent, AgentSpec, Reply, Turn
from chaingeo.evaluation.agents.baselines import oracle_plan
from chaingeo.evaluation.agents.dialects import read_reply
from chaingeo.evaluation.agents.registry import AGENTS
from chaingeo.evaluation.episode import Outcome, ProtocolConfig
from chaingeo.evaluation.play import EpisodeTask, run_episode
from chaingeo.integrations.game import Game
from tests.support.shipped import shipped

#: What a model might write besides its plan: no tag, an empty tag, nonsense, a wasted turn.
NOISE = (
    "Let me look at the pieces first.",
    "<action></action>",
    "<action>fly red to the moon</action>",
    "I will check. <action>state</action>",
)


@cache
def levels() -> tuple[Level, ...]:
    """Small levels of both families (their plans are short; 36-piece burrs are left out)."""
    puzzles = [lv for lv in shipped("puzzle") if len(lv.pieces) <= 6][:3]
    return (*shipped("stacking")[:3], *puzzles)


def script(level: Level, seed: int) -> list[str]:
    """The level's optimal plan as tagged replies with seeded noise between them."""
    rng = random.Random(seed)
    out: list[str] = []
    for action in oracle_plan(level):
        out += rng.sample(NOISE, rng.randint(0, 2))
        out.append(f"Next: <action>{action}</action>")
    return out


class Scripted(Agent):
    """A model that answers with the next reply of its script (``finish`` when it runs out)."""

    name = "scripted"
    uses_images = False

    def __init__(self, replies: list[str]) -> None:
        self.replies = list(replies)

    def act(self, turn: Turn) -> Reply:
        text = self.replies.pop(0) if self.replies else "<action>finish</action>"
        return read_reply("text", text)


def through_chain_eval(level: Level, replies: list[str]) -> Outcome:
    with AGENTS.registered("scripted-test", lambda spec: Scripted(replies)):
        task = EpisodeTask(level, 0, 0, AgentSpec("scripted-test"), ProtocolConfig())
        result = run_episode(task)
    assert result.record["status"] == "done", result.record.get("error")
    return Outcome.from_record(result.record)


def through_the_game(level: Level, replies: list[str]) -> Outcome:
    game = Game(level, images=False)
    game.opening()
    todo = list(replies)
    while True:
        text = todo.pop(0) if todo else "<action>finish</action>"
        if game.answer(text) is None:
            return game.outcome()


@pytest.mark.parametrize("seed", [0, 1])
@pytest.mark.parametrize("index", range(6))
def test_both_doors_give_the_same_outcome(index: int, seed: int) -> None:
    level = levels()[index]
    replies = script(level, seed)
    a, b = through_chain_eval(level, replies), through_the_game(level, replies)
    assert a.success and a.steps == len(replies) >= level.optimal_steps
    for field in ("level_id", "optimal_steps", "success", "steps", "actions", "readable"):
        assert getattr(a, field) == getattr(b, field), field
    assert (a.finished, a.truncated) == (b.finished, b.truncated)
