"""Our levels as verifiers tasks, scored by our metrics.

A task is one level (its file, family, difficulty, optimal plan length) and how it is played
(protocol, images). It carries no prompt: the environment (``ChainGeoEnv``) opens each episode
with the level's first observation, rendered when the episode starts. The rewards read the
episode's :class:`~chaingeo.evaluation.episode.Outcome`, which the environment leaves on the
trace (``trace.info["chaingeo"]``); their weights are the task config's, so
``--env.taskset.task.rewards.efficiency.weight 0`` (or ``load_environment(reward=...)``) changes
them without code.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any, Literal

import verifiers.v1 as vf
from pydantic import Field

from chaingeo.core.level import Level, LevelError, load_level
from chaingeo.core.suite import FAMILIES, suite_folder
from chaingeo.evaluation.episode import Outcome
from chaingeo.integrations.game import (
    DEFAULT_WEIGHTS,
    Game,
    efficiency_reward,
    format_reward,
    offered_tools,
    success_reward,
    system_prompt,
)
from chaingeo.integrations.verifiers.typed import metric, reward

#: The id verifiers imports the taskset, its environment and its harness by (``chaingeo_env``).
TASKSET_ID = "chaingeo-env"
#: Where the environment leaves the episode's outcome on the trace.
INFO_KEY = "chaingeo"
SPLITS = ("test",)


class ChainGeoConfig(vf.TasksetConfig):  # type: ignore[misc]
    """Which levels, and how they are played (``--env.taskset.*``)."""

    family: Literal["puzzle", "stacking"] | None = None
    """Only this family's levels (None: both)."""
    difficulty: Literal["easy", "mid", "hard"] | None = None
    """Only this tier (None: all)."""
    split: Literal["test"] = "test"
    """The shipped suite is the test split (training splits: a ``level_dir``)."""
    level_dir: str | None = None
    """A folder of level files (e.g. from ``chain generate``) instead of the shipped suite."""
    images: bool = True
    """Send the rendered views as image parts (False: text only)."""
    protocol: Literal["interactive", "oneshot"] = "interactive"
    """One action per turn with feedback, or one whole plan from one view."""
    history_window: int = Field(5, ge=0)
    """Past turns shown in each observation (interactive)."""
    tools: bool = False
    """Offer the actions as native tool calls too (text ``<action>`` stays accepted)."""


class ChainGeoData(vf.TaskData):  # type: ignore[misc]
    """One level to play: where its file is, and the settings of the episode."""

    level_path: str
    family: str
    difficulty: str
    optimal_steps: int
    max_steps: int
    protocol: Literal["interactive", "oneshot"] = "interactive"
    images: bool = True
    history_window: int = 5
    tools: list[dict[str, Any]] | None = None
    """The functions the harness offers the model (OpenAI tool specs), or None for text only."""


def outcome_of(trace: Any) -> Outcome | None:
    """The outcome the environment left on ``trace``; None when the episode has none."""
    return Outcome.from_json(trace.info.get(INFO_KEY))


class ChainGeoTask(vf.Task[ChainGeoData, vf.State, vf.TaskConfig]):  # type: ignore[misc]
    """A level; its rewards, weighted to sum to 1 for an optimal, well-formed episode."""

    def game(self) -> Game:
        d: ChainGeoData = self.data
        level = load_level(d.level_path)
        return Game(level, d.protocol, d.images, d.history_window, tools=d.tools is not None)

    @reward(weight=DEFAULT_WEIGHTS["success"])
    async def success(self, trace: Any) -> float:
        """1 when the level was solved."""
        return success_reward(outcome_of(trace))

    @reward(weight=DEFAULT_WEIGHTS["efficiency"])
    async def efficiency(self, trace: Any) -> float:
        """``1 - NormDist`` (extra steps over the optimal plan, relative to it) when solved."""
        return efficiency_reward(outcome_of(trace))

    @reward(weight=DEFAULT_WEIGHTS["format"])
    async def format(self, trace: Any) -> float:
        """The share of actions the environment could read."""
        return format_reward(outcome_of(trace))

    @metric
    async def steps(self, trace: Any) -> float:
        """Steps used (every reply counts), for NormDist and AvgSteps over a run."""
        o = outcome_of(trace)
        return float(o.steps) if o is not None else 0.0


def select_levels(config: ChainGeoConfig) -> list[tuple[Path, Level]]:
    """The level files of ``config`` and their levels, sorted by id (a stable task order for
    ``--select``); a duplicate id is an error, as for :func:`load_levels`."""
    if config.split not in SPLITS:
        raise ValueError(f"unknown split {config.split!r}; use {', '.join(SPLITS)}")
    if config.level_dir is not None:
        folders = [Path(config.level_dir)]
    else:
        families = FAMILIES if config.family is None else (config.family,)
        folders = [suite_folder(f) for f in families]
    found = [(p, load_level(p)) for folder in folders for p in sorted(folder.rglob("*.json"))]
    ids = [lv.id for _, lv in found]
    if len(set(ids)) != len(ids):
        dup = sorted(i for i in ids if ids.count(i) > 1)[0]
        raise LevelError(str(folders[0]), "id", f"duplicate level id {dup!r}")
    keep = [
        (p, lv)
        for p, lv in found
        if config.family in (None, lv.family) and config.difficulty in (None, lv.difficulty)
    ]
    if not keep:
        wanted = f"family {config.family or 'any'}, difficulty {config.difficulty or 'any'}"
        raise LevelError(str(folders[0]), "levels", f"no level matches {wanted}")
    return sorted(keep, key=lambda item: item[1].id)


class ChainGeoTaskset(vf.Taskset[ChainGeoTask, ChainGeoConfig]):  # type: ignore[misc]
    """The shipped suite (or a folder of levels), filtered by family and difficulty."""

    def load(self) -> Iterator[ChainGeoTask]:
        cfg: ChainGeoConfig = self.config
        for path, level in select_levels(cfg):
            yield ChainGeoTask(
                ChainGeoData(
                    id=level.id,
                    name=level.id,
                    level_path=str(path),
                    family=level.family,
                    difficulty=level.difficulty,
                    optimal_steps=level.optimal_steps,
                    max_steps=level.max_steps,
                    protocol=cfg.protocol,
                    images=cfg.images,
                    history_window=cfg.history_window,
                    tools=offered_tools(level, cfg.protocol) if cfg.tools else None,
                    system_prompt=system_prompt(cfg.protocol, cfg.tools),
                ),
                cfg.task,
            )


__all__ = ["ChainGeoConfig", "ChainGeoData", "ChainGeoTask", "ChainGeoTaskset"]
