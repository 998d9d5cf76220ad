"""The state-machine contract shared by both families, and the bookkeeping they have in common.

A state is one level being played: its position, the steps used against the budget, the undo
stack and the log of agent turns. The two families (:mod:`chaingeo.envs.machines.stacking`,
:mod:`chaingeo.envs.machines.puzzle`) supply the position and its rules; this module owns the parts
that must behave identically everywhere: stepping on agent text (an action that cannot be read or
carried out changes nothing but still costs a step), ``push``/``pop``, the budget and ``finish``.

A step is one agent turn. ``apply`` (and ``push``) count a step for a legal action;
``step_text`` counts one for every turn, legal or not. ``pop`` takes back the last action
carried out and its one step; a refused turn changed nothing, so nothing of it is taken back
and its step stays counted, whenever it came. ``finish`` counts like any action and
ends the game: afterwards every action is illegal. ``state`` (:class:`StateAction`) is legal
while the game is not finished, costs its step like any turn and changes nothing else; its
feedback is the text state (:mod:`chaingeo.envs.machines.text_state`). It is not in
``legal_actions()``, so searches, baselines and the Gymnasium action mask never see it.
``key()`` identifies the position only (not the steps used, not the history), so searches can
use it for transpositions.

A refusal is a :class:`chaingeo.core.rules.Rejection`: our reason and, on stacking levels,
CHAIN's error name (``StepResult.code``, ``IllegalActionError.code``).
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Hashable, Sequence
from dataclasses import dataclass
from typing import Any, Protocol, TypeVar, runtime_checkable

from chaingeo.core.level import Level
from chaingeo.core.rules import Rejection
from chaingeo.envs.actions.lists import ActionList
from chaingeo.envs.actions.parse import parse_action
from chaingeo.envs.actions.types import (
    Action,
    ActionError,
    FinishAction,
    IllegalActionError,
    MoveRequest,
    StateAction,
    TurnRequest,
)
from chaingeo.envs.machines.text_state import state_text


@dataclass(frozen=True)
class StepResult:
    """What one agent turn did. ``error`` is None for a legal action, otherwise the kind of
    failure: ``"unparseable"``, ``"illegal"`` or ``"ambiguous"``. ``code`` is CHAIN's error name
    of an illegal stacking action (``"Collision"``, ...; see
    :data:`chaingeo.core.rules.CHAIN_CODES`), else None."""

    action: Action | None
    legal: bool
    error: str | None
    feedback: str
    success: bool
    truncated: bool
    code: str | None = None


@dataclass(frozen=True)
class LoggedTurn:
    """One entry of the turn log: the step number (1-based), what the agent wrote, the reply."""

    step: int
    text: str
    feedback: str
    legal: bool


@runtime_checkable
class GameState(Protocol):
    """The interface both state machines implement (see the module docstring)."""

    level: Level

    @property
    def steps_used(self) -> int: ...
    @property
    def max_steps(self) -> int: ...
    @property
    def finished(self) -> bool: ...
    @property
    def history(self) -> list[LoggedTurn]: ...
    def legal_actions(self) -> Sequence[Action]: ...
    def resolve(self, action: Action | MoveRequest | TurnRequest) -> Action: ...
    def problem(self, action: Action) -> str | None: ...
    def rejection(self, action: Action) -> Rejection | None: ...
    def apply(self, action: Action) -> None: ...
    def push(self, action: Action) -> None: ...
    def pop(self) -> Action: ...
    def clone(self) -> GameState: ...
    def key(self) -> Hashable: ...
    def is_success(self) -> bool: ...
    def is_truncated(self) -> bool: ...
    def step_text(self, text: str) -> StepResult: ...
    def describe(self, action: Action) -> str: ...


S = TypeVar("S", bound="BaseState")


class BaseState(ABC):
    """Shared bookkeeping. Subclasses hold their position in one immutable value
    (``_position``), so a snapshot for undo is a plain reference."""

    level: Level

    def __init__(self, level: Level) -> None:
        self.level = level
        self._steps_used = 0
        self._finished = False
        self._stack: list[tuple[Action, Any, bool]] = []  # action, position, finished before
        self._history: list[LoggedTurn] = []

    # -- family hooks -------------------------------------------------------------------------
    @property
    @abstractmethod
    def _position(self) -> Any:
        """The immutable position value (restored by ``pop``)."""

    @_position.setter
    @abstractmethod
    def _position(self, value: Any) -> None: ...

    @abstractmethod
    def _position_key(self) -> Hashable: ...

    @abstractmethod
    def _legal_moves(self) -> Sequence[Action]:
        """Every legal action except ``finish`` (sorted)."""

    @abstractmethod
    def _move_problem(self, action: Action) -> str | None:
        """Why a non-finish action is illegal here (agent text, 1-based), or None."""

    def _move_rejection(self, action: Action) -> Rejection | None:
        """:meth:`_move_problem` with CHAIN's error name; families that have them override."""
        why = self._move_problem(action)
        return None if why is None else Rejection(why)

    @abstractmethod
    def _after(self, action: Action) -> Any:
        """The position after a legal non-finish action."""

    @abstractmethod
    def is_success(self) -> bool: ...

    @abstractmethod
    def describe(self, action: Action) -> str:
        """Feedback for a legal action just applied (agent text)."""

    def resolve(self, action: Action | MoveRequest | TurnRequest) -> Action:
        """Fill in what the agent left open, or raise Ambiguous/IllegalActionError."""
        if isinstance(action, MoveRequest | TurnRequest):
            raise IllegalActionError("moves belong to puzzle levels; use place or pickup")
        return action

    # -- the contract -------------------------------------------------------------------------
    @property
    def steps_used(self) -> int:
        return self._steps_used

    @property
    def max_steps(self) -> int:
        return self.level.max_steps

    @property
    def steps_left(self) -> int:
        return max(0, self.max_steps - self._steps_used)

    @property
    def finished(self) -> bool:
        """True once ``finish`` was played: the game is over."""
        return self._finished

    @property
    def history(self) -> list[LoggedTurn]:
        return self._history

    def is_truncated(self) -> bool:
        return self._steps_used >= self.max_steps

    def key(self) -> Hashable:
        return (self._position_key(), self._finished)

    def legal_actions(self) -> Sequence[Action]:
        """Every legal action, sorted, ``finish`` last. A read-only sequence whose members
        may be built on demand (see :mod:`chaingeo.envs.actions.lists`): index it, don't copy it."""
        if self._finished:
            return []
        return ActionList([self._legal_moves(), [FinishAction()]])

    def problem(self, action: Action) -> str | None:
        why = self.rejection(action)
        return None if why is None else why.reason

    def rejection(self, action: Action) -> Rejection | None:
        """Why ``action`` is illegal here (our reason and CHAIN's error name), or None."""
        if self._finished:
            return Rejection("the game is over: finish was already played")
        if isinstance(action, FinishAction | StateAction):
            return None
        return self._move_rejection(action)

    def apply(self, action: Action) -> None:
        """Carry out ``action`` (one step) or raise, leaving the state unchanged."""
        self.push(action)

    def push(self, action: Action) -> None:
        resolved = self.resolve(action)
        why = self.rejection(resolved)
        if why is not None:
            raise IllegalActionError(
                why.reason, action=resolved, state_key=self.key(), code=why.code
            )
        self._stack.append((resolved, self._position, self._finished))
        if isinstance(resolved, FinishAction):
            self._finished = True
        elif not isinstance(resolved, StateAction):
            self._position = self._after(resolved)
        self._steps_used += 1

    def pop(self) -> Action:
        """Undo the last applied action (its position change, its finish and its one step) and
        return it. Refused turns after it keep their steps: restoring the step count of the
        snapshot would erase turns that were taken (issue #21, item 12)."""
        if not self._stack:
            raise IndexError("pop from an empty action stack")
        action, position, finished = self._stack.pop()
        self._position = position
        self._steps_used -= 1
        self._finished = finished
        return action

    def clone(self: S) -> S:
        other = object.__new__(type(self))
        other.__dict__.update(self.__dict__)
        other._stack = list(self._stack)
        other._history = list(self._history)
        return other

    def step_text(self, text: str) -> StepResult:
        """The one entry point for agent text: parse, apply, log the turn, report."""
        try:
            action = parse_action(text, self)
            self.push(action)
        except ActionError as e:
            self._steps_used += 1
            self._history.append(LoggedTurn(self._steps_used, text, e.feedback, False))
            return StepResult(
                None, False, e.kind, e.feedback, self.is_success(), self.is_truncated(), e.code
            )
        if isinstance(action, StateAction):
            feedback = f"OK: nothing changed. The state:\n{state_text(self)}"
        else:
            feedback = self.describe(action)
            if self.is_success():
                feedback += " Solved!"
        self._history.append(LoggedTurn(self._steps_used, text, feedback, True))
        return StepResult(action, True, None, feedback, self.is_success(), self.is_truncated())
