"""The shipped level suite, parsed once per test process: a dozen modules parametrize over it at
collection, and each pytest-xdist worker collects every module, so parsing it per module cost
each worker seconds before its first test."""

from __future__ import annotations

from functools import cache

from chaingeo.core.level import Family, Level, load_levels
from tests.support.paths import LEVELS


@cache
def _suite() -> tuple[Level, ...]:
    """Every shipped level, sorted by id (``load_levels`` also refuses a duplicate id)."""
    return tuple(load_levels(LEVELS)) if LEVELS.is_dir() else ()


def shipped(family: Family | None = None) -> list[Level]:
    """The shipped levels (of one family), sorted by id; a new list of the shared, frozen levels."""
    return [lv for lv in _suite() if family is None or lv.family == family]
