"""The fields of a run's header and episode records that readers rely on, checked as they are
read back: a hand-edited or damaged run gets one :class:`~chaingeo.evaluation.logs.RunError`
naming the file, the line and the field, never a traceback, a wrong count or a file name built
from a number (``"sample": 1e300``, ``"success": "yes"``, ``"usage": "lots"``)."""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

from chaingeo.core import limits
from chaingeo.core.level import DIFFICULTIES, FAMILIES, is_level_id

STATUSES = ("done", "error")
_USAGE_FIELDS = ("input_tokens", "output_tokens", "reasoning_tokens", "cached_tokens", "calls")


def _count(value: Any, maximum: int) -> bool:
    return isinstance(value, int) and not isinstance(value, bool) and 0 <= value <= maximum


def usage_problem(value: Any) -> str | None:
    """Why ``value`` is not a stored usage block (an object of token counts), or None."""
    if value is None:
        return None
    if not isinstance(value, Mapping):
        return "not an object"
    for name in _USAGE_FIELDS:
        if name in value and not _count(value[name], limits.MAX_USAGE_TOKENS):
            return f"{name} is not a token count"
    return None


def _field_problems(rec: Mapping[str, Any]) -> tuple[str, str] | None:
    level_id, sample = rec.get("level_id"), rec.get("sample", 0)
    checks: list[tuple[str, bool, str]] = [
        ("level_id", is_level_id(level_id), "not a level id"),
        ("sample", _count(sample, limits.MAX_SAMPLES - 1), "not a sample number"),
        ("key", rec.get("key") == f"{level_id}#{sample}", "not level_id#sample"),
        ("family", rec.get("family") in FAMILIES, "not a family"),
        ("difficulty", rec.get("difficulty") in DIFFICULTIES, "not a difficulty"),
        ("optimal_steps", _count(rec.get("optimal_steps"), limits.MAX_STEPS), "not a count"),
        ("steps_used", _count(rec.get("steps_used"), limits.MAX_STEPS), "not a count"),
        ("success", isinstance(rec.get("success"), bool), "not true or false"),
        ("status", rec.get("status", "done") in STATUSES, f"not one of {list(STATUSES)}"),
        ("steps", isinstance(rec.get("steps", []), list), "not a list"),
    ]
    for name, ok, reason in checks:
        if not ok:
            return name, reason
    cost = rec.get("cost_usd")
    if cost is not None and not (
        isinstance(cost, int | float) and not isinstance(cost, bool) and math.isfinite(cost)
    ):
        return "cost_usd", "not a number"
    problem = usage_problem(rec.get("usage"))
    if problem:
        return "usage", problem
    judge = rec.get("judge")
    if judge is not None and (not isinstance(judge, Mapping) or usage_problem(judge.get("usage"))):
        return "judge", "not an object with a usage block"
    plan = rec.get("plan")
    if plan is not None and _turn_problem(plan):
        return "plan", str(_turn_problem(plan))
    for i, step in enumerate(rec.get("steps", [])):
        problem = _turn_problem(step)
        if problem:
            return f"steps[{i}]", problem
    return None


def _turn_problem(turn: Any) -> str | None:
    """Why a step (or a one-shot plan) is not one readers can show, or None."""
    if not isinstance(turn, Mapping):
        return "not an object"
    if "turn" in turn and not _count(turn["turn"], limits.MAX_STEPS):
        return "turn: not a turn number"
    for name in ("usage", "judge_usage"):
        if usage_problem(turn.get(name)):
            return f"{name}: {usage_problem(turn.get(name))}"
    cands = turn.get("candidates")
    if cands is not None and not (
        isinstance(cands, list)
        and all(isinstance(c, Mapping) and not usage_problem(c.get("usage")) for c in cands)
    ):
        return "candidates: not a list of objects with usage blocks"
    return None


def record_problem(rec: Any) -> str | None:
    """Why ``rec`` is not an episode record readers can use (``field: reason``), or None."""
    if not isinstance(rec, Mapping):
        return "not an object"
    found = _field_problems(rec)
    return None if found is None else f"{found[0]}: {found[1]}"


def header_problem(header: Any) -> str | None:
    """Why ``header`` is not a run header readers can use, or None."""
    if not isinstance(header, Mapping):
        return "not an object"
    agent = header.get("agent")
    if not isinstance(agent, Mapping) or not isinstance(agent.get("name"), str):
        return "agent: not an object with a name"
    protocol = header.get("protocol", {})
    if not isinstance(protocol, Mapping) or not _count(protocol.get("candidates", 1), 10**6):
        return "protocol: not an object with a count of candidates"
    label = header.get("label")
    if label is not None and not isinstance(label, str):
        return "label: not a string"
    levels = header.get("levels", [])
    if not isinstance(levels, list) or not all(is_level_id(x) for x in levels):
        return "levels: not a list of level ids"
    if not _count(header.get("samples", 1), limits.MAX_SAMPLES):
        return "samples: not a sample count"
    return None
