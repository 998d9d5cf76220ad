"""The block lower bound (single-piece moves) against the plain optimal search, and towers of
burr units whose o_i it proves, replayed with the reference kinematics."""

from __future__ import annotations

import dataclasses
from functools import cache

import pytest

from chaingeo.core.geometry import Shape
from chaingeo.core.kinematics import disassembly_of_assembly_plan, replay_disassembly
from chaingeo.core.level import Level, PuzzleSolution
from chaingeo.envs.machines import new_state
from chaingeo.generator.config import PuzzleConfig
from chaingeo.generator.puzzle import make
from chaingeo.generator.result import GenerationRejection
from chaingeo.solvers.motion.disassemble import analyze_assembly
from chaingeo.solvers.optimal.blockbound import analyze_by_blocks, block_lower_bound


@cache
def _small_puzzles() -> list[dict[str, Shape]]:
    """Generated six-piece burrs that come apart with single-piece moves."""
    config = PuzzleConfig(shape="burr6", hill_steps=0, max_group=1)
    out = [item.shapes for i in range(4) if isinstance(item := make(config, 11, i), Level)]
    assert len(out) >= 3
    return out


def _partitions(names: list[str]) -> list[list[list[str]]]:
    return [
        [names[:2], names[2:]],
        [names[::2], names[1::2]],
        [[n] for n in names],
        [names],
    ]


def test_block_bound_is_below_the_plain_optimum_and_exact_when_met() -> None:
    for shapes in _small_puzzles():
        plain = analyze_assembly(shapes, max_group=1, optimal=True)
        assert plain.optimal_steps is not None
        names = sorted(shapes)
        for blocks in _partitions(names):
            bound = block_lower_bound(shapes, blocks, max_group=1)
            assert len(names) - 1 <= bound <= plain.optimal_steps
            found = analyze_by_blocks(shapes, blocks)
            assert found.optimal_steps == plain.optimal_steps
            assert len(found.plan) == found.optimal_steps
            assert replay_disassembly(shapes, found.plan).is_separated()
        # The whole puzzle as one block is the optimum itself.
        assert block_lower_bound(shapes, [names], max_group=1) == plain.optimal_steps


def test_block_bound_refuses_group_moves_and_bad_partitions() -> None:
    shapes = _small_puzzles()[0]
    names = sorted(shapes)
    with pytest.raises(ValueError, match="single-piece"):
        block_lower_bound(shapes, [names], max_group=None)
    with pytest.raises(ValueError, match="split the pieces"):
        block_lower_bound(shapes, [names[:1]], max_group=1)


@cache
def _tower(goal: str) -> Level:
    config = PuzzleConfig(shape="burr12", hill_steps=0, max_group=1)
    item = make(dataclasses.replace(config, goal=goal), 5, 1)  # type: ignore[arg-type]
    assert not isinstance(item, GenerationRejection), item.reason
    return item


def test_tower_o_i_is_the_block_bound_and_the_plan_replays() -> None:
    """A generated 12-piece tower for the assemble game: o_i is the block bound, the stored
    plan reversed takes it apart under the reference kinematics, and the game accepts the
    stored plan as agent text, move by move, to success."""
    level = _tower("assemble")
    shapes = level.shapes
    names = [p.name for p in level.pieces]
    assert len(names) == 12
    bound = block_lower_bound(shapes, [names[:6], names[6:]], max_group=1)
    assert level.optimal_steps == bound
    assert isinstance(level.solution, PuzzleSolution)
    moves = list(level.solution.moves)
    assert len(moves) == bound and all(len(m.pieces) == 1 for m in moves)
    assert replay_disassembly(shapes, disassembly_of_assembly_plan(moves)).is_separated()
    state = new_state(level)
    for m in moves:
        result = state.step_text(m.describe())
        assert result.legal, result.error
    assert state.is_success() and state.steps_used == level.optimal_steps


@pytest.mark.slow
def test_tower_goals_share_the_puzzle() -> None:
    item, plain = _tower("assemble"), _tower("disassemble")
    assert item.optimal_steps == plain.optimal_steps
    assert isinstance(item.solution, PuzzleSolution)
    assert isinstance(plain.solution, PuzzleSolution)
    assert disassembly_of_assembly_plan(item.solution.moves) == list(plain.solution.moves)
    assert replay_disassembly(plain.shapes, plain.solution.moves).is_separated()
