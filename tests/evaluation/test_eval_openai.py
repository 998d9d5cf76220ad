"""The OpenAI-compatible agent against a local fake server: request shape, usage, faults."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from chaingeo.core.geometry import Shape
from chaingeo.core.level import Level, stacking_level
from chaingeo.evaluation.agents.base import Agent, AgentError, AgentSpec, Reply, Turn
from chaingeo.evaluation.agents.http import ChatClient, RetryPolicy, parse_retry_after
from chaingeo.evaluation.agents.prompt import extract_action, extract_plan
from chaingeo.evaluation.agents.registry import AGENTS
from chaingeo.evaluation.episode import ProtocolConfig
from chaingeo.evaluation.runner import RunConfig, evaluate
from tests.support.fake_openai import Script, calls, fake_openai, reply
from tests.support.harness import (
    FAKE,
    GOOD_BODY,
    KEY,
    fake_prices,
    openai_spec,
)


def _level(level_id: str = "t1") -> Level:
    return stacking_level(level_id, "easy", (2, 1, 1), [Shape([(0, 0, 0)]), Shape([(1, 0, 0)])])


def _run(tmp_path: Path, script: Script, name: str = "run", **opts: object) -> list[dict[str, Any]]:
    script.expect_key = KEY
    with fake_openai(script) as url:
        evaluate(
            [_level()],
            openai_spec(url, **opts),
            tmp_path / name,
            FAKE,
            RunConfig(progress=False),
            fake_prices(tmp_path),
        )
    assert script.problems == []
    return [json.loads(x) for x in (tmp_path / name / "episodes.jsonl").read_text().splitlines()]


def test_request_shape_usage_cost_images_and_no_secrets(tmp_path: Path) -> None:
    script = Script(
        [
            reply("I start with red.\n<action>take red</action>", 1000, 200, reasoning=50),
            reply("<action>take green</action>", 3000, 100, cached=1000),
        ]
    )
    (rec,) = _run(tmp_path, script)
    assert rec["success"] and rec["steps_used"] == 2 and rec["status"] == "done"
    body = script.requests[0]["body"]
    assert body["model"] == "fake-model"
    assert body["temperature"] == 0.6 and body["top_p"] == 0.95
    parts = body["messages"][1]["content"]
    assert sum(p["type"] == "image_url" for p in parts) == 4  # four views
    assert "Take every piece" in parts[0]["text"] and "Steps left: 30" in parts[0]["text"]
    assert rec["usage"] == {
        "input_tokens": 4000,
        "output_tokens": 300,
        "reasoning_tokens": 50,
        "cached_tokens": 1000,
        "calls": 2,
    }
    assert rec["cost_usd"] == pytest.approx((4000 * 1.0 + 300 * 2.0) / 1e6)
    # Images are files named by their hash; the log holds names, never base64.
    names = set(rec["steps"][0]["images"].values())
    assert len(names) == 4
    assert all((tmp_path / "run" / "images" / n).exists() for n in names)
    for f in (tmp_path / "run").rglob("*"):
        if f.is_file() and f.suffix != ".png":
            text = f.read_text()
            assert KEY not in text and "base64" not in text


def test_faults_are_retried_with_backoff(tmp_path: Path) -> None:
    script = Script(
        [
            {"fault": "500"},
            {"fault": "429", "after": "0.2"},
            {"fault": "malformed"},
            {"fault": "timeout", "sleep": 0.8},
            {"fault": "drop"},
            reply("<action>take red</action>"),
            reply("<action>take green</action>"),
        ]
    )
    (rec,) = _run(tmp_path, script, timeout=0.4)
    assert rec["success"] and rec["steps_used"] == 2
    assert len(script.requests) == 7  # five faults, then two good answers
    assert rec["usage"]["calls"] == 2


def test_replies_without_an_action_cost_a_step_not_a_crash(tmp_path: Path) -> None:
    script = Script(
        [
            reply("I am not sure what to do."),
            reply("Let me think... <action>take re", fault="cutoff"),
            reply("<action>take blue</action>"),  # illegal: no such piece
            calls(("finish", "{not json"), text="calling the tool"),  # malformed: unparseable
            reply("<action>take red</action>"),
            reply("<action>take green</action>"),
        ]
    )
    (rec,) = _run(tmp_path, script)
    assert rec["success"] and rec["steps_used"] == 6
    notes = [s.get("note") for s in rec["steps"]]
    assert notes[0] == "your reply called no tool and had no <action>...</action>"
    assert notes[1] == "your reply was cut off before </action>"
    assert [s["legal"] for s in rec["steps"]] == [False, False, False, False, True, True]
    assert rec["invalid"] == 4 and rec["illegal"] == 1 and rec["unparseable"] == 3
    assert rec["steps"][3]["sent"].startswith("!malformed finish call: the arguments are not")
    assert rec["steps"][3]["calls"][0]["arguments"] == "{not json"
    offered = [t["function"]["name"] for t in script.requests[0]["body"]["tools"]]
    assert offered == ["place", "pickup", "state", "finish"]
    # The agent is told why its reply could not be read.
    second = script.requests[1]["body"]["messages"][1]["content"][0]["text"]
    assert "called no tool and had no <action>" in second
    # The malformed call was answered (the fake server checks the ids) with the reason.
    tool_msg = script.requests[4]["body"]["messages"][3]
    assert tool_msg["role"] == "tool" and "arguments are not usable JSON" in tool_msg["content"]


def test_giving_up_is_an_episode_error_and_resume_retries_it(tmp_path: Path) -> None:
    script = Script([{"fault": "500"}] * 3)
    (rec,) = _run(tmp_path, script, max_retries=2)
    assert rec["status"] == "error" and "giving up after 3 attempts" in rec["error"]
    assert not rec["success"]
    script = Script([reply("<action>take red</action>"), reply("<action>take green</action>")])
    script.expect_key = KEY
    with fake_openai(script) as url:
        out = evaluate(
            [_level()],
            openai_spec(url, max_retries=2),
            tmp_path / "run",
            FAKE,
            RunConfig(progress=False, resume=True, retry_errors=True),
            fake_prices(tmp_path),
        )
    assert [o.success for o in out] == [True]


def test_client_errors_fail_at_once_and_never_show_the_key(tmp_path: Path) -> None:
    script = Script([{"fault": "echo-key-401"}])
    with fake_openai(script) as url:
        client = ChatClient(url, KEY, retry=RetryPolicy(backoff_base=0.01))
        with pytest.raises(AgentError) as err:
            client.complete(GOOD_BODY)
    assert "401" in str(err.value) and KEY not in str(err.value)
    assert len(script.requests) == 1


def test_backoff_is_seeded_and_honours_retry_after() -> None:
    waits: list[list[float]] = []
    for _ in range(2):
        script = Script([{"fault": "500"}, {"fault": "429", "after": "3"}, reply("x")])
        slept: list[float] = []
        with fake_openai(script) as url:
            client = ChatClient(
                url, None, retry=RetryPolicy(backoff_base=0.5), seed=9, sleep=slept.append
            )
            client.complete(GOOD_BODY)
        assert 0 <= slept[0] <= 0.5 and slept[1] >= 3.0
        waits.append(slept)
    assert waits[0] == waits[1]
    assert parse_retry_after("Wed, 21 Oct 2015 07:28:00 GMT", now=1445412470.0) == pytest.approx(10)
    assert parse_retry_after("junk") is None


def test_action_and_plan_extraction() -> None:
    assert extract_action("a <action>x</action> then <ACTION> place red (1,1,1) </action>") == (
        "place red (1,1,1)",
        None,
    )
    assert extract_action("<action>  </action>")[0] is None
    assert extract_plan("<plan>\n1. take red\n- take green\n\n</plan>") == (
        ("take red", "take green"),
        None,
    )
    assert extract_plan("<action>a</action><action>b</action>") == (("a", "b"), None)
    assert extract_plan("<plan>take red")[1] == "your reply was cut off before </plan>"


def test_a_key_from_the_environment_is_scrubbed_from_logs(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("MY_KEY_VAR", KEY)
    script = Script(
        [reply(f"the key is {KEY} <action>take red</action>"), reply("<action>take green</action>")]
    )
    script.expect_key = KEY
    with fake_openai(script) as url:
        spec = AgentSpec("openai", {"model": "m", "base_url": url, "api_key_env": "MY_KEY_VAR"})
        evaluate([_level()], spec, tmp_path / "run", FAKE, RunConfig(progress=False))
    assert script.problems == []
    text = (tmp_path / "run" / "episodes.jsonl").read_text()
    assert KEY not in text and "the key is [REDACTED]" in text
    assert KEY not in (tmp_path / "run" / "header.json").read_text()


class _TwoWays(Agent):
    """Candidate 0 is illegal; 1 and 2 are the first and last legal 'take'."""

    name = "two-ways"
    needs_state = True
    uses_images = False

    def act(self, turn: Turn) -> Reply:
        assert turn.state is not None
        acts = [a.to_text() for a in turn.state.legal_actions() if a.to_text() != "finish"]
        text = ["take nobody", acts[0], acts[-1]][turn.candidate]
        return Reply(text, text)


def test_a_model_judge_picks_among_verified_candidates(tmp_path: Path) -> None:
    level = stacking_level(
        "t3", "easy", (3, 1, 1), [Shape([(0, 0, 0)]), Shape([(1, 0, 0)]), Shape([(2, 0, 0)])]
    )
    script = Script([reply("the last one <choice>2</choice>", 500, 10), reply("no idea", 400, 5)])
    with AGENTS.registered("two-ways", lambda spec: _TwoWays()), fake_openai(script) as url:
        proto = ProtocolConfig(
            candidates=3,
            judge="model",
            judge_options={"model": "fake-model", "base_url": url, "backoff_base": 0.01},
            env=FAKE.env,
        )
        evaluate([level], AgentSpec("two-ways"), tmp_path / "j", proto, RunConfig(progress=False))
    assert script.problems == [] and len(script.requests) == 2
    listing = script.requests[0]["body"]["messages"][1]["content"][-1]["text"]
    assert listing.startswith("Candidates:\n1. take ") and "take nobody" not in listing
    rec = json.loads((tmp_path / "j" / "episodes.jsonl").read_text())
    chosen = [[c["chosen"] for c in s["candidates"]] for s in rec["steps"]]
    # turn 1: the judge's choice (the last take); turn 2: no readable choice, verifier order;
    # turn 3: one distinct legal action left, no call
    assert chosen == [[False, False, True], [False, True, False], [False, True, False]]
    assert rec["success"] and rec["steps_used"] == 3
    assert rec["judge"] == {
        "model": "fake-model",
        "usage": {
            "input_tokens": 900,
            "output_tokens": 15,
            "reasoning_tokens": 0,
            "cached_tokens": 0,
            "calls": 2,
        },
    }
    assert rec["cost_usd"] is None  # fake-model has no price in the shipped table
    head = json.loads((tmp_path / "j" / "header.json").read_text())
    assert head["protocol"]["judge_options"] == {"model": "fake-model"}
