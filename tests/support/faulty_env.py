"""The fake environment with faults keyed by level id (a test double for the harness's fault
handling): on ``L01`` every ``step_text`` raises ``ZeroDivisionError``, on ``L02`` observing
recurses until ``RecursionError``, on ``L03`` the process playing it dies (``os._exit``) when
``FAULTY_ENV_DIE`` is set. Every other level plays as in :mod:`tests.support.fake_env`.
"""

from __future__ import annotations

import os

from chaingeo.core.level import Level
from tests.support import fake_env
from tests.support.fake_env import FakeObservation, FakeResult, FakeState


class FaultyState(FakeState):
    def step_text(self, text: str) -> FakeResult:
        if self.level.id == "L01":
            raise ZeroDivisionError("the environment divided by zero")
        if self.level.id == "L03" and os.environ.get("FAULTY_ENV_DIE"):
            os._exit(3)
        return super().step_text(text)

    def clone(self) -> FaultyState:
        other = FaultyState(self.level)
        other.steps_used, other.taken, other.finished, other.history = (
            self.steps_used,
            self.taken,
            self.finished,
            list(self.history),
        )
        return other


def _deep(n: int) -> int:
    return _deep(n + 1) + 1


def new_state(level: Level) -> FaultyState:
    return FaultyState(level)


def observe(
    state: FakeState, history_window: int = 5, text_state: bool = False, images: bool = True
) -> FakeObservation:
    if state.level.id == "L02":
        _deep(0)
    return fake_env.observe(state, history_window, text_state, images)
