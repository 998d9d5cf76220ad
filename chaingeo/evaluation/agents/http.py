"""A small OpenAI-compatible chat-completions client on the standard library.

Works with any server speaking ``POST {base_url}/chat/completions`` (hosted APIs, vLLM, SGLang,
Ollama, llama.cpp). Transient faults are retried with exponential backoff and full jitter drawn
from a seeded generator (so a rerun waits the same way): timeouts, connection errors, 429 (the
server's ``Retry-After`` is honoured when longer, up to
:data:`~chaingeo.core.limits.MAX_RETRY_AFTER_SECONDS`), 5xx, and answers outside the protocol
(:mod:`chaingeo.evaluation.agents.protocol`); all retries of one call share a time budget. Other
4xx answers are the caller's mistake and fail at once; 401 and 403, and a remote (non-loopback)
server given no key, raise :class:`AuthenticationError` before any retry, which stops a whole
run. ``timeout`` bounds each request by wall clock (connect and the whole answer), not each
read. The API key goes only into the ``Authorization`` header of requests to the configured
origin: a redirect elsewhere is never followed, and the key never appears in an error message.
"""

from __future__ import annotations

import contextlib
import email.utils
import http.client
import ipaddress
import json
import math
import os
import socket
import threading
import time
import urllib.parse
import urllib.request
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any, Final

import numpy as np

from chaingeo.core import limits
from chaingeo.core.errors import ChainGeoError
from chaingeo.evaluation.agents.base import AgentError, AuthenticationError
from chaingeo.evaluation.agents.protocol import ProtocolError, check_answer, parse_answer
from chaingeo.evaluation.sanitize import clean_text

#: Redirect statuses: followed only to the same origin, and only 307/308 (they keep the POST).
REDIRECTS: Final = frozenset({301, 302, 303, 307, 308})


@dataclass(frozen=True)
class RetryPolicy:
    max_retries: int = 6
    backoff_base: float = 1.0  # seconds; attempt a waits uniform(0, base * 2**a), capped
    backoff_max: float = 60.0
    max_retry_after: float = limits.MAX_RETRY_AFTER_SECONDS  # a longer Retry-After is capped
    budget: float = limits.MAX_RETRY_SECONDS  # requests and waits of one call, all retries


#: Where a model server is when neither the options nor ``$OPENAI_BASE_URL`` say.
DEFAULT_BASE_URL = "https://api.openai.com/v1"
DEFAULT_KEY_ENV = "OPENAI_API_KEY"


def api_key(options: Mapping[str, Any], secrets: Mapping[str, str] | None = None) -> str | None:
    """The one API-key lookup: an explicit secret, else the environment variable the options
    name (``api_key_env``, default ``OPENAI_API_KEY``); None when unset (a local server)."""
    if secrets and secrets.get("api_key"):
        return secrets["api_key"]
    return os.environ.get(str(options.get("api_key_env", DEFAULT_KEY_ENV))) or None


@dataclass(frozen=True)
class ServerSettings:
    """How to reach one OpenAI-compatible server, read once from agent or judge options
    (``base_url``, ``api_key_env``, ``timeout``, ``max_retries``, ``backoff_base``,
    ``backoff_max``, ``retry_budget``); the key itself is kept out of ``repr``."""

    base_url: str
    key: str | None
    timeout: float
    retry: RetryPolicy

    @classmethod
    def from_options(
        cls, options: Mapping[str, Any], secrets: Mapping[str, str] | None = None
    ) -> ServerSettings:
        return cls(
            base_url=str(
                options.get("base_url") or os.environ.get("OPENAI_BASE_URL") or DEFAULT_BASE_URL
            ),
            key=api_key(options, secrets),
            timeout=float(options.get("timeout", 300.0)),
            retry=RetryPolicy(
                max_retries=int(options.get("max_retries", 6)),
                backoff_base=float(options.get("backoff_base", 1.0)),
                backoff_max=float(options.get("backoff_max", 60.0)),
                budget=min(
                    float(options.get("retry_budget", limits.MAX_RETRY_SECONDS)),
                    limits.MAX_RETRY_SECONDS,
                ),
            ),
        )

    def __repr__(self) -> str:
        return f"ServerSettings({self.base_url!r}, key={'set' if self.key else None})"

    def client(self, seed: int) -> ChatClient:
        """A client for one episode, its retry waits drawn from ``seed``."""
        return ChatClient(
            self.base_url, self.key, timeout=self.timeout, retry=self.retry, seed=seed
        )


