"""An agent plays an :class:`~chaingeo.evaluation.episode.Episode`: the loop of ``chain eval``.

:func:`run_episode` is a pure function of its :class:`EpisodeTask` (level, agent spec, protocol,
seeds), so it runs the same in this process, a worker process or on a Dask worker. It asks the
agent for each turn (with ``candidates > 1``, that many times, and commits the candidate the
judge ranks first after every one was checked in a cloned state) and hands the reply to the
episode. Images never go into the record: they come back beside it, keyed by SHA-256, for the
writer to store as files.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from chaingeo.core.level import Level, content_hash
from chaingeo.evaluation.agents.base import (
    Agent,
    AgentError,
    AgentSpec,
    AuthenticationError,
    ObservationLike,
    Reply,
    Turn,
)
from chaingeo.evaluation.agents.registry import make_agent
from chaingeo.evaluation.episode import Episode, ProtocolConfig, header
from chaingeo.evaluation.judges.registry import make_judge
from chaingeo.evaluation.judges.selection import Judge, verify
from chaingeo.evaluation.logs import episode_key
from chaingeo.evaluation.usage import Usage


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


def _empty_record(task: EpisodeTask) -> dict[str, Any]:
    seed = episode_seed(task.seed, task.level, task.sample)
    record = header(task.level, task.sample, seed, task.protocol.name, task.agent.label)
    record.update(
        success=False,
        steps_used=0,
        invalid=0,
        unparseable=0,
        illegal=0,
        ambiguous=0,
        finished=False,
        truncated=False,
        usage=Usage().to_json(),
        steps=[],
    )
    return record


def error_record(task: EpisodeTask, exc: BaseException) -> EpisodeResult:
    """The record of an episode that never produced one (its worker died, its result could not
    come back): status ``error``, nothing played."""
    record = _empty_record(task)
    record.update(model=None, status="error", error=describe_error(exc))
    record["error_type"] = type(exc).__name__
    record["wall_seconds"] = 0.0
    return EpisodeResult(record, {})


def run_episode(task: EpisodeTask) -> EpisodeResult:
    """Play one episode. Whatever an agent or the environment raises becomes an errored record
    (class and message, never a traceback), except :class:`AuthenticationError`, which no
    other episode would survive either: it propagates so the run stops at once."""
    return _AgentPlay(task).run()


class _AgentPlay:
    """One episode driven by one agent: the episode, the agent, the first error."""

    def __init__(self, task: EpisodeTask) -> None:
        self.task = task
        self.seed = episode_seed(task.seed, task.level, task.sample)
        self.started = time.monotonic()
        self.episode: Episode | None = None
        self.agent: Agent | None = None
        self.judge: Judge | None = None
        self.model: str | None = None
        self.notes: Any = None
        self.status: str = "done"
        self.error: str | None = None
        self.error_type: str | None = None

    def _fail(self, e: BaseException) -> None:
        """Record the first error only: later ones are consequences."""
        if self.status == "done":
            self.status, self.error, self.error_type = "error", describe_error(e), type(e).__name__

    def run(self) -> EpisodeResult:
        task = self.task
        try:
            agent = self.agent = make_agent(task.agent)
            self.model = agent.model
            ep = self.episode = Episode(
                task.level, task.protocol, images=agent.uses_images, sample=task.sample,
                seed=self.seed, agent=task.agent.label,
            )  # fmt: skip
            agent.start(task.level, self.seed)
            if task.protocol.name == "interactive":
                self._interactive(ep, agent)
            else:
                obs = ep.observation()
                state = ep.state.clone() if agent.needs_state else None
                ep.play(agent.plan(Turn(task.level, obs, state, 0, task.sample)))
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
            self.notes = self.agent.notes()
            self.agent.close()
        except Exception as e:
            self._fail(e)

    def _interactive(self, ep: Episode, agent: Agent) -> None:
        """Turn after turn until the episode is done."""
        task, proto = self.task, self.task.protocol
        judge = self.judge = make_judge(proto.judge, proto.judge_options)
        judge.start(self.seed)
        while not ep.done:
            obs = ep.observation()
            replies = [
                agent.act(
                    Turn(
                        task.level,
                        obs,
                        ep.state.clone() if agent.needs_state else None,
                        ep.turn,
                        task.sample,
                        c,
                        ep.note,
                        ep.previous,
                        ep.results,
                    )
                )
                for c in range(proto.candidates)
            ]
            spent = sum((r.usage for r in replies), Usage())
            chosen, extra = self._choose(ep, judge, replies, obs)
            ep.play(chosen, spent=spent, extra=extra)

    def _choose(
        self, ep: Episode, judge: Judge, replies: list[Reply], obs: ObservationLike
    ) -> tuple[Reply, dict[str, Any]]:
        """The reply to play (the judge ranks several candidates) and what the turn's first
        step record gets besides (the candidates, their usage, the judge's)."""
        if len(replies) <= 1:
            return replies[0], {}
        checked = verify(ep.state, replies)
        spent = judge.usage
        best = judge.rank(ep.state, checked, obs)[0]
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
            extra["judge_usage"] = (judge.usage - spent).to_json()
        return replies[best], extra

    def _result(self) -> EpisodeResult:
        ep = self.episode
        try:
            record = ep.record() if ep is not None else _empty_record(self.task)
        except Exception as e:  # a state that cannot report its end
            record = _empty_record(self.task)
            if ep is not None:
                record.update(steps=ep.steps, usage=ep.usage.to_json())
            self._fail(e)
        out: dict[str, Any] = {**record, "model": self.model}
        if self.notes:
            out["agent_notes"] = self.notes
        judge = self.judge
        if judge is not None and judge.usage.calls:
            out["judge"] = {"model": judge.model, "usage": judge.usage.to_json()}
        out.update(status=self.status, error=self.error)
        if self.error_type is not None:
            out["error_type"] = self.error_type
        out["wall_seconds"] = round(time.monotonic() - self.started, 3)
        return EpisodeResult(out, ep.images if ep is not None else {})
