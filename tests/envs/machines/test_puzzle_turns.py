"""Turns in agent text, in level files and in the puzzle state machine."""

from __future__ import annotations

import json
from functools import cache

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from chaingeo.core.geometry import Shape, puzzle_signature
from chaingeo.core.kinematics import Move
from chaingeo.core.level import (
    Level,
    LevelError,
    Piece,
    Provenance,
    PuzzleSolution,
    default_step_budget,
    level_bytes,
    parse_level,
    revalidate,
)
from chaingeo.core.rules import PuzzleRules
from chaingeo.core.turns import TurnMove
from chaingeo.envs.actions.parse import action_from_text, parse_action, parse_text
from chaingeo.envs.actions.types import (
    AmbiguousActionError,
    FinishAction,
    IllegalActionError,
    MoveAction,
    TurnAction,
    TurnRequest,
    UnparseableActionError,
    action_from_json,
    action_of_move,
    action_to_json,
)
from chaingeo.envs.machines.puzzle import PuzzleState
from chaingeo.envs.machines.puzzle_actions import reference_actions
from chaingeo.solvers.motion.disassemble import analyze_assembly
from tests.support.env_levels import puzzle_levels
from tests.support.scenes import luban3


@cache
def luban_level(goal: str = "disassemble") -> Level:
    shapes, rods = luban3(6)
    plan = list(analyze_assembly(shapes, turns=True, rods=rods).plan)
    moves = plan if goal == "disassemble" else [m.inverse() for m in reversed(plan)]
    colors = {"blue": "#1f5fbf", "forest": "#228b22", "rust": "#b7410e"}
    level = Level(
        id=f"luban-{goal}",
        family="puzzle",
        difficulty="easy",
        goal=goal,  # type: ignore[arg-type]
        box=None,
        pieces=tuple(
            Piece(n, colors[n], s, rods=rods.get(n, {})) for n, s in sorted(shapes.items())
        ),
        solution=PuzzleSolution(tuple(moves)),
        optimal_steps=len(moves),
        max_steps=default_step_budget(len(moves)),
        rules=PuzzleRules(turns=True),
        provenance=Provenance("tests", "1", None, None, puzzle_signature(shapes.values())),
    )
    return revalidate(level)


# -- text -------------------------------------------------------------------------------------


def test_rotate_text_is_read() -> None:
    req = parse_text("rotate red z +90 about (2,3,1)", "disassemble")
    assert req == TurnRequest(("red",), "z", 1, (2, 4, 0))
    req = parse_text("Rotate Red+Blue around z by -90 degrees about [1.5, 2.5, 7]")
    assert req == TurnRequest(("blue", "red"), "z", -1, (1, 3, 0))
    assert parse_text("turn red x 90") == TurnRequest(("red",), "x", 1, None)
    assert parse_text("rotate blue and red y -90 at (0.5, 4, 0.5)") == TurnRequest(
        ("blue", "red"), "y", -1, (-1, 0, -1)
    )


@pytest.mark.parametrize(
    "text",
    ["rotate", "rotate red", "rotate red w +90", "rotate red z", "rotate red z +90 about (1,2)",
     "rotate red z +90 (1,2,3)", "rotate red z +90 about (1,2,x)"],
)  # fmt: skip
def test_unreadable_turns(text: str) -> None:
    with pytest.raises(UnparseableActionError):
        parse_text(text, "disassemble")


@pytest.mark.parametrize(
    "text",
    ["rotate red z +45", "rotate red z +90 about (1.25,2,1)", "rotate red z +90 about (1.5,2,1)",
     "rotate red+red z +90"],
)  # fmt: skip
def test_meaningless_turns(text: str) -> None:
    with pytest.raises(IllegalActionError):
        parse_text(text, "disassemble")


@given(
    st.lists(st.sampled_from(["red", "blue", "green"]), min_size=1, max_size=3, unique=True),
    st.sampled_from("xyz"),
    st.sampled_from([1, -1]),
    st.integers(-9, 9),
    st.integers(-9, 9),
    st.integers(-9, 9),
)
def test_turn_actions_round_trip(
    pieces: list[str], axis: str, quarter: int, a: int, b: int, c: int
) -> None:
    centre = [a, b, c]
    i = "xyz".index(axis)
    centre[(i + 2) % 3] += (centre[(i + 2) % 3] - centre[(i + 1) % 3]) % 2
    action = TurnAction(TurnMove(tuple(pieces), axis, quarter, (centre[0], centre[1], centre[2])))
    assert action_from_text(action.to_text()) == action
    obj = json.loads(json.dumps(action_to_json(action)))
    assert action_from_json(obj) == action
    assert sorted([FinishAction(), action, MoveAction(Move(("red",), "+x", 1))])[1] == action


def test_turn_text_is_one_based() -> None:
    t = TurnAction(TurnMove(("red",), "z", -1, (5, 7, 0)))
    assert t.to_text() == "rotate red z -90 about (3.5,4.5,1)"
    assert action_to_json(t)["about"] == [2.5, 3.5, 0]
    assert action_of_move(t.turn) == t


