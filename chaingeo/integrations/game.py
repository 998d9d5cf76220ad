"""One level played in chat turns: the part of a training environment that is ours.

A :class:`Game` holds a level's state machine and speaks chat messages (OpenAI wire dicts): it
opens with the observation (text, and the views as base64 PNG parts when ``images``), reads each
assistant reply in the harness's text dialect (:mod:`chaingeo.evaluation.agents.prompt`) and
answers with the next observation, until the level is solved, the agent says ``finish`` or the
step budget is spent. It never sees a framework, so it is tested without one and a framework
adapter (:mod:`chaingeo.integrations.verifiers`) only moves its messages.

Protocols, as in :mod:`chaingeo.evaluation.episode`: ``interactive`` takes one action per reply
(an unreadable reply still costs its step); ``oneshot`` shows one view once and runs the whole
``<plan>`` of the first reply with no feedback. With ``tools`` the agent may also act by native
tool calls (:mod:`chaingeo.evaluation.agents.tools`: one function per action kind, translated to
action text): a reply's calls are played in order, each a step, stopping at the first one
rejected, and each gets its ``tool`` result before the next observation.

Rewards (each in [0, 1], computed from :class:`Outcome` as :mod:`chaingeo.evaluation.metrics`
does for a run): :func:`success_reward`, :func:`efficiency_reward` (``1 - NormDist`` of this
episode when solved) and :func:`format_reward` (the share of replies the environment could read).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import asdict, dataclass
from typing import Any, Final, Literal

from chaingeo.core import limits
from chaingeo.core.level import Level
from chaingeo.envs.machines import new_state
from chaingeo.envs.machines.state import StepResult
from chaingeo.envs.observation import observe
from chaingeo.evaluation.agents.prompt import (
    ONESHOT_PROMPT,
    ONESHOT_TOOLS_PROMPT,
    SYSTEM_PROMPT,
    TOOLS_PROMPT,
    extract_action,
    extract_plan,
    user_content,
)
from chaingeo.evaluation.agents.tools import skipped_result, tool_specs, translate
from chaingeo.evaluation.episode import AUXILIARY_VIEWS

Protocol = Literal["interactive", "oneshot"]
PROTOCOLS: Final[tuple[Protocol, ...]] = ("interactive", "oneshot")
Message = dict[str, Any]
#: A native tool call as a model made it: id, function name, arguments (JSON text).
Call = tuple[str, str, str]

#: Default reward weights: an optimal, well-formed episode sums to 1, a nonsense one to 0.
DEFAULT_WEIGHTS: Final[dict[str, float]] = {"success": 0.5, "efficiency": 0.4, "format": 0.1}


@dataclass(frozen=True)
class Outcome:
    """What the rewards need of one episode (JSON-able: it rides on a framework's trace)."""

    level_id: str
    optimal_steps: int
    success: bool
    steps: int
    actions: int
    readable: int
    finished: bool
    truncated: bool

    def to_json(self) -> dict[str, Any]:
        return asdict(self)

    @classmethod
    def from_json(cls, data: Any) -> Outcome | None:
        """The outcome a trace carries; None when the episode never got one (it errored)."""
        if not isinstance(data, dict):
            return None
        try:
            return cls(**data)
        except TypeError:
            return None


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
    if protocol == "interactive":
        return TOOLS_PROMPT if tools else SYSTEM_PROMPT
    return ONESHOT_TOOLS_PROMPT if tools else ONESHOT_PROMPT


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
    """A level's state machine behind a chat: :meth:`opening`, then :meth:`answer` per reply."""

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
        self.level, self.protocol, self.images = level, protocol, images
        self.history_window, self.oneshot_view = history_window, oneshot_view
        self.tools = offered_tools(level, protocol) if tools else []
        self.state = new_state(level)
        self.actions = 0
        self.readable = 0
        self.over = False

    def _user(self, note: str | None = None) -> Message:
        oneshot = self.protocol == "oneshot"
        obs = observe(self.state, 0 if oneshot else self.history_window, images=self.images)
        views = (self.oneshot_view, *AUXILIARY_VIEWS) if oneshot else None
        return {"role": "user", "content": user_content(obs, note, views=views)}

    def opening(self) -> Message:
        """The first user turn: the task, the pieces, the budget and (with images) the views."""
        return self._user()

    def _ended(self) -> bool:
        s = self.state
        return bool(s.is_success() or s.is_truncated() or s.finished)

    def _step(self, text: str) -> StepResult:
        """Play one action text (one step, whatever it was)."""
        result = self.state.step_text(text)
        self.actions += 1
        self.readable += int(result.error != "unparseable")
        return result

    def _calls(self, calls: Sequence[Call]) -> list[str]:
        """The action text of each call (a malformed one, or one that is not an (id, name,
        arguments) triple, reads as unparseable)."""
        return [translate(*_name_args(call), self.tools).action for call in calls]

    def answer(self, reply: str, calls: Sequence[Call] = ()) -> list[Message] | None:
        """Play ``reply`` (its tool calls, when tools are offered and it made any, else its
        text); the next user turn's messages, or None once the episode is over."""
        if self.over:
            raise RuntimeError("the episode is over")
        reply = reply_text(reply)
        calls = list(calls) if self.tools and isinstance(calls, list | tuple) else []
        if self.protocol == "oneshot":
            plan = self._calls(calls[: limits.MAX_TOOL_CALLS]) if calls else extract_plan(reply)[0]
            for text in plan:
                if self._ended():
                    break
                self._step(text)
            self.actions = max(1, self.actions)  # no plan at all is one unreadable action
            self.over = True
            return None
        if calls:
            return self._play_calls(calls)
        action, note = extract_action(reply)
        self._step(action or "")
        return self._next([], note)

    def _play_calls(self, calls: Sequence[Any]) -> list[Message] | None:
        """Each call in order until one is rejected (or the game ends; at most
        :data:`~chaingeo.core.limits.MAX_TOOL_CALLS`); one ``tool`` message per call, played or
        not (the chat protocol wants every call answered), then the next observation."""
        feedback: list[str] = []
        legal = True
        for text in self._calls(calls[: limits.MAX_TOOL_CALLS]):
            if self._ended() or not legal:
                break
            result = self._step(text)
            feedback.append(result.feedback)
            legal = result.legal
        rejected = None if legal else len(feedback) - 1
        skipped = "Not executed. Nothing changed." if rejected is None else skipped_result(rejected)
        answers = [
            {"role": "tool", "tool_call_id": _call_id(call), "content": text}
            for call, text in zip(calls, feedback + [skipped] * len(calls), strict=False)
        ]
        return self._next(answers, None)

    def _next(self, before: list[Message], note: str | None) -> list[Message] | None:
        if self._ended():
            self.over = True
            return None
        return [*before, self._user(note)]

    def outcome(self) -> Outcome:
        s = self.state
        return Outcome(
            level_id=self.level.id,
            optimal_steps=self.level.optimal_steps,
            success=bool(s.is_success()),
            steps=int(s.steps_used),
            actions=self.actions,
            readable=self.readable,
            finished=bool(s.finished),
            truncated=bool(s.is_truncated()) and not s.is_success(),
        )


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
    if isinstance(call, list | tuple) and len(call) == 3:
        return call[1], call[2]
    return None, None


def _call_id(call: Any) -> str:
    found = call[0] if isinstance(call, list | tuple) and call else ""
    return found if isinstance(found, str) else ""
