"""One command-line grammar: a level file or a shipped level's id wherever a level is taken (one
resolver, one error naming both), outputs by ``--out`` (folders created), ``chain convert``'s
old positional target still working with a warning."""

from __future__ import annotations

import io
import shutil
from pathlib import Path

import pytest

from chaingeo.cli.main import main
from chaingeo.core.suite import suite_folder

PUZZLE = "puzzle-easy-01-luban-3-piece"
STACKING = "stacking-2x2x2-easy-s101-000000"
SMALL_PUZZLE = "puzzle-easy-07-burr3"  # quick to analyse


@pytest.fixture
def suite(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """Three levels of the shipped suite as the whole suite, so an unknown id is quick to refuse."""
    folder = tmp_path / "suite"
    for family, level_id in (("puzzle", PUZZLE), ("puzzle", SMALL_PUZZLE), ("stacking", STACKING)):
        (folder / family).mkdir(parents=True, exist_ok=True)
        shutil.copy(suite_folder(family) / f"{level_id}.json", folder / family)
    monkeypatch.setattr("chaingeo.core.suite.suite_folder", lambda family=None: folder)
    monkeypatch.setattr("sys.stdin", io.StringIO(""))  # chain play: end of input at once
    return folder


#: Every command that takes a level, with the level (``{puzzle}`` or ``{stacking}``) as an id,
#: and its exit status when it runs (2: it fails later, on another input, after the level).
TAKES_A_LEVEL: dict[str, tuple[list[str], int]] = {
    "render": (["render", "{puzzle}", "--out", "{tmp}/new/pictures", "--size", "128"], 0),
    "export": (["export", "{puzzle}", "--format", "stl", "--out", "{tmp}/new/mesh.stl"], 0),
    "convert": (["convert", "{puzzle}", "--to", "xmpuzzle", "--out", "{tmp}/p.xmpuzzle"], 0),
    "validate": (["validate", "{puzzle}", "--no-recheck"], 0),
    "play": (["play", "{puzzle}", "--no-images"], 1),
    "cover": (["cover", "--pieces", "{stacking}"], 0),
    "demos": (["demos", "{stacking}"], 0),
    "video": (["video", "{puzzle}", "--out", "{tmp}/v/plan.gif", "--size", "128"], 0),
    "worldmodel": (
        ["worldmodel", "{puzzle}", "--out", "{tmp}/wm", "--size", "128", "--format", "gif"],
        0,
    ),
    "check-trajectory": (["check-trajectory", "{puzzle}", "{tmp}/no-trajectory.json"], 2),
    "judge-video": (["judge-video", "{tmp}/no-video.gif", "--level", "{puzzle}"], 2),
    "export-dataset": (
        ["export-dataset", "{stacking}", "--out", "{tmp}/ds", "--image-size", "128"],
        0,
    ),
    "analyze": (["analyze", "{small}"], 0),
    "eval": (
        [
            "eval",
            "--levels",
            "{stacking}",
            "--agent",
            "oracle",
            "--out",
            "{tmp}/r",
            "--no-progress",
        ],
        0,
    ),
}


def _argv(template: list[str], tmp: Path, puzzle: str, stacking: str, small: str) -> list[str]:
    return [a.format(tmp=tmp, puzzle=puzzle, stacking=stacking, small=small) for a in template]


@pytest.mark.parametrize("command", sorted(TAKES_A_LEVEL))
def test_a_level_id_is_taken_by_every_command_that_takes_a_level(
    command: str, suite: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    template, status = TAKES_A_LEVEL[command]
    assert main(_argv(template, tmp_path, PUZZLE, STACKING, SMALL_PUZZLE)) == status
    err = capsys.readouterr().err
    assert "level id" not in err and "level file" not in err, err
    if status == 2:  # failed on its other input, so the level was read first
        assert "no-trajectory.json" in err or "no-video.gif" in err, err


@pytest.mark.parametrize("command", sorted(TAKES_A_LEVEL))
def test_an_unknown_level_is_one_error_line_naming_file_and_id(
    command: str, suite: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    template, _ = TAKES_A_LEVEL[command]
    assert main(_argv(template, tmp_path, *["no-such-level"] * 3)) == 2
    captured = capsys.readouterr()
    lines = captured.err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"chain {command}: error:"), captured.err
    if command == "cover":  # --pieces also names piece sets
        assert "no such file or level id" in lines[0]
    else:
        assert "no level file or level id 'no-such-level' (no such file; none in" in lines[0]
    assert not (tmp_path / "new").exists()


def test_a_level_file_is_still_taken(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "copy.json"
    shutil.copy(suite_folder("puzzle") / f"{PUZZLE}.json", path)
    assert main(["export", str(path), "--out", str(tmp_path / "m.glb")]) == 0
    assert (tmp_path / "m.glb").stat().st_size > 0


def test_out_folders_are_created_and_out_files_get_their_folder(
    suite: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    folder = tmp_path / "a" / "b"
    assert main(["render", PUZZLE, "--out", str(folder), "--size", "128"]) == 0
    printed = capsys.readouterr().out.split()
    assert sorted(printed) == sorted(str(p) for p in folder.iterdir()) and len(printed) == 5
    mesh = tmp_path / "c" / "d" / "m.obj"
    assert main(["export", PUZZLE, "--format", "obj", "--out", str(mesh)]) == 0
    assert mesh.is_file()


def test_an_out_folder_that_is_a_file_is_one_error_line(
    suite: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    taken = tmp_path / "taken"
    taken.write_text("x")
    assert main(["render", PUZZLE, "--out", str(taken), "--size", "128"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [f"chain render: error: --out: {taken} is a file; a folder is needed here"]


@pytest.mark.parametrize(
    ("out", "expected"),
    [
        ("new-folder", "new-folder/L.json"),
        ("deep/new/folder", "deep/new/folder/L.json"),
        ("level.json", "level.json"),
        ("sub/level.JSON", "sub/level.JSON"),
    ],
)
def test_import_out_is_a_json_file_or_a_folder(tmp_path: Path, out: str, expected: str) -> None:
    from chaingeo.cli.commands.import_model import import_target

    target = import_target(tmp_path / out, "L")
    assert target == tmp_path / expected
    # a new folder is made, never taken as a file's name; a file is left to the writer
    assert (tmp_path / out).is_dir() == (target.name == "L.json")
    assert not target.exists()


def test_import_out_an_existing_folder_named_like_a_file(tmp_path: Path) -> None:
    from chaingeo.cli.commands.import_model import import_target

    (tmp_path / "odd.json").mkdir()
    assert import_target(tmp_path / "odd.json", "L") == tmp_path / "odd.json" / "L.json"


def test_convert_positional_target_is_deprecated_but_works(
    suite: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    new, old = tmp_path / "new.xmpuzzle", tmp_path / "old.xmpuzzle"
    assert main(["convert", PUZZLE, "--to", "xmpuzzle", "--out", str(new)]) == 0
    assert "deprecated" not in capsys.readouterr().err
    assert main(["convert", PUZZLE, str(old), "--to", "xmpuzzle"]) == 0
    captured = capsys.readouterr()
    assert captured.out == f"{old}\n" and old.read_bytes() == new.read_bytes()
    warning = [line for line in captured.err.splitlines() if "deprecated" in line]
    assert warning == [
        "chain convert: warning: a positional TARGET is deprecated and goes in the next "
        f"release; write --out {old}"
    ]
    assert main(["convert", PUZZLE, str(old), "--to", "xmpuzzle", "--out", str(new)]) == 2
    assert "give the file to write once" in capsys.readouterr().err


def test_a_levels_folder_is_levels_everywhere_and_folder_still_works(
    suite: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    stacking = str(suite / "stacking")
    assert main(["demos", "--levels", stacking]) == 0
    new = capsys.readouterr()
    assert "warning" not in new.err and new.out.count("\n") == 2  # one level, two steps
    assert main(["demos", "--folder", stacking]) == 0
    old = capsys.readouterr()
    assert old.out == new.out
    assert old.err == (
        "chain demos: warning: --folder is deprecated and goes in the next release; "
        "write --levels\n" + new.err
    )
    assert main(["demos", "--levels", str(suite / "puzzle"), STACKING]) == 2
    assert f"no level file or level id {STACKING!r}" in capsys.readouterr().err
