"""Action types: canonical text and JSON round trips, the forgiving parser, the three errors."""

from __future__ import annotations

import json

import pytest
from hypothesis import given
from hypothesis import strategies as st

from chaingeo.core.colors import PALETTE
from chaingeo.core.kinematics import DIRECTIONS, Move
from chaingeo.envs.actions.parse import action_from_text, parse_action, parse_text
from chaingeo.envs.actions.types import (
    Action,
    ActionError,
    ActionFormatError,
    AmbiguousActionError,
    FinishAction,
    IllegalActionError,
    MoveAction,
    MoveRequest,
    PickupAction,
    PlaceAction,
    TurnRequest,
    UnparseableActionError,
    action_from_json,
    action_to_json,
    cell_text,
    rules_text,
)
from chaingeo.envs.machines import new_state
from tests.support.env_levels import puzzle_levels, soma_level

names = st.sampled_from([c.name for c in PALETTE])
cells = st.tuples(*(st.integers(-3, 12) for _ in range(3)))


@st.composite
def actions(draw: st.DrawFn) -> Action:
    kind = draw(st.sampled_from(["place", "pickup", "move", "finish"]))
    if kind == "place":
        return PlaceAction(draw(names), tuple(draw(st.sets(cells, min_size=1, max_size=8))))
    if kind == "pickup":
        return PickupAction(draw(names))
    if kind == "finish":
        return FinishAction()
    group = draw(st.lists(names, min_size=1, max_size=4, unique=True))
    direction = draw(st.sampled_from(sorted(DIRECTIONS)))
    distance = draw(st.none() | st.integers(1, 30))
    into = offset = None
    if distance is None and draw(st.booleans()):
        others = [c.name for c in PALETTE if c.name not in group]
        into = tuple(draw(st.lists(st.sampled_from(others), min_size=1, max_size=3, unique=True)))
        offset = draw(st.tuples(*(st.integers(-5, 5) for _ in range(3))))
    return MoveAction(Move(tuple(group), direction, distance), into=into, offset=offset)


@given(actions())
def test_json_round_trip(action: Action) -> None:
    obj = json.loads(json.dumps(action_to_json(action)))
    assert action_from_json(obj) == action
    assert action_to_json(action_from_json(obj)) == obj


@given(actions())
def test_canonical_text_round_trip(action: Action) -> None:
    text = action.to_text()
    assert action_from_text(text) == action
    assert action_from_text(text).to_text() == text


@given(st.lists(actions(), min_size=2, max_size=8))
def test_actions_of_all_kinds_sort_and_hash(batch: list[Action]) -> None:
    ordered = sorted(batch)
    ranks = [type(a).RANK for a in ordered]
    assert ranks == sorted(ranks)
    assert len({*batch}) == len({a.to_text() for a in batch})


def test_cells_are_one_based_in_text_only() -> None:
    a = PlaceAction("red", ((1, 0, 0), (0, 0, 0)))
    assert a.cells == ((0, 0, 0), (1, 0, 0))  # sorted, 0-based
    assert a.to_text() == "place red (1,1,1) (2,1,1)"
    assert action_to_json(a)["cells"] == [[0, 0, 0], [1, 0, 0]]
    assert cell_text((1, 0, 2)) == "(2,1,3)"
    assert rules_text("collision with blue at (1, 0, 2)") == "collision with blue at (2,1,3)"
    assert rules_text("out of box at (-1, 0, 4)") == "out of box at (0,1,5)"


def test_contract_examples() -> None:
    assert PickupAction("red").to_text() == "pickup red"
    assert MoveAction(Move(("red", "blue"), "+x", 2)).to_text() == "move blue+red +x 2"
    assert MoveAction(Move(("red",), "-z", None)).to_text() == "move red -z inf"
    assert FinishAction().to_text() == "finish"


FORGIVING = [
    ("place red (1,1,1) (2,1,1) (1,2,1)", "place red (1,1,1) (1,2,1) (2,1,1)"),
    ("PLACE Red (1, 1, 1), (2,1,1),(1,2,1)", "place red (1,1,1) (1,2,1) (2,1,1)"),
    ("place red at [[1,1,1],[2,1,1],[1,2,1]]", "place red (1,1,1) (1,2,1) (2,1,1)"),
    ("place red 1 1 1 2 1 1 1 2 1.", "place red (1,1,1) (1,2,1) (2,1,1)"),
    ("`place red on (1,1,1)`", "place red (1,1,1)"),
    ("Action: put red (1,1,1)", "place red (1,1,1)"),
    ("pick up red", "pickup red"),
    ("Pick-Up RED", "pickup red"),
    ("move red+blue +x 2", "move blue+red +x 2"),
    ("move red, blue x+ by 2 units", "move blue+red +x 2"),
    ("move [red, blue] -z infinity", "move blue+red -z inf"),
    ("move red and blue +y out", "move blue+red +y inf"),
    ("move red \u2212z \u221e", "move red -z inf"),
    ("slide red + x 3", "move red +x 3"),
    (
        "move red +x inf into blue+green offset (0,-1,0)",
        "move red +x inf into blue+green offset (0,-1,0)",
    ),
    ("move red +x into green offset 0 0 1", "move red +x into green offset (0,0,1)"),
    ("Finish", "finish"),
    ("done.", "finish"),
]


