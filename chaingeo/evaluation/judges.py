"""Judges by name: the built-in ones of :mod:`chaingeo.evaluation.selection`, the vision-language
judge of :mod:`chaingeo.evaluation.model_judge`, and any registered with :func:`register_judge`
(a factory taking the judge options: a trained reward model, ...)."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any

from chaingeo.evaluation.model_judge import ModelJudge
from chaingeo.evaluation.selection import FirstLegal, Judge, Progress, Vote

JUDGES: dict[str, Callable[[Mapping[str, Any]], Judge]] = {
    "first": lambda options: FirstLegal(),
    "vote": lambda options: Vote(),
    "progress": lambda options: Progress(),
    "model": ModelJudge,
}


def register_judge(name: str, factory: Callable[[Mapping[str, Any]], Judge]) -> None:
    JUDGES[name] = factory


def make_judge(name: str, options: Mapping[str, Any] | None = None) -> Judge:
    try:
        factory = JUDGES[name]
    except KeyError:
        raise ValueError(f"unknown judge {name!r}; known: {sorted(JUDGES)}") from None
    return factory(options or {})
