"""Peeling free pieces in the optimal search (solvers/motion/optimal_part.py): the same o_i as
the plain branch and bound, the A* search and the reference breadth-first search, on seeded
random puzzles and on states part-way through a disassembly; the deletion lemma it rests on."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import pytest

from chaingeo.core.geometry import Shape
from chaingeo.core.kinematics import Assembly, reference_optimal_disassembly, replay_disassembly
from chaingeo.core.level import Level, load_levels
from chaingeo.core.rules import PuzzleRules
from chaingeo.solvers.deadline import Deadline
from chaingeo.solvers.limits import SearchLimits
from chaingeo.solvers.motion.disassemble import _Solver, analyze_assembly
from chaingeo.solvers.motion.partsearch import PartSearch, PieceTable
from chaingeo.solvers.optimal.astar import astar_optimal
from tests.support.paths import ROOT
from tests.support.puzzle_strategies import random_partition
from tests.support.scenes import SCENE, random_walk

#: Seeded random puzzles: (box, pieces, seed).
PUZZLES = [((3, 3, 2), k, seed) for k in (3, 4, 5) for seed in range(6)] + [
    ((3, 3, 3), k, seed) for k in (4, 5) for seed in range(4)
]


def parts_of(state: Assembly) -> list[dict[str, Shape]]:
    """Each part of two or more pieces of ``state`` as an assembly of its own."""
    return [
        {n: state.shapes[n].translate(state.offsets[n]) for n in sorted(part)}
        for part in state.parts
        if len(part) > 1
    ]


def check_same(shapes: Mapping[str, Shape], max_group: int | None) -> int | None:
    """Peeled and plain searches agree exactly; the peeled plan replays at that length."""
    peeled = analyze_assembly(shapes, max_group=max_group, peel=True)
    plain = analyze_assembly(shapes, max_group=max_group, peel=False)
    assert peeled.optimal_steps == plain.optimal_steps
    if peeled.optimal_steps is not None:
        assert len(peeled.plan) == peeled.optimal_steps
        assert replay_disassembly(shapes, peeled.plan).is_separated()
        if max_group is not None:
            assert all(len(m.pieces) <= max_group for m in peeled.plan)
    return peeled.optimal_steps


@pytest.mark.parametrize(("dims", "k", "seed"), PUZZLES)
@pytest.mark.parametrize("max_group", [None, 1])
def test_peeled_matches_plain_on_random_puzzles(
    dims: tuple[int, int, int], k: int, seed: int, max_group: int | None
) -> None:
    check_same(random_partition(dims, k, seed), max_group)


@pytest.mark.parametrize("seed", range(8))
def test_peeled_matches_plain_part_way(seed: int) -> None:
    """States reached by random moves, where pieces are often already free."""
    shapes = random_partition((3, 3, 2), 5, seed)
    state = random_walk(shapes, seed, 6)
    for part in parts_of(state):
        check_same(part, None)


@pytest.mark.parametrize("seed", range(6))
def test_peeled_matches_reference_and_astar(seed: int) -> None:
    """The reference's plain breadth-first search over whole states, and A*."""
    shapes = random_partition((3, 2, 2), 4, seed)
    ref = reference_optimal_disassembly(shapes)
    got = check_same(shapes, None)
    assert got == (None if ref is None else len(ref))
    assert astar_optimal(shapes).optimal_steps == got
    assert check_same(SCENE, None) == astar_optimal(SCENE).optimal_steps


@pytest.mark.parametrize("seed", range(6))
def test_deleting_a_piece_saves_a_move(seed: int) -> None:
    """The lemma: o_i without any one piece is at most o_i - 1."""
    shapes = random_partition((3, 3, 2), 4, seed)
    whole = analyze_assembly(shapes, peel=False).optimal_steps
    if whole is None:
        return
    for name in shapes:
        rest = {n: s for n, s in shapes.items() if n != name}
        fewer = analyze_assembly(rest, peel=False).optimal_steps
        assert fewer is not None and fewer <= whole - 1