# -- level files ------------------------------------------------------------------------------


def test_turn_levels_round_trip_and_others_keep_their_bytes() -> None:
    lv = luban_level()
    data = json.loads(level_bytes(lv))
    assert data["rules"] == {"max_group": None, "turns": True}
    assert data["pieces"][1]["rods"] == {"y": [[3, 2, 3], [3, 3, 3]]}
    assert any("axis" in m for m in data["solution"]["moves"])
    assert parse_level(data) == lv
    plain = puzzle_levels()[0]
    assert "turns" not in json.loads(level_bytes(plain))["rules"]
    assert "rods" not in level_bytes(plain).decode()
    data["rules"] = {"max_group": None}
    with pytest.raises(LevelError, match="do not allow turns"):
        parse_level(data)
    data = json.loads(level_bytes(lv))
    data["pieces"][1]["rods"] = {}
    with pytest.raises(LevelError, match="does not replay"):
        parse_level(data)  # without its round rod the lock does not turn
    data = json.loads(level_bytes(lv))
    data["rules"]["turns"] = False
    with pytest.raises(LevelError, match="turns"):
        parse_level(data)


# -- the state machine ------------------------------------------------------------------------


def test_rotate_resolves_its_centre_and_solves_the_lock() -> None:
    state = PuzzleState(luban_level())
    assert state.step_text("move rust -y inf").error == "illegal"
    r = state.step_text("rotate forest y +90")
    assert r.legal, r.feedback
    assert state.step_text("move rust -y inf").legal
    assert state.step_text("move forest +x inf").legal
    assert state.is_success()


def test_turn_problems_are_explained() -> None:
    state = PuzzleState(luban_level())
    with pytest.raises(IllegalActionError, match="sweep through"):
        parse_action("rotate forest y +90 about (3,1,3)", state)
    with pytest.raises(IllegalActionError, match="no line parallel to z"):
        parse_action("rotate forest z +90", state)
    with pytest.raises(IllegalActionError, match="whole part"):
        parse_action("rotate blue+forest+rust y +90 about (3,1,3)", state)
    plain = PuzzleState(puzzle_levels()[0])
    with pytest.raises(IllegalActionError, match="does not allow turns"):
        parse_action("rotate red z +90", plain)
    key = state.key()
    assert state.step_text("rotate forest z +90").error == "illegal"
    assert state.key() == key


def test_ambiguous_centres_list_candidates() -> None:
    shapes = {"blue": Shape([(3, 0, 0)]), "red": Shape([(0, 0, 0)])}
    lv = revalidate(
        Level(
            id="loose",
            family="puzzle",
            difficulty="easy",
            goal="disassemble",
            box=None,
            pieces=(
                Piece("blue", "#1f5fbf", shapes["blue"]),
                Piece("red", "#e02020", shapes["red"]),
            ),
            solution=PuzzleSolution((Move(("red",), "-x", None),)),
            optimal_steps=1,
            max_steps=30,
            rules=PuzzleRules(turns=True),
            provenance=Provenance("tests", "1", None, None, puzzle_signature(shapes.values())),
        )
    )
    state = PuzzleState(lv)
    # a lone cell turns about its own centre or any of its four corner lines
    with pytest.raises(AmbiguousActionError) as e:
        parse_action("rotate red z +90", state)
    assert len(e.value.candidates) == 5
    assert parse_action("rotate red z +90 about (1,1,1)", state) in e.value.candidates
    r = state.step_text("rotate red z +90 about (0.5,0.5,9)")
    assert r.legal and state.cells_of("red") == ((-1, 0, 0),)


def _walk(state: PuzzleState, choices: list[int]) -> None:
    for c in choices:
        legal = [a for a in state.legal_actions() if not isinstance(a, FinishAction)]
        if not legal or state.is_success():
            return
        state.apply(legal[c % len(legal)])


def _lists_match(goal: str, choices: list[int]) -> None:
    state = PuzzleState(luban_level(goal))
    _walk(state, choices)
    want = reference_actions(state.assembly, goal, None, turns=True)
    assert list(state.legal_actions()) == want


@settings(max_examples=5, deadline=None)
@given(st.sampled_from(["disassemble", "assemble"]), st.lists(st.integers(0, 10**6), max_size=3))
def test_fast_action_lists_match_reference(goal: str, choices: list[int]) -> None:
    _lists_match(goal, choices)


@pytest.mark.slow
@settings(max_examples=60, deadline=None)
@given(st.sampled_from(["disassemble", "assemble"]), st.lists(st.integers(0, 10**6), max_size=5))
def test_fast_action_lists_match_reference_long_walks(goal: str, choices: list[int]) -> None:
    _lists_match(goal, choices)


def test_assembly_plays_the_plan_backwards() -> None:
    lv = luban_level("assemble")
    state = PuzzleState(lv)
    assert state.assembly.rotation_of("forest") != 0  # apart as the plan leaves it
    assert isinstance(lv.solution, PuzzleSolution)
    for m in lv.solution.moves:
        r = state.step_text(action_of_move(m).to_text())
        assert r.legal, r.feedback
    assert state.is_success()
