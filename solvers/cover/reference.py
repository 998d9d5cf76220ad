"""Exact cover by definition, in plain Python: the reference the bit-board kernels must equal.

A cover is a set of rows that covers every mandatory cell exactly once and no optional cell
twice, with each piece type used between its ``lo`` and ``hi`` times. Rows are placed only to
fill an empty mandatory cell (the lowest), so a row lying wholly on optional cells is never
placed, as in every kernel. Slow and obviously right: never call it on a hot path.
"""

from __future__ import annotations

from chaingeo.core.arrays import I32
from chaingeo.solvers.cover.problem import CoverProblem


def count_covers(problem: CoverProblem, rows: I32 | None = None) -> int:
    """The number of covers of ``problem`` by ``rows`` (all of them by default)."""
    chosen = range(problem.n_rows) if rows is None else [int(r) for r in rows]
    cells = {r: frozenset(int(c) for c in problem.row_cells(r)) for r in chosen}
    through: dict[int, list[int]] = {c: [] for c in range(problem.n_cells)}
    for r, cs in cells.items():
        for c in cs:
            through[c].append(r)
    mandatory = [c for c in range(problem.n_cells) if c not in problem.optional]
    types = problem.types
    used = [0] * len(types)

    def count(filled: frozenset[int]) -> int:
        empty = [c for c in mandatory if c not in filled]
        if not empty:
            return int(all(used[t] >= ty.lo for t, ty in enumerate(types)))
        total = 0
        for r in through[empty[0]]:
            t = int(problem.row_type[r])
            if used[t] < types[t].hi and not cells[r] & filled:
                used[t] += 1
                total += count(filled | cells[r])
                used[t] -= 1
        return total

    return count(frozenset())
