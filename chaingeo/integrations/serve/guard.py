"""The ASGI layer in front of OpenEnv's app: everything a client sends is measured here first.

Checked before any parsing or work: the bearer token (header, or the player's cookie), the
path (only the routes this server offers), the size and nesting of an HTTP body or WebSocket
frame, a session's messages and bytes in all (:mod:`chaingeo.core.limits`), the message type
(OpenEnv's ``reset``/``step``/``state``/``close``), and a browser's ``Origin`` (same host only).
A frame that fails is answered with an OpenEnv error frame and never reaches the session, so
the session stays as it was; an HTTP request that fails gets its 4xx and a JSON error.
"""

from __future__ import annotations

import asyncio
import contextlib
import hmac
import json
import re
from collections.abc import Awaitable, Callable, MutableMapping
from http.cookies import SimpleCookie
from typing import Any, Final
from urllib.parse import parse_qs, urlsplit

from starlette.websockets import WebSocketDisconnect

from chaingeo.core import limits
from chaingeo.core.errors import ChainGeoError
from chaingeo.integrations.serve.errors import (
    AuthError,
    NotFoundError,
    RequestError,
    ServeError,
    SessionLimitError,
    TooLargeError,
)

Scope = MutableMapping[str, Any]
Message = MutableMapping[str, Any]
Receive = Callable[[], Awaitable[Message]]
Send = Callable[[Message], Awaitable[None]]
ASGIApp = Callable[[Scope, Receive, Send], Awaitable[None]]

COOKIE: Final = "chain_token"
#: The paths this server answers (OpenEnv's simulation routes, its docs, the player).
ROUTES: Final = re.compile(
    r"/(|health|reset|step|state|schema|metadata|levels|ws|docs|redoc|openapi\.json|"
    r"play/[A-Za-z0-9._-]{1,200}|static/[A-Za-z0-9._-]{1,100})"
)
WS_TYPES: Final = frozenset({"reset", "step", "state", "close"})
PUBLIC: Final = frozenset({"/health"})


def error_body(exc: ServeError) -> bytes:
    return json.dumps({"error": {"type": type(exc).__name__, "message": exc.reason}}).encode()


def _headers(scope: Scope) -> dict[str, str]:
    return {k.decode("latin-1").lower(): v.decode("latin-1") for k, v in scope.get("headers", [])}


class Guard:
    """Wraps the app; ``token`` None means no authentication (the default, on 127.0.0.1)."""

    def __init__(
        self,
        app: ASGIApp,
        token: str | None = None,
        idle_seconds: float = limits.SESSION_IDLE_SECONDS,
    ) -> None:
        self.app, self.token, self.idle_seconds = app, token, idle_seconds

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        kind = scope["type"]
        if kind == "lifespan":
            await self.app(scope, receive, send)
            return
        path = scope.get("path", "")
        headers = _headers(scope)
        try:
            if not ROUTES.fullmatch(path):
                raise NotFoundError(f"no route {path[:100]!r}")
            if kind == "websocket":
                _same_origin(headers)
            if path not in PUBLIC:
                self._authorise(scope, headers)
        except ServeError as e:
            await (_refuse_ws(send, e) if kind == "websocket" else _respond(send, e))
            return
        if kind == "websocket":
            # OpenEnv closes a socket its client already closed: nothing to say
            with contextlib.suppress(WebSocketDisconnect):
                check = _FrameCheck(receive, send, self.idle_seconds)
                await self.app(scope, check.receive, send)
            return
        if self.token is not None and await _login(scope, send, self.token):
            return
        await self._http(scope, receive, send, headers)

    def _authorise(self, scope: Scope, headers: dict[str, str]) -> None:
        if self.token is None:
            return
        given = ""
        auth = headers.get("authorization", "")
        if auth.lower().startswith("bearer "):
            given = auth[7:].strip()
        if not given and "cookie" in headers:
            jar: SimpleCookie = SimpleCookie()
            try:
                jar.load(headers["cookie"])
            except Exception:
                jar = SimpleCookie()
            if COOKIE in jar:
                given = jar[COOKIE].value
        if not given:
            given = _query_token(scope) or ""
        if not hmac.compare_digest(given.encode(), self.token.encode()):
            raise AuthError("a bearer token is required (Authorization: Bearer TOKEN)")

    async def _http(
        self, scope: Scope, receive: Receive, send: Send, headers: dict[str, str]
    ) -> None:
        """Read the body within the limit, check its nesting, then hand it on."""
        try:
            declared = int(headers.get("content-length", "0") or 0)
        except ValueError:
            declared = -1
        try:
            if declared < 0 or declared > limits.MAX_REQUEST_BYTES:
                raise TooLargeError(f"a request body of at most {limits.MAX_REQUEST_BYTES} bytes")
            body, more = bytearray(), True
            while more:
                message = await receive()
                if message["type"] != "http.request":
                    return  # the client left
                body += message.get("body", b"")
                more = bool(message.get("more_body"))
                if len(body) > limits.MAX_REQUEST_BYTES:
                    raise TooLargeError(
                        f"a request body of at most {limits.MAX_REQUEST_BYTES} bytes"
                    )
            _check_json(bytes(body))
        except ServeError as e:
            await _respond(send, e)
            return
        sent = False

        async def replay() -> Message:
            nonlocal sent
            if sent:
                return await receive()
            sent = True
            return {"type": "http.request", "body": bytes(body), "more_body": False}

        await self.app(scope, replay, _secure(send, scope.get("path", "")))


