"""A hostile OpenAI-compatible chat server on 127.0.0.1: every answer plays one scripted entry.

For ``chain bench robustness`` (:func:`serve`; it lives here because every module of
:mod:`chaingeo.benchmarks` is a benchmark name) and the tests' validating fake server
(``tests/support/fake_openai.py``, which answers through :func:`chat_answer` and
:func:`play`). An entry is a dict: a reply (``reply`` text, ``tool_calls`` as ``(name,
arguments)`` pairs, ``usage`` as ``(prompt, completion)`` or ``raw_usage``, any JSON value, sent
as is) or a fault (``fault``): ``trickle`` (a whole answer, one byte every ``interval`` seconds
for at most ``seconds``), ``redirect`` (``status``, default 302, to ``location``), ``answer``
(any JSON value as the 200 body: protocol breaks), ``retry-after`` (429 with ``after``). Text is
sent with ``json.dumps``, so a lone surrogate arrives as ``\\ud800``, as a hostile server sends it.
"""

from __future__ import annotations

import json
import threading
import time
from collections.abc import Iterator, Mapping, Sequence
from contextlib import contextmanager, suppress
from dataclasses import dataclass, field
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from typing import Any, Final

#: What a server answers once its script is spent.
FINISH: Final = {"reply": "<action>finish</action>"}

Call = tuple[str, str, str]  # (id, name, arguments text)


def send(
    handler: BaseHTTPRequestHandler,
    code: int,
    payload: bytes,
    headers: Mapping[str, str] | None = None,
) -> None:
    """One whole answer (a client that hung up is ignored)."""
    handler.send_response(code)
    handler.send_header("Content-Type", "application/json")
    handler.send_header("Content-Length", str(len(payload)))
    for k, v in (headers or {}).items():
        handler.send_header(k, v)
    handler.end_headers()
    with suppress(OSError):
        handler.wfile.write(payload)


def chat_answer(
    entry: Mapping[str, Any], model: str, number: int
) -> tuple[dict[str, Any], list[Call]]:
    """The chat completion a reply entry describes, and its calls (ids ``call_<number>_<i>``)."""
    text = entry.get("reply", "")
    made = [
        (f"call_{number}_{i}", name, args if isinstance(args, str) else json.dumps(args))
        for i, (name, args) in enumerate(entry.get("tool_calls", []))
    ]
    message: dict[str, Any] = {"role": "assistant", "content": text or None}
    if made:
        message["tool_calls"] = [
            {"id": cid, "type": "function", "function": {"name": name, "arguments": a}}
            for cid, name, a in made
        ]
    prompt, completion = entry.get("usage", (100, 20))
    usage = (
        entry.get("raw_usage")
        if "raw_usage" in entry
        else {
            "prompt_tokens": prompt,
            "completion_tokens": completion,
            "total_tokens": prompt + completion,
            "completion_tokens_details": {"reasoning_tokens": entry.get("reasoning", 0)},
            "prompt_tokens_details": {"cached_tokens": entry.get("cached", 0)},
        }
    )
    answer = {
        "id": "x",
        "object": "chat.completion",
        "model": model,
        "choices": [
            {
                "index": 0,
                "message": message,
                "finish_reason": "length" if entry.get("fault") == "cutoff" else "stop",
            }
        ],
        "usage": usage,
    }
    return answer, made


def play(handler: BaseHTTPRequestHandler, entry: Mapping[str, Any], model: str) -> bool:
    """Answer with the hostile fault ``entry`` names; False when it names none of them."""
    fault = entry.get("fault")
    if fault == "trickle":
        body = json.dumps(chat_answer(FINISH, model, 0)[0]).encode()
        handler.send_response(200)
        handler.send_header("Content-Type", "application/json")
        handler.send_header("Content-Length", str(len(body)))
        handler.end_headers()
        interval = float(entry.get("interval", 1.0))
        stop = time.monotonic() + float(entry.get("seconds", 60.0))
        with suppress(OSError):
            for i in range(len(body)):
                if time.monotonic() > stop:
                    break
                handler.wfile.write(body[i : i + 1])
                handler.wfile.flush()
                time.sleep(interval)
        handler.close_connection = True
    elif fault == "redirect":
        send(handler, int(entry.get("status", 302)), b"{}", {"Location": str(entry["location"])})
    elif fault == "answer":
        send(handler, 200, json.dumps(entry["answer"]).encode())
    elif fault == "retry-after":
        send(
            handler,
            429,
            b'{"error": {"message": "slow down"}}',
            {"Retry-After": str(entry["after"])},
        )
    else:
        return False
    return True


@dataclass
class Served:
    """What a :func:`serve` server saw: each request's headers."""

    headers: list[dict[str, str]] = field(default_factory=list)
    lock: threading.Lock = field(default_factory=threading.Lock)


@contextmanager
def serve(entries: Sequence[Mapping[str, Any]], seen: Served | None = None) -> Iterator[str]:
    """Answer requests from ``entries`` in order (then :data:`FINISH`), checking nothing;
    yields the base URL ``http://127.0.0.1:PORT/v1``."""
    script = list(entries)
    log = seen if seen is not None else Served()

    class Handler(BaseHTTPRequestHandler):
        def log_message(self, format: str, *args: Any) -> None:
            pass

        def do_POST(self) -> None:
            self.rfile.read(int(self.headers.get("Content-Length", 0)))
            with log.lock:
                log.headers.append(dict(self.headers))
                number = len(log.headers)
                entry = script.pop(0) if script else FINISH
            if not play(self, entry, "hostile"):
                send(self, 200, json.dumps(chat_answer(entry, "hostile", number)[0]).encode())

        do_GET = do_POST  # a client that turned a redirected POST into a GET is seen too

    with serving(Handler) as url:
        yield url


@contextmanager
def serving(handler: type[BaseHTTPRequestHandler]) -> Iterator[str]:
    """Run ``handler`` on 127.0.0.1 (an ephemeral port) in a thread; yields the base URL
    ``http://127.0.0.1:PORT/v1`` and stops the server on exit."""
    server = ThreadingHTTPServer(("127.0.0.1", 0), handler)
    server.daemon_threads = True
    thread = threading.Thread(target=server.serve_forever, args=(0.05,), daemon=True)
    thread.start()
    try:
        yield f"http://127.0.0.1:{server.server_address[1]}/v1"
    finally:
        server.shutdown()
        server.server_close()
