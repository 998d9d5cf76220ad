"""A* with pattern databases (solvers/optimal/astar.py): optimal against the branch-and-bound
search, admissible and consistent heuristic, plans the reference kinematics replays, caps."""

from __future__ import annotations

from collections.abc import Mapping

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from chaingeo.core.geometry import Shape
from chaingeo.core.kinematics import (
    Assembly,
    SearchLimitError,
    legal_moves,
    reference_optimal_disassembly,
    replay_disassembly,
)
from chaingeo.solvers.motion.disassemble import analyze_assembly
from chaingeo.solvers.optimal.astar import AStarLimits, Heuristic, astar_optimal
from tests.support.puzzle_strategies import random_partition, small_scenes
from tests.support.scenes import SCENE, random_walk
from tests.support.shared_files import BT, needs_files


def exact_distance(state: Assembly, max_group: int | None) -> int | None:
    """Fewest moves from ``state`` to all apart: the sum over its parts of o_i of the part
    (its pieces translated to their offsets), by the branch-and-bound search."""
    total = 0
    for part in state.parts:
        if len(part) < 2:
            continue
        shapes = {n: state.shapes[n].translate(state.offsets[n]) for n in sorted(part)}
        steps = analyze_assembly(shapes, max_group=max_group).optimal_steps
        if steps is None:
            return None
        total += steps
    return total


def check_plan(shapes: Mapping[str, Shape], max_group: int | None) -> None:
    found = astar_optimal(shapes, max_group=max_group)
    expected = analyze_assembly(shapes, max_group=max_group).optimal_steps
    assert found.optimal_steps == expected
    assert found.reopened == 0  # a consistent heuristic never reopens a state
    if expected is not None:
        assert found.start_bound <= expected == found.bound == len(found.plan)
        assert replay_disassembly(shapes, found.plan).is_separated()
        if max_group is not None:
            assert all(len(m.pieces) <= max_group for m in found.plan)


def test_scene_plan_is_optimal_and_replays() -> None:
    check_plan(SCENE, None)
    check_plan(SCENE, 1)
    ref = reference_optimal_disassembly(SCENE)
    assert ref is not None and astar_optimal(SCENE).optimal_steps == len(ref)


@settings(max_examples=40)
@given(small_scenes(max_pieces=5), st.sampled_from([None, 1, 2]))
def test_optimal_like_branch_and_bound(shapes: dict[str, Shape], max_group: int | None) -> None:
    check_plan(shapes, max_group)


@settings(max_examples=25)
@given(small_scenes(max_pieces=4), st.integers(0, 10**6), st.integers(0, 5))
def test_heuristic_admissible_and_consistent(
    shapes: dict[str, Shape], seed: int, steps: int
) -> None:
    """At a random reachable state h <= the exact distance, and h <= 1 + h(next) over every
    legal move (the reference's moves)."""
    state = random_walk(shapes, seed, steps)
    heur = Heuristic(shapes)
    h = heur.value(state)
    d = exact_distance(state, None)
    if h is None:
        assert d is None
        return
    if d is not None:
        assert h <= d
    for move in legal_moves(state):
        after = heur.value(state.apply(move))
        assert after is not None and h <= 1 + after


def test_triples_family_when_small() -> None:
    """Triples are exact sub-puzzle searches too: same optimum, a bound at least as high.
    (Only tiny triples fit: three loose pieces of a 2x2x1 block already have more than
    20,000 one-part states, the sub-puzzle cap then names itself.)"""
    shapes = random_partition((3, 1, 1), 3, 5)
    pairs = astar_optimal(shapes)
    both = astar_optimal(shapes, triples=True, limits=AStarLimits(component_states=200_000))
    assert both.family[1] >= 1
    assert both.optimal_steps == pairs.optimal_steps == analyze_assembly(shapes).optimal_steps
    assert both.start_bound >= pairs.start_bound and both.reopened == 0
    with pytest.raises(SearchLimitError, match="sub-puzzle state cap"):
        astar_optimal(
            random_partition((2, 2, 1), 3, 0),
            triples=True,
            limits=AStarLimits(component_states=20_000),
        )


