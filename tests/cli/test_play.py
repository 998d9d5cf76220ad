"""``chain play``: the terminal game, driven through stdin."""

from __future__ import annotations

import io
from pathlib import Path

import pytest

from chaingeo.cli.main import main
from chaingeo.core.level import save_level
from tests.support.env_levels import tiny_level


def run_play(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str], args: list[str], text: str
) -> tuple[int, str]:
    monkeypatch.setattr("sys.stdin", io.StringIO(text))
    code = main(["play", *args])
    captured = capsys.readouterr()
    return code, captured.out + captured.err


def test_play_to_the_end_with_undo(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    path = save_level(tiny_level(), tmp_path / "tiny.json")
    moves = [
        "place red (1,1,1) (2,1,1) (1,2,1)",
        "place nothing",
        "undo",
        "undo",
        "",
        "help",
        "place red (1,1,1) (2,1,1) (1,2,1)",
        "place green (2,2,1) (2,2,2)",
        "place yellow (1,1,2) (2,1,2) (1,2,2)",
    ]
    code, out = run_play(monkeypatch, capsys, [str(path), "--no-images"], "\n".join(moves) + "\n")
    assert code == 0
    assert "OK: red placed." in out and "Could not read the action 'place nothing'" in out
    assert "Undone: place red (1,1,1) (1,2,1) (2,1,1) (your last turn was refused" in out
    assert "Nothing to undo: no action has been carried out" in out
    assert "Solved in 4 steps (optimal: 3)." in out  # the refused turn stays counted
    assert "In the box:" in out and "Steps used: 2 of 30" in out


def test_play_by_id_quit_and_errors(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    save_level(tiny_level(), tmp_path / "levels" / "tiny.json")
    code, out = run_play(
        monkeypatch,
        capsys,
        ["tiny-test", "--levels", str(tmp_path / "levels"), "--no-images"],
        "pickup red\nquit\n",
    )
    assert code == 1 and "red is not in the box" in out
    code, out = run_play(
        monkeypatch, capsys, ["nope", "--levels", str(tmp_path), "--no-images"], ""
    )
    assert code == 2 and "no level file or level id 'nope'" in out


def test_play_writes_fresh_views(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    path = save_level(tiny_level(), tmp_path / "tiny.json")
    views = tmp_path / "views"
    code, out = run_play(
        monkeypatch,
        capsys,
        [str(path), "--views", str(views), "--size", "128"],
        "place red (1,1,1) (2,1,1) (1,2,1)\n",
    )
    assert code == 1
    assert f"view iso: {views / 'iso.png'}" in out
    assert (views / "tray.png").read_bytes().startswith(b"\x89PNG")
