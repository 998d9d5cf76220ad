"""Box carving, repair and the linear-assembly check behind the stacking generator."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from chaingeo.core.geometry import Shape, box_cells
from chaingeo.core.kinematics import DIRECTIONS, Assembly
from chaingeo.generator.assembly import assembly_order, has_isolated_piece, removal_sequence
from chaingeo.generator.partition import (
    PieceRules,
    box_grid,
    grow,
    is_planar,
    partition_cost,
    piece_count_range,
    pieces_of,
    random_sizes,
    repair,
)

boxes = st.tuples(st.integers(1, 4), st.integers(2, 4), st.integers(2, 4)).filter(
    lambda b: b[0] * b[1] * b[2] >= 6
)


def _rng(seed: int) -> np.random.Generator:
    return np.random.default_rng(np.random.SeedSequence([seed, 0]))


def test_box_grid_indexes_cells_and_face_neighbours() -> None:
    g = box_grid((2, 3, 4))
    assert g.volume == 24
    assert set(g.coords) == box_cells((2, 3, 4)).cell_set
    for i, c in enumerate(g.coords):
        assert g.index(c) == i
        for j in g.neighbours[i]:
            assert i in g.neighbours[j]
            assert sum(abs(p - q) for p, q in zip(c, g.coords[j], strict=True)) == 1
    assert len(g.neighbours[g.index((1, 1, 1))]) == 5


def test_sizes_and_counts() -> None:
    rng = _rng(1)
    for _ in range(20):
        sizes = random_sizes(27, 6, 4, 5, rng)
        assert sum(sizes) == 27 and all(4 <= s <= 5 for s in sizes)
    with pytest.raises(ValueError, match="cannot fill"):
        random_sizes(27, 5, 4, 5, rng)
    assert piece_count_range(64, 4, 5, 13) == range(13, 14)
    assert piece_count_range(8, 4, 5, 2) == range(2, 3)
    assert not piece_count_range(27, 4, 5, 5)


@given(boxes, st.integers(0, 10_000), st.booleans())
def test_growth_partitions_the_box_into_connected_pieces(
    box: tuple[int, int, int], seed: int, planar: bool
) -> None:
    g = box_grid(box)
    rng = _rng(seed)
    k = int(rng.integers(2, max(3, g.volume // 3)))
    sizes = random_sizes(g.volume, k, 1, g.volume, rng)
    labels = grow(g, sizes, rng, planar=planar)
    assert len(labels) == g.volume and min(labels) == 0 and max(labels) == k - 1
    for cells in pieces_of(labels):
        assert g.shape(cells).is_connected()


@given(boxes, st.integers(0, 10_000), st.booleans(), st.booleans())
def test_repair_keeps_a_partition_and_its_cost_is_exact(
    box: tuple[int, int, int], seed: int, planar: bool, distinct: bool
) -> None:
    g = box_grid(box)
    rng = _rng(seed)
    rules = PieceRules(3, 5, planar=planar, distinct=distinct)
    counts = piece_count_range(g.volume, 3, 5, 20)
    if not counts:
        return
    sizes = random_sizes(g.volume, counts[0], 3, 5, rng)
    labels = grow(g, sizes, rng, planar=planar)
    before = partition_cost(g, labels, rules)
    fixed, cost, moves = repair(g, labels, rules, rng, max_moves=30)
    assert cost == partition_cost(g, fixed, rules) <= before
    assert moves <= 30
    shapes = [g.shape(c) for c in pieces_of(fixed)]
    assert all(s.is_connected() for s in shapes)
    assert sum(len(s) for s in shapes) == g.volume
    if cost == 0:
        assert all(3 <= len(s) <= 5 and not s.has_filled_rectangle(2, 3) for s in shapes)
        assert not planar or all(is_planar(s) for s in shapes)
        assert not distinct or len({s.canonical() for s in shapes}) == len(shapes)


def test_repair_fixes_a_small_piece_by_moving_voxels() -> None:
    g = box_grid((1, 2, 4))  # a 2x4 slab: one piece of 7 cells and a single cell
    labels = [0] * 8
    labels[g.index((0, 1, 3))] = 1
    rules = PieceRules(3, 5)
    fixed, cost, moves = repair(g, labels, rules, _rng(0), max_moves=10)
    assert cost == 0 and moves == 2
    assert sorted(len(c) for c in pieces_of(fixed)) == [3, 5]


def test_repair_separates_equal_shapes_when_asked() -> None:
    g = box_grid((2, 2, 3))  # three 2x2 plates: equal shapes
    labels = [g.coords[i][2] for i in range(g.volume)]
    rules = PieceRules(3, 5, distinct=True)
    assert partition_cost(g, labels, rules) == 2
    fixed, cost, _ = repair(g, labels, rules, _rng(3), max_moves=20)
    assert cost == 0
    assert len({g.shape(c).canonical() for c in pieces_of(fixed)}) == 3


def test_is_planar() -> None:
    assert is_planar(Shape([(0, 0, 0), (1, 0, 0), (1, 1, 0)]))
    assert not is_planar(Shape([(0, 0, 0), (1, 0, 0), (1, 0, 1), (1, 1, 1)]))


# -- linear assembly --------------------------------------------------------------------------


def _slides_out(placed: dict[str, Shape], name: str) -> str | None:
    """Oracle: the reference kinematics says the piece can leave to infinity along an axis."""
    state = Assembly.assembled(placed)
    return next((d for d in DIRECTIONS if state.free_distance([name], d) is None), None)


def _linear_by_search(placed: dict[str, Shape]) -> bool:
    """Exhaustive: some order of single-piece removals empties the box."""
    if len(placed) <= 1:
        return True
    return any(
        _slides_out(placed, n) is not None
        and _linear_by_search({k: v for k, v in placed.items() if k != n})
        for n in sorted(placed)
    )


def _all_two_colourings(box: tuple[int, int, int]) -> list[list[Shape]]:
    g = box_grid(box)
    out = []
    for bits in itertools.product((0, 1), repeat=g.volume - 1):
        labels = [0, *bits]
        pieces = [g.shape(c) for c in pieces_of(labels)] if 1 in bits else []
        if len(pieces) == 2 and all(p.is_connected() for p in pieces):
            out.append(pieces)
    return out


def test_greedy_removal_agrees_with_exhaustive_search_on_every_2x2x2_split() -> None:
    splits = _all_two_colourings((2, 2, 2))
    stuck = 0
    for pieces in splits:
        seq = removal_sequence(pieces, (2, 2, 2))
        placed = {f"p{i}": s for i, s in enumerate(pieces)}
        assert (seq is not None) == _linear_by_search(placed)
        stuck += seq is None
    assert stuck == 0  # two pieces in a 2x2x2 box always slide apart


@given(st.integers(0, 10_000), st.sampled_from([(2, 3, 3), (3, 3, 3), (2, 2, 4)]))
def test_greedy_removal_agrees_with_exhaustive_search(seed: int, box: tuple[int, int, int]) -> None:
    g = box_grid(box)
    rng = _rng(seed)
    k = int(rng.integers(3, 6))
    labels = grow(g, random_sizes(g.volume, k, 1, g.volume, rng), rng, planar=False)
    pieces = [g.shape(c) for c in pieces_of(labels)]
    placed = {f"p{i}": s for i, s in enumerate(pieces)}
    seq = removal_sequence(pieces, box)
    assert (seq is not None) == _linear_by_search(placed)
    if seq is not None:  # replay the sequence with the oracle
        left = dict(placed)
        for i, d in seq:
            assert Assembly.assembled(left).free_distance([f"p{i}"], d) is None
            del left[f"p{i}"]
        order = assembly_order(pieces, box)
        assert order is not None and [i for i, _ in order] == [i for i, _ in reversed(seq)]


def test_an_interlocked_packing_has_no_linear_assembly() -> None:
    # Found by search: in this 2x3x3 packing no order of single-piece slides empties the box.
    pieces = [
        Shape([(0, 2, 0), (1, 2, 0)]),
        Shape([(0, 1, 0), (0, 1, 1), (0, 2, 1), (1, 0, 2), (1, 1, 1), (1, 1, 2), (1, 2, 1)]),
        Shape(
            [
                (0, 0, 0),
                (0, 0, 1),
                (0, 0, 2),
                (0, 1, 2),
                (0, 2, 2),
                (1, 0, 0),
                (1, 0, 1),
                (1, 1, 0),
                (1, 2, 2),
            ]
        ),
    ]
    assert sorted(c for s in pieces for c in s) == sorted(box_cells((2, 3, 3)).cells)
    assert removal_sequence(pieces, (2, 3, 3)) is None
    assert assembly_order(pieces, (2, 3, 3)) is None
    assert not _linear_by_search({f"p{i}": s for i, s in enumerate(pieces)})


def test_isolated_piece() -> None:
    a = Shape([(0, 0, 0), (1, 0, 0)])
    b = Shape([(0, 1, 0), (1, 1, 0)])
    far = Shape([(5, 5, 5)])
    assert not has_isolated_piece([a, b])
    assert has_isolated_piece([a, b, far])