def test_caps_raise_named_errors() -> None:
    shapes = random_partition((3, 3, 2), 5, 3)
    with pytest.raises(SearchLimitError, match="expansion cap"):
        astar_optimal(shapes, limits=AStarLimits(max_expansions=0))
    with pytest.raises(SearchLimitError, match="A\\* state cap"):
        astar_optimal(shapes, limits=AStarLimits(max_states=2))
    with pytest.raises(SearchLimitError, match="sub-puzzle state cap"):
        astar_optimal(shapes, limits=AStarLimits(component_states=8))


def test_stuck_and_single_piece() -> None:
    one = {"a": Shape([(0, 0, 0)])}
    assert astar_optimal(one).optimal_steps == 0
    # A ring around a post cannot come apart by translations.
    ring = [(x, y, z) for x in range(3) for y in range(3) for z in (0, 1) if (x, y) != (1, 1)]
    post = [(1, 1, 0), (1, 1, 1), (1, 1, 2), (1, 1, -1), (1, 2, 2), (1, 2, -1)]
    locked = {"ring": Shape(ring), "post": Shape(post)}
    assert analyze_assembly(locked).optimal_steps is None
    assert astar_optimal(locked).optimal_steps is None


@needs_files
def test_alpackino_start_bound() -> None:
    """The heuristic at AlPackino's start is at least the 12 removals and at most the 17
    moves of the BurrTools-style plan."""
    from chaingeo.core.formats.burrtools import read_xmpuzzle

    assert BT is not None
    (asm,) = read_xmpuzzle(BT / "AlPackino.xmpuzzle").assemblies(0)
    shapes = {f"p{k:02d}": s for k, s in asm.items()}
    h = Heuristic(shapes).value(Assembly.assembled(shapes))
    assert h is not None and 12 <= h <= 17


@needs_files
@pytest.mark.slow
def test_alpackino_needs_at_least_16_moves() -> None:
    """A* exhausts every state with g + h <= 15 within 600,000 (partial) expansions (about
    30 s): no plan of 15 moves or fewer takes AlPackino apart; the BurrTools-style plan has
    17."""
    import re

    from chaingeo.core.formats.burrtools import read_xmpuzzle

    assert BT is not None
    (asm,) = read_xmpuzzle(BT / "AlPackino.xmpuzzle").assemblies(0)
    shapes = {f"p{k:02d}": s for k, s in asm.items()}
    assert analyze_assembly(shapes, optimal=False).moves == 17
    with pytest.raises(SearchLimitError, match="A\\* expansion cap") as err:
        astar_optimal(shapes, limits=AStarLimits(max_expansions=600_000, seconds=None))
    found = re.search(r"lower bound (\d+)", str(err.value))
    assert found is not None and int(found.group(1)) >= 16


@needs_files
@pytest.mark.slow
def test_alpackino_optimum_is_17() -> None:
    """The full search (about 6,000,000 partial expansions, several minutes): o_i = 17, the
    plan replays, and the heuristic never had to reopen a state."""
    from chaingeo.core.formats.burrtools import read_xmpuzzle

    assert BT is not None
    (asm,) = read_xmpuzzle(BT / "AlPackino.xmpuzzle").assemblies(0)
    shapes = {f"p{k:02d}": s for k, s in asm.items()}
    found = astar_optimal(shapes, limits=AStarLimits(max_states=8_000_000, seconds=None))
    assert found.optimal_steps == 17 == len(found.plan) and found.reopened == 0
    assert replay_disassembly(shapes, found.plan).is_separated()


def test_bench_astar_quick(capsys: pytest.CaptureFixture[str]) -> None:
    import json

    from chaingeo.cli.main import main

    assert main(["bench", "astar", "--quick"]) == 0
    rows = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    assert len(rows) == 3 and all(r["astar_o_i"] == r["bfs_o_i"] is not None for r in rows)
    assert all(r["astar_expanded"] > 0 and r["bfs_states"] > 0 for r in rows)
