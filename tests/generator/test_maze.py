"""Maze burrs: the generated deep puzzles have the level the generator claims, checked against
the reference kinematics (pure Python), and are deterministic per (seed, index)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from chaingeo.core.kinematics import (
    reference_first_level,
    reference_optimal_disassembly,
    replay_disassembly,
)
from chaingeo.core.level import Level, level_bytes
from chaingeo.generator.config import PuzzleConfig
from chaingeo.generator.maze import maze_pieces, parse_maze_shape, random_walk, runs, with_exit
from chaingeo.generator.puzzle import make

DEEP = PuzzleConfig(shape="maze5", min_level=10, hill_steps=300)


def _deep(index: int = 0, goal: str = "disassemble") -> Level:
    import dataclasses

    item = make(dataclasses.replace(DEEP, goal=goal), 7, index)  # type: ignore[arg-type]
    assert isinstance(item, Level), item
    return item


def test_deep_maze_has_the_claimed_level_under_the_reference_kinematics() -> None:
    level = _deep()
    claimed = level.stats["first_level"]
    assert isinstance(claimed, int) and claimed >= 10
    assert level.stats["level"] == str(claimed)
    assert reference_first_level(level.shapes) == claimed
    # Two pieces: the first removal finishes the disassembly, so o_i is the level too.
    plan = reference_optimal_disassembly(level.shapes)
    assert plan is not None and len(plan) == claimed == level.optimal_steps
    assert level.solution is not None
    final = replay_disassembly(level.shapes, level.solution.moves)  # type: ignore[union-attr]
    assert final.is_separated()
    assert len(level.solution.moves) == claimed  # type: ignore[union-attr]


def test_deep_maze_is_deterministic_per_seed_and_index() -> None:
    a, b = _deep(1), _deep(1)
    assert level_bytes(a) == level_bytes(b)
    assert level_bytes(a) != level_bytes(_deep(2))


def test_assemble_goal_plays_the_reversed_plan() -> None:
    level = _deep(0, "assemble")
    assert level.goal == "assemble"
    assert level.optimal_steps == level.stats["first_level"]


@settings(max_examples=25, deadline=None)
@given(n=st.integers(4, 7), seed=st.integers(0, 2**32 - 1))
def test_runs_of_a_walk_are_the_solver_level(n: int, seed: int) -> None:
    from chaingeo.solvers.motion.disassemble import analyze_assembly

    path = random_walk(n, np.random.default_rng(seed))
    if not path:
        return
    plate, pin = maze_pieces(path, n)
    if not plate.is_connected():
        return
    result = analyze_assembly({"plate": plate, "pin": pin}, optimal=True)
    expected = runs(with_exit(path, n))
    assert result.first_level == expected == result.optimal_steps


def test_walks_are_induced_and_end_on_the_border() -> None:
    rng = np.random.default_rng(3)
    for _ in range(50):
        n = 6
        path = random_walk(n, rng)
        cells = set(path)
        assert len(cells) == len(path)
        for i, (x, y) in enumerate(path):
            touching = {j for j, c in enumerate(path) if abs(c[0] - x) + abs(c[1] - y) == 1}
            assert touching <= {i - 1, i + 1}
        x, y = path[-1]
        assert min(x, y) == 0 or max(x, y) == n - 1


@pytest.mark.parametrize("bad", ["maze", "maze3", "mazeX", "maze41"])
def test_bad_maze_shape_is_a_clear_error(bad: str) -> None:
    with pytest.raises(ValueError, match="maze shapes are"):
        parse_maze_shape(bad)
