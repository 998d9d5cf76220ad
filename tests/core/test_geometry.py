from __future__ import annotations

import itertools

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from chaingeo.core.geometry import (
    QUARTER_TURNS,
    ROTATIONS,
    SYMMETRIES,
    Shape,
    box_cells,
    box_symmetries,
    components,
    puzzle_signature,
    quarter_turn_distance,
    rotation_index,
)
from chaingeo.core.piecesets import BEDLAM, BEDLAM_SOLUTION, PENTOMINOES, SOMA
from tests.support.strategies import offsets, polycubes, rotations


def test_rotations_form_a_group_of_24() -> None:
    keys = {r.tobytes() for r in ROTATIONS}
    assert len(keys) == 24
    for a, b in itertools.product(ROTATIONS, repeat=2):
        assert (a @ b).tobytes() in keys  # closed
    for r in ROTATIONS:
        assert round(np.linalg.det(r)) == 1
        assert (r.T).tobytes() in keys  # inverses
    assert np.array_equal(ROTATIONS[0], np.eye(3, dtype=np.int64))


def test_symmetries_are_the_48_signed_permutations() -> None:
    keys = {m.tobytes() for m in SYMMETRIES}
    assert len(keys) == 48
    expected = set()
    for perm in itertools.permutations(range(3)):
        for signs in itertools.product((1, -1), repeat=3):
            m = np.zeros((3, 3), dtype=np.int64)
            for i, j in enumerate(perm):
                m[i, j] = signs[i]
            expected.add(m.tobytes())
    assert keys == expected


def test_quarter_turn_distance_table() -> None:
    ident = ROTATIONS[0]
    depths = sorted(quarter_turn_distance(ident, r) for r in ROTATIONS)
    # 1 identity, 6 quarter turns, 3 face half turns + 8 vertex turns at depth 2,
    # 6 edge half turns need three quarter turns.
    assert depths == [0] + [1] * 6 + [2] * 11 + [3] * 6
    qx = QUARTER_TURNS["x"]
    assert quarter_turn_distance(ident, qx) == 1
    assert quarter_turn_distance(ident, qx @ qx) == 2


@given(rotations, rotations, rotations)
def test_quarter_turn_distance_is_a_metric(a: np.ndarray, b: np.ndarray, c: np.ndarray) -> None:
    d = quarter_turn_distance
    assert d(a, b) == d(b, a)
    assert (d(a, b) == 0) == (rotation_index(a) == rotation_index(b))
    assert d(a, c) <= d(a, b) + d(b, c)


@given(polycubes(), rotations, offsets)
def test_canonical_form_invariant_under_rotation_and_translation(
    s: Shape, r: np.ndarray, t: tuple[int, int, int]
) -> None:
    moved = s.rotate(r).translate(t)
    assert moved.canonical() == s.canonical()
    assert len(moved) == len(s)
    assert moved.is_connected()


@given(polycubes())
def test_canonical_is_min_normalised_orientation(s: Shape) -> None:
    forms = [s.rotate(r).normalized().cells for r in ROTATIONS]
    assert s.canonical().cells == min(forms)
    assert len(s.orientations()) == len(set(forms))
    assert 24 % len(s.orientations()) == 0


@given(polycubes(min_size=4))
def test_mirror_image_has_same_form_iff_achiral(s: Shape) -> None:
    mirror = s.mirrored()
    achiral = any(s.rotate(m).normalized() == s.normalized() for m in SYMMETRIES[24:])
    assert (mirror.canonical() == s.canonical()) == achiral


def test_chiral_soma_pieces_differ() -> None:
    a, b = SOMA.pieces["A"], SOMA.pieces["B"]
    assert a.canonical() != b.canonical()
    assert a.mirrored().canonical() == b.canonical()
    assert a.is_chiral() and not SOMA.pieces["T"].is_chiral()


