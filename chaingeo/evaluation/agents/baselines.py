"""Built-in agents that need no network: oracle, random and greedy.

They play through the same text interface as a model (they answer action *text*, which the
environment parses), so they exercise the whole pipeline; unlike a model they are handed a clone
of the state (``needs_state``) and never look at images.

- ``oracle`` plays the level's stored optimal plan (stacking: ``place`` in the solution's order;
  puzzle: the solution's moves); its step count is ``optimal_steps`` by construction, which the
  tests check on every level: the yardstick for Dist2Opt.
- ``random``: uniform over the legal actions except ``finish``, from a generator seeded per
  episode.
- ``greedy``: one-step lookahead. Every legal action is tried in a clone; a move that solves the
  level wins; otherwise progress first (stacking: a placement over a pickup; puzzle: a move that
  takes a piece out over one that does not), then a state not seen before in this episode, then
  the most options left afterwards (legal placements or moves of the successor: the classic
  "do not wall yourself in" rule), then a seeded random tie-break.
"""

from __future__ import annotations

from collections.abc import Hashable, Mapping, Sequence
from typing import Any

import numpy as np

from chaingeo.core.level import Level, PuzzleSolution, StackingSolution
from chaingeo.envs.actions.types import (
    FinishAction,
    MoveAction,
    PickupAction,
    PlaceAction,
    action_of_move,
)
from chaingeo.evaluation.agents.base import Agent, AgentError, Reply, StateLike, Turn


def oracle_plan(level: Level) -> list[str]:
    """The stored optimal plan as agent action text (1-based cells, via
    chaingeo.envs.actions.types)."""
    sol = level.solution
    if isinstance(sol, StackingSolution):
        return [PlaceAction(n, tuple(sol.placements[n].cells)).to_text() for n in sol.order]
    assert isinstance(sol, PuzzleSolution)
    return [action_of_move(m).to_text() for m in sol.moves]


class OracleAgent(Agent):
    name = "oracle"
    uses_images = False

    def __init__(self) -> None:
        self._plan: list[str] = []

    def start(self, level: Level, seed: int) -> None:
        self._plan = oracle_plan(level)

    def act(self, turn: Turn) -> Reply:
        if turn.index < len(self._plan):
            text = self._plan[turn.index]
            return Reply(text, text)
        return Reply("finish", "finish", note="the optimal plan is exhausted")

    def plan(self, turn: Turn) -> Reply:
        return Reply("\n".join(self._plan), None, actions=tuple(self._plan))


def _move_count(actions: Sequence[Any]) -> int:
    """How many of ``actions`` are not ``finish``: a state that is not finished lists finish
    last (and a finished one lists nothing), so the moves are ``actions[:n]``. Counted without
    building the actions (an assembly state can offer a hundred thousand insertions, built only
    when indexed)."""
    return max(0, len(actions) - 1)


class _Seeded(Agent):
    needs_state = True
    uses_images = False

    def __init__(self, options: Mapping[str, Any]) -> None:
        self.options = dict(options)
        self._rng = np.random.default_rng(0)

    def start(self, level: Level, seed: int) -> None:
        self._rng = np.random.default_rng(np.random.SeedSequence([seed, 0xA9E7]))

    def choose(self, state: StateLike, turn: Turn) -> str:
        raise NotImplementedError

    def act(self, turn: Turn) -> Reply:
        if turn.state is None:
            raise AgentError(f"{self.name} needs the state")
        text = self.choose(turn.state, turn)
        return Reply(text, text)

    def plan(self, turn: Turn) -> Reply:
        """Open loop: roll the policy out in the clone it was handed."""
        if turn.state is None:
            raise AgentError(f"{self.name} needs the state")
        state = turn.state
        plan: list[str] = []
        while not (state.is_success() or state.is_truncated()):
            text = self.choose(state, turn)
            plan.append(text)
            result = state.step_text(text)
            if state.finished or not result.legal:
                break
        return Reply("\n".join(plan), None, actions=tuple(plan))


