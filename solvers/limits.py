"""Caps on the solvers' searches, given by callers (``chain analyze --states/--seconds``, the
generator, the harness); limits on *input* sizes live in :mod:`chaingeo.core.limits`."""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["SearchLimits"]


@dataclass(frozen=True)
class SearchLimits:
    """Caps that turn an endless search into a :class:`SearchLimitError` with a clear message.

    ``max_states`` caps one part's breadth-first search; ``seconds`` the whole analysis;
    ``group_limit`` the movable groups per direction in one state; ``max_total_states`` the
    states of all searches of one analysis together (unlike time, the same on every machine);
    ``optimal_seconds`` the search for o_i within an analysis (None: the analysis' own time),
    so that a hard o_i does not hold back figures that are known already.
    """

    max_states: int = 2_000_000
    seconds: float | None = 120.0
    group_limit: int = 4096
    max_total_states: int | None = None  # over every search of one analysis (deterministic)
    optimal_seconds: float | None = None
