"""Counting with worker processes gives the same bytes as counting in one: the figures, every
level string in order, the first solution and the JSON line of ``chain analyze``; and the
subtrees together hold every class of the whole search once."""

from __future__ import annotations

from collections import Counter
from pathlib import Path

import numpy as np
import pytest

from chaingeo.core.arrays import I32
from chaingeo.core.formats.bt_level import level_puzzle
from chaingeo.core.formats.burrtools import BTPuzzle, read_xmpuzzle
from chaingeo.core.piecesets import SOMA
from chaingeo.core.suite import load_level
from chaingeo.solvers import jobs as jobs_mod
from chaingeo.solvers.analysis import analyze
from chaingeo.solvers.assembly import btparallel
from chaingeo.solvers.assembly.btassemble import Mirrors, bt_packing_spec
from chaingeo.solvers.assembly.btcount import count_bt
from chaingeo.solvers.cover import parallel as cover_parallel
from chaingeo.solvers.cover.constrained import Packing, compile_packing
from chaingeo.solvers.cover.packings import count_packings
from chaingeo.solvers.cover.problem import CoverProblem
from chaingeo.solvers.cover.search import Engine
from chaingeo.solvers.deadline import Deadline
from chaingeo.solvers.limits import SearchLimits
from tests.support import burrtxt as bt
from tests.support.paths import ROOT

DATA = ROOT / "tests" / "data" / "burrtools"


@pytest.fixture
def split_small(monkeypatch: pytest.MonkeyPatch) -> list[int]:
    return _split_small(monkeypatch)


def _split_small(monkeypatch: pytest.MonkeyPatch) -> list[int]:
    """Every search with more than 4 covers or 50 nodes is cut into at most 8 subtrees; returns
    the list each cut appends its number of subtrees to (to check the cut ran)."""
    monkeypatch.setattr(btparallel, "PROBE_NODES", 50)
    monkeypatch.setattr(btparallel, "PROBE_COVERS", 4)
    monkeypatch.setattr(btparallel, "PARTS", 8)
    cuts: list[int] = []
    split = cover_parallel.split_widest

    def counted(problem: CoverProblem, rows: I32, engine: Engine, parts: int) -> list[I32]:
        out = split(problem, rows, engine, parts)
        cuts.append(len(out))
        return out

    monkeypatch.setattr(btparallel, "split_widest", counted)
    return cuts


def _puzzles() -> list[tuple[str, BTPuzzle]]:
    out = [(p.stem, read_xmpuzzle(p)) for p in (DATA / "soma_problems.xmpuzzle",)]
    out += [(name, level_puzzle(load_level(name))) for name in ("puzzle-mid-02-interlocking-cube",)]
    for index in range(3):
        rng = np.random.default_rng(np.random.SeedSequence([38, index]))
        out.append((f"random-{index}", bt.random_puzzle(rng)))
    return out


Run = tuple[int, int, list[str], object, object]


def _run(packing: Packing, mirrors: Mirrors, jobs: int | jobs_mod.Farm) -> Run:
    levels: list[str] = []
    rep = count_bt(packing, mirrors=mirrors, jobs=jobs, levels=levels)
    first = None if rep.first_analysis is None else rep.first_analysis.level
    return rep.assemblies, rep.solutions, levels, rep.first_packing, first


@pytest.mark.parametrize("mirrors", ["drop", "keep"])
def test_workers_give_the_same_counts_levels_and_first_solution(
    monkeypatch: pytest.MonkeyPatch, mirrors: Mirrors
) -> None:
    """Cut or not, on 1 or 2 workers: the same classes; cut, the same bytes for any number."""
    whole = {}
    for name, puzzle in _puzzles():
        for problem in range(len(puzzle.problems)):
            packing = compile_packing(bt_packing_spec(puzzle, problem))
            whole[name, problem] = _run(packing, mirrors, 1)
    with monkeypatch.context() as m:
        cuts = _split_small(m)
        for name, puzzle in _puzzles():
            for problem in range(len(puzzle.problems)):
                packing = compile_packing(bt_packing_spec(puzzle, problem))
                runs = [_run(packing, mirrors, jobs) for jobs in (1, 2)]
                assert runs[0] == runs[1], (name, problem)
                a, s, levels, _, _ = whole[name, problem]
                assert runs[0][:2] == (a, s), (name, problem)
                assert Counter(runs[0][2]) == Counter(levels), (name, problem)
    assert sum(c > 1 for c in cuts) >= 6


def test_analyze_prints_the_same_line_whatever_the_jobs(split_small: list[int]) -> None:
    for source in ("puzzle-mid-02-interlocking-cube", DATA / "soma_problems.xmpuzzle"):
        lines = []
        for jobs in (1, 2, 3):
            figures = analyze(source, jobs=jobs, optimal=False)
            lines.append(figures.to_json().split('"seconds"')[0])
        assert lines[0] == lines[1] == lines[2]
    assert split_small and max(split_small) > 1


def test_a_deadline_stops_the_workers() -> None:
    """The luban's 518,400 assemblies cannot be counted in 3 s: the count stops at the
    deadline, workers and all, and keeps what it had (lower bounds)."""
    import time

    name = "puzzle-mid-03-luban-15-piece"
    packing = compile_packing(bt_packing_spec(level_puzzle(load_level(name)), 0))
    for jobs in (1, 2):
        start = time.perf_counter()
        rep = count_bt(packing, mirrors="drop", jobs=jobs, deadline=Deadline(3.0), partial=True)
        assert time.perf_counter() - start < 30  # stopped, not run to the end
        assert not rep.complete and rep.limit is not None and rep.limit.cap == "seconds"
        assert 0 <= rep.solutions <= rep.assemblies < 518_400


@pytest.mark.slow
def test_a_dask_cluster_gives_the_same_bytes(
    split_small: list[int], monkeypatch: pytest.MonkeyPatch
) -> None:
    """The subtrees on a Dask cluster (threads of this process): the same figures, levels and
    first solution as in this process, and the same exact-cover counts."""
    distributed = pytest.importorskip("distributed")
    puzzle = level_puzzle(load_level("puzzle-mid-02-interlocking-cube"))
    packing = compile_packing(bt_packing_spec(puzzle, 0))
    here = _run(packing, "drop", 1)
    with distributed.LocalCluster(
        n_workers=1, threads_per_worker=2, processes=False, dashboard_address=None
    ) as cluster:
        there = _run(packing, "drop", jobs_mod.Farm(1, cluster.scheduler_address))
        figures = analyze(
            "puzzle-mid-02-interlocking-cube", optimal=False, scheduler=cluster.scheduler_address
        )
        monkeypatch.setattr(cover_parallel, "MIN_ROWS", 1)
        farm = jobs_mod.Farm(1, cluster.scheduler_address)
        on_cluster = count_packings(SOMA.pieces, (3, 3, 3), jobs=farm)
    assert (on_cluster.solutions, on_cluster.distinct) == (11520, 240)
    assert there == here and max(split_small) > 1
    local = analyze("puzzle-mid-02-interlocking-cube", optimal=False, jobs=1)
    assert figures.to_json().split('"seconds"')[0] == local.to_json().split('"seconds"')[0]


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
