"""Most-constrained-cell exact cover for targets of at most 64 cells, on packed live lists.

The kernel must equal :func:`chaingeo.solvers.cover.reference.count_covers` (the covers by
definition). It makes the choices of the one-word side of :mod:`chaingeo.solvers.cover.bitmrv`
(the empty mandatory cell with the fewest alive rows, lowest bit on ties, or an unused
exact-once piece with at most as many; bit-sliced counters; region pruning), but a level's alive
rows are stored as their masks, one after the other, in runs of one piece type (with their row
numbers beside them). So filtering a level for its child reads and writes memory in order, with
no look-up of a row's mask, type or the count of its type; a type used up is skipped as a whole
run, and branching on a piece is its run, with nothing to copy. Region pruning knows which
sizes the unused pieces can still sum to (a bit set of sums, not only their gcd), which cuts
Soma's regions of 5 or 6 cells too.

``nodes`` counts rows placed (as the other kernels); ``updates`` counts rows tested by the
filter.
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np

from chaingeo.core.arrays import I32, I64, U64
from chaingeo.kernels.jit import njit
from chaingeo.solvers.cover import kernels as kn
from chaingeo.solvers.cover.bitboard import (
    DEBRUIJN_TABLE,
    MAX_CELLS,
    _grow,
    _popcount,
    region_pruning,
    scan_order,
)
from chaingeo.solvers.cover.bitmrv import (
    SATURATED,
    _low,
    _row_cells,
    _with_count,
    reachable_rows,
)
from chaingeo.solvers.cover.problem import CoverProblem

_ONE = np.uint64(1)
_NONE = np.uint64(0)


class BoxRows(NamedTuple):
    """The problem side (read only): every row's mask, type and id (rows sorted by type; the
    root's list is all of them), type runs at the root, count ranges, region pruning (``nb``:
    edge masks and strides; ``sizes``: each type's cell count; ``region`` 0 turns it off)."""

    mask: U64
    rtype: I32
    rid: I32
    root_runs: I64
    primary: np.uint64
    lo: I32
    hi: I32
    counters: I32
    pieces: I32
    table: I32
    nb: U64
    sizes: I32
    region: int


class BoxStack(NamedTuple):
    """The search side, resumable: level ``k``'s alive rows are ``lmask/lrow[runs[k, t] :
    runs[k, t + 1]]`` for each type ``t``, its occupancy ``occ[k]``, its branches
    ``br[k, :nbr[k]]`` (positions in the live list, tried up to ``pos[k]``)."""

    cnt: I32
    lmask: U64
    lrow: I32
    runs: I64
    occ: U64
    tally: I32
    br: I32
    nbr: I64
    pos: I64
    chosen: I32


@njit(cache=True, inline="always")
def _sums(sizes: Any, cnt: Any, hi: Any) -> Any:
    """Bit set of the region sizes (< 64) the unused pieces can fill: sums of sub-multisets."""
    can = _ONE
    for t in range(len(sizes)):
        for _ in range(hi[t] - cnt[t]):
            if sizes[t] < 64:
                can |= can << np.uint64(sizes[t])
    return can


@njit(cache=True, inline="always")
def _regions_fit(placed: Any, empty: Any, nb: Any, can: Any) -> bool:
    """Does every empty region touching the piece just placed have a size in ``can``?
    (Regions of 64 cells or more pass.)"""
    seeds = _grow(placed, nb) & empty
    while seeds != _NONE:
        region = seeds & (~seeds + _ONE)
        while True:
            grown = _grow(region, nb) & empty
            if grown == region:
                break
            region = grown
        size = _popcount(region)
        if size < 64 and ((can >> np.uint64(size)) & _ONE) == _NONE:
            return False
        seeds &= ~region
    return True


@njit(cache=True)
def _exact_min(lmask: Any, a: int, b: int, empty: Any, table: Any, tally: Any) -> Any:
    """``(cell, count)`` of the empty cell with fewest rows of ``lmask[a:b]`` (lowest bit on
    ties), counted one by one (used only when every count is saturated)."""
    tally[:] = 0
    for i in range(a, b):
        m = lmask[i] & empty
        while m != _NONE:
            tally[_low(m, table)] += 1
            m &= m - _ONE
    best, best_n = -1, 1 << 30
    e = empty
    while e != _NONE:
        c = _low(e, table)
        if tally[c] < best_n:
            best, best_n = c, tally[c]
        e &= e - _ONE
    return best, best_n


