"""Exact cover on worker processes: the search tree cut into subtrees, one search each.

A subtree is the search with some rows forced. :func:`split_rows` picks the mandatory cell with
the fewest rows (the lowest cell on ties) and makes one subtree per row ``r`` through it: ``r``
and every row compatible with it (no shared cell; not a second copy of a piece used once).
Every cover holds exactly one row through that cell, so the subtrees' covers are the whole
search's, each met once. Subtrees are cut again, level by level, until there are
:data:`PARTS` of them or :data:`MAX_DEPTH` levels; the cut depends on the problem only, never
on the number of workers, so the counts and the collected covers (in subtree order) are the same
whatever it is. Workers are forked (they inherit the compiled kernels and the problem), or the
subtrees go to a Dask cluster (:class:`chaingeo.solvers.jobs.Farm`).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Final

import numpy as np

from chaingeo.core.arrays import I32
from chaingeo.solvers.cover.bitboard import scan_order
from chaingeo.solvers.cover.problem import CoverProblem
from chaingeo.solvers.cover.search import CoverLimitError, CoverSearch, Engine, choose_kernel
from chaingeo.solvers.jobs import Farm, as_farm, farm_map

#: Subtrees the tree is cut into (when it is that wide: the last level cut stops there; each
#: subtree's search costs its own set-up), and levels cut at most.
PARTS: Final = 16
MAX_DEPTH: Final = 3
#: Searches over fewer rows run in one process: they end before workers pay for themselves
#: (Soma's 688 rows count in a fraction of a second).
MIN_ROWS: Final = 1500


def split_rows(
    problem: CoverProblem,
    rows: I32,
    engine: Engine,
    *,
    parts: int | None = None,
    max_depth: int | None = None,
) -> list[I32]:
    """The subtrees of the search over ``rows`` (see the module's docstring), in order: about
    ``parts`` of them (default :data:`PARTS`), cut ``max_depth`` levels at most (default
    :data:`MAX_DEPTH`)."""
    first_cell = choose_kernel(problem, engine) == "bitboard-first"
    scan = scan_order(problem) if first_cell else np.arange(problem.n_cells, dtype=np.int32)
    want = PARTS if parts is None else parts
    out = [np.ascontiguousarray(rows, dtype=np.int32)]
    for _ in range(MAX_DEPTH if max_depth is None else max_depth):
        if len(out) >= want:
            break
        cut: list[I32] = []
        changed = False  # a level that cuts nothing ends the cutting (dead subtrees dropped)
        for i, part in enumerate(out):
            if len(cut) + len(out) - i >= want:
                cut.append(part)  # enough subtrees: the rest stay whole
            else:
                pieces = _cut(problem, part, scan, first_cell)
                changed |= len(pieces) != 1 or pieces[0] is not part
                cut.extend(pieces)
        if not changed:
            break
        out = cut
    return out


def split_widest(problem: CoverProblem, rows: I32, engine: Engine, parts: int) -> list[I32]:
    """The search over ``rows`` cut into about ``parts`` subtrees, in order: a subtree whose
    search ends within :data:`PROBE_NODES` nodes is left whole (dropped when it holds no
    cover), and of the others the one of most rows is cut next. A search whose first cuts leave
    most branches dead so still ends in many live subtrees."""
    first_cell = choose_kernel(problem, engine) == "bitboard-first"
    scan = scan_order(problem) if first_cell else np.arange(problem.n_cells, dtype=np.int32)
    out = [np.ascontiguousarray(rows, dtype=np.int32)]
    big = [True]  # per part: its search outlasts the probe
    while len(out) < parts and any(big):
        i = max((k for k in range(len(out)) if big[k]), key=lambda k: (len(out[k]), -k))
        pieces = _cut(problem, out[i], scan, first_cell)
        if len(pieces) == 1 and pieces[0] is out[i]:
            big[i] = False
            continue
        sizes = [_probe(problem, p, engine) for p in pieces]
        out[i : i + 1] = [p for p, n in zip(pieces, sizes, strict=True) if n != 0]
        big[i : i + 1] = [n < 0 for n in sizes if n != 0]
    return out


#: Nodes a subtree's search may take and still be left whole by :func:`split_widest`.
PROBE_NODES: Final = 2000


def _probe(problem: CoverProblem, rows: I32, engine: Engine) -> int:
    """The covers of the search over ``rows`` if it ends within :data:`PROBE_NODES` nodes,
    else -1."""
    search = CoverSearch(problem, rows, engine=engine, node_limit=PROBE_NODES)
    try:
        return search.count()
    except CoverLimitError:
        return -1


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


def count_parallel(
    problem: CoverProblem, rows: I32, engine: Engine, jobs: int | Farm
) -> tuple[int, int]:
    """``(covers, nodes)`` of the search over ``rows``, its subtrees on ``jobs`` workers (or a
    :class:`chaingeo.solvers.jobs.Farm`: a Dask cluster)."""
    parts = split_rows(problem, rows, engine)
    results = _map(problem, engine, as_farm(jobs), parts, collect=False)
    return sum(r[0] for r in results), sum(r[1] for r in results)


def collect_parallel(
    problem: CoverProblem, rows: I32, engine: Engine, jobs: int | Farm
) -> tuple[list[I32], int]:
    """Every cover of the search over ``rows`` (blocks in subtree order) and the nodes."""
    parts = split_rows(problem, rows, engine)
    results = _map(problem, engine, as_farm(jobs), parts, collect=True)
    blocks = [b for r in results for b in r[2]]
    return blocks, sum(r[1] for r in results)


def _search(
    work: tuple[CoverProblem, Engine], args: tuple[I32, bool]
) -> tuple[int, int, list[I32]]:
    problem, engine = work
    rows, collect = args
    search = CoverSearch(problem, rows, engine=engine)
    blocks = list(search.batches(4096)) if collect else []
    if not collect:
        search.count()
    return search.found, search.stats.nodes, blocks


def _map(
    problem: CoverProblem, engine: Engine, farm: Farm, parts: Sequence[I32], collect: bool
) -> list[tuple[int, int, list[I32]]]:
    """Each part searched (on the farm's workers), results in part order."""
    work = [(p, collect) for p in parts]
    return list(farm_map(_search, (problem, engine), work, farm))