class TransientError(ChainGeoError):
    """A failure worth retrying; ``retry_after`` is the server's hint in seconds."""

    def __init__(self, reason: str, retry_after: float | None = None) -> None:
        super().__init__(reason)
        self.reason = reason
        self.retry_after = retry_after


def parse_retry_after(value: str | None, now: float | None = None) -> float | None:
    """Seconds from a ``Retry-After`` header: a number, or an HTTP date."""
    if not value:
        return None
    value = value.strip()
    try:
        return max(0.0, float(value))
    except ValueError:
        pass
    try:
        when = email.utils.parsedate_to_datetime(value)
    except (TypeError, ValueError):
        return None
    return max(0.0, when.timestamp() - (time.time() if now is None else now))


class RequestRejected(AgentError):
    """The server refused the request itself (a 4xx other than 401/403/429): retrying the same
    body cannot help; ``status`` and ``detail`` (its error message) let a caller change it."""

    def __init__(self, url: str, status: int, detail: str) -> None:
        super().__init__(f"{url}: HTTP {status} {detail}")
        self.status = status
        self.detail = detail


def origin(url: str) -> tuple[str, str, int | None]:
    """(scheme, host, port) of ``url``, the default port made explicit: what a redirect must
    keep for the key to go with it."""
    parts = urllib.parse.urlsplit(url)
    scheme = parts.scheme.lower()
    try:
        port = parts.port or {"http": 80, "https": 443}.get(scheme)
    except ValueError:
        port = None
    return scheme, (parts.hostname or "").lower(), port


@dataclass(frozen=True)
class _Answer:
    status: int
    headers: http.client.HTTPMessage
    body: bytes


def _connection(url: str, timeout: float) -> tuple[http.client.HTTPConnection, str]:
    """A connection for ``url`` and the request target: direct, or through the proxy the
    environment names (``HTTPS_PROXY``/``HTTP_PROXY``, ``NO_PROXY``) as urllib did; a server on
    this machine is always reached directly. HTTPS goes through a CONNECT tunnel, so the proxy
    never sees the key."""
    parts = urllib.parse.urlsplit(url)
    https = parts.scheme.lower() == "https"
    host = parts.hostname or ""
    path = (parts.path or "/") + (f"?{parts.query}" if parts.query else "")
    proxy = urllib.request.getproxies().get("https" if https else "http")
    if proxy and not is_loopback(url) and not urllib.request.proxy_bypass(host):
        via = urllib.parse.urlsplit(proxy if "://" in proxy else f"http://{proxy}")
        proxy_host, proxy_port = via.hostname or "", via.port or 80
        if https:
            tunnel = http.client.HTTPSConnection(proxy_host, proxy_port, timeout=timeout)
            tunnel.set_tunnel(host, parts.port or 443)
            return tunnel, path
        return http.client.HTTPConnection(proxy_host, proxy_port, timeout=timeout), url
    if https:
        return http.client.HTTPSConnection(host, parts.port, timeout=timeout), path
    return http.client.HTTPConnection(host, parts.port, timeout=timeout), path


