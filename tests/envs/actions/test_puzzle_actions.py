"""The fast, lazy legal actions of puzzle states equal the reference enumeration, in order."""

from __future__ import annotations

import json

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from chaingeo.core.geometry import Shape
from chaingeo.core.kinematics import (
    DIRECTIONS,
    Move,
    insertion_shifts,
)
from chaingeo.core.level import Level
from chaingeo.envs.actions.lists import ActionList
from chaingeo.envs.actions.types import FinishAction, MoveAction
from chaingeo.envs.machines.puzzle import PuzzleState
from chaingeo.envs.machines.puzzle_actions import reference_actions, shifts
from tests.support.env_levels import design_of, puzzle_levels
from tests.support.paths import LEVELS
from tests.support.shipped import shipped
from tests.support.strategies import polycubes

SUITE = LEVELS / "puzzle"


@settings(max_examples=150)
@given(
    polycubes(max_size=6),
    polycubes(max_size=6),
    st.tuples(*(st.integers(-4, 4) for _ in range(3))),
    st.sampled_from(sorted(DIRECTIONS)),
)
def test_insertion_kernel_is_the_reference(
    a: Shape, b: Shape, t: tuple[int, int, int], direction: str
) -> None:
    moving = a.translate(t)
    got = shifts(moving.voxels, b.voxels, direction)
    want = insertion_shifts(moving.cells, b.cells, direction)
    assert [tuple(int(v) for v in row) for row in got] == want


def small_levels() -> list[Level]:
    """The test levels and, per (shape, goal), the first shipped level of at most 6 pieces."""
    picked: dict[tuple[str, str], Level] = {}
    for lv in shipped("puzzle"):
        if len(lv.pieces) <= 6:
            picked.setdefault((design_of(lv), lv.goal), lv)
    return [*puzzle_levels(), *(picked[k] for k in sorted(picked))]


def large_assembly_levels() -> list[Level]:
    """The shipped assemble levels of 12 pieces and more (one per shape)."""
    picked: dict[str, Level] = {}
    for lv in sorted(shipped("puzzle"), key=lambda lv: (-len(lv.pieces), lv.id)):
        if lv.goal == "assemble":
            picked.setdefault(design_of(lv), lv)
    return [lv for lv in picked.values() if len(lv.pieces) >= 12]


def _costly(lv: Level) -> bool:
    """Turns, or six pieces to assemble: the Python reference listing takes 2-9 s."""
    turns = lv.rules.turns  # type: ignore[union-attr]
    return bool(turns) or (lv.goal == "assemble" and len(lv.pieces) > 4)


def _walked(levels: list[Level]) -> list[object]:
    """The levels, the costly ones marked slow. By default the 2-3 piece assemble levels and
    every disassemble level still compare the insertion listing with the reference, and
    tests/envs/machines/test_puzzle_turns.py compares the turn listing on a Lu Ban lock."""
    return [pytest.param(lv, marks=pytest.mark.slow) if _costly(lv) else lv for lv in levels]


@pytest.mark.parametrize("lv", _walked(small_levels()), ids=lambda lv: lv.id)
def test_legal_actions_are_the_reference_along_random_walks(lv: Level) -> None:
    rng = np.random.default_rng(np.random.SeedSequence([7, len(lv.pieces)]))
    state = PuzzleState(lv)
    for _ in range(6):
        legal = state.legal_actions()
        turns = lv.rules.turns  # type: ignore[union-attr]
        assert legal == reference_actions(state.assembly, state.mode, state.tables.max_group, turns)
        moves = len(legal) - 1
        if moves == 0 or state.is_success():
            break
        state.apply(legal[int(rng.integers(moves))])


@pytest.mark.parametrize("lv", large_assembly_levels(), ids=lambda lv: lv.id)
def test_large_assembly_states_are_counted_without_building_them(lv: Level) -> None:
    """Many loose pieces offer 10^5 to 10^6 insertions: counted and indexed, never all built;
    every sampled action is legal, and a wrong offset is not."""
    state = PuzzleState(lv)
    legal = state.legal_actions()
    assert isinstance(legal, ActionList) and len(legal) > 100_000
    assert isinstance(legal[-1], FinishAction)
    rng = np.random.default_rng(3)
    picks = sorted(int(i) for i in rng.choice(len(legal) - 1, size=40, replace=False))
    sample = [legal[i] for i in picks]
    assert sample == sorted(sample)
    for action in sample:
        assert action in legal
        assert state.problem(action) is None
        assert isinstance(action, MoveAction) and action.offset is not None
        wrong = MoveAction(action.move, into=action.into, offset=(99, 99, 99))
        assert wrong not in legal and state.problem(wrong) is not None


def test_action_list_behaves_like_the_list_it_stands_for() -> None:
    a = [FinishAction()]
    moves = [MoveAction(Move(("red",), "+x", k)) for k in (1, 2, 3)]
    lst = ActionList([moves[:2], [], moves[2:], a])
    whole = [*moves, *a]
    assert len(lst) == 4 and lst == whole and list(lst) == whole
    assert lst[-1] == a[0] and lst[2] == moves[2] and lst[1:3] == moves[1:3]
    assert moves[1] in lst and MoveAction(Move(("red",), "+x", 9)) not in lst
    with pytest.raises(IndexError):
        lst[4]
    assert ActionList([]) == [] and len(ActionList([])) == 0


@pytest.mark.slow
def test_bench_actions_quick_agrees_with_the_reference(capsys: pytest.CaptureFixture[str]) -> None:
    import argparse

    from chaingeo.benchmarks import actions

    assert actions.run(argparse.Namespace(quick=True, repeat=1)) == 0
    rows = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    assert rows[-1]["speedup_overall"] > 1
    assert rows[0]["actions_max"] > 50_000
