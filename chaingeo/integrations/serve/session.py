"""One episode behind the server: the reset options read strictly, then turns in and observations
out. Every check runs before anything changes, so a refused request leaves the episode as it was.
"""

from __future__ import annotations

import base64
import dataclasses
import json
import time
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, Final

from chaingeo.core import limits
from chaingeo.core.level import Level
from chaingeo.envs.machines import new_state
from chaingeo.envs.machines.state import BaseState, StepResult
from chaingeo.envs.observation import observe
from chaingeo.evaluation.agents.prompt import extract_action
from chaingeo.evaluation.agents.tools import tool_specs, translate
from chaingeo.integrations.game import Outcome, total_reward
from chaingeo.integrations.serve.errors import NoEpisodeError, RequestError
from chaingeo.integrations.serve.models import ChainAction, ChainObservation
from chaingeo.integrations.serve.scene import scene_json

#: How a ``{"text": ...}`` action is read: ``action``, the text is one action as the state
#: machine takes it (``move red +x 1``; CHAIN's JSON calls too); ``text``, a model's reply with
#: the harness's ``<action>`` tags; ``chain``, CHAIN's JSON tool-call text.
DIALECTS: Final = ("action", "text", "chain")
MAX_HISTORY: Final = 50
MIN_IMAGE_SIZE, MAX_IMAGE_SIZE = 128, 1024


@dataclass(frozen=True)
class Options:
    """A reset's options, checked."""

    dialect: str = "action"
    images: bool = False
    image_size: int = 512
    history: int = 5
    max_steps: int | None = None
    legal: bool = False
    scene: bool = False
    text_state: bool = False


def _bool(data: Mapping[str, Any], name: str, default: bool) -> bool:
    value = data.get(name, default)
    if not isinstance(value, bool):
        raise RequestError(f"{name} must be true or false")
    return value


def _int(
    data: Mapping[str, Any], name: str, default: int | None, low: int, high: int
) -> int | None:
    value = data.get(name, default)
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, int) or not low <= value <= high:
        raise RequestError(f"{name} must be a whole number from {low} to {high}")
    return value


def read_options(data: Mapping[str, Any]) -> Options:
    """The reset options of ``data`` (unknown names are refused, not ignored)."""
    known = {f.name for f in dataclasses.fields(Options)}
    extra = sorted(str(k)[:40] for k in data if k not in known)
    if extra:
        raise RequestError(f"unknown reset option {extra[0]!r}; known: {', '.join(sorted(known))}")
    dialect = data.get("dialect", "action")
    if dialect not in DIALECTS:
        raise RequestError(f"dialect must be one of {', '.join(DIALECTS)}")
    size = _int(data, "image_size", 512, MIN_IMAGE_SIZE, MAX_IMAGE_SIZE)
    history = _int(data, "history", 5, 0, MAX_HISTORY)
    assert size is not None and history is not None
    return Options(
        dialect=str(dialect),
        images=_bool(data, "images", False),
        image_size=size,
        history=history,
        max_steps=_int(data, "max_steps", None, 1, limits.MAX_STEPS),
        legal=_bool(data, "legal", False),
        scene=_bool(data, "scene", False),
        text_state=_bool(data, "text_state", False),
    )


class Play:
    """One level being played under a reset's options; ``events`` logs every turn with its
    time (seconds since the reset) for a study's record."""

    def __init__(
        self, level: Level, options: Options, seed: int | None, hide_optimal: bool
    ) -> None:
        if options.max_steps is not None:
            level = dataclasses.replace(level, max_steps=options.max_steps)
        self.level, self.options, self.seed = level, options, seed
        self.hide_optimal = hide_optimal
        self.state: BaseState = new_state(level)
        self.tools = tool_specs(level)
        self.started = time.monotonic()
        self.events: list[dict[str, Any]] = []
        self.actions = 0
        self.readable = 0
        self.last: StepResult | None = None
        self.sent: str | None = None

    @property
    def done(self) -> bool:
        s = self.state
        return bool(s.is_success() or s.is_truncated() or s.finished)

    def _action_text(self, action: ChainAction) -> tuple[str, bool]:
        """(the text the state machine plays, whether the agent's turn was readable)."""
        if action.tool is not None:
            t = translate(action.tool, action.arguments or {}, self.tools)
            return t.action, t.problem is None
        assert action.text is not None
        if self.options.dialect == "text":
            found, _ = extract_action(action.text)
            return found or "", found is not None
        return action.text, True

    def step(self, action: ChainAction) -> StepResult:
        if self.done:
            raise NoEpisodeError("the episode is over; reset to play again")
        text, readable = self._action_text(action)
        result = self.state.step_text(text)
        self.actions += 1
        self.readable += int(readable and result.error != "unparseable")
        self.last, self.sent = result, text
        self.events.append(
            {
                "t": round(time.monotonic() - self.started, 3),
                "sent": text,
                "action": result.action.to_text() if result.action is not None else None,
                "legal": result.legal,
                "error": result.error,
                "feedback": result.feedback,
            }
        )
        return result

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

    def observation(self) -> ChainObservation:
        opts, s, level = self.options, self.state, self.level
        obs = observe(s, opts.history, opts.text_state, opts.images, opts.image_size)
        last = None
        if self.last is not None:
            last = {"sent": self.sent, "legal": self.last.legal, "error": self.last.error}
        done = self.done
        return ChainObservation(
            done=done,
            reward=total_reward(self.outcome()) if done else 0.0,
            level_id=level.id,
            family=level.family,
            instruction=obs.instruction,
            text=obs.to_text(),
            feedback=None if self.last is None else self.last.feedback,
            last=last,
            success=bool(s.is_success()),
            steps=int(s.steps_used),
            steps_left=int(s.steps_left),
            max_steps=int(s.max_steps),
            optimal_steps=None if self.hide_optimal else level.optimal_steps,
            legal=[a.to_text() for a in s.legal_actions()] if opts.legal else None,
            images={k: base64.b64encode(v).decode("ascii") for k, v in obs.images.items()},
            scene=scene_json(s) if opts.scene else None,
        )

    def key(self) -> str:
        """The position's canonical key as JSON text (nested tuples of names and numbers)."""
        return json.dumps(self.state.key(), separators=(",", ":"))
