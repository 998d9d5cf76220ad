"""The puzzle state machine: disassembly is the reference kinematics, assembly its exact reverse."""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from chaingeo.core.geometry import Shape
from chaingeo.core.kinematics import DIRECTIONS, OPPOSITE, Move, MoveError, legal_moves
from chaingeo.core.level import Level
from chaingeo.envs.actions.parse import parse_action
from chaingeo.envs.actions.types import (
    AmbiguousActionError,
    FinishAction,
    IllegalActionError,
    MoveAction,
)
from chaingeo.envs.machines.puzzle import PuzzleState, normal_key
from tests.support.env_levels import LOCK3, bfs_plan, puzzle_level, puzzle_levels, tube


def level(level_id: str) -> Level:
    return next(lv for lv in puzzle_levels() if lv.id == level_id)


def walk(lv: Level, choices: list[int]) -> PuzzleState:
    state = PuzzleState(lv)
    for c in choices:
        legal = [a for a in state.legal_actions() if not isinstance(a, FinishAction)]
        if not legal or state.is_success():
            break
        state.apply(legal[c % len(legal)])
    return state


DISASSEMBLE = ["lock3-disassemble", "tube2-disassemble", "tube2-single-disassemble"]
ASSEMBLE = ["lock3-assemble", "tube1-assemble", "tube2-assemble", "tube2-single-assemble"]


@settings(max_examples=60)
@given(
    st.sampled_from(DISASSEMBLE),
    st.lists(st.integers(0, 10_000), max_size=4),
    st.lists(st.sampled_from(["red", "green", "blue", "yellow"]), min_size=1, unique=True),
    st.sampled_from(sorted(DIRECTIONS)),
    st.none() | st.integers(1, 6),
)
def test_disassembly_is_the_reference_kinematics(
    which: str, choices: list[int], group: list[str], direction: str, distance: int | None
) -> None:
    lv = level(which)
    state = walk(lv, choices)
    names = {p.name for p in lv.pieces}
    move = Move(tuple(group), direction, distance)
    why = state.problem(MoveAction(move))
    mg = lv.rules.max_group  # type: ignore[union-attr]
    try:
        if not set(group) <= names:
            raise MoveError(move, "unknown piece")
        if mg is not None and len(group) > mg:
            raise MoveError(move, "too many pieces")
        after = state.assembly.apply(move)
    except MoveError:
        assert why is not None
        return
    assert why is None
    state.apply(MoveAction(move))
    assert state.key() == (normal_key(after), False)


@pytest.mark.parametrize("which", DISASSEMBLE)
def test_disassembly_legal_actions_are_the_legal_moves(which: str) -> None:
    lv = level(which)
    state = PuzzleState(lv)
    mg = lv.rules.max_group  # type: ignore[union-attr]
    assert state.legal_actions() == [
        *(MoveAction(m) for m in legal_moves(state.assembly, mg)),
        FinishAction(),
    ]


@settings(max_examples=25)
@given(st.sampled_from(ASSEMBLE), st.lists(st.integers(0, 10_000), max_size=3), st.randoms())
def test_every_assembly_action_reverses_a_disassembly_move(
    which: str, choices: list[int], rnd: object
) -> None:
    """Soundness: Y -a-> Z in assembly implies Z -inverse(a)-> Y in the reference kinematics,
    so no assembly is shorter than the optimal disassembly."""
    state = walk(level(which), choices)
    actions = [a for a in state.legal_actions() if isinstance(a, MoveAction)]
    sample = rnd.sample(actions, min(25, len(actions)))  # type: ignore[attr-defined]
    for action in sample:
        nxt = state.clone()
        nxt.apply(action)
        back = Move(action.move.pieces, OPPOSITE[action.move.direction], action.move.distance)
        undone = nxt.assembly.apply(back)  # raises MoveError if the reverse is not legal
        assert normal_key(undone) == normal_key(state.assembly), action.to_text()


def test_assembly_starts_apart_and_ends_at_the_target() -> None:
    state = PuzzleState(level("lock3-assemble"))
    assert len(state.assembly.parts) == 3 and not state.is_success()
    for text in ("move red -z inf into blue offset (0,0,0)", "move green -z inf into blue"):
        assert state.step_text(text).legal
    assert state.is_success()


def test_open_insertion_follows_the_recorded_plan() -> None:
    for which in ASSEMBLE:
        lv = level(which)
        state = PuzzleState(lv)
        for i, move in enumerate(lv.solution.moves):  # type: ignore[union-attr]
            resolved = state.resolve(MoveAction(move))
            assert isinstance(resolved, MoveAction)
            state.apply(resolved)
            assert state.tables.path[normal_key(state.assembly)] == i + 1
        assert state.is_success()


def test_open_insertion_prefers_the_target_place_then_asks() -> None:
    state = PuzzleState(level("lock3-assemble"))
    # the plan starts by joining green and red: an open insertion that does so follows it
    assert parse_action("move green -z inf", state).to_text() == (
        "move green -z inf into red offset (0,0,0)"
    )
    # off the plan, the target place decides
    action = parse_action("move blue -y inf into red", state)
    assert action.to_text() == "move blue -y inf into red offset (0,0,0)"
    with pytest.raises(AmbiguousActionError) as err:
        parse_action("move blue -y inf", state)
    assert [a.to_text() for a in err.value.candidates] == [
        "move blue -y inf into green offset (0,0,0)",
        "move blue -y inf into red offset (0,0,0)",
    ]
    # off the plan and off the target: every fitting offset is a candidate
    state.apply(parse_action("move red +y inf into green offset (0,-1,0)", state))
    with pytest.raises(AmbiguousActionError) as err:
        parse_action("move blue -z inf", state)
    assert len(err.value.candidates) > 2


