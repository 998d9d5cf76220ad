"""``chain serve`` through OpenEnv's own client (``GenericEnvClient``, WebSocket sessions)
against a real server on 127.0.0.1: the oracle plans of shipped levels played to success, a
turn level, refused requests that leave the session as it was, 32 sessions at once."""

from __future__ import annotations

import asyncio
import json
from collections.abc import Iterator
from typing import Any

import pytest

pytest.importorskip("openenv", reason="chain serve needs the serve extra (openenv-core)")

from openenv.core.generic_client import GenericEnvClient

from chaingeo.core.suite import shipped_level
from chaingeo.envs.demos import plan_texts
from chaingeo.evaluation.agents.tools import tool_specs
from chaingeo.integrations.serve.environment import Catalog
from tests.support.serve import get, post, running

PUZZLE = "puzzle-easy-07-burr3"
TURNS = "puzzle-easy-01-luban-3-piece"
STACKING = "stacking-2x2x3-easy-s103-000000"
MORE = ("puzzle-easy-02-luban-6-piece", "stacking-2x3x3-easy-s107-000000")
IDS = (PUZZLE, TURNS, STACKING, *MORE)
BAD_RESETS: list[dict[str, Any]] = [
    {"level": "nope"},
    {"level": PUZZLE, "images": "yes"},
    {"level": PUZZLE, "history": -1},
    {"level": PUZZLE, "colour": 1},
    {"level": PUZZLE, "seed": -4},
    {"level": PUZZLE, "participant": "p"},
    {"level": PUZZLE, "dialect": "klingon"},
]


@pytest.fixture(scope="module")
def url() -> Iterator[str]:
    catalog = Catalog({i: shipped_level(i) for i in IDS})
    with running(catalog, max_sessions=40) as base:
        yield base


def _client(url: str) -> GenericEnvClient:
    return GenericEnvClient(base_url=url, message_timeout_s=180)


async def _play_plan(url: str, level_id: str, **options: Any) -> list[dict[str, Any]]:
    """Reset and play the stored optimal plan; every observation, in order."""
    async with _client(url) as env:
        first = await env.reset(level=level_id, seed=3, **options)
        seen = [first.observation | {"done": first.done, "reward": first.reward}]
        for text in plan_texts(shipped_level(level_id)):
            r = await env.step({"text": text})
            seen.append(r.observation | {"done": r.done, "reward": r.reward})
        state = await env.state()
        seen.append({"state": state})
        return seen


@pytest.mark.parametrize("level_id", [PUZZLE, STACKING, TURNS])
def test_oracle_plan_reaches_success(url: str, level_id: str) -> None:
    seen = asyncio.run(_play_plan(url, level_id, legal=True))
    level = shipped_level(level_id)
    first, last, state = seen[0], seen[-2], seen[-1]["state"]
    assert first["steps"] == 0 and not first["done"] and first["feedback"] is None
    assert first["legal"] and first["legal"][-1] == "finish"
    assert all(not s["done"] for s in seen[1:-2])
    assert last["done"] and last["success"] and last["steps"] == level.optimal_steps
    assert last["optimal_steps"] == level.optimal_steps
    assert last["last"]["legal"] and last["reward"] == pytest.approx(1.0)
    assert state["level_id"] == level_id and state["steps"] == level.optimal_steps
    assert state["success"] and state["key"]


def test_tool_calls_and_images(url: str) -> None:
    """A tool call plays like its action text; pictures come as base64 PNG when asked."""
    level = shipped_level(STACKING)
    names = [t["function"]["name"] for t in tool_specs(level)]

    async def go() -> tuple[dict[str, Any], dict[str, Any]]:
        async with _client(url) as env:
            r0 = await env.reset(level=STACKING, images=True)
            text = plan_texts(level)[0]
            piece, cells = text.split()[1], text.split(" ", 2)[2]
            triples = [json.loads("[" + c.strip("()") + "]") for c in cells.split(") (")]
            r1 = await env.step({"tool": "place", "arguments": {"piece": piece, "cells": triples}})
            return r0.observation, r1.observation

    first, after = asyncio.run(go())
    assert "place" in names
    assert set(first["images"]) >= {"front", "iso", "tray"}
    import base64

    assert base64.b64decode(first["images"]["iso"])[:8] == b"\x89PNG\r\n\x1a\n"
    assert after["last"]["legal"], after["feedback"]
    assert after["steps"] == 1


async def _expect_error(env: GenericEnvClient, message: dict[str, Any]) -> str:
    with pytest.raises(RuntimeError, match="Server error") as err:
        await env._send_and_receive(message)
    return str(err.value)


