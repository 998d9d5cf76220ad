"""Demonstrations: each level's stored optimal plan replayed through the environment, as JSONL."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from chaingeo.envs.demos import demonstration_lines, plan_texts, write_demonstrations
from tests.support.env_levels import puzzle_levels, soma_level


def test_demonstrations_replay_every_plan_to_success_deterministically(tmp_path: Path) -> None:
    levels = [soma_level(), *list(puzzle_levels())[:2]]
    path = tmp_path / "demos.jsonl"
    count = write_demonstrations(levels, path)
    lines = path.read_text(encoding="ascii").splitlines()
    assert count == len(lines) == sum(lv.optimal_steps for lv in levels)
    assert lines == list(demonstration_lines(reversed(levels)))  # same bytes, any input order
    records = [json.loads(line) for line in lines]
    for level in levels:
        mine = [r for r in records if r["level_id"] == level.id]
        assert [r["action"] for r in mine] == plan_texts(level)
        assert [r["reward"] for r in mine] == [0.0] * (len(mine) - 1) + [1.0]
        assert mine[-1]["terminated"] and not any(r["terminated"] for r in mine[:-1])
        assert mine[0]["observation"].startswith(("Pack all", "Take the", "Put the"))


def test_chain_demos_writes_the_same_lines_and_names_a_bad_level(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from chaingeo.cli.main import main
    from chaingeo.core.level import load_level
    from chaingeo.core.suite import suite_folder

    path = tmp_path / "d.jsonl"
    level_id = "puzzle-easy-07-burr3"
    assert main(["demos", level_id, "--text-state", "--out", str(path)]) == 0
    level = load_level(suite_folder() / "puzzle" / f"{level_id}.json")
    expected = list(demonstration_lines([level], text_state=True))
    assert path.read_text(encoding="ascii").splitlines() == expected
    assert "Current state:" in json.loads(expected[0])["observation"]
    assert main(["demos", "no-such-level"]) == 2
    assert "no-such-level" in capsys.readouterr().err
