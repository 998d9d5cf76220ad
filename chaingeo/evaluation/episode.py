"""The one episode: a level played under a protocol, one agent turn at a time.

Every door drives this class: ``chain eval`` (:mod:`chaingeo.evaluation.play` asks an agent for
each turn), the chat game behind verifiers (:mod:`chaingeo.integrations.game`), and any door
that receives replies from outside (a server, another harness). A driver asks for the
:meth:`Episode.observation`, gets a reply from somewhere, reads it into a :class:`Reply` (the
dialects of :mod:`chaingeo.evaluation.dialects`) and hands it to :meth:`Episode.play`, until
:attr:`Episode.done`; then :meth:`Episode.outcome` is the one :class:`Outcome` every metric
reads, and :meth:`Episode.record` the run-format record ``chain report`` reads.

Protocols:

- ``interactive`` (closed loop): each turn the agent sees the observation (task, colour table,
  the last ``history_window`` turns, steps left, views) and answers one action; the environment
  applies it or explains why not (an unparseable, illegal or ambiguous action changes nothing
  but costs a step) until the level is solved, the agent says ``finish`` or the step budget is
  spent. A reply may hold several actions (a model's native tool calls): they are taken in
  order, each a step with its own record, stopping at the first one rejected.
- ``oneshot`` (open loop): the agent sees one fixed view once (plus the tray of pieces, or the
  assembly target, where the level has one: they say what there is to place, not where things
  are) and writes its whole plan, which is executed action by action with no feedback (a failed
  action costs its step and the plan goes on) until solved, finished, out of budget or out of
  actions.
"""

from __future__ import annotations

import dataclasses
import hashlib
import importlib
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any, Literal

from chaingeo.core.errors import ChainGeoError
from chaingeo.core.level import Level, content_hash
from chaingeo.envs.machines import new_state
from chaingeo.envs.observation import observe
from chaingeo.evaluation.agents.base import (
    TRANSPORT,
    ObservationLike,
    Reply,
    StateLike,
    StepResultLike,
)
from chaingeo.evaluation.judges.registry import make_judge
from chaingeo.evaluation.logs import episode_key
from chaingeo.evaluation.usage import Usage

ProtocolName = Literal["interactive", "oneshot"]
PROTOCOLS: tuple[ProtocolName, ...] = ("interactive", "oneshot")
#: Pictures that show what the pieces or the goal are rather than the scene (kept in one-shot).
AUXILIARY_VIEWS = ("tray", "target")


@dataclass(frozen=True)
class ProtocolConfig:
    name: ProtocolName = "interactive"
    history_window: int = 5
    text_state: bool = False
    candidates: int = 1  # > 1: verifier-based selection among this many per turn
    judge: str = "first"
    judge_options: Mapping[str, Any] = field(default_factory=dict)
    oneshot_view: str = "iso"
    #: The module providing ``new_state`` and ``observe`` (tests may point at a double).
    env: str = "chaingeo"

    def __post_init__(self) -> None:
        if self.name not in PROTOCOLS:
            raise ValueError(f"unknown protocol {self.name!r}; use interactive or oneshot")
        if self.candidates < 1 or self.history_window < 0:
            raise ValueError("candidates must be >= 1 and history_window >= 0")
        make_judge(self.judge, self.judge_options)

    def to_json(self) -> dict[str, Any]:
        out: dict[str, Any] = {"name": self.name, "text_state": self.text_state}
        if self.name == "interactive":
            out.update(
                history_window=self.history_window, candidates=self.candidates, judge=self.judge
            )
            opts = {k: v for k, v in sorted(self.judge_options.items()) if k not in TRANSPORT}
            if opts:
                out["judge_options"] = opts
        else:
            out["view"] = self.oneshot_view
        if self.env != "chaingeo":
            out["env"] = self.env
        return out


class EpisodeOverError(ChainGeoError, RuntimeError):
    """A driver played a turn after the episode ended (a driver's mistake, not an agent's)."""


