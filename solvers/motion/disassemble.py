"""Disassembly search: the BurrTools level, and the optimal full disassembly o_i.

Semantics are those of :mod:`chaingeo.core.kinematics` (the reference); the search itself runs on
:mod:`chaingeo.solvers.motion.kinematics_kernel` (numba). Two questions are answered:

* **Level** (BurrTools' notation, e.g. ``"4.9.3"``): by default BurrTools' own answer
  (``separations="first"``, :mod:`chaingeo.solvers.motion.btsearch`): breadth first in its search
  order to the first separation, then the same in each part; if a part cannot be taken apart, the
  assembly cannot either (``disassembler_a.cpp``, ``checkSubproblems``). ``separations="any"``:
  breadth first to the first removal whose two parts can both be taken apart in turn (single pieces
  first), a stuck part's whole component remembered so that no state is searched twice. The
  first number is the fewest moves until something comes free; the text lists the moves of
  each separation, the part left behind before the part removed, omitting sub-trees made only
  of one-move separations (``disassembly.cpp``, ``movesText``). ``moves`` is the tree's total.
* **Optimal plan**: the fewest moves that take *every* piece apart, over all ways of doing it.
  Parts never interact after a removal, so ``f(part) = min over reachable states s and removals
  r at s of dist(s) + 1 + f(removed) + f(left)``; a part of ``m`` pieces needs at least
  ``m - 1`` removals, which bounds the search (branch and bound, memoised per part state); a
  state where one piece comes free alone is a leaf, its value that removal plus the rest's
  (:mod:`chaingeo.solvers.motion.optimal_part`).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from functools import lru_cache
from typing import TYPE_CHECKING, Literal

import numpy as np

from chaingeo.core.geometry import Cell, Shape
from chaingeo.core.kinematics import DIRECTIONS, Move, SearchLimitError
from chaingeo.core.turns import TurnMove
from chaingeo.solvers.deadline import Deadline
from chaingeo.solvers.limits import SearchLimits
from chaingeo.solvers.motion import btsearch as bt
from chaingeo.solvers.motion import kinematics_kernel as mv
from chaingeo.solvers.motion import levelsearch as ls
from chaingeo.solvers.motion.apart import apart_groups
from chaingeo.solvers.motion.btorient import BTImage, symmetries_of
from chaingeo.solvers.motion.optimal_part import OptimalParts, PartKey
from chaingeo.solvers.motion.partsearch import DIRECTION_NAMES, PartSearch, PieceTable

# Per-state helpers, at home in chaingeo.solvers.motion.partsearch, still importable from here.
from chaingeo.solvers.motion.partsearch import fast_legal_moves as fast_legal_moves
from chaingeo.solvers.motion.partsearch import move_rows as move_rows

if TYPE_CHECKING:  # imported when a puzzle turns: most never do
    from chaingeo.solvers.motion.turns_kernel import TurnTable
    from chaingeo.solvers.motion.turnsearch import TurnPartSearch

__all__ = [
    "Analysis",
    "OptimalLimitError",
    "SearchLimitError",
    "SearchLimits",
    "Separation",
    "analyze_assembly",
    "fast_legal_moves",
    "move_rows",
]

#: Nodes the level kernel may expand before the Python search (with its deadline) takes over:
#: the Python search's own chunk between two clock readings.
KERNEL_NODES = 20000
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
    #: True when ``level`` is BurrTools' own figure (its first separation took it apart).
    burrtools: bool = False

    @classmethod
    def taken_apart(
        cls,
        tree: Separation,
        moves: int,
        steps: int | None,
        plan: Sequence[Move | TurnMove],
        states: int,
        first_level: int | None = None,
        burrtools: bool = False,
    ) -> Analysis:
        """A puzzle that comes apart: its level read off the separation ``tree``."""
        level = tree.level_text()
        return cls(True, level, moves, steps, tuple(plan), tree, states, first_level, burrtools)


#: ``"first"``: BurrTools' disassembler (its first separation or nothing); ``"any"``: any
#: separation whose parts come apart.
Separations = Literal["first", "any"]


#: Round rods of each piece: cell (assembled frame) -> the rod's axis (0, 1, 2).
Rods = Mapping[str, Mapping[Cell, int]]


class _Solver(OptimalParts):
    """Searches of one puzzle, sharing the piece table, the caps, the deadline and memos.

    With ``turns`` a part's configuration is ``(n, 4)`` poses (offset, rotation index) in real
    coordinates, searched by :class:`chaingeo.solvers.motion.turnsearch.TurnPartSearch`; plans then
    name turn centres in real coordinates, so memo keys keep the absolute poses. ``deadline``: the
    one the whole analysis shares (default: a new one of ``limits.seconds``)."""

    def __init__(
        self,
        shapes: Mapping[str, Shape],
        max_group: int | None,
        limits: SearchLimits,
        turns: bool = False,
        rods: Rods | None = None,
        deadline: Deadline | None = None,
        separations: Separations = "first",
        order: Sequence[str] | None = None,
    ) -> None:
        if separations not in ("first", "any"):
            raise ValueError(f"separations: 'first' or 'any', got {separations!r}")
        self.table = PieceTable(shapes, order)
        # BurrTools has neither turns nor a cap on the pieces a move carries: with either, the
        # level is searched over any separation (our rules, not a BurrTools figure).
        self.separations: Separations = "any" if turns or max_group is not None else separations
        self.turn_table: TurnTable | None = None
        if turns:
            from chaingeo.solvers.motion.turns_kernel import TurnTable

            self.turn_table = TurnTable(shapes, rods or {})
        self.max_group = max_group
        self.limits = limits
        self.deadline = Deadline(limits.seconds) if deadline is None else deadline
        self.greedy_memo: dict[PartKey, Separation | None] = {}
        self.first_memo: dict[PartKey, Separation | None] = {}
        self.opt_memo: dict[PartKey, tuple[int, bool, list[Move | TurnMove]]] = {}
        self.states = 0
        #: ``[lo, hi]`` proven on the whole puzzle's o_i while :meth:`optimal` searches it (set
        #: by the caller that asks for them; None otherwise).
        self.bounds: list[int] | None = None
        #: Take a single piece free at a part's start out first (exact without piece groups).
        self.peel = not turns

    def key(self, members: tuple[int, ...], offsets: np.ndarray) -> PartKey:
        if self.turn_table is not None:
            return members, np.asarray(offsets, dtype=np.int16).tobytes()
        rel = np.asarray(offsets, dtype=np.int64) - np.asarray(offsets[0], dtype=np.int64)
        return members, rel.astype(np.int16).tobytes()

    def check_total(self) -> None:
        cap = self.limits.max_total_states
        if cap is not None and self.states > cap:
            raise SearchLimitError(
                f"total state cap of {cap} reached over all searches",
                "max_total_states",
            )

    def search(
        self, members: tuple[int, ...], offsets: np.ndarray, peel: bool = False
    ) -> PartSearch | TurnPartSearch:
        self.check_total()
        if self.turn_table is not None:
            from chaingeo.solvers.motion.turnsearch import TurnPartSearch

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
            peel=peel,
        )

    # -- BurrTools-style tree ------------------------------------------------------------------
    def greedy(self, members: tuple[int, ...], offsets: np.ndarray) -> Separation | None:
        """Shortest way to a removal whose parts both come apart, recursively (None: stuck)."""
        k = self.key(members, offsets)
        if k in self.greedy_memo:
            return self.greedy_memo[k]
        if self.stuck_apart(members, offsets):
            self.greedy_memo[k] = None
            return None
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
        if result is None and isinstance(s, PartSearch):
            # Every state of the component was seen and none of them comes apart.
            for node in range(1, s.n_states):
                self.greedy_memo.setdefault(self.key(members, s.offsets_of(node)), None)
        return result

    def stuck_apart(self, members: tuple[int, ...], offsets: np.ndarray) -> bool:
        """Whether a group of the part's pieces that lies apart is proven stuck alone, and
        so the part (:mod:`chaingeo.solvers.motion.apart`; translations only). A group's own
        search past its state cap proves nothing: the part is then searched as before."""
        if self.turn_table is not None or len(members) < 3:
            return False
        groups = apart_groups(self.table.lo, self.table.hi, members, offsets)
        for group in groups if len(groups) > 1 else ():
            if len(group) < 2:
                continue
            sub = tuple(members[i] for i in group)
            try:
                if self.greedy(sub, np.asarray(offsets)[group]) is None:
                    return True
            except SearchLimitError as e:
                if e.cap != "max_states":
                    raise
        return False

    def first(self, members: tuple[int, ...], offsets: np.ndarray) -> Separation | None:
        """BurrTools' tree of a part: its first separation in BurrTools' order
        (:func:`chaingeo.solvers.motion.btsearch.first_split`), then the part left and the part
        removed, each through :meth:`subpart`; None when either cannot be done
        (``checkSubproblems``)."""
        k = self.key(members, offsets)
        if k in self.first_memo:
            return self.first_memo[k]
        self.check_total()
        split, n_states = bt.first_split(self.table, members, offsets, self.limits, self.deadline)
        self.states += n_states
        result: Separation | None = None
        if split is not None:
            done, left = self.subpart(split.left, split.left_offsets)
            if done:
                done, removed = self.subpart(split.removed, split.removed_offsets)
                if done:
                    result = Separation(split.moves, removed, left)
        self.first_memo[k] = result
        return result

    def part_tree(self, members: tuple[int, ...], offsets: np.ndarray) -> Separation | None:
        """The tree of a part under :attr:`separations`."""
        if self.separations == "first":
            return self.first(members, offsets)
        return self.greedy(members, offsets)

    def level_tree(self) -> Separation | None:
        """:meth:`part_tree` of the whole assembled puzzle (translations only, no piece
        groups) in one kernel call, decoded into a tree; past :data:`KERNEL_NODES` expanded
        nodes the Python search takes over, reading the clock between chunks."""
        n = len(self.table.names)
        if n > mv.MAX_PIECES:
            raise ValueError(f"at most {mv.MAX_PIECES} pieces per part, got {n}")
        if self.separations == "any":
            return self.any_tree()
        lim = self.limits
        params = np.array(
            [
                lim.max_states,
                lim.group_limit,
                KERNEL_NODES,
                -1 if lim.max_total_states is None else lim.max_total_states,
            ],
            dtype=np.int64,
        )
        t = self.table
        start = np.zeros((n, 3), dtype=np.int64)

        def call(cap: int, ctx: np.ndarray, nodes: np.ndarray, moves: np.ndarray) -> int:
            return int(bt.first_tree(t.vox, t.starts, t.lo, t.hi, start, params, ctx, nodes, moves))

        return self.kernel_tree(call, lambda: self.first(tuple(range(n)), start))

    def kernel_tree(
        self,
        call: Callable[[int, np.ndarray, np.ndarray, np.ndarray], int],
        fallback: Callable[[], Separation | None],
    ) -> Separation | None:
        """Run a level kernel (``call(cap, ctx, nodes, moves)``), again with larger buffers
        while it asks for them, and decode its tree; past its node budget, ``fallback()``."""
        self.deadline.check()
        cap = _TREE_ROWS
        while True:  # rerun with larger buffers in the rare tree that outgrows them
            ctx = np.zeros(7, dtype=np.int64)
            nodes = np.zeros((cap, 4), dtype=np.int64)
            moves = np.zeros((4 * cap, 3), dtype=np.int64)
            root = call(cap, ctx, nodes, moves)
            if ctx[ls.STATUS] != ls.NEED_BUFFERS:
                break
            cap *= 4
        status = int(ctx[ls.STATUS])
        if status == ls.OVER_BUDGET:
            return fallback()
        self.states += int(ctx[ls.STATES])
        self.raise_status(status, int(ctx[ls.INFO]))
        used = int(ctx[ls.N_MOVES])
        names = self.table.names
        return _decode(names, nodes[: ctx[ls.N_NODES]].tolist(), moves[:used].tolist(), root)

    def raise_status(self, status: int, info: int) -> None:
        """The :class:`SearchLimitError` of a level kernel's cap status (both kernels use
        :mod:`chaingeo.solvers.motion.levelsearch`'s codes)."""
        lim = self.limits
        if status == ls.TOTAL_CAP:
            raise SearchLimitError(
                f"total state cap of {lim.max_total_states} reached over all searches",
                "max_total_states",
            )
        if status == ls.STATE_CAP:
            raise SearchLimitError(
                f"state cap of {lim.max_states} reached in a {info}-piece part",
                "max_states",
            )
        if status == ls.GROUP_CAP:
            raise SearchLimitError(
                f"more than {lim.group_limit} movable groups along one direction in one state",
                "group_limit",
            )

    def any_tree(self) -> Separation | None:
        """:meth:`greedy` of the whole assembled puzzle (translations only, no piece groups)
        in one kernel call (:func:`chaingeo.solvers.motion.levelsearch.greedy`), decoded into a
        tree. Past :data:`KERNEL_NODES` expanded nodes it hands over to :meth:`greedy`, which checks
        the deadline between chunks (the kernel cannot read the clock)."""
        n = len(self.table.names)
        lim = self.limits
        params = np.array(
            [
                -1 if self.max_group is None else self.max_group,
                lim.group_limit,
                lim.max_states,
                -1 if lim.max_total_states is None else lim.max_total_states,
                KERNEL_NODES,
            ],
            dtype=np.int64,
        )
        t = self.table
        start = np.zeros((n, 3), dtype=np.int64)

        def call(cap: int, ctx: np.ndarray, nodes: np.ndarray, moves: np.ndarray) -> int:
            keys = np.zeros((cap, 4 + 3 * n), dtype=np.int16)
            table = np.full(4 * cap, -1, dtype=np.int64)
            memo = np.full(cap, -3, dtype=np.int64)
            root = ls.greedy(
                ls.Puzzle(t.vox, t.starts, t.lo, t.hi), np.arange(n, dtype=np.int64), start,
                params, ctx, ls.LevelTree(nodes, moves), ls.Memo(keys, table, memo),
            )  # fmt: skip
            return int(root)

        return self.kernel_tree(call, lambda: self.greedy(tuple(range(n)), start))

    def subpart(
        self, members: tuple[int, ...], offsets: np.ndarray
    ) -> tuple[bool, Separation | None]:
        """Whether a part a separation leaves can be taken apart, and its tree (None: nothing
        left to do). The hook :mod:`chaingeo.solvers.assembly.groups` overrides for BurrTools' piece
        groups."""
        if len(members) == 1:
            return True, None
        tree = self.part_tree(members, offsets)
        return tree is not None, tree


