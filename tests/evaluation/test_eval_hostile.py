"""A hostile model server against the harness (issue #21, items 1-8 and 12): each test plays one
attack from the fake server (tests/support) and checks that the run goes on, the episode is
recorded as what it is (the model's step or the server's error), no key leaves its origin and
the logs stay bounded. Deadlines are short (1-2 s) and every script is fixed, so each test is
seeded and quick."""

from __future__ import annotations

import json
import re
import socket
import time
from pathlib import Path
from typing import Any

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from chaingeo.core import limits
from chaingeo.evaluation.agents.base import AgentError
from chaingeo.evaluation.agents.http import ChatClient, RetryPolicy
from chaingeo.evaluation.agents.prompt import extract_action, extract_plan
from chaingeo.evaluation.hostile_server import Served, serve
from chaingeo.evaluation.report.tables import load_run
from chaingeo.evaluation.runner import RunConfig, evaluate
from chaingeo.evaluation.sanitize import bound_record, clean, size
from chaingeo.evaluation.usage import Price, PriceError, PriceTable, Usage
from tests.support.fake_openai import Script, calls, fake_openai, reply
from tests.support.harness import (
    FAKE,
    GOOD_BODY,
    KEY,
    chain_eval,
    fake_levels,
    fake_prices,
    openai_args,
    openai_spec,
    suite_folder,
)

FAST = {"max_retries": 0, "backoff_base": 0.001, "timeout": 2.0}


def _play(tmp_path: Path, entries: list[dict[str, Any]], levels: int = 1, **opts: Any) -> list[Any]:
    """Run the fake server's ``entries`` over ``levels`` episodes; every record, in order."""
    script = Script(entries, expect_key=KEY)
    with fake_openai(script) as url:
        evaluate(
            fake_levels(levels),
            openai_spec(url, **{**FAST, **opts}),
            tmp_path / "run",
            FAKE,
            RunConfig(progress=False),
            fake_prices(tmp_path),
        )
    assert script.problems == []
    lines = (tmp_path / "run" / "episodes.jsonl").read_text("utf-8").splitlines()
    return [json.loads(x) for x in lines]


# 1 --------------------------------------------------------------------------- lone surrogates


