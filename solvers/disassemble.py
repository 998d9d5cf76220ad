"""Disassembly search: the BurrTools level, and the optimal full disassembly o_i.

Semantics are those of :mod:`chaingeo.core.kinematics` (the reference); the search itself runs on
:mod:`solvers.movement` (numba). Two questions are answered:

* **Level** (BurrTools' notation, e.g. ``"4.9.3"``): breadth first to the first removal whose two
  parts can both be taken apart in turn, then the same in each part. The first number is the
  fewest moves until something comes free; the text lists the moves of each separation, the
  part left behind before the part removed, omitting sub-trees made only of one-move
  separations (BurrTools' rule). ``moves`` is the total of the whole tree.
* **Optimal plan**: the fewest moves that take *every* piece apart, over all ways of doing it.
  Parts never interact after a removal, so ``f(part) = min over reachable states s and removals
  r at s of dist(s) + 1 + f(removed) + f(left)``; a part of ``m`` pieces needs at least
  ``m - 1`` removals, which bounds the search (branch and bound, memoised per part state).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from chaingeo.core.geometry import Cell, Shape
from chaingeo.core.kinematics import DIRECTIONS, Assembly, Move, SearchLimitError
from chaingeo.core.turns import TurnMove
from solvers import levelsearch as ls
from solvers import movement as mv
from solvers.deadline import Deadline
from solvers.partsearch import DIRECTION_NAMES, PartSearch, PieceTable, SearchLimits

if TYPE_CHECKING:  # imported when a puzzle turns: most never do
    from solvers.turnmoves import TurnTable
    from solvers.turnsearch import TurnPartSearch

__all__ = [
    "Analysis",
    "SearchLimitError",
    "SearchLimits",
    "Separation",
    "analyze",
    "fast_legal_moves",
]

_UNSOLVABLE = 1 << 30
#: Nodes the level kernel may expand before the Python search (with its deadline) takes over:
#: the Python search's own chunk between two clock readings.
_KERNEL_NODES = 20000
#: Tree nodes and memo entries the level kernel starts with (4 moves per node).
_TREE_ROWS = 64


@dataclass(frozen=True)
class Separation:
    """One node of a disassembly tree: ``moves`` (ending with the removal) split a part into
    ``removed`` and ``left`` (None where that side is a single piece)."""

    moves: tuple[Move | TurnMove, ...]
    removed: Separation | None = None
    left: Separation | None = None

    def total_moves(self) -> int:
        return (
            len(self.moves)
            + (self.removed.total_moves() if self.removed else 0)
            + (self.left.total_moves() if self.left else 0)
        )

    def has_multi_moves(self) -> bool:
        return (
            len(self.moves) > 1
            or (self.left is not None and self.left.has_multi_moves())
            or (self.removed is not None and self.removed.has_multi_moves())
        )

    def level_text(self) -> str:
        """BurrTools' notation: this separation's moves, then the left and removed sub-trees
        that contain a separation of more than one move."""
        text = str(len(self.moves))
        for sub in (self.left, self.removed):
            if sub is not None and sub.has_multi_moves():
                text += "." + sub.level_text()
        return text

    def all_moves(self) -> list[Move | TurnMove]:
        """The whole tree as one move sequence: this part, then the left part, then the
        removed one (parts are independent, so any interleaving is as good)."""
        out: list[Move | TurnMove] = list(self.moves)
        if self.left is not None:
            out.extend(self.left.all_moves())
        if self.removed is not None:
            out.extend(self.removed.all_moves())
        return out


@dataclass(frozen=True)
class Analysis:
    """What the disassembler found for one assembled puzzle."""

    disassemblable: bool
    level: str | None  # BurrTools notation, None when it cannot be taken apart
    moves: int | None  # total moves of that (BurrTools-style) disassembly
    optimal_steps: int | None  # o_i, the fewest moves of any full disassembly
    plan: tuple[Move | TurnMove, ...] = ()  # one optimal full disassembly
    tree: Separation | None = None
    states: int = 0  # states visited, over every search
    first_level: int | None = field(default=None)  # moves until the first part comes free


PartKey = tuple[tuple[int, ...], bytes]


#: Round rods of each piece: cell (assembled frame) -> the rod's axis (0, 1, 2).
Rods = Mapping[str, Mapping[Cell, int]]


class _Solver:
    """Searches of one puzzle, sharing the piece table, the caps, the deadline and memos.

    With ``turns`` a part's configuration is ``(n, 4)`` poses (offset, rotation index) in real
    coordinates, searched by :class:`solvers.turnsearch.TurnPartSearch`; plans then name turn
    centres in real coordinates, so memo keys keep the absolute poses. ``deadline``: the one
    the whole analysis shares (default: a new one of ``limits.seconds``)."""

    def __init__(
        self,
        shapes: Mapping[str, Shape],
        max_group: int | None,
        limits: SearchLimits,
        turns: bool = False,
        rods: Rods | None = None,
        deadline: Deadline | None = None,
    ) -> None:
        self.table = PieceTable(shapes)
        self.turn_table: TurnTable | None = None
        if turns:
            from solvers.turnmoves import TurnTable

            self.turn_table = TurnTable(shapes, rods or {})
        self.max_group = max_group
        self.limits = limits
        self.deadline = Deadline(limits.seconds) if deadline is None else deadline
        self.greedy_memo: dict[PartKey, Separation | None] = {}
        self.opt_memo: dict[PartKey, tuple[int, bool, list[Move | TurnMove]]] = {}
        self.states = 0

    def key(self, members: tuple[int, ...], offsets: np.ndarray) -> PartKey:
        if self.turn_table is not None:
            return members, np.asarray(offsets, dtype=np.int16).tobytes()
        rel = np.asarray(offsets, dtype=np.int64) - np.asarray(offsets[0], dtype=np.int64)
        return members, rel.astype(np.int16).tobytes()

    def search(self, members: tuple[int, ...], offsets: np.ndarray) -> PartSearch | TurnPartSearch:
        cap = self.limits.max_total_states
        if cap is not None and self.states > cap:
            raise SearchLimitError(
                f"total state cap of {cap} reached over all searches; "
                "raise SearchLimits(max_total_states=...)"
            )
        if self.turn_table is not None:
            from solvers.turnsearch import TurnPartSearch

            return TurnPartSearch(
                self.turn_table,
                members,
                offsets,
                max_group=self.max_group,
                limits=self.limits,
                deadline=self.deadline,
            )
        return PartSearch(
            self.table,
            members,
            offsets,
            max_group=self.max_group,
            limits=self.limits,
            deadline=self.deadline,
        )

    # -- BurrTools-style tree ------------------------------------------------------------------
    def greedy(self, members: tuple[int, ...], offsets: np.ndarray) -> Separation | None:
        """Shortest way to a removal whose parts both come apart, recursively (None: stuck)."""
        k = self.key(members, offsets)
        if k in self.greedy_memo:
            return self.greedy_memo[k]
        s = self.search(members, offsets)
        result: Separation | None = None
        while result is None and not s.exhausted:
            # Like BurrTools, prefer taking out single pieces (then smaller groups) first.
            found = sorted(s.expand_layers(), key=lambda r: (r.mask.bit_count(), r.node))
            for sp in s.unique_splits(found):
                done, removed = self.subpart(sp.removed, sp.removed_offsets)
                if not done:
                    continue
                done, left = self.subpart(sp.left, sp.left_offsets)
                if not done:
                    continue
                r = sp.removal
                moves = (*s.path_to(r.node), s.removal_move(r))
                result = Separation(moves, removed, left)
                break
        self.states += s.n_states
        self.greedy_memo[k] = result
        return result

    def level_tree(self) -> Separation | None:
        """:meth:`greedy` of the whole assembled puzzle (translations only, no piece groups)
        in one kernel call (:func:`solvers.levelsearch.greedy`), decoded into a tree. Past
        :data:`_KERNEL_NODES` expanded nodes it hands over to :meth:`greedy`, which checks
        the deadline between chunks (the kernel cannot read the clock)."""
        n = len(self.table.names)
        if n > mv.MAX_PIECES:
            raise ValueError(f"at most {mv.MAX_PIECES} pieces per part, got {n}")
        lim = self.limits
        params = np.array(
            [
                -1 if self.max_group is None else self.max_group,
                lim.group_limit,
                lim.max_states,
                -1 if lim.max_total_states is None else lim.max_total_states,
                _KERNEL_NODES,
            ],
            dtype=np.int64,
        )
        self.deadline.check()
        t = self.table
        cap = _TREE_ROWS
        while True:  # rerun with larger buffers in the rare tree that outgrows them
            ctx = np.zeros(7, dtype=np.int64)
            nodes = np.zeros((cap, 4), dtype=np.int64)
            moves = np.zeros((4 * cap, 3), dtype=np.int64)
            keys = np.zeros((cap, 4 + 3 * n), dtype=np.int16)
            table = np.full(4 * cap, -1, dtype=np.int64)
            memo = np.full(cap, -3, dtype=np.int64)
            root = ls.greedy(
                t.vox, t.starts, t.lo, t.hi, np.arange(n, dtype=np.int64),
                np.zeros((n, 3), dtype=np.int64), params, ctx, nodes, moves, keys, table,
                memo,
            )  # fmt: skip
            if ctx[ls.STATUS] != ls.NEED_BUFFERS:
                break
            cap *= 4
        status = int(ctx[ls.STATUS])
        if status == ls.OVER_BUDGET:
            return self.greedy(tuple(range(n)), np.zeros((n, 3), dtype=np.int64))
        self.states += int(ctx[ls.STATES])
        if status == ls.TOTAL_CAP:
            raise SearchLimitError(
                f"total state cap of {lim.max_total_states} reached over all searches; "
                "raise SearchLimits(max_total_states=...)"
            )
        if status == ls.STATE_CAP:
            raise SearchLimitError(
                f"state cap of {lim.max_states} reached in a {int(ctx[ls.INFO])}-piece part; "
                "raise SearchLimits(max_states=...) or --max-states"
            )
        if status == ls.GROUP_CAP:
            raise SearchLimitError(
                f"more than {lim.group_limit} movable groups along one direction "
                "in one state; raise SearchLimits(group_limit=...)"
            )
        used = int(ctx[ls.N_MOVES])
        return _decode(t.names, nodes[: ctx[ls.N_NODES]].tolist(), moves[:used].tolist(), root)

    def subpart(
        self, members: tuple[int, ...], offsets: np.ndarray
    ) -> tuple[bool, Separation | None]:
        """Whether a part a separation leaves can be taken apart, and its tree (None: nothing
        left to do). The hook :mod:`solvers.groups` overrides for BurrTools' piece groups."""
        if len(members) == 1:
            return True, None
        tree = self.greedy(members, offsets)
        return tree is not None, tree

    # -- optimal full disassembly --------------------------------------------------------------
    def optimal(
        self, members: tuple[int, ...], offsets: np.ndarray, budget: int, floor: int = 0
    ) -> tuple[int, list[Move | TurnMove] | None]:
        """``(f, plan)`` with ``f`` the fewest moves to take the part apart if that is below
        ``budget``; otherwise ``(lower bound >= budget, None)``. ``floor`` is a proven lower
        bound on ``f`` from the caller: the search stops as soon as a plan meets it."""
        n = len(members)
        if n == 1:
            return 0, []
        if n - 1 >= budget:
            return n - 1, None
        k = self.key(members, offsets)
        memo = self.opt_memo.get(k)
        if memo is not None:
            value, exact, plan = memo
            if exact:
                return (value, plan) if value < budget else (value, None)
            if value >= budget:
                return value, None
        s = self.search(members, offsets)
        best, best_plan = budget, None
        while not s.exhausted and s.depth + 1 + (n - 2) < best and best > floor:
            for sp in s.unique_splits(s.expand_layers(best - n)):
                if best <= floor:
                    break
                r = sp.removal
                rm, roff, lm, loff = sp.removed, sp.removed_offsets, sp.left, sp.left_offsets
                base = r.depth + 1
                if base + (len(rm) - 1) + (len(lm) - 1) >= best:
                    continue
                fa, pa = self.optimal(rm, roff, best - base - (len(lm) - 1))
                if pa is None:
                    continue
                fb, pb = self.optimal(lm, loff, best - base - fa)
                if pb is None:
                    continue
                best = base + fa + fb
                best_plan = [
                    *s.path_to(r.node),
                    s.removal_move(r),
                    *pb,
                    *pa,
                ]
        self.states += s.n_states
        if best_plan is not None:
            self.opt_memo[k] = (best, True, best_plan)
            return best, best_plan
        if s.exhausted and budget >= _UNSOLVABLE:
            self.opt_memo[k] = (_UNSOLVABLE, True, [])  # every state seen: it never comes apart
            return _UNSOLVABLE, None
        self.opt_memo[k] = (budget, False, [])
        return budget, None


