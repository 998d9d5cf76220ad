"""``chain analyze`` prints burrTxt's figures for a BurrTools file by default, and says so."""

from __future__ import annotations

import json

import pytest

from chaingeo.cli.main import main
from tests.solvers.bt_example_files import example


@pytest.mark.parametrize(
    ("name", "burrtxt", "kept"),
    [
        ("DemoPieceGenerator", (928, 927), (1760, 1759)),
        ("SolidSixPieceBurrs", (588, 179), (1063, 314)),
    ],
)
def test_burrtxt_figures_by_default(
    name: str, burrtxt: tuple[int, int], kept: tuple[int, int], capsys: pytest.CaptureFixture[str]
) -> None:
    path = str(example(name))
    assert main(["analyze", path, "--no-optimal", "--jit", "numba"]) == 0
    row = json.loads(capsys.readouterr().out)
    assert (row["assemblies"], row["solutions"], row["convention"]) == (*burrtxt, "burrtxt")
    assert main(["analyze", path, "--no-optimal", "--mirrors", "keep", "--jit", "numba"]) == 0
    row = json.loads(capsys.readouterr().out)
    assert (row["assemblies"], row["solutions"], row["convention"]) == (*kept, "mirrors-kept")
