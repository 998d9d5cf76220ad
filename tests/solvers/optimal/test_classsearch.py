"""The search under the class bound (solvers/optimal/classsearch.py): the exact optimum of the
branch-and-bound search on random scenes with random blocks, plans that replay, the suite's
towers with multi-piece moves closed (the 36-piece puzzle-hard-09 at its bound 38), caps."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from chaingeo.cli.main import main
from chaingeo.core.geometry import Shape
from chaingeo.core.kinematics import SearchLimitError, replay_disassembly
from chaingeo.core.level import load_level
from chaingeo.solvers.analysis import analyze_level
from chaingeo.solvers.motion.disassemble import analyze_assembly, translations
from chaingeo.solvers.optimal.classbound import band_blocks, class_lower_bound
from chaingeo.solvers.optimal.classsearch import ClassSearchLimits, class_search_optimal
from tests.support.jit import seconds_for
from tests.support.paths import LEVELS
from tests.support.puzzle_strategies import random_blocks, small_scenes

SUITE = LEVELS / "puzzle"


@settings(max_examples=40, deadline=None)
@given(small_scenes(max_pieces=5), st.data(), st.sampled_from([None, 2, 1]))
def test_the_exact_optimum_on_random_scenes(
    shapes: dict[str, Shape], data: st.DataObject, max_group: int | None
) -> None:
    names = sorted(shapes)
    blocks = random_blocks(names, data)
    exact = analyze_assembly(shapes, max_group=max_group).optimal_steps
    limits = ClassSearchLimits(max_nodes=20_000)
    if exact is None:  # never comes apart: every round fails, the search ends at its cap
        with pytest.raises(SearchLimitError, match="proven lower bound"):
            class_search_optimal(shapes, blocks, max_group=max_group, limits=limits)
        return
    found = class_search_optimal(shapes, blocks, max_group=max_group, limits=limits)
    assert found.optimal_steps == exact == len(found.plan)
    assert replay_disassembly(shapes, found.plan).is_separated()
    if max_group is None or max_group > 1:
        assert all(len(m.pieces) <= (max_group or len(names)) for m in found.plan)
    else:
        assert all(len(m.pieces) == 1 for m in found.plan)
    assert found.start_bound == class_lower_bound(shapes, blocks, max_group=max_group).bound


def test_twelve_piece_tower() -> None:
    level = load_level(SUITE / "puzzle-mid-04-burr12.json")
    found = class_search_optimal(level.shapes, band_blocks(level.shapes, 6))
    assert found.optimal_steps == found.start_bound == level.optimal_steps == 13
    assert replay_disassembly(level.shapes, found.plan).is_separated()


def test_thirty_six_piece_tower_with_multi_piece_moves_is_closed() -> None:
    """puzzle-hard-09 (six burr units; the file's moves carry one piece, here any group): the
    class bound 38 is met by a replayed plan of 38 moves, so o_i = 38 (the units one by one
    take 41; A* with pair databases proves 36). Its plan shares slides between units."""
    path = SUITE / "puzzle-hard-09-burr36.json"
    level = load_level(path)
    blocks = json.loads(path.read_text())["stats"]["blocks"]
    found = class_search_optimal(level.shapes, blocks)
    assert found.optimal_steps == found.start_bound == len(found.plan) == 38
    assert replay_disassembly(level.shapes, found.plan).is_separated()
    unit = {n: k for k, b in enumerate(blocks) for n in b}
    assert any(len({unit[p] for p in m.pieces}) > 1 for m in found.plan if m.distance)


@pytest.mark.slow
def test_the_other_thirty_six_piece_tower() -> None:
    """puzzle-hard-08 with multi-piece moves: o_i = 41, its class bound (about 4 minutes;
    ``chain bench astar`` prints it too)."""
    level = load_level(SUITE / "puzzle-hard-08-burr36.json")
    found = class_search_optimal(level.shapes, band_blocks(level.shapes, 6))
    assert found.optimal_steps == len(found.plan) == 41
    assert replay_disassembly(level.shapes, found.plan).is_separated()


def test_caps_and_errors() -> None:
    level = load_level(SUITE / "puzzle-hard-09-burr36.json")
    blocks = band_blocks(level.shapes, 6)
    with pytest.raises(SearchLimitError, match=r"node cap.*proven lower bound 38"):
        class_search_optimal(level.shapes, blocks, limits=ClassSearchLimits(max_nodes=5))
    with pytest.raises(SearchLimitError, match=r"time limit.*proven lower bound"):
        class_search_optimal(level.shapes, blocks, limits=ClassSearchLimits(seconds=0.0))
    with pytest.raises(SearchLimitError, match="class bound state cap"):
        class_search_optimal(level.shapes, blocks, limits=ClassSearchLimits(vector_states=3))
    with pytest.raises(ValueError, match="split the pieces"):
        class_search_optimal(level.shapes, blocks[1:])
    with pytest.raises(ValueError, match="max_nodes"):
        ClassSearchLimits(max_nodes=0)


def test_chain_analyze_proves_a_multi_piece_tower(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A tower level that carries its blocks and allows moves of any size: ``chain analyze``
    (one analysis everywhere, :mod:`chaingeo.solvers.analysis`) proves o_i with the class search."""
    raw = json.loads((SUITE / "puzzle-hard-09-burr36.json").read_text())
    raw["rules"]["max_group"] = None
    path = tmp_path / "tower.json"
    path.write_text(json.dumps(raw))
    budget = ["--seconds", f"{seconds_for(60):g}", "--optimal-seconds", f"{seconds_for(10):g}"]
    assert main(["analyze", str(path), "--no-assemble", *budget]) == 0
    out = json.loads(capsys.readouterr().out)
    level = load_level(path)
    quick = analyze_assembly(
        level.shapes, max_group=None, optimal=False
    )  # BurrTools' level and moves
    assert out["optimal_steps"] == 38 and (out["level"], out["moves"]) == (quick.level, quick.moves)
    found = analyze_level(level)
    assert found.optimal_steps == len(found.plan) == 38 and quick.moves == 42
    assert replay_disassembly(level.shapes, translations(found.plan)).is_separated()
    raw["stats"]["blocks"] = raw["stats"]["blocks"][1:]
    path.write_text(json.dumps(raw))
    with pytest.raises(ValueError, match="every piece exactly once"):
        analyze_level(load_level(path))
