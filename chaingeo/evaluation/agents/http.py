"""A small OpenAI-compatible chat-completions client on the standard library.

Works with any server speaking ``POST {base_url}/chat/completions`` (hosted APIs, vLLM, SGLang,
Ollama, llama.cpp). Transient faults are retried with exponential backoff and full jitter drawn
from a seeded generator (so a rerun waits the same way): timeouts, connection errors, 429 (the
server's ``Retry-After`` is honoured when longer), 5xx, and bodies that are not JSON or carry no
choice. Other 4xx answers are the caller's mistake and fail at once; 401 and 403, and a remote
(non-loopback) server given no key, raise :class:`AuthenticationError` before any retry, which
stops a whole run. The API key goes only into the ``Authorization`` header and never into an
error message.
"""

from __future__ import annotations

import email.utils
import http.client
import ipaddress
import json
import os
import time
import urllib.error
import urllib.parse
import urllib.request
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from chaingeo.evaluation.agents.base import AgentError, AuthenticationError


@dataclass(frozen=True)
class RetryPolicy:
    max_retries: int = 6
    backoff_base: float = 1.0  # seconds; attempt a waits uniform(0, base * 2**a), capped
    backoff_max: float = 60.0
    max_retry_after: float = 300.0  # never wait longer than this for a Retry-After


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
    ``backoff_max``); the key itself is kept out of ``repr``."""

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
            ),
        )

    def __repr__(self) -> str:
        return f"ServerSettings({self.base_url!r}, key={'set' if self.key else None})"

    def client(self, seed: int) -> ChatClient:
        """A client for one episode, its retry waits drawn from ``seed``."""
        return ChatClient(
            self.base_url, self.key, timeout=self.timeout, retry=self.retry, seed=seed
        )


class TransientError(Exception):
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
        self.url = base_url.rstrip("/") + "/chat/completions"
        self._key = api_key
        self.timeout = timeout
        self.retry = retry or RetryPolicy()
        self._rng = np.random.default_rng(np.random.SeedSequence([seed, 0x7E7]))
        self._sleep = sleep
        self._headers = dict(headers or {})
        self.waits: list[float] = []  # every backoff taken, for logs and tests
        self.faults: list[str] = []  # why each retry happened

    def _request(self, body: Mapping[str, Any]) -> dict[str, Any]:
        data = json.dumps(body).encode("utf-8")
        headers = {"Content-Type": "application/json", "Accept": "application/json"}
        headers.update(self._headers)
        if self._key:
            headers["Authorization"] = f"Bearer {self._key}"
        req = urllib.request.Request(self.url, data=data, headers=headers, method="POST")
        try:
            with urllib.request.urlopen(req, timeout=self.timeout) as resp:
                raw = resp.read()
        except urllib.error.HTTPError as e:
            detail = _error_text(e)
            if self._key:
                detail = detail.replace(self._key, "[REDACTED]")
            if e.code == 429:
                raise TransientError(
                    f"HTTP 429 {detail}", parse_retry_after(e.headers.get("Retry-After"))
                ) from None
            if e.code >= 500:
                raise TransientError(
                    f"HTTP {e.code} {detail}", parse_retry_after(e.headers.get("Retry-After"))
                ) from None
            if e.code in (401, 403):
                raise AuthenticationError(
                    f"{self.url}: HTTP {e.code} {detail} (check the API key and --api-key-env)"
                ) from None
            raise RequestRejected(self.url, e.code, detail) from None
        except TimeoutError as e:
            raise TransientError(f"timeout after {self.timeout}s ({e})") from None
        except urllib.error.URLError as e:
            raise TransientError(f"connection failed: {e.reason}") from None
        except (ConnectionError, OSError, http.client.HTTPException) as e:  # cut mid-answer
            raise TransientError(f"connection failed: {type(e).__name__} {e}") from None
        try:
            parsed = json.loads(raw)
        except (json.JSONDecodeError, UnicodeDecodeError):
            raise TransientError("the server answered with malformed JSON") from None
        if not isinstance(parsed, dict) or not isinstance(parsed.get("choices"), list):
            raise TransientError("the server's answer has no 'choices' list")
        if not parsed["choices"]:
            raise TransientError("the server's answer has an empty 'choices' list")
        return parsed

    def complete(self, body: Mapping[str, Any]) -> dict[str, Any]:
        """POST with retries; the decoded answer, or :class:`AgentError` once retries run out."""
        if not self._key and not is_loopback(self.url):
            raise AuthenticationError(
                f"{self.url}: no API key for a remote server; set $OPENAI_API_KEY or the"
                " variable named by --api-key-env"
            )
        policy = self.retry
        for attempt in range(policy.max_retries + 1):
            try:
                return self._request(body)
            except TransientError as e:
                self.faults.append(e.reason)
                if attempt == policy.max_retries:
                    raise AgentError(
                        f"{self.url}: giving up after {attempt + 1} attempts: {e.reason}"
                    ) from None
                cap = min(policy.backoff_max, policy.backoff_base * 2.0**attempt)
                wait = float(self._rng.uniform(0.0, cap))
                if e.retry_after is not None:
                    wait = max(wait, min(e.retry_after, policy.max_retry_after))
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


def _error_text(e: urllib.error.HTTPError) -> str:
    try:
        body = e.read(2000).decode("utf-8", "replace")
    except OSError:
        body = ""
    try:
        obj = json.loads(body)
        msg = obj.get("error", {}).get("message") if isinstance(obj, dict) else None
        if isinstance(msg, str):
            return msg[:300]
    except (json.JSONDecodeError, AttributeError):
        pass
    return body[:300].strip()
