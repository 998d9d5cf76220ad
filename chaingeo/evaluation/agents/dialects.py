"""Dialects: how a model's turn (its text and native tool calls) becomes a :class:`Reply`.

Every door reads replies here, so a model speaks the same language to ``chain eval``, the
verifiers game, the inspect_ai task and the environment server. A dialect is registered once
(:data:`DIALECTS` refuses a second one under a taken name) with its two system prompts and its
reader. Built in:

- ``text``: the action between ``<action>`` and ``</action>`` (one-shot: a ``<plan>`` block),
  the original benchmark's format; tool calls are ignored.
- ``tools``: native tool calls, one per action, played in order (translated to action text by
  :mod:`chaingeo.evaluation.agents.tools`); a reply with no call falls back to ``text``.

What the action text itself may say (our words, CHAIN's JSON calls, turns) is the environment's
grammar (:mod:`chaingeo.envs.actions.parse`), the same in every dialect.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from chaingeo.core import limits
from chaingeo.core.registry import Registry
from chaingeo.evaluation.agents.base import Reply, ToolCall
from chaingeo.evaluation.agents.prompt import (
    ONESHOT_PROMPT,
    ONESHOT_TOOLS_PROMPT,
    SYSTEM_PROMPT,
    TOOLS_PROMPT,
    extract_action,
    extract_plan,
)
from chaingeo.evaluation.agents.tools import translate
from chaingeo.evaluation.usage import Usage

#: Reads (text, translated calls, one-shot?) into the reply's action(s) and note.
Reader = Callable[[str, Sequence[ToolCall], bool], "Reading"]


@dataclass(frozen=True)
class Reading:
    actions: tuple[str, ...]
    note: str | None = None
    calls: tuple[ToolCall, ...] = ()


@dataclass(frozen=True)
class Dialect:
    name: str
    interactive_prompt: str
    oneshot_prompt: str
    read: Reader
    uses_tools: bool = False

    def system_prompt(self, oneshot: bool) -> str:
        return self.oneshot_prompt if oneshot else self.interactive_prompt


DIALECTS: Registry[Dialect] = Registry("dialect")


def register_dialect(dialect: Dialect) -> Dialect:
    """Add a dialect; a name already taken raises :class:`DuplicateNameError`."""
    return DIALECTS.register(dialect.name, dialect)


def _read_text(text: str, calls: Sequence[ToolCall], oneshot: bool) -> Reading:
    if oneshot:
        actions, note = extract_plan(text)
        return Reading(actions, note)
    action, note = extract_action(text)
    return Reading((action,) if action is not None else (), note)


def _read_tools(text: str, calls: Sequence[ToolCall], oneshot: bool) -> Reading:
    if calls:
        kept = tuple(calls[: limits.MAX_TOOL_CALLS])
        return Reading(tuple(c.action for c in kept), None, kept)
    reading = _read_text(text, (), oneshot)
    if not reading.actions and reading.note and reading.note.startswith("no <action>"):
        return Reading((), "your reply called no tool and had no <action>...</action>")
    return reading


register_dialect(Dialect("text", SYSTEM_PROMPT, ONESHOT_PROMPT, _read_text))
register_dialect(Dialect("tools", TOOLS_PROMPT, ONESHOT_TOOLS_PROMPT, _read_tools, uses_tools=True))


def read_reply(
    dialect: str,
    text: str,
    calls: Sequence[ToolCall] = (),
    *,
    oneshot: bool = False,
    usage: Usage | None = None,
    reasoning: str | None = None,
) -> Reply:
    """The :class:`Reply` of one model turn in ``dialect``: in one-shot, the whole plan; in
    interactive play, its action (or its calls' actions, to be taken in order). Text that holds
    no action gives a reply with none and a note saying why; nothing here raises on it."""
    reading = DIALECTS.get(dialect).read(text, calls, oneshot)
    first = reading.actions[0] if reading.actions and not oneshot else None
    many = reading.actions if oneshot or len(reading.actions) > 1 or reading.calls else ()
    return Reply(
        text,
        first,
        usage or Usage(),
        actions=many,
        note=reading.note,
        reasoning=reasoning,
        calls=reading.calls,
    )


def tool_call(
    call_id: str, name: Any, arguments: Any, offered: Sequence[Mapping[str, Any]]
) -> ToolCall:
    """One native call as a model made it (arguments as JSON text or already decoded),
    translated against the functions ``offered``; a malformed one reads as unparseable."""
    if isinstance(arguments, str):
        shown = arguments
    else:
        try:
            shown = json.dumps(arguments if arguments is not None else {})
        except (TypeError, ValueError):
            shown = "{}"
    action = translate(name, arguments, offered).action
    return ToolCall(call_id, name if isinstance(name, str) else str(name), shown, action)


def wire_tool_calls(
    raw: Any, offered: Sequence[Mapping[str, Any]], id_prefix: str
) -> tuple[ToolCall, ...]:
    """The calls of an OpenAI-format assistant message (``tool_calls``), each translated (a call
    without an id gets ``{id_prefix}_{i}``); at most
    :data:`~chaingeo.core.limits.MAX_TOOL_CALLS`, the rest dropped unplayed."""
    if not isinstance(raw, list):
        return ()
    out: list[ToolCall] = []
    for i, call in enumerate(raw[: limits.MAX_TOOL_CALLS]):
        call = call if isinstance(call, dict) else {}
        fn = call.get("function")
        fn = fn if isinstance(fn, dict) else {}
        cid = call.get("id")
        if not isinstance(cid, str) or not cid:
            cid = f"{id_prefix}_{i}"
        out.append(tool_call(cid, fn.get("name"), fn.get("arguments"), offered))
    return tuple(out)
