"""One episode: an agent plays one level under one protocol; the result is a log record.

This is a pure function of its :class:`EpisodeTask` (level, agent spec, protocol, seeds), so it
runs the same in this process, a worker process or on a Dask worker. Images never go into the
record: they come back beside it, keyed by SHA-256, for the writer to store as files.

Protocols:

- ``interactive`` (closed loop): each turn the agent sees the observation (task, colour table,
  the last ``history_window`` turns, steps left, views) and answers one action; the environment
  applies it or explains why not (an unparseable, illegal or ambiguous action changes nothing
  but costs a step) until the level is solved, the agent says ``finish`` or the step budget is
  spent. A reply may hold several actions (a model's native tool calls): they are taken in
  order, each a step with its own record, stopping at the first one rejected; the next turn
  hands the agent that reply and what each executed action did. With ``candidates > 1`` each
  turn asks the agent that many times and commits the candidate the judge ranks first after
  every one was checked in a cloned state (its first action: the verifier tries that one).
- ``oneshot`` (open loop): the agent sees one fixed view once (plus the tray of pieces, or the
  assembly target, where the level has one: they say what there is to place, not where things
  are) and writes its whole plan, which
  is executed action by action with no feedback (a failed action costs its step and the plan
  goes on) until solved, finished, out of budget or out of actions.
"""

from __future__ import annotations

import hashlib
import importlib
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np

from chaingeo.core.level import Level, content_hash
from chaingeo.envs.machines import new_state
from chaingeo.envs.observation import observe
from chaingeo.evaluation.agents.base import (
    TRANSPORT,
    Agent,
    AgentError,
    AgentSpec,
    AuthenticationError,
    ObservationLike,
    Reply,
    StateLike,
    StepResultLike,
    Turn,
)
from chaingeo.evaluation.agents.registry import make_agent
from chaingeo.evaluation.judges.registry import make_judge
from chaingeo.evaluation.judges.selection import Judge, verify
from chaingeo.evaluation.logs import episode_key
from chaingeo.evaluation.usage import Usage

ProtocolName = Literal["interactive", "oneshot"]
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
        if self.name not in ("interactive", "oneshot"):
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


@dataclass(frozen=True)
class EpisodeTask:
    level: Level
    sample: int
    seed: int  # the run's seed
    agent: AgentSpec
    protocol: ProtocolConfig = field(default_factory=ProtocolConfig)

    @property
    def key(self) -> str:
        return episode_key(self.level.id, self.sample)


@dataclass
class EpisodeResult:
    record: dict[str, Any]
    images: dict[str, bytes]  # file name (sha256.png) -> PNG bytes


def episode_seed(run_seed: int, level: Level, sample: int) -> int:
    """Seed of one episode, from the run seed, the level's content and the sample number: an
    episode draws the same randomness whichever other levels share the run."""
    level_part = int(content_hash(level)[:15], 16)
    ss = np.random.SeedSequence([run_seed, level_part, sample])
    return int(ss.generate_state(1, dtype=np.uint64)[0] >> np.uint64(1))


def _environment(module: str) -> tuple[Callable[[Level], StateLike], Callable[..., Any]]:
    """The state machine factory and observation function: ours, or those of the module named
    (any module exposing ``new_state`` and ``observe``, e.g. a test double)."""
    if module == "chaingeo":
        return new_state, observe
    mod = importlib.import_module(module)
    return mod.new_state, mod.observe


class _Images:
    def __init__(self) -> None:
        self.files: dict[str, bytes] = {}

    def names(self, obs: ObservationLike | None) -> dict[str, str]:
        out: dict[str, str] = {}
        if obs is None:
            return out
        for view, png in obs.images.items():
            name = hashlib.sha256(png).hexdigest() + ".png"
            self.files[name] = png
            out[view] = name
        return out


