"""Bit-board exact cover for targets of at most 64 cells.

The occupancy is one ``uint64``; every row is a precomputed mask. The search always fills the
first empty mandatory cell (in a scan order that runs fastest along the target's shortest
axis), trying only the rows whose lowest mandatory cell is that cell: each solution is found
exactly once, and the fit test is one AND. Piece types carry count ranges exactly as in
:mod:`solvers.dlx` (checked against ``hi`` on the way down, against ``lo`` at a full cover).

``nodes`` counts rows placed; ``updates`` counts rows tested (the bit-board's unit of work).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numba import njit

from solvers.kernels import (
    DONE,
    FRESH,
    LIMIT,
    REG_DEPTH,
    REG_NODES,
    REG_SOLUTIONS,
    REG_STATUS,
    REG_UPDATES,
    RUNNING,
    shuffle_prefix,
)
from solvers.problem import CoverProblem, Int32Array

MAX_CELLS = 64

_DEBRUIJN = np.uint64(0x03F79D71B4CB0A89)
_DEBRUIJN_TABLE = np.zeros(64, dtype=np.int32)
for _i in range(64):
    _DEBRUIJN_TABLE[(((1 << _i) * 0x03F79D71B4CB0A89) & 0xFFFFFFFFFFFFFFFF) >> 58] = _i


@njit(cache=True)
def _lowest_bit(x: np.uint64, table: Any) -> int:
    low = x & (~x + np.uint64(1))
    return int(table[(low * np.uint64(0x03F79D71B4CB0A89)) >> np.uint64(58)])


@njit(cache=True)
def bitboard_run(
    mask: Any, rtype: Any, rid: Any, cand_ptr: Any, cand: Any, primary: np.uint64,
    lo: Any, hi: Any, cnt: Any, counters: Any, table: Any,
    occ: Any, buf: Any, nbuf: Any, pos: Any, base: Any, chosen: Any,
    regs: Any, rng: Any, shuffle: bool,
    out: Any, max_store: int, stop_after: int, node_limit: int,
) -> int:  # fmt: skip
    """Run (or resume) the search; same contract as :func:`solvers.dlx.dlx_run`."""
    status = regs[REG_STATUS]
    if status == DONE:
        return 0
    nodes = regs[REG_NODES]
    updates = regs[REG_UPDATES]
    found = 0
    n_out = 0
    if status == FRESH:
        k = 0
        occ[0] = np.uint64(0)
        cell = _lowest_bit(primary, table)
        base[0] = cand_ptr[cell]
        nbuf[0] = cand_ptr[cell + 1] - cand_ptr[cell]
        pos[0] = 0
        if shuffle:
            for i in range(nbuf[0]):
                buf[0, i] = cand[base[0] + i]
            shuffle_prefix(buf[0], nbuf[0], rng)
    else:
        k = regs[REG_DEPTH]
    regs[REG_STATUS] = RUNNING
    while True:
        if pos[k] < nbuf[k]:
            if shuffle:
                r = buf[k, pos[k]]
            else:
                r = cand[base[k] + pos[k]]
            pos[k] += 1
            updates += 1
            t = rtype[r]
            if cnt[t] >= hi[t] or (mask[r] & occ[k]) != 0:
                continue
            if nodes >= node_limit:
                pos[k] -= 1
                updates -= 1
                regs[REG_STATUS] = LIMIT
                break
            nodes += 1
            cnt[t] += 1
            chosen[k] = r
            o = occ[k] | mask[r]
            free = primary & ~o
            if free == 0:
                ok = True
                for q in counters:
                    if cnt[q] < lo[q]:
                        ok = False
                        break
                cnt[t] -= 1
                if ok:
                    found += 1
                    if max_store > 0:
                        for d in range(k + 1):
                            out[n_out, d] = rid[chosen[d]]
                        for d in range(k + 1, out.shape[1]):
                            out[n_out, d] = -1
                        n_out += 1
                    if (max_store > 0 and n_out == max_store) or found == stop_after:
                        break
                continue
            k += 1
            occ[k] = o
            cell = _lowest_bit(free, table)
            base[k] = cand_ptr[cell]
            nbuf[k] = cand_ptr[cell + 1] - cand_ptr[cell]
            pos[k] = 0
            if shuffle:
                for i in range(nbuf[k]):
                    buf[k, i] = cand[base[k] + i]
                shuffle_prefix(buf[k], nbuf[k], rng)
        else:
            if k == 0:
                regs[REG_STATUS] = DONE
                break
            k -= 1
            cnt[rtype[chosen[k]]] -= 1
    regs[REG_DEPTH] = k
    regs[REG_NODES] = nodes
    regs[REG_UPDATES] = updates
    regs[REG_SOLUTIONS] += found
    return n_out


def scan_order(problem: CoverProblem) -> Int32Array:
    """``bit[cell]``: cells ranked with the shortest bounding-box axis varying fastest."""
    vox = problem.target.voxels - problem.target.min_corner
    ext = np.asarray(problem.target.extent)
    axes = sorted(range(3), key=lambda a: (ext[a], a))  # fastest first
    rank = np.lexsort([vox[:, a] for a in axes])  # last key is the primary sort key
    bit = np.empty(len(vox), dtype=np.int32)
    bit[rank] = np.arange(len(vox), dtype=np.int32)
    return bit


class BitboardArrays:
    """Row masks and per-cell candidate lists of a problem restricted to a subset of rows."""

    def __init__(self, problem: CoverProblem, rows: Int32Array) -> None:
        if problem.n_cells > MAX_CELLS:
            raise ValueError(f"bit-board needs at most {MAX_CELLS} cells, got {problem.n_cells}")
        bit = scan_order(problem)
        primary = np.uint64(0)
        for c in range(problem.n_cells):
            if c not in problem.optional:
                primary |= np.uint64(1) << np.uint64(bit[c])
        rows = np.asarray(rows, dtype=np.int32)
        ptr, flat = problem.row_ptr, problem.flat_cells
        masks = np.zeros(len(rows), dtype=np.uint64)
        for i, r in enumerate(rows):
            m = np.uint64(0)
            for c in bit[flat[ptr[r] : ptr[r + 1]]]:
                m |= np.uint64(1) << np.uint64(c)
            masks[i] = m
        pm = masks & primary
        keep = pm != 0  # rows entirely on optional cells are unreachable
        rows, masks, pm = rows[keep], masks[keep], pm[keep]
        low = np.array([_lowest_bit(np.uint64(x), _DEBRUIJN_TABLE) for x in pm], dtype=np.int64)
        order = np.lexsort((rows, low))  # by lowest mandatory cell, then row id
        self.mask = np.ascontiguousarray(masks[order])
        self.rid = np.ascontiguousarray(rows[order])
        self.rtype = np.ascontiguousarray(problem.row_type[self.rid]).astype(np.int32)
        self.cand = np.arange(len(order), dtype=np.int32)
        counts = np.bincount(low[order], minlength=MAX_CELLS)
        self.cand_ptr = np.zeros(MAX_CELLS + 1, dtype=np.int64)
        np.cumsum(counts, out=self.cand_ptr[1:])
        self.primary = primary
        T = len(problem.types)
        self.lo = np.array([t.lo for t in problem.types], dtype=np.int32)
        self.hi = np.array([t.hi for t in problem.types], dtype=np.int32)
        self.counters = np.array([t for t in range(T) if self.lo[t] > 0], dtype=np.int32)
        n_primary = problem.n_cells - len(problem.optional)
        self.max_depth = min(n_primary, int(self.hi.sum()))
        self.max_col = int(counts.max()) if len(counts) else 0
        self.table = _DEBRUIJN_TABLE