@njit(cache=True, inline="always")
def _filter(
    lmask: Any, lrow: Any, runs: Any, k: int, occ: Any, primary: Any, cnt: Any, hi: Any,
    lo: Any, counters: Any, pieces: Any, table: Any, tally: Any, br: Any,
) -> tuple[int, int, int]:  # fmt: skip
    """Level ``k + 1``'s live list from level ``k``'s under ``occ``, and its branches in
    ``br``: ``(branches, piece branched on or -1, rows tested)``; 0 branches for a dead end."""
    T = runs.shape[1] - 1
    n = runs[k, T]
    b0 = _NONE
    b1 = _NONE
    b2 = _NONE
    b3 = _NONE
    sat = _NONE
    tested = 0
    for t in range(T):
        runs[k + 1, t] = n
        if cnt[t] >= hi[t]:
            continue
        a, b = runs[k, t], runs[k, t + 1]
        tested += b - a
        for i in range(a, b):  # branch-free keep test: it is unpredictable
            m = lmask[i]
            keep = (m & occ) == _NONE
            lmask[n] = m
            lrow[n] = lrow[i]
            n += keep
            m &= _NONE - np.uint64(keep)
            c0 = b0 & m
            b0 ^= m
            c1 = b1 & c0
            b1 ^= c0
            c2 = b2 & c1
            b2 ^= c1
            sat |= b3 & c2
            b3 ^= c2
        if cnt[t] + n - runs[k + 1, t] < lo[t]:
            return 0, -1, tested  # no rows left for a piece still needed: stop at once
    runs[k + 1, T] = n
    empty = primary & ~occ
    if empty & ~(b0 | b1 | b2 | b3 | sat):
        return 0, -1, tested  # an empty cell no row can fill
    r = runs[k + 1]
    best_t, best_n = -1, 1 << 30
    for t in pieces:
        if cnt[t] == 0 and r[t + 1] - r[t] < best_n:
            best_t, best_n = t, r[t + 1] - r[t]
    cell = -1
    for v in range(1, min(best_n, SATURATED)):  # cells strictly below the best piece
        x = empty & _with_count(v, b0, b1, b2, b3, sat)
        if x != _NONE:
            cell, best_n = _low(x, table), v
            break
    if cell < 0 and best_n > SATURATED:
        c, cn = _exact_min(lmask, r[0], n, empty, table, tally)
        if cn < best_n:
            cell, best_n = c, cn
    if cell < 0:
        return best_n, best_t, tested
    bit = _ONE << np.uint64(cell)
    j = 0
    for i in range(r[0], n):
        if lmask[i] & bit:
            br[j] = i
            j += 1
    return j, -1, tested


@njit(cache=True, _nrt=False)
def box_run(rows: BoxRows, st: BoxStack, ctl: kn.Control) -> int:
    """Run (or resume) the search (:func:`chaingeo.solvers.cover.kernels.depth_first` with the
    steps below; :class:`BoxStack` describes the levels)."""
    return kn.depth_first(_root, _peek, _place, _back, rows, st, st.chosen, rows.rid, ctl)


@njit(cache=True, inline="always")
def _root(rows: BoxRows, st: BoxStack, rng: Any, shuffle: bool) -> int:
    """Level 0: every row, filtered in place (level "-1" is the root list itself)."""
    for i in range(len(rows.mask)):
        st.lmask[i] = rows.mask[i]
        st.lrow[i] = i
    for t in range(len(rows.root_runs)):
        st.runs[0, t] = st.runs[1, t] = rows.root_runs[t]
    st.occ[0] = _NONE
    return _open(rows, st, 0, _NONE, rng, shuffle)[1]


@njit(cache=True, inline="always")
def _open(rows: BoxRows, st: BoxStack, k: int, occ: Any, rng: Any, shuffle: bool) -> kn.Step:
    """Filter level ``k``'s live list under ``occ`` and list its branches: ``(branches, rows
    tested)``."""
    n_br, piece, tested = _filter(
        st.lmask, st.lrow, st.runs, k, occ, rows.primary, st.cnt, rows.hi, rows.lo,
        rows.counters, rows.pieces, rows.table, st.tally, st.br[k],
    )  # fmt: skip
    _branches_of_piece(st.br[k], n_br, piece, st.runs[k + 1])
    kn.open_level(st.br, st.nbr, st.pos, k, n_br, rng, shuffle)
    return n_br, tested


@njit(cache=True, inline="always")
def _peek(rows: BoxRows, st: BoxStack, k: int, shuffle: bool) -> kn.Step:
    return kn.next_listed(st.br, st.nbr, st.pos, k)


