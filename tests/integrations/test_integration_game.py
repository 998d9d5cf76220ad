"""The chat game behind the training integrations (no framework needed): the shipped levels
played through chat messages, and the rewards read off their outcomes."""

from __future__ import annotations

import base64
import json
from functools import cache

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from chaingeo.core import limits
from chaingeo.core.level import Level
from chaingeo.evaluation.agents.baselines import oracle_plan
from chaingeo.evaluation.agents.tools import skipped_result, translate
from chaingeo.evaluation.episode import Outcome
from chaingeo.integrations.game import Game, Protocol, efficiency_reward, recent
from chaingeo.integrations.game import total_reward as total
from tests.support.plans import place_calls
from tests.support.shipped import shipped


@cache
def stacking() -> tuple[Level, ...]:
    return tuple(shipped("stacking"))


def play(game: Game, replies: list[str]) -> int:
    """Answer with ``replies`` until the game ends; the number of replies it took."""
    for n, text in enumerate(replies, 1):
        if game.answer(text) is None:
            return n
    return len(replies)


def images_of(message: dict[str, object]) -> list[bytes]:
    parts = message["content"]
    assert isinstance(parts, list)
    prefix = "data:image/png;base64,"
    urls = [p["image_url"]["url"] for p in parts if p["type"] == "image_url"]
    assert all(u.startswith(prefix) for u in urls)
    return [base64.b64decode(u[len(prefix) :]) for u in urls]


@settings(max_examples=15, deadline=None)
@given(st.data())
def test_wasted_turns_cost_efficiency_not_success(data: st.DataObject) -> None:
    """Each ``state`` turn before the optimal plan is a legal step that changes nothing: the
    level is still solved, every reply was readable, and efficiency is 1 - NormDist."""
    level = data.draw(st.sampled_from(stacking()))
    plan = oracle_plan(level)
    wasted = data.draw(st.integers(0, level.max_steps - len(plan)))
    game = Game(level, images=False)
    assert images_of(game.opening()) == []
    texts = ["I look first. <action>state</action>"] * wasted
    texts += [f"<action>{a}</action>" for a in plan]
    assert play(game, texts) == len(texts)
    o = game.outcome()
    assert (o.success, o.steps, o.actions, o.readable) == (True, len(texts), len(texts), len(texts))
    want = max(0.0, 1 - wasted / max(1, level.optimal_steps))
    assert efficiency_reward(o) == pytest.approx(want)
    assert total(o) == pytest.approx(0.5 + 0.4 * want + 0.1)
    assert (total(o) == pytest.approx(1.0)) == (wasted == 0)


@settings(max_examples=10, deadline=None)
@given(level=st.sampled_from(stacking()), text=st.text(max_size=60))
def test_nonsense_scores_zero_and_spends_the_budget(level: Level, text: str) -> None:
    """Replies with no action tag are unreadable steps: the budget runs out, nothing scores."""
    game = Game(level, images=False)
    game.opening()
    reply = text.replace("<", "(")  # never an action tag
    assert play(game, [reply] * level.max_steps) == level.max_steps
    o = game.outcome()
    assert (o.success, o.truncated, o.steps, o.readable) == (False, True, level.max_steps, 0)
    assert total(o) == 0.0
    with pytest.raises(RuntimeError):
        game.answer("<action>finish</action>")


@pytest.mark.parametrize("images", [True, False])
def test_oneshot_runs_one_plan_on_one_view(images: bool) -> None:
    level = stacking()[0]
    game = Game(level, "oneshot", images=images)
    shown = images_of(game.opening())
    # the one scene view and the tray of pieces, as PNG files
    assert len(shown) == (2 if images else 0)
    assert all(png.startswith(b"\x89PNG") for png in shown)
    plan = "\n".join(f"{i}. {a}" for i, a in enumerate(oracle_plan(level), 1))
    assert game.answer(f"My plan:\n<plan>\n{plan}\n</plan>") is None
    assert total(game.outcome()) == pytest.approx(1.0)
    nothing = Game(level, "oneshot", images=False)
    assert nothing.answer("I give up.") is None
    o = nothing.outcome()
    assert (o.steps, o.actions, total(o)) == (0, 1, 0.0)


def test_interactive_turns_show_the_views_and_the_feedback() -> None:
    level = stacking()[0]
    game = Game(level)
    assert len(images_of(game.opening())) >= 4  # front, side, top, iso (and the tray)
    nxt = game.answer("no tags here")
    assert nxt is not None
    first = nxt[-1]["content"][0]["text"]
    assert "Feedback on your last reply: no <action>" in first
    assert f"Steps left: {level.max_steps - 1}" in first