def _bt_frame_tree(shapes: Mapping[str, Shape], solver: _Solver) -> Separation | None:
    """BurrTools' tree of the puzzle as :func:`chaingeo.core.formats.bt_write.assembled_puzzle`
    writes it (each piece its own shape, the union the result): searched in the symmetric image
    BurrTools' assembler reports (:class:`chaingeo.solvers.motion.btorient.BTImage`), its moves
    turned back into the puzzle's own frame."""
    names = sorted(shapes)
    grids = {k: shapes[k].normalized().voxels for k in names}
    union = np.concatenate([shapes[k].voxels for k in names])
    symmetries = symmetries_of(union)
    if len(symmetries) < 2:  # nothing to choose from: the assembly as it lies
        return solver.level_tree()
    image, m = BTImage(grids, symmetries, union)(shapes, [[k] for k in names])
    if np.array_equal(m, np.eye(3, dtype=np.int64)):
        return solver.level_tree()
    other = _Solver(
        image, None, solver.limits, deadline=solver.deadline, separations="first", order=names
    )
    tree = other.level_tree()
    solver.states += other.states
    return None if tree is None else _turn_back(tree, m)


def _turn_back(tree: Separation, m: np.ndarray) -> Separation:
    """The tree with every move's direction mapped by ``m``'s inverse (its transpose)."""
    dirs = {tuple(int(v) for v in vec): name for name, vec in DIRECTIONS.items()}

    def move(mv_: Move | TurnMove) -> Move | TurnMove:
        if not isinstance(mv_, Move):
            return mv_
        vec = np.asarray(DIRECTIONS[mv_.direction]) @ m  # m.T @ vec
        return Move(mv_.pieces, dirs[tuple(int(v) for v in vec)], mv_.distance)

    def walk(t: Separation | None) -> Separation | None:
        if t is None:
            return None
        return Separation(tuple(move(x) for x in t.moves), walk(t.removed), walk(t.left))

    out = walk(tree)
    assert out is not None
    return out