def _check_json(body: bytes) -> None:
    """Bodies are JSON or empty; nesting past the limit is refused before any parser recurses."""
    if not body.strip():
        return
    try:
        text = body.decode("utf-8")
    except UnicodeDecodeError:
        raise RequestError("the body is not UTF-8 text") from None
    depth = limits.json_depth(text)
    if depth > limits.MAX_JSON_DEPTH:
        raise RequestError(f"JSON nested {depth} deep; at most {limits.MAX_JSON_DEPTH}")


def _query_token(scope: Scope) -> str | None:
    query = parse_qs(scope.get("query_string", b"").decode("latin-1"))
    values = query.get("token")
    return values[0] if values else None


async def _login(scope: Scope, send: Send, token: str) -> bool:
    """A browser's first visit with ``?token=``: the token goes into a cookie (HttpOnly,
    SameSite=Strict) and the page reloads without it, so it stays out of the address bar."""
    given = _query_token(scope)
    if given is None or (not scope.get("path", "").startswith("/play/") and scope["path"] != "/"):
        return False
    if not hmac.compare_digest(given.encode(), token.encode()):
        return False
    cookie = f"{COOKIE}={token}; HttpOnly; SameSite=Strict; Path=/"
    await send(
        {
            "type": "http.response.start",
            "status": 303,
            "headers": [(b"location", scope["path"].encode()), (b"set-cookie", cookie.encode())],
        }
    )
    await send({"type": "http.response.body", "body": b""})
    return True


def _same_origin(headers: dict[str, str]) -> None:
    """A browser always sends ``Origin`` on a WebSocket: it must name this very host, so no
    other site's page can open a session with the player's cookie."""
    origin = headers.get("origin")
    if origin is None:
        return
    if urlsplit(origin).netloc != headers.get("host", ""):
        raise AuthError("WebSocket connections from another origin are refused")


#: Headers of every HTTP answer: the player's pages run only their own scripts, and nothing
#: from a level file or a feedback line can ever be markup (the page sets text, never HTML).
SECURITY_HEADERS: Final = [
    (
        b"content-security-policy",
        b"default-src 'self'; img-src 'self' data:; style-src 'self'; script-src 'self'; "
        b"connect-src 'self'; object-src 'none'; base-uri 'none'; frame-ancestors 'none'",
    ),
    (b"x-content-type-options", b"nosniff"),
    (b"referrer-policy", b"no-referrer"),
]


def _secure(send: Send, path: str) -> Send:
    docs = path in ("/docs", "/redoc")  # FastAPI's documentation pages load their own scripts

    async def wrapped(message: Message) -> None:
        if message["type"] == "http.response.start" and not docs:
            message = dict(message)
            message["headers"] = [*message.get("headers", []), *SECURITY_HEADERS]
        await send(message)

    return wrapped


async def _respond(send: Send, exc: ServeError) -> None:
    body = error_body(exc)
    await send(
        {
            "type": "http.response.start",
            "status": exc.status,
            "headers": [(b"content-type", b"application/json"), *SECURITY_HEADERS],
        }
    )
    await send({"type": "http.response.body", "body": body})


async def _refuse_ws(send: Send, exc: ServeError) -> None:
    """Refuse a WebSocket before it opens (the client sees HTTP 403 and the reason)."""
    await send({"type": "websocket.close", "code": 1008, "reason": str(exc)[:120]})


def ws_error(message: str) -> str:
    """An OpenEnv error frame (its client raises ``RuntimeError`` with the message)."""
    return json.dumps({"type": "error", "data": {"message": message, "code": "VALIDATION_ERROR"}})


class _FrameCheck:
    """A WebSocket's ``receive`` that answers bad frames itself and passes only good ones on;
    a session silent for ``idle`` seconds is told the client left (OpenEnv then closes the
    session and the socket)."""

    def __init__(self, receive: Receive, send: Send, idle: float) -> None:
        self._receive, self._send, self.idle = receive, send, idle
        self.messages = 0
        self.bytes = 0
        self.opened = False

    async def receive(self) -> Message:
        while True:
            if not self.opened:  # the handshake waits for no timer
                self.opened = True
                return await self._receive()
            try:
                message = await asyncio.wait_for(self._receive(), timeout=self.idle)
            except TimeoutError:
                return {"type": "websocket.disconnect", "code": 1001}
            if message["type"] != "websocket.receive":
                return message
            problem = self._problem(message)
            if problem is None:
                return message
            await self._send({"type": "websocket.send", "text": ws_error(str(problem))})

    def _problem(self, message: Message) -> ServeError | None:
        text, data = message.get("text"), message.get("bytes")
        size = len(data) if data is not None else len((text or "").encode("utf-8", "replace"))
        self.messages += 1
        self.bytes += size
        if self.messages > limits.MAX_SESSION_MESSAGES or self.bytes > limits.MAX_SESSION_BYTES:
            return SessionLimitError(
                f"this session has sent {limits.MAX_SESSION_MESSAGES} messages or "
                f"{limits.MAX_SESSION_BYTES} bytes; open a new one"
            )
        if text is None:
            return RequestError("frames are JSON text, not binary")
        if size > limits.MAX_REQUEST_BYTES:
            return RequestError(f"a frame of at most {limits.MAX_REQUEST_BYTES} bytes")
        try:
            parsed = limits.loads_bounded(text)
        except (ChainGeoError, ValueError, RecursionError) as e:
            return RequestError(f"not a JSON message: {str(e)[:200]}")
        if not isinstance(parsed, dict) or parsed.get("type") not in WS_TYPES:
            return RequestError('a message is {"type": "reset" | "step" | "state" | "close", ...}')
        if not isinstance(parsed.get("data", {}), dict):
            return RequestError("a message's data is a JSON object")
        return None