def layered_states(part: Mapping[str, Shape], peel: bool, depth: int) -> tuple[int, int]:
    """States stored and single-piece removals seen by the part search to ``depth``."""
    table = PieceTable(part)
    n = len(table.names)
    s = PartSearch(
        table,
        tuple(range(n)),
        np.zeros((n, 3), dtype=np.int64),
        max_group=None,
        limits=SearchLimits(),
        deadline=Deadline(None),
        peel=peel,
    )
    singles = 0
    while not s.exhausted and s.depth <= depth:
        singles += sum(r.mask.bit_count() in (1, n - 1) for r in s.expand_layers(depth))
    return s.n_states, singles


@pytest.mark.parametrize("seed", range(4))
def test_peeling_stops_at_free_states(seed: int) -> None:
    """With ``peel`` a state where one piece comes free alone has no children: the search
    stores fewer states, and where the start has a free piece, it alone."""
    part = random_partition((3, 3, 2), 5, seed)
    plain, singles = layered_states(part, False, 2)
    peeled, _ = layered_states(part, True, 2)
    assert peeled < plain if singles else peeled == plain
    free = max(parts_of(random_walk(part, seed, 2)), key=len)
    states, singles = layered_states(free, True, 0)
    assert states == 1 if singles else states >= 1


def test_budget_below_o_i_finds_nothing() -> None:
    """The lower bound: asked for a plan shorter than o_i, the search proves there is none."""
    shapes = random_partition((3, 3, 2), 5, 1)
    steps = analyze_assembly(shapes).optimal_steps
    assert steps is not None
    solver = _Solver(shapes, None, SearchLimits())
    n = len(shapes)
    lo, plan = solver.optimal(tuple(range(n)), np.zeros((n, 3), dtype=np.int64), steps)
    assert plan is None and lo >= steps


def shipped_puzzles() -> list[Level]:
    """The shipped puzzle levels the plain search finishes quickly (no turns, at most 15
    pieces)."""
    levels = load_levels(ROOT / "levels" / "puzzle")
    return [
        lv
        for lv in levels
        if len(lv.shapes) <= 15 and not (isinstance(lv.rules, PuzzleRules) and lv.rules.turns)
    ]


@pytest.mark.parametrize("level", shipped_puzzles(), ids=lambda lv: lv.id)
def test_peeled_matches_plain_on_shipped_levels(level: Level) -> None:
    max_group = level.rules.max_group if isinstance(level.rules, PuzzleRules) else None
    assert check_same(level.shapes, max_group) is not None


def scattered(seed: int) -> dict[str, Shape]:
    """Four pieces (not connected) sharing out a 3x3x2 box at random."""
    rng = np.random.default_rng(seed)
    cells = [(x, y, z) for x in range(3) for y in range(3) for z in range(2)]
    owner = rng.integers(0, 4, len(cells)).tolist()
    return {
        f"p{k}": Shape([c for c, o in zip(cells, owner, strict=True) if o == k]) for k in range(4)
    }


@pytest.mark.parametrize("seed", [20, 100, 102, 107, 198, 247])
def test_group_removals_at_the_start_are_tried(seed: int) -> None:
    """Starts where only groups of two come free: without a seed plan to lean on (a large
    budget), the peeled search still tries them and agrees with the plain one."""
    shapes = scattered(seed)
    n = len(shapes)
    found = []
    for peel in (True, False):
        solver = _Solver(shapes, None, SearchLimits(seconds=60))
        solver.peel = peel
        found.append(solver.optimal(tuple(range(n)), np.zeros((n, 3), dtype=np.int64), 50))
    assert found[0][0] == found[1][0] == n - 1
    assert found[0][1] is not None and replay_disassembly(shapes, found[0][1]).is_separated()
