"""The model agent: any OpenAI-compatible chat-completions server.

Options (all logged; the key is not an option): ``model``, ``base_url`` (default: env
``OPENAI_BASE_URL``, else ``https://api.openai.com/v1``), ``api_key_env`` (the variable holding
the key, default ``OPENAI_API_KEY``; a local server may need none), ``temperature`` 0.6 and
``top_p`` 0.95 (the paper's), ``max_tokens``, ``timeout`` (a wall-clock deadline per request),
``max_retries``, ``backoff_base``, ``retry_budget`` (seconds for all retries of one call, at most
:data:`~chaingeo.core.limits.MAX_RETRY_SECONDS`), ``tools``, ``model_options``, ``send_seed``
(pass a per-call seed to servers that accept one), ``image_detail``, ``views`` (subset of views
sent).

``tools`` is ``auto`` (default), ``on`` or ``off``. With tools the model is offered one function
per action kind (:mod:`chaingeo.evaluation.agents.tools`); each call it makes is one action, and
several calls in one reply are played in order (the harness stops at the first one rejected).
``auto`` falls back to text actions (``<action>...</action>``) for the rest of the episode when
the server refuses the request with HTTP 400 or 422 naming tools; the record says so
(:meth:`OpenAIAgent.notes`). A reply without a tool call is read as text either way.

``model_options`` (``chain eval --model-option KEY=VALUE``) are body fields passed through to
the server as given (``reasoning_effort``, ``max_completion_tokens``, ...; ``null`` removes a
default such as ``temperature``); their ``extra_body`` object is merged into the body as well
(``{"top_k": 20}``). The fields the agent owns (``model``, ``messages``, ``tools``, ``stream``)
cannot be set.

Text mode keeps each turn one stateless request (system prompt + the observation, whose history
already holds the last N turns). Tool mode adds the previous exchange only, which the chat format
needs to answer the calls: the previous observation (text), the assistant message with its tool
calls and one ``tool`` message per call with its result, so the context stays bounded and a run
can resume anywhere.
"""

from __future__ import annotations

import json
from collections.abc import Mapping, Sequence
from typing import Any, Final

from chaingeo.core.level import Level
from chaingeo.evaluation.agents.base import Agent, AgentError, Reply, ToolCall, Turn
from chaingeo.evaluation.agents.dialects import read_reply, wire_tool_calls
from chaingeo.evaluation.agents.http import ChatClient, RequestRejected, ServerSettings
from chaingeo.evaluation.agents.prompt import (
    ONESHOT_PROMPT,
    ONESHOT_TOOLS_PROMPT,
    SYSTEM_PROMPT,
    TOOLS_PROMPT,
    user_content,
)
from chaingeo.evaluation.agents.tools import skipped_result, tool_specs
from chaingeo.evaluation.usage import Usage

TOOL_SETTINGS: Final = ("auto", "on", "off")
#: Body fields the agent builds itself; model options may not replace them.
RESERVED_FIELDS: Final = frozenset({"model", "messages", "tools", "stream"})
#: The HTTP statuses with which a server refuses a field it does not support.
REFUSALS: Final = (400, 422)


def tools_setting(value: Any) -> str:
    """``auto``, ``on`` or ``off`` from an option value (``true``/``false`` mean on/off)."""
    if value is None:
        return "auto"
    if isinstance(value, bool):
        return "on" if value else "off"
    if isinstance(value, str) and value.lower() in TOOL_SETTINGS:
        return value.lower()
    raise ValueError(f"tools must be one of auto, on, off; got {value!r}")