@given(st.lists(polycubes(), min_size=1, max_size=5), st.randoms(use_true_random=False), rotations)
def test_signature_ignores_order_and_pose(shapes: list[Shape], rnd: object, r: np.ndarray) -> None:
    shuffled = [s.rotate(r).translate((3, -1, 2)) for s in shapes]
    rnd.shuffle(shuffled)  # type: ignore[attr-defined]
    assert puzzle_signature(shuffled) == puzzle_signature(shapes)


def test_signature_tells_sets_apart() -> None:
    a = list(SOMA.pieces.values())
    b = [*a[:-1], SOMA.pieces["A"]]
    assert puzzle_signature(a) != puzzle_signature(b)


def test_shape_basics() -> None:
    s = Shape([(2, 1, 0), (1, 1, 0), (1, 1, 0), (1, 2, 0)])
    assert s.cells == ((1, 1, 0), (1, 2, 0), (2, 1, 0))
    assert s.extent == (2, 2, 1)
    assert s.normalized().cells == ((0, 0, 0), (0, 1, 0), (1, 0, 0))
    assert s.translate((1, 0, 0)) != s
    assert not s.voxels.flags.writeable
    assert s.contact(Shape([(3, 1, 0)])) == 1
    assert s.contact(Shape([(5, 5, 5)])) == 0
    assert s.overlaps(Shape([(1, 2, 0)]))
    assert not Shape([(0, 0, 0), (2, 0, 0)]).is_connected()
    assert components([(0, 0, 0), (2, 0, 0), (1, 0, 0), (5, 5, 5)]) == [
        [(0, 0, 0), (1, 0, 0), (2, 0, 0)],
        [(5, 5, 5)],
    ]


def test_structural_predicates() -> None:
    slab = Shape([(x, y, 0) for x in range(3) for y in range(2)])
    assert slab.has_filled_rectangle() and slab.is_cuboid()
    upright = slab.rotate(QUARTER_TURNS["x"])
    assert upright.has_filled_rectangle()
    assert not PENTOMINOES.pieces["P"].has_filled_rectangle()  # 2x2 plus one: no 2x3
    l_shape = Shape([(0, 0, 0), (1, 0, 0), (2, 0, 0), (0, 1, 0), (1, 1, 0), (0, 0, 1)])
    assert not l_shape.has_filled_rectangle()
    assert not l_shape.is_cuboid()
    assert box_cells((2, 3, 4)).is_cuboid() and len(box_cells((2, 3, 4))) == 24
    assert slab.size_within(6, 6) and not slab.size_within(1, 5)


def test_box_symmetries() -> None:
    assert len(box_symmetries((3, 3, 3))) == 48
    assert len(box_symmetries((2, 5, 6))) == 8
    assert len(box_symmetries((2, 2, 3))) == 16
    box = box_cells((2, 3, 5))
    for m, t in box_symmetries((2, 3, 5)):
        assert box.rotate(m).translate(t) == box


def test_piece_sets_match_their_boxes() -> None:
    assert SOMA.cells == 27 and len(SOMA.pieces) == 7
    assert len(PENTOMINOES.pieces) == 12 and PENTOMINOES.cells == 60
    assert len({p.canonical() for p in PENTOMINOES.pieces.values()}) == 12
    assert len(BEDLAM.pieces) == 13 and BEDLAM.cells == 64
    placed = set().union(*(s.cell_set for s in BEDLAM_SOLUTION.values()))
    assert placed == box_cells((4, 4, 4)).cell_set
    for s in [*SOMA.pieces.values(), *PENTOMINOES.pieces.values(), *BEDLAM.pieces.values()]:
        assert s.is_connected() and s == s.normalized()


@given(st.sets(st.tuples(*[st.integers(0, 3)] * 3), max_size=20))
def test_is_connected_is_one_component(cells: set[tuple[int, int, int]]) -> None:
    """The flood fill answers as the component listing does, on any voxel set."""
    from chaingeo.core.geometry import components

    assert Shape(list(cells)).is_connected() == (len(components(cells)) == 1)