class RandomAgent(_Seeded):
    name = "random"

    def choose(self, state: StateLike, turn: Turn) -> str:
        actions = state.legal_actions()
        n = _move_count(actions)
        if n == 0:
            return "finish"
        return str(actions[int(self._rng.integers(n))].to_text())


def _step_kind(action: Any) -> int:
    """+1 for a step forward (place / a move out to or in from infinity), -1 for a step back
    (pickup), 0 otherwise: what an action does when the state says nothing more."""
    if isinstance(action, PlaceAction):
        return 1
    if isinstance(action, PickupAction):
        return -1
    if isinstance(action, MoveAction) and action.move.distance is None:
        return 1
    return 0


def _progress(before: StateLike, action: Any, after: StateLike) -> int:
    """How much closer ``after`` is to the goal: pieces in the box (stacking), parts apart
    (disassembly) or joined (assembly), read from the state when it offers them."""
    placed = getattr(after, "placed", None)
    if isinstance(placed, Mapping):
        return len(placed) - len(getattr(before, "placed", {}))
    asm_after, asm_before = getattr(after, "assembly", None), getattr(before, "assembly", None)
    if asm_after is not None and asm_before is not None:
        delta = len(asm_after.parts) - len(asm_before.parts)
        return -delta if getattr(after, "mode", "disassemble") == "assemble" else delta
    return _step_kind(action)


def _options_left(state: StateLike) -> int:
    """Legal moves that are not a step back (pickups); a puzzle has none, so its count needs
    no action built."""
    actions = state.legal_actions()
    if getattr(state, "placed", None) is None:
        return _move_count(actions)
    return sum(1 for a in actions if _step_kind(a) >= 0 and not isinstance(a, FinishAction))


class GreedyAgent(_Seeded):
    name = "greedy"

    def __init__(self, options: Mapping[str, Any]) -> None:
        super().__init__(options)
        self.lookahead = int(options.get("lookahead", 48))
        # Assembly states can offer tens of thousands of insertions: look at a seeded sample of
        # them, and skip the costly options-left tie-break, so an episode stays seconds long.
        self.max_candidates = int(options.get("max_candidates", 512))
        self._seen: set[Hashable] = set()

    def start(self, level: Level, seed: int) -> None:
        super().start(level, seed)
        self._seen = set()

    def choose(self, state: StateLike, turn: Turn) -> str:
        self._seen.add(state.key())
        legal = state.legal_actions()
        n = _move_count(legal)
        if n == 0:
            return "finish"
        lookahead = self.lookahead
        indices: Sequence[int] = range(n)
        if n > self.max_candidates:
            keep = self._rng.choice(n, size=self.max_candidates, replace=False)
            indices = sorted(int(k) for k in keep)
            lookahead = 0
        scored: list[tuple[int, int, float, Any, StateLike]] = []
        for i in indices:
            a = legal[i]
            after = state.clone()
            after.apply(a)
            if after.is_success():
                return str(a.to_text())
            novel = 0 if after.key() in self._seen else 1
            scored.append((_progress(state, a, after), novel, float(self._rng.random()), a, after))
        scored.sort(key=lambda t: (t[0], t[1], t[2]), reverse=True)
        # Options left is the costly part: only for the best few by progress and novelty.
        top = _best_prefix(scored, lookahead)
        if lookahead == 0:
            return str(top[0][3].to_text())
        best = max(top, key=lambda t: (t[0], t[1], _options_left(t[4]), t[2]))
        return str(best[3].to_text())


def _best_prefix(
    scored: Sequence[tuple[int, int, float, Any, StateLike]], limit: int
) -> Sequence[tuple[int, int, float, Any, StateLike]]:
    head = scored[0][:2]
    same = [t for t in scored if t[:2] == head]
    return same[: max(1, limit)]