def provider_fields(model_options: Any) -> dict[str, Any]:
    """The body fields ``model_options`` pass through, checked: a JSON object of JSON values;
    its ``extra_body`` (an object, or the JSON text of one, read with ``json.loads`` only) is
    merged in after the others. A value of ``None`` removes that field from the body."""
    if model_options is None:
        return {}
    if not isinstance(model_options, Mapping):
        raise ValueError("model options must be an object of KEY: VALUE")
    out: dict[str, Any] = {}
    extra = model_options.get("extra_body")
    for key, value in model_options.items():
        if key != "extra_body":
            out[_field(key)] = value
    if isinstance(extra, str):
        try:
            extra = json.loads(extra)
        except json.JSONDecodeError as e:
            raise ValueError(f"extra_body is not JSON: {e}") from None
    if extra is not None:
        if not isinstance(extra, Mapping):
            raise ValueError("extra_body must be a JSON object, e.g. '{\"top_k\": 20}'")
        for key, value in extra.items():
            out[_field(key)] = value
    try:
        json.dumps(out, allow_nan=False)
    except (TypeError, ValueError) as e:
        raise ValueError(f"model options must be JSON values: {e}") from None
    return out


def _field(key: Any) -> str:
    if not isinstance(key, str) or not key:
        raise ValueError(f"a model option needs a name, got {key!r}")
    if key in RESERVED_FIELDS:
        raise ValueError(f"the agent sets {key!r} itself; it cannot be a model option")
    return key


