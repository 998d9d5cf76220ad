"""Counting with worker processes gives the same bytes as counting in one: the figures, every
level string in order, the first solution and the JSON line of ``chain analyze``."""

from __future__ import annotations

from multiprocessing.pool import Pool
from pathlib import Path

import numpy as np
import pytest

from chaingeo.core.formats.bt_level import level_puzzle
from chaingeo.core.formats.burrtools import BTPuzzle, read_xmpuzzle
from chaingeo.core.suite import load_level
from chaingeo.solvers import jobs as jobs_mod
from chaingeo.solvers.analysis import analyze
from chaingeo.solvers.assembly import btparallel
from chaingeo.solvers.assembly.btassemble import bt_packing_spec
from chaingeo.solvers.assembly.btcount import count_bt
from chaingeo.solvers.cover.constrained import compile_packing
from chaingeo.solvers.deadline import Deadline
from chaingeo.solvers.limits import SearchLimits
from tests.support import burrtxt as bt
from tests.support.paths import ROOT

DATA = ROOT / "tests" / "data" / "burrtools"


@pytest.fixture
def small_batches(monkeypatch: pytest.MonkeyPatch) -> list[int]:
    """Workers from the 9th assembly on, 5 a batch, so that small problems use them; returns
    the list each pool start appends its size to (to check the workers ran)."""
    monkeypatch.setattr(btparallel, "SERIAL_ASSEMBLIES", 8)
    monkeypatch.setattr(btparallel, "BATCH", 5)
    started: list[int] = []
    pool = btparallel._pool

    def counted(jobs: int, worker: btparallel.WorkerFactory) -> Pool:
        started.append(jobs)
        return pool(jobs, worker)

    monkeypatch.setattr(btparallel, "_pool", counted)
    return started


def _puzzles() -> list[tuple[str, BTPuzzle]]:
    out = [(p.stem, read_xmpuzzle(p)) for p in (DATA / "soma_problems.xmpuzzle",)]
    out += [(name, level_puzzle(load_level(name))) for name in ("puzzle-mid-02-interlocking-cube",)]
    for index in range(3):
        rng = np.random.default_rng(np.random.SeedSequence([38, index]))
        out.append((f"random-{index}", bt.random_puzzle(rng)))
    return out


@pytest.mark.parametrize("mirrors", ["drop", "keep"])
def test_workers_give_the_same_counts_levels_and_first_solution(
    small_batches: list[int], mirrors: str
) -> None:
    used = 0
    for name, puzzle in _puzzles():
        for problem in range(len(puzzle.problems)):
            packing = compile_packing(bt_packing_spec(puzzle, problem))
            runs = []
            for jobs in (1, 2):
                levels: list[str] = []
                rep = count_bt(packing, mirrors=mirrors, jobs=jobs, levels=levels)  # type: ignore[arg-type]
                first = None if rep.first_analysis is None else rep.first_analysis.level
                runs.append((rep.assemblies, rep.solutions, levels, rep.first_packing, first))
            assert runs[0] == runs[1], (name, problem)
            used += runs[0][0] > btparallel.SERIAL_ASSEMBLIES
    assert used >= 3 and small_batches and set(small_batches) == {2}


def test_analyze_prints_the_same_line_whatever_the_jobs(small_batches: list[int]) -> None:
    for source in ("puzzle-mid-02-interlocking-cube", DATA / "soma_problems.xmpuzzle"):
        lines = []
        for jobs in (1, 2, 3):
            figures = analyze(source, jobs=jobs, optimal=False)
            lines.append(figures.to_json().split('"seconds"')[0])
        assert lines[0] == lines[1] == lines[2]
    assert set(small_batches) == {2, 3}


def test_a_deadline_stops_the_workers(small_batches: list[int]) -> None:
    """The luban's 518,400 assemblies cannot be counted in 3 s: the count stops at the
    deadline, workers and all, and keeps what it had (lower bounds)."""
    import time

    name = "puzzle-mid-03-luban-15-piece"
    packing = compile_packing(bt_packing_spec(level_puzzle(load_level(name)), 0))
    start = time.perf_counter()
    rep = count_bt(packing, mirrors="drop", jobs=2, deadline=Deadline(3.0), partial=True)
    assert time.perf_counter() - start < 30  # stopped, not run to the end
    assert not rep.complete and rep.limit is not None and rep.limit.cap == "seconds"
    assert 0 <= rep.solutions <= rep.assemblies < 518_400
    assert rep.assemblies <= btparallel.SERIAL_ASSEMBLIES or small_batches == [2]


@pytest.mark.parametrize("jobs", [0, -1, True, 1.5])
def test_jobs_must_be_a_positive_count(jobs: object) -> None:
    with pytest.raises(ValueError, match="jobs"):
        jobs_mod.check_jobs(jobs)  # type: ignore[arg-type]


def test_default_jobs_is_the_cores_this_process_may_use() -> None:
    assert 1 <= jobs_mod.check_jobs(None) == jobs_mod.default_jobs()
    limits = SearchLimits(seconds=30)
    assert (
        analyze(DATA / "soma_problems.xmpuzzle", problem=1, limits=limits).convention == "burrtxt"
    )


def test_the_cli_refuses_no_workers(capsys: pytest.CaptureFixture[str]) -> None:
    from chaingeo.cli.main import main

    assert main(["analyze", str(Path(DATA / "soma_problems.xmpuzzle")), "--jobs", "0"]) == 2
    assert "--jobs" in capsys.readouterr().err
