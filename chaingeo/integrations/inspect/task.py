"""The task ``chaingeo/chain``: its parameters (``-T``), its levels and its samples.

``inspect eval chaingeo/chain -T family=stacking -T levels=3 --model openai/gpt-4o`` plays the
first three stacking levels of the shipped suite. Parameters:

- ``family``: ``puzzle``, ``stacking`` or ``all``; ``tier``: ``easy``, ``mid`` or ``hard``.
- ``levels``: a count (the first N by id), a folder or file of levels, or level ids (a list,
  or comma-separated).
- ``protocol``: ``interactive`` (or ``both`` to run each level under both, as ``chain eval
  --protocol both``: samples ``ID`` and ``ID@oneshot``), ``one_shot`` / ``oneshot``.
- ``dialect``: ``text`` (``<action>`` tags) or ``tools`` (native tool calls).
- ``images``: on / off, or the views to show (``front,top``).
- ``history`` (turns kept, default 5), ``max_steps`` (default: each level's own budget),
  ``seed``, ``agent`` (``model``, or ``oracle``: the stored plans through the same path).
- ``config``: an evaluation config (``chain-paper``, or a ``.toml`` file; see
  :mod:`chaingeo.evaluation.eval_config`): its protocols, history, pictures, budgets and
  sampling (temperature, top-p); explicit parameters override it.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

from inspect_ai import Epochs, Task, task
from inspect_ai.dataset import MemoryDataset, Sample

from chaingeo.core.errors import ChainGeoError
from chaingeo.core.level import Level, load_levels
from chaingeo.core.suite import load_level, suite_folder
from chaingeo.evaluation.episode import Episode, ProtocolConfig
from chaingeo.evaluation.eval_config import EvalConfig, load_config
from chaingeo.integrations.inspect._encoding import seed_o200k
from chaingeo.integrations.inspect.scoring import METRICS, REDUCERS, success
from chaingeo.integrations.inspect.solver import first_messages, play_level

FAMILY_CHOICES = ("all", "puzzle", "stacking")
TIERS = ("easy", "mid", "hard")
PROTOCOL_NAMES = {"interactive": "interactive", "one_shot": "oneshot", "oneshot": "oneshot"}


class TaskParameterError(ChainGeoError, ValueError):
    """A ``-T`` parameter of the chain task that cannot be used."""


def select_levels(family: str, tier: str | None, levels: Any) -> list[Level]:
    """The levels a task plays, sorted by id."""
    if family not in FAMILY_CHOICES:
        raise TaskParameterError(f"family={family!r}: use one of {', '.join(FAMILY_CHOICES)}")
    if tier is not None and tier not in TIERS:
        raise TaskParameterError(f"tier={tier!r}: use one of {', '.join(TIERS)}")
    count: int | None = None
    if levels is None or isinstance(levels, int) or str(levels).isdigit():
        count = None if levels is None else int(levels)
        chosen = load_levels(suite_folder())
    elif isinstance(levels, str) and Path(levels).exists():
        path = Path(levels)
        chosen = load_levels(path) if path.is_dir() else [load_level(path)]
    else:
        ids = levels if isinstance(levels, list | tuple) else str(levels).split(",")
        chosen = [load_level(str(i).strip()) for i in ids if str(i).strip()]
    chosen = [
        lv
        for lv in chosen
        if (family == "all" or lv.family == family) and (tier is None or lv.difficulty == tier)
    ]
    chosen = sorted(chosen, key=lambda lv: lv.id)[:count]
    if count is not None and count < 1:
        raise TaskParameterError(f"levels={levels!r}: a count is at least 1")
    if not chosen:
        raise TaskParameterError(f"no level matches family={family}, tier={tier}, levels={levels}")
    return chosen


def parse_images(images: Any) -> tuple[bool, list[str] | None]:
    """``images`` as (pictures on?, the views to keep or None for all)."""
    if isinstance(images, bool):
        return images, None
    text = str(images).strip().lower()
    if text in ("on", "true", "yes", "1", "all"):
        return True, None
    if text in ("off", "false", "no", "0", "none"):
        return False, None
    views = [v.strip() for v in text.split(",") if v.strip()]
    return True, views


def _protocols(protocol: str | None, config: EvalConfig) -> list[str]:
    if protocol is None:
        return list(config.protocols)
    if protocol == "both":
        return ["interactive", "oneshot"]
    if protocol not in PROTOCOL_NAMES:
        raise TaskParameterError(f"protocol={protocol!r}: use interactive, one_shot or both")
    return [PROTOCOL_NAMES[protocol]]


def _sample(level: Level, proto: ProtocolConfig, dialect: str, images: bool, views: Any) -> Sample:
    episode = Episode(level, proto, images=images, keep_images=False)
    suffix = "" if proto.name == "interactive" else "@oneshot"
    return Sample(
        id=level.id + suffix,
        input=first_messages(episode, dialect, views),
        target=str(level.optimal_steps),
        metadata={
            "level_id": level.id,
            "family": level.family,
            "difficulty": level.difficulty,
            "o_i": level.optimal_steps,
            "max_steps": level.max_steps,
            "protocol": proto.name,
        },
    )


@task
def chain(
    family: str = "all",
    tier: str | None = None,
    levels: Any = None,
    protocol: str | None = None,
    dialect: str = "text",
    images: Any = None,
    history: int | None = None,
    max_steps: int | None = None,
    seed: int = 0,
    agent: str = "model",
    config: str | None = None,
) -> Task:
    """CHAIN's levels played by a model (see the module docstring for the parameters)."""
    seed_o200k()
    cfg = load_config(config) if config else EvalConfig()
    if agent not in ("model", "oracle"):
        raise TaskParameterError(f"agent={agent!r}: use model or oracle")
    if dialect not in ("text", "tools"):
        raise TaskParameterError(f"dialect={dialect!r}: use text or tools")
    on, views = parse_images(cfg.images if images is None else images)
    window = cfg.history_window if history is None else int(history)
    budget = cfg.max_steps if max_steps is None else int(max_steps)
    chosen = EvalConfig(max_steps=budget).budgeted(select_levels(family, tier, levels))
    by_id = {lv.id: lv for lv in chosen}
    samples, protos = [], {}
    for name in _protocols(protocol, cfg):
        proto = cfg.protocol(name, history_window=window)  # type: ignore[arg-type]
        protos[name] = proto
        samples += [_sample(lv, proto, dialect, on, views) for lv in chosen]
    solver = play_level(by_id, protos, dialect, on, views, agent, int(seed), cfg.sampling())  # type: ignore[arg-type]
    return Task(
        dataset=MemoryDataset(samples, name="chaingeo"),
        solver=solver,
        scorer=success(),
        metrics=METRICS,
        epochs=Epochs(1, REDUCERS),
        name="chain",
    )


__all__: Sequence[str] = ["chain", "select_levels"]
