"""Interlocking cubes: why they need empty cells, and that generated ones really interlock.

Checked against the reference kinematics (:mod:`chaingeo.core.kinematics`), not the numba search.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from chaingeo.core.geometry import Shape
from chaingeo.core.kinematics import (
    Assembly,
    legal_moves,
    reference_first_level,
    reference_optimal_disassembly,
)
from chaingeo.core.level import Level, level_bytes
from chaingeo.generator.config import PuzzleConfig
from chaingeo.generator.cubes import (
    VOID,
    nearest_to_leaving,
    random_partition,
    shapes_of,
    void_count,
    void_sites,
)
from chaingeo.generator.puzzle import make
from chaingeo.generator.result import GenerationRejection
from chaingeo.solvers.motion.partsearch import PieceTable

EASY = PuzzleConfig(shape="cube3", pieces=3, min_level=2, hole_rate=0.3, hill_steps=10)


@pytest.mark.parametrize("seed", range(6))
def test_a_cube_without_empty_cells_always_has_a_piece_that_lifts_off(seed: int) -> None:
    """Why the generator leaves cells empty: in a full cube every group that can move at all
    can leave that way (a group that can step along +x fills its lines up to the face, so
    nothing is ahead of it): the level is always 1."""
    rng = np.random.default_rng(seed)
    owner = random_partition(3, 3 + seed % 3, 0, 2, rng)
    named = {f"p{i}": s for i, s in enumerate(shapes_of(owner, int(owner.max()) + 1))}
    start = Assembly.assembled(named)
    moves = legal_moves(start)
    assert moves and all(start.free_distance(m.pieces, m.direction) is None for m in moves)


def test_voids_sit_inside_so_the_outline_stays_a_cube() -> None:
    assert void_sites(4) == [(x, y, z) for x in (1, 2) for y in (1, 2) for z in (1, 2)]
    assert len(void_sites(3)) == 7  # the centre and the six face centres
    assert void_count(3, 0.3) == 2 and void_count(4, 0.5) == 4 and void_count(4, 0.0) == 1
    with pytest.raises(ValueError, match="cube3 or larger"):
        void_count(2, 0.5)
    owner = random_partition(4, 6, 4, 3, np.random.default_rng(1))
    assert set(map(tuple, np.argwhere(owner == VOID).tolist())) <= set(void_sites(4))
    assert (owner == VOID).sum() == 4
    assert all(len(s) >= 3 and s.is_connected() for s in shapes_of(owner, 6))


def test_nearest_to_leaving_counts_blockers_ahead() -> None:
    # a voxel shut in a hollow 3x3x3 shell: each is blocked by exactly one voxel pair at best
    shell = [
        (x, y, z) for x in range(3) for y in range(3) for z in range(3) if (x, y, z) != (1, 1, 1)
    ]
    table = PieceTable({"a": Shape([(1, 1, 1)]), "b": Shape(shell)})
    vox = np.concatenate(table.voxels)
    starts = np.array([0, 1, 27], dtype=np.int64)
    states = np.zeros((2, 6), dtype=np.int16)
    states[1, 2] = 5  # the inner voxel lifted out of the shell along z
    assert nearest_to_leaving(vox, starts, states, 1) == 1
    assert nearest_to_leaving(vox, starts, states, 2) == 0


def test_generated_cube_interlocks_and_its_level_is_what_the_stats_say() -> None:
    level = make(EASY, 102, 0)
    assert isinstance(level, Level)
    shapes = level.shapes
    start = Assembly.assembled(shapes)
    assert not any(start.removes(m) for m in legal_moves(start))  # nothing lifts straight off
    first = reference_first_level(shapes)
    assert first is not None and level.stats["first_level"] == first >= 2
    assert str(level.stats["level"]).split(".")[0] == str(level.stats["first_level"])
    reference = reference_optimal_disassembly(shapes)
    assert reference is not None and len(reference) == level.optimal_steps
    again = make(EASY, 102, 0)
    assert isinstance(again, Level) and level_bytes(level) == level_bytes(again)
    cells = [c for s in shapes.values() for c in s.cells]
    assert len(cells) == len(set(cells)) and len(cells) == 27 - void_count(3, 0.3)


@pytest.mark.slow
@pytest.mark.parametrize("index", range(2))
def test_generated_four_cubes_reach_level_three(index: int) -> None:
    config = PuzzleConfig(shape="cube4", pieces=6, min_level=3, hole_rate=0.5, hill_steps=40)
    level = make(config, 202, index)
    assert isinstance(level, Level)
    first = reference_first_level(level.shapes, max_states=200_000)
    assert first is not None and level.stats["first_level"] == first >= 3


@pytest.mark.slow
def test_a_cube_that_misses_its_level_is_rejected_with_the_reason() -> None:
    item = make(dataclasses.replace(EASY, min_level=9), 5, 0)
    assert isinstance(item, GenerationRejection) and "level 9 or more" in item.reason
