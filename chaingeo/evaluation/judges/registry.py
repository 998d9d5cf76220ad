"""Judges by name: the built-in ones of :mod:`chaingeo.evaluation.judges.selection`, the
vision-language judge of :mod:`chaingeo.evaluation.judges.model_judge`, and any registered with
:func:`register_judge` (a factory taking the judge options: a trained reward model, ...)."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any

from chaingeo.core.registry import Registry
from chaingeo.evaluation.judges.model_judge import ModelJudge
from chaingeo.evaluation.judges.selection import FirstLegal, Judge, ProgressJudge, Vote

#: Judge factories by name (taking the judge options); a taken name is refused.
JUDGES: Registry[Callable[[Mapping[str, Any]], Judge]] = Registry("judge")
JUDGES.register("first", lambda options: FirstLegal())
JUDGES.register("vote", lambda options: Vote())
JUDGES.register("progress", lambda options: ProgressJudge())
JUDGES.register("model", ModelJudge)


def register_judge(name: str, factory: Callable[[Mapping[str, Any]], Judge]) -> None:
    """Add a judge; a name already taken raises :class:`DuplicateNameError`."""
    JUDGES.register(name, factory)


def make_judge(name: str, options: Mapping[str, Any] | None = None) -> Judge:
    return JUDGES.get(name)(options or {})
