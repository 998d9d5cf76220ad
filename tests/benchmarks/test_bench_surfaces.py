"""``chain bench robustness``, round three (issue #37): every class of
:mod:`chaingeo.benchmarks._surfaces` runs its cases (seeded, each bounded in time) and finds no
traceback, hang, wrong acceptance or file outside its folder."""

from __future__ import annotations

from pathlib import Path

import pytest

from chaingeo.benchmarks import _surfaces as bench


@pytest.mark.parametrize("cls", bench.CLASSES, ids=lambda c: c.__name__)
def test_each_surface_holds(cls: object, tmp_path: Path) -> None:
    row = cls(tmp_path)  # type: ignore[operator]
    assert row.cases > 0 or cls is bench.video_limits  # (needs imageio-ffmpeg)
    assert (row.tracebacks, row.hangs, row.wrong, row.outside) == (0, 0, 0, 0), row


def test_the_table_prints_every_surface_and_the_totals() -> None:
    rows = [
        bench.Surface("a", cases=3, tracebacks=1, kinds={"TypeError": 1}),
        bench.Surface("b", 2),
    ]
    table = bench.surface_table(rows)
    assert "| a | 3 | 1 (TypeError 1) | 0 | 0 | 0 |" in table
    assert table.splitlines()[-1] == "| **all** | 5 | 1 | 0 | 0 | 0 |"
