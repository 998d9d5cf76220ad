"""The stacking state machine: legal placements, the rules' reasons, undo, keys, step counting."""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from chaingeo.core.geometry import NEIGHBOURS, Cell, Shape
from chaingeo.core.level import Level, stacking_level
from chaingeo.core.rules import placement_problem
from chaingeo.envs.actions.types import (
    FinishAction,
    IllegalActionError,
    PickupAction,
    PlaceAction,
)
from chaingeo.envs.machines.stacking import StackingState, _placements
from tests.support.env_levels import bedlam_level, drop_level, soma_level, tiny_level
from tests.support.strategies import polycubes


def brute_force_legal(state: StackingState) -> list[object]:
    """Every orientation at every offset in the box, filtered by the rules module directly."""
    out: list[object] = []
    occupied = state.occupied()
    bx, by, bz = state.box
    for name in sorted(state.tray):
        for orient in state.tables.shapes[name].orientations():
            ex, ey, ez = orient.extent
            for ox in range(bx - ex + 1):
                for oy in range(by - ey + 1):
                    for oz in range(bz - ez + 1):
                        cells = orient.translate((ox, oy, oz))
                        if placement_problem(cells, occupied, state.box, state.tables.rules):
                            continue
                        out.append(PlaceAction(name, cells.cells))
    for name in sorted(state.placed):
        if state.problem(PickupAction(name)) is None:
            out.append(PickupAction(name))
    return [*sorted(out), FinishAction()]  # type: ignore[type-var]


def walk(level: Level, choices: list[int]) -> StackingState:
    """The state reached by taking legal actions (never finish) chosen by ``choices``."""
    state = StackingState(level)
    for c in choices:
        legal = [a for a in state.legal_actions() if not isinstance(a, FinishAction)]
        if not legal:
            break
        state.apply(legal[c % len(legal)])
    return state


@settings(max_examples=40)
@given(
    st.sampled_from(["tiny", "drop", "soma"]),
    st.lists(st.integers(0, 10_000), max_size=6),
)
def test_legal_actions_equal_the_rules(which: str, choices: list[int]) -> None:
    level = {"tiny": tiny_level, "drop": drop_level, "soma": soma_level}[which]()
    state = walk(level, choices)
    legal = state.legal_actions()
    assert legal == sorted(legal)
    assert legal == brute_force_legal(state)
    for action in legal:
        assert state.problem(action) is None
    catalogue = set(state.catalogue())
    assert all(a in catalogue for a in legal)


def test_place_accepts_any_rotation_and_explains_refusals() -> None:
    state = StackingState(soma_level())
    name = state.tray[0]
    shape = state.tables.shapes[name]
    turned = shape.orientations()[-1]
    assert state.problem(PlaceAction(name, turned.cells)) is None  # at the origin, on the floor
    state.apply(PlaceAction(name, turned.cells))
    first = next(iter(turned.cells))
    other = state.tray[0]
    other_shape = state.tables.shapes[other]
    cases = {
        "unknown piece 'pink'": PlaceAction("pink", ((0, 0, 0),)),
        "already in the box": PlaceAction(name, turned.cells),
        f"{other} has {len(other_shape)} cubes but 1 cells were given": PlaceAction(
            other, ((2, 2, 2),)
        ),
        "not the shape of": PlaceAction(other, tuple((0, 0, z) for z in range(len(other_shape)))),
        "out of box at (": PlaceAction(other, other_shape.translate((2, 2, 0)).cells),
        f"collision with {name} at (": PlaceAction(
            other,
            other_shape.translate(first).cells,
        ),
    }
    for reason, action in cases.items():
        why = state.problem(action)
        assert why is not None and reason in why, (reason, why)
        with pytest.raises(IllegalActionError) as err:
            state.apply(action)
        assert reason in err.value.reason
    assert state.steps_used == 1
    flat = min(other_shape.orientations(), key=lambda o: o.extent[2])  # at most 2 high
    fresh = StackingState(soma_level())
    assert "floating" in (fresh.problem(PlaceAction(other, flat.translate((0, 0, 1)).cells)) or "")


