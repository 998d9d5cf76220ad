"""A real ``chain serve`` app on 127.0.0.1 (a free port), run by uvicorn in a thread of the test
process, and small helpers for its clients. One server per test module keeps the tests fast
(importing openenv-core costs seconds)."""

from __future__ import annotations

import contextlib
import socket
import threading
import time
from collections.abc import Iterator
from typing import Any

import pytest

pytest.importorskip("openenv", reason="chain serve needs the serve extra (openenv-core)")

import httpx
import uvicorn

from chaingeo.core import limits
from chaingeo.integrations.serve.app import ServeOptions, build_app
from chaingeo.integrations.serve.environment import Catalog


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port: int = s.getsockname()[1]
        return port


@contextlib.contextmanager
def running(catalog: Catalog, **options: Any) -> Iterator[str]:
    """The server's base URL while the block runs; stopped (sessions closed) after it."""
    port = free_port()
    opts = ServeOptions(port=port, **options)
    config = uvicorn.Config(
        build_app(catalog, opts),
        host="127.0.0.1",
        port=port,
        ws_max_size=2 * limits.MAX_REQUEST_BYTES,
        log_level="warning",
        lifespan="on",
    )
    server = uvicorn.Server(config)
    thread = threading.Thread(target=server.run, daemon=True)
    thread.start()
    url = f"http://127.0.0.1:{port}"
    deadline = time.monotonic() + 30
    while not server.started:
        if time.monotonic() > deadline or not thread.is_alive():
            raise RuntimeError("the test server did not start")
        time.sleep(0.02)
    try:
        yield url
    finally:
        server.should_exit = True
        thread.join(timeout=15)


def get(url: str, **kwargs: Any) -> httpx.Response:
    return httpx.get(url, timeout=30, **kwargs)


def post(url: str, **kwargs: Any) -> httpx.Response:
    return httpx.post(url, timeout=30, **kwargs)
