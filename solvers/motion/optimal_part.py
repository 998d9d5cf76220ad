"""o_i of one part: branch and bound over its first removal, free single pieces peeled.

``f(P, c)``, the fewest moves that take part ``P`` (configuration ``c``: relative offsets)
apart, is the least over the states ``s`` reachable inside ``P`` and the removals at ``s``
(splitting ``P`` into ``P1``, ``P2``) of ``dist(c, s) + 1 + f(P1) + f(P2)``: parts never
interact again. :meth:`OptimalParts.optimal` searches it breadth first by ``dist``, memoised per
part state (members, offsets relative to the first), with the budget of the best plan so far.

**Deletion lemma.** For a piece ``x`` of ``P``, ``f(P \\ {x}, c') <= f(P, c) - 1`` (``c'``:
``c`` without ``x``). Take an optimal plan of ``P`` and delete ``x`` from every move: a move of
``G`` inside a plan part ``Q`` becomes the move of ``G \\ {x}`` inside ``Q \\ {x}``, by the same
distance (a finite move stays finite, a removal stays a removal), or nothing when ``G \\ {x}``
is empty or all of ``Q \\ {x}``. Its obstacles ``(Q \\ {x}) \\ G`` are a subset of ``Q \\ G``,
so it is legal and carries no more pieces on either side (``max_group`` holds); the parts of
the new plan stay those of the plan without ``x``, so every move acts in one part and the plan
ends with every piece apart. The move that leaves ``x`` alone (``G = {x}`` or ``Q \\ G = {x}``)
becomes nothing: the new plan is at least one move shorter. (Unlike the pattern databases'
projection, finite moves are never turned into removals, so any subset may be deleted.)

**Peeling.** If a single piece ``x`` can be removed at ``s``, then ``f(P, s) = 1 +
f(P \\ {x}, s')``: removing it gives ``<=``, the lemma ``>=``. So a state where one piece comes
free alone is a leaf of the search: its value is known through that removal, and no plan
needs to pass through it to a state reached only from it (any plan through it is no shorter
than that removal followed by an optimal plan of the rest). The part search stops there
(:func:`chaingeo.solvers.motion.bfs_kernel.expand` with ``peel``), and a part whose start has a
free piece is not searched at all. Breadth-first order is kept, so the search still proves
its lower bound by exhausting every shorter plan. Without a whole disassembly as the goal
(BurrTools' piece groups may keep pieces together) the lemma does not hold, and peeling is
off.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from chaingeo.core.kinematics import Move
from chaingeo.core.turns import TurnMove
from chaingeo.solvers.motion.partsearch import PartSearch, Removal

if TYPE_CHECKING:
    from chaingeo.solvers.motion.turnsearch import TurnPartSearch

#: A part state: its members (global indices) and their offsets (relative, as bytes).
PartKey = tuple[tuple[int, ...], bytes]
#: The value of a part that never comes apart.
_UNSOLVABLE = 1 << 30


class OptimalParts:
    """The optimal search of :class:`chaingeo.solvers.motion.disassemble._Solver` (which
    provides the part searches, the memo keys and the state count)."""

    opt_memo: dict[PartKey, tuple[int, bool, list[Move | TurnMove]]]
    #: ``[lo, hi]`` proven on the whole puzzle's o_i while :meth:`optimal` searches it.
    bounds: list[int] | None
    #: Take free single pieces out first (exact only when every piece must come apart).
    peel: bool
    states: int

    def key(self, members: tuple[int, ...], offsets: np.ndarray) -> PartKey:
        raise NotImplementedError

    def search(
        self, members: tuple[int, ...], offsets: np.ndarray, peel: bool = False
    ) -> PartSearch | TurnPartSearch:
        raise NotImplementedError

    def min_removals(self, members: tuple[int, ...]) -> int:
        """Removals any plan needs to finish the part: every piece comes apart (with piece
        groups, :class:`chaingeo.solvers.assembly.groups.GroupedSolver` needs fewer)."""
        return len(members) - 1

    def optimal(
        self, members: tuple[int, ...], offsets: np.ndarray, budget: int, floor: int = 0
    ) -> tuple[int, list[Move | TurnMove] | None]:
        """``(f, plan)`` with ``f`` the fewest moves to take the part apart if that is below
        ``budget``; otherwise ``(lower bound >= budget, None)``. ``floor`` is a proven lower
        bound on ``f`` from the caller: the search stops as soon as a plan meets it."""
        least = self.min_removals(members)
        if least == 0:
            return 0, []
        if least >= budget:
            return least, None
        k = self.key(members, offsets)
        memo = self.opt_memo.get(k)
        if memo is not None:
            value, exact, plan = memo
            if exact:
                return (value, plan) if value < budget else (value, None)
            if value >= budget:
                return value, None
        top, self.bounds = self.bounds, None  # only the outermost call proves the whole's bounds
        try:
            return self._optimal_part(members, offsets, budget, floor, k, top)
        finally:
            self.bounds = top

    def _optimal_part(
        self,
        members: tuple[int, ...],
        offsets: np.ndarray,
        budget: int,
        floor: int,
        k: PartKey,
        top: list[int] | None,
    ) -> tuple[int, list[Move | TurnMove] | None]:
        """:meth:`optimal` past its memo: the search itself (``top``: the whole puzzle's
        bounds, updated as they are proved, when this is the outermost call)."""
        after = self.min_removals(members) - 1  # removals still needed after the first
        s = self.search(members, offsets, self.peel)
        best, best_plan = budget, None
        if self.peel:  # the start's removals: a free piece settles the part
            first = s.expand_layers(0)
            peeled = self._peel(s, first, budget, floor, k, top)
            if peeled is not None:
                return peeled
            best, best_plan = self._splits(s, first, best, best_plan, floor, top)
        while not s.exhausted and s.depth + 1 + after < best and best > floor:
            if top is not None:
                # Every removal above the next layer has been tried: a shorter plan first
                # separates there or deeper, then needs ``after`` more removals.
                top[0] = max(top[0], min(best, s.depth + 1 + after))
            removals = s.expand_layers(best - 2 - after)
            if top is not None and removals:
                top[0] = max(top[0], min(best, removals[0].depth + 1 + after))
            best, best_plan = self._splits(s, removals, best, best_plan, floor, top)
        self.states += s.n_states
        if best_plan is not None:
            self.opt_memo[k] = (best, True, best_plan)
            return best, best_plan
        if s.exhausted and budget >= _UNSOLVABLE:
            self.opt_memo[k] = (_UNSOLVABLE, True, [])  # every state seen: it never comes apart
            return _UNSOLVABLE, None
        self.opt_memo[k] = (budget, False, [])
        return budget, None

    def _splits(
        self,
        s: PartSearch | TurnPartSearch,
        removals: list[Removal],
        best: int,
        best_plan: list[Move | TurnMove] | None,
        floor: int,
        top: list[int] | None,
    ) -> tuple[int, list[Move | TurnMove] | None]:
        """The best plan so far after trying ``removals`` (found by ``s``), each followed by
        optimal plans of its two parts within what is left of ``best``."""
        for sp in s.unique_splits(removals):
            if best <= floor:
                break
            r = sp.removal
            rm, roff, lm, loff = sp.removed, sp.removed_offsets, sp.left, sp.left_offsets
            base = r.depth + 1
            left_least = self.min_removals(lm)
            if base + self.min_removals(rm) + left_least >= best:
                continue
            fa, pa = self.optimal(rm, roff, best - base - left_least)
            if pa is None:
                continue
            fb, pb = self.optimal(lm, loff, best - base - fa)
            if pb is None:
                continue
            best = base + fa + fb
            if top is not None:
                top[1] = min(top[1], best)
            best_plan = [*s.path_to(r.node), s.removal_move(r), *pb, *pa]
        return best, best_plan

    def _peel(
        self,
        s: PartSearch | TurnPartSearch,
        first: list[Removal],
        budget: int,
        floor: int,
        k: PartKey,
        top: list[int] | None,
    ) -> tuple[int, list[Move | TurnMove] | None] | None:
        """A single piece free at the start comes out first (exact: see the module
        docstring); None when no single piece is free. ``top``: as in :meth:`_optimal_part`,
        proved through the rest's own bounds (one more than theirs)."""
        if not isinstance(s, PartSearch):  # turns: not peeled
            return None
        n = s.n
        for r in first:
            if r.depth != 0 or r.mask.bit_count() not in (1, n - 1):
                continue
            rm, roff, lm, loff = s.split(r)
            rest, off = (lm, loff) if len(rm) == 1 else (rm, roff)
            self.states += s.n_states
            inner = None if top is None else [max(top[0] - 1, 0), top[1] - 1]
            self.bounds = inner  # the rest's search proves the whole's bounds
            try:
                f, plan = self.optimal(rest, off, budget - 1, max(floor - 1, 0))
            finally:
                self.bounds = None
                if top is not None and inner is not None:
                    top[0], top[1] = max(top[0], inner[0] + 1), min(top[1], inner[1] + 1)
            if plan is None:
                value = f if f >= _UNSOLVABLE else f + 1
                self.opt_memo[k] = (value, value >= _UNSOLVABLE, [])
                return value, None
            out: list[Move | TurnMove] = [s.removal_move(r), *plan]
            self.opt_memo[k] = (f + 1, True, out)
            return f + 1, out
        return None
