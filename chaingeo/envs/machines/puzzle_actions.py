"""The legal actions of a puzzle state, computed fast and handed out lazily.

A loose assembly state can offer hundreds of thousands of actions (every group, every distance;
every part coming in anywhere next to another): building them all costs seconds per turn, while
an agent looks at a few. So they come in sorted lazy blocks inside an
:class:`~chaingeo.envs.actions.lists.ActionList`:

* :class:`~chaingeo.envs.machines.move_table.MoveTable`: every group along every direction,
  distances ``1..kmax`` (then ``inf`` when it can leave), from the numba movement analysis
  (:func:`chaingeo.solvers.motion.disassemble.move_rows`, tested equal to the reference
  :func:`chaingeo.core.kinematics.legal_moves`), as arrays; assembling, the slides as one
  :class:`~chaingeo.envs.machines.move_table.MoveRange` per group and direction;
* :class:`InsertionBlock`: one part coming in along one direction into another part, every
  landing place, from a numba kernel equal to the reference
  :func:`chaingeo.core.kinematics.insertion_shifts`;
* where the rules allow turns, one sorted list of :class:`~chaingeo.envs.actions.types.TurnAction`
  from the numba turn kernel (:func:`chaingeo.solvers.motion.turnsearch.turn_rows`, tested equal to
  the reference :func:`chaingeo.core.kinematics.legal_turns`), after every move.

Pieces a turn left in another orientation are read through :func:`oriented_table` (the
translation kernels see each piece as it stands now).
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from chaingeo.core.geometry import Cell
from chaingeo.core.kinematics import (
    DIRECTIONS,
    OPPOSITE,
    Assembly,
    Move,
    insertion_shifts,
    legal_moves,
    legal_turns,
    movable_groups,
    oriented,
)
from chaingeo.core.turns import AXES, TurnMove
from chaingeo.envs.actions.lists import ActionList
from chaingeo.envs.actions.types import Action, FinishAction, MoveAction, TurnAction
from chaingeo.envs.machines.move_table import LazyBlock, MoveRange, MoveTable
from chaingeo.kernels.jit import njit
from chaingeo.solvers.motion.disassemble import move_rows
from chaingeo.solvers.motion.partsearch import PieceTable
from chaingeo.solvers.motion.turns_kernel import TurnTable
from chaingeo.solvers.motion.turnsearch import turn_rows

#: Movable groups along one direction before a state's action list gives up with a
#: SearchLimitError (a loose part of n pieces has up to 2**n - 2).
GROUP_LIMIT = 1 << 16
_DIRS = tuple(DIRECTIONS)

_FAR = np.iinfo(np.int64).max // 4


@njit(cache=True)
def _shifts_kernel(a: np.ndarray, b: np.ndarray, axis: int, sign: int) -> np.ndarray:
    """Shifts ``t`` (rows, lexicographic) that bring cells ``a`` in along ``sign * axis`` next
    to cells ``b``: no overlap, free way in, bounding boxes touching or overlapping."""
    lo = np.empty(3, np.int64)
    hi = np.empty(3, np.int64)
    for i in range(3):
        lo[i] = b[:, i].min() - 1 - a[:, i].max()
        hi[i] = b[:, i].max() + 1 - a[:, i].min()
    l0 = 1 if axis == 0 else 0
    l1 = 1 if axis == 2 else 2
    n0 = hi[l0] - lo[l0] + 1
    n1 = hi[l1] - lo[l1] + 1
    # per lateral line: the lowest and highest axis value of a shift that overlaps b
    low = np.full((n0, n1), _FAR, np.int64)
    high = np.full((n0, n1), -_FAR, np.int64)
    for p in range(a.shape[0]):
        for q in range(b.shape[0]):
            i0 = b[q, l0] - a[p, l0] - lo[l0]
            i1 = b[q, l1] - a[p, l1] - lo[l1]
            v = b[q, axis] - a[p, axis]
            if v < low[i0, i1]:
                low[i0, i1] = v
            if v > high[i0, i1]:
                high[i0, i1] = v
    out = np.empty(((hi[0] - lo[0] + 1) * (hi[1] - lo[1] + 1) * (hi[2] - lo[2] + 1), 3), np.int64)
    t = np.empty(3, np.int64)
    count = 0
    for t0 in range(lo[0], hi[0] + 1):
        t[0] = t0
        for t1 in range(lo[1], hi[1] + 1):
            t[1] = t1
            for t2 in range(lo[2], hi[2] + 1):
                t[2] = t2
                i0 = t[l0] - lo[l0]
                i1 = t[l1] - lo[l1]
                if low[i0, i1] <= high[i0, i1]:  # this line meets b: only the near side is free
                    if sign > 0 and t[axis] >= low[i0, i1]:
                        continue
                    if sign < 0 and t[axis] <= high[i0, i1]:
                        continue
                out[count, 0] = t0
                out[count, 1] = t1
                out[count, 2] = t2
                count += 1
    return out[:count]


def shifts(moving: np.ndarray, fixed: np.ndarray, direction: str) -> np.ndarray:
    """The insertion shifts of cells ``moving`` (n x 3 ints) into ``fixed``, as an int64
    array of rows in lexicographic order (the same as the reference's list)."""
    d = DIRECTIONS[direction]
    axis = next(i for i in range(3) if d[i])
    return _shifts_kernel(
        np.ascontiguousarray(moving, dtype=np.int64),
        np.ascontiguousarray(fixed, dtype=np.int64),
        axis,
        d[axis],
    )


def part_cells(asm: Assembly, part: frozenset[str]) -> np.ndarray:
    """The cells a part fills now, as an int64 array (pieces by name)."""
    return np.concatenate([_placed(asm, n) for n in sorted(part)])


def _placed(asm: Assembly, name: str) -> np.ndarray:
    shape = oriented(asm.shapes[name], asm.rotation_of(name))
    return np.asarray(shape.voxels, dtype=np.int64) + np.asarray(asm.offsets[name], np.int64)


def oriented_table(asm: Assembly, table: PieceTable, cache: dict[object, PieceTable]) -> PieceTable:
    """``table`` when no piece is turned, else a table of the pieces as they stand now (kept
    in ``cache`` by orientations); the offsets of ``asm`` apply to it unchanged."""
    if not asm.rotations:
        return table
    key = tuple(sorted(asm.rotations.items()))
    hit = cache.get(key)
    if hit is None:
        if len(cache) > 64:
            cache.clear()
        hit = cache[key] = PieceTable(
            {n: oriented(s, asm.rotation_of(n)) for n, s in asm.shapes.items()}
        )
    return hit


def turn_actions(asm: Assembly, max_group: int | None, table: TurnTable) -> list[TurnAction]:
    """Every legal turn, sorted (the fast kernel; equal to the reference
    :func:`chaingeo.core.kinematics.legal_turns`)."""
    out: list[TurnAction] = []
    for names, rows in turn_rows(asm, max_group, table, GROUP_LIMIT):
        groups: dict[int, tuple[str, ...]] = {}
        for mask, axis, sense, c0, c1, c2 in rows.tolist():
            pieces = groups.get(mask)
            if pieces is None:
                pieces = groups[mask] = tuple(n for i, n in enumerate(names) if mask >> i & 1)
            turn = TurnMove.listed(pieces, AXES[axis], 1 - 2 * sense, (c0, c1, c2))
            out.append(TurnAction(turn))
    out.sort(key=TurnAction.sort_key)  # one kind: the key alone orders them, as sorted() would
    return out


class InsertionBlock(LazyBlock):
    """The insertions of ``part`` along ``direction`` into ``into``, sorted by offset.

    ``delta`` turns a shift into the agent's offset (the shift of ``part``'s first piece
    relative to ``into``'s first piece, measured from where the target puts it)."""

    __slots__ = ("delta", "direction", "into", "pieces", "rows")

    def __init__(
        self,
        pieces: tuple[str, ...],
        direction: str,
        into: tuple[str, ...],
        delta: Cell,
        rows: np.ndarray,
    ) -> None:
        self.pieces = pieces
        self.direction = direction
        self.into = into
        self.delta = delta
        self.rows = rows

    @property
    def key(self) -> tuple[object, ...]:
        return (self.pieces, self.direction, True, self.into)

    def __len__(self) -> int:
        return int(self.rows.shape[0])

    def offset(self, i: int) -> Cell:
        x, y, z = (int(v) for v in self.rows[i])
        return (x + self.delta[0], y + self.delta[1], z + self.delta[2])

    def _build(self, i: int) -> MoveAction:
        return MoveAction(
            Move(self.pieces, self.direction, None), into=self.into, offset=self.offset(i)
        )

    def __contains__(self, value: object) -> bool:
        if not (
            isinstance(value, MoveAction)
            and value.move.pieces == self.pieces
            and value.move.direction == self.direction
            and value.move.distance is None
            and value.into == self.into
            and value.offset is not None
        ):
            return False
        t = np.asarray(value.offset, dtype=np.int64) - np.asarray(self.delta, dtype=np.int64)
        return bool(np.any(np.all(self.rows == t, axis=1)))


def insertion_blocks(
    asm: Assembly, max_group: int | None, offsets: Mapping[str, Cell] | None = None
) -> list[InsertionBlock]:
    """Every insertion of every part (at most ``max_group`` pieces) into every other part, one
    block per (part, direction, part joined), in the order of their actions' sort keys."""
    offsets = asm.offsets if offsets is None else offsets
    parts = sorted(asm.parts, key=lambda p: sorted(p))
    cells = {p: part_cells(asm, p) for p in parts}
    blocks: list[InsertionBlock] = []
    for a in parts:
        if max_group is not None and len(a) > max_group:
            continue
        oa = offsets[min(a)]
        for d in sorted(DIRECTIONS):
            for b in parts:
                if b == a:
                    continue
                ob = offsets[min(b)]
                delta = (oa[0] - ob[0], oa[1] - ob[1], oa[2] - ob[2])
                rows = shifts(cells[a], cells[b], d)
                if len(rows):
                    blocks.append(
                        InsertionBlock(tuple(sorted(a)), d, tuple(sorted(b)), delta, rows)
                    )
    return blocks


def _ranges(
    asm: Assembly, max_group: int | None, table: PieceTable
) -> list[tuple[tuple[str, ...], np.ndarray]]:
    return move_rows(asm, max_group, GROUP_LIMIT, table)


def _groups(names: tuple[str, ...], masks: np.ndarray) -> dict[int, tuple[str, ...]]:
    """The pieces of each group mask (bit ``i``: ``names[i]``), built once per mask."""
    return {
        m: tuple(names[i] for i in range(len(names)) if m >> i & 1)
        for m in sorted(set(masks.tolist()))
    }


def disassembly_actions(asm: Assembly, max_group: int | None, table: PieceTable) -> MoveTable:
    """The moves of :func:`chaingeo.core.kinematics.legal_moves`, sorted, as one lazy table."""
    return MoveTable(_ranges(asm, max_group, table))


def disassembly_ranges(asm: Assembly, max_group: int | None, table: PieceTable) -> list[MoveRange]:
    """The same moves as one lazy block per (group, direction), one Python object per pair:
    the simple form :class:`MoveTable` is tested against (tests/envs/machines)."""
    chunks: list[MoveRange] = []
    for names, rows in _ranges(asm, max_group, table):
        groups = _groups(names, rows[:, 0])
        chunks.extend(MoveRange(groups[m], _DIRS[d], k, bool(r)) for m, d, k, r in rows.tolist())
    return sorted((c for c in chunks if len(c)), key=lambda c: c.key)


def _slide_rows(rows: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """Which move rows of one part are assembly slides: some finite distance, and not a
    group lying clear of the rest on the side it moves away from while free to leave that
    way (the move it would undo is a removal). ``lo``/``hi``: each piece's bounding box now.
    """
    masks, dirs, kmax, leaves = rows.T
    keep: np.ndarray = kmax > 0
    back = dirs ^ 1  # DIRECTIONS pairs each axis as (+a, -a) at (2a, 2a + 1)
    can_leave = set(zip(dirs[leaves == 1].tolist(), masks[leaves == 1].tolist(), strict=True))
    cand = np.flatnonzero(keep)
    hit = [
        (b, m) in can_leave for b, m in zip(back[cand].tolist(), masks[cand].tolist(), strict=True)
    ]
    idx = cand[np.array(hit, dtype=bool)] if cand.size else cand
    if idx.size:
        n = lo.shape[0]
        member = ((masks[idx, None].astype(np.uint64) >> np.arange(n, dtype=np.uint64)) & 1) == 1
        axis = dirs[idx] // 2
        lo_ax, hi_ax = lo.T[axis], hi.T[axis]  # (rows, pieces) along each row's axis
        big = np.iinfo(np.int64).max // 4
        g_lo = np.where(member, lo_ax, big).min(axis=1)
        g_hi = np.where(member, hi_ax, -big).max(axis=1)
        r_lo = np.where(member, big, lo_ax).min(axis=1)
        r_hi = np.where(member, -big, hi_ax).max(axis=1)
        clearance = np.where(back[idx] % 2 == 0, r_hi - g_lo + 1, g_hi - r_lo + 1)
        keep[idx[clearance <= 0]] = False
    return keep


def assembly_slides(asm: Assembly, max_group: int | None, table: PieceTable) -> list[MoveRange]:
    """The finite moves of a group within its part while assembling (see :func:`_slide_rows`)."""
    out: list[MoveRange] = []
    for names, rows in _ranges(asm, max_group, table):
        lo = np.array([_placed(asm, p).min(axis=0) for p in names])
        hi = np.array([_placed(asm, p).max(axis=0) for p in names])
        kept = rows[_slide_rows(rows, lo, hi)]
        groups = _groups(names, kept[:, 0])
        out.extend(MoveRange(groups[m], _DIRS[d], k, False) for m, d, k, _ in kept.tolist())
    return sorted(out, key=lambda c: c.key)


def assembly_actions(
    asm: Assembly, max_group: int | None, table: PieceTable
) -> tuple[list[MoveRange], ActionList]:
    """The slides (also returned apart, for resolving text) and every action, sorted."""
    slides = assembly_slides(asm, max_group, table)
    blocks: list[MoveRange | InsertionBlock] = [*slides, *insertion_blocks(asm, max_group)]
    blocks.sort(key=lambda c: c.key)
    return slides, ActionList(blocks)


def reference_actions(
    asm: Assembly, mode: str, max_group: int | None, turns: bool = False
) -> list[Action]:
    """Every legal action, built one by one from the pure-Python reference kinematics
    (:mod:`chaingeo.core.kinematics`): what the fast lazy lists must equal, in the same order. Slow;
    for tests and ``chain bench actions``."""
    spins: list[Action] = [TurnAction(t) for t in legal_turns(asm, max_group)] if turns else []
    if mode == "disassemble":
        moves = [MoveAction(m) for m in legal_moves(asm, max_group)]
        return [*moves, *sorted(spins), FinishAction()]
    out: list[Action] = [*spins]
    for d in DIRECTIONS:
        for group in movable_groups(asm, d):
            if max_group is not None and len(group) > max_group:
                continue
            back = OPPOSITE[d]
            if asm.clearance(group, back) <= 0 and asm.free_distance(group, back) is None:
                continue
            free = asm.free_distance(group, d)
            top = asm.clearance(group, d) - 1 if free is None else free
            out.extend(MoveAction(Move(group, d, k)) for k in range(1, top + 1))
    for a in asm.parts:
        if max_group is not None and len(a) > max_group:
            continue
        for b in asm.parts:
            if a == b:
                continue
            oa, ob = asm.offsets[min(a)], asm.offsets[min(b)]
            acells = [c for n in sorted(a) for c in asm.cells_of(n)]
            bcells = [c for n in sorted(b) for c in asm.cells_of(n)]
            for d in DIRECTIONS:
                for t in insertion_shifts(acells, bcells, d):
                    offset = (oa[0] + t[0] - ob[0], oa[1] + t[1] - ob[1], oa[2] + t[2] - ob[2])
                    out.append(
                        MoveAction(
                            Move(tuple(sorted(a)), d, None), into=tuple(sorted(b)), offset=offset
                        )
                    )
    return [*sorted(out), FinishAction()]
