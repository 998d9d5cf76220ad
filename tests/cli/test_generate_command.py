"""``chain generate``: the command line face of the generator."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from chaingeo.cli.main import main
from chaingeo.core.level import load_levels


def test_generate_stacking_writes_levels_pictures_and_a_summary(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "out"
    argv = ["generate", "stacking", "--box", "2x2x3", "--mode", "easy", "--count", "2"]
    argv += ["--seed", "3", "--out", str(out), "--no-progress"]
    assert main(argv) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["accepted"] == 2 and summary["config"]["box"] == [2, 2, 3]
    levels = load_levels(out)
    assert [lv.id for lv in levels] == summary["levels"]
    assert all(lv.difficulty == "easy" and lv.box == (2, 2, 3) for lv in levels)
    assert sorted(p.name for p in (out / "pictures").iterdir()) == sorted(
        f"{lv.id}-{view}.png" for lv in levels for view in ("assembly", "pieces")
    )
    assert (out / "summary.jsonl").exists()


def test_generate_stacking_by_config_name_with_overrides(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    argv = ["generate", "stacking", "--config", "2x3x3-hard", "--min-nodes", "30", "--count", "1"]
    argv += ["--out", str(tmp_path), "--no-progress", "--no-pictures", "--seed", "1"]
    assert main(argv) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["config"]["min_nodes"] == 30 and summary["accepted"] == 1
    (level,) = load_levels(tmp_path)
    assert level.stats["exact_cover"]["nodes_first"] >= 30
    assert not (tmp_path / "pictures").exists()


def test_a_run_that_falls_short_exits_1(tmp_path: Path) -> None:
    argv = ["generate", "stacking", "--box", "2x2x2", "--mode", "easy", "--count", "2"]
    argv += ["--max-items", "3", "--out", str(tmp_path), "--no-progress", "--no-pictures"]
    assert main(argv) == 1  # the 2x2x2 box holds a single easy puzzle


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (["--box", "3x3"], "not of the form AxBxC"),
        (["--box", "3x3x3"], "--box and --mode are required"),
        (["--config", "3x3x3-hard", "--box", "3x3x3"], "either --config or --box/--mode"),
        (["--config", "nope"], "no stacking config named 'nope'"),
        (["--box", "3x3x3", "--mode", "hard", "--min-piece", "9"], "min_piece"),
        (["--box", "3x3x3", "--mode", "hard", "--jobs", "0"], "jobs must be >= 1"),
    ],
)
def test_bad_options_are_one_clear_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], extra: list[str], message: str
) -> None:
    argv = ["generate", "stacking", *extra, "--out", str(tmp_path), "--no-progress"]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith("chain generate: error: ") and message in err
