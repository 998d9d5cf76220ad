"""The class bound (solvers/optimal/classbound.py): at most the exact optimum with multi-piece
moves, on random scenes with random blocks and on generated burrs; exact on the suite's 12-piece
tower; its figures on the suite's 36-piece towers played with multi-piece moves."""

from __future__ import annotations

import json

import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from chaingeo.core.geometry import Shape
from chaingeo.core.kinematics import SearchLimitError, replay_disassembly
from chaingeo.core.level import Level, load_level
from chaingeo.generator.config import PuzzleConfig
from chaingeo.generator.puzzle import make
from chaingeo.solvers.motion.disassemble import analyze_assembly, translations
from chaingeo.solvers.optimal.blockbound import end_first_plan
from chaingeo.solvers.optimal.classbound import (
    MAX_BUDGET,
    ClassPacking,
    ClassVector,
    band_blocks,
    below,
    class_lower_bound,
    join,
    total,
)
from tests.support.paths import LEVELS
from tests.support.puzzle_strategies import random_blocks, small_scenes

SUITE = LEVELS / "puzzle"


def test_vector_algebra() -> None:
    a = (((0, 1), 2),)
    b = (((0, 1), 1), ((2, 3), 1))
    assert join(a, b) == (((0, 1), 2), ((2, 3), 1))
    assert below(a, join(a, b)) and below(b, join(a, b)) and not below(a, b)
    pk = ClassPacking()
    pa, pb = pk.encode(a), pk.encode(b)
    assert pk.decode(pk.join(pa, pb)) == join(a, b) and pk.total(pa) == 2
    assert pk.minimal([pk.join(pa, pb), pa, pb, 0]) == [0]
    assert sorted(pk.minimal([pk.join(pa, pb), pa, pb])) == sorted([pa, pb])  # the join is above
    assert pk.smallest_join([[pa, pb], [pb]], 10) == pb  # b alone serves both blocks
    assert pk.smallest_join([[pa], [pb]], 2) is None  # the join has total 3
    with pytest.raises(ValueError, match="count per class"):
        pk.encode((((0, 1), MAX_BUDGET + 1),))


_vectors = st.lists(
    st.tuples(st.tuples(st.integers(0, 2), st.integers(1, 4)), st.integers(1, 40)),
    max_size=3,
    unique_by=lambda cv: cv[0],
).map(lambda v: tuple(sorted(v)))


@settings(max_examples=200, deadline=None)
@given(_vectors, _vectors)
def test_packed_vectors_agree_with_the_counts(a: ClassVector, b: ClassVector) -> None:
    """The packed fields compare, join and add up as the counts per class do (no borrow or
    carry crosses a field, whatever order the classes were met in)."""
    pk = ClassPacking()
    pb, pa = pk.encode(b), pk.encode(a)
    assert pk.decode(pa) == a and pk.decode(pb) == b
    assert pk.below(pa, pb) == below(a, b) and pk.below(pb, pa) == below(b, a)
    assert pk.decode(pk.join(pa, pb)) == join(a, b)
    assert pk.total(pa) == total(a)


@settings(max_examples=40, deadline=None)
@given(small_scenes(max_pieces=5), st.data(), st.sampled_from([None, 2]))
def test_at_most_the_exact_optimum(
    shapes: dict[str, Shape], data: st.DataObject, max_group: int | None
) -> None:
    names = sorted(shapes)
    blocks = random_blocks(names, data)
    exact = analyze_assembly(shapes, max_group=max_group).optimal_steps
    assume(exact is not None)  # then every block comes apart alone too
    assert exact is not None
    for split in (blocks, [names]):
        found = class_lower_bound(shapes, split, max_group=max_group)
        assert found.complete
        assert len(names) - 1 <= found.bound <= exact
        assert found.bound == found.removals + found.finite
        assert all(any(below(v, found.classes) for v in vs) for vs in found.block_vectors)


