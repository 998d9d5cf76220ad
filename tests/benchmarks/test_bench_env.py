"""``chain bench env``: its reference environments show what ours show; a smoke run (slow)."""

from __future__ import annotations

import argparse
from typing import Any

import gymnasium
import pytest
from gymnasium.utils.env_checker import data_equivalence

from chaingeo.benchmarks import env as bench
from chaingeo.envs.demos import plan_texts
from tests.support.env_levels import puzzle_levels, soma_level


@pytest.mark.parametrize("family", ["stacking", "puzzle"])
def test_the_png_reference_shows_the_same_observations(family: str) -> None:
    level = soma_level() if family == "stacking" else puzzle_levels()[0]
    _, ours_cls, png_cls = bench.FAMILIES[family]
    ours, ref = ours_cls([level], image_size=128), png_cls([level], image_size=128)
    seen: list[tuple[Any, Any]] = [(ours.reset(seed=1), ref.reset(seed=1))]
    for text in plan_texts(level):
        seen.append((ours.step(text), ref.step(text)))
    for mine, theirs in seen:
        assert data_equivalence(mine, theirs, exact=True)


@pytest.mark.slow
def test_bench_env_quick_runs(capsys: pytest.CaptureFixture[str]) -> None:
    assert bench.run(argparse.Namespace(quick=True, repeat=1)) == 0
    out = capsys.readouterr().out
    assert "worst ratio" in out and out.count("async") == 8
    assert "chaingeo/Stacking-v0" in gymnasium.registry
