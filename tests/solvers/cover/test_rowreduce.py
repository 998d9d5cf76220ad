"""Rows no cover can hold (chaingeo.solvers.cover.rowreduce): removing them changes no solution, on
puzzles we did not make (seeded random boxes cut into pieces, with holes and congruent pieces), and
on a 36-piece burr they are BurrTools' own figure (burrTxt -r: "removed 3688 rows")."""

from __future__ import annotations

import time

import numpy as np
import pytest

from chaingeo.core.formats.bt_level import level_puzzle
from chaingeo.core.level import load_level
from chaingeo.generator.bt_examples import EXAMPLES
from chaingeo.solvers.assembly.btassemble import bt_packing_spec, iter_classes
from chaingeo.solvers.cover.constrained import compile_packing
from chaingeo.solvers.cover.problem import CoverProblem
from chaingeo.solvers.cover.rowreduce import live_rows
from chaingeo.solvers.cover.search import CoverSearch
from tests.support.burrtxt import random_puzzle
from tests.support.paths import LEVELS

PUZZLES = LEVELS / "puzzle"


def _covers(problem: CoverProblem, rows: np.ndarray | None) -> list[tuple[int, ...]]:
    found: list[tuple[int, ...]] = []
    for block in CoverSearch(problem, rows).batches(4096):
        found.extend(tuple(sorted(int(r) for r in sol if r >= 0)) for sol in block)
    return sorted(found)


@pytest.mark.parametrize("index", range(30))
def test_no_cover_is_lost(index: int) -> None:
    rng = np.random.default_rng(np.random.SeedSequence([5, index]))
    problem = compile_packing(bt_packing_spec(random_puzzle(rng), 0)).problem
    live = live_rows(problem)
    everything = _covers(problem, None)
    assert _covers(problem, live) == everything
    used = {r for cover in everything for r in cover}
    assert used <= set(live.tolist())  # a row of some cover is never removed


#: Examples whose raw covers (every symmetric copy) take seconds to list twice.
_MANY_COVERS = {"colour_pentominoes", "solid_burrs", "deep_maze"}


@pytest.mark.parametrize(
    "name",
    [pytest.param(n, marks=pytest.mark.slow) if n in _MANY_COVERS else n for n in sorted(EXAMPLES)],
)
def test_feature_examples_keep_their_covers(name: str) -> None:
    problem = compile_packing(bt_packing_spec(EXAMPLES[name](), 0)).problem
    assert _covers(problem, live_rows(problem)) == _covers(problem, None)


def test_a_subset_of_rows_stays_a_subset() -> None:
    rng = np.random.default_rng(np.random.SeedSequence([5, 1000]))
    problem = compile_packing(bt_packing_spec(random_puzzle(rng), 0)).problem
    some = np.arange(0, problem.n_rows, 2, dtype=np.int32)
    assert set(live_rows(problem, some).tolist()) <= set(some.tolist())


def test_a_36_piece_burr_is_reduced_as_burrtools_does_and_assembles_at_once() -> None:
    puzzle = level_puzzle(load_level(PUZZLES / "puzzle-hard-08-burr36.json"))
    packing = compile_packing(bt_packing_spec(puzzle, 0))
    assert (packing.n_rows, len(live_rows(packing.problem))) == (4253, 4253 - 3688)
    start = time.monotonic()
    first = next(iter_classes(packing, mirrors="drop"))
    assert len(first) == 36 and time.monotonic() - start < 30