def test_reasons_quote_one_based_cells() -> None:
    state = StackingState(tiny_level())
    red = state.level.solution.placements["red"]  # type: ignore[union-attr]
    state.apply(PlaceAction("red", red.cells))
    clash = state.problem(PlaceAction("red", red.cells))
    assert clash is not None
    result = state.step_text("place green (1,1,1) (1,1,2)")
    assert not result.legal and result.error == "illegal"
    assert "collision with red at (1,1,1)" in result.feedback


def test_drop_rule_and_pickup_rules() -> None:
    level = drop_level()
    placements = level.solution.placements  # type: ignore[union-attr]
    state = StackingState(level)
    lid, left, right = (placements[n] for n in ("red", "green", "yellow"))
    state.apply(PlaceAction("green", left.cells))
    # under the drop rule the lid cannot go in before the second column
    state.apply(PlaceAction("red", lid.cells))
    why = state.problem(PlaceAction("yellow", right.cells))
    assert why is not None and "cannot be lowered into place: red is above it" in why
    assert "rests on top of it" in (state.problem(PickupAction("green")) or "")
    state.pop()
    state.apply(PlaceAction("yellow", right.cells))
    state.apply(PlaceAction("red", lid.cells))
    assert state.is_success() and state.steps_used == 3


def test_pickup_may_not_leave_a_piece_floating() -> None:
    level = stacking_level("tower", "easy", (1, 1, 2), [Shape([(0, 0, 0)]), Shape([(0, 0, 1)])])
    state = StackingState(level)
    state.apply(PlaceAction("red", ((0, 0, 0),)))
    state.apply(PlaceAction("green", ((0, 0, 1),)))
    assert state.is_success()
    assert state.problem(PickupAction("red")) == "green would be left floating"
    state.apply(PickupAction("green"))
    assert state.tray == ["green"] and not state.is_success()
    assert state.problem(PickupAction("green")) == "green is not in the box"
    assert PickupAction("red") in state.legal_actions()


def test_push_pop_clone_and_key() -> None:
    level = soma_level()
    placements = level.solution.placements  # type: ignore[union-attr]
    order = list(level.solution.order)  # type: ignore[union-attr]
    a = StackingState(level)
    start = a.key()
    a.push(PlaceAction(order[0], placements[order[0]].cells))
    b = a.clone()
    b.push(PlaceAction(order[1], placements[order[1]].cells))
    assert a.steps_used == 1 and b.steps_used == 2 and a.key() != b.key()
    assert b.pop() == PlaceAction(order[1], placements[order[1]].cells)
    assert b.key() == a.key() and b.steps_used == 1
    popped = a.pop()
    assert isinstance(popped, PlaceAction) and popped.piece == order[0]
    assert a.key() == start and a.steps_used == 0
    with pytest.raises(IndexError):
        a.pop()
    # the key is the position, whatever the order it was reached in
    grounded = [n for n in order if any(z == 0 for _, _, z in placements[n].cells)][:2]
    c, d = StackingState(level), StackingState(level)
    for s, names in ((c, grounded), (d, grounded[::-1])):
        for n in names:
            s.apply(PlaceAction(n, placements[n].cells))
    assert c.key() == d.key() and hash(c.key()) == hash(d.key())


def test_step_text_counts_every_turn_and_finish_ends_the_game() -> None:
    level = tiny_level()
    state = StackingState(level)
    r = state.step_text("hello")
    assert (r.legal, r.error, r.action, r.success) == (False, "unparseable", None, False)
    r = state.step_text("pickup red")
    assert (r.legal, r.error) == (False, "illegal") and "red is not in the box" in r.feedback
    assert state.steps_used == 2 and state.key() == StackingState(level).key()
    r = state.step_text("finish")
    assert r.legal and r.feedback.startswith("Finished without solving")
    assert state.finished and state.legal_actions() == []
    r = state.step_text("pickup red")
    assert "the game is over" in r.feedback
    assert [t.step for t in state.history] == [1, 2, 3, 4]