def test_bad_requests_leave_the_session_intact(url: str) -> None:
    """Malformed actions and options are refused with a typed error; the episode, its steps
    and its position are exactly as before, and the session plays on to success."""

    async def go() -> None:
        async with _client(url) as env:
            await env.reset(level=PUZZLE)
            plan = plan_texts(shipped_level(PUZZLE))
            await env.step({"text": plan[0]})
            before = await env.state()
            bad_actions: list[Any] = [
                {"txt": "finish"},
                {"text": 5},
                {"text": "finish", "tool": "finish"},
                {},
                {"tool": "move", "arguments": "not an object"},
                {"text": "x" * 300_000},
                {"type": "call_tool", "tool_name": "x"},
            ]
            for action in bad_actions:
                await _expect_error(env, {"type": "step", "data": action})
            for raw in ("not json", "[1,2]", '{"type": "mcp", "data": {}}', "[" * 5000):
                await env._ws.send(raw)
                reply = json.loads(await env._ws.recv())
                assert reply["type"] == "error"
            await env._ws.send(b"\x00binary")
            assert json.loads(await env._ws.recv())["type"] == "error"
            for opts in BAD_RESETS:
                text = await _expect_error(env, {"type": "reset", "data": opts})
                assert "Error" in text
            assert await env.state() == before
            for text in plan[1:]:
                r = await env.step({"text": text})
            assert r.done and r.observation["success"]
            await _expect_error(env, {"type": "step", "data": {"text": "finish"}})

    asyncio.run(go())


def test_an_illegal_action_costs_a_step_like_an_agents(url: str) -> None:
    async def go() -> dict[str, Any]:
        async with _client(url) as env:
            await env.reset(level=PUZZLE, dialect="text")
            r = await env.step({"text": "I think <action>move nobody +x 1</action>"})
            obs: dict[str, Any] = r.observation
            return obs

    obs = asyncio.run(go())
    assert obs["steps"] == 1 and not obs["last"]["legal"] and obs["feedback"]

    async def untagged() -> dict[str, Any]:
        async with _client(url) as env:
            await env.reset(level=PUZZLE, dialect="text")
            r = await env.step({"text": "move red -y inf"})  # no <action> tags
            obs: dict[str, Any] = r.observation
            return obs

    obs = asyncio.run(untagged())
    assert obs["steps"] == 1 and obs["last"]["error"] == "unparseable"
    assert "no <action>...</action> found" in obs["text"]


def test_32_sessions_at_once_all_finish(url: str) -> None:
    """32 WebSocket sessions over five levels, interleaved; each reaches success on its own."""

    async def one(i: int) -> tuple[str, dict[str, Any]]:
        level_id = IDS[i % len(IDS)]
        seen = await _play_plan(url, level_id)
        return level_id, seen[-2]

    async def all_of() -> list[tuple[str, dict[str, Any]]]:
        return await asyncio.gather(*(one(i) for i in range(32)))

    results = asyncio.run(all_of())
    assert len(results) == 32
    for level_id, last in results:
        assert last["success"] and last["steps"] == shipped_level(level_id).optimal_steps


def test_http_routes_answer_4xx_to_bad_input(url: str) -> None:
    assert get(f"{url}/health").json() == {"status": "healthy"}
    r = post(f"{url}/reset", json={"level": PUZZLE})
    assert r.status_code == 200 and r.json()["observation"]["level_id"] == PUZZLE
    cases = [
        (post(f"{url}/step", json={"action": {"text": "finish"}}), 409, "NoEpisodeError"),
        (post(f"{url}/reset", json={"level": "nope"}), 404, "UnknownLevelIdError"),
        (post(f"{url}/reset", json={"level": PUZZLE, "history": "x"}), 400, "RequestError"),
        (post(f"{url}/reset", content=b"[" * 10_000), 400, "RequestError"),
        (post(f"{url}/reset", content=b"x" * 2_000_000), 413, "TooLargeError"),
        (post(f"{url}/mcp", json={}), 404, "NotFoundError"),
        (get(f"{url}/play/nope"), 404, "UnknownLevelIdError"),
        (get(f"{url}/static/nope.js"), 404, "NotFoundError"),
    ]
    for response, status, kind in cases:
        assert response.status_code == status, response.text
        assert response.json()["error"]["type"] == kind
    assert post(f"{url}/step", json={"action": {"bad": 1}}).status_code == 422
    levels = get(f"{url}/levels").json()
    assert [lv["id"] for lv in levels] == sorted(IDS)


@pytest.mark.slow
def test_every_shipped_levels_oracle_plan_succeeds_over_the_wire() -> None:
    """All shipped levels, 8 sessions at a time, each plan played step by step to success."""
    from chaingeo.core.suite import shipped_levels

    ids = shipped_levels()
    with running(Catalog({i: shipped_level(i) for i in ids}), max_sessions=8) as base:

        async def share(part: list[str]) -> list[tuple[str, dict[str, Any]]]:
            return [(i, (await _play_plan(base, i))[-2]) for i in part]

        async def all_of() -> list[list[tuple[str, dict[str, Any]]]]:
            return await asyncio.gather(*(share(ids[k::8]) for k in range(8)))

        results = [r for part in asyncio.run(all_of()) for r in part]
    assert len(results) == len(ids) > 100
    for level_id, last in results:
        assert last["success"] and last["steps"] == shipped_level(level_id).optimal_steps, level_id
