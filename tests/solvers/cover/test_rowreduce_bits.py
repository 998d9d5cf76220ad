"""The bit-set row reduction (``rowreduce._dead_rows``) against the count-and-restore test it
replaced (dancing links' column counts, one trial placement a row, rows in order), transcribed
here: the same rows killed on seeded random puzzles, on row subsets and on the feature
examples, including problems where some required column ends with no row (where the order of
the tests decides which rows stay)."""

from __future__ import annotations

import numpy as np
import pytest

from chaingeo.generator.bt_examples import EXAMPLES
from chaingeo.solvers.assembly.btassemble import bt_packing_spec
from chaingeo.solvers.cover.constrained import compile_packing
from chaingeo.solvers.cover.problem import CoverProblem
from chaingeo.solvers.cover.rowreduce import MAX_PASSES, _dead_rows, columns
from tests.support.burrtxt import random_puzzle


def _count_and_restore(arrays: tuple[np.ndarray, ...], max_passes: int) -> np.ndarray:
    """The alive rows after the former test, one row at a time in order."""
    row_ptr, cols, col_ptr, col_rows, required, alive = (a.copy() for a in arrays)
    n_cols = len(required)
    owner = np.repeat(np.arange(len(row_ptr) - 1), np.diff(row_ptr))
    count = np.bincount(cols[alive[owner]], minlength=n_cols)
    for _ in range(max_passes):
        changed = False
        for r in range(len(row_ptr) - 1):
            if not alive[r]:
                continue
            mine = cols[row_ptr[r] : row_ptr[r + 1]]
            near = np.concatenate([col_rows[col_ptr[c] : col_ptr[c + 1]] for c in mine])
            gone = np.zeros(len(row_ptr) - 1, dtype=bool)
            gone[near] = True
            gone &= alive
            lost = np.bincount(cols[gone[owner]], minlength=n_cols)
            hit = (lost > 0) & (count - lost == 0) & required
            hit[mine] = False
            if hit.any():
                alive[r] = False
                count[mine] -= 1
                changed = True
        if not changed:
            break
    return alive


def _same(problem: CoverProblem, rows: np.ndarray | None = None, passes: int = MAX_PASSES) -> int:
    arrays = columns(problem, rows)
    want = _count_and_restore(arrays, passes)
    row_ptr, cols, col_ptr, col_rows, required, alive = columns(problem, rows)
    killed = _dead_rows(row_ptr, cols, col_ptr, col_rows, required, alive, passes)
    assert np.array_equal(alive, want)
    assert killed == int(arrays[-1].sum() - want.sum())
    return killed


@pytest.mark.parametrize("index", range(25))
def test_bits_kill_the_rows_counts_killed(index: int) -> None:
    rng = np.random.default_rng(np.random.SeedSequence([2026_11_27, 20, index]))
    problem = compile_packing(bt_packing_spec(random_puzzle(rng), 0)).problem
    _same(problem)
    some = np.flatnonzero(rng.random(problem.n_rows) < 0.5).astype(np.int32)
    _same(problem, some)  # rows missing: required columns may end with none
    _same(problem, None, passes=1)


def test_the_examples_lose_the_same_rows() -> None:
    killed = 0
    for name in sorted(EXAMPLES):
        problem = compile_packing(bt_packing_spec(EXAMPLES[name](), 0)).problem
        if problem.n_rows <= 2500:
            killed += _same(problem)
    assert killed > 0
