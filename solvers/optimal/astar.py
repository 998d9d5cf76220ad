"""A* over whole disassembly states: o_i, the fewest moves that take every piece apart.

**The problem** (the quantity :func:`chaingeo.solvers.motion.disassemble.analyze_assembly` computes
with
``optimal=True``; rules of :mod:`chaingeo.core.kinematics`). A state is a partition of the pieces
into *parts* plus, per part, its pieces' offsets relative to the part's first piece. A move
translates a proper sub-group ``G`` of one part ``P`` along an axis by ``k >= 1`` (legal when
no unit step meets ``P \\ G``) or to infinity; a move that clears ``P \\ G`` for good is a
*removal* and splits ``P`` into ``G`` and ``P \\ G``, each keeping its relative offsets.
Every move costs 1; the goal is all parts single pieces. Parts never interact again, so the
distance of a state is the sum of its parts' distances ``f(P, c)``.

**Search.** States are rows of ``int16`` (per piece: the smallest piece index of its part, then
its offsets relative to that piece), stored in an open-addressing table (numba). Only the
*active part* moves, the part of two or more pieces holding the smallest piece index: moves of
different parts commute and act on nothing else, so any plan can be reordered to finish the
parts in that order with the same length (the next move of the active part in the given plan is
legal now, as it depends on that part alone); the optimum is unchanged, and interleavings are
never enumerated. A* pops by ``f = g + h`` (ties: deeper first, then older); with a
consistent ``h`` the first goal popped is optimal and no state is reached again more cheaply
after its expansion (the search would reopen it, and counts it: the tests check it never
happens). *Partial expansion* (Yoshizumi et al.'s PEA*): expanding a state with value ``F``
stores only the children with ``f == F`` and puts the state back with ``F`` = the smallest
larger child ``f``; children that never reach the front (most of them) are never stored. A
child is stored at the expansion whose ``F`` equals its ``f``, so every child is still
considered in ``f`` order and the optimum is unchanged; ``expanded`` counts these partial
expansions.

**Heuristic.** For a subset ``S`` of a part ``P`` (a pair or a triple), ``g_S(X)`` is the fewest
moves that take ``S`` apart when every other piece is gone, from the one-part state ``X`` with
``S``'s offsets (exact, from :mod:`chaingeo.solvers.optimal.pattern_db`); ``pi_S(s)`` is that state
at ``s``. For a whole state ``s``::

    h(s) = sum over parts P of  max( |P| - 1,  max over S in F, S within P of
                                     g_S(pi_S(s)) + |P| - |S| )

*Lemma 1 (projection; |S| <= 3).* Take a plan for part ``P`` from ``c``. Follow it on ``S``:
the restricted parts start as ``{S}``; a move of ``G`` inside a plan part ``Q`` becomes the
move of ``G & R`` inside the restricted part ``R`` (of ``Q & S``) when that is a proper,
non-empty subset of ``R``, else nothing. Its obstacles ``R \\ G`` are a subset of ``Q \\ G``,
so it is legal (a removal stays one; a finite move may become a removal and split ``R``), and
``|G & R| <= |G|``, ``|R \\ G| <= |Q \\ G|`` respect ``max_group``. A move could touch two
restricted parts only if both had two pieces or more: impossible with ``|S| <= 3``, so each
move projects to at most one. The plan ends with singletons, so do the restricted parts: the
projection takes ``S`` apart and ``g_S(pi_S) <=`` (projected moves). Removals: the plan has
exactly ``|P| - 1`` (each splits one part), the projection exactly ``|S| - 1``, and a
projected removal of the plan is a removal of the projection, so at least ``|P| - |S|``
removals of the plan project to nothing. Hence ``f(P, c) >= g_S(pi_S) + |P| - |S|``; with
``|P| - 1`` (no ``S``) this bounds ``f(P, c)``, and summing over parts (additive, as every
move acts in one part) ``h(s) <= d(s)``: **admissible**.

*Lemma 2 (refinement; |S| <= 3).* If ``Y`` is ``X`` with ``S`` split into parts (same offsets),
``g_S(Y) <= g_S(X)``: Lemma 1's projection with the restricted parts starting as ``Y``'s.

**Consistent**, ``h(s) <= 1 + h(s')`` for a move ``s -> s'`` in part ``P`` (other parts keep
their terms). A non-removal: for ``S`` within ``P``, ``pi_S(s)`` goes by at most one move to
``Y``, which is ``pi_S(s')`` or a refinement of it (when the move clears inside ``S``), so
``g_S(pi_S(s)) <= 1 + g_S(Y) <= 1 + g_S(pi_S(s'))`` (Lemma 2); ``|P|`` is unchanged. A
removal splitting ``P`` into ``P1, P2``: a term ``S`` within ``P1`` keeps ``g_S`` (``S``
moves rigidly or not at all) and ``g_S + |P| - |S| = 1 + (g_S + |P1| - |S|) + (|P2| - 1)``.
If ``S`` meets both, ``pi_S(s)`` goes by one removal to ``S1 = S & P1``, ``S2 = S & P2`` apart,
whose distance is ``g_S1 + g_S2`` (0 for a single piece), so ``g_S + |P| - |S| <= 1 + (g_S1 +
|P1| - |S1|) + (g_S2 + |P2| - |S2|)``, each bracket at most that part's term because ``F`` is
closed under taking subsets (every pair of a triple in ``F`` is in ``F``). At a goal ``h = 0``.

*Not used:* adding ``g`` over disjoint subsets of one part. With multi-piece moves one move of
``G`` moves both ``S1`` and ``S2`` (``G`` meets ``S1``, the rest meets ``S2``), so the sum can
overshoot; only the sum over *parts* is used. (With ``max_group=1`` it does hold:
:mod:`chaingeo.solvers.optimal.blockbound`.) Nor ``|S| >= 4``: two restricted parts of two pieces
each could both move at once, breaking Lemma 1.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from chaingeo.core.geometry import Shape
from chaingeo.core.kinematics import Assembly, Move
from chaingeo.solvers.deadline import Deadline
from chaingeo.solvers.motion.partsearch import DIRECTION_NAMES, PieceTable
from chaingeo.solvers.optimal import astar_kernel as ak
from chaingeo.solvers.optimal.astar_kernel import AStarLimits
from chaingeo.solvers.optimal.pattern_db import DEAD, KEY_WIDTH, PatternDB

__all__ = ["AStarLimits", "AStarResult", "Heuristic", "astar_optimal", "default_family"]


@dataclass(frozen=True)
class AStarResult:
    """``optimal_steps`` (o_i; None if the puzzle never comes apart) and one optimal ``plan``;
    ``expanded``/``states``: whole states expanded/stored; ``start_bound``: ``h`` at the
    start; ``bound``: the largest ``f`` popped (o_i when found: the proven lower bound);
    ``reopened``: states improved after expansion (0 for a consistent heuristic);
    ``pdb_entries``/``pdb_searches``/``pdb_states``: pattern database size, sub-puzzle
    searches run and the states they enumerated; ``family``: how many pairs and triples."""

    optimal_steps: int | None
    plan: tuple[Move, ...]
    expanded: int
    states: int
    start_bound: int
    bound: int
    reopened: int
    pdb_entries: int
    pdb_searches: int
    pdb_states: int
    family: tuple[int, int]


def _boxes_touch(table: PieceTable, i: int, j: int) -> bool:
    return bool(np.all(table.lo[i] <= table.hi[j] + 1) and np.all(table.lo[j] <= table.hi[i] + 1))


def default_family(table: PieceTable, triples: bool = True) -> list[tuple[int, ...]]:
    """Pairs whose bounding boxes touch or overlap in the assembly, and (if ``triples``) the
    triples holding two such pairs, with every pair of a chosen triple added (closed under
    subsets). Any such family gives an admissible, consistent heuristic; this one skips
    subsets that start far apart, whose ``g`` is mostly the trivial ``|S| - 1``."""
    n = len(table.names)
    touch = {(i, j) for i in range(n) for j in range(i + 1, n) if _boxes_touch(table, i, j)}
    fam: set[tuple[int, ...]] = set(touch)
    if triples:
        for a in range(n):
            for b in range(a + 1, n):
                for c in range(b + 1, n):
                    pairs = [(a, b), (a, c), (b, c)]
                    if sum(p in touch for p in pairs) >= 2:
                        fam.add((a, b, c))
                        fam.update(pairs)
    return sorted(fam, key=lambda s: (len(s), s))


class Heuristic:
    """``h`` of the module docstring for any state of one puzzle (for tests and tools; the
    search evaluates the same function in numba,
    :func:`chaingeo.solvers.optimal.astar_kernel.part_h`)."""

    def __init__(
        self,
        shapes: Mapping[str, Shape],
        *,
        max_group: int | None = None,
        limits: AStarLimits | None = None,
        family: Sequence[tuple[str, ...]] | None = None,
        triples: bool = False,
    ) -> None:
        lim = limits or AStarLimits()
        self.table = PieceTable(shapes)
        if family is None:
            self.family = default_family(self.table, triples)
        else:
            self.family = [tuple(sorted(self.table.index(p) for p in s)) for s in family]
        self.pdb = PatternDB(
            self.table,
            self.family,
            max_group=max_group,
            component_states=lim.component_states,
            max_keys=lim.pdb_states,
            group_limit=lim.group_limit,
            deadline=Deadline(lim.seconds),
        )

    def row(self, state: Assembly) -> np.ndarray:
        """The search's row of ``state``: part labels, then offsets relative to them."""
        names = self.table.names
        n = len(names)
        out = np.zeros(4 * n, dtype=np.int16)
        for part in state.parts:
            idx = sorted(self.table.index(p) for p in part)
            base = state.offsets[names[idx[0]]]
            for i in idx:
                out[i] = idx[0]
                off = state.offsets[names[i]]
                out[n + 3 * i : n + 3 * i + 3] = [off[t] - base[t] for t in range(3)]
        return out

    def value(self, state: Assembly) -> int | None:
        """``h(state)``, or None when some subset can never come apart (nor can the puzzle)."""
        row = self.row(state)
        n = len(self.table.names)
        miss = np.zeros(KEY_WIDTH, dtype=np.int16)
        total = 0
        pdb = self.pdb
        for part in state.parts:
            label = min(self.table.index(p) for p in part)
            while True:
                h = ak.part_h(row, n, label, len(part), ak.pdb_view(pdb, miss))
                if h >= 0:
                    break
                pdb.ensure(miss.tolist())
            if h >= DEAD:
                return None
            total += h
        return total


