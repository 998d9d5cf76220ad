"""The shipped puzzle suite: the split, goals, unique puzzles, and exact optimal plans."""

from __future__ import annotations

import json
from collections import Counter
from pathlib import Path

import pytest

from chaingeo.cli.main import main
from chaingeo.core.formats.models import import_model
from chaingeo.core.kinematics import disassembly_of_assembly_plan, replay_disassembly
from chaingeo.core.level import Level, PuzzleSolution, level_bytes
from chaingeo.core.rules import PuzzleRules
from chaingeo.generator.counts import without_counts
from chaingeo.generator.imported import imported_puzzle_level
from chaingeo.generator.puzzle import difficulty_of
from chaingeo.generator.puzzle_suite import MODEL_LIMITS
from chaingeo.solvers.analysis import analyze_level
from chaingeo.solvers.limits import SearchLimits
from tests.support.env_levels import design_of
from tests.support.paths import LEVELS as LEVELS_DIR
from tests.support.shared_files import MODELS, needs_models
from tests.support.shipped import shipped

SUITE = LEVELS_DIR / "puzzle"
LEVELS = shipped("puzzle")


def _model(level: Level) -> str | None:
    """The CHAIN model an imported level comes from (None for a generated one)."""
    design = design_of(level)
    return design.removeprefix("chain/") if design.startswith("chain/") else None


#: CHAIN's published models that import exactly (docs/guides/importing.md); the other
#: three are refused (two not on a lattice) or are a stacking model.
IMPORTABLE = {
    "interlocking-cube-puzzle",
    "liliput",
    "luban-15-piece",
    "luban-3-piece",
    "luban-6-piece",
    "luban-separate-pieces",
    "three-plate-burr-puzzle",
}


def test_the_split_and_the_goals() -> None:
    assert len(LEVELS) == 32
    assert Counter(lv.difficulty for lv in LEVELS) == {"easy": 10, "mid": 12, "hard": 10}
    for tier in ("easy", "mid", "hard"):
        assert {lv.goal for lv in LEVELS if lv.difficulty == tier} == {"disassemble", "assemble"}
    # one puzzle twice only as a model asked both ways
    assert len({(lv.provenance.signature, lv.goal) for lv in LEVELS}) == 32
    by_signature: dict[str, set[str | None]] = {}
    for lv in LEVELS:
        by_signature.setdefault(lv.provenance.signature, set()).add(_model(lv))
    assert all(len(m) == 1 for m in by_signature.values())
    # every CHAIN model that imports exactly, and every generated family
    assert {_model(lv) for lv in LEVELS} - {None} == IMPORTABLE
    shapes = {str(lv.stats["shape"]) for lv in LEVELS if _model(lv) is None}
    assert shapes == {"burr6", "burr3", "plate3", "cube3", "cube4", "burr12", "burr36", "burr6x8"}
    assert max(len(lv.pieces) for lv in LEVELS) > 30
    # interlocking: in generated levels other than towers of burr units (which come apart
    # from the top), nothing comes free in one move
    for lv in LEVELS:
        if _model(lv) is None and not str(lv.stats["shape"]).startswith(("burr12", "burr36")):
            assert int(lv.stats["first_level"]) >= 2, lv.id


def test_the_hard_tier_is_deep() -> None:
    """Hard means strong interlocks and long plans: most first parts need far more than five
    moves, and the CHAIN models of the tier need more than ten."""
    hard = [lv for lv in LEVELS if lv.difficulty == "hard"]
    first = sorted(int(lv.stats["first_level"]) for lv in hard)
    assert sum(f >= 7 for f in first) >= 5, first
    assert all(int(lv.stats["first_level"]) > 10 for lv in hard if _model(lv) in
               {"liliput", "three-plate-burr-puzzle"})  # fmt: skip


@needs_models
@pytest.mark.parametrize(
    "level", [lv for lv in LEVELS if _model(lv) is not None], ids=lambda lv: lv.id
)
def test_imported_levels_are_what_the_importer_makes(level: Level) -> None:
    """Re-import the source model with the level's options: the same bytes, apart from the
    counts the count step adds (tests/generator/test_puzzle_counts.py checks those)."""
    assert MODELS is not None and isinstance(level.rules, PuzzleRules) and level.goal != "pack"
    model = import_model(MODELS / str(_model(level)), "puzzle")
    again, _ = imported_puzzle_level(
        model, goal=level.goal, turns=level.rules.turns, limits=MODEL_LIMITS, level_id=level.id
    )
    assert level_bytes(again) == level_bytes(without_counts(level))


@pytest.mark.parametrize("level", LEVELS, ids=lambda lv: lv.id)
def test_stored_plan_replays_and_matches_the_stats(level: Level) -> None:
    assert isinstance(level.solution, PuzzleSolution)
    moves = list(level.solution.moves)
    plan = moves if level.goal == "disassemble" else disassembly_of_assembly_plan(moves)
    assert replay_disassembly(level.shapes, plan, level.rods).is_separated()
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
@needs_models
def test_suite_rebuilds_byte_for_byte(tmp_path: Path) -> None:
    from chaingeo.generator.puzzle_suite import build_puzzle_suite

    assert MODELS is not None
    build_puzzle_suite(tmp_path, MODELS, jobs=2, counts_from=SUITE)
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
