"""The reference kinematics on a small hand-checked scene."""

from __future__ import annotations

import pytest

from chaingeo.core.geometry import Shape
from chaingeo.core.kinematics import Assembly, Move, MoveError, legal_moves, movable_groups

SCENE = {
    "red": Shape([(0, 0, 0), (1, 0, 0), (2, 0, 0)]),
    "blue": Shape([(0, 1, 0), (1, 1, 0), (2, 1, 0), (3, 1, 0), (3, 0, 0)]),
    "green": Shape([(0, 0, 1), (1, 0, 1), (2, 0, 1), (3, 0, 1)]),
}


def test_blocking_and_groups() -> None:
    a = Assembly.assembled(SCENE)
    assert a.blockers("red", "+x") == ["blue"]
    assert a.blockers("red", "+z") == ["green"]
    assert movable_groups(a, "+x") == [("blue",), ("green",), ("blue", "green"), ("blue", "red")]
    assert a.free_distance(["red"], "-x") is None
    assert a.free_distance(["blue", "red"], "+x") is None
    assert a.free_distance(["red"], "+x") == 0


def test_moves_apply_and_leave_the_state_unchanged() -> None:
    a = Assembly.assembled(SCENE)
    with pytest.raises(MoveError, match="blocked after 0"):
        a.apply(Move(("red",), "+x", 1))
    b = a.apply(Move(("red",), "-x", 2))
    assert a.offsets["red"] == (0, 0, 0) and b.offsets["red"] == (-2, 0, 0)
    assert len(b.parts) == 1
    c = b.apply(Move(("red",), "-x", 5))  # far enough to clear everything: a removal
    assert sorted(map(sorted, c.parts)) == [["blue", "green"], ["red"]]
    d = c.apply(Move(("green",), "+z", None))
    assert d.is_separated()
    with pytest.raises(MoveError, match="whole part"):
        d.apply(Move(("green",), "+z", None))


def test_legal_moves_are_sorted_and_all_legal() -> None:
    a = Assembly.assembled(SCENE)
    moves = legal_moves(a)
    assert moves == sorted(
        moves, key=lambda m: (m.pieces, m.direction, m.distance is None, m.distance or 0)
    )
    for m in moves:
        a.check(m)
    assert Move(("red",), "-x", None) in moves and Move(("red",), "+x", 1) not in moves
    assert all(len(m.pieces) == 1 for m in legal_moves(a, max_group=1))
