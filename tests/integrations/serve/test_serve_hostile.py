"""No input makes ``chain serve`` answer 500 or touch another session: seeded random frames and
bodies (hypothesis) against a real server, a watched session checked after each; the token."""

from __future__ import annotations

import contextlib
import json
import os
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from typing import Any

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

pytest.importorskip("openenv", reason="chain serve needs the serve extra (openenv-core)")

from websockets.exceptions import ConnectionClosed
from websockets.sync.client import connect

from chaingeo.core.suite import shipped_level
from chaingeo.envs.demos import plan_texts
from chaingeo.integrations.serve.environment import Catalog
from tests.support.serve import free_port, get, post, running

LEVEL = "puzzle-easy-07-burr3"
TOKEN = "s3cret-token-0123"

json_values = st.recursive(
    st.none() | st.booleans() | st.integers() | st.floats(allow_nan=False) | st.text(max_size=20),
    lambda inner: (
        st.lists(inner, max_size=4) | st.dictionaries(st.text(max_size=8), inner, max_size=4)
    ),
    max_leaves=12,
)
keys = st.sampled_from(
    ["text", "tool", "arguments", "level", "seed", "images", "history", "legal", "dialect",
     "max_steps", "scene", "participant", "metadata", "episode_id", "x"]
)  # fmt: skip
payloads = st.dictionaries(
    keys, json_values | st.sampled_from([LEVEL, "finish", "move"]), max_size=4
)
frames = st.one_of(
    st.builds(
        lambda t, d: json.dumps({"type": t, "data": d}),
        st.sampled_from(["reset", "step", "state", "mcp", "nope"]),
        payloads,
    ),
    st.text(max_size=60),
    json_values.map(json.dumps),
)


@pytest.fixture(scope="module")
def url() -> Iterator[str]:
    with running(Catalog({LEVEL: shipped_level(LEVEL)})) as base:
        yield base


def _ws(url: str, **kwargs: Any) -> Any:
    return connect(url.replace("http://", "ws://") + "/ws", max_size=None, **kwargs)


def _ask(ws: Any, message: dict[str, Any]) -> dict[str, Any]:
    ws.send(json.dumps(message))
    reply: dict[str, Any] = json.loads(ws.recv(timeout=120))
    return reply


@pytest.fixture(scope="module")
def watched(url: str) -> Iterator[tuple[Any, dict[str, Any]]]:
    """A session one step into the level: no other client may change it."""
    with _ws(url) as ws:
        _ask(ws, {"type": "reset", "data": {"level": LEVEL}})
        _ask(ws, {"type": "step", "data": {"text": plan_texts(shipped_level(LEVEL))[0]}})
        yield ws, _ask(ws, {"type": "state"})


@settings(max_examples=30, deadline=None, suppress_health_check=list(HealthCheck))
@given(batch=st.lists(frames, min_size=1, max_size=6))
def test_random_frames_get_answers_never_a_broken_session(
    url: str, watched: tuple[Any, dict[str, Any]], batch: list[str]
) -> None:
    with _ws(url) as ws:
        for frame in batch:
            ws.send(frame)
            reply = json.loads(ws.recv(timeout=120))
            assert reply["type"] in ("observation", "state", "error"), reply
            if reply["type"] == "error":
                assert reply["data"]["code"] in ("VALIDATION_ERROR", "EXECUTION_ERROR"), reply
        assert _ask(ws, {"type": "state"})["type"] == "state"  # still open, still answering
    ws_watched, before = watched
    assert _ask(ws_watched, {"type": "state"}) == before


@settings(max_examples=30, deadline=None, suppress_health_check=list(HealthCheck))
@given(
    path=st.sampled_from(["/reset", "/step", "/state", "/health", "/schema", "/levels", "/"]),
    body=st.one_of(payloads.map(json.dumps), st.text(max_size=40), json_values.map(json.dumps)),
    wrap=st.booleans(),
)
def test_random_http_bodies_get_no_5xx(url: str, path: str, body: str, wrap: bool) -> None:
    if wrap and body.startswith("{"):
        body = json.dumps({"action": json.loads(body)})
    r = post(url + path, content=body.encode(), headers={"content-type": "application/json"})
    assert r.status_code < 500, r.text
    assert get(url + path).status_code < 500