@pytest.mark.parametrize(("text", "canonical"), FORGIVING)
def test_parser_is_forgiving_in_syntax(text: str, canonical: str) -> None:
    parsed = parse_text(text, "assemble")
    shown = parsed.text() if isinstance(parsed, MoveRequest | TurnRequest) else parsed.to_text()
    assert shown == canonical


def test_open_distance_is_kept_open() -> None:
    req = parse_text("move red +x", "disassemble")
    assert isinstance(req, MoveRequest) and not req.distance_given
    with pytest.raises(UnparseableActionError, match="needs its distance"):
        action_from_text("move red +x")


UNPARSEABLE = [
    "",
    "   ",
    "plase red (1,1,1)",
    "place (1,1,1)",
    "place red",
    "place red (1,1)",
    "place red (1,1,1) (2,1)",
    "place red 1 2",
    "place red (1,1,1) please",
    "place red ((1,1,1)",
    "pickup",
    "pickup red blue",
    "move red",
    "move red 2",
    "move +x 1",
    "move red +x 1 2",
    "move red +w 1",
    "move red +x 1 offset (1,2)",
    "finish now",
    "rotate red 90",
    "place red (1,1,1) @",
]


@pytest.mark.parametrize("text", UNPARSEABLE)
def test_unparseable_text(text: str) -> None:
    with pytest.raises(UnparseableActionError) as err:
        parse_text(text, "stacking")
    assert err.value.kind == "unparseable"
    assert "Nothing changed" in err.value.feedback and "expected" in err.value.feedback


@pytest.mark.parametrize(
    ("text", "reason"),
    [
        ("place red (1,1,1) (1,1,1)", "listed twice"),
        ("move red +x 0", "at least 1"),
        ("move red+red +x 1", "named twice"),
        ("move red +x inf into red", "into itself"),
    ],
)
def test_well_formed_but_meaningless_text_is_illegal(text: str, reason: str) -> None:
    with pytest.raises(IllegalActionError, match=reason):
        parse_text(text, "stacking")


def test_errors_carry_feedback_and_the_state_key() -> None:
    state = new_state(soma_level())
    key = state.key()
    for text, kind in [
        ("plase red", UnparseableActionError),
        ("place pink (1,1,1)", IllegalActionError),
        ("place red (1,1,1)", IllegalActionError),
        ("move red +x 1", IllegalActionError),
    ]:
        with pytest.raises(kind) as err:
            parse_action(text, state)
        assert isinstance(err.value, ActionError)
        assert err.value.state_key == key and err.value.feedback
        assert err.value.text == text
    assert state.key() == key and state.steps_used == 0
    with pytest.raises(IllegalActionError) as err:
        parse_action("place pink (1,1,1)", state)
    assert err.value.reason.startswith("unknown piece 'pink'")


def test_ambiguous_lists_candidates() -> None:
    level = next(lv for lv in puzzle_levels() if lv.id == "lock3-disassemble")
    state = new_state(level)
    with pytest.raises(AmbiguousActionError) as err:
        parse_action("move red -x", state)
    texts = [a.to_text() for a in err.value.candidates]
    assert texts == ["move red -x 1", "move red -x 2", "move red -x inf"]
    assert "fits 3 legal actions" in err.value.feedback
    assert err.value.state_key == state.key()


@pytest.mark.parametrize(
    "obj",
    [
        [],
        {"type": "jump"},
        {"type": "place", "piece": "red"},
        {"type": "place", "piece": "red", "cells": [[0, 0]]},
        {"type": "place", "piece": "red", "cells": [[0, 0, True]]},
        {"type": "place", "piece": "red", "cells": []},
        {"type": "pickup", "piece": 3},
        {"type": "move", "pieces": ["red"], "direction": "+q", "distance": 1},
        {"type": "move", "pieces": ["red"], "direction": "+x"},
        {"type": "move", "pieces": ["red"], "direction": "+x", "distance": 0},
        {"type": "move", "pieces": ["red"], "direction": "+x", "distance": 1, "into": ["blue"]},
        {"type": "finish", "extra": 1},
    ],
)
def test_bad_json_is_a_typed_error(obj: object) -> None:
    with pytest.raises(ActionFormatError):
        action_from_json(obj)


def test_an_action_syntax_is_a_plug_in_and_a_name_is_taken_once() -> None:
    """A registered syntax reads the texts it claims; the built-in names are refused again."""
    from chaingeo.core.registry import DuplicateNameError
    from chaingeo.envs.actions.parse import SYNTAXES, ActionSyntax, parse_text

    def claims(text: str, body: str) -> bool:
        return body.strip().lower() == "surrender"

    done = ActionSyntax("surrender-word", claims, lambda text, body: FinishAction())
    with pytest.raises(UnparseableActionError):
        parse_text("surrender")
    with SYNTAXES.registered("surrender-word", done):
        assert parse_text("<action>Surrender</action>") == FinishAction()
    with pytest.raises(UnparseableActionError):
        parse_text("surrender")
    for name in ("chain", "turn"):
        with pytest.raises(DuplicateNameError):
            SYNTAXES.register(name, done)
