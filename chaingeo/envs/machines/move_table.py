"""Every move of a disassembly state as one lazy block of arrays, sorted as the actions sort.

Once the pieces of a big puzzle wander apart, nearly every subset of a part can move: the
15-piece Luban lock offers ~10^5 (group, direction) pairs and ~10^8 actions a turn after a
few random moves. One Python object per pair (a :class:`MoveRange`) cost seconds a turn there,
so the random agent spent a minute in one episode. :class:`MoveTable` keeps the movement
kernel's rows as numpy arrays: one ``lexsort`` puts them in the actions' order, a cumulative
sum gives each row's first action index, and an action object is built only when asked for (by
index, by iteration, or by lookup of a group and direction).

The order is that of the actions' sort keys: a group's piece names (sorted), compared as tuples,
then the direction's text. Piece names are replaced by their rank among all names and a group's
ascending ranks are packed into a few integer columns (a prefix sorts first), the direction by
the rank of its text.
"""

from __future__ import annotations

from bisect import bisect_left
from collections.abc import Iterator, Sequence
from typing import Protocol, overload

import numpy as np

from chaingeo.core.kinematics import DIRECTIONS, Move
from chaingeo.core.limits import MAX_PIECES
from chaingeo.envs.actions.types import MoveAction
from chaingeo.kernels.jit import njit

_DIRS = tuple(DIRECTIONS)
#: the rank of each direction index's text (the actions sort directions as text)
_DIR_RANK = np.array([sorted(_DIRS).index(d) for d in _DIRS], dtype=np.int64)
_DIR_INDEX = {d: i for i, d in enumerate(_DIRS)}


class LazyBlock(Sequence[MoveAction]):
    """A sorted block of actions that builds its ``i``-th member only when asked."""

    __slots__ = ()

    def _build(self, i: int) -> MoveAction:
        raise NotImplementedError

    @overload
    def __getitem__(self, index: int) -> MoveAction: ...
    @overload
    def __getitem__(self, index: slice) -> list[MoveAction]: ...
    def __getitem__(self, index: int | slice) -> MoveAction | list[MoveAction]:
        if isinstance(index, slice):
            return [self[i] for i in range(*index.indices(len(self)))]
        i = index + len(self) if index < 0 else index
        if not 0 <= i < len(self):
            raise IndexError(f"action index {index} out of range for {len(self)}")
        return self._build(i)

    def __iter__(self) -> Iterator[MoveAction]:
        return (self._build(i) for i in range(len(self)))


class MoveRange(LazyBlock):
    """The moves of ``pieces`` along ``direction``: distances ``1..kmax``, then ``inf`` when
    ``removable``, in the order of the actions' sort keys."""

    __slots__ = ("direction", "key", "kmax", "pieces", "removable")

    def __init__(self, pieces: tuple[str, ...], direction: str, kmax: int, removable: bool):
        self.pieces = pieces
        self.direction = direction
        self.kmax = kmax
        self.removable = removable
        self.key: tuple[object, ...] = (pieces, direction, False, ())

    def __len__(self) -> int:
        return self.kmax + (1 if self.removable else 0)

    def _build(self, i: int) -> MoveAction:
        return MoveAction(Move(self.pieces, self.direction, i + 1 if i < self.kmax else None))

    def __contains__(self, value: object) -> bool:
        if not (
            isinstance(value, MoveAction)
            and value.into is None
            and value.offset is None
            and value.move.pieces == self.pieces
            and value.move.direction == self.direction
        ):
            return False
        k = value.move.distance
        return self.removable if k is None else 1 <= k <= self.kmax


class GroupMoves(Protocol):
    """Moves looked up by (group, direction): a :class:`MoveTable`, or a dict of ranges."""

    def get(self, key: tuple[tuple[str, ...], str], /) -> MoveRange | None: ...


