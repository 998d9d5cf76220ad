"""The moves of a disassembly state as one table of arrays equal the per-group blocks they
replace (one object per group and direction, each checked against the reference kinematics in
tests/envs/actions/test_puzzle_actions.py): same actions in the same order, same lookups, same
membership, on random walks that take big shipped puzzles apart (where the groups run into the
hundreds of thousands)."""

from __future__ import annotations

import numpy as np
import pytest

from chaingeo.core.kinematics import DIRECTIONS, Move
from chaingeo.core.level import Level, load_level
from chaingeo.envs.actions.types import MoveAction
from chaingeo.envs.machines.move_table import MoveTable
from chaingeo.envs.machines.puzzle import PuzzleState
from chaingeo.envs.machines.puzzle_actions import (
    disassembly_actions,
    disassembly_ranges,
    oriented_table,
)
from tests.support.paths import LEVELS

WALKS = {  # level -> (states compared along the walk, actions of the largest one at least)
    "puzzle-easy-02-luban-6-piece": (12, 1_000),
    "puzzle-mid-01-interlocking-cube": (8, 50),
    "puzzle-mid-04-burr12": (8, 500),
    "puzzle-hard-08-burr36": (4, 9),
    "puzzle-mid-03-luban-15-piece": (6, 100_000),
}


def _both(state: PuzzleState) -> tuple[MoveTable, list[list[MoveAction]]]:
    table = oriented_table(state.assembly, state.tables.piece_table, state.tables.oriented)
    mg = state.tables.max_group
    return (
        disassembly_actions(state.assembly, mg, table),
        [list(r) for r in disassembly_ranges(state.assembly, mg, table)],
    )


def _compare(table: MoveTable, ranges: list[list[MoveAction]], rng: np.random.Generator) -> None:
    flat = [a for r in ranges for a in r]
    assert len(table) == len(flat)
    if len(flat) <= 20_000:
        assert list(table) == flat
    picks: list[int] = rng.integers(len(flat), size=300).tolist() if flat else []
    for i in [*picks, 0, len(flat) - 1] if flat else []:
        assert table[i] == flat[i] and table[i - len(flat)] == flat[i]
        assert flat[i] in table
    for r in ranges[:: max(1, len(ranges) // 200)]:
        got = table.get((r[0].move.pieces, r[0].move.direction))
        assert got is not None and list(got) == r
        last = r[-1].move
        beyond = 10**6 if last.distance is None else last.distance + 1
        assert MoveAction(Move(last.pieces, last.direction, beyond)) not in table


def _absent(table: MoveTable, names: list[str]) -> None:
    """Groups and directions the table does not hold are not found."""
    assert table.get(((), "+x")) is None and table.get(((names[0],), "up")) is None
    assert table.get((("no-such-piece",), "+x")) is None
    assert MoveAction(Move(tuple(names), "+x", None), into=("x",), offset=(0, 0, 0)) not in table
    with pytest.raises(IndexError):
        table[len(table)]


@pytest.mark.parametrize("level_id", sorted(WALKS))
def test_the_table_is_the_per_group_blocks_along_random_walks(level_id: str) -> None:
    level: Level = load_level(LEVELS / "puzzle" / f"{level_id}.json")
    walk, check = (
        np.random.default_rng(np.random.SeedSequence([s, len(level.pieces)])) for s in (20, 21)
    )
    state = PuzzleState(level)
    steps, largest = WALKS[level_id]
    sizes = []
    for _ in range(steps):
        table, ranges = _both(state)
        _compare(table, ranges, check)
        _absent(table, sorted(state.tables.names))
        sizes.append(len(table))
        state.apply(table[int(walk.integers(len(table)))])
    assert max(sizes) >= largest


def test_an_empty_table() -> None:
    table = MoveTable([(("a", "b"), np.empty((0, 4), np.int64))])
    assert len(table) == 0 and list(table) == [] and table.get((("a",), "+x")) is None
    assert MoveAction(Move(("a",), "+x", 1)) not in table


def test_rows_offering_nothing_are_dropped_and_directions_sort_as_text() -> None:
    dirs = list(DIRECTIONS)
    rows = np.array(
        [[0b01, dirs.index("-x"), 2, 0], [0b01, dirs.index("+z"), 0, 1], [0b10, 0, 0, 0]],
        dtype=np.int64,
    )
    table = MoveTable([(("a", "b"), rows)])
    assert [a.to_text() for a in table] == [
        MoveAction(Move(("a",), "+z", None)).to_text(),
        MoveAction(Move(("a",), "-x", 1)).to_text(),
        MoveAction(Move(("a",), "-x", 2)).to_text(),
    ]
