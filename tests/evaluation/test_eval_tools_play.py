"""A model that answers only with tool calls plays whole levels through ``chain eval`` on the
real environments, against the fake server (which checks that every call is answered by id);
and a server that refuses tools is played in text instead."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

pytest.importorskip("chaingeo.envs.machines.state")

from chaingeo.cli.main import main
from chaingeo.core.colors import assign_colors
from chaingeo.core.geometry import Shape, puzzle_signature
from chaingeo.core.kinematics import Move
from chaingeo.core.level import (
    Level,
    Piece,
    Provenance,
    PuzzleSolution,
    revalidate,
    save_level,
    stacking_level,
)
from chaingeo.core.rules import PuzzleRules
from chaingeo.evaluation.agents.base import AgentSpec
from chaingeo.evaluation.agents.prompt import SYSTEM_PROMPT, TOOLS_PROMPT
from chaingeo.evaluation.episode import ProtocolConfig
from chaingeo.evaluation.runner import RunConfig, evaluate
from tests.support.fake_openai import REFUSAL, Script, calls, fake_openai, reply

KEY = "sk-tools-key-never-logged-42"


def _bars() -> Level:
    """Two bars side by side along y: slide green out along +y and they are apart."""
    colors = assign_colors(2)
    shapes = [Shape([(0, i, 0), (1, i, 0)]) for i in range(2)]
    level = Level(
        id="a-bars",
        family="puzzle",
        difficulty="easy",
        goal="disassemble",
        box=None,
        pieces=tuple(Piece(c.name, c.hex, s) for c, s in zip(colors, shapes, strict=True)),
        solution=PuzzleSolution((Move(("green",), "+y", None),)),
        optimal_steps=1,
        max_steps=30,
        rules=PuzzleRules(),
        provenance=Provenance("test", "1", None, None, puzzle_signature(shapes)),
    )
    return revalidate(level)


def _cubes() -> Level:
    """Three unit cubes (red, green, yellow) for a 3x1x1 box."""
    return stacking_level(
        "b-cubes", "easy", (3, 1, 1), [Shape([(0, 0, 0)]), Shape([(1, 0, 0)]), Shape([(2, 0, 0)])]
    )


def _suite(tmp_path: Path) -> Path:
    folder = tmp_path / "levels"
    for level in (_bars(), _cubes()):
        save_level(level, folder / f"{level.id}.json")
    return folder


def _place(piece: str, *cells: list[int]) -> tuple[str, dict[str, Any]]:
    return ("place", {"piece": piece, "cells": list(cells)})


def _records(run: Path) -> dict[str, dict[str, Any]]:
    lines = (run / "episodes.jsonl").read_text().splitlines()
    return {json.loads(x)["level_id"]: json.loads(x) for x in lines}


def _eval(url: str, levels: Path, out: Path, *extra: str) -> int:
    args = ["eval", "--levels", str(levels), "--agent", "openai", "--model", "fake"]
    args += ["--base-url", url, "--api-key-env", "TOOLS_TEST_KEY", "--out", str(out)]
    return main([*args, "--no-progress", "--agent-option", "backoff_base=0.01", *extra])


def test_a_model_plays_whole_levels_with_tool_calls_only(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.setenv("TOOLS_TEST_KEY", KEY)
    script = Script(
        [
            # a-bars (disassembly): look at the state (a step, whatever the parser makes of it),
            # then slide green out.
            calls(("state", "{}"), reasoning=40),
            calls(("move", {"pieces": ["green"], "direction": "+y", "distance": "inf"})),
            # b-cubes: three calls; the second collides, so the third is not executed.
            calls(
                _place("red", [1, 1, 1]),
                _place("green", [1, 1, 1]),
                _place("yellow", [3, 1, 1]),
                text="Left to right.",
                new_episode=True,
                reasoning=25,
            ),
            calls(("place", '{"piece": "green", "cells": [[2, 1]]}')),  # malformed
            # The level is solved by the second call: the finish after it is never taken.
            calls(_place("green", [2, 1, 1]), _place("yellow", [3, 1, 1]), ("finish", "{}")),
        ]
    )
    script.expect_key = KEY
    out = tmp_path / "runs"
    with fake_openai(script) as url:
        code = _eval(
            url,
            _suite(tmp_path),
            out,
            "--tools",
            "--model-option",
            "reasoning_effort=high",
            "--model-option",
            'extra_body={"top_k": 20}',
        )
    assert script.problems == []  # every request answered the last calls, by id and in order
    assert code == 0
    assert "| fake | 100.0 [" in capsys.readouterr().out
    bodies = [r["body"] for r in script.requests]
    assert len(bodies) == 5
    assert all(b["reasoning_effort"] == "high" and b["top_k"] == 20 for b in bodies)
    assert all(b["messages"][0]["content"] == TOOLS_PROMPT for b in bodies)
    assert [t["function"]["name"] for t in bodies[0]["tools"]] == ["move", "state", "finish"]
    assert [t["function"]["name"] for t in bodies[2]["tools"]] == [
        "place",
        "pickup",
        "state",
        "finish",
    ]
    # The turn after the three calls gets one result per call: done, rejected, not executed.
    history = bodies[3]["messages"]
    roles = ["system", "user", "assistant", "tool", "tool", "tool", "user"]
    assert [m["role"] for m in history] == roles
    assert history[2]["content"] == "Left to right."
    results = [m["content"] for m in history[3:6]]
    assert "red" in results[0] and "collision" in results[1]
    assert results[2].startswith("Not executed: call 2 of this reply was rejected")
    assert "three integers" in bodies[4]["messages"][3]["content"]

    recs = _records(out / "fake-interactive")
    bars, cubes = recs["a-bars"], recs["b-cubes"]
    assert bars["success"] and bars["steps_used"] == 2
    assert [s["sent"] for s in bars["steps"]] == ["state", "move green +y inf"]
    assert cubes["success"] and cubes["steps_used"] == 5 and not cubes["finished"]
    assert [s["sent"] for s in cubes["steps"]] == [
        "place red (1,1,1)",
        "place green (1,1,1)",
        "!malformed place call: cells[0] must be three integers [x, y, z]",
        "place green (2,1,1)",
        "place yellow (3,1,1)",
    ]
    assert [s["turn"] for s in cubes["steps"]] == [0, 0, 1, 2, 2]
    assert [s["legal"] for s in cubes["steps"]] == [True, False, False, True, True]
    assert [s["error"] for s in cubes["steps"]] == [None, "illegal", "unparseable", None, None]
    assert [s["call"] for s in cubes["steps"]] == [0, 1, 0, 0, 1]
    # The turn's first step lists every call of the reply, the skipped one too.
    first = cubes["steps"][0]["calls"]
    assert [c["id"] for c in first] == ["call_3_0", "call_3_1", "call_3_2"]
    assert first[2] == {
        "id": "call_3_2",
        "name": "place",
        "arguments": '{"piece": "yellow", "cells": [[3, 1, 1]]}',
        "action": "place yellow (3,1,1)",
    }
    assert "calls" not in cubes["steps"][1]
    assert cubes["steps"][0]["reply"] == "Left to right." and cubes["steps"][1]["reply"] == ""
    # Usage is the reply's, on its first step only; reasoning tokens are recorded.
    assert [s["usage"]["calls"] for s in cubes["steps"]] == [1, 0, 1, 1, 0]
    assert cubes["usage"]["calls"] == 3 and cubes["usage"]["reasoning_tokens"] == 25
    assert bars["usage"]["reasoning_tokens"] == 40
    assert sum(s["usage"]["output_tokens"] for s in cubes["steps"]) == 60
    assert bars["agent_notes"] == cubes["agent_notes"] == {"tool_mode": "native"}
    head = json.loads((out / "fake-interactive" / "header.json").read_text())
    assert head["agent"]["options"]["tools"] == "on"
    assert head["agent"]["options"]["model_options"] == {
        "reasoning_effort": "high",
        "extra_body": {"top_k": 20},
    }
    for f in out.rglob("*"):
        if f.is_file() and f.suffix != ".png":
            assert KEY not in f.read_text()


def test_a_server_refusing_tools_is_played_in_text_said_once_per_run(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    script = Script(
        [
            reply("<action>move green +y inf</action>"),
            reply("<action>place green (2,1,1)</action>"),
            reply("<action>place red (1,1,1)</action>"),
            reply("<action>place yellow (3,1,1)</action>"),
        ],
        refuse_tools=True,
    )
    out = tmp_path / "runs"
    with fake_openai(script) as url:
        assert _eval(url, _suite(tmp_path), out) == 0  # tools=auto, the default
    assert script.problems == []
    printed = capsys.readouterr().out
    assert printed.count("NOTE:") == 1
    assert "fake-interactive: the server refused tools" in printed
    assert "2 episode(s) played with text actions instead" in printed
    # Each episode asks with tools once, is refused, then asks the same turn in text.
    offered = ["tools" in r["body"] for r in script.requests]
    assert offered == [True, False, True, False, False, False]
    assert script.requests[1]["body"]["messages"][0]["content"] == SYSTEM_PROMPT
    recs = _records(out / "fake-interactive")
    for rec in recs.values():
        assert rec["success"] and rec["steps_used"] == rec["optimal_steps"]
        assert rec["usage"]["calls"] == rec["steps_used"]  # a refusal costs no tokens
        assert rec["agent_notes"]["tool_mode"] == "text"
        assert REFUSAL in rec["agent_notes"]["tools_refused"]
        assert rec["agent_notes"]["tools_refused"].startswith("HTTP 400")


def test_tools_on_with_a_refusing_server_is_an_episode_error(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    script = Script([], refuse_tools=True)
    levels = tmp_path / "one"
    save_level(_cubes(), levels / "b-cubes.json")
    with fake_openai(script) as url:
        assert _eval(url, levels, tmp_path / "runs", "--tools", "on") == 1
    (rec,) = _records(tmp_path / "runs" / "fake-interactive").values()
    assert rec["status"] == "error" and "HTTP 400" in rec["error"] and REFUSAL in rec["error"]
    assert len(script.requests) == 1  # a refusal is not retried
    assert "WARNING: 1 episode(s) errored" in capsys.readouterr().out


def test_a_oneshot_plan_of_tool_calls(tmp_path: Path) -> None:
    plan = calls(
        _place("green", [2, 1, 1]),
        _place("red", [1, 1, 1]),
        _place("blue", [3, 1, 1]),  # no such piece: fails, and the open loop goes on
        _place("yellow", [3, 1, 1]),
        ("finish", "{}"),
    )
    script = Script([plan])
    with fake_openai(script) as url:
        spec = AgentSpec("openai", {"model": "m", "base_url": url, "images": False})
        evaluate(
            [_cubes()],
            spec,
            tmp_path / "run",
            ProtocolConfig(name="oneshot"),
            RunConfig(progress=False),
        )
    assert script.problems == []
    body = script.requests[0]["body"]
    assert [t["function"]["name"] for t in body["tools"]] == ["place", "pickup", "finish"]
    (rec,) = _records(tmp_path / "run").values()
    assert rec["success"] and rec["steps_used"] == 4
    assert rec["plan"]["actions"][2] == "place blue (3,1,1)"
    assert [c["name"] for c in rec["plan"]["calls"]] == ["place"] * 4 + ["finish"]


def test_bad_model_options_are_a_usage_error(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    levels = tmp_path / "one"
    save_level(_cubes(), levels / "b-cubes.json")
    for option, why in [
        ("model=other", "the agent sets 'model' itself"),
        ("extra_body=[1]", "extra_body must be a JSON object"),
        ("reasoning_effort", "expected KEY=VALUE"),
    ]:
        code = _eval("http://127.0.0.1:9/v1", levels, tmp_path / "runs", "--model-option", option)
        assert code == 2
        assert why in capsys.readouterr().err
    assert not (tmp_path / "runs").exists()