@njit(cache=True, inline="always")
def _place(rows: BoxRows, st: BoxStack, k: int, i: int, rng: Any, shuffle: bool) -> kn.Step:
    """Place the live row ``i`` on level ``k``: a cover, a dead end, or level ``k + 1``."""
    st.pos[k] += 1
    m = st.lmask[i]
    r = st.lrow[i]
    st.chosen[k] = r
    h0 = st.occ[k] | m
    cnt, primary = st.cnt, rows.primary
    t = rows.rtype[r]
    cnt[t] += 1
    if (h0 & primary) == primary:  # every mandatory cell covered
        ok = kn.counts_met(rows.counters, cnt, rows.lo, -1)
        cnt[t] -= 1
        return (kn.COVER if ok else kn.DEAD), 0
    if rows.region and not _regions_fit(m, primary & ~h0, rows.nb, _sums(rows.sizes, cnt, rows.hi)):
        cnt[t] -= 1  # cuts off a region no set of the unused pieces can fill
        return kn.DEAD, 0
    n_br, tested = _open(rows, st, k + 1, h0, rng, shuffle)
    if n_br == 0:
        cnt[t] -= 1
        return kn.DEAD, tested
    st.occ[k + 1] = h0
    return kn.DOWN, tested


@njit(cache=True, inline="always")
def _back(rows: BoxRows, st: BoxStack, k: int) -> None:
    """Leave level ``k``: the row placed on level ``k - 1`` is free again."""
    if k > 0:
        st.cnt[rows.rtype[st.chosen[k - 1]]] -= 1


@njit(cache=True, inline="always")
def _branches_of_piece(br: Any, n_br: int, piece: int, run: Any) -> None:
    """When the level branches on ``piece``, its branches are that type's run."""
    if piece >= 0:
        for j in range(n_br):
            br[j] = run[piece] + j


class BoxArrays:
    """Row masks of a problem (at most 64 cells) restricted to a subset of its rows, sorted by
    type, and the search-side arrays' sizes."""

    def __init__(self, problem: CoverProblem, rows: I32) -> None:
        n_cells = problem.n_cells
        if n_cells > MAX_CELLS:
            raise ValueError(f"box kernel needs at most {MAX_CELLS} cells, got {n_cells}")
        bit = scan_order(problem)  # the first-cell kernel's order: _grow relies on it
        rows, optional = reachable_rows(problem, rows)
        rtype = problem.row_type[rows].astype(np.int64)
        rows = rows[np.lexsort((rows, rtype))]  # runs of one type, in row order
        owner, cells = _row_cells(problem, rows)
        shift = np.uint64(1) << bit[cells].astype(np.uint64)
        masks = np.zeros(len(rows), dtype=np.uint64)
        np.bitwise_or.at(masks, owner, shift)
        primary = np.uint64(0)
        for c in range(n_cells):
            if not optional[c]:
                primary |= np.uint64(1) << np.uint64(bit[c])
        T = len(problem.types)
        self.rid = np.ascontiguousarray(rows)
        self.rtype = np.ascontiguousarray(problem.row_type[rows]).astype(np.int32)
        self.mask = masks
        per_type = np.bincount(self.rtype, minlength=T).astype(np.int64)
        root_runs = np.zeros(T + 1, dtype=np.int64)
        np.cumsum(per_type, out=root_runs[1:])
        lo = np.array([t.lo for t in problem.types], dtype=np.int32)
        hi = np.array([t.hi for t in problem.types], dtype=np.int32)
        counters = np.array([t for t in range(T) if lo[t] > 0], dtype=np.int32)
        pieces = np.array(
            [t for t, ty in enumerate(problem.types) if ty.lo == 1 and ty.hi == 1], dtype=np.int32
        )
        n_primary = n_cells - int(optional.sum())
        self.max_depth = min(n_primary, int(hi.sum()))
        per_cell = np.bincount(cells, minlength=n_cells)
        self.max_col = max(int(per_cell.max(initial=0)), int(per_type.max(initial=0)), 1)
        nb, _, smallest = region_pruning(problem)
        sizes = np.array([len(t.shape) for t in problem.types], dtype=np.int32)
        self.rows = BoxRows(
            masks, self.rtype, self.rid, root_runs, primary, lo, hi, counters, pieces,
            DEBRUIJN_TABLE, nb, sizes, int(smallest > 0),
        )  # fmt: skip

    def stack(self, depth: int, n_types: int) -> BoxStack:
        """Fresh search-side arrays for ``depth`` levels."""
        size = (depth + 2) * max(len(self.rid), 1)
        return BoxStack(
            cnt=np.zeros(n_types, dtype=np.int32),
            lmask=np.zeros(size, dtype=np.uint64),
            lrow=np.zeros(size, dtype=np.int32),
            runs=np.zeros((depth + 2, n_types + 1), dtype=np.int64),
            occ=np.zeros(depth + 1, dtype=np.uint64),
            tally=np.zeros(MAX_CELLS, dtype=np.int32),
            br=np.zeros((depth, self.max_col), dtype=np.int32),
            nbr=np.zeros(depth, dtype=np.int64),
            pos=np.zeros(depth, dtype=np.int64),
            chosen=np.zeros(depth, dtype=np.int32),
        )
