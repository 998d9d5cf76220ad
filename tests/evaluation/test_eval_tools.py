"""Native tool calling: the schemas offered, the translation of calls into action text, model
options passed through, and reasoning tokens read from every usage dialect."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path
from typing import Any, Literal

import pytest

from chaingeo.core.geometry import Shape
from chaingeo.core.level import Level, stacking_level
from chaingeo.core.rules import PuzzleRules
from chaingeo.envs.actions.parse import parse_text
from chaingeo.envs.actions.types import TurnRequest
from chaingeo.evaluation.agents.base import Agent, AgentSpec, Reply, ToolCall, Turn
from chaingeo.evaluation.agents.openai_chat import OpenAIAgent, provider_fields, tools_setting
from chaingeo.evaluation.agents.registry import AGENTS
from chaingeo.evaluation.agents.tools import (
    MALFORMED,
    parse_arguments,
    tool_specs,
    translate,
    turns_allowed,
)
from chaingeo.evaluation.episode import ProtocolConfig
from chaingeo.evaluation.runner import RunConfig, evaluate
from chaingeo.evaluation.usage import Usage
from tests.support.fake_env import FakeObservation, FakeResult


def _stacking() -> Level:
    return stacking_level("t1", "easy", (2, 1, 1), [Shape([(0, 0, 0)]), Shape([(1, 0, 0)])])


@dataclasses.dataclass(frozen=True)
class _TurningRules:
    max_group: int | None = None
    turns: bool = True


def _puzzle(goal: Literal["disassemble", "assemble"], rules: Any = None) -> Level:
    return dataclasses.replace(
        _stacking(), family="puzzle", goal=goal, box=None, rules=rules or PuzzleRules()
    )


def _names(tools: list[dict[str, Any]]) -> list[str]:
    return [t["function"]["name"] for t in tools]


def test_the_functions_offered_follow_the_level() -> None:
    assert _names(tool_specs(_stacking())) == ["place", "pickup", "state", "finish"]
    assert _names(tool_specs(_stacking(), state=False)) == ["place", "pickup", "finish"]
    dis = tool_specs(_puzzle("disassemble"))
    assert _names(dis) == ["move", "state", "finish"]
    assert "into" not in dis[0]["function"]["parameters"]["properties"]
    asm = tool_specs(_puzzle("assemble"))
    assert {"into", "offset"} <= set(asm[0]["function"]["parameters"]["properties"])
    # A rules field `turns` that is exactly True offers rotate.
    assert not turns_allowed(_puzzle("disassemble"))
    turning = _puzzle("disassemble", _TurningRules())
    assert turns_allowed(turning)
    assert _names(tool_specs(turning)) == ["move", "rotate", "state", "finish"]
    assert not turns_allowed(_puzzle("disassemble", _TurningRules(turns="yes")))  # type: ignore[arg-type]
    for tool in tool_specs(turning) + tool_specs(_stacking()):
        params = tool["function"]["parameters"]
        assert params["type"] == "object" and params["additionalProperties"] is False
        json.dumps(tool)  # plain JSON


STACK = tool_specs(_stacking())
ASM = tool_specs(_puzzle("assemble", _TurningRules()))


def _mv(**changes: Any) -> dict[str, Any]:
    return {"pieces": ["red"], "direction": "+x", "distance": 1, **changes}


def _rot(**changes: Any) -> dict[str, Any]:
    return {"pieces": ["red"], "axis": "z", "angle": 90, **changes}


def _cells(*cells: Any) -> str:
    return json.dumps({"piece": "red", "cells": list(cells)})


@pytest.mark.parametrize(
    ("name", "arguments", "offered", "text"),
    [
        ("place", _cells([1, 1, 1], [2, 1, 1]), STACK, "place red (1,1,1) (2,1,1)"),
        ("place", {"piece": "sky-blue", "cells": [[0, -1, 3]]}, STACK, "place sky-blue (0,-1,3)"),
        ("pickup", '{"piece": "red"}', STACK, "pickup red"),
        ("state", "{}", STACK, "state"),
        ("state", "", STACK, "state"),  # an empty argument string: no arguments
        ("finish", None, STACK, "finish"),
        ("move", json.dumps(_mv(pieces=["red", "blue"], direction="-z", distance="inf")), ASM,
         "move red+blue -z inf"),
        ("move", _mv(distance=2), ASM, "move red +x 2"),
        ("move", _mv(distance="inf", into=["blue", "green"], offset=[0, -1, 0]), ASM,
         "move red +x inf into blue+green offset (0,-1,0)"),
        ("rotate", _rot(pieces=["red", "blue"]), ASM, "rotate red+blue z +90"),
        ("rotate", _rot(angle=-90), ASM, "rotate red z -90"),
    ],
)  # fmt: skip
def test_calls_become_canonical_action_text(
    name: str, arguments: Any, offered: list[dict[str, Any]], text: str
) -> None:
    assert translate(name, arguments, offered).action == text
    assert translate(name, arguments, offered).problem is None


@pytest.mark.parametrize(
    ("name", "arguments", "offered", "why"),
    [
        ("jump", "{}", STACK, "there is no tool named 'jump' here"),
        ("move", json.dumps(_mv()), STACK, "there is no tool named 'move' here"),
        (["place"], "{}", STACK, "there is no tool named"),
        ("place", "{not json", STACK, "the arguments are not usable JSON: not valid JSON"),
        ("place", "[1, 2]", STACK, "the arguments are not a JSON object"),
        ("place", "\"__import__('os').system('x')\"", STACK, "not a JSON object"),
        ("place", '{"piece": "red"}', STACK, "missing field 'cells'"),
        ("place", '{"piece": "red", "cells": [], "why": 1}', STACK, "unexpected field 'why'"),
        ("place", '{"piece": "red blue", "cells": []}', STACK, "piece must be a colour name"),
        ("place", '{"piece": "red", "cells": [[1,1,1]); finish"}', STACK, "not usable JSON"),
        ("place", _cells([1, 1]), STACK, "cells[0] must be three integers"),
        ("place", _cells([1, 1, 1], [1, 1, True]), STACK, "cells[1] must be three"),
        ("place", _cells([1, 1, 1.5]), STACK, "cells[0] must be three"),
        ("place", '{"piece": "red", "cells": "(1,1,1)"}', STACK, "cells must be a non-empty list"),
        ("place", _cells(), STACK, "cells must be a non-empty list"),
        ("pickup", '{"piece": 3}', STACK, "piece must be a colour name, got '3'"),
        ("state", '{"verbose": true}', STACK, "unexpected field 'verbose'"),
        ("move", _mv(pieces="red"), ASM, "pieces must be a non-empty list"),
        ("move", _mv(pieces=[]), ASM, "pieces must be a non-empty list"),
        ("move", _mv(pieces=["red", "x y"]), ASM, "pieces[1] must be a colour name"),
        ("move", _mv(direction="x+"), ASM, "direction must be one of"),
        ("move", _mv(distance=0), ASM, "distance must be a positive"),
        ("move", _mv(distance=True), ASM, "distance must be"),
        ("move", _mv(distance="INF"), ASM, "distance must be"),
        ("move", _mv(distance="2"), ASM, "distance must be"),
        ("move", _mv(distance="inf", offset=[0, 0]), ASM, "offset must be"),
        ("rotate", _rot(angle=45), ASM, "angle must be one of 90, -90"),
        ("rotate", _rot(angle=180), ASM, "angle must be one of 90, -90"),
        ("rotate", _rot(angle="90"), ASM, "angle must be one of"),
        ("rotate", _rot(angle=90.0), ASM, "angle must be one of"),
        ("rotate", _rot(axis="w"), ASM, "axis must be one of x, y, z"),
    ],
)
def test_malformed_calls_become_unparseable_text_saying_why(
    name: Any, arguments: Any, offered: list[dict[str, Any]], why: str
) -> None:
    out = translate(name, arguments, offered)
    assert out.problem is not None and why in out.problem
    assert out.action.startswith(MALFORMED) and why in out.action
    assert "\n" not in out.action and len(out.action) < 200


def test_a_long_or_multiline_value_is_quoted_short_on_one_line() -> None:
    out = translate("pickup", {"piece": "x\n" * 500}, STACK)
    assert out.action.startswith("!malformed pickup call: piece must be a colour name, got 'x x")
    assert "\n" not in out.action and len(out.action) < 120
    assert parse_arguments("[" * 100_000) == "[" * 100_000  # too deep for json: refused, no crash
    refused = translate("pickup", "[" * 100_000, STACK)
    assert refused.problem == (
        "the arguments are not usable JSON: 100000 characters of JSON; at most 4096"
    )


def test_tools_setting_and_model_options() -> None:
    assert [tools_setting(v) for v in (None, True, False, "ON", "off", "auto")] == [
        "auto",
        "on",
        "off",
        "on",
        "off",
        "auto",
    ]
    with pytest.raises(ValueError, match="auto, on, off"):
        tools_setting("sometimes")
    fields = provider_fields(
        {"reasoning_effort": "high", "temperature": None, "extra_body": '{"top_k": 20}'}
    )
    assert fields == {"reasoning_effort": "high", "temperature": None, "top_k": 20}
    assert provider_fields({"extra_body": {"chat_template_kwargs": {"thinking": True}}}) == {
        "chat_template_kwargs": {"thinking": True}
    }
    for bad, why in [
        ({"model": "other"}, "sets 'model' itself"),
        ({"extra_body": '{"messages": []}'}, "sets 'messages' itself"),
        ({"stream": True}, "sets 'stream' itself"),
        ({"extra_body": "[1]"}, "extra_body must be a JSON object"),
        ({"extra_body": "{top_k: 20}"}, "extra_body is not JSON"),
        ({"x": float("nan")}, "must be JSON values"),
        ("reasoning_effort=high", "an object"),
    ]:
        with pytest.raises(ValueError, match=why):
            provider_fields(bad)


def test_the_body_carries_model_options_and_the_tool_history() -> None:
    agent = OpenAIAgent(
        {
            "model": "m",
            "base_url": "http://127.0.0.1:9/v1",
            "max_tokens": 100,
            "model_options": {
                "temperature": None,
                "max_tokens": 4096,
                "reasoning_effort": "high",
                "extra_body": '{"top_k": 20}',
            },
        },
        {},
    )
    level = _stacking()
    agent.start(level, 0)
    obs = FakeObservation("Do it.", {}, [], 30)
    body = agent._body("sys", Turn(level, obs, None, 0, 0), [])
    assert "temperature" not in body and body["top_p"] == 0.95
    assert body["max_tokens"] == 4096 and body["reasoning_effort"] == "high"
    assert body["top_k"] == 20 and body["tools"] == []
    # The next turn answers each call of the reply it committed, in order, by id.
    made = (
        ToolCall("a", "place", '{"piece": "red"}', "!malformed place call: missing field"),
        ToolCall("b", "finish", "{}", "finish"),
    )
    prev = Reply("", made[0].action, actions=("x", "finish"), calls=made)
    rejected = FakeResult(None, False, "unparseable", "Could not read it.", False, False)
    turn = Turn(level, obs, None, 1, 0, previous=prev, results=(rejected,))
    msgs = agent._body("sys", turn, [])["messages"]
    assert [m["role"] for m in msgs] == ["system", "user", "assistant", "tool", "tool", "user"]
    assert msgs[1]["content"].startswith("Do it.")
    assert msgs[2]["content"] is None and [c["id"] for c in msgs[2]["tool_calls"]] == ["a", "b"]
    assert msgs[3] == {"role": "tool", "tool_call_id": "a", "content": "Could not read it."}
    assert msgs[4]["tool_call_id"] == "b" and msgs[4]["content"].startswith(
        "Not executed: call 1 of this reply was rejected"
    )
    # Text mode stays one stateless request.
    text = agent._body("sys", turn, None)
    assert [m["role"] for m in text["messages"]] == ["system", "user"] and "tools" not in text


def test_reasoning_tokens_in_every_usage_dialect() -> None:
    chat = {
        "prompt_tokens": 10,
        "completion_tokens": 50,
        "completion_tokens_details": {"reasoning_tokens": 30},
        "prompt_tokens_details": {"cached_tokens": 4},
    }
    assert Usage.from_openai(chat) == Usage(10, 50, 30, 4, 1)
    responses = {
        "prompt_tokens": 10,
        "completion_tokens": 50,
        "output_tokens_details": {"reasoning_tokens": 7},
        "input_tokens_details": {"cached_tokens": 2},
    }
    assert Usage.from_openai(responses) == Usage(10, 50, 7, 2, 1)
    bare = {"prompt_tokens": 10, "completion_tokens": 50, "reasoning_tokens": 12}
    assert Usage.from_openai(bare) == Usage(10, 50, 12, 0, 1)
    assert Usage.from_openai({**bare, "completion_tokens_details": None}).reasoning_tokens == 12


class _Several(Agent):
    """Answers several actions a turn; candidate 0 always starts with an illegal one."""

    name = "several"
    uses_images = False

    def __init__(self) -> None:
        self.seen: list[tuple[int, Reply | None, list[bool]]] = []

    def act(self, turn: Turn) -> Reply:
        self.seen.append((turn.index, turn.previous, [r.legal for r in turn.results]))
        if turn.candidate == 0:
            return Reply("no", "take nobody", actions=("take nobody", "take red"))
        plan = [("take red", "take blue", "take green"), ("take green", "finish", "take red")]
        actions = plan[turn.index]
        return Reply(f"turn {turn.index}", actions[0], Usage(calls=1), actions=actions)


def test_several_actions_a_turn_stop_at_the_first_rejected(tmp_path: Path) -> None:
    agent = _Several()
    proto = ProtocolConfig(candidates=2, env="tests.support.fake_env")
    with AGENTS.registered("several", lambda spec: agent):
        run = AgentSpec("several")
        evaluate([_stacking()], run, tmp_path / "r", proto, RunConfig(progress=False))
    rec = json.loads((tmp_path / "r" / "episodes.jsonl").read_text())
    assert rec["success"] and rec["steps_used"] == 3 and not rec["finished"]
    assert [(s["turn"], s["sent"], s["legal"]) for s in rec["steps"]] == [
        (0, "take red", True),
        (0, "take blue", False),  # the judge committed candidate 1; take green never ran
        (1, "take green", True),  # solved: the finish after it is not taken
    ]
    assert rec["steps"][0]["candidates"][1]["actions"] == ["take red", "take blue", "take green"]
    assert rec["usage"]["calls"] == 2  # candidate 1 of each turn; steps after the first add none
    assert [s["usage"]["calls"] for s in rec["steps"]] == [1, 0, 1]
    # Turn 1 is handed the committed reply of turn 0 and what each executed action did.
    index, previous, legal = agent.seen[-1]
    assert index == 1 and previous is not None and previous.text == "turn 0"
    assert legal == [True, False]
    assert agent.seen[0][1:] == (None, [])


def test_rotate_calls_become_turns_the_parser_reads() -> None:
    """Levels whose rules allow turns offer ``rotate``; its calls read as the turn grammar."""
    offered = tool_specs(_puzzle("disassemble", PuzzleRules(turns=True)))
    assert "rotate" in _names(offered)
    for angle, quarter in ((90, 1), (-90, -1)):
        text = translate("rotate", json.dumps(_rot(angle=angle)), offered).action
        request = parse_text(text, "disassemble")
        assert isinstance(request, TurnRequest) and request.quarter == quarter
        assert request.axis == "z" and request.pieces == ("red",)