def _step_record(
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


def _header(task: EpisodeTask, seed: int) -> dict[str, Any]:
    level = task.level
    return {
        "key": task.key,
        "level_id": level.id,
        "level_hash": content_hash(level),
        "family": level.family,
        "difficulty": level.difficulty,
        "goal": level.goal,
        "optimal_steps": level.optimal_steps,
        "max_steps": level.max_steps,
        "sample": task.sample,
        "seed": seed,
        "protocol": task.protocol.name,
        "agent": task.agent.label,
    }


#: The longest exception message an errored record keeps.
MAX_ERROR_CHARS = 500


def describe_error(exc: BaseException) -> str:
    """``Class: message`` of an exception, one line, bounded, with no traceback; an agent error
    is the harness's own wording and keeps just its message."""
    message = " ".join(str(exc).split())
    if len(message) > MAX_ERROR_CHARS:
        message = message[: MAX_ERROR_CHARS - 3] + "..."
    if isinstance(exc, AgentError):
        return message
    return f"{type(exc).__name__}: {message}" if message else type(exc).__name__


def error_record(task: EpisodeTask, exc: BaseException) -> EpisodeResult:
    """The record of an episode that never produced one (its worker died, its result could not
    come back): status ``error``, nothing played."""
    record = _header(task, episode_seed(task.seed, task.level, task.sample))
    record.update(
        model=None,
        status="error",
        error=describe_error(exc),
        error_type=type(exc).__name__,
        success=False,
        steps_used=0,
        invalid=0,
        unparseable=0,
        illegal=0,
        ambiguous=0,
        finished=False,
        truncated=False,
        usage=Usage().to_json(),
        wall_seconds=0.0,
        steps=[],
    )
    return EpisodeResult(record, {})


def run_episode(task: EpisodeTask) -> EpisodeResult:
    """Play one episode. Whatever an agent or the environment raises becomes an errored record
    (class and message, never a traceback), except :class:`AuthenticationError`, which no
    other episode would survive either: it propagates so the run stops at once."""
    return _Episode(task).run()


class _Episode:
    """One episode's play: the state, the agent, what has been recorded so far."""

    def __init__(self, task: EpisodeTask) -> None:
        self.task = task
        self.seed = episode_seed(task.seed, task.level, task.sample)
        self.started = time.monotonic()
        self.images = _Images()
        self.steps: list[dict[str, Any]] = []
        self.usage = Usage()
        self.record = _header(task, self.seed)
        self.record["model"] = None
        self.state: StateLike | None = None
        self.agent: Agent | None = None
        self.judge: Judge | None = None
        self.finished = False
        self.status: str = "done"
        self.error: str | None = None
        self.error_type: str | None = None

    def _fail(self, e: BaseException) -> None:
        """Record the first error only: later ones are consequences."""
        if self.status == "done":
            self.status, self.error, self.error_type = "error", describe_error(e), type(e).__name__

    def run(self) -> EpisodeResult:
        proto = self.task.protocol
        try:
            make_state, observe_state = _environment(proto.env)
            state = self.state = make_state(self.task.level)
            agent = self.agent = make_agent(self.task.agent)
            self.record["model"] = agent.model
            agent.start(self.task.level, self.seed)

            def see(window: int) -> ObservationLike:
                obs: ObservationLike = observe_state(
                    state, history_window=window, text_state=proto.text_state,
                    images=agent.uses_images,
                )  # fmt: skip
                return obs

            if proto.name == "interactive":
                self._interactive(state, agent, see)
            else:
                self._oneshot(state, agent, see(0))
        except AuthenticationError:
            raise
        except Exception as e:  # one bad episode must never stop a run
            self._fail(e)
        finally:
            self._close_agent()
        return self._result()

    def _close_agent(self) -> None:
        if self.agent is None:
            return
        try:
            notes = self.agent.notes()
            if notes:
                self.record["agent_notes"] = notes
            self.agent.close()
        except Exception as e:
            self._fail(e)

    def _interactive(
        self, state: StateLike, agent: Agent, see: Callable[[int], ObservationLike]
    ) -> None:
        """Turn after turn until success, truncation or the agent finishes."""
        task, proto = self.task, self.task.protocol
        judge = self.judge = make_judge(proto.judge, proto.judge_options)
        judge.start(self.seed)
        note: str | None = None
        previous: Reply | None = None
        results: tuple[StepResultLike, ...] = ()
        turn = 0
        while not (state.is_success() or state.is_truncated()):
            if turn >= state.max_steps:
                raise RuntimeError(f"{task.level.id}: the environment stopped counting steps")
            obs = see(proto.history_window)
            shown = self.images.names(obs)
            replies = [
                agent.act(
                    Turn(
                        task.level,
                        obs,
                        state.clone() if agent.needs_state else None,
                        turn,
                        task.sample,
                        c,
                        note,
                        previous,
                        results,
                    )
                )
                for c in range(proto.candidates)
            ]
            for r in replies:
                self.usage = self.usage + r.usage
            chosen, extra = self._choose(state, judge, replies, obs)
            done = self._take(state, turn, chosen, {"images": shown, **extra})
            note = chosen.note if chosen.action is None else None
            previous, results = chosen, tuple(done)
            turn += 1
            if state.finished:
                self.finished = True
                return

    def _choose(
        self, state: StateLike, judge: Judge, replies: list[Reply], obs: ObservationLike
    ) -> tuple[Reply, dict[str, Any]]:
        """The reply to play (the judge ranks several candidates) and what the turn's first
        step record gets besides (the candidates, their usage, the judge's)."""
        if len(replies) <= 1:
            return replies[0], {}
        checked = verify(state, replies)
        spent = judge.usage
        best = judge.rank(state, checked, obs)[0]
        cands = [
            {
                "reply": c.reply.text,
                "action": c.reply.action,
                **({"actions": list(c.reply.actions)} if c.reply.actions else {}),
                "legal": c.legal,
                "error": c.result.error if c.result else None,
                "usage": c.reply.usage.to_json(),
                "chosen": c.index == best,
            }
            for c in checked
        ]
        extra: dict[str, Any] = {
            "candidates": cands,
            "usage": sum((r.usage for r in replies), Usage()).to_json(),
        }
        if judge.usage != spent:
            extra["judge_usage"] = _spent(judge.usage, spent).to_json()
        return replies[best], extra

    def _take(
        self, state: StateLike, turn: int, chosen: Reply, first: dict[str, Any]
    ) -> list[StepResultLike]:
        """Play the chosen reply's actions, one step record each; stop at a rejected one."""
        todo = chosen.actions or (chosen.action if chosen.action is not None else "",)
        done: list[StepResultLike] = []
        for i, sent in enumerate(todo):
            if i and (state.finished or state.is_success() or state.is_truncated()):
                break
            result = state.step_text(sent)
            done.append(result)
            rec = _step_record(turn, chosen, sent, result, i)
            if i == 0:
                rec.update(first)
            self.steps.append(rec)
            if not result.legal:
                break  # the actions after a rejected one are not taken
        return done

    def _oneshot(self, state: StateLike, agent: Agent, obs: ObservationLike) -> None:
        """One plan from the first observation, its actions played in order."""
        task, proto = self.task, self.task.protocol
        keep = (proto.oneshot_view, *AUXILIARY_VIEWS)
        view = {k: v for k, v in obs.images.items() if k in keep}
        obs = _with_images(obs, view)
        shown = self.images.names(obs)
        plan = agent.plan(
            Turn(task.level, obs, state.clone() if agent.needs_state else None, 0, task.sample)
        )
        self.usage = self.usage + plan.usage
        self.record["plan"] = {
            "reply": plan.text,
            "actions": list(plan.actions),
            "note": plan.note,
            "usage": plan.usage.to_json(),
            "images": shown,
        }
        if plan.calls:
            self.record["plan"]["calls"] = [c.to_json() for c in plan.calls]
        for i, text in enumerate(plan.actions):
            if state.is_success() or state.is_truncated():
                break
            result = state.step_text(text)
            self.steps.append(_step_record(i, Reply(text, text), text, result))
            if state.finished:
                self.finished = True
                break

    def _result(self) -> EpisodeResult:
        record, steps, judge = self.record, self.steps, self.judge
        if judge is not None and judge.usage.calls:
            record["judge"] = {"model": judge.model, "usage": judge.usage.to_json()}
        try:
            ended = _ending(self.state)
        except Exception as e:  # a state that cannot report its end
            ended = _ending(None)
            self._fail(e)
        record.update(status=self.status, error=self.error)
        if self.error_type is not None:
            record["error_type"] = self.error_type
        record.update(
            success=ended["success"],
            steps_used=ended["steps_used"],
            invalid=sum(1 for s in steps if not s["legal"]),
            unparseable=sum(1 for s in steps if s["error"] == "unparseable"),
            illegal=sum(1 for s in steps if s["error"] == "illegal"),
            ambiguous=sum(1 for s in steps if s["error"] == "ambiguous"),
            finished=self.finished,
            truncated=ended["truncated"],
            usage=self.usage.to_json(),
            wall_seconds=round(time.monotonic() - self.started, 3),
            steps=steps,
        )
        return EpisodeResult(record, self.images.files)


def _ending(state: StateLike | None) -> dict[str, Any]:
    if state is None:
        return {"success": False, "steps_used": 0, "truncated": False}
    success = bool(state.is_success())
    return {
        "success": success,
        "steps_used": int(state.steps_used),
        "truncated": bool(state.is_truncated()) and not success,
    }


def _spent(now: Usage, before: Usage) -> Usage:
    return Usage(
        now.input_tokens - before.input_tokens,
        now.output_tokens - before.output_tokens,
        now.reasoning_tokens - before.reasoning_tokens,
        now.cached_tokens - before.cached_tokens,
        now.calls - before.calls,
    )


def _with_images(obs: ObservationLike, images: Mapping[str, bytes]) -> ObservationLike:
    import dataclasses

    if dataclasses.is_dataclass(obs) and not isinstance(obs, type):
        out: ObservationLike = dataclasses.replace(obs, images=dict(images))
        return out
    raise TypeError("observations must be dataclasses with an 'images' field")