def test_insertion_refusals_say_why() -> None:
    state = PuzzleState(level("lock3-assemble"))
    cases = {
        "move red -z inf into blue offset (0,1,0)": "red would overlap blue at (1,2,1)",
        "move red -x inf into blue offset (0,0,0)": "on the way in it would pass through blue",
        "move red -z inf into blue offset (0,7,0)": "bounding boxes touch or overlap",
        "move red -z inf into red offset (0,0,0)": "into itself",
        "move red -z inf into pink": "unknown piece 'pink'",
    }
    for text, reason in cases.items():
        with pytest.raises(IllegalActionError) as err:
            parse_action(text, state)
        assert reason in err.value.reason, (text, err.value.reason)
    # a part apart comes in from afar whatever distance the text gives
    assert parse_action("move red +x 2", state).to_text() == (
        "move red +x inf into green offset (0,0,0)"
    )
    state.apply(parse_action("move red -z inf into blue offset (0,0,0)", state))
    with pytest.raises(IllegalActionError, match="nothing leaves a part"):
        parse_action("move red -y inf", state)


def test_a_group_clear_of_the_rest_cannot_slide_back_in() -> None:
    # red sits under blue's arm; inserted one short along +x it lies clear on the -x side:
    # pushing it the rest of the way would undo a removal, so it must come in in one move.
    shapes = {
        "blue": Shape([(2, 0, 0), (2, 0, 1), (1, 0, 1)]),
        "red": Shape([(1, 0, 0)]),
    }
    plan = bfs_plan(shapes)
    assert plan is not None
    state = PuzzleState(puzzle_level("arm", shapes, plan, "assemble"))
    state.apply(parse_action("move red +x inf into blue offset (-1,0,0)", state))
    why = state.problem(MoveAction(Move(("red",), "+x", 1)))
    assert why is not None and "lies clear of the rest of its part on the -x side" in why
    assert MoveAction(Move(("red",), "+x", 1)) not in state.legal_actions()


def test_group_rules_and_max_group() -> None:
    state = PuzzleState(level("lock3-single-disassemble"))
    assert "at most 1 piece" in (state.problem(MoveAction(Move(("red", "blue"), "+z", None))) or "")
    state.apply(MoveAction(Move(("green",), "+z", None)))
    why = state.problem(MoveAction(Move(("green",), "+z", 1)))
    assert why is not None and "already apart" in why
    other = PuzzleState(level("lock3-disassemble"))
    other.apply(MoveAction(Move(("green",), "+z", None)))
    why = other.problem(MoveAction(Move(("green", "red"), "+x", 1)))
    assert why is not None and "different parts" in why
    blocked = state.problem(MoveAction(Move(("red",), "+x", 1)))
    assert blocked == "blocked by blue: it cannot move +x at all"


def test_key_ignores_where_separated_parts_lie() -> None:
    c = PuzzleState(level("lock3-disassemble"))
    for move in (Move(("red",), "-x", 1), Move(("red",), "-x", None), Move(("green",), "+z", 5)):
        c.apply(MoveAction(move))  # green +z 5 clears the rest: a removal
    d = PuzzleState(level("lock3-disassemble"))
    for move in (Move(("green",), "+z", None), Move(("red",), "-x", None)):
        d.apply(MoveAction(move))
    assert c.is_success() and d.is_success()
    assert c.assembly.offsets != d.assembly.offsets and c.key() == d.key()


def test_step_text_feedback_for_moves() -> None:
    state = PuzzleState(level("lock3-disassemble"))
    r = state.step_text("move red -x")
    assert r.error == "ambiguous" and state.steps_used == 1
    r = state.step_text("move red -x 1")
    assert r.legal and r.feedback == "OK: red slid -x by 1 unit(s)."
    r = state.step_text("move green +z inf")
    assert r.feedback == "OK: green was taken out along +z. 1 of 3 pieces apart."
    r = state.step_text("move red -x inf")
    assert r.success and r.feedback.endswith("Solved!")


def test_lock3_shapes_are_the_level_pieces() -> None:
    assert {p.name: p.shape for p in level("lock3-disassemble").pieces} == LOCK3


def shortest(state: PuzzleState) -> int:
    """Fewest actions to success, by breadth-first search over the state machine."""
    seen = {state.key()}
    frontier = [state]
    depth = 0
    while frontier:
        if any(s.is_success() for s in frontier):
            return depth
        nxt: list[PuzzleState] = []
        for s in frontier:
            for a in s.legal_actions():
                if isinstance(a, FinishAction):
                    continue
                child = s.clone()
                child.apply(a)
                if child.key() not in seen:
                    seen.add(child.key())
                    nxt.append(child)
        frontier, depth = nxt, depth + 1
    raise AssertionError("target unreachable")


@pytest.mark.parametrize(
    "shapes",
    [
        {"blue": Shape([(2, 0, 0), (2, 0, 1), (1, 0, 1)]), "red": Shape([(1, 0, 0)])},
        tube(3, 1),
    ],
    ids=["arm", "tube"],
)
def test_two_piece_assembly_is_exactly_as_long_as_disassembly(shapes: dict[str, Shape]) -> None:
    plan = bfs_plan(shapes)
    assert plan is not None
    assemble = PuzzleState(puzzle_level("two", shapes, plan, "assemble"))
    assert shortest(assemble) == len(plan)
