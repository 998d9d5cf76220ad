"""Every shipped puzzle level carries complete counts (BurrTools' assemblies and solutions, in
burrTxt's convention) written by the count step, and counting again gives them: the cheap ones
in the default run, all of them in the slow run."""

from __future__ import annotations

import dataclasses
import shutil
from pathlib import Path

import numpy as np
import pytest

from chaingeo.core.level import Level, PuzzleSolution, load_level, save_level
from chaingeo.core.rules import PuzzleRules
from chaingeo.generator.counts import (
    COUNT_KEYS,
    PROGRAM,
    PROGRAM_PROVEN,
    count_folder,
    count_level,
    has_counts,
    reuse_counts,
    without_counts,
)
from chaingeo.solvers.analysis import RowOptions, level_analysis_row
from chaingeo.solvers.jobs import Farm
from chaingeo.solvers.limits import SearchLimits
from tests.support.paths import LEVELS as LEVELS_DIR
from tests.support.shipped import shipped

LEVELS = shipped("puzzle")
#: Counted again in the default run (a few seconds in all); the others in the slow run.
CHEAP_ASSEMBLIES = 5000
#: Shipped levels still without complete counts, and why. Counted, a level leaves this set
#: (the test says so).
UNCOUNTED: set[str] = set()
#: Levels counted by arrangement (their congruent pieces' relabellings judged once): hard-03's
#: 11 congruent sticks are separate BurrTools shapes, 11! assemblies of one arrangement, whose
#: verdict is proven for every labelling.
BY_ARRANGEMENT = {"puzzle-hard-03-luban-separate-pieces"}


def test_every_shipped_puzzle_level_has_complete_counts() -> None:
    assert len(LEVELS) == 32
    assert {lv.id for lv in LEVELS if not has_counts(lv)} == UNCOUNTED
    for lv in LEVELS:
        if lv.id in UNCOUNTED:
            continue
        info = lv.stats["counts"]
        program = PROGRAM_PROVEN if lv.id in BY_ARRANGEMENT else PROGRAM
        assert info["convention"] == "burrtxt" and info["program"] == program, lv.id
        assert isinstance(info["version"], str) and info["complete"] is True
        assert 0 <= lv.stats["solutions"] <= lv.stats["assemblies"], lv.id


def _recount(level: Level, jobs: int) -> dict[str, object]:
    counted = count_level(without_counts(level), Farm(jobs))
    return {k: counted.stats[k] for k in COUNT_KEYS}


def _counted(cheap: bool) -> list[Level]:
    return [
        lv
        for lv in LEVELS
        if has_counts(lv)
        and (lv.stats["assemblies"] <= CHEAP_ASSEMBLIES or lv.id in BY_ARRANGEMENT) == cheap
    ]


@pytest.mark.parametrize("level", _counted(True), ids=lambda lv: lv.id)
def test_cheap_counts_count_again(level: Level) -> None:
    assert _recount(level, 1) == {k: level.stats[k] for k in COUNT_KEYS}


@pytest.mark.slow
@pytest.mark.parametrize("level", _counted(False), ids=lambda lv: lv.id)
def test_every_count_counts_again(level: Level) -> None:
    assert _recount(level, 2) == {k: level.stats[k] for k in COUNT_KEYS}


@pytest.mark.parametrize("seed", range(3))
def test_counts_are_burrtxts_whatever_the_levels_max_group(seed: int) -> None:
    """The counts are BurrTools' on the level's BurrTools file, which has no ``max_group``: a
    level that caps its moving groups (as tightly as its own plan allows) counts the same.
    Judging the first assemblies by the cap instead never ended in puzzle-hard-09 (a capped
    part whose interlocked pair walks off by single moves has no end of states)."""
    rng = np.random.default_rng(seed)
    cheap = [
        lv
        for lv in _counted(True)
        if isinstance(lv.rules, PuzzleRules) and not lv.rules.turns and lv.stats["solutions"]
    ]
    level = cheap[int(rng.integers(len(cheap)))]
    assert isinstance(level.solution, PuzzleSolution)
    cap = max(len(m.pieces) for m in level.solution.moves) + int(rng.integers(2))
    capped = dataclasses.replace(level, rules=PuzzleRules(cap))
    assert _recount(capped, 1) == {k: level.stats[k] for k in COUNT_KEYS}


@pytest.mark.parametrize("name", ["puzzle-mid-01-interlocking-cube", "puzzle-hard-05-burr6x8"])
def test_chain_analyze_counts_a_capped_level_as_burrtxt_does(name: str) -> None:
    """With a cap of one piece a move (which these levels' own plans break), ``chain analyze``
    counts the level's BurrTools file still: judged by the cap, mid-01 counted 0 of its 16
    solutions and hard-05 0 of 2."""
    level = load_level(LEVELS_DIR / "puzzle" / f"{name}.json")
    capped = dataclasses.replace(level, rules=PuzzleRules(1))
    row = level_analysis_row(capped, RowOptions(SearchLimits(seconds=None), optimal=False))
    assert (row["assemblies"], row["solutions"]) == (
        level.stats["assemblies"],
        level.stats["solutions"],
    )


def test_the_count_step_writes_what_is_missing_and_keeps_the_rest(tmp_path: Path) -> None:
    names = ["puzzle-mid-01-interlocking-cube", "puzzle-easy-04-burr6"]
    for name in names:
        shutil.copy(LEVELS_DIR / "puzzle" / f"{name}.json", tmp_path)
    first = tmp_path / f"{names[0]}.json"
    shipped_level = load_level(first)
    save_level(without_counts(shipped_level), first)
    done = count_folder(tmp_path, Farm(1))
    assert [lv.id for lv in done] == [names[0]]
    assert first.read_bytes() == (LEVELS_DIR / "puzzle" / f"{names[0]}.json").read_bytes()
    assert count_folder(tmp_path, Farm(1)) == []
    bare = without_counts(shipped_level)
    assert reuse_counts(bare, [shipped_level]) == shipped_level
    other = without_counts(load_level(tmp_path / f"{names[1]}.json"))
    assert reuse_counts(other, [shipped_level]) is None
