"""BurrTools' verdicts on rows (chaingeo.solvers.assembly.btcount.RowVerdicts) against the general
path: the same image, the same counts, the same level strings in the same order, on puzzles we did
not hand-make (seeded random boxes cut into pieces, congruent and mirror pieces, holes) and on the
feature examples and shipped levels."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from chaingeo.core.formats.bt_level import level_puzzle
from chaingeo.core.formats.burrtools import BTPuzzle
from chaingeo.core.level import load_level
from chaingeo.generator.bt_examples import EXAMPLES
from chaingeo.solvers.assembly.btassemble import (
    BTFrame,
    Mirrors,
    bt_packing_spec,
    iter_classes,
    named_assembly,
)
from chaingeo.solvers.assembly.btcount import RowVerdicts, count_bt
from chaingeo.solvers.cover.constrained import compile_packing
from tests.support.burrtxt import random_puzzle
from tests.support.paths import LEVELS

PUZZLES = LEVELS / "puzzle"
_SMALL = ("cube4", "burr6", "burr12", "three", "stair")


def _same_counts(puzzle: BTPuzzle, mirrors: Mirrors) -> None:
    packing = compile_packing(bt_packing_spec(puzzle, 0))
    fast_levels: list[str] = []
    slow_levels: list[str] = []
    fast = count_bt(packing, mirrors=mirrors, levels=fast_levels)
    slow = count_bt(packing, mirrors=mirrors, levels=slow_levels, fast=False)
    assert (fast.assemblies, fast.solutions) == (slow.assemblies, slow.solutions)
    assert fast_levels == slow_levels
    assert fast.first_packing == slow.first_packing


def _same_images(puzzle: BTPuzzle, most: int = 200) -> int:
    """Every assembly's image on rows is the general path's image, piece by piece."""
    packing = compile_packing(bt_packing_spec(puzzle, 0))
    frame = BTFrame(packing)
    verdicts = RowVerdicts(packing, None, want_levels=False)
    checked = 0
    for rows in iter_classes(packing):
        pieces = rows[verdicts.piece[rows]].astype(np.int64)
        if len(pieces) < 2 or checked >= most:
            continue
        image = verdicts.image_rows(pieces)
        assert image is not None
        want = frame(named_assembly(packing, rows))
        got = [packing.placed(int(r)) for r in image]
        assert got == list(want.values())
        checked += 1
    return checked


@pytest.mark.parametrize("index", range(40))
def test_random_puzzles_count_alike(index: int) -> None:
    rng = np.random.default_rng(np.random.SeedSequence([2026_11_25, index]))
    puzzle = random_puzzle(rng)
    _same_counts(puzzle, "drop" if index % 2 else "keep")


@pytest.mark.parametrize("index", range(20))
def test_random_puzzles_choose_burrtools_image(index: int) -> None:
    rng = np.random.default_rng(np.random.SeedSequence([7, index]))
    _same_images(random_puzzle(rng))


@pytest.mark.parametrize("name", sorted(EXAMPLES))
def test_feature_examples_count_alike(name: str) -> None:
    _same_counts(EXAMPLES[name](), "drop")


@pytest.mark.parametrize(
    "path",
    [p for p in sorted(PUZZLES.glob("*.json")) if any(s in p.name for s in _SMALL)],
    ids=lambda p: p.stem,
)
def test_small_shipped_levels_count_alike(path: Path) -> None:
    puzzle = level_puzzle(load_level(path))
    _same_counts(puzzle, "drop")
    assert _same_images(puzzle, most=50) > 0
