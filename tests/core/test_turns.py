"""Quarter turns: the exact sweep test, the reference kinematics, and FCL's verdict."""

from __future__ import annotations

import itertools
import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from chaingeo.core.geometry import ROTATIONS, Shape
from chaingeo.core.kinematics import (
    Assembly,
    Move,
    MoveError,
    legal_turns,
    replay_disassembly,
    state_key,
)
from chaingeo.core.turns import (
    TurnMove,
    centres_within,
    square_hit,
    swept_squares,
    turn_cells,
    turn_from_json,
)
from chaingeo.pictures.collision_check import turn_is_legal, turning_collision
from tests.support.puzzle_strategies import scenes, small_scenes

Sq = tuple[int, int]


def _squares(parity: int, reach: int) -> list[Sq]:
    r = range(-reach, reach + 1)
    return [p for p in itertools.product(r, r) if p[0] % 2 == parity and p[1] % 2 == parity]


# -- the planar test --------------------------------------------------------------------------


def _overlap_area(s: Sq, f: Sq, theta: float) -> float:
    """Area common to square ``s`` turned by ``theta`` about O and square ``f`` (doubled units),
    by clipping one convex polygon with the other (floating point)."""
    c, sn = math.cos(theta), math.sin(theta)
    corners = [(s[0] + dx, s[1] + dy) for dx, dy in ((-1, -1), (1, -1), (1, 1), (-1, 1))]
    poly = [(c * x - sn * y, sn * x + c * y) for x, y in corners]
    for axis, bound, keep_below in ((0, f[0] + 1, True), (0, f[0] - 1, False),
                                    (1, f[1] + 1, True), (1, f[1] - 1, False)):  # fmt: skip
        out: list[tuple[float, float]] = []
        for i, p in enumerate(poly):
            q = poly[(i + 1) % len(poly)]
            pin = (p[axis] <= bound) if keep_below else (p[axis] >= bound)
            qin = (q[axis] <= bound) if keep_below else (q[axis] >= bound)
            if pin:
                out.append(p)
            if pin != qin:
                t = (bound - p[axis]) / (q[axis] - p[axis])
                out.append((p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])))
        poly = out
        if not poly:
            return 0.0
    return 0.5 * abs(
        sum(
            poly[i][0] * poly[(i + 1) % len(poly)][1] - poly[(i + 1) % len(poly)][0] * poly[i][1]
            for i in range(len(poly))
        )
    )


def _sampled_hit(s: Sq, f: Sq, samples: int = 181) -> bool:
    return max(_overlap_area(s, f, math.pi / 2 * k / (samples - 1)) for k in range(samples)) > 1e-6


def test_square_hit_matches_sampled_overlap_near_the_axis() -> None:
    """Every pair of squares within 3 cells of the axis, both kinds of axis: the exact test
    agrees with a brute-force overlap area sampled every half degree."""
    for parity in (0, 1):
        squares = _squares(parity, 5)
        for s, f in itertools.product(squares, squares):
            if s != f:
                assert square_hit(s, f) == _sampled_hit(s, f), (s, f)


@pytest.mark.slow
def test_square_hit_matches_sampled_overlap_further_out() -> None:
    for parity in (0, 1):
        squares = _squares(parity, 9)
        for s, f in itertools.product(squares, squares):
            if s != f and abs(s[0]) + abs(s[1]) <= 12:
                assert square_hit(s, f) == _sampled_hit(s, f, 721), (s, f)


def test_known_sweeps() -> None:
    # a square rod turning about its own centre sweeps the disc of radius sqrt(1/2): its four
    # edge neighbours, not the diagonal ones
    assert swept_squares((0, 0), 1) == ((-2, 0), (0, -2), (0, 0), (0, 2), (2, 0))
    # about its own corner its far corner (radius 2 sqrt 2) passes over the cells above it
    assert swept_squares((1, 1), 1) == ((-1, 1), (-1, 3), (1, 1), (1, 3))
    assert swept_squares((1, 1), -1) == ((1, -1), (1, 1), (3, -1), (3, 1))
    # the edge neighbour of the axis cell swings round past the diagonal cell
    assert swept_squares((2, 0), 1) == ((0, 0), (0, 2), (0, 4), (2, 0), (2, 2), (4, 0))


