"""A minimal stand-in for ``chaingeo.envs.machines.state`` / ``chaingeo.envs.observation`` (a test
double).

The game: take every piece once (``take NAME``), in any order. It follows the contract the
harness relies on: ``step_text`` parses and applies, an unparseable or illegal action changes
nothing but costs a step, success when every piece is taken, truncation at the budget.
Set ``FAKE_ENV_DELAY`` (seconds) to slow every observation down (for the kill-and-resume test).
"""

from __future__ import annotations

import io
import os
import time
from collections.abc import Hashable
from dataclasses import dataclass, field

from PIL import Image

from chaingeo.core.level import Level


@dataclass(frozen=True, order=True)
class FakeAction:
    text: str

    def to_text(self) -> str:
        return self.text


@dataclass(frozen=True)
class FakeResult:
    action: FakeAction | None
    legal: bool
    error: str | None
    feedback: str
    success: bool
    truncated: bool


class FakeState:
    def __init__(self, level: Level) -> None:
        self.level = level
        self.max_steps = level.max_steps
        self.steps_used = 0
        self.taken: tuple[str, ...] = ()
        self.finished = False
        self.history: list[str] = []

    def legal_actions(self) -> list[FakeAction]:
        if self.finished:
            return []
        names = sorted(p.name for p in self.level.pieces if p.name not in self.taken)
        return [FakeAction(f"take {n}") for n in names] + [FakeAction("finish")]

    def _check(self, text: str) -> tuple[FakeAction | None, str | None, str]:
        words = text.split()
        if words == ["finish"]:
            return FakeAction("finish"), None, "finished"
        if len(words) != 2 or words[0] != "take":
            return None, "unparseable", f"cannot parse {text!r}: write 'take NAME'"
        name = words[1]
        if name not in {p.name for p in self.level.pieces}:
            return FakeAction(text), "illegal", f"unknown piece {name}"
        if name in self.taken:
            return FakeAction(text), "illegal", f"{name} is already taken"
        return FakeAction(text), None, f"took {name}"

    def apply(self, action: FakeAction) -> None:
        _, error, feedback = self._check(action.text)
        if error:
            raise ValueError(feedback)
        self._commit(action)

    def _commit(self, action: FakeAction) -> None:
        self.steps_used += 1
        if action.text == "finish":
            self.finished = True
        else:
            self.taken = (*self.taken, action.text.split()[1])

    def step_text(self, text: str) -> FakeResult:
        action, error, feedback = self._check(text.strip())
        if error is None and action is not None:
            self._commit(action)
        else:
            self.steps_used += 1
        self.history.append(f"{text!r}: {feedback}")
        return FakeResult(
            action if error is None else None,
            error is None,
            error,
            feedback,
            self.is_success(),
            self.is_truncated(),
        )

    def clone(self) -> FakeState:
        other = FakeState(self.level)
        other.steps_used, other.taken, other.finished, other.history = (
            self.steps_used,
            self.taken,
            self.finished,
            list(self.history),
        )
        return other

    def key(self) -> Hashable:
        return tuple(sorted(self.taken))

    def is_success(self) -> bool:
        return len(self.taken) == len(self.level.pieces)

    def is_truncated(self) -> bool:
        return self.steps_used >= self.max_steps


@dataclass(frozen=True)
class FakeObservation:
    instruction: str
    color_table: dict[str, str]
    history: list[str]
    steps_left: int
    text_state: str | None = None
    images: dict[str, bytes] = field(default_factory=dict)

    def to_text(self) -> str:
        parts = [self.instruction, "\n".join(f"{k}: {v}" for k, v in self.color_table.items())]
        parts += self.history + ([self.text_state] if self.text_state else [])
        parts.append(f"Steps left: {self.steps_left}")
        return "\n\n".join(parts)


def _png(seed: int, view: int) -> bytes:
    img = Image.new("RGB", (8, 8), (seed * 37 % 256, view * 60 % 256, 90))
    buf = io.BytesIO()
    img.save(buf, format="PNG")
    return buf.getvalue()


def new_state(level: Level) -> FakeState:
    return FakeState(level)


def observe(
    state: FakeState, history_window: int = 5, text_state: bool = False, images: bool = True
) -> FakeObservation:
    delay = float(os.environ.get("FAKE_ENV_DELAY", "0") or 0)
    if delay:
        time.sleep(delay)
    views = ("front", "side", "top", "iso")
    return FakeObservation(
        instruction="Take every piece: write 'take NAME'.",
        color_table={p.name: p.rgb for p in state.level.pieces},
        history=state.history[-history_window:] if history_window else [],
        steps_left=state.max_steps - state.steps_used,
        text_state=f"taken: {list(state.taken)}" if text_state else None,
        images={v: _png(len(state.taken), i) for i, v in enumerate(views)} if images else {},
    )
