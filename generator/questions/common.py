"""Helpers the question families share: draws, number options and the registry.

The registry maps a category name to the function that drafts its questions for one level; it
refuses a second function under a name already taken (:class:`chaingeo.core.registry.Registry`).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any, TypeVar

import numpy as np

from chaingeo.core.level import Level
from chaingeo.core.registry import Registry
from chaingeo.generator.questions.model import Option, Question

T = TypeVar("T")

#: A category's drafter: (level, random generator) -> its questions on that level.
Drafter = Callable[[Level, np.random.Generator], list[Question]]

CATEGORIES: Registry[Drafter] = Registry("question category")


def pick(rng: np.random.Generator, items: Sequence[T], k: int) -> list[T]:
    """``k`` distinct items in a random order (all of them if fewer)."""
    if len(items) <= k:
        return [items[i] for i in rng.permutation(len(items)).tolist()]
    return [items[i] for i in rng.choice(len(items), size=k, replace=False).tolist()]


def number_options(
    rng: np.random.Generator, value: int, lowest: int, unit: str
) -> tuple[Option, list[Option], list[int]]:
    """The right number and three wrong ones: four consecutive whole numbers from ``lowest``
    up, the window placed at random around ``value`` so its rank among them says nothing."""
    first = max(lowest, value - int(rng.integers(0, 4)))
    values = list(range(first, first + 4))
    words = [f"{v} {unit if v == 1 else unit + 's'}" for v in values]
    right = Option(words[values.index(value)])
    wrong = [Option(w) for v, w in zip(values, words, strict=True) if v != value]
    return right, wrong, values


def names_text(names: Sequence[str]) -> str:
    return "+".join(sorted(names))


def jsonable(moves: Sequence[Any]) -> list[Any]:
    return [m.to_json() for m in moves]