class OpenAIAgent(Agent):
    name = "openai"

    def __init__(self, options: Mapping[str, Any], secrets: Mapping[str, str]) -> None:
        if not options.get("model"):
            raise ValueError("the openai agent needs a model name (--model)")
        self.options = dict(options)
        self.model = str(options["model"])
        self.server = ServerSettings.from_options(options, secrets)
        self.uses_images = bool(options.get("images", True))
        self.tools = tools_setting(options.get("tools"))
        self.fields = provider_fields(options.get("model_options"))
        self._client: ChatClient | None = None
        self._seed = 0
        self._native = self.tools != "off"
        self._refused: str | None = None
        self._act_tools: list[dict[str, Any]] = []
        self._plan_tools: list[dict[str, Any]] = []
        self._shown: dict[int, str] = {}  # turn index -> the observation text sent that turn

    def start(self, level: Level, seed: int) -> None:
        self._seed = seed
        self._client = self.server.client(seed)
        self._native = self.tools != "off"
        self._refused = None
        self._act_tools = tool_specs(level)
        self._plan_tools = tool_specs(level, state=False)
        self._shown = {}

    def notes(self) -> dict[str, Any]:
        out: dict[str, Any] = {"tool_mode": "native" if self._native else "text"}
        if self._refused:
            out["tools_refused"] = self._refused
        return out

    # -- requests -----------------------------------------------------------------------------

    def _messages(self, system: str, turn: Turn, native: bool) -> list[dict[str, Any]]:
        assert turn.observation is not None
        views = self.options.get("views")
        content = user_content(
            turn.observation,
            turn.last_feedback,
            views=list(views) if views else None,
            image_detail=self.options.get("image_detail"),
        )
        before = self._shown.get(turn.index - 1)  # kept for the next turn's tool history
        self._shown = {turn.index: str(content[0]["text"])}
        if before is not None:
            self._shown[turn.index - 1] = before
        messages: list[dict[str, Any]] = [{"role": "system", "content": system}]
        prev = turn.previous
        if native and prev is not None and prev.calls and before is not None:
            messages.append({"role": "user", "content": before})
            messages.append(_assistant_message(prev))
            messages += _tool_results(prev, turn.results)
        messages.append({"role": "user", "content": content})
        return messages

    def _body(
        self, system: str, turn: Turn, tools: Sequence[dict[str, Any]] | None
    ) -> dict[str, Any]:
        body: dict[str, Any] = {
            "model": self.model,
            "messages": self._messages(system, turn, tools is not None),
            "temperature": float(self.options.get("temperature", 0.6)),
            "top_p": float(self.options.get("top_p", 0.95)),
        }
        if self.options.get("max_tokens"):
            body["max_tokens"] = int(self.options["max_tokens"])
        if self.options.get("send_seed"):
            body["seed"] = (self._seed * 1_000_003 + turn.index * 101 + turn.candidate) % 2**31
        if tools is not None:
            body["tools"] = list(tools)
        for key, value in self.fields.items():
            if value is None:
                body.pop(key, None)
            else:
                body[key] = value
        return body

    def _complete(
        self, turn: Turn, prompts: tuple[str, str], tools: Sequence[dict[str, Any]]
    ) -> dict[str, Any]:
        """One answer: with the tools while they are on, else (or once refused) in text."""
        if self._client is None:
            raise AgentError("start() was not called")
        text_prompt, tools_prompt = prompts
        if not self._native:
            return self._client.complete(self._body(text_prompt, turn, None))
        try:
            return self._client.complete(self._body(tools_prompt, turn, tools))
        except RequestRejected as e:
            if self.tools != "auto" or e.status not in REFUSALS or "tool" not in e.detail.lower():
                raise
            self._native, self._refused = False, f"HTTP {e.status} {e.detail}"
        return self._client.complete(self._body(text_prompt, turn, None))

    def _read(
        self, answer: Mapping[str, Any], turn: Turn, tools: Sequence[dict[str, Any]]
    ) -> tuple[str, str | None, tuple[ToolCall, ...], Usage]:
        """The parts of an answer the client checked (:func:`protocol.check_answer`)."""
        message = answer["choices"][0]["message"]
        text = _content_text(message.get("content"))
        reasoning = message.get("reasoning_content") or message.get("reasoning")
        prefix = f"call_{turn.index}_{turn.candidate}"
        calls = wire_tool_calls(message.get("tool_calls"), tools, prefix) if self._native else ()
        usage = Usage.from_openai(answer.get("usage"))
        return text, reasoning if isinstance(reasoning, str) else None, calls, usage

    # -- the protocols ------------------------------------------------------------------------

    def act(self, turn: Turn) -> Reply:
        answer = self._complete(turn, (SYSTEM_PROMPT, TOOLS_PROMPT), self._act_tools)
        return self._reply(answer, turn, self._act_tools, oneshot=False)

    def plan(self, turn: Turn) -> Reply:
        answer = self._complete(turn, (ONESHOT_PROMPT, ONESHOT_TOOLS_PROMPT), self._plan_tools)
        return self._reply(answer, turn, self._plan_tools, oneshot=True)

    def _reply(
        self, answer: Mapping[str, Any], turn: Turn, tools: Sequence[dict[str, Any]], oneshot: bool
    ) -> Reply:
        text, reasoning, calls, usage = self._read(answer, turn, tools)
        dialect = "tools" if self._native else "text"
        return read_reply(dialect, text, calls, oneshot=oneshot, usage=usage, reasoning=reasoning)


def _content_text(content: Any) -> str:
    if isinstance(content, str):
        return content
    if isinstance(content, list):  # content parts
        return "".join(
            str(p.get("text", ""))
            for p in content
            if isinstance(p, dict) and p.get("type") == "text"
        )
    return ""


def _assistant_message(reply: Reply) -> dict[str, Any]:
    return {
        "role": "assistant",
        "content": reply.text or None,
        "tool_calls": [
            {
                "id": c.id,
                "type": "function",
                "function": {"name": c.name, "arguments": c.arguments},
            }
            for c in reply.calls
        ],
    }


def _tool_results(reply: Reply, results: Sequence[Any]) -> list[dict[str, Any]]:
    """One ``tool`` message per call: what it did, or that it was not executed."""
    rejected = len(results) - 1 if results and not results[-1].legal else None
    out = []
    for i, call in enumerate(reply.calls):
        if i < len(results):
            content = str(results[i].feedback)
        elif rejected is not None:
            content = skipped_result(rejected)
        else:
            content = "Not executed. Nothing changed."
        out.append({"role": "tool", "tool_call_id": call.id, "content": content})
    return out
