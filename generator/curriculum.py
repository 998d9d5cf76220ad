"""Curriculum settings: one knob per family, ``K = 0`` easiest, each step harder.

A trainer wants "a bit harder than last time" without learning the generator's parameters, so
each family gets an ordered list of configurations; ``chain generate FAMILY --curriculum K``
picks step ``K``. Stacking walks up the modes (cuboids, planar pieces, free shapes with a least
search effort) and the box sizes; small boxes in easy mode are left out, as their few distinct
puzzles are all in the shipped suite (a train split would refuse every one). Puzzles walk up
the level of the first removal (three-piece burrs, then maze burrs whose level is the number of
straight runs of a path). Each step costs about a second per item or less; the tier mix
measured per step is in docs/benchmarks/generation.md.
"""

from __future__ import annotations

from typing import Final

from chaingeo.generator.config import PuzzleConfig, StackingConfig, stacking_config

#: Stacking steps: (box, mode), easy to hard.
STACKING_STEPS: Final[tuple[tuple[tuple[int, int, int], str], ...]] = (
    ((3, 4, 4), "easy"),
    ((4, 4, 4), "easy"),
    ((2, 3, 4), "mid"),
    ((3, 3, 3), "mid"),
    ((3, 4, 4), "mid"),
    ((3, 3, 3), "hard"),
    ((3, 3, 4), "hard"),
    ((4, 4, 4), "hard"),
)

#: The three-piece burr's settings (docs/guides/generating.md: 1 s per item, levels 1 to 4).
_BURR3: Final[dict[str, object]] = {"shape": "burr3", "hole_rate": 0.8, "hill_steps": 100}

#: Puzzle steps: PuzzleConfig fields, easy to hard (first-removal level grows with K).
PUZZLE_STEPS: Final[tuple[dict[str, object], ...]] = (
    {**_BURR3, "min_level": 1, "hill_steps": 0},  # random designs, no climbing: mostly level 1
    {**_BURR3, "min_level": 2},
    {**_BURR3, "min_level": 3},
    {**_BURR3, "min_level": 4},
    {"shape": "maze4", "min_level": 5, "hill_steps": 300},
    {"shape": "maze5", "min_level": 8, "hill_steps": 300},
    {"shape": "maze6", "min_level": 10, "hill_steps": 300},
)

CURRICULA: Final[dict[str, int]] = {"stacking": len(STACKING_STEPS), "puzzle": len(PUZZLE_STEPS)}


def _check(family: str, k: int) -> None:
    top = CURRICULA[family] - 1
    if not 0 <= k <= top:
        raise ValueError(f"--curriculum for {family} runs from 0 (easiest) to {top}, got {k}")


def stacking_step(k: int) -> StackingConfig:
    """The stacking configuration of curriculum step ``k``."""
    _check("stacking", k)
    box, mode = STACKING_STEPS[k]
    return stacking_config(box, mode)


def puzzle_step(k: int) -> PuzzleConfig:
    """The puzzle configuration of curriculum step ``k``."""
    _check("puzzle", k)
    return PuzzleConfig(**PUZZLE_STEPS[k])  # type: ignore[arg-type]
