"""Replay: actions from a file, or the actions a recorded run sent (to reproduce it exactly).

``options["file"]`` is either a JSON object ``{"LEVEL_ID": ["action", ...], ...}`` (one plan
per level, used for every sample), or a run directory, whose ``episodes.jsonl`` gives, per
level and sample, the action text of every step in order. When a plan runs out the agent says
``finish``.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

from chaingeo.core import limits
from chaingeo.core.files import UnreadableFile, read_json
from chaingeo.core.level import Level
from chaingeo.evaluation.agents.base import Agent, Reply, Turn
from chaingeo.evaluation.logs import EPISODES, RunLog


def load_plans(source: str | Path) -> dict[tuple[str, int | None], tuple[str, ...]]:
    """(level id, sample or None for any sample) -> actions."""
    path = Path(source)
    if path.is_dir():
        if not (path / EPISODES).exists():
            raise ValueError(f"{path}: not a run directory (no {EPISODES})")
        plans: dict[tuple[str, int | None], tuple[str, ...]] = {}
        for rec in RunLog(path).latest().values():
            steps = rec.get("steps") or []
            plans[(str(rec["level_id"]), int(rec.get("sample", 0)))] = tuple(
                str(s.get("sent", "")) for s in steps
            )
        return plans
    try:  # the one bounded JSON reader
        data = read_json(path, limits.MAX_FILE_BYTES)
    except UnreadableFile as e:
        raise ValueError(f"{path}: cannot read replay file: {e.reason}") from None
    if not isinstance(data, dict) or not all(
        isinstance(v, list) and all(isinstance(a, str) for a in v) for v in data.values()
    ):
        raise ValueError(f"{path}: expected an object mapping level ids to lists of actions")
    return {(str(k), None): tuple(v) for k, v in data.items()}


class ReplayAgent(Agent):
    name = "replay"
    uses_images = False

    def __init__(self, options: Mapping[str, Any]) -> None:
        if not options.get("file"):
            raise ValueError("the replay agent needs a file (--agent-option file=PATH)")
        self.plans = load_plans(str(options["file"]))
        self._level = ""

    def start(self, level: Level, seed: int) -> None:
        self._level = level.id

    def _plan(self, sample: int) -> tuple[str, ...]:
        plan = self.plans.get((self._level, sample))
        if plan is None:
            plan = self.plans.get((self._level, None), ())
        return plan

    def act(self, turn: Turn) -> Reply:
        plan = self._plan(turn.sample)
        if turn.index < len(plan):
            return Reply(plan[turn.index], plan[turn.index])
        return Reply("finish", "finish", note="the replayed plan ran out")

    def plan(self, turn: Turn) -> Reply:
        plan = self._plan(turn.sample)
        return Reply("\n".join(plan), None, actions=plan)
