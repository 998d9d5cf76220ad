from __future__ import annotations

import argparse
import importlib
import json
import re
import subprocess
import sys
from pathlib import Path

import pytest

from chaingeo.cli.main import COMMANDS, main
from chaingeo.core.colors import BY_NAME, PALETTE, assign_colors
from chaingeo.core.formats.chain_json import export_chain_stacking
from chaingeo.core.level import load_level, save_level, stacking_level
from chaingeo.core.piecesets import BEDLAM_SOLUTION


def test_palette_has_40_distinct_typable_colours() -> None:
    assert len(PALETTE) >= 40
    assert len(BY_NAME) == len(PALETTE)
    assert len({c.hex for c in PALETTE}) == len(PALETTE)
    for c in PALETTE:
        assert c.name.isalpha() and c.name.islower()
    # visually distinct: no two colours closer than a small RGB distance
    rgb = [c.rgb for c in PALETTE]
    closest = min(
        sum((a - b) ** 2 for a, b in zip(p, q, strict=True)) ** 0.5
        for i, p in enumerate(rgb)
        for q in rgb[i + 1 :]
    )
    assert closest > 30


def test_assign_colors_is_deterministic_and_bounded() -> None:
    assert assign_colors(3) == assign_colors(3) == list(PALETTE[:3])
    with pytest.raises(ValueError):
        assign_colors(len(PALETTE) + 1)


def test_help_lists_every_subcommand() -> None:
    out = subprocess.run(
        [sys.executable, "-m", "chaingeo.cli.main", "--help"],
        capture_output=True,
        text=True,
        check=True,
    )
    for mod in COMMANDS:  # each command module registers one command, listed in the help
        sub = argparse.ArgumentParser().add_subparsers()
        importlib.import_module(mod).register(sub)
        (name,) = sub.choices
        assert re.search(rf"^    {name}\b", out.stdout, flags=re.M), name


def test_validate_and_convert(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    level = stacking_level("bedlam-known", "hard", (4, 4, 4), list(BEDLAM_SOLUTION.values()))
    path = save_level(level, tmp_path / "levels" / "bedlam.json")
    assert main(["validate", str(tmp_path / "levels")]) == 0
    lines = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    assert lines[0]["id"] == "bedlam-known" and lines[-1]["levels"] == 1
    orig = tmp_path / "orig.json"
    assert main(["convert", str(path), "--out", str(orig), "--to", "chain-json"]) == 0
    assert json.loads(orig.read_text()) == export_chain_stacking(level)
    back = tmp_path / "back.json"
    assert (
        main(
            [
                "convert",
                str(orig),
                "--out",
                str(back),
                "--to",
                "chain-level",
                "--id",
                "bedlam-known",
                "--difficulty",
                "hard",
            ]
        )
        == 0
    )
    imported = load_level(back)
    assert [(p.name, p.rgb, p.shape) for p in imported.pieces] == [
        (p.name, p.rgb, p.shape) for p in level.pieces
    ]
    assert [p.chain_id for p in imported.pieces] == [str(i) for i in range(len(level.pieces))]
    assert imported.solution == level.solution


def test_bad_file_is_one_line_error(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    bad = tmp_path / "bad.json"
    bad.write_text("{}")
    assert main(["validate", str(bad)]) == 2
    err = capsys.readouterr().err
    assert "format: missing field" in err and "Traceback" not in err