def test_truncation_at_the_budget() -> None:
    state = StackingState(tiny_level())
    for i in range(state.max_steps):
        r = state.step_text("nonsense")
        assert r.truncated == (i == state.max_steps - 1)
    assert state.is_truncated() and state.steps_left == 0


def test_bedlam_plays_out_and_enumerates_fast_enough_to_mask() -> None:
    level = bedlam_level()
    state = StackingState(level)
    catalogue = state.catalogue()
    assert len(catalogue) == len(set(catalogue)) and catalogue == sorted(catalogue)
    for name in level.solution.order:  # type: ignore[union-attr]
        cells = level.solution.placements[name].cells  # type: ignore[union-attr]
        assert PlaceAction(name, cells) in state.legal_actions()
        state.apply(PlaceAction(name, cells))
    assert state.is_success() and state.empty_cells() == 0


def test_tray_keeps_the_handed_orientation() -> None:
    level = soma_level()
    state = StackingState(level)
    for p in level.pieces:
        assert state.tables.shapes[p.name] == p.shape
        assert Shape(p.shape.cells).normalized().cells in state.tables.orientations[p.name]


def _reference_placement(cells: tuple[Cell, ...], box: tuple[int, int, int]) -> tuple[object, ...]:
    """(cells, mask, around, floor, above) of one placement, cell by cell from the definitions."""
    _, by, bz = box
    own = set(cells)

    def bits(found: set[Cell]) -> int:
        return sum(1 << ((x * by + y) * bz + z) for x, y, z in found)

    def inside(c: Cell) -> bool:
        return all(0 <= c[i] < box[i] for i in range(3))

    around = {
        n
        for x, y, z in own
        for dx, dy, dz in NEIGHBOURS
        if inside(n := (x + dx, y + dy, z + dz)) and n not in own
    }
    above = {(x, y, h) for x, y, z in own for h in range(z + 1, bz) if (x, y, h) not in own}
    return cells, bits(own), bits(around), any(z == 0 for _, _, z in own), bits(above)


@settings(max_examples=60, deadline=None)
@given(polycubes(1, 6), st.tuples(st.integers(1, 5), st.integers(1, 5), st.integers(1, 5)))
def test_placement_tables_are_the_cell_by_cell_definitions(
    shape: Shape, box: tuple[int, int, int]
) -> None:
    """The tables' masks, computed for every orientation and offset at once, are the cells each
    placement fills, the box cells beside it, whether it touches the floor and the box cells
    above it, one placement at a time; every placement inside the box, sorted by cells."""
    orients = shape.orientations()
    expected = sorted(
        _reference_placement(o.translate((x, y, z)).cells, box)
        for o in orients
        for x in range(box[0] - o.extent[0] + 1)
        for y in range(box[1] - o.extent[1] + 1)
        for z in range(box[2] - o.extent[2] + 1)
    )
    found = _placements("p", orients, box)
    assert [(p.action.cells, p.mask, p.around, p.floor, p.above) for p in found] == expected
    assert all(p.action == PlaceAction("p", p.action.cells) for p in found)


def test_states_of_one_level_share_its_tables_while_it_lives() -> None:
    """Every state of a level object reads one set of tables (an environment resets without
    rebuilding them); another object gets its own; the entry leaves with its level."""
    import dataclasses
    import gc

    from chaingeo.envs.machines import stacking

    level = tiny_level()
    first, second = StackingState(level), StackingState(level)
    assert first.tables is second.tables is stacking.tables_of(level)
    other = dataclasses.replace(level)
    assert StackingState(other).tables is not first.tables
    key = id(other)
    del other
    gc.collect()
    assert key not in stacking._BUILT
