"""A local OpenAI-compatible chat-completions server for the tests (127.0.0.1, ephemeral port).

It checks every request's shape (model, system + user messages, base64 PNG images, the sampling
parameters, the bearer key) and answers from a script: each entry is a reply text, native tool
calls (:func:`calls`), or a fault (``timeout``, ``500``, ``429`` with Retry-After, ``malformed``
JSON, ``cutoff``), or one of the hostile faults of :mod:`chaingeo.evaluation.hostile_server`
(``trickle``, ``redirect`` to another port, ``answer``: any JSON as the body, ``retry-after``;
``raw_usage`` sends any usage block). Reply text goes out through ``json.dumps``, so lone
surrogates arrive escaped as from a hostile server. When the script runs out it answers
``<action>finish</action>``.

Tool calling: an answer's calls get ids ``call_<request>_<i>``. The next request must answer
them (unless its entry says ``new_episode``): the previous observation, the assistant message
with exactly those calls, then one ``tool`` message per id, in order; anything else is a problem
(HTTP 400). With ``refuse_tools`` every request offering tools is refused as vLLM does without
``--enable-auto-tool-choice`` (HTTP 400, not a problem).
"""

from __future__ import annotations

import json
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from http.server import BaseHTTPRequestHandler
from typing import Any

from chaingeo.core import limits
from chaingeo.evaluation.hostile_server import chat_answer, play, send, serving


@dataclass
class Script:
    entries: list[dict[str, Any]] = field(default_factory=list)
    requests: list[dict[str, Any]] = field(default_factory=list)
    problems: list[str] = field(default_factory=list)
    expect_key: str | None = None
    refuse_tools: bool = False
    #: a chat that resends its whole conversation each turn (verifiers' harnesses): the messages
    #: between the system prompt and the new turn alternate user and assistant (with the tool
    #: results of any calls), and the sampling parameters are the caller's business
    chat_history: bool = False
    #: the calls of the last answer (id, name, arguments), which the next request must answer
    pending: list[tuple[str, str, str]] = field(default_factory=list)
    lock: threading.Lock = field(default_factory=threading.Lock)

    def next(self) -> dict[str, Any]:
        with self.lock:
            return self.entries.pop(0) if self.entries else {"reply": "<action>finish</action>"}

    def peek(self) -> dict[str, Any]:
        with self.lock:
            return self.entries[0] if self.entries else {}


def reply(text: str, prompt: int = 100, completion: int = 20, **extra: Any) -> dict[str, Any]:
    return {"reply": text, "usage": (prompt, completion), **extra}


def calls(
    *made: tuple[str, Any], text: str = "", prompt: int = 100, completion: int = 20, **extra: Any
) -> dict[str, Any]:
    """An answer made of tool calls ``(name, arguments)``: arguments as an object (sent as JSON
    text, as OpenAI does) or as raw text (sent as is)."""
    return {"reply": text, "usage": (prompt, completion), "tool_calls": list(made), **extra}


REFUSAL = '"auto" tool choice requires --enable-auto-tool-choice and --tool-call-parser to be set'


def _check_tool_history(middle: list[Any], script: Script, fresh: bool) -> str | None:
    """The messages between the system prompt and the new observation answer the last calls."""
    pending = script.pending[: limits.MAX_TOOL_CALLS]  # a client plays (and echoes) no more
    if not middle:
        missing = pending and not fresh
        return "the tool results of the last answer did not come back" if missing else None
    if not pending:
        return "tool history sent, but the last answer made no tool calls"
    if len(middle) != 2 + len(pending):
        return f"expected user, assistant and {len(pending)} tool messages before the new turn"
    before, assistant, *results = middle
    if before.get("role") != "user" or not isinstance(before.get("content"), str):
        return "the previous observation must come back as a user text message"
    if assistant.get("role") != "assistant":
        return "the calls must come back in an assistant message"
    echoed = [
        (c.get("id"), c.get("function", {}).get("name"), c.get("function", {}).get("arguments"))
        for c in assistant.get("tool_calls") or []
        if isinstance(c, dict) and c.get("type") == "function"
    ]
    if echoed != pending:
        return f"assistant tool_calls {echoed} are not the calls made {pending}"
    ids = [m.get("tool_call_id") for m in results if m.get("role") == "tool"]
    if ids != [p[0] for p in pending]:
        return f"tool results for {ids}, expected {[p[0] for p in pending]}"
    if not all(isinstance(m.get("content"), str) and m["content"] for m in results):
        return "a tool result has no text"
    return None


def _check_chat_history(middle: list[Any]) -> str | None:
    """Earlier turns, oldest first: user, assistant, user, ...; an assistant message that made
    tool calls (its content may then be null) is followed by one ``tool`` message per call, in
    order, before the next user message."""
    expect: list[str] = ["user"]  # the roles (or tool call ids) the next message may take
    for i, m in enumerate(middle):
        role = m.get("role") if isinstance(m, dict) else None
        if role == "tool" and expect and expect[0] not in ("user", "assistant"):
            if m.get("tool_call_id") != expect.pop(0) or not isinstance(m.get("content"), str):
                return f"history message {i}: a tool result out of order or without text"
            expect = expect or ["user"]
            continue
        if role != expect[0]:
            return f"history message {i} has role {role!r}; expected {expect[0]!r}"
        if role == "user":
            expect = ["assistant"]
            continue
        calls = m.get("tool_calls") or []
        if not calls and not isinstance(m.get("content"), str):
            return f"history message {i}: the assistant's reply did not come back as text"
        expect = [c.get("id") for c in calls] or ["user"]
    return None if expect == ["user"] else "the history ends before its turn is answered"