def _exchange(url: str, data: bytes, headers: Mapping[str, str], timeout: float) -> _Answer:
    """One POST whose connect, send and whole answer finish within ``timeout`` seconds of wall
    clock: a watchdog shuts the socket at the deadline, so a server trickling a byte at a time
    cannot hold the call (a per-read timeout would restart with every byte). The body is read up
    to :data:`~chaingeo.core.limits.MAX_ANSWER_BYTES` (plus one, to see it is longer)."""
    expired = threading.Event()
    try:
        conn, path = _connection(url, timeout)
    except ValueError as e:  # a port that is not a number
        raise AgentError(f"{url}: {e}") from None

    opened: list[socket.socket] = []  # the connection drops its socket once answered

    def abort() -> None:
        expired.set()
        for sock in opened:
            with contextlib.suppress(OSError):
                sock.shutdown(socket.SHUT_RDWR)

    timer = threading.Timer(timeout, abort)
    timer.daemon = True
    timer.start()
    try:
        conn.connect()
        if conn.sock is not None:
            opened.append(conn.sock)
            if expired.is_set():  # the deadline passed while connecting
                abort()
        conn.request("POST", path, body=data, headers=dict(headers))
        resp = conn.getresponse()
        chunks: list[bytes] = []
        size = 0
        while size <= limits.MAX_ANSWER_BYTES:
            chunk = resp.read(min(1 << 16, limits.MAX_ANSWER_BYTES + 1 - size))
            if not chunk:
                break
            chunks.append(chunk)
            size += len(chunk)
        if resp.length and size <= limits.MAX_ANSWER_BYTES:
            raise http.client.IncompleteRead(b"", resp.length)
    except (OSError, http.client.HTTPException) as e:
        if expired.is_set():
            raise TransientError(f"no complete answer within {timeout:g}s") from None
        if isinstance(e, TimeoutError):
            raise TransientError(f"timeout after {timeout:g}s") from None
        raise TransientError(f"connection failed: {type(e).__name__} {e}") from None
    finally:
        timer.cancel()
        conn.close()
    if expired.is_set():
        raise TransientError(f"no complete answer within {timeout:g}s")
    return _Answer(resp.status, resp.headers, b"".join(chunks))


