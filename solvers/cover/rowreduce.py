"""Placements that can take part in no cover, found before the search (BurrTools' ``-r``).

A row is dead when placing it leaves some required column (a fixed cell of the target, or a
piece that must be used exactly once) with no row compatible with it: rows that share a cell
with it, or are the same single-use piece, are gone. No cover holds a dead row, so removing it
changes no count; removing rows can kill others, so passes repeat until none dies. The depth-
first search then meets far fewer dead ends: on a 36-piece burr it finds assemblies at once
where the unreduced search found none in minutes. Each test is one trial placement, each
column's alive rows a bit set (one OR over the row's columns, one subset test per column), in
numba.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from chaingeo.core.arrays import I32, I64
from chaingeo.kernels.jit import mode, njit
from chaingeo.solvers.cover.problem import CoverProblem

B1 = npt.NDArray[np.bool_]

#: Passes over the rows at most (each after the first only when some row died).
MAX_PASSES = 16
#: Interpreted kernels: rows x rows x columns up to this go through :func:`_dead_rows_dense`.
DENSE_WORK = 60_000_000


@njit(cache=True)
def _dead_rows(
    row_ptr: I64, cols: I64, col_ptr: I64, col_rows: I64, required: B1, alive: B1,
    max_passes: int,
) -> int:  # fmt: skip
    """Clear ``alive`` for every dead row (row ``r`` covers ``cols[row_ptr[r]:row_ptr[r+1]]``;
    column ``c`` is covered by ``col_rows[col_ptr[c]:col_ptr[c+1]]``); returns rows killed.

    Rows are tested one at a time, in order, each against the rows alive then. Row ``r`` is
    dead when some required column it does not cover has alive rows, all of which share a
    column with ``r``. With each column's alive rows as a bit set that is one OR over
    ``r``'s columns and one subset test per column (the count-and-restore of dancing links
    walked every conflicting row's cells: 0.05 s a pass on SolidSixPieceBurrs' 1241 rows)."""
    n_rows = row_ptr.shape[0] - 1
    n_cols = col_ptr.shape[0] - 1
    words = (n_rows + 63) >> 6
    bits = np.zeros((n_cols, words), dtype=np.uint64)
    size = np.zeros(n_cols, dtype=np.int64)
    for c in range(n_cols):
        for p in range(col_ptr[c], col_ptr[c + 1]):
            r = col_rows[p]
            if alive[r]:
                bits[c, r >> 6] |= np.uint64(1) << np.uint64(r & 63)
                size[c] += 1
    own = np.zeros(n_cols, dtype=np.int64)
    gone = np.zeros(words, dtype=np.uint64)
    killed = 0
    for _ in range(max_passes):
        changed = False
        for r in range(n_rows):
            if not alive[r]:
                continue
            gone[:] = 0
            for q in range(row_ptr[r], row_ptr[r + 1]):
                own[cols[q]] = r + 1
                for w in range(words):
                    gone[w] |= bits[cols[q], w]
            if _some_column_gone(bits, size, required, own, gone, r + 1):
                alive[r] = False
                killed += 1
                changed = True
                for q in range(row_ptr[r], row_ptr[r + 1]):
                    bits[cols[q], r >> 6] &= ~(np.uint64(1) << np.uint64(r & 63))
                    size[cols[q]] -= 1
        if not changed:
            break
    return killed


@njit(cache=True)
def _some_column_gone(
    bits: npt.NDArray[np.uint64], size: I64, required: B1, own: I64,
    gone: npt.NDArray[np.uint64], mine: int,
) -> bool:  # fmt: skip
    """Whether a required column outside the row (``own[c] != mine``) has alive rows, every
    one of them in ``gone``."""
    for c in range(bits.shape[0]):
        if not required[c] or own[c] == mine or size[c] == 0:
            continue
        covered = True
        for w in range(bits.shape[1]):
            if bits[c, w] & ~gone[w]:
                covered = False
                break
        if covered:
            return True
    return False


def live_rows(problem: CoverProblem, rows: I32 | None = None) -> I32:
    """``rows`` (default: all) without the rows no cover of ``problem`` can hold, in order.

    Columns: every cell (required unless optional) and, for a piece used at most once, the
    piece (required when it must be used); pieces that may be used several times add no
    column (their rows stay compatible with each other), which only keeps more rows."""
    if problem.n_rows == 0:
        return np.zeros(0, dtype=np.int32)
    row_ptr, cols, col_ptr, col_rows, required, alive = columns(problem, rows)
    dense = mode() == "python" and problem.n_rows**2 * len(required) <= DENSE_WORK
    if not (dense and _dead_rows_dense(row_ptr, cols, required, alive, MAX_PASSES)):
        _dead_rows(row_ptr, cols, col_ptr, col_rows, required, alive, MAX_PASSES)
    return np.flatnonzero(alive).astype(np.int32)


def columns(problem: CoverProblem, rows: I32 | None = None) -> tuple[I64, I64, I64, I64, B1, B1]:
    """The arrays :func:`_dead_rows` takes: rows' columns, columns' rows, required, alive."""
    n_rows, n_cells = problem.n_rows, problem.n_cells
    alive = np.zeros(n_rows, dtype=np.bool_)
    if rows is None:
        alive[:] = True
    else:
        alive[np.asarray(rows, dtype=np.int64)] = True
    single = np.array([t.hi == 1 for t in problem.types], dtype=np.bool_)
    must = np.array([t.lo == 1 for t in problem.types], dtype=np.bool_)
    row_type = problem.row_type.astype(np.int64)
    cell_ptr = np.asarray(problem.row_ptr, dtype=np.int64)
    sizes = np.diff(cell_ptr) + single[row_type]
    row_ptr = np.zeros(n_rows + 1, dtype=np.int64)
    np.cumsum(sizes, out=row_ptr[1:])
    cols = np.empty(int(row_ptr[-1]), dtype=np.int64)
    ends = row_ptr[1:] - single[row_type]  # a row's cells, then its piece column
    cell_of = np.arange(len(problem.flat_cells)) - np.repeat(cell_ptr[:-1], np.diff(cell_ptr))
    cols[np.repeat(row_ptr[:-1], np.diff(cell_ptr)) + cell_of] = problem.flat_cells
    with_piece = np.flatnonzero(single[row_type])
    cols[ends[with_piece]] = n_cells + row_type[with_piece]
    required = np.ones(n_cells + len(problem.types), dtype=np.bool_)
    required[sorted(problem.optional)] = False
    required[n_cells:] = single & must
    order = np.argsort(cols, kind="stable")
    col_rows = np.repeat(np.arange(n_rows), sizes)[order]
    col_ptr = np.zeros(len(required) + 1, dtype=np.int64)
    np.cumsum(np.bincount(cols, minlength=len(required)), out=col_ptr[1:])
    return row_ptr, cols, col_ptr, col_rows, required, alive


def _dead_rows_dense(row_ptr: I64, cols: I64, required: B1, alive: B1, max_passes: int) -> bool:
    """:func:`_dead_rows` in numpy for interpreted runs (the loop there costs 0.2-0.5 s of a
    small puzzle): every alive row tested at once per round, rows x rows conflicts as a matrix
    product. Returns False, ``alive`` untouched, where the result could differ from the
    kernel's one row at a time: more than ``max_passes`` rounds, or a required column left
    with no row (then which rows the kernel keeps depends on its order). Elsewhere both reach
    the same greatest set of rows none of which is dead: deadness only grows as rows go."""
    n_rows, n_cols = len(row_ptr) - 1, len(required)
    cover = np.zeros((n_rows, n_cols), dtype=np.float32)
    cover[np.repeat(np.arange(n_rows), np.diff(row_ptr)), cols] = 1.0
    free = required[None, :] & (cover == 0)
    live = alive.copy()
    for _ in range(max_passes + 1):
        held = cover * live[:, None]
        count = held.sum(axis=0)
        clash = (cover @ held.T > 0).astype(np.float32)  # [r, r2]: alive r2 shares a column
        left = clash @ cover  # [r, c]: alive rows covering c that placing r removes
        dead = live & ((left > 0) & (left == count[None, :]) & free).any(axis=1)
        if not dead.any():
            break
        live &= ~dead
    else:
        return False
    if np.any(required & ((cover * live[:, None]).sum(axis=0) == 0)):
        return False
    alive[:] = live
    return True