@lru_cache(maxsize=1 << 16)
def _move(names: tuple[str, ...], group: int, direction: int, k: int) -> Move:
    """A kernel's move row as a :class:`Move` (moves recur across the assemblies of one
    problem, whose pieces keep their names: built and checked once)."""
    pieces = tuple(names[b] for b in range(len(names)) if group >> b & 1)
    return Move(pieces, DIRECTION_NAMES[direction], None if k < 0 else k)


def _decode(
    names: tuple[str, ...], nodes: list[list[int]], moves: list[list[int]], root: int
) -> Separation | None:
    """The tree :func:`chaingeo.solvers.motion.levelsearch.greedy` left in ``nodes``/``moves`` from
    ``root``."""
    built: dict[int, Separation] = {}

    def build(i: int) -> Separation | None:
        if i < 0:
            return None
        if i not in built:
            first, length, removed, left = nodes[i]
            seq = tuple(_move(names, g, d, k) for g, d, k in moves[first : first + length])
            built[i] = Separation(seq, build(removed), build(left))
        return built[i]

    return build(root)


class OptimalLimitError(SearchLimitError):
    """The optimal search stopped at a cap, with what it proved: ``lo <= o_i <= hi`` (``hi``:
    the shortest full disassembly found, ``lo``: no shorter one exists)."""

    def __init__(self, cause: SearchLimitError, lo: int, hi: int) -> None:
        super().__init__(cause.reason, cause.cap)
        self.lo = lo
        self.hi = hi