def test_an_unknown_protocol_or_outcome_is_refused() -> None:
    with pytest.raises(ValueError, match="protocol"):
        Game(stacking()[0], "telepathy")  # type: ignore[arg-type]
    assert Outcome.from_json({"level_id": "x"}) is None
    assert Outcome.from_json(None) is None
    assert total(None) == 0.0


def test_a_puzzle_is_played_the_same_way() -> None:
    level = next(lv for lv in shipped("puzzle") if lv.difficulty == "easy")
    game = Game(level, images=False)
    game.opening()
    plan = oracle_plan(level)
    assert play(game, [f"<action>{a}</action>" for a in plan]) == len(plan)
    assert total(game.outcome()) == pytest.approx(1.0)


def as_calls(made: list[tuple[str, dict[str, object]]]) -> list[tuple[str, str, str]]:
    return [(f"call_{i}", name, json.dumps(args)) for i, (name, args) in enumerate(made)]


@settings(max_examples=10, deadline=None)
@given(level=st.sampled_from(stacking()), protocol=st.sampled_from(["interactive", "oneshot"]))
def test_the_optimal_plan_as_tool_calls(level: Level, protocol: Protocol) -> None:
    """One reply calling every action of the plan solves the level, in both protocols; the
    calls read as the very text of the plan."""
    made = place_calls(level)
    game = Game(level, protocol, images=False, tools=True)
    assert [t["function"]["name"] for t in game.tools][-1] == "finish"
    assert [translate(n, a, game.tools).action for _, n, a in as_calls(made)] == oracle_plan(level)
    game.opening()
    assert game.answer("", as_calls(made)) is None
    assert total(game.outcome()) == pytest.approx(1.0)


def test_calls_stop_at_the_first_rejected_one_and_each_gets_a_result() -> None:
    level = next(lv for lv in stacking() if len(lv.pieces) >= 3)
    first, *rest = place_calls(level)
    clash = (rest[0][0], {**rest[0][1], "cells": first[1]["cells"]})  # where the first one is
    game = Game(level, images=False, tools=True)
    game.opening()
    made = as_calls([first, clash, rest[1]])
    nxt = game.answer("Three at once.", made)
    assert nxt is not None
    tool, _, skipped, _ = nxt
    assert [m["role"] for m in nxt] == ["tool", "tool", "tool", "user"]
    assert [m["tool_call_id"] for m in nxt[:3]] == [c[0] for c in made]
    assert tool["content"].startswith("OK")
    assert skipped["content"] == skipped_result(1)
    o = game.outcome()
    assert (o.steps, o.actions, o.readable) == (2, 2, 2)  # the third call was never played
    # text is still read when a reply calls nothing, and a malformed call is unreadable
    assert game.answer("<action>state</action>") is not None
    assert game.answer("", [("c", "place", '{"piece": 3}')]) is not None
    assert (game.outcome().actions, game.outcome().readable) == (4, 3)


def test_recent_keeps_the_latest_observation_and_the_last_tool_exchange() -> None:
    level = stacking()[0]
    game = Game(level, tools=True)
    said = [game.opening()]
    said.append({"role": "assistant", "content": "<action>state</action>"})
    nxt = game.answer("<action>state</action>")
    assert nxt is not None
    said += nxt
    assert recent(said) == said[-1:]  # a text reply: the new observation says what it did
    made = as_calls(place_calls(level)[:1])
    said.append({"role": "assistant", "content": None, "tool_calls": made})
    nxt = game.answer("", made)
    assert nxt is not None
    said += nxt
    shown = recent(said)
    assert [m["role"] for m in shown] == ["user", "assistant", "tool", "user"]
    assert shown[1:] == said[-3:]
    # the observation the calls answered, without its pictures
    assert [p["type"] for p in shown[0]["content"]] == ["text"]
    assert shown[0]["content"][0] == said[2]["content"][0]
    assert len(images_of(said[2])) >= 4 and len(images_of(shown[-1])) >= 4


def test_every_call_is_answered_even_past_the_limit() -> None:
    """A rejected first call skips the rest, and each of them, past the limit too, is
    answered (the chat protocol wants it); only the first was played."""
    level = stacking()[0]
    game = Game(level, images=False, tools=True)
    game.opening()
    unplaced = json.dumps({"piece": level.pieces[0].name})
    made = [(f"c{i}", "pickup", unplaced) for i in range(limits.MAX_TOOL_CALLS + 3)]
    nxt = game.answer("", made)
    assert nxt is not None
    assert [m.get("tool_call_id") for m in nxt[:-1]] == [c[0] for c in made]
    assert nxt[1]["content"] == skipped_result(0)
    assert game.outcome().steps == 1