class ChatClient:
    def __init__(
        self,
        base_url: str,
        api_key: str | None = None,
        *,
        timeout: float = 120.0,
        retry: RetryPolicy | None = None,
        seed: int = 0,
        sleep: Callable[[float], None] = time.sleep,
        headers: Mapping[str, str] | None = None,
    ) -> None:
        if not base_url.startswith(("http://", "https://")):
            raise ValueError(f"base URL must start with http:// or https://, got {base_url!r}")
        if not (timeout > 0 and math.isfinite(timeout)):
            raise ValueError(f"timeout must be a positive number of seconds, got {timeout!r}")
        self.url = base_url.rstrip("/") + "/chat/completions"
        self._key = api_key
        self.timeout = timeout
        self.retry = retry or RetryPolicy()
        self._rng = np.random.default_rng(np.random.SeedSequence([seed, 0x7E7]))
        self._sleep = sleep
        self._headers = dict(headers or {})
        self.waits: list[float] = []  # every backoff taken, for logs and tests
        self.faults: list[str] = []  # why each retry happened

    def _redacted(self, text: str) -> str:
        text = clean_text(text)
        return text.replace(self._key, "[REDACTED]") if self._key else text

    def _post(self, data: bytes) -> _Answer:
        """POST to this client's URL, following at most
        :data:`~chaingeo.core.limits.MAX_REDIRECTS` 307/308 redirects that keep the origin;
        any other redirect is an error and never followed, so the key never leaves the origin."""
        headers = {"Content-Type": "application/json", "Accept": "application/json"}
        headers.update(self._headers)
        if self._key:
            headers["Authorization"] = f"Bearer {self._key}"
        url = self.url
        for _ in range(limits.MAX_REDIRECTS + 1):
            answer = _exchange(url, data, headers, self.timeout)
            if answer.status not in REDIRECTS:
                return answer
            target = urllib.parse.urljoin(url, answer.headers.get("Location") or "")
            if origin(target) != origin(url):
                scheme, host, port = origin(target)
                raise AgentError(
                    f"{self.url}: HTTP {answer.status} redirect to another origin"
                    f" ({self._redacted(f'{scheme}://{host}:{port}')}); not followed, the key is"
                    " never sent elsewhere (use that server's URL as --base-url if you trust it)"
                )
            if answer.status not in (307, 308):
                raise AgentError(
                    f"{self.url}: HTTP {answer.status} redirect; only 307/308 keep a POST"
                )
            url = target
        raise AgentError(f"{self.url}: more than {limits.MAX_REDIRECTS} redirects")

    def _request(self, body: Mapping[str, Any]) -> dict[str, Any]:
        answer = self._post(json.dumps(body).encode("utf-8"))
        status = answer.status
        if not 200 <= status < 300:
            detail = self._redacted(_error_text(answer.body))
            retry_after = parse_retry_after(answer.headers.get("Retry-After"))
            if status == 429 or status >= 500:
                raise TransientError(f"HTTP {status} {detail}", retry_after)
            if status in (401, 403):
                raise AuthenticationError(
                    f"{self.url}: HTTP {status} {detail} (check the API key and --api-key-env)"
                )
            if 400 <= status < 500:
                raise RequestRejected(self.url, status, detail)
            raise ProtocolError(f"HTTP {status} is not an answer")
        parsed = parse_answer(answer.body)
        check_answer(parsed)
        assert isinstance(parsed, dict)
        return parsed

    def complete(self, body: Mapping[str, Any]) -> dict[str, Any]:
        """POST with retries; the checked answer, else :class:`AgentError` (a
        :class:`ProtocolError` when the last fault was an answer outside the protocol) once
        retries, or the retry time budget, run out."""
        if not self._key and not is_loopback(self.url):
            raise AuthenticationError(
                f"{self.url}: no API key for a remote server; set $OPENAI_API_KEY or the"
                " variable named by --api-key-env"
            )
        policy = self.retry
        spent = 0.0  # seconds of requests and waits so far
        for attempt in range(policy.max_retries + 1):
            started = time.monotonic()
            try:
                return self._request(body)
            except (TransientError, ProtocolError) as e:
                spent += time.monotonic() - started
                reason = e.reason if isinstance(e, TransientError) else str(e)
                self.faults.append(reason)
                kind = ProtocolError if isinstance(e, ProtocolError) else AgentError
                if attempt == policy.max_retries:
                    raise kind(
                        f"{self.url}: giving up after {attempt + 1} attempts: {reason}"
                    ) from None
                cap = min(policy.backoff_max, policy.backoff_base * 2.0**attempt)
                wait = float(self._rng.uniform(0.0, cap))
                after = e.retry_after if isinstance(e, TransientError) else None
                if after is not None:
                    wait = max(wait, min(after, policy.max_retry_after))
                if spent + wait > policy.budget:
                    raise kind(
                        f"{self.url}: giving up after {attempt + 1} attempts: {reason} (a wait"
                        f" of {wait:.0f}s would pass the {policy.budget:g}s retry budget)"
                    ) from None
                spent += wait
                self.waits.append(wait)
                self._sleep(wait)
        raise AssertionError("unreachable")


def is_loopback(url: str) -> bool:
    """Whether ``url`` names this machine (``localhost``, 127.0.0.0/8, ``::1``): a local server
    may run without a key; any other needs one."""
    host = urllib.parse.urlsplit(url).hostname or ""
    if host == "localhost" or host.endswith(".localhost"):
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


def _error_text(body: bytes) -> str:
    text = body[:2000].decode("utf-8", "replace")
    try:
        obj = json.loads(text)
        msg = obj.get("error", {}).get("message") if isinstance(obj, dict) else None
        if isinstance(msg, str):
            return msg[:300]
    except (ValueError, AttributeError, RecursionError):
        pass
    return text[:300].strip()