def test_token_is_required_everywhere_but_health() -> None:
    with running(Catalog({LEVEL: shipped_level(LEVEL)}), token=TOKEN) as url:
        assert get(f"{url}/health").status_code == 200
        assert post(f"{url}/reset", json={"level": LEVEL}).status_code == 401
        assert get(f"{url}/").status_code == 401
        wrong = {"authorization": "Bearer nope"}
        assert post(f"{url}/reset", json={"level": LEVEL}, headers=wrong).status_code == 401
        good = {"authorization": f"Bearer {TOKEN}"}
        assert post(f"{url}/reset", json={"level": LEVEL}, headers=good).status_code == 200
        with pytest.raises(Exception, match="403"), _ws(url):
            pass
        with _ws(url, additional_headers=good) as ws:
            assert _ask(ws, {"type": "reset", "data": {"level": LEVEL}})["type"] == "observation"
        login = get(f"{url}/play/{LEVEL}?token={TOKEN}", follow_redirects=False)
        assert login.status_code == 303 and "HttpOnly" in login.headers["set-cookie"]
        assert login.headers["location"] == f"/play/{LEVEL}"
        cookie = {"cookie": f"chain_token={TOKEN}"}
        assert get(f"{url}/play/{LEVEL}", headers=cookie).status_code == 200
        other = {"origin": "http://evil.example", **cookie}
        with pytest.raises(Exception, match="403"), _ws(url, additional_headers=other):
            pass


def test_chain_serve_starts_and_stops_on_sigterm(tmp_path: Any) -> None:
    """The command itself: one line says where it serves, /health answers, SIGTERM ends it
    cleanly (exit 0) within seconds."""
    port = free_port()
    proc = subprocess.Popen(
        [sys.executable, "-m", "chaingeo.cli.main", "serve", LEVEL, "--port", str(port)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        cwd=tmp_path,
        env={**os.environ, "CHAIN_SERVE_TOKEN": ""},
    )
    try:
        assert proc.stdout is not None
        line = json.loads(proc.stdout.readline())
        assert line == {"serving": f"http://127.0.0.1:{port}/", "levels": 1}
        deadline = time.monotonic() + 60
        while True:
            try:
                if get(f"http://127.0.0.1:{port}/health").status_code == 200:
                    break
            except Exception:
                if time.monotonic() > deadline:
                    raise
                time.sleep(0.1)
        proc.send_signal(signal.SIGTERM)
        assert proc.wait(timeout=20) == 0
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()


def test_sessions_are_bounded_in_count_idle_time_and_messages(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    from chaingeo.core import limits

    monkeypatch.setattr(limits, "MAX_SESSION_MESSAGES", 4)
    with running(Catalog({LEVEL: shipped_level(LEVEL)}), max_sessions=2, idle_seconds=2.0) as url:
        with _ws(url) as a, contextlib.ExitStack() as later:
            assert _ask(a, {"type": "reset", "data": {"level": LEVEL}})["type"] == "observation"
            b = later.enter_context(_ws(url))
            assert _ask(b, {"type": "state"})["type"] == "state"
            with _ws(url) as c:  # a third is refused: OpenEnv's capacity error, then closed
                reply = json.loads(c.recv(timeout=120))
                assert reply["data"]["code"] == "CAPACITY_REACHED"
            for _ in range(3):
                assert _ask(a, {"type": "state"})["type"] == "state"
            refused = _ask(a, {"type": "state"})  # the fifth message of this session
            assert refused["type"] == "error" and "SessionLimitError" in refused["data"]["message"]
            time.sleep(2.5)  # b has been silent: closed
            with pytest.raises(ConnectionClosed):
                _ask(b, {"type": "state"})
        with _ws(url) as d:  # its slot is free again
            assert _ask(d, {"type": "state"})["type"] == "state"
