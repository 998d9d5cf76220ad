"""The stacking generator: configurations, the three modes, determinism and rejections."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from chaingeo.core.level import Level, level_bytes, revalidate
from chaingeo.generator.checks import level_problems
from chaingeo.generator.config import (
    StackingConfig,
    config_names,
    get_config,
    parse_box,
    register_config,
    stacking_config,
)
from chaingeo.generator.result import ATTEMPTS_KEY, GenerationRejection
from chaingeo.generator.stacking import easy_cuboids, make, random_multiset, stage_problem


def _level(config: StackingConfig, seed: int, index: int) -> Level:
    out = make(config, seed, index)
    assert isinstance(out, Level), out
    return out


# -- configuration ------------------------------------------------------------------------------


def test_parse_box() -> None:
    assert parse_box("3x3x4") == (3, 3, 4)
    assert parse_box(" 2 X 3 x 4 ") == (2, 3, 4)
    for bad in ("3x3", "axbxc", "0x2x2", "3x3x4x1"):
        with pytest.raises(ValueError, match="box"):
            parse_box(bad)


@pytest.mark.parametrize(
    ("changes", "message"),
    [
        ({"box": (0, 2, 2)}, "box"),
        ({"mode": "extreme"}, "mode"),
        ({"min_piece": 6}, "min_piece"),
        ({"max_pieces": 1}, "max_pieces"),
        ({"attempts": 0}, "attempts"),
        ({"min_nodes": -1}, "min_nodes"),
        ({"support": "glue"}, "support"),
    ],
)
def test_bad_configs_are_refused(changes: dict[str, object], message: str) -> None:
    base: dict[str, object] = {"box": (2, 3, 4), "mode": "hard"}
    with pytest.raises(ValueError, match=message):
        StackingConfig(**(base | changes))  # type: ignore[arg-type]


def test_registry_holds_every_suite_box_and_mode() -> None:
    names = config_names()
    assert "3x3x4-hard" in names and "2x2x2-easy" in names and len(names) >= 30
    cfg = get_config("4x4x4-hard")
    assert cfg.box == (4, 4, 4) and cfg.mode == "hard" and cfg.max_pieces == 13
    assert cfg.min_nodes > 0 and cfg.stages == [(4, 200), (3, 200)]
    assert get_config("2x2x3-easy").max_piece_cells == 8
    assert get_config("2x2x3-mid").stages == [(3, 400)]
    with pytest.raises(ValueError, match="no stacking config named 'nope'; known: "):
        get_config("nope")
    with pytest.raises(ValueError, match="already registered"):
        register_config("3x3x4-hard", cfg)
    assert stacking_config((5, 5, 5), "mid").max_pieces == 28  # 125 / 4.5
    assert cfg.to_json()["box"] == [4, 4, 4]


def test_easy_parts_are_cuboids_with_two_equal_sides_and_no_2x3_face() -> None:
    parts = easy_cuboids((2, 2, 3), 3, 8)
    assert sorted(s.extent for s in parts) == [(1, 1, 3), (1, 2, 2), (2, 2, 2)]
    assert [len(s) for s in easy_cuboids((4, 4, 4), 4, 8)] == [4, 4, 8]
    rng = np.random.default_rng(0)
    for _ in range(20):
        multiset = random_multiset(18, easy_cuboids((2, 3, 3), 3, 8), range(2, 6), rng)
        assert multiset is not None and sum(len(s) for s in multiset) == 18
        assert 2 <= len(multiset) <= 5
    assert random_multiset(18, easy_cuboids((2, 3, 3), 4, 8), range(2, 6), rng) is None


def test_stage_problems_are_decided_up_front() -> None:
    cfg = get_config("2x3x3-easy")
    assert stage_problem(cfg, 4) == "no-cuboid-multiset"  # plates and cubes never make 18
    assert stage_problem(cfg, 3) is None
    assert stage_problem(stacking_config((3, 3, 3), "hard", max_pieces=5), 4) == (
        "no-feasible-piece-count"
    )


# -- the modes ---------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("name", "index"),
    [("2x2x2-easy", 0), ("2x2x3-easy", 1), ("2x2x2-mid", 0), ("2x3x3-mid", 2), ("2x3x3-hard", 0)],
)
def test_levels_keep_every_promise_of_their_mode(name: str, index: int) -> None:
    cfg = get_config(name)
    level = _level(cfg, 11, index)
    assert level_problems(level, cfg) == []
    assert revalidate(level) == level
    assert level.id == f"stacking-{name.split('-')[0]}-{cfg.mode}-s11-{index:06d}"
    assert level.provenance.seed == 11 and level.provenance.index == index
    stats = level.stats
    assert stats["mode"] == cfg.mode and stats["pieces"] == len(level.pieces)
    assert stats["exact_cover"]["solutions"] >= 1
    assert stats["exact_cover"]["nodes_first"] >= cfg.min_nodes
    assert stats["attempts"] == 1 + sum(stats[ATTEMPTS_KEY].values())
    names = {p.name for p in level.pieces}
    assembly = stats["linear_assembly"]
    assert sorted(n for n, _ in assembly) == sorted(names)
    assert level.optimal_steps == len(level.pieces) and level.max_steps >= level.optimal_steps


def test_hard_levels_need_the_configured_search_effort() -> None:
    cfg = get_config("3x3x3-hard")
    level = _level(cfg, 5, 0)
    assert level_problems(level, cfg) == []
    assert level.stats["exact_cover"]["nodes_first"] >= cfg.min_nodes >= 20
    shapes = [p.shape for p in level.pieces]
    assert len({s.canonical() for s in shapes}) == len(shapes)


def test_make_is_a_pure_function_of_config_seed_and_index() -> None:
    cfg = get_config("2x3x4-mid")
    a = level_bytes(_level(cfg, 3, 4))
    assert level_bytes(_level(cfg, 3, 4)) == a
    assert level_bytes(_level(cfg, 3, 5)) != a
    assert level_bytes(_level(cfg, 4, 4)) != a


def test_pieces_are_handed_shuffled_and_turned() -> None:
    cfg = get_config("2x4x4-hard")
    level = _level(cfg, 1, 0)
    placed = level.solution.placements  # type: ignore[union-attr]
    turned = sum(p.shape != placed[p.name].normalized() for p in level.pieces)
    assert turned >= 1


def test_no_level_gives_a_rejection_with_every_reason() -> None:
    # Two 4-cell pieces in a 2x2x2 box are always congruent: hard mode cannot succeed.
    cfg = stacking_config((2, 2, 2), "hard", min_piece=4, fallback_min_piece=None, attempts=5)
    out = make(cfg, 0, 7)
    assert isinstance(out, GenerationRejection)
    assert out.reason == "repair-failed:repeated-shape"
    assert out.attempts == {"repair-failed:repeated-shape": 5}
    assert (out.seed, out.index) == (0, 7)
    impossible = make(stacking_config((3, 3, 3), "hard", max_pieces=5, attempts=3), 0, 0)
    assert isinstance(impossible, GenerationRejection)
    assert impossible.attempts == {"no-feasible-piece-count": 2}


def test_without_linear_assembly_rule_levels_still_verify() -> None:
    cfg = stacking_config((2, 3, 3), "hard", linear_assembly=False)
    level = _level(cfg, 2, 0)
    assert level_problems(level, cfg) == []


@settings(max_examples=12)
@given(
    st.sampled_from(["2x2x3-easy", "2x2x4-mid", "2x3x3-mid", "2x3x3-hard", "2x2x4-easy"]),
    st.integers(0, 2**32),
    st.integers(0, 10_000),
)
def test_every_outcome_is_a_sound_level_or_a_counted_rejection(
    name: str, seed: int, index: int
) -> None:
    cfg = get_config(name).replace(attempts=40)
    out = make(cfg, seed, index)
    if isinstance(out, GenerationRejection):
        assert out.reason in out.attempts and sum(out.attempts.values()) <= cfg.attempts
    else:
        assert level_problems(out, cfg) == []
        assert out.stats["attempts"] <= cfg.attempts