def test_generated_burrs_any_blocks() -> None:
    config = PuzzleConfig(shape="burr6", hill_steps=0)
    burrs = [item.shapes for i in range(3) if isinstance(item := make(config, 5, i), Level)]
    assert len(burrs) >= 2
    for shapes in burrs:
        names = sorted(shapes)
        exact = analyze_assembly(shapes, max_group=None).optimal_steps
        assert exact is not None
        for blocks in ([names[:3], names[3:]], [names[::2], names[1::2]], [names]):
            assert 5 <= class_lower_bound(shapes, blocks).bound <= exact


def test_exact_on_the_twelve_piece_tower() -> None:
    """puzzle-mid-04 (two burr units, multi-piece moves): the bound meets o_i = 13, where the
    removals alone give 11 and the units' classes y1 and z1 are shared."""
    level = load_level(SUITE / "puzzle-mid-04-burr12.json")
    found = class_lower_bound(level.shapes, band_blocks(level.shapes, 6))
    assert found.bound == level.optimal_steps == 13
    assert found.classes == (((1, 1), 1), ((2, 1), 1))


TOWERS = [("puzzle-hard-08-burr36", 41, 48), ("puzzle-hard-09-burr36", 38, 42)]


@pytest.mark.parametrize(("name", "bound", "plan"), TOWERS)
def test_thirty_six_piece_towers_with_multi_piece_moves(name: str, bound: int, plan: int) -> None:
    """The suite's towers (single-piece moves in the file) with moves of any size: 35 removals
    plus the most any class is needed over the six units. A* with pair databases proved 36."""
    path = SUITE / f"{name}.json"
    level = load_level(path)
    blocks = json.loads(path.read_text())["stats"]["blocks"]
    assert sorted(map(sorted, blocks)) == sorted(band_blocks(level.shapes, 6))
    found = class_lower_bound(level.shapes, blocks)
    assert found.complete and found.removals == 35 and found.bound == bound
    assert analyze_assembly(level.shapes, max_group=None, optimal=False).moves == plan >= bound


def test_tower_taken_apart_unit_by_unit_is_within_three_of_the_bound() -> None:
    """puzzle-hard-09 with multi-piece moves: the units leave the stack one by one, each by its
    own optimal plan (5 + 36 = 41 moves, replayed), so 38 <= o_i <= 41 (the class search
    finds 38: tests/solvers/optimal/test_classsearch.py)."""
    shapes = dict(load_level(SUITE / "puzzle-hard-09-burr36.json").shapes)
    blocks = band_blocks(shapes, 6)
    own = [
        translations(analyze_assembly({n: shapes[n] for n in b}, max_group=None).plan)
        for b in blocks
    ]
    plan = end_first_plan(shapes, blocks, own)
    assert plan is not None and len(plan) == 41
    assert replay_disassembly(shapes, plan).is_separated()


def test_errors() -> None:
    ring = [(x, y, z) for x in range(3) for y in range(3) for z in (0, 1) if (x, y) != (1, 1)]
    post = [(1, 1, 0), (1, 1, 1), (1, 1, 2), (1, 1, -1), (1, 2, 2), (1, 2, -1)]
    locked = {"post": Shape(post), "ring": Shape(ring)}
    with pytest.raises(ValueError, match="cannot be taken apart"):
        class_lower_bound(locked, [["post", "ring"]], max_budget=2)
    with pytest.raises(ValueError, match="split the pieces"):
        class_lower_bound(locked, [["post"]])
    level = load_level(SUITE / "puzzle-mid-04-burr12.json")
    with pytest.raises(SearchLimitError, match="class bound state cap"):
        class_lower_bound(level.shapes, band_blocks(level.shapes, 6), max_states=3)
    capped = class_lower_bound(level.shapes, band_blocks(level.shapes, 6), max_budget=1)
    assert not capped.complete and capped.bound == 11 + 2  # M > 1 is still proven
