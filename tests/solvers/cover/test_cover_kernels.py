"""The exact-cover kernels agree: DLX, the first-cell bit-board and the MRV bit-board (one-word
and multi-word masks) list the same solutions, and the automatic rule picks as documented."""

from __future__ import annotations

from math import comb

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from chaingeo.core.geometry import Shape, box_cells
from chaingeo.core.piecesets import PENTOMINOES, SOMA
from chaingeo.solvers.cover.packings import (
    CoverLimitError,
    CoverSearch,
    PieceSpec,
    count_packings,
    cover_problem,
)
from chaingeo.solvers.cover.problem import CoverProblem
from chaingeo.solvers.cover.search import choose_kernel
from tests.support.cover_instances import instances, wide_instances

KERNELS = ("dlx", "bitboard-first", "bitboard-mrv")


def _rod(n: int) -> Shape:
    return Shape([(0, 0, z) for z in range(n)])


def _solution_set(problem: CoverProblem, engine: str, limit: int | None = None) -> set[bytes]:
    """Every solution as the bytes of its sorted row ids."""
    search = CoverSearch(problem, engine=engine, node_limit=limit)  # type: ignore[arg-type]
    out: set[bytes] = set()
    for block in search.batches(4096):
        for sol in block:
            key = np.sort(sol[sol >= 0]).astype(np.int32).tobytes()
            assert key not in out, engine  # each solution exactly once
            out.add(key)
    assert len(out) == search.found
    return out


@settings(max_examples=60, deadline=None)
@given(instances(), st.booleans())
def test_kernels_list_the_same_solutions(
    inst: tuple[list[PieceSpec], tuple[int, int, int], Shape | None], reflections: bool
) -> None:
    specs, dims, optional = inst
    problem = cover_problem(specs, dims, optional=optional, reflections=reflections)
    if not problem.types:
        return
    sets = {k: _solution_set(problem, k) for k in KERNELS}
    assert sets["dlx"] == sets["bitboard-first"] == sets["bitboard-mrv"]
    for k in KERNELS:  # and with symmetry reduction
        r = count_packings(problem, engine=k)  # type: ignore[arg-type]
        assert r.solutions == len(sets["dlx"]), k


@settings(max_examples=25, deadline=None)
@given(wide_instances())
def test_multiword_bitboard_matches_dlx(inst: tuple[list[PieceSpec], tuple[int, int, int]]) -> None:
    specs, dims = inst
    problem = cover_problem(specs, dims)
    assert problem.n_cells > 64
    try:
        expected = _solution_set(problem, "dlx", limit=50_000)
    except CoverLimitError:
        return  # too big for a quick check
    assert _solution_set(problem, "bitboard-mrv") == expected


def test_rods_across_the_word_boundary() -> None:
    # A line of 70 cells tiled by rods of 3 and 5 (any number): one tiling per composition.
    expected = sum(comb(a + b, a) for a in range(24) for b in range(15) if 3 * a + 5 * b == 70)
    specs = [PieceSpec(_rod(3), "r3", 0, 30), PieceSpec(_rod(5), "r5", 0, 20)]
    for engine in ("auto", "dlx", "bitboard", "bitboard-mrv"):
        r = count_packings(specs, (1, 1, 70), engine=engine, distinct=False)
        assert r.solutions == expected == 63862, engine


def test_optional_cells_beyond_64() -> None:
    # Two rows of 34 filled by rods of 4 and 5; two far corners may stay empty.
    opt = Shape([(0, 0, 0), (0, 1, 33)])
    specs = [PieceSpec(_rod(4), "r4", 0, 17), PieceSpec(_rod(5), "r5", 0, 13)]
    wide = cover_problem(specs, (1, 2, 34), optional=opt)
    assert wide.n_cells == 68
    sols = _solution_set(wide, "dlx")
    assert len(sols) > 100 and _solution_set(wide, "bitboard-mrv") == sols


@pytest.mark.parametrize("box", [(3, 3, 3), (6, 10, 1), (2, 5, 6), (4, 4, 5)])
def test_automatic_rule(box: tuple[int, int, int]) -> None:
    pieces = SOMA.pieces if box == (3, 3, 3) else PENTOMINOES.pieces
    problem = cover_problem(pieces, box)
    expected = {
        (3, 3, 3): "bitboard-mrv",  # thick
        (6, 10, 1): "bitboard-first",  # one layer
        (2, 5, 6): "bitboard-mrv",  # thick
        (4, 4, 5): "bitboard-mrv",  # over 64 cells
    }[box]
    assert choose_kernel(problem, "auto") == choose_kernel(problem, "bitboard") == expected
    assert choose_kernel(problem, "dlx") == "dlx"


@pytest.mark.parametrize("engine", KERNELS)
def test_random_order_is_a_permutation(engine: str) -> None:
    problem = cover_problem([PieceSpec(_rod(2), "d", 0, 40)], box_cells((2, 3, 4)))
    plain = _solution_set(problem, engine)
    rng = np.random.default_rng(7)
    search = CoverSearch(problem, engine=engine, rng=rng)  # type: ignore[arg-type]
    shuffled = [np.sort(s[s >= 0]).astype(np.int32).tobytes() for b in search.batches(7) for s in b]
    assert len(shuffled) == len(plain) and set(shuffled) == plain


def test_mrv_visits_fewer_nodes_than_first_cell_in_thick_boxes() -> None:
    problem = cover_problem(PENTOMINOES.pieces, (2, 5, 6))
    nodes = {}
    for k in ("bitboard-first", "bitboard-mrv"):
        search = CoverSearch(problem, engine=k, node_limit=300_000)
        for _ in search.batches(1):
            break  # nodes to the first packing
        nodes[k] = search.stats.nodes
    assert nodes["bitboard-mrv"] < nodes["bitboard-first"]