def _decode(
    names: tuple[str, ...], nodes: list[list[int]], moves: list[list[int]], root: int
) -> Separation | None:
    """The tree :func:`solvers.levelsearch.greedy` left in ``nodes``/``moves`` from ``root``."""
    built: dict[int, Separation] = {}

    def build(i: int) -> Separation | None:
        if i < 0:
            return None
        if i not in built:
            first, length, removed, left = nodes[i]
            seq = tuple(
                Move(
                    tuple(names[b] for b in range(len(names)) if g >> b & 1),
                    DIRECTION_NAMES[d],
                    None if k < 0 else k,
                )
                for g, d, k in moves[first : first + length]
            )
            built[i] = Separation(seq, build(removed), build(left))
        return built[i]

    return build(root)


def analyze(
    shapes: Mapping[str, Shape],
    *,
    max_group: int | None = None,
    limits: SearchLimits | None = None,
    optimal: bool = True,
    lower_bound: int | None = None,
    turns: bool = False,
    rods: Rods | None = None,
    deadline: Deadline | None = None,
) -> Analysis:
    """Level, total moves and (if ``optimal``) o_i with one optimal plan, from the assembled
    state (every piece at offset zero, one part). ``lower_bound``: a *proven* lower bound on
    o_i (e.g. :func:`solvers.blockbound.block_lower_bound`); the search stops at a plan that
    meets it, and a plan below it raises ``ValueError`` (the bound was not a bound). With
    ``turns`` groups may also turn (:mod:`solvers.turnsearch`; ``rods``: the round rods of each
    piece, which spin in place). ``deadline``: shared with the caller's other searches (default:
    one of ``limits.seconds`` for this analysis alone)."""
    solver = _Solver(shapes, max_group, limits or SearchLimits(), turns, rods, deadline)
    n = len(solver.table.names)
    members = tuple(range(n))
    offsets = np.zeros((n, 4 if turns else 3), dtype=np.int64)
    if n == 1:
        return Analysis(True, "0", 0, 0)
    tree = solver.greedy(members, offsets) if turns else solver.level_tree()
    if tree is None:
        return Analysis(False, None, None, None, states=solver.states)
    total = tree.total_moves()
    plan = tree.all_moves()
    steps: int | None = None
    if optimal:
        floor = lower_bound or 0
        if total > floor:
            found, better = solver.optimal(members, offsets, total, floor)
            steps, plan = (found, better) if better is not None else (total, plan)
        else:
            steps = total
        if steps < floor:
            raise ValueError(f"a plan of {steps} moves is below the lower bound {floor}")
    return Analysis(
        disassemblable=True,
        level=tree.level_text(),
        moves=total,
        optimal_steps=steps,
        plan=tuple(plan),
        tree=tree,
        states=solver.states,
        first_level=len(tree.moves),
    )


