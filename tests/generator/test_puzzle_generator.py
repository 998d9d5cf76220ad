"""The puzzle generator: layouts, determinism, exact o_i, both goals, the CLI."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

from chaingeo.cli.main import main
from chaingeo.core.kinematics import (
    disassembly_of_assembly_plan,
    reference_optimal_disassembly,
    replay_disassembly,
)
from chaingeo.core.level import Level, level_bytes, load_level
from chaingeo.generator.config import PuzzleConfig
from chaingeo.generator.layouts import get_layout
from chaingeo.generator.puzzle import difficulty_of, make
from chaingeo.generator.result import GenerationRejection

SMALL = PuzzleConfig(shape="cube3", pieces=3, hill_steps=20, hole_rate=0.3)


def test_layout_designs_are_disjoint_pieces_of_the_slots() -> None:
    layout = get_layout("burr6")
    assert len(layout.shared) == 32  # 24 cells in two slots, the 2x2x2 core in three
    design = [layout.owners(c)[-1] if i % 3 else -1 for i, c in enumerate(layout.shared)]
    pieces = layout.pieces(design)
    cells = [c for p in pieces for c in p.cells]
    assert len(cells) == len(set(cells))
    union = {c for s in layout.slots for c in s.cells}
    holes = {c for c, o in zip(layout.shared, design, strict=True) if o < 0}
    assert set(cells) == union - holes
    assert len(get_layout("burr12").slots) == 12


def test_make_is_deterministic_and_exact() -> None:
    first = make(SMALL, 5, 0)
    assert isinstance(first, Level)
    again = make(SMALL, 5, 0)
    assert isinstance(again, Level) and level_bytes(first) == level_bytes(again)
    ref = reference_optimal_disassembly(first.shapes)
    assert ref is not None and first.optimal_steps == len(ref)
    assert replay_disassembly(first.shapes, first.solution.moves).is_separated()  # type: ignore[union-attr]
    stats = first.stats
    assert first.difficulty == difficulty_of(stats["first_level"], first.optimal_steps, 3)


def test_assemble_goal_stores_the_reversed_plan() -> None:
    level = make(dataclasses.replace(SMALL, goal="assemble"), 5, 0)
    plain = make(SMALL, 5, 0)
    assert isinstance(level, Level) and isinstance(plain, Level)
    assert level.goal == "assemble" and level.optimal_steps == plain.optimal_steps
    moves = level.solution.moves  # type: ignore[union-attr]
    assert disassembly_of_assembly_plan(moves) == list(plain.solution.moves)  # type: ignore[union-attr]


def test_rejections_say_why() -> None:
    item = make(PuzzleConfig(shape="burr6", hill_steps=0, min_level=9), 5, 0)
    assert isinstance(item, GenerationRejection) and "below 9" in item.reason


def test_chain_generate_puzzle(tmp_path: Path, capsys: object) -> None:
    out = tmp_path / "gen"
    args = ["generate", "puzzle", "--shape", "cube3", "--pieces", "3", "--count", "1"]
    args += [
        "--seed",
        "5",
        "--out",
        str(out),
        "--no-progress",
        "--no-pictures",
        "--hill-steps",
        "20",
        "--hole-rate",
        "0.3",
    ]
    assert main(args) == 0
    (path,) = sorted(out.glob("*.json"))
    level = load_level(path)
    assert level.family == "puzzle" and level.provenance.seed == 5
    summary = json.loads(capsys.readouterr().out.strip().splitlines()[-1])  # type: ignore[attr-defined]
    assert summary["accepted"] == 1