def test_lone_surrogates_in_a_reply_or_a_tool_name_are_logged_and_the_run_goes_on(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.delenv("OPENAI_API_KEY", raising=False)
    script = Script([reply("\ud800 <action>finish</action>"), calls(("\udfff", "{}"))])
    with fake_openai(script) as url:
        assert chain_eval(suite_folder(tmp_path, 2), tmp_path / "out", *openai_args(url)) == 0
    assert script.problems == []
    text = (tmp_path / "out" / "fake-interactive" / "episodes.jsonl").read_text("utf-8")
    recs = [json.loads(x) for x in text.splitlines()]
    assert [r["status"] for r in recs] == ["done", "done"]  # neither stopped the run
    assert recs[0]["steps"][0]["reply"] == "\ufffd <action>finish</action>"
    assert recs[1]["steps"][0]["calls"][0]["name"] == "\ufffd"
    assert recs[1]["steps"][0]["error"] == "unparseable"  # the model's bad call, a step


# 2 ---------------------------------------------------------------------------- huge usage


@pytest.mark.parametrize("tokens", [10**400, 1e308, -5, "12"])
def test_usage_out_of_bounds_is_a_recorded_server_error_never_an_overflow(
    tmp_path: Path, tokens: Any
) -> None:
    bad = reply("<action>take red</action>", raw_usage={"prompt_tokens": tokens})
    recs = _play(tmp_path, [bad], levels=2)  # the second episode plays on
    assert [r["status"] for r in recs] == ["error", "done"]
    assert recs[0]["error_type"] == "ProtocolError"
    why = "digits" if tokens == 10**400 else "usage.prompt_tokens"  # refused while parsing
    assert why in recs[0]["error"] and recs[0]["cost_usd"] == 0.0
    assert load_run(tmp_path / "run").errors == 1  # reports count it like any server error


def test_costs_are_finite_whatever_the_counts_and_prices(tmp_path: Path) -> None:
    huge = Usage(2**80, 2**80, 0, 2**81)
    assert 0 < Price(1e6, 1e6).cost(huge) < float("inf")
    for value in ("Infinity", "NaN", "1" + "0" * 5000, "-1", "1e7"):
        f = tmp_path / "p.json"
        f.write_text('{"models": {"m": {"input": ' + value + ', "output": 1}}}')
        with pytest.raises(PriceError, match=r"p\.json"):
            PriceTable.load(f)


# 3 -------------------------------------------------------- tool-call arguments past the limits


def test_tool_call_arguments_past_the_limits_are_the_models_unparseable_step(
    tmp_path: Path,
) -> None:
    def place(number: str) -> dict[str, Any]:
        return calls(("place", '{"piece": "red", "cells": [[' + number + ", 1, 1]]}"))

    done = reply("<action>finish</action>")
    recs = _play(tmp_path, [place("9" * 5000), done, place("9" * 50)], levels=2, tools="on")
    assert [r["status"] for r in recs] == ["done", "done"]
    first, second = recs[0]["steps"][0], recs[1]["steps"][0]
    assert first["error"] == second["error"] == "unparseable"
    assert f"at most {limits.MAX_TOOL_ARGUMENT_CHARS}" in first["sent"]
    assert f"more than {limits.MAX_AGENT_DIGITS} digits" in second["sent"]


def test_arguments_a_server_sent_decoded_obey_the_same_limits() -> None:
    from chaingeo.evaluation.agents.tools import tool_specs, translate

    offered = tool_specs(fake_levels(1)[0])
    huge = translate("place", {"piece": "red", "cells": [[10**15, 1, 1]]}, offered)
    assert huge.problem is not None and "digits" in huge.problem
    wide = translate("place", {"piece": "red", "cells": [[1, 1, 1]] * 2000}, offered)
    assert wide.problem is not None and f"at most {limits.MAX_TOOL_ARGUMENT_CHARS}" in wide.problem
    assert translate("place", {"piece": "red", "cells": [[1, 1, 1]]}, offered).problem is None


# 4 ------------------------------------------------------------------ linear action extraction


def test_action_extraction_is_linear_and_bounded() -> None:
    for text in ("<action>" * 20_000, "<plan><action>" * 12_000, "</action><action>" * 10_000):
        started = time.perf_counter()
        extract_action(text)
        extract_plan(text)
        assert time.perf_counter() - started < 0.5
    assert extract_action("<action>" * 20_000) == (None, "your reply was cut off before </action>")
    long = "x" * limits.MAX_REPLY_CHARS + "<action>take red</action>"
    action, note = extract_action(long)
    assert action is None and note is not None and f"at most {limits.MAX_REPLY_CHARS}" in note


_OLD_ACTION = re.compile(r"<action>(.*?)</action>", re.IGNORECASE | re.DOTALL)


@settings(max_examples=300, deadline=None, derandomize=True)
@given(
    st.lists(st.sampled_from(["<action>", "</ACTION>", "<Action>", "</action>", "a", " ", "\n"]))
)
def test_action_extraction_reads_what_the_regular_expression_read(parts: list[str]) -> None:
    text = "".join(parts)
    found = [" ".join(x.split()) for x in _OLD_ACTION.findall(text)]
    action, _ = extract_action(text)
    assert action == (found[-1] if found and found[-1] else None)
    plan, _ = extract_plan(text)
    assert plan == tuple(a for a in found if a)


# 5 ------------------------------------------------------------- deadlines and Retry-After


def test_a_trickling_server_cannot_hold_a_call_past_its_deadline() -> None:
    script = Script([{"fault": "trickle", "interval": 0.2, "seconds": 8}])
    with fake_openai(script) as url:
        client = ChatClient(url, KEY, timeout=1.0, retry=RetryPolicy(max_retries=0))
        started = time.monotonic()
        with pytest.raises(AgentError, match="no complete answer within 1s"):
            client.complete(GOOD_BODY)
        assert time.monotonic() - started < 2.0


def test_retry_after_is_capped_and_all_retries_share_one_budget() -> None:
    day = {"fault": "retry-after", "after": "86400"}
    for budget, expect_waits, succeeds in ((900.0, [60.0, 60.0], True), (100.0, [60.0], False)):
        slept: list[float] = []
        script = Script([day, day, reply("x")])
        with fake_openai(script) as url:
            policy = RetryPolicy(max_retries=3, backoff_base=0.01, budget=budget)
            client = ChatClient(url, KEY, retry=policy, sleep=slept.append)
            if succeeds:
                client.complete(GOOD_BODY)
            else:
                with pytest.raises(AgentError, match="retry budget"):
                    client.complete(GOOD_BODY)
        assert slept == expect_waits


# 6 ------------------------------------------------------------------------------ redirects


def test_a_redirect_to_another_port_is_not_followed_and_the_key_never_goes_there() -> None:
    seen = Served()
    with serve([reply("<action>take red</action>")] * 3, seen) as elsewhere:
        script = Script([{"fault": "redirect", "location": f"{elsewhere}/chat/completions"}])
        with fake_openai(script) as url:
            client = ChatClient(url, KEY, retry=RetryPolicy(max_retries=2, backoff_base=0.01))
            with pytest.raises(AgentError, match="redirect to another origin") as err:
                client.complete(GOOD_BODY)
    assert seen.headers == []  # never contacted, so no key and no answer taken from there
    assert KEY not in str(err.value) and len(script.requests) == 1  # not retried either


def test_a_same_origin_307_is_followed_with_the_key() -> None:
    script = Script(
        [{"fault": "redirect", "status": 307, "location": "/v1/chat/completions"}, reply("ok")],
        expect_key=KEY,
    )
    with fake_openai(script) as url:
        answer = ChatClient(url, KEY).complete(GOOD_BODY)
    assert answer["choices"][0]["message"]["content"] == "ok"
    assert script.problems == [] and len(script.requests) == 2


def test_the_environments_proxy_is_used_for_a_remote_server_as_urllib_did(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    seen = Served()
    with serve([reply("via the proxy")], seen) as proxy:
        monkeypatch.setenv("HTTP_PROXY", proxy.removesuffix("/v1"))
        monkeypatch.delenv("NO_PROXY", raising=False)
        answer = ChatClient("http://models.example.invalid/v1", KEY).complete(GOOD_BODY)
    assert answer["choices"][0]["message"]["content"] == "via the proxy"
    assert [h["Host"] for h in seen.headers] == ["models.example.invalid"]


# 7 ---------------------------------------------------------------------------- log budgets


def test_run_logs_stay_within_their_byte_budgets(tmp_path: Path) -> None:
    image = "data:image/png;base64," + "iVBOR" + "A" * 4_000_000
    junk = [reply("no action here " + "z" * 400_000) for _ in range(12)]
    many = calls(*[("pickup", {"piece": "q" * 3000})] * 300)
    entries = [reply(f"look {image} <action>take red</action>"), *junk, many]
    recs = _play(tmp_path, entries, levels=2, tools="on")
    size = (tmp_path / "run" / "episodes.jsonl").stat().st_size
    assert [r["status"] for r in recs] == ["done", "done"]
    assert size < 2 * limits.MAX_LOG_EPISODE_BYTES
    for rec in recs:
        for step in rec["steps"]:
            assert len(json.dumps(step, ensure_ascii=False).encode()) <= limits.MAX_LOG_REPLY_BYTES
    first = recs[0]["steps"][0]["reply"]
    assert "AAAAAAAA" not in first and "[4000005 characters, sha256 " in first
    assert "truncated: 400015 characters, sha256 " in recs[0]["steps"][1]["reply"]
    called = [s for s in recs[0]["steps"] if "calls" in s]
    assert len(called) == 1 and len(called[0]["calls"]) == limits.MAX_TOOL_CALLS


def test_an_episode_past_its_budget_keeps_only_the_outcome_of_later_steps() -> None:
    step = {"turn": 0, "reply": "r" * 60_000, "sent": "x", "action": None, "legal": False}
    step["images"] = {"iso": "f" * 64 + ".png"}
    record = {
        "key": "L#0",
        "cost_usd": float("nan"),
        "steps": [{**step, "error": "unparseable"}] * 400,
    }
    out = bound_record(record)
    assert size(out) <= limits.MAX_LOG_EPISODE_BYTES + limits.MAX_LOG_REPLY_BYTES
    assert out["cost_usd"] is None and 0 < out["log_compacted_steps"] < 400
    last = out["steps"][-1]
    assert last["compacted"] and last["error"] == "unparseable" and "reply" not in last
    assert "sha256" in out["steps"][0]["reply"] and len(out["steps"]) == 400
    assert out["steps"][-1]["images"] == {"iso": "f" * 64 + ".png"}  # still names its picture


def test_a_key_is_redacted_before_any_cut_so_no_part_of_it_stays() -> None:
    cap = limits.MAX_LOG_FIELD_CHARS
    text = "a" * (cap - 5) + KEY + "\ud800"
    out = clean(text, cap, lambda t: t.replace(KEY, "[REDACTED]"))
    assert KEY[:5] not in out and "\ud800" not in out and out.startswith("a" * (cap - 5) + "[REDA")


# 8 ------------------------------------------------------------------------- protocol breaks


@pytest.mark.parametrize(
    "answer",
    [
        {"choices": [1]},
        {"choices": [{"message": "hi"}]},
        {"choices": [{"message": {"content": 5}}]},
        {"choices": [{"message": {"content": None}, "finish_reason": "stop"}]},
        {"choices": [{"message": {"content": {"text": "<action>finish</action>"}}}]},
    ],
)
def test_protocol_breaks_are_server_errors_not_the_models_steps(
    tmp_path: Path, answer: dict[str, Any]
) -> None:
    recs = _play(tmp_path, [{"fault": "answer", "answer": answer}], levels=2)
    assert [r["status"] for r in recs] == ["error", "done"]
    assert recs[0]["error_type"] == "ProtocolError" and recs[0]["steps"] == []
    assert load_run(tmp_path / "run").errors == 1


def test_a_reply_cut_off_by_max_tokens_is_still_the_models_step(tmp_path: Path) -> None:
    (rec,) = _play(tmp_path, [{"fault": "cutoff", "reply": ""}])
    assert rec["status"] == "done" and rec["steps"][0]["error"] == "unparseable"


# 12 ---------------------------------------------------------------- reasons on the console


def test_chain_eval_prints_each_distinct_error_reason_with_its_count(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.delenv("OPENAI_API_KEY", raising=False)
    with socket.socket() as s:  # a port with nobody listening: the server is down
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    down = openai_args(f"http://127.0.0.1:{port}/v1")
    fast = ["--agent-option", "max_retries=0"]
    assert chain_eval(suite_folder(tmp_path, 2), tmp_path / "out", *down, *fast) == 1
    lines = capsys.readouterr().out.splitlines()
    reasons = [x for x in lines if x.startswith("  2 x ")]
    assert len(reasons) == 1 and "connection failed" in reasons[0], lines


# ------------------------------------------------------------------ chain bench robustness


def test_the_benchs_tool_call_and_server_fault_classes_find_nothing() -> None:
    from chaingeo.benchmarks.robustness import tool_call_fuzz
    from chaingeo.evaluation.drills import fault_table, server_fault_rows

    calls = tool_call_fuzz(40)
    assert calls["other_exceptions"] == calls["contract_violations"] == 0
    assert calls["calls"]["malformed"] > 0 and calls["calls"]["translated"] > 0
    rows = server_fault_rows(["302 to another port", "lone surrogate as a tool name"])
    assert [(r["crash"], r["hang"], r["leak"], r["episodes"]) for r in rows] == [(0, 0, 0, 2)] * 2
    assert [r["server_errors"] for r in rows] == [0, 2]  # the model's bad call; the redirect
    assert "| **all** | 2 attacks | 4 |" in fault_table(rows)
