"""Exact cover on worker processes: the search tree cut into subtrees, one search each.

A subtree is the search with some rows forced. :func:`split_rows` picks the mandatory cell with
the fewest rows (the lowest cell on ties) and makes one subtree per row ``r`` through it: ``r``
and every row compatible with it (no shared cell; not a second copy of a piece used once).
Every cover holds exactly one row through that cell, so the subtrees' covers are the whole
search's, each met once. Subtrees are cut again, level by level, until there are
:data:`PARTS` of them or :data:`MAX_DEPTH` levels; the cut depends on the problem only, never
on the number of workers, so the counts and the collected covers (in subtree order) are the same
whatever it is. Workers are forked (they inherit the compiled kernels and the problem).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Final

import numpy as np

from chaingeo.core.arrays import I32
from chaingeo.solvers.cover.bitboard import scan_order
from chaingeo.solvers.cover.problem import CoverProblem
from chaingeo.solvers.cover.search import CoverSearch, Engine, choose_kernel
from chaingeo.solvers.jobs import fork_pool

#: Subtrees the tree is cut into (when it is that wide: the last level cut stops there; each
#: subtree's search costs its own set-up), and levels cut at most.
PARTS: Final = 16
MAX_DEPTH: Final = 3
#: Searches over fewer rows run in one process: they end before workers pay for themselves
#: (Soma's 688 rows count in a fraction of a second).
MIN_ROWS: Final = 1500


def split_rows(problem: CoverProblem, rows: I32, engine: Engine) -> list[I32]:
    """The subtrees of the search over ``rows`` (see the module's docstring), in order."""
    first_cell = choose_kernel(problem, engine) == "bitboard-first"
    scan = scan_order(problem) if first_cell else np.arange(problem.n_cells, dtype=np.int32)
    parts = [np.ascontiguousarray(rows, dtype=np.int32)]
    for _ in range(MAX_DEPTH):
        if len(parts) >= PARTS:
            break
        cut: list[I32] = []
        for i, part in enumerate(parts):
            if len(cut) + len(parts) - i >= PARTS:
                cut.append(part)  # enough subtrees: the rest stay whole
            else:
                cut.extend(_cut(problem, part, scan, first_cell))
        if len(cut) == len(parts):
            break
        parts = cut
    return parts


def _cut(problem: CoverProblem, rows: I32, scan: I32, first_cell: bool) -> list[I32]:
    """One subtree per row of the column the kernel would branch on (as near as it can be
    told from outside): an exact-once piece or a mandatory cell, of two rows or more. The
    first-cell kernel takes the first open cell in its scan order unless a piece has fewer
    rows; the others the column of fewest rows, pieces first on ties. ``[rows]`` when every
    column is decided, ``[]`` when one can no longer be covered."""
    ptr, flat = problem.row_ptr, problem.flat_cells
    sizes = (ptr[rows + 1] - ptr[rows]).astype(np.int64)
    owner = np.repeat(np.arange(len(rows)), sizes)
    starts = np.zeros(len(rows), dtype=np.int64)
    starts[1:] = np.cumsum(sizes)[:-1]
    cells = flat[np.repeat(ptr[rows] - starts, sizes) + np.arange(len(owner))]
    count = np.bincount(cells, minlength=problem.n_cells)
    mandatory = np.ones(problem.n_cells, dtype=bool)
    mandatory[sorted(problem.optional)] = False
    types = problem.row_type[rows]
    once = np.array([t.lo == 1 and t.hi == 1 for t in problem.types], dtype=bool)
    per_type = np.bincount(types, minlength=len(problem.types))
    if np.any(count[mandatory] == 0) or np.any(per_type[once] == 0):
        return []
    open_cells = np.flatnonzero(mandatory & (count >= 2))
    open_types = np.flatnonzero(once & (per_type >= 2))
    piece = int(open_types[np.argmin(per_type[open_types])]) if len(open_types) else -1
    cell = -1
    if len(open_cells):
        key = scan[open_cells] if first_cell else count[open_cells] * len(scan) + scan[open_cells]
        cell = int(open_cells[np.argmin(key)])
    if cell < 0 and piece < 0:
        return [rows]
    if piece >= 0 and (cell < 0 or per_type[piece] < count[cell] + (not first_cell)):
        chosen = np.flatnonzero(types == piece)
    else:
        chosen = np.unique(owner[cells == cell])
    out: list[I32] = []
    for i in chosen.tolist():
        taken = np.zeros(problem.n_cells, dtype=bool)
        taken[cells[starts[i] : starts[i] + sizes[i]]] = True
        clash = np.logical_or.reduceat(taken[cells], starts)
        t = types[i]
        if problem.types[t].hi == 1:
            clash |= types == t
        clash[i] = False
        out.append(rows[~clash])
    return out


def count_parallel(problem: CoverProblem, rows: I32, engine: Engine, jobs: int) -> tuple[int, int]:
    """``(covers, nodes)`` of the search over ``rows``, its subtrees on ``jobs`` workers."""
    parts = split_rows(problem, rows, engine)
    results = _map(problem, engine, jobs, parts, collect=False)
    return sum(r[0] for r in results), sum(r[1] for r in results)


def collect_parallel(
    problem: CoverProblem, rows: I32, engine: Engine, jobs: int
) -> tuple[list[I32], int]:
    """Every cover of the search over ``rows`` (blocks in subtree order) and the nodes."""
    parts = split_rows(problem, rows, engine)
    results = _map(problem, engine, jobs, parts, collect=True)
    blocks = [b for r in results for b in r[2]]
    return blocks, sum(r[1] for r in results)


_WORK: list[tuple[CoverProblem, Engine]] = []


def _start(problem: CoverProblem, engine: Engine) -> None:
    _WORK[:] = [(problem, engine)]


def _search(args: tuple[I32, bool]) -> tuple[int, int, list[I32]]:
    rows, collect = args
    problem, engine = _WORK[0]
    search = CoverSearch(problem, rows, engine=engine)
    blocks = list(search.batches(4096)) if collect else []
    if not collect:
        search.count()
    return search.found, search.stats.nodes, blocks


def _map(
    problem: CoverProblem, engine: Engine, jobs: int, parts: Sequence[I32], collect: bool
) -> list[tuple[int, int, list[I32]]]:
    """Each part searched (on ``jobs`` workers when more than one), results in part order."""
    work = [(p, collect) for p in parts]
    if jobs <= 1:
        _start(problem, engine)
        return [_search(w) for w in work]
    pool = fork_pool(jobs, _start, (problem, engine))
    try:
        return pool.map(_search, work, chunksize=1)
    finally:
        pool.terminate()
        pool.join()
