"""A chat harness that runs in-process: one chat completion per segment, no program to install.

verifiers' built-in ``null`` harness launches a script under ``uv`` (which it may download);
ours posts the conversation straight to the rollout's interception endpoint, which is all a
harness must do (``Harness.launch``: "a harness may run its loop in-process ... as long as every
model call goes through endpoint + secret"). It offers the model the task's own tools (our
action functions, when the taskset has ``tools``) and no MCP servers: the environment reads the
calls and answers each with a ``tool`` message (:class:`~chaingeo.integrations.game.Game`).
Any other harness (``--env.agent.harness.id null``) plays the same environment in text.
"""

from __future__ import annotations

import ssl
from functools import cache
from typing import Any, Literal

import httpx
import verifiers.v1 as vf
from verifiers.v1.dialects.chat import message_to_wire
from verifiers.v1.errors import MODEL_TRANSPORT_ERROR_EXIT_CODE
from verifiers.v1.runtimes import ProgramResult

from chaingeo.integrations.game import recent

#: Seconds one model call may take (a reasoning model's long answer included).
REQUEST_TIMEOUT = 600.0


class ChainGeoHarnessConfig(vf.HarnessConfig):  # type: ignore[misc]
    """What the model is shown; sampling and limits are the agent's config."""

    context: Literal["recent", "full"] = "recent"
    """``recent``: the latest observation only (its text keeps the last turns), plus the last
    reply's tool exchange, as ``chain eval`` asks; ``full``: the whole conversation, every
    turn's pictures included (long levels then outgrow a model's context)."""


class ChainGeoHarness(vf.Harness[ChainGeoHarnessConfig]):  # type: ignore[misc]
    """Relaunched each segment on the conversation so far (``SUPPORTS_RESUME``), of which it
    sends what its ``context`` says."""

    APPENDS_SYSTEM_PROMPT = True
    SUPPORTS_RESUME = True
    EXECUTES_CODE = False
    NEEDS_CONTAINER = False

    async def launch(
        self,
        ctx: Any,
        trace: Any,
        runtime: Any,
        endpoint: str,
        secret: str,
        mcp_urls: dict[str, str],
        data: Any,
        tool_interception_url: str | None = None,
    ) -> ProgramResult:
        system, prompt = self.resolve_prompt(data)
        messages = wire_messages(system, prompt, self.config.context == "recent")
        body: dict[str, Any] = {"model": ctx.model, "messages": messages}
        tools = getattr(data, "tools", None)
        if tools:
            body["tools"] = tools
        url = endpoint.rstrip("/") + "/chat/completions"
        headers = {"Authorization": f"Bearer {secret}"}
        try:
            async with httpx.AsyncClient(timeout=REQUEST_TIMEOUT, verify=_tls()) as client:
                answer = await client.post(url, json=body, headers=headers)
        except httpx.TransportError as e:
            return ProgramResult(MODEL_TRANSPORT_ERROR_EXIT_CODE, "", f"{type(e).__name__}: {e}")
        if answer.is_success:
            return ProgramResult(0, "", "")
        return ProgramResult(1, "", f"HTTP {answer.status_code}: {answer.text[-2000:]}")


@cache
def _tls() -> ssl.SSLContext:
    """One TLS context, httpx's default, for every segment's client (building one reads the
    certificate bundle, ~25 ms, more than a whole segment against a local endpoint)."""
    return httpx.create_ssl_context()


def wire_messages(system: str | None, prompt: Any, window: bool = True) -> list[dict[str, Any]]:
    """The chat-completions messages of a segment: the system prompt, then the conversation
    (verifiers messages or wire dicts; only its :func:`~chaingeo.integrations.game.recent`
    part with ``window``) or the prompt text."""
    out: list[dict[str, Any]] = [{"role": "system", "content": system}] if system else []
    if isinstance(prompt, str):
        return [*out, {"role": "user", "content": prompt}]
    said = [m if isinstance(m, dict) else message_to_wire(m) for m in prompt or []]
    return [*out, *(recent(said) if window else said)]
