"""Bit-board exact cover for targets of at most 64 cells.

The occupancy is one ``uint64``; every row is a precomputed mask. The search fills the first
empty mandatory cell (in a scan order that runs fastest along the target's shortest axis),
trying only the rows whose lowest mandatory cell is that cell: each solution is found exactly
once, and the fit test is one AND. Near the root (:data:`MRV_DEPTH` levels) it branches instead
on an unused exact-once piece when that piece has fewer fitting placements than the cell, which
puts a symmetry-reduced anchor first and awkward pieces early. A placement is rejected when it
cuts off an empty region that no set of pieces could fill (smaller than the smallest piece or
not a multiple of the gcd of the piece sizes; box targets without optional cells). Piece types
carry count ranges exactly as in :mod:`chaingeo.solvers.cover.dlx` (checked against ``hi`` on the
way down, against ``lo`` at a full cover).

``nodes`` counts rows placed; ``updates`` counts rows tested (the bit-board's unit of work).
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np

from chaingeo.core.arrays import I32, I64, U64
from chaingeo.kernels.jit import njit
from chaingeo.solvers.cover import kernels as kn
from chaingeo.solvers.cover.problem import CoverProblem

MAX_CELLS = 64
#: Levels (from the root) at which the search branches on whichever of the first empty cell and
#: the unused exact-once pieces has the fewest fitting rows, rather than on the cell alone.
MRV_DEPTH = 2

_DEBRUIJN = np.uint64(0x03F79D71B4CB0A89)
DEBRUIJN_TABLE = np.zeros(64, dtype=np.int32)
for _i in range(64):
    DEBRUIJN_TABLE[(((1 << _i) * 0x03F79D71B4CB0A89) & 0xFFFFFFFFFFFFFFFF) >> 58] = _i


@njit(cache=True)
def _lowest_bit(x: np.uint64, table: Any) -> int:
    low = x & (~x + np.uint64(1))
    return int(table[(low * np.uint64(0x03F79D71B4CB0A89)) >> np.uint64(58)])


@njit(cache=True)
def _popcount(x: np.uint64) -> int:
    x = x - ((x >> np.uint64(1)) & np.uint64(0x5555555555555555))
    x = (x & np.uint64(0x3333333333333333)) + ((x >> np.uint64(2)) & np.uint64(0x3333333333333333))
    x = (x + (x >> np.uint64(4))) & np.uint64(0x0F0F0F0F0F0F0F0F)
    return int((x * np.uint64(0x0101010101010101)) >> np.uint64(56))


@njit(cache=True)
def _grow(x: np.uint64, nb: Any) -> Any:
    """``x`` with its face neighbours in the box (``nb``: edge masks and strides)."""
    return (
        x
        | ((x & nb[0]) << np.uint64(1))
        | ((x & nb[1]) >> np.uint64(1))
        | ((x & nb[2]) << nb[6])
        | ((x & nb[3]) >> nb[6])
        | ((x & nb[4]) << nb[7])
        | ((x & nb[5]) >> nb[7])
    )


@njit(cache=True)
def regions_ok(placed: np.uint64, empty: np.uint64, nb: Any, gcd: int, smallest: int) -> bool:
    """Can every empty region touching the piece just placed still be filled?

    Each region is grown from a seed next to the piece; it must hold at least ``smallest``
    cells and a multiple of ``gcd`` (the gcd of all piece sizes). With ``gcd`` 1 the growth
    stops once the region is big enough. Regions the piece does not touch were checked when
    they formed.
    """
    seeds = _grow(placed, nb) & empty
    while seeds != 0:
        region = seeds & (~seeds + np.uint64(1))
        while True:
            grown = _grow(region, nb) & empty
            if grown == region:
                break
            region = grown
            if gcd == 1 and _popcount(region) >= smallest:
                break
        size = _popcount(region)
        if size < smallest or size % gcd != 0:
            return False
        seeds &= ~region
    return True


@njit(cache=True)
def _enter(k: int, lst_start: int, lst_len: int, cand: Any, perm: Any, width: int,
           base: Any, pos: Any, end: Any, shuffle: bool, rng: Any) -> None:  # fmt: skip
    """Start level ``k`` on the candidate list ``cand[lst_start : lst_start + lst_len]``
    (copied into level ``k``'s slice of ``perm`` and shuffled in random mode)."""
    if shuffle:
        off = k * width
        for i in range(lst_len):
            perm[off + i] = cand[lst_start + i]
        kn.shuffle_prefix(perm[off : off + lst_len], lst_len, rng)
        base[k] = off
    else:
        base[k] = lst_start
    pos[k] = base[k]
    end[k] = base[k] + lst_len


@njit(cache=True)
def _count_fits(cand: Any, start: int, n: int, mask: Any, rtype: Any, cnt: Any, hi: Any,
                here: np.uint64) -> int:  # fmt: skip
    """How many rows of ``cand[start : start + n]`` are still available and fit."""
    fits = 0
    for i in range(start, start + n):
        r = cand[i]
        t = rtype[r]
        if cnt[t] < hi[t] and (mask[r] & here) == 0:
            fits += 1
    return fits


@njit(cache=True)
def _fewest_fits(
    c: int, cand_ptr: Any, cand: Any, type_ptr: Any, exact1: Any, mask: Any,
    rtype: Any, cnt: Any, hi: Any, here: np.uint64,
) -> tuple[int, int, int, int]:  # fmt: skip
    """The list to branch on: cell ``c``'s or an unused exact-once piece's, whichever has the
    fewest rows that fit; returns ``(start, length, fits, rows examined)``."""
    a = cand_ptr[c]
    n = cand_ptr[c + 1] - a
    best = _count_fits(cand, a, n, mask, rtype, cnt, hi, here)
    work = n
    for t in exact1:
        if best == 0:
            break
        if cnt[t] == 0:
            ta = type_ptr[t]
            tn = type_ptr[t + 1] - ta
            work += tn
            fits = _count_fits(cand, ta, tn, mask, rtype, cnt, hi, here)
            if fits < best:
                best, a, n = fits, ta, tn
    return a, n, best, work


class BitboardRows(NamedTuple):
    """The problem side of a first-cell search (read only): row masks and types, candidate
    lists per cell and per type (``skip``: the end of each type's run), the exact-once pieces
    and how deep to branch on them, the mandatory cells, count ranges, region pruning."""

    mask: U64
    rtype: I32
    rid: I32
    cand_ptr: I64
    cand: I32
    skip: I64
    type_ptr: I64
    exact1: I32
    mrv_depth: int
    primary: np.uint64
    lo: I32
    hi: I32
    counters: I32
    table: I32
    nb: U64
    region_gcd: int
    region_min: int


@njit(cache=True, _nrt=False)
def bitboard_run(rows: BitboardRows, occ: U64, lv: kn.Levels, ctl: kn.Control) -> int:
    """Run (or resume) the search (:func:`chaingeo.solvers.cover.kernels.depth_first` with the
    steps below).

    ``lv.pos[k]``/``lv.nbuf[k]`` (position, end) index ``cand`` (fixed order) or level ``k``'s
    slice of ``lv.buf`` (random order, ``width`` entries per level, from ``lv.aux[k]``);
    ``occ[k]``: level ``k``'s occupancy.
    """
    return kn.depth_first(_root, _peek, _place, _back, rows, (occ, lv), lv.chosen, rows.rid, ctl)


@njit(cache=True, inline="always")
def _root(rows: BitboardRows, state: Any, rng: Any, shuffle: bool) -> int:
    """Level 0: the first mandatory cell's list (or a piece's, with the fewest fits)."""
    occ, lv = state
    occ[0] = np.uint64(0)
    return _open(rows, occ, lv, 0, rows.primary, rng, shuffle)


@njit(cache=True, inline="always")
def _open(
    rows: BitboardRows, occ: U64, lv: kn.Levels, k: int, free: Any, rng: Any, shuffle: bool
) -> int:
    """Level ``k`` tries the rows of the first empty mandatory cell of ``free`` (near the root:
    or of the piece with fewest fits); returns the rows examined."""
    c = _lowest_bit(free, rows.table)
    a = rows.cand_ptr[c]
    n = rows.cand_ptr[c + 1] - a
    work = 0
    if k < rows.mrv_depth:  # near the root: branch on the cell or piece with fewest fits
        a, n, fits, work = _fewest_fits(
            c, rows.cand_ptr, rows.cand, rows.type_ptr, rows.exact1, rows.mask, rows.rtype,
            lv.cnt, rows.hi, occ[k],
        )  # fmt: skip
        if fits == 0:
            n = 0
    width = len(lv.buf) // len(lv.pos)
    _enter(k, a, n, rows.cand, lv.buf, width, lv.aux, lv.pos, lv.nbuf, shuffle, rng)
    return work


@njit(cache=True, inline="always")
def _peek(rows: BitboardRows, state: Any, k: int, shuffle: bool) -> kn.Step:
    """The next row that fits at level ``k`` (its position left in ``pos[k]``) and the rows
    tested before it."""
    occ, lv = state
    rtype, cnt, hi, mask, primary = rows.rtype, lv.cnt, rows.hi, rows.mask, rows.primary
    nb, region_gcd, region_min = rows.nb, rows.region_gcd, rows.region_min
    src = lv.buf if shuffle else rows.cand
    p = lv.pos[k]
    e = lv.nbuf[k]
    here = occ[k]
    tested = 0
    while p < e:
        r = src[p]
        t = rtype[r]
        if cnt[t] >= hi[t]:
            p = p + 1 if shuffle else rows.skip[p]  # past this type's run
            continue
        p += 1
        tested += 1
        m = mask[r]
        if (m & here) != 0:
            continue
        free = primary & ~(here | m)
        if region_min > 0 and free != 0 and not regions_ok(m, free, nb, region_gcd, region_min):
            continue
        lv.pos[k] = p - 1
        return r, tested - 1  # placing it counts its test (at a node limit: tried again)
    lv.pos[k] = p
    return -1, tested


@njit(cache=True, inline="always")
def _place(rows: BitboardRows, state: Any, k: int, r: int, rng: Any, shuffle: bool) -> kn.Step:
    """Place row ``r`` on level ``k``: a cover, a dead end, or level ``k + 1``."""
    occ, lv = state
    lv.pos[k] += 1
    t = rows.rtype[r]
    lv.chosen[k] = r
    here = occ[k] | rows.mask[r]
    free = rows.primary & ~here
    if free == 0:  # every mandatory cell covered
        return (kn.COVER if kn.counts_met(rows.counters, lv.cnt, rows.lo, t) else kn.DEAD), 1
    lv.cnt[t] += 1
    occ[k + 1] = here
    return kn.DOWN, 1 + _open(rows, occ, lv, k + 1, free, rng, shuffle)


@njit(cache=True, inline="always")
def _back(rows: BitboardRows, state: Any, k: int) -> None:
    """Leave level ``k``: the row placed on level ``k - 1`` is free again."""
    if k > 0:
        lv = state[1]
        lv.cnt[rows.rtype[lv.chosen[k - 1]]] -= 1


def scan_axes(problem: CoverProblem) -> list[int]:
    """The axes in scan order, fastest first: the shortest bounding-box axis first."""
    ext = problem.target.extent
    axes = sorted(range(3), key=lambda a: (ext[a], a))
    return axes


def scan_order(problem: CoverProblem) -> I32:
    """``bit[cell]``: cells ranked in :func:`scan_axes` order."""
    vox = problem.target.voxels - problem.target.min_corner
    axes = scan_axes(problem)
    rank = np.lexsort([vox[:, a] for a in axes])  # last key is the primary sort key
    bit = np.empty(len(vox), dtype=np.int32)
    bit[rank] = np.arange(len(vox), dtype=np.int32)
    return bit


class BitboardArrays:
    """Row masks and per-cell candidate lists of a problem restricted to a subset of rows."""

    def __init__(self, problem: CoverProblem, rows: I32) -> None:
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
        low = np.array([_lowest_bit(np.uint64(x), DEBRUIJN_TABLE) for x in pm], dtype=np.int64)
        rtype = problem.row_type[rows].astype(np.int64)
        order = np.lexsort((rows, rtype, low))  # by lowest mandatory cell, type, row id
        self.mask = np.ascontiguousarray(masks[order])
        self.rid = np.ascontiguousarray(rows[order])
        self.rtype = np.ascontiguousarray(rtype[order]).astype(np.int32)
        counts = np.bincount(low, minlength=MAX_CELLS)
        self.cand_ptr = np.zeros(MAX_CELLS + 1, dtype=np.int64)
        np.cumsum(counts, out=self.cand_ptr[1:])
        # Every row again, grouped by type: lists for branching on a piece.
        n = len(order)
        T = len(problem.types)
        by_type = np.argsort(self.rtype, kind="stable").astype(np.int32)
        self.type_ptr = np.zeros(T + 1, dtype=np.int64)
        np.cumsum(np.bincount(self.rtype, minlength=T), out=self.type_ptr[1:])
        self.type_ptr += n
        self.cand = np.concatenate([np.arange(n), by_type]).astype(np.int32)
        self.exact1 = np.array(
            [t for t, ty in enumerate(problem.types) if ty.lo == 1 and ty.hi == 1], dtype=np.int32
        )
        self.mrv_depth = MRV_DEPTH
        # skip[i]: end of the run of candidates of one type (in one list) containing position i.
        key = np.concatenate([low[order] * (T + 1) + self.rtype, -2 - self.rtype[by_type]])
        self.skip = np.empty(len(self.cand), dtype=np.int64)
        end = len(self.cand)
        for i in range(len(self.cand) - 1, -1, -1):
            if i + 1 < len(self.cand) and key[i + 1] != key[i]:
                end = i + 1
            self.skip[i] = end
        self.primary = primary
        self.lo = np.array([t.lo for t in problem.types], dtype=np.int32)
        self.hi = np.array([t.hi for t in problem.types], dtype=np.int32)
        self.counters = np.array([t for t in range(T) if self.lo[t] > 0], dtype=np.int32)
        n_primary = problem.n_cells - len(problem.optional)
        self.max_depth = min(n_primary, int(self.hi.sum()))
        self.max_col = max(int(counts.max()), int(np.diff(self.type_ptr).max(initial=0)))
        nb, gcd, smallest = region_pruning(problem)
        self.rows = BitboardRows(
            self.mask, self.rtype, self.rid, self.cand_ptr, self.cand, self.skip, self.type_ptr,
            self.exact1, self.mrv_depth, primary, self.lo, self.hi, self.counters,
            DEBRUIJN_TABLE, nb, int(gcd), int(smallest),
        )  # fmt: skip


def region_pruning(problem: CoverProblem) -> tuple[np.ndarray, int, int]:
    """Edge masks and strides of a box target in scan order, the gcd and the least of the piece
    sizes; ``region_min`` is 0 (pruning off) for non-box targets, optional cells, or when no
    region size could ever be ruled out."""
    nb = np.zeros(8, dtype=np.uint64)
    ext = problem.target.extent
    if problem.optional or problem.n_cells != ext[0] * ext[1] * ext[2]:
        return nb, 1, 0
    sizes = [len(t.shape) for t in problem.types]
    gcd = int(np.gcd.reduce(sizes))
    smallest = min(sizes)
    if gcd == 1 and smallest == 1:
        return nb, 1, 0
    e0, e1, e2 = (ext[a] for a in scan_axes(problem))
    i = np.arange(problem.n_cells)
    i0, i1, i2 = i % e0, (i // e0) % e1, i // (e0 * e1)
    for slot, sel in enumerate([i0 < e0 - 1, i0 > 0, i1 < e1 - 1, i1 > 0, i2 < e2 - 1, i2 > 0]):
        nb[slot] = np.uint64(sum(1 << int(b) for b in i[sel]))
    nb[6], nb[7] = np.uint64(e0), np.uint64(e0 * e1)
    return nb, gcd, smallest
