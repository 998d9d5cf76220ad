"""``chain cover`` and ``chain bench cover`` end to end."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from chaingeo.cli.main import main
from chaingeo.core.geometry import Shape
from chaingeo.core.level import save_level, stacking_level


def _run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def test_cover_builtin_set(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = _run(capsys, "cover", "--pieces", "soma", "--box", "3x3x3")
    assert code == 0
    data = json.loads(out)
    assert (data["solutions"], data["distinct"]) == (11520, 240)
    assert data["nodes"] > 0 and data["seconds"] >= 0


def test_cover_json_piece_list(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    f = tmp_path / "pieces.json"
    f.write_text(json.dumps([[[0, 0, 0], [1, 0, 0]], [[0, 0, 0], [0, 1, 0]]]))
    code, out, _ = _run(capsys, "cover", "--pieces", str(f), "--box", "2x2x1")
    assert code == 0
    data = json.loads(out)
    # Two identical dominoes tile a 2x2 square twice; the quarter turn makes them one.
    assert (data["solutions"], data["distinct"]) == (2, 1)


def test_cover_level_file(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    placed = [Shape([(0, 0, 0), (1, 0, 0), (0, 1, 0)]), Shape([(1, 1, 0), (0, 2, 0), (1, 2, 0)])]
    level = stacking_level("t-1", "easy", (2, 3, 1), placed)
    path = save_level(level, tmp_path / "t-1.json")
    code, out, _ = _run(capsys, "cover", "--pieces", str(path))
    assert code == 0
    assert json.loads(out)["solutions"] == 2  # two L trominoes in a 2x3 rectangle


@pytest.mark.parametrize(
    "argv",
    [
        ("cover", "--pieces", "nonsense", "--box", "3x3x3"),
        ("cover", "--pieces", "soma", "--box", "3x3"),
        ("cover", "--pieces", "soma"),
        ("cover", "--pieces", "soma", "--box", "3x3x3", "--node-limit", "5"),
    ],
)
def test_cover_errors(argv: tuple[str, ...], capsys: pytest.CaptureFixture[str]) -> None:
    code, out, err = _run(capsys, *argv)
    assert code == 2 and out == "" and err.startswith("chain cover: error:")


def test_bench_cover_quick(capsys: pytest.CaptureFixture[str]) -> None:
    pytest.importorskip("xcover")
    code, out, _ = _run(capsys, "bench", "cover", "--quick", "--repeat", "1")
    assert code == 0
    summary = json.loads(out.strip().splitlines()[-1])
    assert [r["instance"] for r in summary["rows"]] == ["soma 3x3x3", "pentominoes 5x12x1"]
    assert all(r["solutions"] in (11520, 4040) for r in summary["rows"])
