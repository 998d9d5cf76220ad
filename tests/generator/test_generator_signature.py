"""Split signatures (generator/signature.py) and the train split that holds out the suite."""

from __future__ import annotations

import json
from collections import defaultdict
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from chaingeo.cli.main import main
from chaingeo.core.geometry import IntArray, Shape
from chaingeo.core.level import load_levels
from chaingeo.core.suite import suite_folder
from chaingeo.generator.batch import HELD_OUT, GenerationJob, run
from chaingeo.generator.config import stacking_config
from chaingeo.generator.signature import (
    level_signature,
    puzzle_signature,
    shipped_signatures,
    stacking_signature,
)
from chaingeo.generator.stacking import make
from tests.support.strategies import offsets, polycubes, rotations

pieces = st.lists(polycubes(1, 6), min_size=1, max_size=5)


@settings(max_examples=40, deadline=None)
@given(pieces, st.data(), st.permutations((2, 3, 4)))
def test_stacking_signature_ignores_each_pieces_pose_their_order_and_the_box_turn(
    shapes: list[Shape], data: st.DataObject, box: tuple[int, ...]
) -> None:
    moved = [s.rotate(data.draw(rotations)).translate(data.draw(offsets)) for s in shapes]
    order = data.draw(st.permutations(range(len(shapes))))
    assert stacking_signature([moved[i] for i in order], box) == stacking_signature(
        shapes, (2, 3, 4)
    )
    assert stacking_signature(shapes, (2, 3, 5)) != stacking_signature(shapes, (2, 3, 4))


@settings(max_examples=40, deadline=None)
@given(pieces, rotations, offsets, st.data())
def test_puzzle_signature_ignores_a_common_turn_shift_and_order_but_not_a_piece_moved(
    shapes: list[Shape], rotation: IntArray, offset: tuple[int, int, int], data: st.DataObject
) -> None:
    # Lay the pieces side by side along x (apart, never overlapping): the "assembly".
    laid, x = [], 0
    for s in shapes:
        n = s.normalized()
        laid.append(n.translate((x, 0, 0)))
        x += n.extent[0]
    whole = [s.rotate(rotation).translate(offset) for s in laid]
    order = data.draw(st.permutations(range(len(laid))))
    assert puzzle_signature([whole[i] for i in order]) == puzzle_signature(laid)
    if len(laid) > 1:  # one piece pulled far away: same pieces, another assembled shape
        apart = [*laid[:-1], laid[-1].translate((50, 0, 0))]
        assert puzzle_signature(apart) != puzzle_signature(laid)


def test_a_mirrored_piece_is_another_puzzle() -> None:
    chiral = Shape([(0, 0, 0), (1, 0, 0), (1, 1, 0), (1, 1, 1)])
    assert chiral.is_chiral()
    box = (2, 2, 2)
    assert stacking_signature([chiral], box) != stacking_signature([chiral.mirrored()], box)
    assert puzzle_signature([chiral]) != puzzle_signature([chiral.mirrored()])


def test_every_shipped_level_has_a_signature_and_only_goal_twins_share_one() -> None:
    levels = load_levels(suite_folder())
    owners: dict[str, list[str]] = defaultdict(list)
    for level in levels:
        owners[level_signature(level)].append(level.id)
    assert set(owners) == shipped_signatures() and len(levels) == 109
    shared = [ids for ids in owners.values() if len(ids) > 1]
    # The same puzzle to take apart and to put together: one puzzle, two goals.
    assert sorted(shared) == [
        ["puzzle-easy-02-luban-6-piece", "puzzle-easy-03-luban-6-piece"],
        ["puzzle-mid-01-interlocking-cube", "puzzle-mid-02-interlocking-cube"],
    ]


def test_a_held_out_run_accepts_none_of_the_levels_a_free_run_made(tmp_path: Path) -> None:
    config = stacking_config((2, 3, 4), "mid")
    free = run(GenerationJob("stacking", make, config, 5, 4), tmp_path / "a", progress=False)
    made = {level_signature(lv) for lv in load_levels(tmp_path / "a")}
    assert len(made) == 4
    job = GenerationJob("stacking", make, config, 5, 4, max_items=12, held_out=frozenset(made))
    held = run(job, tmp_path / "b", progress=False)
    kept = {level_signature(lv) for lv in load_levels(tmp_path / "b")}
    assert kept.isdisjoint(made) and held.outcomes[HELD_OUT] >= 1
    assert free.outcomes[HELD_OUT] == 0


def test_generate_split_train_refuses_the_shipped_levels_and_says_so(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # A 2x2x2 box holds one easy puzzle, and the shipped suite has it.
    argv = ["generate", "stacking", "--box", "2x2x2", "--mode", "easy", "--count", "1"]
    argv += ["--max-items", "3", "--out", str(tmp_path), "--no-progress", "--no-pictures"]
    assert main([*argv, "--split", "train"]) == 1
    out, err = capsys.readouterr()
    assert json.loads(out)["outcomes"] == {HELD_OUT: 3}
    assert "skipped 3 level(s) of the shipped suite" in err
    assert main(argv) == 0  # without --split train the same item is accepted
    (level,) = load_levels(tmp_path)
    assert level_signature(level) in shipped_signatures()


def test_curriculum_steps_run_easy_to_hard_and_bad_steps_are_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from chaingeo.generator.curriculum import CURRICULA, STACKING_STEPS, puzzle_step, stacking_step

    modes = [stacking_step(k).mode for k in range(CURRICULA["stacking"])]
    assert modes == sorted(modes, key=("easy", "mid", "hard").index)
    assert [stacking_step(k).box for k in range(len(STACKING_STEPS))] == [
        b for b, _ in STACKING_STEPS
    ]
    levels = [puzzle_step(k).min_level for k in range(CURRICULA["puzzle"])]
    assert levels == sorted(levels)
    base = ["--count", "1", "--out", str(tmp_path), "--no-progress", "--no-pictures"]
    assert main(["generate", "puzzle", "--curriculum", "4", "--split", "train", *base]) == 0
    (level,) = load_levels(tmp_path)
    assert level.difficulty == "hard" and level_signature(level) not in shipped_signatures()
    capsys.readouterr()
    assert main(["generate", "puzzle", "--curriculum", "99", *base]) == 2
    assert "runs from 0 (easiest) to 6" in capsys.readouterr().err
    assert main(["generate", "stacking", "--curriculum", "0", "--box", "2x2x2", *base]) == 2


def test_the_command_line_knows_each_curriculum_s_length_without_importing_it() -> None:
    from chaingeo.cli.commands.generate import CURRICULUM_STEPS
    from chaingeo.generator.curriculum import CURRICULA

    assert CURRICULUM_STEPS == CURRICULA
