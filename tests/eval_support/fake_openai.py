"""A local OpenAI-compatible chat-completions server for the tests (127.0.0.1, ephemeral port).

It checks every request's shape (model, system + user messages, base64 PNG images, the sampling
parameters, the bearer key) and answers from a script: each entry is a reply text, or a fault
(``timeout``, ``500``, ``429`` with Retry-After, ``malformed`` JSON, ``cutoff``). When the script
runs out it answers ``<action>finish</action>``.
"""

from __future__ import annotations

import json
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager, suppress
from dataclasses import dataclass, field
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from typing import Any


@dataclass
class Script:
    entries: list[dict[str, Any]] = field(default_factory=list)
    requests: list[dict[str, Any]] = field(default_factory=list)
    problems: list[str] = field(default_factory=list)
    expect_key: str | None = None
    lock: threading.Lock = field(default_factory=threading.Lock)

    def next(self) -> dict[str, Any]:
        with self.lock:
            return self.entries.pop(0) if self.entries else {"reply": "<action>finish</action>"}


def reply(text: str, prompt: int = 100, completion: int = 20, **extra: Any) -> dict[str, Any]:
    return {"reply": text, "usage": (prompt, completion), **extra}


def _check_shape(body: Any, headers: Any, script: Script) -> str | None:
    if not isinstance(body, dict):
        return "body is not an object"
    if not isinstance(body.get("model"), str):
        return "no model"
    msgs = body.get("messages")
    if not (isinstance(msgs, list) and len(msgs) == 2):
        return "expected system + user messages"
    if msgs[0].get("role") != "system" or msgs[1].get("role") != "user":
        return "roles must be system, user"
    content = msgs[1].get("content")
    if not isinstance(content, list) or content[0].get("type") != "text":
        return "user content must be parts starting with text"
    for part in content:
        if part.get("type") == "image_url":
            url = part["image_url"]["url"]
            if not url.startswith("data:image/png;base64,iVBOR"):
                return "image is not a base64 PNG data URL"
    for k in ("temperature", "top_p"):
        if not isinstance(body.get(k), int | float):
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
            self.send_response(code)
            self.send_header("Content-Type", "application/json")
            self.send_header("Content-Length", str(len(payload)))
            for k, v in (headers or {}).items():
                self.send_header(k, v)
            self.end_headers()
            with suppress(BrokenPipeError, ConnectionResetError):
                self.wfile.write(payload)

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
            if problem:
                script.problems.append(problem)
                self._send(400, json.dumps({"error": {"message": problem}}).encode())
                return
            entry = script.next()
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
            text = entry.get("reply", "")
            prompt, completion = entry.get("usage", (100, 20))
            message: dict[str, Any] = {"role": "assistant", "content": text}
            if "tool_action" in entry:
                message["tool_calls"] = [
                    {
                        "id": "call_1",
                        "type": "function",
                        "function": {
                            "name": "act",
                            "arguments": json.dumps({"action": entry["tool_action"]}),
                        },
                    }
                ]
            answer = {
                "id": "x",
                "object": "chat.completion",
                "model": body["model"],
                "choices": [
                    {
                        "index": 0,
                        "message": message,
                        "finish_reason": "length" if fault == "cutoff" else "stop",
                    }
                ],
                "usage": {
                    "prompt_tokens": prompt,
                    "completion_tokens": completion,
                    "total_tokens": prompt + completion,
                    "completion_tokens_details": {"reasoning_tokens": entry.get("reasoning", 0)},
                    "prompt_tokens_details": {"cached_tokens": entry.get("cached", 0)},
                },
            }
            self._send(200, json.dumps(answer).encode())

    return Handler


@contextmanager
def fake_openai(script: Script) -> Iterator[str]:
    """Serve ``script``; yields the base URL (``http://127.0.0.1:PORT/v1``)."""
    server = ThreadingHTTPServer(("127.0.0.1", 0), _make_handler(script))
    server.daemon_threads = True
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    try:
        yield f"http://127.0.0.1:{server.server_address[1]}/v1"
    finally:
        server.shutdown()
        server.server_close()
