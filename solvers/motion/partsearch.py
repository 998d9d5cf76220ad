"""Breadth-first search over the configurations of one part, with caps and a deadline.

A *part* is a set of pieces still to be taken apart; its states are the pieces' offsets relative
to its first piece. :class:`PartSearch` grows the search one depth layer at a time (numba does
the expansion, :mod:`chaingeo.solvers.motion.kinematics_kernel`), remembers each state's parent and
the move
that made it, and collects every removal (a move that splits the part) seen on the way.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass
from typing import ClassVar, Generic, TypeVar

import numpy as np

from chaingeo.core.geometry import Shape
from chaingeo.core.kinematics import DIRECTIONS, Assembly, Move, SearchLimitError
from chaingeo.kernels.jit import Pinned
from chaingeo.solvers.deadline import Deadline
from chaingeo.solvers.limits import SearchLimits
from chaingeo.solvers.motion import bfs_kernel as bfs
from chaingeo.solvers.motion import kinematics_kernel as mv

DIRECTION_NAMES: tuple[str, ...] = tuple(DIRECTIONS)

#: :func:`chaingeo.solvers.motion.bfs_kernel.expand` as :class:`PartSearch` calls it: the types
#: of its arguments are fixed by PartSearch's constructor (see :class:`Pinned`).
_expand = Pinned(bfs.expand)


class PieceTable:
    """Every piece's voxels (assembled position), pre-sorted per axis for the gap kernel.

    Built once per analysis in one kernel call (``vox[a]``: piece by piece, each sorted by the
    two other axes, then ``a``); a part's arrays are a gather."""

    def __init__(self, shapes: Mapping[str, Shape], order: Sequence[str] | None = None) -> None:
        # BurrTools lists moves piece by piece: ``order`` is its piece order (default: sorted
        # names, the order chaingeo.core.formats.bt_write.assembled_puzzle writes them in).
        self.names: tuple[str, ...] = tuple(sorted(shapes)) if order is None else tuple(order)
        if sorted(self.names) != sorted(shapes):
            raise ValueError("order: every piece name exactly once")
        if not self.names:
            raise ValueError("a puzzle needs at least one piece")
        self.voxels = [np.ascontiguousarray(shapes[n].voxels, dtype=np.int64) for n in self.names]
        sizes = [len(v) for v in self.voxels]
        if not all(sizes):
            raise ValueError("every piece needs at least one voxel")
        self.starts = np.zeros(len(sizes) + 1, dtype=np.int64)
        self.starts[1:] = np.cumsum(sizes)
        every = np.concatenate(self.voxels)
        self.lo = np.minimum.reduceat(every, self.starts[:-1], axis=0)
        self.hi = np.maximum.reduceat(every, self.starts[:-1], axis=0)
        # Relative offsets stay within the sum of the extents plus the assembled span.
        bound = int((self.hi - self.lo + 1).sum(axis=0).max()) + int(
            (self.hi.max(axis=0) - self.lo.min(axis=0)).max()
        )
        if bound > 30000:
            raise ValueError(f"puzzle too large for 16-bit offsets (bound {bound})")
        self.vox = mv.sort_axes(every, self.starts)
        self.owner = np.repeat(np.arange(len(sizes)), sizes)  # the piece of each row of vox[a]

    def index(self, name: str) -> int:
        return self.names.index(name)

    def part_arrays(
        self, members: Sequence[int]
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """``(vox, starts, lo, hi)`` for the pieces ``members`` (global indices), in order."""
        sel = list(members)
        sizes = self.starts[1:][sel] - self.starts[:-1][sel]
        starts = np.zeros(len(sel) + 1, dtype=np.int64)
        starts[1:] = np.cumsum(sizes)
        if sel == list(range(len(self.names))):
            vox = self.vox  # the kernels only read it
        elif sel == sorted(sel):
            keep = np.zeros(len(self.names), dtype=bool)
            keep[sel] = True
            vox = np.ascontiguousarray(self.vox[:, keep[self.owner]])
        else:
            rows = np.concatenate([np.arange(self.starts[m], self.starts[m + 1]) for m in sel])
            vox = np.ascontiguousarray(self.vox[:, rows])
        return vox, starts, self.lo[sel], self.hi[sel]


@dataclass(frozen=True)
class Removal:
    """A removal seen while expanding ``node`` at ``depth``: ``mask`` (local bits) leaves along
    ``direction``."""

    node: int
    depth: int
    mask: int
    direction: int


@dataclass(frozen=True)
class Split:
    """A removal and the two parts it leaves: members (global indices) and their offsets."""

    removal: Removal
    removed: tuple[int, ...]
    removed_offsets: np.ndarray
    left: tuple[int, ...]
    left_offsets: np.ndarray


def part_size(members: Sequence[int]) -> int:
    """The number of pieces of a part to search: at least two, at most the kernels' limit."""
    n = len(members)
    if n < 2:
        raise ValueError("a part to search needs at least two pieces")
    if n > mv.MAX_PIECES:
        raise ValueError(f"at most {mv.MAX_PIECES} pieces per part, got {n}")
    return n


TableT = TypeVar("TableT")


class LayeredSearch(Generic[TableT]):
    """What the layered breadth-first searches of one part share (translations only here,
    with turns in :class:`chaingeo.solvers.motion.turnsearch.TurnPartSearch`): the part, its
    caps, its deadline, and the state cap's error. A subclass names its :attr:`CHUNK` and
    builds its own buffers from the start configuration in :meth:`_begin`."""

    #: Nodes one kernel call expands at most (when the caller names no ``chunk``).
    CHUNK: ClassVar[int] = 2000

    def __init__(
        self,
        table: TableT,
        members: Sequence[int],
        start: np.ndarray,
        *,
        max_group: int | None,
        limits: SearchLimits,
        deadline: Deadline,
        chunk: int | None = None,
    ) -> None:
        self.n = part_size(members)
        self.table = table
        self.members = tuple(members)
        self.max_group = -1 if max_group is None else int(max_group)
        self.group_limit = int(limits.group_limit)
        self.limits = limits
        self.deadline = deadline
        self.chunk = self.CHUNK if chunk is None else chunk
        self.n_states = 1
        self.n_seps = 0
        self._begin(start)

    def _begin(self, start: np.ndarray) -> None:
        """Build the search's buffers and put the start configuration in them."""
        raise NotImplementedError

    def next_capacity(self, cap: int) -> int:
        """The state buffers' next size after ``cap``; at the state cap, its
        :class:`SearchLimitError`."""
        if cap >= self.limits.max_states:
            raise SearchLimitError(
                f"state cap of {self.limits.max_states} reached in a {self.n}-piece part",
                "max_states",
            )
        return min(2 * cap, self.limits.max_states)


class PartSearch(LayeredSearch[PieceTable]):
    """Layered breadth-first search of one part from one configuration."""

    CHUNK = 20000

    def __init__(
        self,
        table: PieceTable,
        members: Sequence[int],
        offsets: np.ndarray,
        *,
        max_group: int | None,
        limits: SearchLimits,
        deadline: Deadline,
        chunk: int | None = None,
        peel: bool = False,
    ) -> None:
        #: Stop at states where one piece comes free alone (the optimal search's pruning).
        self.peel = peel
        super().__init__(
            table, members, offsets, max_group=max_group, limits=limits, deadline=deadline,
            chunk=chunk,
        )  # fmt: skip

    def _begin(self, offsets: np.ndarray) -> None:
        n, limits = self.n, self.limits
        vox, starts, lo, hi = self.table.part_arrays(self.members)
        cap = max(2, min(128, limits.max_states))  # most parts come apart in a few states
        # The kernel's bundles are kept, and replaced only when a buffer grows: every call
        # expands one or two nodes on a typical part, so building them per call would cost
        # more than the call (and _expand relies on their types, fixed here).
        self.tree = bfs.Tree(
            np.zeros((cap, 3 * n), dtype=np.int16),
            np.full(cap, -1, dtype=np.int64),
            np.zeros((cap, 3), dtype=np.int64),
            np.full(1 << (4 * cap - 1).bit_length(), -1, dtype=np.int64),
        )
        self.pieces = mv.Pieces(
            vox, starts, lo, hi, self.max_group, int(limits.group_limit),
            np.zeros((64, 4), dtype=np.int64),
            np.empty(min(limits.group_limit, 1 << 16) + 1, dtype=np.uint64),
        )  # fmt: skip
        self.seps = np.zeros((64, 3), dtype=np.int64)
        start = np.asarray(offsets, dtype=np.int64).reshape(n, 3)
        start = start - start[0]
        row = start.reshape(-1).astype(np.int16)
        mv.find_or_insert(self.tree.states, 0, self.tree.table, row)
        # Layer d holds nodes layers[d]:layers[d + 1]; ``node``: the next one to expand.
        self.layers = np.zeros(cap + 2, dtype=np.int64)
        self.layers[1] = 1
        self.n_layers = 2
        self.node = 0

    @property
    def depth(self) -> int:
        """Depth of the deepest layer found so far."""
        return self.n_layers - 2

    def offsets_of(self, node: int) -> np.ndarray:
        out: np.ndarray = self.states[node].astype(np.int64).reshape(self.n, 3)
        return out

    @property
    def states(self) -> np.ndarray:
        """The state rows (``n_states`` of them filled)."""
        return self.tree.states

    @property
    def parent(self) -> np.ndarray:
        return self.tree.parent

    @property
    def move(self) -> np.ndarray:
        return self.tree.move

    def _grow_states(self) -> None:
        states, parent, move, table = self.tree
        cap = states.shape[0]
        if self.n_states + 1 >= cap:
            new_cap = self.next_capacity(cap)
            states, parent, move = bfs.grow_search(states, parent, move, new_cap)
            self.layers = np.concatenate([self.layers, np.zeros_like(self.layers)])[: new_cap + 2]
        self.tree = bfs.Tree(states, parent, move, bfs.fit_table(table, states, self.n_states))

    def expand_layer(self) -> list[Removal]:
        """Expand the deepest layer; return the removals found there (in search order)."""
        return self.expand_layers(self.depth)

    def expand_layers(self, max_depth: int | None = None) -> list[Removal]:
        """Expand layer after layer (one kernel call, paused only for the deadline) up to the
        first that yields removals, which are returned (in search order); ``[]`` once every
        state is expanded or the next layer would be deeper than ``max_depth``."""
        first_sep = self.n_seps
        deepest = self.limits.max_states if max_depth is None else max_depth
        while True:
            self.deadline.check()
            status, self.node, self.n_states, self.n_seps, self.n_layers = _expand(
                self.tree, self.n_states, self.node, self.layers, self.n_layers, deepest,
                self.chunk, self.pieces, self.seps, self.n_seps, self.peel,
            )  # fmt: skip
            if status == bfs.DONE:
                break
            if status == bfs.NEED_STATES:
                self._grow_states()
            elif status == bfs.NEED_MOVES:
                grown = np.zeros((2 * self.pieces.moves.shape[0], 4), dtype=np.int64)
                self.pieces = self.pieces._replace(moves=grown)
            elif status == bfs.NEED_SEPS:
                self.seps = np.concatenate([self.seps, np.zeros_like(self.seps)])
            elif status == bfs.TOO_MANY_GROUPS:
                raise SearchLimitError(
                    f"more than {self.limits.group_limit} movable groups along one direction "
                    "in one state",
                    "group_limit",
                )
        d = self.n_layers - 3  # the layer just completed (only it can have removals)
        return [
            Removal(int(s[0]), d, int(s[1]), int(s[2]))
            for s in self.seps[first_sep : self.n_seps].tolist()
        ]

    @property
    def exhausted(self) -> bool:
        """True when the deepest layer is empty: every reachable state has been expanded."""
        return bool(self.layers[self.n_layers - 1] == self.layers[self.n_layers - 2])

    def local_move(self, mask: int, direction: int, distance: int | None) -> Move:
        names = self.table.names
        pieces = tuple(names[self.members[i]] for i in range(self.n) if mask >> i & 1)
        return Move(pieces, DIRECTION_NAMES[direction], distance)

    def removal_move(self, removal: Removal) -> Move:
        """The removal as a move (to infinity)."""
        return self.local_move(removal.mask, removal.direction, None)

    def path_to(self, node: int) -> list[Move]:
        """The moves from the start state to ``node`` (shortest, as found)."""
        out: list[Move] = []
        while node > 0:
            m = self.move[node]
            out.append(self.local_move(int(m[0]), int(m[1]), int(m[2])))
            node = int(self.parent[node])
        return out[::-1]

    def unique_splits(self, removals: Sequence[Removal]) -> Iterator[Split]:
        """The removals that lead to different sub-problems (which pieces go, and the
        configurations of both sides), first occurrence kept, in the given order; each split
        is made when asked for (the level search mostly stops at the first)."""
        if not removals:
            return
        nodes = np.array([r.node for r in removals], dtype=np.int64)
        masks = np.array([r.mask for r in removals], dtype=np.int64)
        keep = mv.unique_removals(self.states, nodes, masks, self.n)
        for r, k in zip(removals, keep.tolist(), strict=True):
            if k:
                yield Split(r, *self.split(r))

    def split(
        self, removal: Removal
    ) -> tuple[tuple[int, ...], np.ndarray, tuple[int, ...], np.ndarray]:
        """``(removed members, their offsets, left members, their offsets)`` at the removal."""
        off = self.offsets_of(removal.node)
        inside = [i for i in range(self.n) if removal.mask >> i & 1]
        outside = [i for i in range(self.n) if not removal.mask >> i & 1]
        return (
            tuple(self.members[i] for i in inside),
            off[inside],
            tuple(self.members[i] for i in outside),
            off[outside],
        )


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