class MoveTable(LazyBlock):
    """The moves of every group of every part: ``parts`` as the movement kernel gives them
    (per part, its sorted piece names and rows ``(mask, direction index, kmax, removable)``).
    A row offers distances ``1..kmax``, then ``inf`` when removable."""

    __slots__ = (
        "_dirs",
        "_ends",
        "_kmax",
        "_leaves",
        "_masks",
        "_names",
        "_part",
        "_rank",
        "_rows",
    )

    def __init__(self, parts: Sequence[tuple[tuple[str, ...], np.ndarray]]) -> None:
        self._names = [names for names, _ in parts]
        self._rank = {n: i for i, n in enumerate(sorted(n for ns in self._names for n in ns))}
        blocks = [(p, rows) for p, (_, rows) in enumerate(parts) if len(rows)]
        width = -(-max((len(self._names[p]) for p, _ in blocks), default=0) // _FIELDS)
        keys = [
            _group_keys(rows[:, 0], np.array([self._rank[n] for n in self._names[p]]), width)
            for p, rows in blocks
        ]
        part = np.concatenate([np.full(len(r), p, np.int64) for p, r in blocks] or [_EMPTY])
        rows = np.concatenate([r for _, r in blocks] or [np.empty((0, 4), np.int64)])
        sort_rows = np.column_stack(
            [np.concatenate(keys or [np.empty((0, width), np.int64)]), _DIR_RANK[rows[:, 1]]]
        )
        order = np.lexsort(sort_rows.T[::-1])
        order = order[rows[order, 2] + rows[order, 3] > 0]  # rows offering no action: none
        self._rows = sort_rows[order]
        self._part = part[order]
        self._masks, self._dirs = rows[order, 0], rows[order, 1]
        self._kmax, self._leaves = rows[order, 2], rows[order, 3]
        self._ends = np.cumsum(self._kmax + self._leaves)

    def __len__(self) -> int:
        return int(self._ends[-1]) if len(self._ends) else 0

    def _build(self, i: int) -> MoveAction:
        row = int(np.searchsorted(self._ends, i, side="right"))
        k = i - (int(self._ends[row - 1]) if row else 0)
        pieces, direction = self._group(row)
        return MoveAction(Move(pieces, direction, k + 1 if k < int(self._kmax[row]) else None))

    def __contains__(self, value: object) -> bool:
        if not (isinstance(value, MoveAction) and value.into is None and value.offset is None):
            return False
        moves = self.get((value.move.pieces, value.move.direction))
        return moves is not None and value in moves

    def get(self, key: tuple[Sequence[str], str]) -> MoveRange | None:
        """The moves of group ``key[0]`` along direction ``key[1]`` (as the per-group blocks
        are looked up), or ``None`` when that group cannot move that way."""
        row = self._find(*key)
        if row < 0:
            return None
        pieces, direction = self._group(row)
        return MoveRange(pieces, direction, int(self._kmax[row]), bool(self._leaves[row]))

    def _find(self, pieces: Sequence[str], direction: str) -> int:
        """The row of group ``pieces`` moving along ``direction`` (binary search), or -1."""
        d = _DIR_INDEX.get(direction)
        if d is None or not pieces or any(p not in self._rank for p in pieces):
            return -1
        ranks = sorted(self._rank[p] for p in pieces)
        key = [*_packed(ranks, self._rows.shape[1] - 1), int(_DIR_RANK[d])]
        rows = _RowView(self._rows)
        at = bisect_left(rows, key)
        return at if at < len(rows) and rows[at] == key else -1

    def _group(self, row: int) -> tuple[tuple[str, ...], str]:
        names = self._names[int(self._part[row])]
        mask = int(self._masks[row])
        return tuple(n for i, n in enumerate(names) if mask >> i & 1), _DIRS[int(self._dirs[row])]


_EMPTY = np.empty(0, np.int64)
#: a group's ascending name ranks are packed into int64 key columns, ``_FIELDS`` ranks of
#: ``_BITS`` bits each (rank + 1; 0 ends the group, so a prefix sorts first); the most
#: significant field first, so comparing columns compares the rank tuples
_BITS = 9
_FIELDS = 7
assert (MAX_PIECES + 1) < 1 << _BITS and _BITS * _FIELDS < 64


@njit(cache=True)
def _group_keys(masks: np.ndarray, ranks: np.ndarray, width: int) -> np.ndarray:
    """Each mask's members (bit ``i``: the name of rank ``ranks[i]``, ascending in ``i``) as
    packed key columns (see :data:`_FIELDS`)."""
    out = np.zeros((masks.shape[0], width), np.int64)
    for r in range(masks.shape[0]):
        m = masks[r]
        slot = 0
        for i in range(ranks.shape[0]):
            if (m >> i) & 1:
                shift = _BITS * (_FIELDS - 1 - slot % _FIELDS)
                out[r, slot // _FIELDS] |= (ranks[i] + 1) << shift
                slot += 1
    return out


def _packed(ranks: list[int], width: int) -> list[int]:
    """The key columns of one group's ascending ``ranks``, as :func:`_group_keys` packs them,
    zero-padded to ``width`` columns (a group too long for ``width`` gets more columns, and
    then no row of the table can equal it)."""
    cols = [0] * max(width, -(-len(ranks) // _FIELDS))
    for slot, rank in enumerate(ranks):
        cols[slot // _FIELDS] |= (rank + 1) << (_BITS * (_FIELDS - 1 - slot % _FIELDS))
    return cols


class _RowView(Sequence[list[int]]):
    """The sorted key rows as lists, for :func:`bisect.bisect_left` (a row read per probe)."""

    __slots__ = ("_rows",)

    def __init__(self, rows: np.ndarray) -> None:
        self._rows = rows

    def __len__(self) -> int:
        return int(self._rows.shape[0])

    @overload
    def __getitem__(self, index: int) -> list[int]: ...
    @overload
    def __getitem__(self, index: slice) -> list[list[int]]: ...
    def __getitem__(self, index: int | slice) -> list[int] | list[list[int]]:
        if isinstance(index, slice):
            return [list(r) for r in self._rows[index].tolist()]
        return list(self._rows[index].tolist())
