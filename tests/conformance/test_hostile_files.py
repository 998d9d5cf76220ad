"""Hostile files (issue #21, items 9-12): level files with non-finite numbers or more pieces
than the search kernels take, BurrTools XML that hides a DOCTYPE in another encoding, and the
command-line paths a new user meets first. Each input gets one typed error or a clear row,
never a traceback. Model folders (``chain import``) are in ``test_hostile_models.py``."""

from __future__ import annotations

import dataclasses
import gzip
import io
import json
import math
import os
import re
import subprocess
import sys
import threading
import time
from pathlib import Path
from typing import Any

import pytest

from chaingeo.cli.main import main
from chaingeo.core.formats.burrtools import BurrToolsError, parse_xmpuzzle, read_xmpuzzle
from chaingeo.core.geometry import Shape, puzzle_signature
from chaingeo.core.level import LevelError, level_bytes, load_level, save_level
from chaingeo.core.suite import suite_folder
from chaingeo.solvers.motion.kinematics_kernel import MAX_PIECES
from tests.support.env_levels import tiny_level

BURR = suite_folder("puzzle") / "puzzle-easy-04-burr6.json"

# ---------------------------------------------------------------------------------------------
# Item 9: level files
# ---------------------------------------------------------------------------------------------

#: (where the literal goes, the literal, the field the error must name)
NON_FINITE = [
    ("stats", '{"score": NaN}', "stats.score"),
    ("stats", '{"a": [1, {"b": -Infinity}]}', "stats.a[1].b"),
    ("stats", '{"big": 1e999}', "stats.big"),
    ("stats", '{"small": -1E+400}', "stats.small"),
    ("max_steps", "Infinity", "max_steps"),
]


def _with_literal(tmp_path: Path, key: str, literal: str) -> Path:
    """The shipped burr level with ``key`` set to raw JSON text (json.dumps cannot write NaN
    in every position we want, so the text is spliced)."""
    data = json.loads(BURR.read_text())
    data[key] = "@@"
    path = tmp_path / "level.json"
    path.write_text(json.dumps(data).replace('"@@"', literal))
    return path


@pytest.mark.parametrize(("key", "literal", "field"), NON_FINITE)
def test_non_finite_number_is_a_level_error_naming_the_field(
    tmp_path: Path, key: str, literal: str, field: str
) -> None:
    path = _with_literal(tmp_path, key, literal)
    with pytest.raises(LevelError) as err:
        load_level(path)
    assert err.value.field == field and "not a finite number" in err.value.reason


