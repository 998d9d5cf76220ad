"""``chain analyze FILE...``: many files in one process (one JSON line each), level ids, and
kernels interpreted for one small file (the same figures as numba's, and a move to numba when
the work is large)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from chaingeo.cli.main import main
from chaingeo.core.suite import suite_folder
from tests.support.paths import DATA

DATA = DATA / "burrtools"
#: Small files whose whole analysis takes well under a second interpreted.
SMALL = [
    "puzzle-easy-02-luban-6-piece",
    "puzzle-easy-04-burr6",
    "puzzle-easy-07-burr3",
    "puzzle-easy-08-plate3",
    "puzzle-easy-09-cube3",
    str(DATA / "linked_rings.xmpuzzle"),
    str(DATA / "ring_maze.xmpuzzle"),
]


def _lines(text: str) -> list[dict[str, Any]]:
    return [json.loads(line) for line in text.splitlines() if line.strip()]


def _figures(row: dict[str, Any]) -> dict[str, Any]:
    return {k: v for k, v in row.items() if k not in ("seconds", "kernels")}


def _chain(*args: str, env: dict[str, str] | None = None) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "chaingeo.cli.main", "analyze", *args],
        capture_output=True,
        text=True,
        timeout=300,
        env={**os.environ, **(env or {})},
        check=False,
    )


def test_many_files_one_line_each_and_a_bad_file_does_not_stop_the_batch(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bad = tmp_path / "bad.xmpuzzle"
    bad.write_bytes(b"not a puzzle")
    level = "puzzle-easy-07-burr3"
    by_file = suite_folder("puzzle") / f"{level}.json"
    status = main(["analyze", level, str(bad), str(by_file), "--no-optimal", "--jit", "numba"])
    assert status == 2
    captured = capsys.readouterr()
    first, broken, last = _lines(captured.out)
    assert first["file"] == level and last["file"] == str(by_file)
    assert _figures(first) | {"file": ""} == _figures(last) | {"file": ""}
    assert (first["assemblies"], first["solutions"], first["level"]) == (1, 1, "2")
    assert broken["file"] == str(bad) and broken["error"]
    assert f"{bad}: error:" in captured.err


def test_one_bad_file_is_an_error_with_no_json(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["analyze", "no-such-level", "--jit", "numba"]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    assert "no level file or level id 'no-such-level'" in captured.err


def test_kernels_cannot_change_in_a_process_that_has_them(
    capsys: pytest.CaptureFixture[str],
) -> None:
    from chaingeo.kernels.jit import mode

    assert mode() == "numba"  # the test process compiles its kernels
    assert main(["analyze", "puzzle-easy-07-burr3", "--jit", "python"]) == 2
    assert "the mode is fixed per process" in capsys.readouterr().err


def test_interpreted_kernels_give_numba_s_figures(capsys: pytest.CaptureFixture[str]) -> None:
    interpreted = _chain(*SMALL, "--mirrors", "drop", "--jit", "python")
    assert interpreted.returncode == 0, interpreted.stderr
    assert main(["analyze", *SMALL, "--mirrors", "drop", "--jit", "numba"]) == 0
    compiled = _lines(capsys.readouterr().out)
    rows = _lines(interpreted.stdout)
    assert {r["kernels"] for r in rows} == {"python"}
    assert {r["kernels"] for r in compiled} == {"numba"}
    assert [_figures(r) for r in rows] == [_figures(r) for r in compiled]


def test_auto_runs_a_small_file_interpreted_and_a_large_one_with_numba() -> None:
    small = _chain(str(DATA / "linked_rings.xmpuzzle"))
    assert small.returncode == 0, small.stderr
    assert _lines(small.stdout)[0]["kernels"] == "python"
    by_id = _chain("puzzle-easy-07-burr3")  # a level id is looked at too
    assert _lines(by_id.stdout)[0]["kernels"] == "python", by_id.stderr
    # Small by its size, but seconds of work interpreted: the command starts again with numba.
    slow = _chain(str(DATA / "deep_maze.xmpuzzle"), "--no-optimal")
    assert slow.returncode == 0, slow.stderr
    (row,) = _lines(slow.stdout)
    assert (row["kernels"], row["level"]) == ("numba", "51")
    forced = _chain(str(DATA / "linked_rings.xmpuzzle"), env={"CHAINGEO_JIT": "numba"})
    assert _lines(forced.stdout)[0]["kernels"] == "numba"


def test_a_bad_mode_in_the_environment_is_named() -> None:
    bad = _chain(str(DATA / "linked_rings.xmpuzzle"), env={"CHAINGEO_JIT": "fast"})
    assert bad.returncode == 2
    assert "CHAINGEO_JIT: expected one of numba, aot, python, got 'fast'" in bad.stderr


def test_an_interpreted_analysis_never_imports_numba() -> None:
    script = (
        "import sys\n"
        "from chaingeo.cli.main import main\n"
        f"status = main(['analyze', {str(DATA / 'linked_rings.xmpuzzle')!r}, '--jit', 'python'])\n"
        "print('numba' in sys.modules, status)\n"
    )
    run = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, timeout=120, check=False
    )
    assert run.stdout.splitlines()[-1] == "False 0", run.stderr


def test_chain_version(capsys: pytest.CaptureFixture[str]) -> None:
    from chaingeo import __version__

    with pytest.raises(SystemExit) as done:
        main(["--version"])
    assert done.value.code == 0
    assert capsys.readouterr().out.strip() == f"chain {__version__}"


def test_counting_cut_short_keeps_the_known_assembly_s_figures() -> None:
    from chaingeo.core.formats.bt_level import level_puzzle
    from chaingeo.core.level import load_level
    from chaingeo.solvers.analysis import RowOptions, level_analysis_row, problem_analysis_row
    from chaingeo.solvers.deadline import Deadline
    from chaingeo.solvers.limits import SearchLimits

    level = load_level(suite_folder("puzzle") / "puzzle-mid-04-burr12.json")
    limits = SearchLimits(seconds=30.0)
    spent = Deadline(0.0)  # counting stops at once; the known assembly gets its own time
    out = level_analysis_row(level, RowOptions(limits, deadline=spent))
    assert out["counts_complete"] is False and out["limit_cap"] == "seconds"
    assert (out["assemblies"], out["solutions"]) == (0, 0)
    assert (out["level"], out["moves"]) == (level.stats["level"], level.stats["moves"])
    assert out["optimal_steps"] == level.optimal_steps
    stored = problem_analysis_row(
        level_puzzle(level), 0, RowOptions(limits, deadline=Deadline(0.0))
    )
    assert stored["counts_complete"] is False
    assert (stored["level"], stored["optimal_steps"]) == ("1.2.2", level.optimal_steps)
    whole = problem_analysis_row(level_puzzle(level), 0, RowOptions(limits, optimal=False))
    assert "counts_complete" not in whole
    assert (whole["assemblies"], whole["solutions"], whole["level"]) == (2, 1, "1.2.2")


def test_a_state_cap_names_its_flag_not_a_python_field(
    capsys: pytest.CaptureFixture[str],
) -> None:
    status = main(
        [
            "analyze",
            "puzzle-hard-01-liliput",
            "--no-assemble",
            "--max-states",
            "2",
            "--jit",
            "numba",
        ]
    )
    err = capsys.readouterr().err
    assert status == 2, err
    assert "state cap of 2 reached" in err and "raise it with --max-states" in err
    assert "SearchLimits(" not in err


def test_an_optimal_search_stopped_by_a_cap_names_its_flag(
    capsys: pytest.CaptureFixture[str],
) -> None:
    """The level is found within the cap, o_i is not: the line says which flag raises it."""
    status = main(["analyze", "puzzle-mid-04-burr12", "--no-assemble", "--max-states", "30"])
    row = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert status == 0
    assert (row["level"], row["optimal_steps"]) == ("1.2.2", None)
    assert row["optimal_error"].endswith("; raise it with --max-states")
    assert "optimal_limit_cap" not in row and "SearchLimits(" not in row["optimal_error"]


def test_a_hard_optimal_search_stops_at_its_own_time_limit(
    capsys: pytest.CaptureFixture[str],
) -> None:
    """o_i past --optimal-seconds is unknown, with its flag; level and counts still stand, and
    the analysis ends well before --seconds."""
    start = time.monotonic()
    status = main(
        ["analyze", "puzzle-mid-04-burr12", "--no-assemble", "--optimal-seconds", "0.001"]
    )
    row = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert status == 0 and time.monotonic() - start < 30
    assert (row["level"], row["moves"], row["optimal_steps"]) == ("1.2.2", 13, None)
    assert row["optimal_error"] == "time limit of 0.001 s reached; raise it with --optimal-seconds"


@pytest.mark.parametrize("value", ["0", "-1", "nan", "inf"])
def test_a_bad_optimal_time_limit_is_refused(
    value: str, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["analyze", "puzzle-mid-04-burr12", "--optimal-seconds", value]) == 2
    captured = capsys.readouterr()
    assert captured.out == "" and "--optimal-seconds: expected a positive number" in captured.err


@pytest.mark.parametrize("seed", range(30))
def test_the_interpreted_try_counts_the_assemblers_placements(seed: int) -> None:
    """``--jit auto`` tries a BurrTools file interpreted by its placements: the count it
    stops at is exactly the assembler's rows for the pieces (no colours in these puzzles),
    on seeded random boxes cut into pieces, with holes and congruent bars."""
    from chaingeo.cli.commands.analyze import placements_within
    from chaingeo.solvers.assembly.btassemble import bt_packing_spec
    from chaingeo.solvers.cover.constrained import compile_packing
    from tests.support.burrtxt import random_puzzle

    puzzle = random_puzzle(np.random.default_rng(seed))
    packing = compile_packing(bt_packing_spec(puzzle, 0))
    starts = packing.problem.row_start
    rows = sum(
        int(starts[t + 1] - starts[t]) for t in range(len(packing.types)) if t != packing.hole_type
    )
    assert placements_within(puzzle, puzzle.problems, rows)
    assert not placements_within(puzzle, puzzle.problems, rows - 1)


# Issue #37, item 3: --seconds bounds the command, not each problem; the problems and files it
# does not reach are reported as not reached.


def test_seconds_bounds_the_whole_command(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    import gzip

    from tests.support.paths import DATA

    xml = gzip.decompress((DATA / "burrtools" / "solid_burrs.xmpuzzle").read_bytes())
    a, b = xml.index(b"<problem "), xml.index(b"</problem>") + len(b"</problem>")
    many = tmp_path / "many.xmpuzzle"
    many.write_bytes(gzip.compress(xml[:a] + xml[a:b] * 1024 + xml[b:]))
    t0 = time.monotonic()
    code = main(["analyze", "--jit", "numba", "--seconds", "2", str(many), str(many)])
    assert time.monotonic() - t0 < 2 + 10 + 5  # one grace period at most past the deadline
    rows = [json.loads(x) for x in capsys.readouterr().out.splitlines()]
    assert code == 1 and len(rows) == 2
    missed = [p for p in rows[0]["problems"] if "not reached" in (p.get("limit") or "")]
    assert len(rows[0]["problems"]) == 1024 and len(missed) > 900
    assert "not reached" in rows[1]["limit"] and "--seconds" in rows[1]["limit"]
