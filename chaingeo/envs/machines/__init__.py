"""The state machines: the base state, stacking, puzzles (with their action tables and turns),
and :func:`new_state`, the one place that chooses between the two families."""

from __future__ import annotations

from chaingeo.core.level import Level
from chaingeo.envs.machines.puzzle import PuzzleState
from chaingeo.envs.machines.stacking import StackingState
from chaingeo.envs.machines.state import BaseState


def new_state(level: Level) -> BaseState:
    """The state machine for a level, at its start: stacking, or puzzle (either goal)."""
    if level.family == "stacking":
        return StackingState(level)
    return PuzzleState(level)
