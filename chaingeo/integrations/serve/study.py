"""A human-baseline study: levels in a seeded order per participant, every episode a run record.

``chain serve --study NAME --levels DIR`` writes one run directory, ``STUDY_DIR/NAME``, in the
format ``chain eval`` writes (:mod:`chaingeo.evaluation.logs`; agent ``human``), so ``chain
report`` puts a ``human`` row beside the models and the human table (solve times by tier). A
participant is an anonymous id the browser makes up; their order of levels is a permutation
drawn from ``SeedSequence([seed, sha256(id)])``, so the same id gets the same order on any
machine, and a restarted server (same name, levels and seed) resumes where each one was: a
participant's next level is the first of their order without a record. Each record keeps every
action with its time (seconds since the level started); ``optimal_steps`` is never shown to
the participant (the observations hide it), only written in the record for the metrics.
"""

from __future__ import annotations

import hashlib
import re
import threading
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Final

import numpy as np

from chaingeo.core import limits
from chaingeo.core.level import Level, level_set_hash
from chaingeo.evaluation.logs import RunError, RunLog, make_header
from chaingeo.integrations.serve.errors import StudyError
from chaingeo.integrations.serve.session import Play

NAME_RE: Final = re.compile(rf"[A-Za-z0-9_-]{{1,{limits.MAX_PARTICIPANT_CHARS}}}")
HUMAN: Final = "human"


def participant_seed(seed: int, participant: str) -> int:
    digest = int(hashlib.sha256(participant.encode("utf-8")).hexdigest()[:15], 16)
    return int(np.random.SeedSequence([seed, digest]).generate_state(1)[0])


@dataclass
class Study:
    """One study's levels, seed, run directory and progress (thread-safe: sessions share it)."""

    name: str
    levels: list[Level]
    seed: int
    log: RunLog
    done: dict[str, set[str]] = field(default_factory=dict)  # participant -> level ids
    samples: dict[str, int] = field(default_factory=dict)  # participant -> record sample
    lock: threading.Lock = field(default_factory=threading.Lock)

    def close(self) -> None:
        """Release the study's run folder (its writer's lock) for another server."""
        with self.lock:
            self.log.close()

    @classmethod
    def create(cls, name: str, folder: Path, levels: Sequence[Level], seed: int) -> Study:
        if not NAME_RE.fullmatch(name):
            raise StudyError("a study's name is 1-64 letters, digits, '-' or '_'")
        ordered = sorted(levels, key=lambda lv: lv.id)
        header = make_header(
            agent={"name": HUMAN, "kind": HUMAN},
            protocol={"name": "interactive", "study": name, "history_window": 5},
            level_set_hash=level_set_hash(ordered),
            levels=[lv.id for lv in ordered],
            seed=seed,
            samples=1,
            extra={"label": HUMAN, "study": name},
        )
        try:
            log = RunLog.create(folder / name, header, resume=True)
        except RunError as e:
            raise StudyError(str(e)) from None
        study = cls(name, ordered, seed, log)
        for rec in log.records():
            who = str(rec.get("participant", ""))
            study.done.setdefault(who, set()).add(str(rec["level_id"]))
            study.samples.setdefault(who, int(rec.get("sample", 0)))
        return study

    @staticmethod
    def check_participant(value: Any) -> str:
        if not isinstance(value, str) or not NAME_RE.fullmatch(value):
            raise StudyError("participant is an id of 1-64 letters, digits, '-' or '_'")
        return value

    def order(self, participant: str) -> list[Level]:
        rng = np.random.default_rng(participant_seed(self.seed, participant))
        return [self.levels[i] for i in rng.permutation(len(self.levels))]

    def next_level(self, participant: str) -> Level:
        with self.lock:
            seen = self.done.get(participant, set())
            for level in self.order(participant):
                if level.id not in seen:
                    return level
        raise StudyError("you have played every level of this study: thank you")

    def record(self, participant: str, play: Play, episode_id: str | None) -> None:
        with self.lock:
            if play.level.id in self.done.get(participant, set()):
                return
            sample = self.samples.setdefault(participant, len(self.samples))
            self.log.append(study_record(play, participant, sample, self.name, episode_id))
            self.done.setdefault(participant, set()).add(play.level.id)


def study_record(
    play: Play, participant: str, sample: int, study: str, episode_id: str | None
) -> dict[str, Any]:
    """The run record of one human episode: the episode's own record (as ``chain eval`` writes
    it, every step with its time ``t``) and who played it, when, how long."""
    ep = play.episode
    ep.sample = sample
    record = ep.record()
    times = [s["t"] for s in ep.steps]
    record.update(
        model=None,
        participant=participant,
        study=study,
        episode_id=episode_id,
        status="done",
        error=None,
        wall_seconds=round(time.monotonic() - play.started, 3),
        solve_seconds=times[-1] if record["success"] and times else None,
    )
    return record