def astar_optimal(
    shapes: Mapping[str, Shape],
    *,
    max_group: int | None = None,
    limits: AStarLimits | None = None,
    family: Sequence[tuple[str, ...]] | None = None,
    triples: bool = False,
) -> AStarResult:
    """o_i and one optimal plan by A* with the pattern-database heuristic (module docstring).
    ``family``: the subsets (piece names) to use, closed under taking pairs of triples;
    default :func:`default_family` (``triples``: include triples; off by default, as a
    triple's sub-puzzle of loose pieces has millions of states)."""
    lim = limits or AStarLimits()
    table = PieceTable(shapes)
    names = table.names
    n = len(names)
    if n > 63:
        raise ValueError(f"at most 63 pieces, got {n}")
    if family is None:
        fam = default_family(table, triples)
    else:
        fam = [tuple(sorted(table.index(p) for p in s)) for s in family]
    deadline = Deadline(lim.seconds)
    pdb = PatternDB(
        table,
        fam,
        max_group=max_group,
        component_states=lim.component_states,
        max_keys=lim.pdb_states,
        group_limit=lim.group_limit,
        deadline=deadline,
    )
    sizes = (sum(len(s) == 2 for s in fam), sum(len(s) == 3 for s in fam))
    if n == 1:
        return AStarResult(0, (), 0, 1, 0, 0, 0, 0, 0, 0, sizes)
    run = ak.AStarRun(table, pdb, -1 if max_group is None else int(max_group), lim, deadline)
    goal = run.search()
    plan: tuple[Move, ...] = ()
    steps: int | None = None
    if goal >= 0:
        out: list[Move] = []
        node = goal
        while run.parent[node] >= 0:
            mask = int(run.mmask[node])
            pieces = tuple(names[i] for i in range(n) if mask >> i & 1)
            k = int(run.mk[node])
            out.append(Move(pieces, DIRECTION_NAMES[int(run.mdir[node])], k if k > 0 else None))
            node = int(run.parent[node])
        plan = tuple(out[::-1])
        steps = len(plan)
    return AStarResult(
        optimal_steps=steps,
        plan=plan,
        expanded=run.expanded,
        states=run.n_states,
        start_bound=run.start_h,
        bound=run.bound,
        reopened=run.reopened,
        pdb_entries=pdb.n_keys,
        pdb_searches=pdb.searches,
        pdb_states=pdb.searched_states,
        family=sizes,
    )
