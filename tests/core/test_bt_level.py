"""Our levels written as BurrTools files (``chain convert LEVEL --to xmpuzzle``): every shipped
level read back is its own assembly, piece for piece, with the union as the result."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from chaingeo.cli.main import main
from chaingeo.core.formats.bt_level import level_puzzle, rules_not_carried
from chaingeo.core.formats.burrtools import read_xmpuzzle, write_xmpuzzle
from chaingeo.core.geometry import Shape
from chaingeo.core.level import Level, StackingSolution
from chaingeo.core.suite import suite_folder
from tests.support.shipped import shipped

LEVELS = shipped()


def _assembled(level: Level) -> dict[str, Shape]:
    if isinstance(level.solution, StackingSolution):
        return dict(level.solution.placements)
    return level.shapes


def _same_up_to_shift(a: dict[str, Shape], b: dict[str, Shape]) -> bool:
    """The same pieces in the same relative places (the file's frame starts at 0)."""
    base_a = np.concatenate([s.voxels for s in a.values()]).min(axis=0)
    base_b = np.concatenate([s.voxels for s in b.values()]).min(axis=0)
    return sorted(a) == sorted(b) and all(
        Shape(a[n].voxels - base_a) == Shape(b[n].voxels - base_b) for n in a
    )


@pytest.mark.parametrize("level", LEVELS, ids=lambda lv: lv.id)
def test_every_shipped_level_reads_back_as_its_own_assembly(level: Level, tmp_path: Path) -> None:
    path = write_xmpuzzle(level_puzzle(level), tmp_path / f"{level.id}.xmpuzzle")
    back = read_xmpuzzle(path)
    (problem,) = back.problems
    assert [back.shapes[p.shape].name for p in problem.parts] == sorted(level.shapes)
    assert all((p.min, p.max) == (1, 1) for p in problem.parts)
    (stored,) = back.assemblies(0)
    names = [back.shapes[p.shape].name or "" for p in problem.parts]
    by_name = {names[slot]: shape for slot, shape in stored.items()}
    assembled = _assembled(level)
    assert _same_up_to_shift(by_name, assembled)
    union = Shape(np.concatenate([s.voxels for s in by_name.values()]))
    assert back.shapes[problem.result].filled == union.normalized()


def test_rules_burrtools_cannot_carry_are_named() -> None:
    by_id = {lv.id: lv for lv in LEVELS}
    assert rules_not_carried(by_id["puzzle-easy-01-luban-3-piece"]) == [
        "turns (BurrTools only slides pieces)"
    ]
    assert all(
        rules_not_carried(lv) == []
        for lv in LEVELS
        if lv.family == "stacking" or not (lv.rules.to_json().get("turns"))
        if lv.rules.to_json().get("max_group") is None
    )


def test_convert_takes_a_level_id_or_file_and_writes_the_same_bytes(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    level = next(lv for lv in LEVELS if lv.id == "puzzle-mid-04-burr12")
    by_id, by_file = tmp_path / "a.xmpuzzle", tmp_path / "b.xmpuzzle"
    assert main(["convert", level.id, "--to", "xmpuzzle", "--out", str(by_id)]) == 0
    source = suite_folder("puzzle") / f"{level.id}.json"
    assert main(["convert", str(source), "--out", str(by_file), "--to", "xmpuzzle"]) == 0
    assert by_id.read_bytes() == by_file.read_bytes()
    capsys.readouterr()
    turned = tmp_path / "c.xmpuzzle"
    assert (
        main(["convert", "puzzle-easy-01-luban-3-piece", "--to", "xmpuzzle", "--out", str(turned)])
        == 0
    )
    assert "not carried into the BurrTools file: turns" in capsys.readouterr().err


def test_convert_refuses_an_unknown_level_and_a_missing_target(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["convert", "no-such-level", "--to", "xmpuzzle", "--out", str(tmp_path / "x")]) == 2
    assert "no level file or level id 'no-such-level'" in capsys.readouterr().err
    assert main(["convert", "puzzle-mid-04-burr12", "--to", "xmpuzzle"]) == 2
    assert "needs a target file" in capsys.readouterr().err
    assert not any(tmp_path.iterdir())
