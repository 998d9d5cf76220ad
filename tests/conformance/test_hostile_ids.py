"""Identifiers (issue #37, item 8): ``^...$`` matches before a final newline, so ``"red\n"``
passed as a piece name and ``X`` and ``X\n`` coexisted as level ids. Every identifier is now
matched whole (``fullmatch``); a suite with one id twice is refused."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from chaingeo.cli.main import main
from chaingeo.core.level import LevelError, load_level, load_levels
from chaingeo.core.suite import suite_folder
from chaingeo.generator.dedup import SignatureStore

BURR = suite_folder("puzzle") / "puzzle-easy-04-burr6.json"


def _edited(tmp_path: Path, name: str, edit: object) -> Path:
    data = json.loads(BURR.read_text())
    edit(data)  # type: ignore[operator]
    path = tmp_path / name
    path.write_text(json.dumps(data))
    return path


@pytest.mark.parametrize("suffix", ["\n", "\r", " ", "\x00"])
def test_piece_name_with_a_trailing_character_is_refused(tmp_path: Path, suffix: str) -> None:
    def edit(data: dict) -> None:  # type: ignore[type-arg]
        data["pieces"][0]["name"] += suffix

    with pytest.raises(LevelError, match=r"pieces\[0\]\.name"):
        load_level(_edited(tmp_path, "level.json", edit))


@pytest.mark.parametrize(
    ("field", "value"),
    [("id", "X\n"), ("rgb", "#aabbcc\n"), ("chain_id", "3\n")],
)
def test_other_identifiers_with_a_final_newline_are_refused(
    tmp_path: Path, field: str, value: str
) -> None:
    def edit(data: dict) -> None:  # type: ignore[type-arg]
        if field == "id":
            data["id"] = value
        else:
            for i, piece in enumerate(data["pieces"]):
                piece[field] = value if i == 0 else (f"#{i:06x}" if field == "rgb" else str(i + 9))

    with pytest.raises(LevelError):
        load_level(_edited(tmp_path, "level.json", edit))


def test_chain_validate_refuses_a_newline_name(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    def edit(data: dict) -> None:  # type: ignore[type-arg]
        data["pieces"][0]["name"] += "\n"

    assert main(["validate", str(_edited(tmp_path, "level.json", edit))]) != 0


def test_a_suite_with_x_and_x_newline_keeps_neither_twice(tmp_path: Path) -> None:
    """``X`` and ``X\\n``: the second is refused at load, so no folder can hold both."""
    _edited(tmp_path, "a.json", lambda d: d.update(id="X"))
    _edited(tmp_path, "b.json", lambda d: d.update(id="X\n"))
    with pytest.raises(LevelError, match=r"b\.json"):
        load_levels(tmp_path)


def test_a_suite_with_one_id_twice_is_refused(tmp_path: Path) -> None:
    _edited(tmp_path, "a.json", lambda d: d.update(id="X"))
    _edited(tmp_path, "b.json", lambda d: d.update(id="X"))
    with pytest.raises(LevelError, match="duplicate level id 'X'"):
        load_levels(tmp_path)


def test_signature_with_a_final_newline_is_refused(tmp_path: Path) -> None:
    store = SignatureStore(tmp_path)
    with pytest.raises(ValueError, match="hex digest"):
        store.reserve("0123456789abcdef\n", "owner")