@dataclass(frozen=True)
class Outcome:
    """What every metric and reward needs of one episode (JSON-able: it rides on a framework's
    trace). ``actions`` counts the agent's action attempts, ``readable`` those the environment
    could read (parsed, legal or not)."""

    level_id: str
    family: str
    difficulty: str
    optimal_steps: int
    success: bool
    steps: int
    sample: int = 0
    usage: Usage = Usage()
    cost_usd: float | None = 0.0
    actions: int = 0
    readable: int = 0
    finished: bool = False
    truncated: bool = False
    #: Why the episode errored (its record's ``error``, or its class); None when it played.
    error: str | None = None

    def to_json(self) -> dict[str, Any]:
        out = dataclasses.asdict(self)
        out["usage"] = self.usage.to_json()
        return out

    @classmethod
    def from_json(cls, data: Any) -> Outcome | None:
        """The outcome a trace carries; None when the episode never got one (it errored)."""
        if not isinstance(data, dict):
            return None
        try:
            usage = Usage.from_json(data.get("usage") or {})
            return cls(**{**data, "usage": usage})
        except (TypeError, ValueError, AttributeError):
            return None

    @classmethod
    def from_record(cls, record: Mapping[str, Any]) -> Outcome:
        """The outcome of a run record (:meth:`Episode.record`); a model judge's tokens count
        with the agent's."""
        usage = Usage.from_json(record.get("usage", {}))
        if record.get("judge"):
            usage = usage + Usage.from_json(record["judge"]["usage"])
        steps = record.get("steps") or []
        return cls(
            level_id=str(record["level_id"]),
            family=str(record["family"]),
            difficulty=str(record["difficulty"]),
            optimal_steps=int(record["optimal_steps"]),
            success=bool(record["success"]),
            steps=int(record["steps_used"]),
            sample=int(record.get("sample", 0)),
            actions=len(steps),
            readable=sum(1 for s in steps if s.get("error") != "unparseable"),
            finished=bool(record.get("finished", False)),
            truncated=bool(record.get("truncated", False)),
            usage=usage,
            cost_usd=record.get("cost_usd"),
            error=_error_of(record),
        )


def _error_of(record: Mapping[str, Any]) -> str | None:
    if record.get("status") != "error":
        return None
    return str(record.get("error") or record.get("error_type") or "?")


def _environment(module: str) -> tuple[Callable[[Level], StateLike], Callable[..., Any]]:
    """The state machine factory and observation function: ours, or those of the module named
    (any module exposing ``new_state`` and ``observe``, e.g. a test double)."""
    if module == "chaingeo":
        return new_state, observe
    mod = importlib.import_module(module)
    return mod.new_state, mod.observe


def header(level: Level, sample: int, seed: int, protocol: str, agent: str) -> dict[str, Any]:
    """The fields every run record of ``level`` starts with."""
    return {
        "key": episode_key(level.id, sample),
        "level_id": level.id,
        "level_hash": content_hash(level),
        "family": level.family,
        "difficulty": level.difficulty,
        "goal": level.goal,
        "optimal_steps": level.optimal_steps,
        "max_steps": level.max_steps,
        "sample": sample,
        "seed": seed,
        "protocol": protocol,
        "agent": agent,
    }


def step_record(
    turn: int, reply: Reply, sent: str, result: StepResultLike, call: int = 0
) -> dict[str, Any]:
    """One step. Of a reply with several actions, the first step holds the reply, its usage,
    reasoning and every tool call it made (executed or not), later ones an empty reply and no
    usage (nothing is counted twice); each step of a tool-calling reply gives its call's index."""
    first = call == 0
    rec: dict[str, Any] = {
        "turn": turn,
        "reply": reply.text if first else "",
        "sent": sent,
        "action": result.action.to_text() if result.action is not None else None,
        "legal": result.legal,
        "error": result.error,
        "feedback": result.feedback,
        "usage": (reply.usage if first else Usage()).to_json(),
    }
    if reply.calls:
        rec["call"] = call
        if first:
            rec["calls"] = [c.to_json() for c in reply.calls]
    if reply.note and first:
        rec["note"] = reply.note
    if reply.reasoning and first:
        rec["reasoning"] = reply.reasoning
    return rec


