"""The shipped puzzle suite: the split, goals, unique puzzles, and exact optimal plans."""

from __future__ import annotations

import json
from collections import Counter
from pathlib import Path

import pytest

from chaingeo.cli.main import main
from chaingeo.core.kinematics import disassembly_of_assembly_plan, replay_disassembly
from chaingeo.core.level import Level, PuzzleSolution, level_bytes, load_levels
from generator.puzzle import difficulty_of
from solvers.analysis import analyze_level
from solvers.partsearch import SearchLimits

SUITE = Path(__file__).resolve().parents[1] / "levels" / "puzzle"
LEVELS = load_levels(SUITE) if any(SUITE.glob("*.json")) else []


def test_the_split_and_the_goals() -> None:
    assert len(LEVELS) == 32
    assert Counter(lv.difficulty for lv in LEVELS) == {"easy": 10, "mid": 12, "hard": 10}
    assert {lv.goal for lv in LEVELS} == {"disassemble", "assemble"}
    assert len({lv.provenance.signature for lv in LEVELS}) == 32
    # every family of issue 4, each with both goals, from six pieces to more than thirty
    goals: dict[str, set[str]] = {}
    for lv in LEVELS:
        goals.setdefault(str(lv.stats["shape"]), set()).add(lv.goal)
    for shape in ("burr6", "burr3", "plate3", "cube3", "cube4", "burr36"):
        assert goals.get(shape) == {"disassemble", "assemble"}, shape
    assert "burr12" in goals
    assert max(len(lv.pieces) for lv in LEVELS) > 30
    # interlocking: nothing comes free in one move (first part's level >= 2), except in the
    # towers of burr units, which come apart from the top
    for lv in LEVELS:
        if not str(lv.stats["shape"]).startswith(("burr12", "burr36")):
            assert int(lv.stats["first_level"]) >= 2, lv.id


@pytest.mark.parametrize("level", LEVELS, ids=lambda lv: lv.id)
def test_stored_plan_replays_and_matches_the_stats(level: Level) -> None:
    assert isinstance(level.solution, PuzzleSolution)
    moves = list(level.solution.moves)
    plan = moves if level.goal == "disassemble" else disassembly_of_assembly_plan(moves)
    assert replay_disassembly(level.shapes, plan).is_separated()
    assert len(moves) == level.optimal_steps
    first = int(level.stats["first_level"])
    assert level.difficulty == difficulty_of(first, level.optimal_steps, len(level.pieces))


@pytest.mark.parametrize("level", LEVELS, ids=lambda lv: lv.id)
def test_optimal_steps_are_optimal(level: Level) -> None:
    """Every level is small enough to search again in the default run (about 15 s in all);
    towers of burr units with single-piece moves are proven with the block bound."""
    limits = SearchLimits(seconds=None, max_total_states=5_000_000)
    result = analyze_level(level, limits)
    assert result.optimal_steps == level.optimal_steps
    assert result.level == level.stats["level"] and result.moves == level.stats["moves"]


@pytest.mark.slow
def test_suite_rebuilds_byte_for_byte(tmp_path: Path) -> None:
    from generator.puzzle_suite import build_puzzle_suite

    build_puzzle_suite(tmp_path)
    for lv in LEVELS:
        assert (tmp_path / f"{lv.id}.json").read_bytes() == level_bytes(lv)


@pytest.mark.parametrize(
    "level", [lv for lv in LEVELS if "blocks" in lv.stats], ids=lambda lv: lv.id
)
def test_chain_analyze_proves_a_tower_as_the_generator_did(
    level: Level, capsys: pytest.CaptureFixture[str]
) -> None:
    """One analysis everywhere: ``chain analyze`` reads the blocks the level carries and
    proves the stored o_i with the block bound (the plain search would stop at its caps)."""
    path = SUITE / f"{level.id}.json"
    assert main(["analyze", str(path), "--no-assemble", "--seconds", "60"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["optimal_steps"] == level.optimal_steps and out["level"] == level.stats["level"]
