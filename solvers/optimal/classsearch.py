"""o_i with multi-piece moves: iterative deepening under the class bound.

Towers of burr units played with moves that may carry any group of pieces have state spaces far
beyond breadth-first search, and A* with pair databases (:mod:`chaingeo.solvers.optimal.astar`)
proves only 36 on the suite's 36-piece towers. The class bound of
:mod:`chaingeo.solvers.optimal.classbound` is much closer; as the heuristic of a depth-first
iterative deepening search it closes them (figures: docs/benchmarks/search.md, "Class search", and
``chain bench astar``).

**Problem** as in :mod:`chaingeo.solvers.optimal.astar`: a state is a partition of the pieces into
parts with offsets; a move carries a proper group of one part one or more steps along an axis, or
away for good (a *removal*, which splits the part); parts never interact again, so the distance of a
state is the sum of its parts' distances ``d(P)``.

**Heuristic.** For one part ``P`` (its pieces at their offsets) and blocks ``B_1 .. B_k`` (a
partition of all pieces, given by the caller), ``h(P) = (|P| - 1) + M(P)``, where ``M(P)`` is
the class bound's ``M`` over the blocks restricted to ``P``: the smallest total of a join of
one vector ``v_j`` of ``V(B_j & P)`` per block (the restricted block as one part, at its
offsets in ``P``; fewer than two pieces: the zero vector). *Admissible*: the class bound's
claim holds from any one-part state, not only the assembled one: its proof asks of the
restricted parts only that each starts inside one part of the whole, and ``B_j & P`` lies in
``P``. So every plan that takes ``P`` apart has its ``|P| - 1`` removals and at least ``M(P)``
other moves. (The search does not need consistency: a failed call proves a bound by trying
every child, whatever ``h`` says of them.)

**Search.** ``within(P, r)`` finds a plan of at most ``r`` moves for part ``P`` or proves there
is none. It prunes when ``h(P) > r`` or a memoised lower bound on ``d(P)`` exceeds ``r``; else
it tries every legal move of ``P`` (:func:`chaingeo.solvers.motion.kinematics_kernel.node_moves`:
one of each
group / rest pair, every finite distance, and the removal), smallest ``f = 1 + bound(child)`` first,
removals first among equals. A finite move needs ``within(P', r - 1)``. A removal into ``P1``
and ``P2`` needs ``d(P1) + d(P2) <= r - 1``: ``d(P1)`` is found exactly (deepening from its
bound up to ``r - 1 - h(P2)``), then ``within(P2, r - 1 - d(P1))``. When every child fails,
``d(P) > r`` is proven (each child was answered exactly, whatever path led to ``P``) and kept
per state; exact distances and their plans are kept too. :func:`class_search_optimal` raises
``r`` from ``h`` of the assembled puzzle: the first ``r`` that succeeds is o_i, every failed
round proves ``o_i > r``, and a cap reached in round ``r`` still proves ``o_i >= r``.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace

import numpy as np

from chaingeo.core.geometry import Shape
from chaingeo.core.kinematics import Move, SearchLimitError
from chaingeo.solvers.deadline import Deadline, deadline_of
from chaingeo.solvers.limits import SearchLimits
from chaingeo.solvers.motion import kinematics_kernel as mv
from chaingeo.solvers.motion.disassemble import Analysis, analyze_assembly
from chaingeo.solvers.motion.partsearch import DIRECTION_NAMES, PieceTable
from chaingeo.solvers.optimal.classbound import MAX_BUDGET, ClassVectors, moved

Offsets = np.ndarray
Key = tuple[tuple[int, ...], bytes]

__all__ = [
    "ClassSearchLimits",
    "ClassSearchResult",
    "analyze_by_classes",
    "class_search_optimal",
]


@dataclass(frozen=True)
class ClassSearchLimits:
    """Caps, checked as the search runs: ``max_nodes`` states expanded, ``seconds`` of wall
    clock (None: no limit), ``vector_states`` one-part states searched for class vectors,
    ``group_limit`` movable groups along one axis of one state."""

    max_nodes: int = 1_000_000
    seconds: float | None = None
    vector_states: int = 2_000_000
    group_limit: int = 1 << 16

    def __post_init__(self) -> None:
        for name in ("max_nodes", "vector_states", "group_limit"):
            if getattr(self, name) < 1:
                raise ValueError(f"{name} must be at least 1, got {getattr(self, name)}")


@dataclass(frozen=True)
class ClassSearchResult:
    """``optimal_steps`` (o_i) and one optimal ``plan`` (from the assembled state, replayable
    with :func:`chaingeo.core.kinematics.replay_disassembly`); ``start_bound``: ``h`` of the
    assembled puzzle; ``nodes``: states expanded over all rounds; ``children``: finite moves
    and removals evaluated; ``vector_states``: one-part states the class vectors searched."""

    optimal_steps: int
    plan: tuple[Move, ...]
    start_bound: int
    nodes: int
    children: int
    vector_states: int


@dataclass(frozen=True)
class _Child:
    """A move tried from a state: ``f`` (1 + the child's bound), the moving local ``mask``,
    direction and ``distance`` (None: a removal, then ``split`` holds both parts, their
    offsets and the second part's bound; else ``after``: the offsets it leads to)."""

    f: int
    mask: int
    direction: int
    distance: int | None
    after: Offsets | None
    split: tuple[tuple[int, ...], Offsets, tuple[int, ...], Offsets, int] | None


class _Search:
    """The memoised ``within`` / ``exact`` of the module docstring, for one puzzle."""

    def __init__(
        self,
        table: PieceTable,
        blocks: Sequence[Sequence[int]],
        max_group: int | None,
        limits: ClassSearchLimits,
        deadline: Deadline,
    ) -> None:
        self.table = table
        self.block_of = np.zeros(len(table.names), dtype=np.int64)
        for b, block in enumerate(blocks):
            self.block_of[list(block)] = b
        self.vectors = ClassVectors(table, max_group, limits.vector_states, limits.group_limit)
        self.limits = limits
        self.deadline = deadline
        self.lower: dict[Key, int] = {}
        self.exact: dict[Key, tuple[int, list[Move]]] = {}
        self.m_cache: dict[Key, tuple[int, bool]] = {}
        self.sub_cache: dict[tuple[int, ...], list[tuple[tuple[int, ...], list[int]]]] = {}
        self.nodes = 0
        self.children = 0

    # -- the heuristic -------------------------------------------------------------------

    def _subs(self, members: tuple[int, ...]) -> list[tuple[tuple[int, ...], list[int]]]:
        """The blocks restricted to a part: members and local indices, two pieces or more."""
        subs = self.sub_cache.get(members)
        if subs is None:
            by_block: dict[int, list[int]] = {}
            for i, m in enumerate(members):
                by_block.setdefault(int(self.block_of[m]), []).append(i)
            subs = [
                (tuple(members[i] for i in idx), idx)
                for _, idx in sorted(by_block.items())
                if len(idx) > 1
            ]
            self.sub_cache[members] = subs
        return subs

    def m_value(self, members: tuple[int, ...], off: Offsets, cap: int) -> int:
        """``M(P)`` when it is at most ``cap``, else a proven lower bound above ``cap`` (or
        above :data:`MAX_BUDGET`, the most the class vectors count)."""
        key = (members, off.tobytes())
        low, known = self.m_cache.get(key, (0, False))
        if known or low > cap:
            return low
        subs = [(m, off[idx]) for m, idx in self._subs(members)]
        top = min(cap, MAX_BUDGET)  # past it, M > MAX_BUDGET is still a proven bound
        for budget in range(low, top + 1):
            choices = [self.vectors.vectors(m, o, budget) for m, o in subs]
            if self.vectors.packing.smallest_join(choices, budget) is not None:
                self.m_cache[key] = (budget, True)
                return budget
        self.m_cache[key] = (top + 1, False)
        return top + 1

    def bound(self, members: tuple[int, ...], off: Offsets, cap: int) -> int:
        """A proven lower bound on ``d(P)``, exact enough to compare with ``cap``."""
        n = len(members)
        if n == 1:
            return 0
        key = (members, off.tobytes())
        done = self.exact.get(key)
        if done is not None:
            return done[0]
        h = n - 1 + self.m_value(members, off, cap - (n - 1))
        return max(h, self.lower.get(key, 0))

    # -- the search ----------------------------------------------------------------------

    def _tick(self) -> None:
        self.nodes += 1
        if self.nodes > self.limits.max_nodes:
            raise SearchLimitError(f"class search node cap: more than {self.limits.max_nodes}")
        if self.deadline.expired():
            raise self.deadline.error("the class search")

    def _move(self, members: tuple[int, ...], mask: int, d: int, k: int | None) -> Move:
        names = self.table.names
        pieces = tuple(names[m] for i, m in enumerate(members) if mask >> i & 1)
        return Move(pieces, DIRECTION_NAMES[d], k)

    def within(self, members: tuple[int, ...], off: Offsets, r: int) -> list[Move] | None:
        """A plan of at most ``r`` moves taking part ``P`` apart, or None (then proven)."""
        n = len(members)
        if n == 1:
            return [] if r >= 0 else None
        key = (members, off.tobytes())
        done = self.exact.get(key)
        if done is not None:
            return list(done[1]) if done[0] <= r else None
        h = self.bound(members, off, r)
        if h > r:
            self.lower[key] = max(self.lower.get(key, 0), h)
            return None
        self._tick()
        kids: list[_Child] = []
        for mask, d, kmax, removable in self.vectors.moves(members, off):
            if removable:
                self.children += 1
                ins = [i for i in range(n) if mask >> i & 1]
                out = [i for i in range(n) if not mask >> i & 1]
                m1, o1 = tuple(members[i] for i in ins), off[ins] - off[ins[0]]
                m2, o2 = tuple(members[i] for i in out), off[out] - off[out[0]]
                h1, h2 = self.bound(m1, o1, r - 1), self.bound(m2, o2, r - 1)
                if 1 + h1 + h2 <= r:
                    kids.append(_Child(1 + h1 + h2, mask, d, None, None, (m1, o1, m2, o2, h2)))
            for k in range(1, kmax + 1):
                self.children += 1
                after = moved(off, mask, d, k)
                f = 1 + self.bound(members, after, r - 1)
                if f <= r:
                    kids.append(_Child(f, mask, d, k, after, None))
        kids.sort(key=lambda kid: (kid.f, kid.distance is not None))  # stable: removals first
        for kid in kids:
            here = self._move(members, kid.mask, kid.direction, kid.distance)
            if kid.after is not None:
                plan = self.within(members, kid.after, r - 1)
                if plan is not None:
                    return [here, *plan]
                continue
            assert kid.split is not None
            m1, o1, m2, o2, h2 = kid.split
            first = self.exact_upto(m1, o1, r - 1 - h2)
            if first is not None:
                rest = self.within(m2, o2, r - 1 - len(first))
                if rest is not None:
                    return [here, *first, *rest]
        self.lower[key] = max(self.lower.get(key, 0), r + 1)
        return None

    def exact_upto(self, members: tuple[int, ...], off: Offsets, cap: int) -> list[Move] | None:
        """An optimal plan for part ``P`` if ``d(P) <= cap``, else None (then proven)."""
        if len(members) == 1:
            return [] if cap >= 0 else None
        key = (members, off.tobytes())
        done = self.exact.get(key)
        if done is None:
            for r in range(self.bound(members, off, cap), cap + 1):
                plan = self.within(members, off, r)
                if plan is not None:
                    done = self.exact[key] = (r, plan)
                    break
        return None if done is None or done[0] > cap else list(done[1])


def class_search_optimal(
    shapes: Mapping[str, Shape],
    blocks: Sequence[Sequence[str]],
    *,
    max_group: int | None = None,
    limits: ClassSearchLimits | None = None,
    deadline: Deadline | None = None,
) -> ClassSearchResult:
    """o_i of ``shapes`` (assembled as given) and an optimal plan, by the search of the module
    docstring with the class bound over ``blocks`` (a partition of the piece names; for a
    tower of burr units, :func:`chaingeo.solvers.optimal.classbound.band_blocks`). ``deadline``:
    shared with the caller's other searches (default: one of ``limits.seconds``).

    Raises ``ValueError`` when the blocks are not a partition, and :class:`SearchLimitError`
    at a cap, naming the proven lower bound (``"proven lower bound N"``). A puzzle that never
    comes apart ends at a cap, as every round fails."""
    lim = limits or ClassSearchLimits()
    names = sorted(shapes)
    if sorted(n for b in blocks for n in b) != names:
        raise ValueError("the blocks must split the pieces: every name in exactly one block")
    if len(names) > mv.MAX_PIECES:
        raise ValueError(f"at most {mv.MAX_PIECES} pieces, got {len(names)}")
    table = PieceTable({n: shapes[n] for n in names})
    search = _Search(
        table,
        [sorted(table.index(n) for n in b) for b in blocks],
        max_group,
        lim,
        deadline_of(lim.seconds, deadline),
    )
    members = tuple(range(len(names)))
    start = np.zeros((len(names), 3), dtype=np.int64)
    r = len(names) - 1  # the removals: proven before anything is searched
    try:
        r = first = search.bound(members, start, r + 16)  # M stops at its value
        while True:
            plan = search.within(members, start, r)
            if plan is not None:
                break
            r += 1
    except SearchLimitError as e:
        raise SearchLimitError(f"{e}; proven lower bound {r}") from e
    return ClassSearchResult(
        optimal_steps=r,
        plan=tuple(plan),
        start_bound=first,
        nodes=search.nodes,
        children=search.children,
        vector_states=search.vectors.states,
    )


def analyze_by_classes(
    shapes: Mapping[str, Shape],
    blocks: Sequence[Sequence[str]],
    *,
    max_group: int | None,
    limits: SearchLimits | None = None,
    deadline: Deadline | None = None,
) -> Analysis:
    """:func:`chaingeo.solvers.motion.disassemble.analyze_assembly` of a puzzle made of ``blocks``
    with moves
    of several pieces: level and moves from the BurrTools-style search, o_i and its plan from
    :func:`class_search_optimal` (``states`` counts both). Its caps come from ``limits``:
    ``max_total_states`` (default 1,000,000) expanded states, ``max_states`` class-vector
    states, one deadline of ``seconds`` for both searches."""
    lim = limits or SearchLimits()
    deadline = deadline_of(lim.seconds, deadline)
    quick = analyze_assembly(
        shapes, max_group=max_group, limits=lim, optimal=False, deadline=deadline
    )
    if not quick.disassemblable:
        return quick
    caps = ClassSearchLimits(
        max_nodes=lim.max_total_states or ClassSearchLimits.max_nodes,
        vector_states=lim.max_states,
        group_limit=max(lim.group_limit, ClassSearchLimits.group_limit),
    )
    found = class_search_optimal(
        shapes, blocks, max_group=max_group, limits=caps, deadline=deadline
    )
    return replace(
        quick, optimal_steps=found.optimal_steps, plan=found.plan, states=quick.states + found.nodes
    )
