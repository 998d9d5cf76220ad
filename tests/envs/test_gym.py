"""The Gymnasium environments: Gymnasium's own checker, reset options, masks, episode ends."""

from __future__ import annotations

import warnings

import gymnasium
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

from chaingeo.core.limits import MAX_STACKING_ACTIONS
from chaingeo.envs.actions.types import PlaceAction, action_of_move
from chaingeo.envs.gym import CHARSET, PuzzleEnv, StackingEnv
from tests.support.env_levels import drop_level, puzzle_levels, soma_level, tiny_level


def stacking_env(**kw: object) -> StackingEnv:
    return StackingEnv([tiny_level(), drop_level(), soma_level()], **kw)  # type: ignore[arg-type]


def puzzle_env(**kw: object) -> PuzzleEnv:
    return PuzzleEnv(list(puzzle_levels()), **kw)  # type: ignore[arg-type]


@pytest.mark.parametrize("make", [stacking_env, puzzle_env])
def test_check_env_passes(make: object) -> None:
    env = make(images=False, text_state=True)  # type: ignore[operator]
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the checker's warnings count as failures
        warnings.filterwarnings("ignore", message=".*environment not having a spec.*")
        check_env(env, skip_render_check=True)


@pytest.mark.parametrize("env_id", ["chaingeo/Stacking-v0", "chaingeo/Puzzle-v0"])
def test_check_env_with_images_through_make(env_id: str) -> None:
    levels = [tiny_level()] if "Stacking" in env_id else [puzzle_levels()[0], puzzle_levels()[1]]
    env = gymnasium.make(env_id, levels=levels, image_size=128)
    check_env(env.unwrapped)
    obs, _ = env.reset(seed=1)
    for image in obs["images"].values():
        assert image.dtype == np.uint8 and image.ndim == 3 and image.shape[2] == 3
    env.close()


def test_make_registers_both_ids() -> None:
    env = gymnasium.make("chaingeo/Stacking-v0", levels=[tiny_level()], images=False)
    assert isinstance(env.unwrapped, StackingEnv)
    env = gymnasium.make("chaingeo/Puzzle-v0", levels=list(puzzle_levels()), images=False)
    assert isinstance(env.unwrapped, PuzzleEnv)


def test_reset_picks_by_seed_or_by_id() -> None:
    env = stacking_env(images=False)
    picks = {env.reset(seed=s)[1]["level_id"] for s in range(12)}
    assert picks == {"tiny-test", "drop-test", "soma-test"}
    assert env.reset(seed=3)[1]["level_id"] == env.reset(seed=3)[1]["level_id"]
    _, info = env.reset(options={"level": "soma-test"})
    assert info["level_id"] == "soma-test" and info["steps_used"] == 0
    with pytest.raises(ValueError, match="unknown stacking level"):
        env.reset(options={"level": "lock3-assemble"})
    with pytest.raises(ValueError, match="no puzzle levels"):
        PuzzleEnv([tiny_level()], images=False)


def test_stacking_episode_mask_reward_and_termination() -> None:
    env = stacking_env(images=False)
    obs, info = env.reset(options={"level": "soma-test"})
    assert set(obs["text"]) <= CHARSET and "Pack all 7 pieces" in obs["text"]
    catalogue = env.action_catalogue()
    assert info["action_mask"].shape == (MAX_STACKING_ACTIONS,)
    assert info["action_mask"].dtype == np.int8 and not info["action_mask"][len(catalogue) :].any()
    level = soma_level()
    placements = level.solution.placements  # type: ignore[union-attr]
    for i, name in enumerate(level.solution.order):  # type: ignore[union-attr]
        text = PlaceAction(name, placements[name].cells).to_text()
        assert info["action_mask"][catalogue.index(text)] == 1
        obs, reward, terminated, truncated, info = env.step(text)
        last = i == len(level.solution.order) - 1  # type: ignore[union-attr]
        assert (reward, terminated, truncated) == (1.0 if last else 0.0, last, False)
        assert info["legal"] and info["error"] is None
    assert info["success"] and info["steps_used"] == level.optimal_steps
    with pytest.raises(RuntimeError, match="episode has ended"):
        env.step("finish")


def test_bad_text_counts_and_truncates() -> None:
    env = stacking_env(images=False)
    env.reset(options={"level": "tiny-test"})
    budget = tiny_level().max_steps
    for i in range(budget):
        obs, reward, terminated, truncated, info = env.step("place nothing \u00e9")
        assert info["error"] == "unparseable" and not terminated and reward == 0.0
        assert truncated == (i == budget - 1)
        assert set(obs["text"]) <= CHARSET  # the echoed non-ASCII letter became '?'


def test_finish_terminates_the_puzzle_episode_and_lists_moves() -> None:
    env = puzzle_env(images=False, list_legal_actions=True)
    _, info = env.reset(options={"level": "lock3-disassemble"})
    assert "move red -x inf" in info["legal_actions"] and "action_mask" not in info
    _, reward, terminated, truncated, info = env.step("finish")
    assert (reward, terminated, truncated) == (0.0, True, False) and not info["success"]
    env.reset(options={"level": "lock3-assemble"})
    lock3 = next(lv for lv in puzzle_levels() if lv.id == "lock3-assemble")
    for move in lock3.solution.moves:  # type: ignore[union-attr]
        _, reward, terminated, truncated, info = env.step(action_of_move(move).to_text())
    assert terminated and reward == 1.0 and info["steps_used"] == 2
