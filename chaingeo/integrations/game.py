"""One level played in chat turns: the part of a training environment that is ours.

A :class:`Game` holds a level's state machine and speaks chat messages (OpenAI wire dicts): it
opens with the observation (text, and the views as base64 PNG parts when ``images``), reads each
assistant reply in the harness's text dialect (:mod:`chaingeo.evaluation.agents.prompt`) and
answers with the next observation, until the level is solved, the agent says ``finish`` or the
step budget is spent. It never sees a framework, so it is tested without one and a framework
adapter (:mod:`chaingeo.integrations.verifiers`) only moves its messages.

Protocols, as in :mod:`chaingeo.evaluation.episode`: ``interactive`` takes one action per reply
(an unreadable reply still costs its step); ``oneshot`` shows one view once and runs the whole
``<plan>`` of the first reply with no feedback.

Rewards (each in [0, 1], computed from :class:`Outcome` as :mod:`chaingeo.evaluation.metrics`
does for a run): :func:`success_reward`, :func:`efficiency_reward` (``1 - NormDist`` of this
episode when solved) and :func:`format_reward` (the share of replies the environment could read).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Any, Final, Literal

from chaingeo.core.level import Level
from chaingeo.envs.machines import new_state
from chaingeo.envs.observation import observe
from chaingeo.evaluation.agents.prompt import (
    ONESHOT_PROMPT,
    SYSTEM_PROMPT,
    extract_action,
    extract_plan,
    user_content,
)
from chaingeo.evaluation.episode import AUXILIARY_VIEWS

Protocol = Literal["interactive", "oneshot"]
PROTOCOLS: Final[tuple[Protocol, ...]] = ("interactive", "oneshot")
Message = dict[str, Any]

#: Default reward weights: an optimal, well-formed episode sums to 1, a nonsense one to 0.
DEFAULT_WEIGHTS: Final[dict[str, float]] = {"success": 0.5, "efficiency": 0.4, "format": 0.1}


@dataclass(frozen=True)
class Outcome:
    """What the rewards need of one episode (JSON-able: it rides on a framework's trace)."""

    level_id: str
    optimal_steps: int
    success: bool
    steps: int
    replies: int
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
    """The share of the agent's actions the environment could read (the action tag was there
    and the action parsed, legal or not); 0 with no reply."""
    if o is None or o.replies == 0:
        return 0.0
    return o.readable / o.replies


def system_prompt(protocol: Protocol) -> str:
    """The harness's system prompt for ``protocol`` (the text dialect: ``<action>``/``<plan>``)."""
    return SYSTEM_PROMPT if protocol == "interactive" else ONESHOT_PROMPT


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


class Game:
    """A level's state machine behind a chat: :meth:`opening`, then :meth:`answer` per reply."""

    def __init__(
        self,
        level: Level,
        protocol: Protocol = "interactive",
        images: bool = True,
        history_window: int = 5,
        oneshot_view: str = "iso",
    ) -> None:
        if protocol not in PROTOCOLS:
            raise ValueError(f"unknown protocol {protocol!r}; use interactive or oneshot")
        self.level, self.protocol, self.images = level, protocol, images
        self.history_window, self.oneshot_view = history_window, oneshot_view
        self.state = new_state(level)
        self.replies = 0
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

    def _step(self, text: str) -> None:
        result = self.state.step_text(text)
        self.readable += int(result.error != "unparseable")

    def answer(self, reply: str) -> Message | None:
        """Play ``reply``; the next user turn, or None once the episode is over."""
        if self.over:
            raise RuntimeError("the episode is over")
        if self.protocol == "oneshot":
            actions, _ = extract_plan(reply)
            for text in actions:
                if self._ended():
                    break
                self._step(text)
                self.replies += 1
            self.replies = max(1, self.replies)  # no plan at all is one unreadable reply
            self.over = True
            return None
        action, note = extract_action(reply)
        self.replies += 1
        self._step(action or "")
        if self._ended():
            self.over = True
            return None
        return self._user(note)

    def outcome(self) -> Outcome:
        s = self.state
        return Outcome(
            level_id=self.level.id,
            optimal_steps=self.level.optimal_steps,
            success=bool(s.is_success()),
            steps=int(s.steps_used),
            replies=self.replies,
            readable=self.readable,
            finished=bool(s.finished),
            truncated=bool(s.is_truncated()) and not s.is_success(),
        )
