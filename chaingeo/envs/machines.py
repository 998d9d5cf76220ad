"""The state machine for a level: the one place that chooses between the two families."""

from __future__ import annotations

from chaingeo.core.level import Level
from chaingeo.envs.puzzle import PuzzleState
from chaingeo.envs.stacking import StackingState
from chaingeo.envs.state import BaseState


def new_state(level: Level) -> BaseState:
    """The state machine for a level, at its start: stacking, or puzzle (either goal)."""
    if level.family == "stacking":
        return StackingState(level)
    return PuzzleState(level)
