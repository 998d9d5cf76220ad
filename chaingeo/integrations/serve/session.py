"""One episode behind the server: the reset options read strictly, then turns in and observations
out, on the one :class:`~chaingeo.evaluation.episode.Episode` every door drives. Every check runs
before anything changes, so a refused request leaves the episode as it was.
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
from chaingeo.evaluation.agents.base import Reply, StepResultLike
from chaingeo.evaluation.agents.dialects import DIALECTS, read_reply, tool_call
from chaingeo.evaluation.agents.prompt import observation_text
from chaingeo.evaluation.agents.tools import tool_specs
from chaingeo.evaluation.episode import Episode, Outcome, ProtocolConfig
from chaingeo.integrations.game import total_reward
from chaingeo.integrations.serve.errors import NoEpisodeError, RequestError
from chaingeo.integrations.serve.models import ChainAction, ChainObservation
from chaingeo.integrations.serve.scene import scene_json

#: How a ``{"text": ...}`` action is read: ``action`` (the default), the text is one action as
#: the state machine takes it (``move red +x 1``, or one of CHAIN's JSON calls); any registered
#: dialect (:mod:`chaingeo.evaluation.agents.dialects`: ``text``, a model's reply with the
#: harness's ``<action>`` tags, ...) reads it as a model's whole reply.
PLAIN: Final = "action"
MAX_HISTORY: Final = 50


def dialects() -> tuple[str, ...]:
    return (PLAIN, *DIALECTS.names())


@dataclass(frozen=True)
class Options:
    """A reset's options, checked."""

    dialect: str = PLAIN
    images: bool = False
    history: int = 5
    max_steps: int | None = None
    #: True, False, or "auto": only where the legal list is short enough to send every step
    #: and a player needs it (stacking placements, puzzle turns; a big puzzle's moves are many).
    legal: bool | str = False
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
    dialect = data.get("dialect", PLAIN)
    if dialect not in dialects():
        raise RequestError(f"dialect must be one of {', '.join(dialects())}")
    history = _int(data, "history", 5, 0, MAX_HISTORY)
    assert history is not None
    return Options(
        dialect=str(dialect),
        images=_bool(data, "images", False),
        history=history,
        max_steps=_int(data, "max_steps", None, 1, limits.MAX_STEPS),
        legal="auto" if data.get("legal") == "auto" else _bool(data, "legal", False),
        scene=_bool(data, "scene", False),
        text_state=_bool(data, "text_state", False),
    )


class Play:
    """One level being played under a reset's options (an :class:`Episode`); each step record
    gets ``t``, its time in seconds since the reset, for a study's record."""

    def __init__(
        self, level: Level, options: Options, seed: int | None, hide_optimal: bool, agent: str
    ) -> None:
        if options.max_steps is not None:
            level = dataclasses.replace(level, max_steps=options.max_steps)
        protocol = ProtocolConfig(history_window=options.history, text_state=options.text_state)
        self.episode = Episode(
            level, protocol, images=options.images, seed=seed or 0, agent=agent, keep_images=False
        )
        self.level, self.options, self.seed = level, options, seed
        self.hide_optimal = hide_optimal
        self.tools = tool_specs(level)
        self.started = time.monotonic()
        self.last: StepResultLike | None = None

    @property
    def state(self) -> Any:
        return self.episode.state

    @property
    def done(self) -> bool:
        return self.episode.done

    @property
    def steps(self) -> list[dict[str, Any]]:
        return self.episode.steps

    def _reply(self, action: ChainAction) -> Reply:
        if action.tool is not None:
            call = tool_call("call_0", action.tool, action.arguments or {}, self.tools)
            return read_reply("tools", "", (call,))
        assert action.text is not None
        if self.options.dialect == PLAIN:
            return Reply(action.text, action.text)
        return read_reply(self.options.dialect, action.text)

    def step(self, action: ChainAction) -> None:
        if self.done:
            raise NoEpisodeError("the episode is over; reset to play again")
        before = len(self.episode.steps)
        results = self.episode.play(self._reply(action))
        t = round(time.monotonic() - self.started, 3)
        for rec in self.episode.steps[before:]:
            rec["t"] = t
        if results:
            self.last = results[-1]

    def outcome(self) -> Outcome:
        return self.episode.outcome()

    @property
    def sends_legal(self) -> bool:
        if self.options.legal == "auto":
            return self.level.family == "stacking" or bool(getattr(self.level.rules, "turns", 0))
        return bool(self.options.legal)

    def observation(self) -> ChainObservation:
        opts, s, level, ep = self.options, self.state, self.level, self.episode
        obs = ep.observation()
        last = None
        if self.last is not None:
            sent = ep.steps[-1]["sent"] if ep.steps else None
            last = {"sent": sent, "legal": self.last.legal, "error": self.last.error}
        done = self.done
        return ChainObservation(
            done=done,
            reward=total_reward(ep.outcome()) if done else 0.0,
            level_id=level.id,
            family=level.family,
            instruction=obs.instruction,
            text=observation_text(obs, ep.note),
            feedback=None if self.last is None else self.last.feedback,
            last=last,
            success=bool(s.is_success()),
            steps=int(s.steps_used),
            steps_left=int(s.steps_left),
            max_steps=int(s.max_steps),
            optimal_steps=None if self.hide_optimal else level.optimal_steps,
            legal=[a.to_text() for a in s.legal_actions()] if self.sends_legal else None,
            images={k: base64.b64encode(v).decode("ascii") for k, v in obs.images.items()},
            scene=scene_json(s) if opts.scene else None,
        )

    def key(self) -> str:
        """The position's canonical key as JSON text (nested tuples of names and numbers)."""
        return json.dumps(self.state.key(), separators=(",", ":"))
