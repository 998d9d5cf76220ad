"""The one-word MRV kernel (:mod:`chaingeo.solvers.cover.boxmrv`) equals exact cover by definition
(:func:`chaingeo.solvers.cover.reference.count_covers`) and xcover, when it is installed, on
random polycube sets in random boxes: raw counts, symmetry-reduced counts, and subtrees."""

from __future__ import annotations

import importlib.util

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from chaingeo.core.geometry import Shape
from chaingeo.solvers.cover.boxmrv import BoxArrays
from chaingeo.solvers.cover.packings import PieceSpec, count_packings, cover_problem
from chaingeo.solvers.cover.parallel import split_rows
from chaingeo.solvers.cover.problem import CoverProblem
from chaingeo.solvers.cover.reference import count_covers
from chaingeo.solvers.cover.search import CoverSearch
from tests.support.cover_instances import instances
from tests.support.equivalence import assert_same
from tests.support.strategies import polycubes

HAS_XCOVER = importlib.util.find_spec("xcover") is not None


@st.composite
def filled_boxes(draw: st.DrawFn) -> tuple[list[PieceSpec], tuple[int, int, int]]:
    """A box of up to 18 cells (the reference is plain Python) and pieces whose sizes add up to
    its volume (region pruning is on: a whole box, no optional cells), of one size or mixed."""
    a, b = draw(st.integers(1, 3)), draw(st.integers(2, 3))
    dims = (a, b, draw(st.integers(2, 18 // (a * b))))
    volume = dims[0] * dims[1] * dims[2]
    uniform = draw(st.integers(2, 5))
    mixed = draw(st.booleans())
    specs: list[PieceSpec] = []
    left = volume
    while left > 0:
        size = min(left, draw(st.integers(1, 5)) if mixed else uniform)
        shape = draw(polycubes(min_size=size, max_size=size))
        specs.append(PieceSpec(shape, f"p{len(specs)}"))
        left -= size
    return specs, dims


def _xcover_count(problem: CoverProblem) -> int | None:
    """xcover's count over the same rows, when it can state the problem (each type used exactly
    once, no optional cells); None otherwise."""
    if not HAS_XCOVER or problem.optional or any(t.lo != 1 or t.hi != 1 for t in problem.types):
        return None
    if problem.n_rows == 0:
        return 0  # xcover needs an option
    from xcover import covers

    options = [
        [f"piece{int(problem.row_type[r])}", *problem.row_cells(r).tolist()]
        for r in range(problem.n_rows)
    ]
    primary = [f"piece{t}" for t in range(len(problem.types))] + list(range(problem.n_cells))
    return sum(1 for _ in covers(options, primary=primary, secondary=[]))


def _check(problem: CoverProblem) -> None:
    expected = count_covers(problem)
    search = CoverSearch(problem, engine="bitboard-mrv")
    assert isinstance(search._arr, BoxArrays)
    assert_same(expected, search.count(), "raw count")
    assert_same(expected, count_packings(problem, symmetry=True).solutions, "reduced count")
    rows = np.arange(problem.n_rows, dtype=np.int32)
    parts = split_rows(problem, rows, "auto")
    assert_same(expected, sum(CoverSearch(problem, p).count() for p in parts), "subtrees")
    reference = _xcover_count(problem)
    if reference is not None:
        assert_same(reference, expected, "xcover")


@settings(max_examples=40, deadline=None, derandomize=True)
@given(filled_boxes())
def test_box_kernel_equals_the_definition_in_filled_boxes(
    inst: tuple[list[PieceSpec], tuple[int, int, int]],
) -> None:
    specs, dims = inst
    _check(cover_problem(specs, dims))


@settings(max_examples=40, deadline=None, derandomize=True)
@given(instances())
def test_box_kernel_equals_the_definition_with_ranges_and_optional_cells(
    inst: tuple[list[PieceSpec], tuple[int, int, int], Shape | None],
) -> None:
    specs, dims, optional = inst
    problem = cover_problem(specs, dims, optional=optional)
    if problem.types:
        _check(problem)