@given(st.integers(-9, 9), st.integers(-9, 9), st.integers(-9, 9), st.integers(-9, 9))
def test_relative_motion_is_symmetric(a: int, b: int, c: int, d: int) -> None:
    """s turning +90 meets f exactly when f turning -90 meets s (the same relative motion)."""
    s, f = (a, b - (a - b) % 2), (c - (c - a) % 2, d - (d - a) % 2)
    assert (f in swept_squares(s, 1)) == (s in swept_squares(f, -1))


def test_fcl_screw_motion_agrees_with_the_exact_test() -> None:
    """FCL (eroded cube meshes, screw motion sampled every 0.1 degree) on single cubes."""
    checked = 0
    for c2 in ((0, 0, 0), (1, 1, 0)):
        squares = [s for s in _squares(c2[0] % 2, 4) if abs(s[0]) + abs(s[1]) <= 5]
        for s, f in itertools.product(squares, squares):
            if s == f:
                continue
            a = Shape([((s[0] + c2[0]) // 2, (s[1] + c2[1]) // 2, 0)])
            b = Shape([((f[0] + c2[0]) // 2, (f[1] + c2[1]) // 2, 0)])
            assert turning_collision([a], [b], 2, 1, c2) == square_hit(s, f), (c2, s, f)
            checked += 1
    assert checked > 250


@settings(max_examples=60, deadline=None)
@given(scenes(), st.data())
def test_fcl_agrees_with_turn_legality_on_random_scenes(
    pieces: dict[str, Shape], data: st.DataObject
) -> None:
    """Random pieces in a small box, a random group, axis, sense and centre in the group's
    bounding box: the kinematics' exact verdict equals FCL's on the eroded meshes."""
    names = sorted(pieces)
    size = data.draw(st.integers(1, len(names) - 1))
    group = tuple(sorted(data.draw(st.permutations(names))[:size]))
    axis = data.draw(st.integers(0, 2))
    cells = [c for n in group for c in pieces[n]]
    centre = data.draw(st.sampled_from(centres_within(cells, axis)))
    quarter = data.draw(st.sampled_from([1, -1]))
    turn = TurnMove(group, "xyz"[axis], quarter, centre)
    exact = Assembly.assembled(pieces).turn_problem(turn) is None
    assert turn_is_legal(pieces, group, axis, quarter, centre) == exact, turn.describe()


# -- moves and the reference kinematics -------------------------------------------------------


def test_turn_move_is_validated_and_round_trips() -> None:
    t = TurnMove(("red", "blue"), "z", 1, (3, 5, 7))
    assert t.pieces == ("blue", "red") and t.centre2 == (3, 5, 0)
    assert t.describe() == "rotate blue+red z +90 about (1.5,2.5,0)"
    assert turn_from_json(t.to_json()) == t
    assert t.inverse().inverse() == t and t.inverse().quarter == -1
    with pytest.raises(ValueError, match="cell centres or cell corners"):
        TurnMove(("red",), "z", 1, (2, 1, 0))
    with pytest.raises(ValueError):
        TurnMove(("red",), "w", 1, (0, 0, 0))
    with pytest.raises(ValueError):
        turn_from_json({"pieces": ["red"], "axis": "x", "angle": 45, "about": [0, 0, 0]})
    with pytest.raises(ValueError, match="half"):
        turn_from_json({"pieces": ["red"], "axis": "x", "angle": 90, "about": [0, 0.25, 0]})


def test_turn_cells_keep_the_lattice_for_both_kinds_of_axis() -> None:
    assert turn_cells([(1, 0, 0)], 2, 1, (0, 0, 0)) == [(0, 1, 0)]  # about a cell centre
    assert turn_cells([(0, 0, 0)], 2, 1, (1, 1, 0)) == [(1, 0, 0)]  # about a cell corner
    assert turn_cells([(0, 0, 0)], 2, -1, (1, 1, 0)) == [(0, 1, 0)]


def _t_piece() -> dict[str, Shape]:
    # red: an L that can swing round the corner of blue's cell
    return {"blue": Shape([(0, 0, 0)]), "red": Shape([(1, 0, 0), (1, 1, 0)])}


def test_apply_turn_changes_orientation_and_checks_the_sweep() -> None:
    asm = Assembly.assembled(_t_piece())
    # about red's own cell centre it would sweep its edge neighbour, blue, either way
    for q in (1, -1):
        with pytest.raises(MoveError, match="sweep through blue"):
            asm.check(TurnMove(("red",), "z", q, (2, 0, 0)))
    # about the corner at (1.5, -0.5): clockwise it swings away from blue, anticlockwise into it
    with pytest.raises(MoveError, match="sweep through blue"):
        asm.check(TurnMove(("red",), "z", 1, (3, -1, 0)))
    turn = TurnMove(("red",), "z", -1, (3, -1, 0))
    after = asm.apply(turn)
    assert sorted(after.cells_of("red")) == [(2, 0, 0), (3, 0, 0)]
    assert after.rotation_of("red") != 0
    assert after.apply(turn.inverse()).cells_of("red") == asm.cells_of("red")
    with pytest.raises(MoveError, match="bounding box"):
        asm.check(TurnMove(("red",), "z", -1, (9, -1, 0)))
    with pytest.raises(MoveError, match="whole part"):
        asm.check(TurnMove(("blue", "red"), "z", -1, (3, -1, 0)))


def test_state_key_ignores_how_the_whole_part_is_turned() -> None:
    shapes = _t_piece()
    asm = Assembly.assembled(shapes)
    twisted = asm.apply(TurnMove(("red",), "z", -1, (3, -1, 0)))
    # the whole part turned by +90 degrees about z: cells v -> Q v, poses (Q R, Q o)
    whole = Assembly(
        twisted.shapes,
        {n: (-o[1], o[0], o[2]) for n, o in twisted.offsets.items()},
        twisted.parts,
        {n: _compose(2, twisted.rotation_of(n)) for n in twisted.shapes},
    )
    assert state_key(whole) == state_key(twisted)
    assert state_key(twisted) != state_key(asm)


def _compose(axis: int, r: int) -> int:
    from chaingeo.core.geometry import rotation_index
    from chaingeo.core.turns import quarter_matrix

    return rotation_index(quarter_matrix(axis, 1) @ ROTATIONS[r])


def test_replay_with_turns_and_rods() -> None:
    # a square rod in a square hole cannot spin; a round one can
    shapes = {
        "rod": Shape([(1, 1, 0), (1, 1, 1), (1, 2, 1), (2, 2, 1)]),
        "frame": Shape([(0, 1, 0), (2, 1, 0), (1, 0, 0), (1, 2, 0)]),
    }
    spin = TurnMove(("rod",), "z", 1, (2, 2, 0))
    with pytest.raises(MoveError):
        replay_disassembly(shapes, [spin])
    state = replay_disassembly(shapes, [spin], rods={"rod": {(1, 1, 0): 2}})
    assert state.rotation_of("rod") != 0
    assert spin in legal_turns(Assembly.assembled(shapes, {"rod": {(1, 1, 0): 2}}))
    assert spin not in legal_turns(Assembly.assembled(shapes))
    out = replay_disassembly(
        shapes, [spin, Move(("rod",), "+z", None)], rods={"rod": {(1, 1, 0): 2}}
    )
    assert out.is_separated()


@settings(max_examples=25)
@given(small_scenes(max_pieces=3), st.integers(0, 2**16))
def test_turn_then_inverse_returns(shapes: dict[str, Shape], seed: int) -> None:
    asm = Assembly.assembled(shapes)
    turns = legal_turns(asm)
    if not turns:
        return
    t = turns[seed % len(turns)]
    after = asm.apply(t)
    assert state_key(after.apply(t.inverse())) == state_key(asm)