def test_every_command_refuses_a_non_finite_level_by_name(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = _with_literal(tmp_path, "stats", '{"score": NaN}')
    out = str(tmp_path / "out.json")
    for argv in (
        ["validate", str(path)],
        ["convert", str(path), "--out", out, "--to", "chain-json"],
        ["play", str(path), "--no-images"],
    ):
        assert main(argv) == 2, argv
        err = capsys.readouterr().err
        assert "stats.score: NaN is not a finite number" in err and err.count("\n") == 1
    assert not (tmp_path / "out.json").exists()


def test_level_built_in_code_with_nan_names_the_field_when_written() -> None:
    level = dataclasses.replace(load_level(BURR), stats={"score": [1.0, math.nan]})
    with pytest.raises(ValueError, match=r"^stats\.score\[1\]: nan is not a finite number$"):
        level_bytes(level)


def _unblock_later(fifo: Path, data: bytes) -> None:
    """Should a reader block on ``fifo``, feed it ``data`` within 3 s, so a regression fails
    instead of hanging; with no reader this gives up quietly (daemon thread)."""

    def feed() -> None:
        for _ in range(30):
            try:
                fd = os.open(fifo, os.O_WRONLY | os.O_NONBLOCK)  # fails while no one reads
            except OSError:
                time.sleep(0.1)
                continue
            os.write(fd, data)
            os.close(fd)
            return

    threading.Thread(target=feed, daemon=True).start()


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no FIFOs here")
def test_fifo_level_or_puzzle_file_is_refused_unopened(tmp_path: Path) -> None:
    """``chain validate`` over a folder holding a FIFO named ``x.json`` hung for good."""
    for name, load, error in (
        ("x.json", load_level, LevelError),
        ("x.xmpuzzle", read_xmpuzzle, BurrToolsError),
    ):
        fifo = tmp_path / name
        os.mkfifo(fifo)
        _unblock_later(fifo, BURR.read_bytes() if name.endswith("json") else b"<puzzle/>")
        with pytest.raises(error, match="not a regular file"):
            load(fifo)


def line_puzzle(n: int) -> dict[str, Any]:
    """``n`` one-cell pieces in a row along x, taken apart from the +x end one by one."""
    pieces = [
        {"name": f"p{i}", "rgb": f"#{i:02x}{i:02x}{i:02x}", "voxels": [[i, 0, 0]]} for i in range(n)
    ]
    moves = [
        {"pieces": [f"p{i}"], "direction": "+x", "distance": None} for i in range(n - 1, 0, -1)
    ]
    return {
        "format": "chain-level/1", "id": f"line-{n}", "family": "puzzle", "difficulty": "hard",
        "goal": "disassemble", "box": None, "pieces": pieces, "solution": {"moves": moves},
        "optimal_steps": n - 1, "max_steps": 2 * n, "rules": {},
        "provenance": {"generator": "test", "version": "1", "seed": None, "index": None,
                       "signature": puzzle_signature(Shape([(i, 0, 0)]) for i in range(n))},
        "stats": {},
    }  # fmt: skip


def _validate(path: Path, capsys: pytest.CaptureFixture[str]) -> tuple[int, dict[str, Any]]:
    code = main(["validate", str(path)])
    out = capsys.readouterr().out.splitlines()
    return code, json.loads(out[0])


def test_validate_reports_a_part_past_the_kernel_bound_unchecked(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The loader takes 256 pieces; the search kernels 63 in a part: validate says so."""
    path = tmp_path / "line.json"
    path.write_text(json.dumps(line_puzzle(MAX_PIECES + 1)))
    load_level(path)  # a valid level
    code, row = _validate(path, capsys)
    assert code == 0 and row["optimal_checked"] is False and "error" not in row
    assert row["unchecked_reason"] == (
        f"{MAX_PIECES + 1} pieces; the optimal search takes at most {MAX_PIECES} pieces in a part"
    )


@pytest.mark.parametrize("case", ["unknown piece", "blocks with turns"])
def test_validate_reports_malformed_blocks_as_an_error_row(
    case: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    data = json.loads(BURR.read_text())
    if case == "unknown piece":
        data["stats"]["blocks"] = [["nobody"]]
    else:  # well formed, but the bounds that use blocks hold for translations only
        data["stats"]["blocks"] = [[p["name"] for p in data["pieces"]]]
        data["rules"]["turns"] = True
    path = tmp_path / "blocks.json"
    path.write_text(json.dumps(data))
    code, row = _validate(path, capsys)
    assert code == 2 and row["optimal_checked"] is False
    assert row["error"].startswith(f"{path}: stats.blocks:")


# ---------------------------------------------------------------------------------------------
# Item 10: BurrTools XML in any encoding
# ---------------------------------------------------------------------------------------------

_PUZZLE = (
    '<puzzle version="2"><shapes><voxel x="1" y="1" z="1" type="0">#</voxel></shapes>'
    "<comment>{text}</comment></puzzle>"
)
_LAUGHS = '<!DOCTYPE puzzle [<!ENTITY x "laugh">]>' + _PUZZLE.format(text="&x;")


def _declared(encoding: str) -> str:
    return f'<?xml version="1.0" encoding="{encoding}"?>'


#: name -> the bytes of an XML file carrying a DOCTYPE with an entity
HIDDEN_DOCTYPES = {
    "utf-16 with BOM": (_declared("UTF-16") + _LAUGHS).encode("utf-16"),
    "utf-16le, no BOM": (_declared("UTF-16LE") + _LAUGHS).encode("utf-16-le"),
    "utf-16be, no BOM": (_declared("UTF-16BE") + _LAUGHS).encode("utf-16-be"),
    "utf-16, no declaration": _LAUGHS.encode("utf-16"),
    "utf-8 with BOM": b"\xef\xbb\xbf" + _LAUGHS.encode(),
    "latin-1 declared": (_declared("ISO-8859-1") + _LAUGHS).encode("latin-1"),
    "gzip of utf-16": gzip.compress((_declared("UTF-16") + _LAUGHS).encode("utf-16"), mtime=0),
    "utf-32": (_declared("UTF-32") + _LAUGHS).encode("utf-32"),  # expat cannot read it at all
}


@pytest.mark.parametrize("name", sorted(HIDDEN_DOCTYPES))
def test_doctype_is_refused_in_any_encoding(name: str, tmp_path: Path) -> None:
    path = tmp_path / "laughs.xmpuzzle"
    path.write_bytes(HIDDEN_DOCTYPES[name])
    with pytest.raises(BurrToolsError) as err:
        read_xmpuzzle(path)
    assert err.value.source == str(path) and err.value.where == "(file)"
    expected = "invalid XML" if name == "utf-32" else "DOCTYPE is not allowed"
    assert expected in err.value.reason


def test_clean_utf16_puzzle_still_reads() -> None:
    puzzle = parse_xmpuzzle((_declared("UTF-16") + _PUZZLE.format(text="hi")).encode("utf-16"))
    assert puzzle.comment == "hi" and len(puzzle.shapes) == 1


# ---------------------------------------------------------------------------------------------
# Item 12: what a new user meets first
# ---------------------------------------------------------------------------------------------

_RED = "place red (1,1,1) (2,1,1) (1,2,1)"


def _play(
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
    lines: list[str],
) -> tuple[list[str], list[int]]:
    """The replies to ``undo`` and every "Steps used" figure printed, in order."""
    path = save_level(tiny_level(), tmp_path / "tiny.json")
    monkeypatch.setattr("sys.stdin", io.StringIO("\n".join(lines) + "\n"))
    main(["play", str(path), "--no-images"])
    out = capsys.readouterr().out
    undos = re.findall(r"(?:Undone|Nothing to undo)[^\n]*", out)  # after a "> " prompt
    return undos, [int(n) for n in re.findall(r"Steps used: (\d+) of", out)]


def test_undo_after_a_refused_turn_keeps_the_turn_counted(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """Steps used = turns taken - actions undone, whatever order they come in."""
    undos, steps = _play(tmp_path, monkeypatch, capsys, [_RED, "place nothing", "undo", "undo"])
    # start 0; red 1; refused 2; undo takes red back: 1; nothing left to undo: 1
    assert steps == [0, 1, 2, 1, 1]
    assert undos[0].startswith("Undone: place red") and "your last turn was refused" in undos[0]
    assert undos[1].startswith("Nothing to undo: no action has been carried out")


def test_undo_of_a_first_refused_turn_is_nothing_and_keeps_its_step(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    undos, steps = _play(tmp_path, monkeypatch, capsys, ["place nothing", "undo", _RED, "undo"])
    assert steps == [0, 1, 1, 2, 1]
    assert undos[0] == (
        "Nothing to undo: no action has been carried out "
        "(refused turns change nothing and keep their steps)."
    )
    assert undos[1].startswith("Undone: place red") and "refused" not in undos[1]


def test_export_prints_no_nanobind_leak_warnings(tmp_path: Path) -> None:
    """Meshes hold copies, not views of manifold3d's nanobind objects, which then die with
    the function: nothing is left to report as leaked at exit."""
    out = tmp_path / "burr.glb"
    run = subprocess.run(
        [sys.executable, "-m", "chaingeo.cli.main", "export", str(BURR), "--out", str(out)],
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    assert run.returncode == 0 and run.stdout.strip() == str(out)
    assert run.stderr == "" and out.read_bytes()[:4] == b"glTF"


def test_bench_cover_without_xcover_says_how_to_install_it(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.setitem(sys.modules, "xcover", None)  # as if not installed
    assert main(["bench", "cover", "--quick"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "pip install 'chaingeo[bench]'" in err


def test_analyze_reports_a_part_past_the_kernel_bound_unsearched(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "line-64.json"
    path.write_text(json.dumps(line_puzzle(64)))
    assert main(["analyze", str(path), "--no-assemble", "--jit", "numba"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["level"] is None and out["optimal_steps"] is None
    assert "64 pieces in one part" in out["disassembly_error"]
    assert "at most 63" in out["disassembly_error"]


def test_a_piece_longer_than_255_cells_is_counted(tmp_path: Path) -> None:
    from chaingeo.solvers.assembly.assemble import count_assemblies
    from chaingeo.solvers.cover.problem import PieceSpec

    rod = Shape([(x, 0, 0) for x in range(300)])
    report = count_assemblies([PieceSpec(rod, "rod")], rod)
    assert report.assemblies == 1
