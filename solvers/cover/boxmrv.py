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
from chaingeo.solvers.cover.bitmrv import SATURATED, _low, _row_cells, _starts, _with_count
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


@njit(cache=True)
def box_run(rows: BoxRows, st: BoxStack, ctl: kn.Control) -> int:
    """Run (or resume) the search; same contract as :func:`chaingeo.solvers.cover.dlx.dlx_run`
    (:class:`BoxStack` describes the levels)."""
    mask, rtype, rid, root_runs, primary, lo, hi, counters, pieces, table = rows[:10]
    nb, sizes, region = rows[10:]
    cnt, lmask, lrow, runs, occ, tally, br, nbr, pos, chosen = st
    regs, rng, shuffle, out, max_store, stop_after, node_limit = ctl
    status = regs[kn.REG_STATUS]
    if status == kn.DONE:
        return 0
    nodes = regs[kn.REG_NODES]
    updates = regs[kn.REG_UPDATES]
    found = 0
    n_out = 0
    if status == kn.FRESH:
        k = 0
        occ[0] = _NONE
        n = len(mask)
        lmask[:n] = mask
        lrow[:n] = np.arange(n, dtype=np.int32)
        runs[0, :] = root_runs  # level "-1" is the root list itself, so filter it in place
        runs[1, :] = root_runs
        n_br, piece, tested = _filter(
            lmask, lrow, runs, 0, _NONE, primary, cnt, hi, lo, counters, pieces, table,
            tally, br[0],
        )  # fmt: skip
        _branches_of_piece(br[0], n_br, piece, runs[1])
        updates += tested
        nbr[0] = n_br
        pos[0] = 0
        if shuffle:
            kn.shuffle_prefix(br[0], n_br, rng)
    else:
        k = regs[kn.REG_DEPTH]
    regs[kn.REG_STATUS] = kn.RUNNING
    while True:
        if pos[k] < nbr[k]:
            if nodes >= node_limit:
                regs[kn.REG_STATUS] = kn.LIMIT
                break
            i = br[k, pos[k]]
            pos[k] += 1
            nodes += 1
            m = lmask[i]
            r = lrow[i]
            chosen[k] = r
            h0 = occ[k] | m
            t = rtype[r]
            cnt[t] += 1
            if (h0 & primary) == primary:  # every mandatory cell covered
                ok = True
                for q in counters:
                    if cnt[q] < lo[q]:
                        ok = False
                        break
                cnt[t] -= 1
                if ok:
                    found += 1
                    if max_store > 0:
                        n_out = kn.store_solution(out, n_out, chosen, rid, k)
                    if (max_store > 0 and n_out == max_store) or found == stop_after:
                        break
                continue
            if region and not _regions_fit(m, primary & ~h0, nb, _sums(sizes, cnt, hi)):
                cnt[t] -= 1  # cuts off a region no set of the unused pieces can fill
                continue
            n_br, piece, tested = _filter(
                lmask, lrow, runs, k + 1, h0, primary, cnt, hi, lo, counters, pieces, table,
                tally, br[k + 1],
            )  # fmt: skip
            updates += tested
            if n_br == 0:
                cnt[t] -= 1
                continue
            _branches_of_piece(br[k + 1], n_br, piece, runs[k + 2])
            k += 1
            occ[k] = h0
            nbr[k] = n_br
            pos[k] = 0
            if shuffle:
                kn.shuffle_prefix(br[k], n_br, rng)
        else:
            if k == 0:
                regs[kn.REG_STATUS] = kn.DONE
                break
            k -= 1
            cnt[rtype[chosen[k]]] -= 1
    kn.save_registers(regs, k, nodes, updates, found)
    return n_out


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
        optional = np.zeros(n_cells, dtype=bool)
        if problem.optional:
            optional[sorted(problem.optional)] = True
        rows = np.asarray(rows, dtype=np.int32)
        owner, cells = _row_cells(problem, rows)
        if len(rows):
            rows = rows[~np.logical_and.reduceat(optional[cells], _starts(owner, len(rows)))]
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
