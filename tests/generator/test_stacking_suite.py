"""The shipped stacking suite: the CHAIN split, every level re-verified, reproducible."""

from __future__ import annotations

from collections import Counter
from functools import cache
from pathlib import Path

import pytest

from chaingeo.core.level import Level, level_bytes, load_level
from chaingeo.generator.checks import level_problems
from chaingeo.generator.stacking import make
from chaingeo.generator.suite import SUITE, suite_entry
from tests.support.paths import ROOT

SUITE_DIR = ROOT / "levels" / "stacking"
FILES = sorted(SUITE_DIR.glob("*.json"))


@cache
def _level(path: Path) -> Level:
    return load_level(path)


def test_the_suite_is_exactly_the_chain_split() -> None:
    assert len(FILES) == 77
    split = Counter((_level(f).box, _level(f).difficulty) for f in FILES)
    assert split == {(e.box, e.mode): e.count for e in SUITE}
    by_mode = Counter(_level(f).difficulty for f in FILES)
    assert by_mode == {"easy": 10, "mid": 20, "hard": 47}


@pytest.mark.parametrize("path", FILES, ids=[f.stem for f in FILES])
def test_every_suite_level_keeps_its_promises(path: Path) -> None:
    level = _level(path)  # loading re-checks the stored packing is an exact cover
    entry = suite_entry(level.box, level.difficulty)  # type: ignore[arg-type]
    assert path.name == f"{level.id}.json"
    assert level.provenance.seed == entry.seed
    assert level_problems(level, entry.config) == []  # includes a fresh exact-cover search
    assert level.max_steps >= level.optimal_steps == len(level.pieces)


def test_no_two_suite_levels_share_a_signature() -> None:
    sigs = Counter(_level(f).provenance.signature for f in FILES)
    assert sigs.most_common(1)[0][1] == 1


@pytest.mark.parametrize("name", ["stacking-2x2x3-easy-s103", "stacking-2x3x3-hard-s109"])
def test_regenerating_a_suite_item_reproduces_its_bytes(name: str) -> None:
    path = next(f for f in FILES if f.name.startswith(name))
    level = _level(path)
    entry = suite_entry(level.box, level.difficulty)  # type: ignore[arg-type]
    assert level.provenance.index is not None
    again = make(entry.config, entry.seed, level.provenance.index)
    assert isinstance(again, Level)
    assert level_bytes(again) == path.read_bytes()


def test_docs_document_the_suite_command() -> None:
    assert "chain generate suite" in (ROOT / "docs" / "guides" / "generating.md").read_text()