def analyze_assembly(
    shapes: Mapping[str, Shape],
    *,
    max_group: int | None = None,
    limits: SearchLimits | None = None,
    optimal: bool = True,
    lower_bound: int | None = None,
    turns: bool = False,
    rods: Rods | None = None,
    deadline: Deadline | None = None,
    separations: Separations = "first",
    order: Sequence[str] | None = None,
    fallback: bool = True,
    peel: bool = True,
) -> Analysis:
    """Level, total moves and (if ``optimal``) o_i with one optimal plan, from the assembled
    state (every piece at offset zero, one part). ``lower_bound``: a *proven* lower bound on
    o_i (e.g. :func:`chaingeo.solvers.optimal.blockbound.block_lower_bound`); the search stops at a
    plan that meets it, and a plan below it raises ``ValueError`` (the bound was not a bound). With
    ``turns`` groups may also turn (:mod:`chaingeo.solvers.motion.turnsearch`; ``rods``: the round
    rods of each piece, which spin in place). ``deadline``: shared with the caller's other searches
    (default: one of ``limits.seconds`` for this analysis alone). ``separations``: BurrTools' level
    (``"first"``, the default; with turns or ``max_group`` always ``"any"``) or ``"any"``;
    ``order``: the pieces in BurrTools' order (default: sorted names). Where BurrTools' first
    separation leaves a part that cannot come apart, ``fallback`` answers with any separation
    (``Analysis.burrtools`` False: the puzzle still comes apart, o_i is still searched); without
    it the analysis says it does not come apart, as BurrTools does. ``peel``: take free single
    pieces out first in the optimal search (exact, :mod:`chaingeo.solvers.motion.optimal_part`;
    off only to check it against the plain search)."""
    solver = _Solver(
        shapes, max_group, limits or SearchLimits(), turns, rods, deadline, separations, order
    )
    solver.peel = peel and not turns
    n = len(solver.table.names)
    members = tuple(range(n))
    offsets = np.zeros((n, 4 if turns else 3), dtype=np.int64)
    if n == 1:
        return Analysis(True, "0", 0, 0)
    bt_level = solver.separations == "first"
    if turns:
        tree = solver.greedy(members, offsets)
    elif bt_level and order is None:
        tree = _bt_frame_tree(shapes, solver)
    else:
        tree = solver.level_tree()
    if tree is None and bt_level and fallback:
        # BurrTools would give up; whether (and how fast) it comes apart is still asked.
        solver.separations, bt_level = "any", False
        tree = solver.level_tree()
    if tree is None:
        return Analysis(False, None, None, None, states=solver.states)
    total = tree.total_moves()
    seed = tree
    if optimal and bt_level:
        # o_i is its own question: seeded, as it always was, by any separation's tree.
        solver.separations = "any"
        seed = solver.level_tree() or tree
    plan = seed.all_moves()
    steps: int | None = None
    if optimal:
        floor = lower_bound or 0
        bound = seed.total_moves()
        if bound > floor:
            # BurrTools' own plan (``tree``) may be the shorter: an upper bound too.
            solver.bounds = [max(floor, solver.min_removals(members)), min(bound, total)]
            try:
                found, better = solver.optimal(members, offsets, bound, floor)
            except SearchLimitError as e:
                lo, hi = solver.bounds or (floor, bound)
                raise OptimalLimitError(e, lo, hi) from None
            steps, plan = (found, better) if better is not None else (bound, plan)
        else:
            steps = bound
        if steps < floor:
            raise ValueError(f"a plan of {steps} moves is below the lower bound {floor}")
    return Analysis.taken_apart(tree, total, steps, plan, solver.states, len(tree.moves), bt_level)


def translations(plan: Sequence[Move | TurnMove]) -> list[Move]:
    """A plan known to hold translations only (no turns: the rules did not allow them);
    ``ValueError`` otherwise."""
    out = [m for m in plan if isinstance(m, Move)]
    if len(out) != len(plan):
        raise ValueError("the plan turns pieces; expected translations only")
    return out
