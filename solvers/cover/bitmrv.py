"""Bit-board exact cover that branches on the most constrained cell (any target size).

Every node keeps the list of rows still *alive* (not overlapping the occupancy, type not used
up), filtered from its parent's list in one pass. The same pass adds each alive row's cell mask
into bit-sliced counters (four planes and a saturation plane), so at the end of it the number
of alive rows through every empty cell is known up to 15 without a loop over cells. The search
then branches on the empty mandatory cell with the fewest alive rows (ties: lowest bit, i.e.
first in scan order), or on an unused exact-once piece when that piece has at most as many
alive rows (pieces win ties, as in :mod:`chaingeo.solvers.cover.dlx`). When every empty cell has 16
or more rows (near the root only: 21 thousand of 3.4 million nodes on the 2x5x6 solid pentominoes)
the counts are taken exactly, cell by cell. A cell with no alive row,
an exact-once piece with no alive row, or a piece type with fewer alive rows than it still needs
ends the branch at once.

Masks take ``W = ceil(cells / 64)`` words (:func:`_expand_wide`). The search runs this kernel
on targets over 64 cells; targets of one word go to :mod:`chaingeo.solvers.cover.boxmrv`, the
same choices on packed lists, with region pruning.
Piece types carry count ranges exactly as in :mod:`chaingeo.solvers.cover.dlx`. ``nodes``
counts rows placed (as in the DLX kernel: a row that completes a cover or ends in a dead end
counts too); ``updates`` counts rows tested by the filter (the unit of work here).
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np
import numpy.typing as npt

from chaingeo.core.arrays import I32, I64, U64
from chaingeo.kernels.jit import njit
from chaingeo.solvers.cover import kernels as kn
from chaingeo.solvers.cover.bitboard import DEBRUIJN_TABLE, scan_order
from chaingeo.solvers.cover.problem import CoverProblem

_ONE = np.uint64(1)
_NONE = np.uint64(0)

_DEBRUIJN_MUL = np.uint64(0x03F79D71B4CB0A89)  # with bitboard.DEBRUIJN_TABLE

#: Saturated count of the bit-sliced counters (counts 0..15 are exact).
SATURATED = 16


@njit(cache=True, inline="always")
def _low(x: Any, table: Any) -> int:
    """Index of the lowest set bit of a non-zero ``uint64``."""
    return int(table[((x & (~x + _ONE)) * _DEBRUIJN_MUL) >> np.uint64(58)])


@njit(cache=True, inline="always")
def _with_count(v: int, b0: Any, b1: Any, b2: Any, b3: Any, sat: Any) -> Any:
    """Bits whose bit-sliced count is exactly ``v`` (0 <= v < 16)."""
    x = ~sat
    x &= b0 if v & 1 else ~b0
    x &= b1 if v & 2 else ~b1
    x &= b2 if v & 4 else ~b2
    x &= b3 if v & 8 else ~b3
    return x


class MRVRows(NamedTuple):
    """The problem side of a search (read only): row types and their count ranges (the masks
    are in :class:`MRVWide`)."""

    rtype: I32
    rid: I32
    allrows: I32
    primary: U64
    lo: I32
    hi: I32
    counters: I32
    pieces: I32
    table: I32


class MRVStack(NamedTuple):
    """The search side, resumable: level ``k`` has the alive rows ``live[lstart[k] :
    lstart[k + 1]]`` (:class:`MRVWide` has the occupancies) and branches ``br[k, :nbr[k]]``
    (tried up to ``pos[k]``); the rest is scratch."""

    cnt: I32
    live: I32
    lstart: I64
    tcount: I32
    tally: I32
    br: I32
    nbr: I64
    pos: I64
    chosen: I32


class MRVWide(NamedTuple):
    """The multi-word side of a search: row masks (rows, ``W``), the
    occupancy of every level (levels, ``W``), the bit-sliced counters (5, ``W``) and scratch
    (2, ``W``: the occupancy being placed, the empty cells)."""

    masks: U64
    occ: U64
    planes: U64
    scratch: U64


@njit(cache=True, inline="always")
def _short_or_best(counters: Any, pieces: Any, lo: Any, cnt: Any, tcount: Any) -> tuple[int, int]:
    """``(-2, 0)`` when a counted type has too few rows left, else the unused exact-once piece
    with the fewest alive rows ``(type, rows)`` (``(-1, 2^30)`` when there is none)."""
    for q in counters:
        if cnt[q] + tcount[q] < lo[q]:
            return -2, 0
    best_t, best_n = -1, 1 << 30
    for t in pieces:
        if cnt[t] == 0 and tcount[t] < best_n:
            best_t, best_n = t, tcount[t]
    return best_t, best_n


@njit(cache=True, inline="always")
def _branches(
    live: Any, w: int, n: int, col: Any, bit: Any, rtype: Any, best_t: int, br: Any
) -> int:
    """Write to ``br`` the alive rows ``live[w:n]`` through the cell ``bit`` of the mask column
    ``col`` (``bit`` non-zero), else those of the piece type ``best_t``; returns how many."""
    k = 0
    if bit != _NONE:
        for i in range(w, n):
            j = live[i]
            if col[j] & bit:
                br[k] = j
                k += 1
    else:
        for i in range(w, n):
            j = live[i]
            if rtype[j] == best_t:
                br[k] = j
                k += 1
    return k


@njit(cache=True)
def _expand_wide(
    src: Any, a: int, b: int, live: Any, w0: int, occ: Any, primary: Any,
    masks: Any, rtype: Any, lo: Any, hi: Any, cnt: Any, tcount: Any, counters: Any,
    pieces: Any, table: Any, tally: Any, planes: Any, empty: Any, br: Any,
) -> tuple[int, int]:  # fmt: skip
    """:func:`_expand` on masks of ``W`` words (``planes``: (5, W) scratch counters)."""
    W = masks.shape[1]
    planes[:] = _NONE
    tcount[:] = 0
    n = w0
    for i in range(a, b):
        j = src[i]
        t = rtype[j]
        hit = _NONE
        for w in range(W):
            hit |= masks[j, w] & occ[w]
        if hit != _NONE or cnt[t] >= hi[t]:
            continue
        live[n] = j
        n += 1
        tcount[t] += 1
        for w in range(W):
            c = masks[j, w]
            for p in range(4):
                nxt = planes[p, w] & c
                planes[p, w] ^= c
                c = nxt
            planes[4, w] |= c
    for w in range(W):
        empty[w] = primary[w] & ~occ[w]
        seen = planes[0, w] | planes[1, w] | planes[2, w] | planes[3, w] | planes[4, w]
        if empty[w] & ~seen:
            return n, 0
    best_t, best_n = _short_or_best(counters, pieces, lo, cnt, tcount)
    if best_t == -2:
        return n, 0
    cell = -1
    for v in range(1, min(best_n, SATURATED)):  # cells strictly below the best piece
        for w in range(W):
            x = empty[w] & _with_count(
                v, planes[0, w], planes[1, w], planes[2, w], planes[3, w], planes[4, w]
            )
            if x != _NONE:
                cell = 64 * w + _low(x, table)
                break
        if cell >= 0:
            best_n = v
            break
    if cell < 0 and best_n > SATURATED:
        cell, best_n = _exact_min_wide(live, w0, n, masks, empty, table, tally, cell, best_n)
    if cell < 0:
        return n, _branches(live, w0, n, masks[:, 0], _NONE, rtype, best_t, br)
    word, bit = cell // 64, _ONE << np.uint64(cell % 64)
    return n, _branches(live, w0, n, masks[:, word], bit, rtype, best_t, br)


@njit(cache=True)
def _exact_min_wide(
    live: Any, a: int, b: int, masks: Any, empty: Any, table: Any, tally: Any, cell: int, best: int
) -> tuple[int, int]:
    """``(cell, count)`` of the empty cell with fewest rows of ``live[a:b]`` (lowest bit on
    ties) counted one by one, when every count is saturated; ``(cell, best)`` unless a cell has
    fewer."""
    W = masks.shape[1]
    tally[:] = 0
    for i in range(a, b):
        for w in range(W):
            m = masks[live[i], w] & empty[w]
            while m != _NONE:
                tally[64 * w + _low(m, table)] += 1
                m &= m - _ONE
    for w in range(W):
        e = empty[w]
        while e != _NONE:
            c = 64 * w + _low(e, table)
            if tally[c] < best:
                cell, best = c, tally[c]
            e &= e - _ONE
    return cell, best


@njit(cache=True, inline="always")
def _place_wide(occ: Any, add: Any, primary: Any, here: Any) -> bool:
    """``here = occ | add`` (``W`` words); whether it covers every mandatory cell."""
    full = True
    for w in range(occ.shape[0]):
        here[w] = occ[w] | add[w]
        if (here[w] & primary[w]) != primary[w]:
            full = False
    return full


@njit(cache=True, _nrt=False)
def mrv_run(rows: MRVRows, st: MRVStack, ctl: kn.Control, wide: MRVWide) -> int:
    """Run (or resume) the search (:func:`chaingeo.solvers.cover.kernels.depth_first` with the
    steps below; :class:`MRVStack` describes the levels)."""
    return kn.depth_first(_root, _peek, _place, _back, rows, (st, wide), st.chosen, rows.rid, ctl)


@njit(cache=True, inline="always")
def _root(rows: MRVRows, state: Any, rng: Any, shuffle: bool) -> int:
    """Level 0: every row filtered."""
    st, wide = state
    st.lstart[0] = 0
    for w in range(wide.occ.shape[1]):
        wide.occ[0, w] = _NONE
    _open(rows, st, wide, 0, rows.allrows, 0, len(rows.allrows), 0, wide.occ[0], rng, shuffle)
    return len(rows.allrows)


@njit(cache=True, inline="always")
def _open(
    rows: MRVRows, st: MRVStack, wide: MRVWide, k: int, src: Any, a: int, b: int, w0: int,
    occ: Any, rng: Any, shuffle: bool,
) -> int:  # fmt: skip
    """Level ``k``: the rows of ``src[a:b]`` alive under ``occ``, written from ``live[w0]``,
    and its branches; returns how many."""
    end, n_br = _expand_wide(
        src, a, b, st.live, w0, occ, rows.primary, wide.masks, rows.rtype, rows.lo, rows.hi,
        st.cnt, st.tcount, rows.counters, rows.pieces, rows.table, st.tally, wide.planes,
        wide.scratch[1], st.br[k],
    )  # fmt: skip
    st.lstart[k + 1] = end
    kn.open_level(st.br, st.nbr, st.pos, k, n_br, rng, shuffle)
    return n_br


@njit(cache=True, inline="always")
def _peek(rows: MRVRows, state: Any, k: int, shuffle: bool) -> kn.Step:
    st = state[0]
    return kn.next_listed(st.br, st.nbr, st.pos, k)


@njit(cache=True, inline="always")
def _place(rows: MRVRows, state: Any, k: int, r: int, rng: Any, shuffle: bool) -> kn.Step:
    """Place row ``r`` on level ``k``: a cover, a dead end, or level ``k + 1``."""
    st, wide = state
    st.pos[k] += 1
    st.chosen[k] = r
    here = wide.scratch[0]
    full = _place_wide(wide.occ[k], wide.masks[r], rows.primary, here)
    t = rows.rtype[r]
    st.cnt[t] += 1
    if full:  # every mandatory cell covered
        ok = kn.counts_met(rows.counters, st.cnt, rows.lo, -1)
        st.cnt[t] -= 1
        return (kn.COVER if ok else kn.DEAD), 0
    a, b = st.lstart[k], st.lstart[k + 1]
    if _open(rows, st, wide, k + 1, st.live, a, b, b, here, rng, shuffle) == 0:
        st.cnt[t] -= 1
        return kn.DEAD, b - a
    for w in range(len(here)):
        wide.occ[k + 1, w] = here[w]
    return kn.DOWN, b - a


@njit(cache=True, inline="always")
def _back(rows: MRVRows, state: Any, k: int) -> None:
    """Leave level ``k``: the row placed on level ``k - 1`` is free again."""
    if k > 0:
        st = state[0]
        st.cnt[rows.rtype[st.chosen[k - 1]]] -= 1


class MRVArrays:
    """Row masks (``W`` words each) of a problem restricted to a subset of its rows."""

    def __init__(self, problem: CoverProblem, rows: I32) -> None:
        n_cells = problem.n_cells
        self.words = W = max(1, -(-n_cells // 64))
        bit = scan_order(problem)  # the other kernels' order: the same ties
        rows, optional = reachable_rows(problem, rows)
        owner, cells = _row_cells(problem, rows)
        masks = np.zeros((len(rows), W), dtype=np.uint64)
        per_cell = np.bincount(cells, minlength=n_cells).astype(np.int64)
        b = bit[cells]
        np.bitwise_or.at(masks, (owner, b // 64), np.uint64(1) << (b % 64).astype(np.uint64))
        primary = np.zeros(W, dtype=np.uint64)
        for c in range(n_cells):
            if not optional[c]:
                primary[bit[c] // 64] |= np.uint64(1) << np.uint64(bit[c] % 64)
        self.rid = np.ascontiguousarray(rows)
        self.rtype = np.ascontiguousarray(problem.row_type[rows]).astype(np.int32)
        self.masks = masks
        self.primary = primary
        self.allrows = np.arange(len(rows), dtype=np.int32)
        T = len(problem.types)
        self.lo = np.array([t.lo for t in problem.types], dtype=np.int32)
        self.hi = np.array([t.hi for t in problem.types], dtype=np.int32)
        self.counters = np.array([t for t in range(T) if self.lo[t] > 0], dtype=np.int32)
        self.pieces = np.array(
            [t for t, ty in enumerate(problem.types) if ty.lo == 1 and ty.hi == 1], dtype=np.int32
        )
        n_primary = n_cells - int(optional.sum())
        self.max_depth = min(n_primary, int(self.hi.sum()))
        per_type = np.bincount(self.rtype, minlength=T) if T else np.zeros(1, np.int64)
        self.max_col = max(int(per_cell.max(initial=0)), int(per_type.max(initial=0)), 1)
        self.rows = MRVRows(
            self.rtype, self.rid, self.allrows, primary, self.lo, self.hi, self.counters,
            self.pieces, DEBRUIJN_TABLE,
        )  # fmt: skip

    def stack(self, depth: int, n_types: int) -> MRVStack:
        """Fresh search-side arrays for ``depth`` levels."""
        return MRVStack(
            cnt=np.zeros(n_types, dtype=np.int32),
            live=np.zeros((depth + 1) * max(len(self.rid), 1), dtype=np.int32),
            lstart=np.zeros(depth + 2, dtype=np.int64),
            tcount=np.zeros(max(n_types, 1), dtype=np.int32),
            tally=np.zeros(64 * self.words, dtype=np.int32),
            br=np.zeros((depth, self.max_col), dtype=np.int32),
            nbr=np.zeros(depth, dtype=np.int64),
            pos=np.zeros(depth, dtype=np.int64),
            chosen=np.zeros(depth, dtype=np.int32),
        )

    def wide(self, depth: int) -> MRVWide:
        """The multi-word side for ``depth`` levels."""
        W = self.words
        return MRVWide(
            self.masks,
            np.zeros((depth + 1, W), dtype=np.uint64),
            np.zeros((5, W), dtype=np.uint64),
            np.zeros((2, W), dtype=np.uint64),
        )


def reachable_rows(problem: CoverProblem, rows: I32) -> tuple[I32, npt.NDArray[np.bool_]]:
    """``rows`` but those lying on optional cells only (a search that branches on mandatory
    cells never reaches them), and which cells are optional (whole arrays: no Python loop
    per row and cell)."""
    optional = np.zeros(problem.n_cells, dtype=bool)
    if problem.optional:
        optional[sorted(problem.optional)] = True
    rows = np.asarray(rows, dtype=np.int32)
    owner, cells = _row_cells(problem, rows)
    if len(rows):
        rows = rows[~np.logical_and.reduceat(optional[cells], _starts(owner, len(rows)))]
    return rows, optional


def _row_cells(problem: CoverProblem, rows: I32) -> tuple[I32, I32]:
    """The cells of ``rows`` one after the other, and the index into ``rows`` of each."""
    ptr, flat = problem.row_ptr, problem.flat_cells
    sizes = ptr[rows + 1] - ptr[rows]
    owner = np.repeat(np.arange(len(rows), dtype=np.int32), sizes)
    first = np.repeat(ptr[rows] - np.cumsum(sizes) + sizes, sizes)
    return owner, flat[first + np.arange(len(owner))]


def _starts(owner: I32, n: int) -> I32:
    """Where each of the ``n`` rows begins in :func:`_row_cells`' arrays (rows are never
    empty: a piece has a voxel)."""
    return np.searchsorted(owner, np.arange(n, dtype=np.int32)).astype(np.int32)
