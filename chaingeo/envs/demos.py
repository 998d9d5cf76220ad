"""Demonstrations: each level's stored optimal plan replayed through the Gymnasium environment.

A level's ``solution`` is a plan of ``optimal_steps`` actions (stacking: the placements in the
stored order; puzzles: the stored moves and turns). Replayed through :class:`ChainEnv`, it gives
the (observation, action text, reward) trajectory an imitation learner wants, with the exact
text an agent is shown and writes. Records are canonical JSON lines (sorted keys, no
whitespace), one per step, so the same levels give the same bytes. Pictures are left out of the
JSON lines (logs never hold images); ``demonstration(level, picture_size=N)`` adds the PNG of
every view shown with each step, for the dataset export (:mod:`chaingeo.envs.dataset`).
"""

from __future__ import annotations

import json
from collections.abc import Iterable, Iterator
from pathlib import Path
from typing import Any

from chaingeo.core.errors import ChainGeoError
from chaingeo.core.files import atomic_path
from chaingeo.core.level import Level, PuzzleSolution, StackingSolution
from chaingeo.envs.actions.types import PlaceAction, action_of_move


class DemonstrationError(ChainGeoError, RuntimeError):
    """A stored plan that does not solve its level when replayed (a broken level file)."""


def plan_texts(level: Level) -> list[str]:
    """The canonical text of every action of the level's stored optimal plan, in order."""
    solution = level.solution
    if isinstance(solution, StackingSolution):
        return [PlaceAction(n, solution.placements[n].cells).to_text() for n in solution.order]
    if isinstance(solution, PuzzleSolution):
        return [action_of_move(m).to_text() for m in solution.moves]
    raise DemonstrationError(f"level {level.id!r} stores no plan")


def demonstration(
    level: Level, *, picture_size: int | None = None, **env_kwargs: Any
) -> Iterator[dict[str, Any]]:
    """One record per step of the level's plan: ``level_id``, ``step`` (1-based),
    ``observation`` (the text shown before the action), ``action``, ``reward``,
    ``terminated``, ``truncated``, ``feedback``. ``env_kwargs`` go to the environment (for
    example ``text_state=True``). With ``picture_size``, ``images`` too: view name -> PNG bytes
    of the pictures shown with the text (which then names them), in the environment's order."""
    from chaingeo.envs.gym import PuzzleEnv, StackingEnv

    cls = StackingEnv if level.family == "stacking" else PuzzleEnv
    drawn = {"images": True, "image_size": picture_size} if picture_size else {"images": False}
    env = cls([level], **{**env_kwargs, **drawn})
    obs, _ = env.reset(options={"level": level.id})
    plan = plan_texts(level)
    for step, action in enumerate(plan, start=1):
        shown = obs["text"]
        pictures = _pngs(obs["images"]) if picture_size else None
        obs, reward, terminated, truncated, info = env.step(action)
        record = {
            "level_id": level.id,
            "step": step,
            "observation": shown,
            "action": action,
            "reward": reward,
            "terminated": terminated,
            "truncated": truncated,
            "feedback": info["feedback"],
        }
        yield record if pictures is None else {**record, "images": pictures}
        if not info["legal"] or ((terminated or truncated) and step < len(plan)):
            raise DemonstrationError(
                f"level {level.id!r}: step {step} of its plan ({action!r}) was refused or "
                f"ended the episode early: {info['feedback']}"
            )
    if not env.state.is_success():
        raise DemonstrationError(f"level {level.id!r}: its plan does not solve it")


def _pngs(frames: dict[str, Any]) -> dict[str, bytes]:
    """PNG bytes of the environment's pixel arrays (pixel-equal to ``render_state``'s PNGs)."""
    from PIL import Image

    from chaingeo.pictures.raster import png_bytes

    return {name: png_bytes(Image.fromarray(frame)) for name, frame in frames.items()}


def demonstration_lines(levels: Iterable[Level], **env_kwargs: Any) -> Iterator[str]:
    """Canonical JSON lines of every level's demonstration, levels sorted by id."""
    for level in sorted(levels, key=lambda lv: lv.id):
        for record in demonstration(level, **env_kwargs):
            yield json.dumps(record, sort_keys=True, separators=(",", ":"), ensure_ascii=True)


def write_demonstrations(levels: Iterable[Level], path: Path, **env_kwargs: Any) -> int:
    """Write :func:`demonstration_lines` to ``path`` (JSONL); returns the number of records."""
    count = 0
    with atomic_path(path) as tmp, tmp.open("w", encoding="ascii", newline="\n") as out:
        for line in demonstration_lines(levels, **env_kwargs):
            out.write(line + "\n")
            count += 1
    return count