def translations(plan: Sequence[Move | TurnMove]) -> list[Move]:
    """A plan known to hold translations only (no turns: the rules did not allow them);
    ``ValueError`` otherwise."""
    out = [m for m in plan if isinstance(m, Move)]
    if len(out) != len(plan):
        raise ValueError("the plan turns pieces; expected translations only")
    return out


# -------------------------------------------------------------------------------------------
# Per-state helpers (for environments and for the conformance tests against the reference)
# -------------------------------------------------------------------------------------------


def move_rows(
    state: Assembly,
    max_group: int | None = None,
    group_limit: int = 4096,
    table: PieceTable | None = None,
) -> list[tuple[tuple[str, ...], np.ndarray]]:
    """The legal moves of ``state`` in the movement kernel's raw form: per part of two or
    more pieces, its piece names (sorted) and int64 rows ``(mask, direction index, kmax,
    removable)`` (bit ``i`` of ``mask``: the part's ``i``-th piece; direction index into
    :data:`chaingeo.core.kinematics.DIRECTIONS`; finite moves ``1..kmax``; ``removable``: it can
    also leave for good). Raises :class:`SearchLimitError` past ``group_limit`` groups along a
    direction."""
    table = PieceTable(state.shapes) if table is None else table
    out: list[tuple[tuple[str, ...], np.ndarray]] = []
    for part in sorted(state.parts, key=lambda p: sorted(p)):
        if len(part) < 2:
            continue
        names = tuple(sorted(part))
        members = tuple(table.index(p) for p in names)
        vox, starts, lo, hi = table.part_arrays(members)
        off = np.array([state.offsets[n] for n in names], dtype=np.int64)
        n = len(members)
        gaps = np.empty((3, n, n), dtype=np.int64)
        groups = np.zeros(group_limit + 1, dtype=np.uint64)
        buf = np.zeros((1024, 4), dtype=np.int64)
        while True:
            rows = mv.node_moves(
                vox, starts, lo, hi, off, -1 if max_group is None else max_group,
                group_limit, True, gaps, groups, buf,
            )  # fmt: skip
            if rows != -1:
                break
            buf = np.zeros((2 * buf.shape[0], 4), dtype=np.int64)
        if rows == -2:
            raise SearchLimitError(f"more than {group_limit} movable groups along one direction")
        out.append((names, buf[:rows].copy()))
    return out


def fast_legal_moves(
    state: Assembly, max_group: int | None = None, group_limit: int = 4096
) -> list[Move]:
    """Every legal move of ``state``, as :func:`chaingeo.core.kinematics.legal_moves` lists them,
    computed by the numba movement analysis."""
    dirs = list(DIRECTIONS)
    moves: list[Move] = []
    for names, rows in move_rows(state, max_group, group_limit):
        for mask, d, kmax, removable in rows.tolist():
            pieces = tuple(names[i] for i in range(len(names)) if mask >> i & 1)
            moves.extend(Move(pieces, dirs[d], k) for k in range(1, kmax + 1))
            if removable:
                moves.append(Move(pieces, dirs[d], None))
    return sorted(moves, key=lambda m: (m.pieces, m.direction, m.distance is None, m.distance or 0))
