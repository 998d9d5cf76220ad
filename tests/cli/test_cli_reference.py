"""docs/reference/commands.md is what ``python -m chaingeo.cli.reference`` writes from the parser:
regenerate it after changing a command's arguments."""

from __future__ import annotations

import argparse
from pathlib import Path

import pytest

from chaingeo.cli import reference
from chaingeo.cli.main import build_parser
from tests.support.paths import ROOT

COMMITTED = ROOT / reference.DEFAULT_PATH


def test_the_committed_reference_is_up_to_date() -> None:
    assert COMMITTED.is_file(), f"missing {COMMITTED}: python -m chaingeo.cli.reference"
    assert COMMITTED.read_text(encoding="utf-8") == reference.reference(), (
        "docs/reference/commands.md is out of date: run python -m chaingeo.cli.reference"
    )


def test_every_command_and_option_is_in_the_reference() -> None:
    text = reference.reference()
    for names, _, parser in reference.subcommands(build_parser()):
        assert f"## `chain {' '.join(names)}`" in text
        for action in parser._actions:
            for flag in action.option_strings:
                if flag.startswith("--") and action.help != argparse.SUPPRESS:
                    assert f"`{flag}" in text, (names, flag)


def test_check_mode_tells_a_stale_file(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    target = tmp_path / "docs" / "commands.md"
    assert reference.main([str(target), "--check"]) == 1
    assert reference.main([str(target)]) == 0
    assert reference.main([str(target), "--check"]) == 0
    target.write_text(target.read_text() + "edited by hand\n")
    assert reference.main([str(target), "--check"]) == 1
    assert "out of date" in capsys.readouterr().err


def test_the_usage_lines_do_not_depend_on_the_terminal(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("COLUMNS", "40")
    narrow = reference.reference()
    monkeypatch.setenv("COLUMNS", "250")
    assert reference.reference() == narrow