class Episode:
    """A level's state machine, one protocol, and what has been played so far.

    ``images`` says whether observations carry pictures; ``keep_images`` whether their PNG bytes
    are kept for :attr:`images` (a run stores them as files; a training game need not)."""

    def __init__(
        self,
        level: Level,
        protocol: ProtocolConfig | None = None,
        *,
        images: bool = True,
        sample: int = 0,
        seed: int = 0,
        agent: str = "agent",
        keep_images: bool = True,
    ) -> None:
        self.level = level
        self.protocol = protocol or ProtocolConfig()
        self.sample, self.seed = sample, seed
        self.uses_images, self.keep_images = images, keep_images
        make_state, self._observe = _environment(self.protocol.env)
        self.state: StateLike = make_state(level)
        self.steps: list[dict[str, Any]] = []
        self.images: dict[str, bytes] = {}  # file name (sha256.png) -> PNG bytes
        self.usage = Usage()
        self.turn = 0
        self.note: str | None = None  # why the last reply could not be read
        self.previous: Reply | None = None
        self.results: tuple[StepResultLike, ...] = ()
        self.plan: dict[str, Any] | None = None  # one-shot: the plan as the agent gave it
        self._shown: dict[str, str] = {}
        self._over = False
        self.agent = agent

    # -- what the agent sees -------------------------------------------------------------------

    @property
    def oneshot(self) -> bool:
        return self.protocol.name == "oneshot"

    def observation(self) -> ObservationLike:
        """What the agent sees now (in one-shot: the one view, and the tray or target)."""
        proto = self.protocol
        window = 0 if self.oneshot else proto.history_window
        obs: ObservationLike = self._observe(
            self.state, history_window=window, text_state=proto.text_state,
            images=self.uses_images,
        )  # fmt: skip
        if self.oneshot:
            keep = (proto.oneshot_view, *AUXILIARY_VIEWS)
            obs = _with_images(obs, {k: v for k, v in obs.images.items() if k in keep})
        self._shown = self._names(obs)
        return obs

    def _names(self, obs: ObservationLike) -> dict[str, str]:
        out: dict[str, str] = {}
        for view, png in obs.images.items():
            name = hashlib.sha256(png).hexdigest() + ".png"
            if self.keep_images:
                self.images[name] = png
            out[view] = name
        return out

    # -- playing -------------------------------------------------------------------------------

    @property
    def done(self) -> bool:
        s = self.state
        return self._over or bool(s.is_success() or s.is_truncated() or s.finished)

    def play(
        self, reply: Reply, *, spent: Usage | None = None, extra: Mapping[str, Any] | None = None
    ) -> list[StepResultLike]:
        """Play one agent turn and return what each step it took did. ``spent`` is the turn's
        usage when it differs from the reply's (several candidates were asked); ``extra`` goes
        into the turn's first step record. An unreadable reply costs one step; nothing an agent
        writes raises here."""
        if self.done:
            raise EpisodeOverError(f"{self.level.id}: the episode is over")
        self.usage = self.usage + (reply.usage if spent is None else spent)
        if self.oneshot:
            return self._play_plan(reply)
        done = self._take(reply, {"images": self._shown, **(extra or {})})
        self.note = reply.note if reply.action is None else None
        self.previous, self.results = reply, tuple(done)
        self.turn += 1
        if self.turn >= self.state.max_steps and not self.done:
            raise RuntimeError(f"{self.level.id}: the environment stopped counting steps")
        return done

    def _take(self, reply: Reply, first: Mapping[str, Any]) -> list[StepResultLike]:
        """The reply's actions, one step record each; stop at a rejected one."""
        todo = reply.actions or (reply.action if reply.action is not None else "",)
        done: list[StepResultLike] = []
        for i, sent in enumerate(todo):
            if i and self.done:
                break
            result = self.state.step_text(sent)
            done.append(result)
            rec = step_record(self.turn, reply, sent, result, i)
            if i == 0:
                rec.update(first)
            self.steps.append(rec)
            if not result.legal:
                break  # the actions after a rejected one are not taken
        return done

    def _play_plan(self, plan: Reply) -> list[StepResultLike]:
        """A one-shot plan's actions in order, with no feedback; then the episode is over."""
        self.plan = {
            "reply": plan.text,
            "actions": list(plan.actions),
            "note": plan.note,
            "usage": plan.usage.to_json(),
            "images": self._shown,
        }
        if plan.calls:
            self.plan["calls"] = [c.to_json() for c in plan.calls]
        done: list[StepResultLike] = []
        for i, text in enumerate(plan.actions):
            if self.done:
                break
            result = self.state.step_text(text)
            done.append(result)
            self.steps.append(step_record(i, Reply(text, text), text, result))
        self._over = True
        return done

    # -- the end -------------------------------------------------------------------------------

    def outcome(self) -> Outcome:
        s, level = self.state, self.level
        success = bool(s.is_success())
        actions = len(self.steps)
        readable = sum(1 for r in self.steps if r["error"] != "unparseable")
        return Outcome(
            level_id=level.id,
            family=level.family,
            difficulty=level.difficulty,
            optimal_steps=level.optimal_steps,
            success=success,
            steps=int(s.steps_used),
            sample=self.sample,
            actions=max(actions, 1) if self.oneshot and self._over else actions,
            readable=readable,
            finished=bool(s.finished),
            truncated=bool(s.is_truncated()) and not success,
            usage=self.usage,
        )

    def record(self) -> dict[str, Any]:
        """The run-format record of what was played (``chain eval`` adds status, timing, the
        model and the agent's notes)."""
        o = self.outcome()
        steps = self.steps
        rec = header(self.level, self.sample, self.seed, self.protocol.name, self.agent)
        if self.plan is not None:
            rec["plan"] = self.plan
        rec.update(
            success=o.success,
            steps_used=o.steps,
            invalid=sum(1 for s in steps if not s["legal"]),
            unparseable=sum(1 for s in steps if s["error"] == "unparseable"),
            illegal=sum(1 for s in steps if s["error"] == "illegal"),
            ambiguous=sum(1 for s in steps if s["error"] == "ambiguous"),
            finished=o.finished,
            truncated=o.truncated,
            usage=self.usage.to_json(),
            steps=steps,
        )
        return rec


def _with_images(obs: ObservationLike, images: Mapping[str, bytes]) -> ObservationLike:
    if dataclasses.is_dataclass(obs) and not isinstance(obs, type):
        out: ObservationLike = dataclasses.replace(obs, images=dict(images))
        return out
    raise TypeError("observations must be dataclasses with an 'images' field")
