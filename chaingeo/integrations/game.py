"""One level played in chat turns: the part of a training environment that is ours.

A :class:`Game` is the one :class:`~chaingeo.evaluation.episode.Episode` spoken in chat
messages (OpenAI wire dicts): it opens with the observation (text, and the views as base64 PNG
parts when ``images``), reads each assistant reply in its dialect
(:mod:`chaingeo.evaluation.agents.dialects`: ``text``, or ``tools`` for native tool calls with
text as a fallback) and answers with the next observation, until the episode is done. It never
sees a framework, so it is tested without one and a framework adapter
(:mod:`chaingeo.integrations.verifiers`) only moves its messages. A reply's tool calls each get
their ``tool`` result before the next observation.

Rewards (each in [0, 1], computed from the episode's
:class:`~chaingeo.evaluation.episode.Outcome` as :mod:`chaingeo.evaluation.metrics` does for a
run): :func:`success_reward`, :func:`efficiency_reward` (``1 - NormDist`` of this
episode when solved) and :func:`format_reward` (the share of replies the environment could read).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, Final, Literal

from chaingeo.core.level import Level
from chaingeo.evaluation.agents.base import ToolCall
from chaingeo.evaluation.agents.dialects import DIALECTS, read_reply, tool_call
from chaingeo.evaluation.agents.prompt import user_content
from chaingeo.evaluation.agents.tools import skipped_result, tool_specs
from chaingeo.evaluation.episode import (
    PROTOCOLS,
    Episode,
    EpisodeOverError,
    Outcome,
    ProtocolConfig,
)

Protocol = Literal["interactive", "oneshot"]
Message = dict[str, Any]
#: A native tool call as a model made it: id, function name, arguments (JSON text).
Call = tuple[str, str, str]

#: Default reward weights: an optimal, well-formed episode sums to 1, a nonsense one to 0.
DEFAULT_WEIGHTS: Final[dict[str, float]] = {"success": 0.5, "efficiency": 0.4, "format": 0.1}


def success_reward(o: Outcome | None) -> float:
    """1 when the level was solved (the paper's Pass@1 for one sample), else 0."""
    return 1.0 if o is not None and o.success else 0.0


def efficiency_reward(o: Outcome | None) -> float:
    """``1 - NormDist`` of a solved episode, ``NormDist = (steps - o) / max(1, o)`` with ``o``
    the optimal plan's length, floored at 0; 0 when not solved."""
    if o is None or not o.success:
        return 0.0
    return max(0.0, 1.0 - (o.steps - o.optimal_steps) / max(1, o.optimal_steps))


def format_reward(o: Outcome | None) -> float:
    """The share of the agent's actions the environment could read (the action tag or tool call
    was there and the action parsed, legal or not); 0 with no action at all."""
    if o is None or o.actions == 0:
        return 0.0
    return o.readable / o.actions


def system_prompt(protocol: Protocol, tools: bool = False) -> str:
    """The harness's system prompt for ``protocol`` (text dialect, or tools with text as a
    fallback)."""
    return DIALECTS.get("tools" if tools else "text").system_prompt(protocol == "oneshot")


def offered_tools(level: Level, protocol: Protocol) -> list[dict[str, Any]]:
    """The functions offered for ``level`` (no ``state`` in one-shot: it sees no result)."""
    return tool_specs(level, state=protocol == "interactive")


def scores(o: Outcome | None) -> dict[str, float]:
    """Every reward of an episode, by name (the names of :data:`DEFAULT_WEIGHTS`)."""
    return {
        "success": success_reward(o),
        "efficiency": efficiency_reward(o),
        "format": format_reward(o),
    }


def total_reward(o: Outcome | None, weights: dict[str, float] = DEFAULT_WEIGHTS) -> float:
    """The weighted sum of :func:`scores`, as a framework adds them up."""
    return sum(weights[k] * v for k, v in scores(o).items())


def recent(conversation: Sequence[Message]) -> list[Message]:
    """What a model is shown of a conversation, as :mod:`chaingeo.evaluation` shows it: the
    latest observation (which carries the recent turns as text), preceded, when the last reply
    made tool calls, by that reply and its tool results and the observation it answered, the
    latter without its pictures."""
    asked = [i for i, m in enumerate(conversation) if m.get("role") == "assistant"]
    if not asked or not conversation[asked[-1]].get("tool_calls"):
        return list(conversation[-1:])
    start = asked[-1]
    before = [m for m in conversation[:start] if m.get("role") == "user"][-1:]
    return [*(_text_only(m) for m in before), *conversation[start:]]


def _text_only(message: Message) -> Message:
    content = message.get("content")
    if not isinstance(content, list):
        return message
    texts = [p for p in content if p.get("type") == "text"]
    kept = [p for p in texts if not str(p.get("text", "")).startswith("View: ")]
    return {**message, "content": kept or texts}


class Game:
    """A level's episode behind a chat: :meth:`opening`, then :meth:`answer` per reply."""

    def __init__(
        self,
        level: Level,
        protocol: Protocol = "interactive",
        images: bool = True,
        history_window: int = 5,
        oneshot_view: str = "iso",
        tools: bool = False,
    ) -> None:
        if protocol not in PROTOCOLS:
            raise ValueError(f"unknown protocol {protocol!r}; use interactive or oneshot")
        config = ProtocolConfig(protocol, history_window=history_window, oneshot_view=oneshot_view)
        self.episode = Episode(level, config, images=images, keep_images=False)
        self.level, self.protocol = level, protocol
        self.tools = offered_tools(level, protocol) if tools else []
        self.dialect = "tools" if tools else "text"

    @property
    def state(self) -> Any:
        return self.episode.state

    def _user(self) -> Message:
        obs = self.episode.observation()
        return {"role": "user", "content": user_content(obs, self.episode.note)}

    def opening(self) -> Message:
        """The first user turn: the task, the pieces, the budget and (with images) the views."""
        return self._user()

    def answer(self, reply: str, calls: Sequence[Call] = ()) -> list[Message] | None:
        """Play ``reply`` (its tool calls, when tools are offered and it made any, else its
        text); the next user turn's messages, or None once the episode is over."""
        ep = self.episode
        if ep.done:
            raise EpisodeOverError(f"{self.level.id}: the episode is over")
        reply = reply_text(reply)
        given = list(calls) if isinstance(calls, list | tuple) else []
        made = tuple(tool_call(_call_id(c), *_name_args(c), self.tools) for c in given)
        results = ep.play(
            read_reply(self.dialect, reply, made if self.tools else (), oneshot=ep.oneshot)
        )
        answers: list[Message] = []
        if self.tools and made and not ep.oneshot:
            answers = _tool_messages(made, [r.feedback for r in results], results)
        if ep.done:
            return None
        return [*answers, self._user()]

    def outcome(self) -> Outcome:
        return self.episode.outcome()


def _tool_messages(
    calls: Sequence[ToolCall], feedback: list[str], results: Sequence[Any]
) -> list[Message]:
    """One ``tool`` message per call, played or not (the chat protocol wants every call
    answered): the played ones their feedback, the rest why they were skipped."""
    rejected = next((i for i, r in enumerate(results) if not r.legal), None)
    skipped = "Not executed. Nothing changed." if rejected is None else skipped_result(rejected)
    return [
        {"role": "tool", "tool_call_id": c.id, "content": (feedback + [skipped] * len(calls))[i]}
        for i, c in enumerate(calls)
    ]


def reply_text(reply: Any) -> str:
    """A reply's text: a string, or the text parts of OpenAI content parts (a list of
    ``{"type": "text", "text": ...}``); anything else reads as no text (an unreadable reply)."""
    if isinstance(reply, str):
        return reply
    if isinstance(reply, list):
        parts = [
            p["text"]
            for p in reply
            if isinstance(p, dict) and p.get("type") == "text" and isinstance(p.get("text"), str)
        ]
        return "\n".join(parts)
    return ""


def _name_args(call: Any) -> tuple[Any, Any]:
    """A call's function name and arguments; a call that is not an (id, name, arguments)
    triple reads as one with neither (translated as malformed: an unparseable step)."""
    if isinstance(call, list | tuple) and len(call) == 3:
        return call[1], call[2]
    return None, None


def _call_id(call: Any) -> str:
    found = call[0] if isinstance(call, list | tuple) and call else ""
    return found if isinstance(found, str) else ""
