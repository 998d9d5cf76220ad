"""The numpy row reduction of interpreted runs keeps exactly the kernel's rows (or declines):
on seeded random puzzles, with random starting row subsets, and on the shipped examples."""

from __future__ import annotations

import numpy as np
import pytest

from chaingeo.generator.bt_examples import EXAMPLES
from chaingeo.solvers.assembly.btassemble import bt_packing_spec
from chaingeo.solvers.cover.constrained import compile_packing
from chaingeo.solvers.cover.problem import CoverProblem
from chaingeo.solvers.cover.rowreduce import MAX_PASSES, _dead_rows, _dead_rows_dense, columns
from tests.support.burrtxt import random_puzzle


def _both(problem: CoverProblem, rows: np.ndarray | None, passes: int) -> tuple[bool, bool]:
    """(dense answered, dense == kernel when it did)."""
    row_ptr, cols, col_ptr, col_rows, required, alive = columns(problem, rows)
    kernel, dense = alive.copy(), alive.copy()
    _dead_rows(row_ptr, cols, col_ptr, col_rows, required, kernel, passes)
    answered = _dead_rows_dense(row_ptr, cols, required, dense, passes)
    if not answered:
        return False, bool(np.array_equal(dense, alive))  # declined: left untouched
    return True, bool(np.array_equal(dense, kernel))


@pytest.mark.parametrize("index", range(24))
def test_dense_is_the_kernel_on_random_puzzles(index: int) -> None:
    rng = np.random.default_rng(np.random.SeedSequence([20, index]))
    problem = compile_packing(bt_packing_spec(random_puzzle(rng), 0)).problem
    answered, same = _both(problem, None, MAX_PASSES)
    assert answered and same  # every one of these seeds is in the dense path's reach
    subset = np.flatnonzero(rng.random(problem.n_rows) < 0.7).astype(np.int32)
    for passes in (1, 2, MAX_PASSES):
        answered_sub, same_sub = _both(problem, subset, passes)
        assert same_sub, (passes, answered_sub)


@pytest.mark.parametrize("name", ["soma_problems", "ring_maze", "linked_rings", "solid_burrs"])
def test_dense_answers_on_the_examples(name: str) -> None:
    puzzle = EXAMPLES[name]()
    for index in range(len(puzzle.problems)):
        problem = compile_packing(bt_packing_spec(puzzle, index)).problem
        answered, same = _both(problem, None, MAX_PASSES)
        assert answered and same, (name, index)