def _check_tools(tools: Any) -> str | None:
    if tools is None:
        return None
    if not isinstance(tools, list) or not tools:
        return "tools must be a non-empty list"
    names = []
    for t in tools:
        fn = t.get("function") if isinstance(t, dict) else None
        if t.get("type") != "function" or not isinstance(fn, dict):
            return "every tool must be a function"
        params = fn.get("parameters")
        if not isinstance(params, dict) or params.get("type") != "object":
            return f"tool {fn.get('name')}: parameters must be a JSON schema object"
        names.append(fn.get("name"))
    return "duplicate tool names" if len(set(names)) != len(names) else None


def _check_shape(body: Any, headers: Any, script: Script) -> str | None:
    if not isinstance(body, dict):
        return "body is not an object"
    if not isinstance(body.get("model"), str):
        return "no model"
    msgs = body.get("messages")
    if not (isinstance(msgs, list) and len(msgs) >= 2):
        return "expected system + user messages"
    if msgs[0].get("role") != "system" or msgs[-1].get("role") != "user":
        return "roles must be system, (tool history,) user"
    problem = _check_tools(body.get("tools"))
    if script.chat_history:
        problem = problem or _check_chat_history(msgs[1:-1])
    else:
        problem = problem or _check_tool_history(
            msgs[1:-1], script, bool(script.peek().get("new_episode"))
        )
    if problem:
        return problem
    content = msgs[-1].get("content")
    if not isinstance(content, list) or content[0].get("type") != "text":
        return "user content must be parts starting with text"
    for part in content:
        if part.get("type") == "image_url":
            url = part["image_url"]["url"]
            if not url.startswith("data:image/png;base64,iVBOR"):
                return "image is not a base64 PNG data URL"
    for k in ("temperature", "top_p"):
        if not script.chat_history and not isinstance(body.get(k), int | float):
            return f"missing {k}"
    if script.expect_key is not None and headers.get("Authorization") != (
        f"Bearer {script.expect_key}"
    ):
        return "wrong or missing bearer key"
    return None


def _make_handler(script: Script) -> type[BaseHTTPRequestHandler]:
    class Handler(BaseHTTPRequestHandler):
        def log_message(self, format: str, *args: Any) -> None:
            pass

        def _send(self, code: int, payload: bytes, headers: dict[str, str] | None = None) -> None:
            send(self, code, payload, headers)

        def do_POST(self) -> None:
            n = int(self.headers.get("Content-Length", 0))
            raw = self.rfile.read(n)
            if self.path != "/v1/chat/completions":
                self._send(404, b'{"error": {"message": "no such path"}}')
                return
            try:
                body = json.loads(raw)
            except json.JSONDecodeError:
                body = None
            problem = _check_shape(body, self.headers, script)
            with script.lock:
                script.requests.append({"body": body, "headers": dict(self.headers)})
                number = len(script.requests)
            if problem:
                script.problems.append(problem)
                self._send(400, json.dumps({"error": {"message": problem}}).encode())
                return
            if script.refuse_tools and "tools" in body:
                self._send(400, json.dumps({"error": {"message": REFUSAL}}).encode())
                return
            entry = script.next()
            if play(self, entry, body["model"]):
                return
            fault = entry.get("fault")
            if fault == "timeout":
                time.sleep(float(entry.get("sleep", 1.0)))
                entry = {"reply": "<action>too late</action>"}
            elif fault == "500":
                self._send(500, b'{"error": {"message": "internal"}}')
                return
            elif fault == "429":
                self._send(
                    429,
                    b'{"error": {"message": "slow down"}}',
                    {"Retry-After": str(entry["after"])},
                )
                return
            elif fault == "drop":  # promise a long body, send half, hang up
                self.send_response(200)
                self.send_header("Content-Type", "application/json")
                self.send_header("Content-Length", "4000")
                self.end_headers()
                self.wfile.write(b'{"choices": [')
                self.wfile.flush()
                self.close_connection = True
                return
            elif fault == "malformed":
                self._send(200, b'{"choices": [ {"message": ')
                return
            elif fault == "echo-key-401":
                key = self.headers.get("Authorization", "")
                self._send(401, json.dumps({"error": {"message": f"bad key {key}"}}).encode())
                return
            answer, script.pending = chat_answer(entry, body["model"], number)
            answer.setdefault("created", 0)  # as OpenAI sends it (strict clients require it)
            self._send(200, json.dumps(answer).encode())

    return Handler


@contextmanager
def fake_openai(script: Script) -> Iterator[str]:
    """Serve ``script``; yields the base URL (``http://127.0.0.1:PORT/v1``)."""
    with serving(_make_handler(script)) as url:
        yield url
