"""Observations: instruction, colour table, history window, text state, pictures."""

from __future__ import annotations

import random

import numpy as np

from chaingeo.core.geometry import Shape
from chaingeo.core.kinematics import Move
from chaingeo.envs.actions.types import MoveAction
from chaingeo.envs.demos import plan_texts
from chaingeo.envs.gym import PuzzleEnv
from chaingeo.envs.machines import new_state
from chaingeo.envs.machines.puzzle import PuzzleState
from chaingeo.envs.observation import observe, ordered_parts, scene, state_text
from tests.support.env_levels import drop_level, puzzle_levels, soma_level


def puzzle(level_id: str):  # type: ignore[no-untyped-def]
    return new_state(next(lv for lv in puzzle_levels() if lv.id == level_id))


def test_stacking_observation_text() -> None:
    state = new_state(soma_level())
    state.step_text("place orange (3,1,1) (3,2,1) (3,2,2) (3,3,1)")
    for i in range(6):
        state.step_text(f"nonsense {i}")
    obs = observe(state, history_window=3, text_state=True, images=False)
    assert "3x3x3 box" in obs.instruction and "place COLOUR (x,y,z)" in obs.instruction
    assert obs.color_table["orange"] == f"{soma_level().piece('orange').rgb}, 4 cubes"
    assert [h.split(":")[0] for h in obs.history] == ["step 5", "step 6", "step 7"]
    assert obs.steps_left == soma_level().max_steps - 7
    assert obs.images == {}
    assert obs.text_state is not None
    assert "  orange: (3,1,1) (3,2,1) (3,2,2) (3,3,1)" in obs.text_state
    assert "In the tray" in obs.text_state and "orange" not in obs.text_state.split("tray")[1]
    text = obs.to_text()
    assert text.startswith(obs.instruction) and "Steps left: 23" in text
    assert observe(state, history_window=0, images=False).history == []
    assert observe(state, images=False).text_state is None


def test_drop_rule_is_in_the_instruction() -> None:
    assert "lowerable straight down" in observe(new_state(drop_level()), images=False).instruction


def test_puzzle_text_state_lists_parts_and_the_target() -> None:
    state = puzzle("lock3-disassemble")
    state.apply(MoveAction(Move(("green",), "+z", None)))
    text = state_text(state)
    assert text.startswith("2 parts")
    assert "part 2 (apart): green" in text and "    red: (1,1,1) (2,1,1) (3,1,1)" in text
    assemble = puzzle("lock3-assemble")
    text = state_text(assemble)
    assert text.startswith("3 parts") and "Target (every piece in its place):" in text
    assert "offset (dx,dy,dz)" in observe(assemble, images=False).instruction


def test_puzzle_scene_lays_separate_parts_out_without_overlap() -> None:
    state = puzzle("lock3-disassemble")
    state.apply(MoveAction(Move(("red",), "-x", 1)))
    state.apply(MoveAction(Move(("green",), "+z", None)))
    pieces, box, tray = scene(state)
    assert box is None and tray == {}
    cells = [c for shape, _ in pieces.values() for c in shape.cells]
    assert len(cells) == len(set(cells))
    # the largest part stays where it is
    assert pieces["red"][0].cells == state.cells_of("red")


def test_images_are_png_per_view() -> None:
    obs = observe(new_state(soma_level()), image_size=128)
    assert sorted(obs.images) == ["front", "iso", "side", "top", "tray"]
    assert all(png.startswith(b"\x89PNG") for png in obs.images.values())
    assert observe(new_state(soma_level()), image_size=128).images == obs.images
    obs = observe(puzzle("lock3-assemble"), image_size=128)
    assert "target" in obs.images


def _scene_cell_by_cell(state: PuzzleState) -> dict[str, tuple[Shape, str]]:
    """The puzzle scene as it was first written: each piece from ``state.cells_of``."""
    rgb = {p.name: p.rgb for p in state.level.pieces}
    pieces: dict[str, tuple[Shape, str]] = {}
    cursor: int | None = None
    for part in ordered_parts(state):
        cells = {n: state.cells_of(n) for n in sorted(part)}
        shift = (
            (0, 0, 0)
            if cursor is None
            else (cursor - min(c[0] for cs in cells.values() for c in cs), 0, 0)
        )
        for n, cs in cells.items():
            pieces[n] = (Shape(cs).translate(shift), rgb[n])
        cursor = max(c[0] for n in part for c in pieces[n][0].cells) + 1 + 2  # a gap of 2
    return pieces


def test_puzzle_scene_is_the_cells_piece_by_piece_along_plans_and_random_moves() -> None:
    rng = random.Random(23)
    levels = list(PuzzleEnv(images=False).levels.values())
    turned = 0
    for level in rng.sample(levels, 10):
        state = new_state(level)
        assert isinstance(state, PuzzleState)
        for text in [*plan_texts(level)[:-1], *["?"] * 6]:
            if text == "?":
                moves = [a for a in state.legal_actions() if a.to_text() != "finish"]
                if not moves:
                    break
                text = rng.choice(moves).to_text()
            state.step_text(text)
            pieces, _, _ = scene(state)
            expected = _scene_cell_by_cell(state)
            assert list(pieces) == list(expected)
            for name, (shape, color) in pieces.items():
                assert shape == expected[name][0] and color == expected[name][1]
                assert np.array_equal(shape.voxels, expected[name][0].voxels)
            turned += any(state.assembly.rotation_of(n) for n in pieces)
    assert turned  # some states have turned pieces
