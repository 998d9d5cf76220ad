"""What a chat-completions answer must be before anything reads it.

A server that answers outside the protocol (``{"choices": [1]}``, a message that is text, content
that is a number or an object, usage counts of 400 digits, a body of many megabytes) is at fault,
not the model: its answer raises :class:`ProtocolError`, which the client retries like other
server faults and the episode records as a server error (``status: error``, ``error_type:
ProtocolError``) instead of scoring the model an unparseable step. The model's own mistakes (text
without an action, a malformed tool call, a reply cut off by ``max_tokens``) stay steps.

Parsing is bounded by :mod:`chaingeo.core.limits`: bytes of the body, nesting, digits of every
integer; ``NaN``/``Infinity`` are refused.
"""

from __future__ import annotations

import json
from typing import Any, Final

from chaingeo.core import limits
from chaingeo.core.errors import ChainGeoError
from chaingeo.evaluation.agents.base import AgentError
from chaingeo.evaluation.usage import Usage, UsageError

#: Why a choice may carry no content and no call: the model ran out of tokens or was filtered
#: (the model's empty reply, an unparseable step, not the server's fault).
MODEL_STOPS: Final = frozenset({"length", "content_filter"})


class ProtocolError(AgentError):
    """The server's answer broke the chat-completions protocol (shape, types, bounds)."""


class _ReplyTooLong(ChainGeoError, ValueError):
    pass


def _int(literal: str) -> int:
    if len(literal.lstrip("-")) > limits.MAX_ANSWER_INT_DIGITS:
        raise _ReplyTooLong(literal)
    return int(literal)


def _constant(name: str) -> Any:
    raise ValueError(f"{name} is not JSON")


def _kind(value: Any) -> str:
    if value is None:
        return "null"
    return {bool: "a boolean", int: "a number", float: "a number", str: "text", list: "a list"}.get(
        type(value), "an object"
    )


def parse_answer(raw: bytes) -> Any:
    """The decoded body of a 2xx answer; :class:`ProtocolError` past a bound or not JSON."""
    if len(raw) > limits.MAX_ANSWER_BYTES:
        raise ProtocolError(f"the answer is larger than {limits.MAX_ANSWER_BYTES} bytes")
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError:
        raise ProtocolError("the answer is not UTF-8") from None
    depth = limits.json_depth(text)
    if depth > limits.MAX_JSON_DEPTH:
        raise ProtocolError(f"the answer is JSON nested {depth} deep")
    try:
        return json.loads(text, parse_int=_int, parse_constant=_constant)
    except _ReplyTooLong as e:
        raise ProtocolError(
            f"the answer holds a number of {len(str(e))} digits; at most"
            f" {limits.MAX_ANSWER_INT_DIGITS}"
        ) from None
    except (ValueError, RecursionError):
        raise ProtocolError("the server answered with malformed JSON") from None


def _check_calls(calls: Any) -> None:
    if calls is None:
        return
    if not isinstance(calls, list):
        raise ProtocolError(f"message.tool_calls is {_kind(calls)}, not a list")
    for i, call in enumerate(calls):
        if not isinstance(call, dict) or not isinstance(call.get("function"), dict):
            raise ProtocolError(f"message.tool_calls[{i}] is not an object with a 'function'")


def _check_content(content: Any) -> None:
    if content is None or isinstance(content, str):
        return
    if isinstance(content, list):  # content parts
        for i, part in enumerate(content):
            text = part.get("text", "") if isinstance(part, dict) else None
            if not isinstance(text, str):
                raise ProtocolError(f"message.content[{i}] is not a content part")
        return
    raise ProtocolError(f"message.content is {_kind(content)}, not text")


def check_answer(answer: Any) -> None:
    """:class:`ProtocolError` unless ``answer`` is a chat completion whose first choice holds a
    message (content text, parts or null; tool calls a list of calls) and a valid usage block."""
    if not isinstance(answer, dict):
        raise ProtocolError(f"the answer is {_kind(answer)}, not an object")
    choices = answer.get("choices")
    if not isinstance(choices, list):
        raise ProtocolError("the server's answer has no 'choices' list")
    if not choices:
        raise ProtocolError("the server's answer has an empty 'choices' list")
    choice = choices[0]
    if not isinstance(choice, dict):
        raise ProtocolError(f"choices[0] is {_kind(choice)}, not an object")
    message = choice.get("message")
    if not isinstance(message, dict):
        raise ProtocolError(f"choices[0].message is {_kind(message)}, not an object")
    _check_content(message.get("content"))
    _check_calls(message.get("tool_calls"))
    reasoning = [message.get(k) for k in ("reasoning_content", "reasoning")]
    if any(r is not None and not isinstance(r, str) for r in reasoning):
        raise ProtocolError("message reasoning is not text")
    empty = message.get("content") is None and not message.get("tool_calls") and not any(reasoning)
    if empty and choice.get("finish_reason") not in MODEL_STOPS:
        raise ProtocolError("choices[0].message has no content and no tool calls")
    try:
        Usage.from_openai(answer.get("usage"))
    except UsageError as e:
        raise ProtocolError(str(e)) from None
