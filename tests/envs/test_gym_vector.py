"""Pictures as arrays, fixed spaces, vector environments (sync and async) and their seeding."""

from __future__ import annotations

import warnings
from typing import Any

import gymnasium
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env, data_equivalence
from gymnasium.vector import AutoresetMode
from gymnasium.vector.utils import iterate

import chaingeo.envs.gym as gym_module
from chaingeo.core.level import Level
from chaingeo.core.limits import LimitError
from chaingeo.envs.demos import plan_texts
from chaingeo.envs.frames import FrameCache, png_frames, render_frames
from chaingeo.envs.gym import ENV_IDS, PuzzleEnv, StackingEnv, _ascii
from chaingeo.envs.machines import new_state
from chaingeo.envs.observation import observe
from chaingeo.envs.vector import SeedSequenceSeeds, vector_seeds
from tests.support.env_levels import drop_level, puzzle_levels, soma_level, tiny_level

SIZE = 128


def stacking() -> list[Level]:
    return [tiny_level(), drop_level(), soma_level()]


def puzzles() -> list[Level]:
    return list(puzzle_levels())


def walk(level: Level) -> list[Any]:
    """The states along a level's plan, the start included."""
    state = new_state(level)
    out = [state.clone()]
    for text in plan_texts(level):
        assert state.step_text(text).legal
        out.append(state.clone())
    return out


@pytest.mark.parametrize("level", [soma_level(), puzzles()[0]], ids=["soma", "puzzle"])
def test_frames_are_the_pixels_of_todays_png_and_the_cache_is_exact(level: Level) -> None:
    cache = FrameCache(SIZE, max_bytes=SIZE * SIZE * 3 * 6)  # room for one position: evictions
    states = walk(level)
    for state in [*states, *reversed(states)]:
        fresh = render_frames(state, SIZE)
        assert data_equivalence(fresh, png_frames(state, SIZE), exact=True)
        cached = cache.frames(state)
        assert data_equivalence(cached, fresh, exact=True)
        assert all(f.flags.writeable and f.shape == (SIZE, SIZE, 3) for f in cached.values())
    assert cache.hits > 0 and cache.misses > len(states)  # the target (or tray) was reused


@pytest.mark.parametrize("level", [drop_level(), puzzles()[0]], ids=["drop", "lock3"])
def test_a_seeded_random_walk_through_one_cache_draws_what_a_fresh_render_draws(
    level: Level,
) -> None:
    rng = np.random.default_rng(23)
    state = new_state(level)
    cache = FrameCache(SIZE, max_bytes=SIZE * SIZE * 3 * 40)
    for _ in range(25):
        assert data_equivalence(cache.frames(state), render_frames(state, SIZE), exact=True)
        legal = state.legal_actions()
        choice = legal[int(rng.integers(len(legal) - 1))] if len(legal) > 1 else None
        if choice is None or state.is_success():
            state = new_state(level)
        else:
            state.apply(choice)
    assert cache.hits > 0


def test_the_cache_keys_what_is_drawn_not_the_position_key() -> None:
    """Two puzzle states with one position key (parts up to translation) whose pictures differ:
    the largest part is drawn, and labelled, where it really is."""
    level = puzzles()[0]
    assert level.id == "lock3-disassemble"
    a, b = new_state(level), new_state(level)
    assert a.step_text("move blue +x 1").legal and b.step_text("move green+red -x 1").legal
    assert a.key() == b.key()
    fresh_a, fresh_b = render_frames(a, SIZE), render_frames(b, SIZE)
    assert not data_equivalence(fresh_a["front"], fresh_b["front"], exact=True)
    cache = FrameCache(SIZE)
    assert data_equivalence(cache.frames(a), fresh_a, exact=True)
    assert data_equivalence(cache.frames(b), fresh_b, exact=True)


@pytest.mark.parametrize("cls", [StackingEnv, PuzzleEnv])
def test_text_is_todays_text_and_images_are_fresh_arrays(cls: type[Any]) -> None:
    env = cls(stacking() if cls is StackingEnv else puzzles(), image_size=SIZE)
    obs, _ = env.reset(seed=4)
    old = observe(env.state, images=True, image_size=SIZE)
    assert obs["text"] == _ascii(old.to_text()) and "Views: front, side, top, iso" in obs["text"]
    again, *_ = env.step("no such action")  # nothing changes: pictures from the cache
    assert data_equivalence(again["images"], obs["images"], exact=True)
    assert all(
        a is not b for a, b in zip(again["images"].values(), obs["images"].values(), strict=True)
    )
    assert env.observation_space.contains(again)


@pytest.mark.parametrize("env_id", sorted(k for k in gymnasium.registry if "chaingeo" in k))
def test_check_env_on_every_registered_id(env_id: str) -> None:
    env = gymnasium.make(env_id)  # the shipped levels, with images
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        check_env(env.unwrapped, skip_render_check=True)
    env.close()


def test_every_id_is_registered() -> None:
    assert set(ENV_IDS) <= set(gymnasium.registry)


def _kwargs(env_id: str) -> dict[str, Any]:
    levels = stacking() if "Stacking" in env_id else puzzles()
    return {"levels": levels, "image_size": SIZE}


@pytest.mark.parametrize("env_id", sorted(ENV_IDS))
def test_make_vec_sync_and_async_batch_the_same_observations(env_id: str) -> None:
    single = gymnasium.make(env_id, **_kwargs(env_id))
    runs = []
    for mode, n in (("sync", 8), ("async", 3)):
        envs = SeedSequenceSeeds(
            gymnasium.make_vec(env_id, num_envs=n, vectorization_mode=mode, **_kwargs(env_id))
        )
        assert envs.single_observation_space == single.observation_space
        obs, info = envs.reset(seed=11)
        assert envs.observation_space.contains(obs)
        for item in iterate(envs.observation_space, obs):
            assert single.observation_space.contains(item)
        steps = [obs]
        for _ in range(3):
            obs, *_ = envs.step(("finish",) * n)
            steps.append(obs)
        runs.append((steps, info))
        envs.close()
    (sync_steps, sync_info), (async_steps, async_info) = runs
    assert list(sync_info["level_id"][:3]) == list(async_info["level_id"])
    for a, b in zip(sync_steps, async_steps, strict=True):
        assert a["text"][:3] == b["text"]
        for view in a["images"]:
            assert np.array_equal(a["images"][view][:3], b["images"][view])


def test_autoreset_follows_gymnasium_next_step_and_same_step() -> None:
    kw = _kwargs("chaingeo/Stacking-v0")
    envs = gymnasium.make_vec("chaingeo/Stacking-v0", num_envs=2, **kw)
    assert envs.metadata["autoreset_mode"] == AutoresetMode.NEXT_STEP
    envs.reset(seed=0)
    _, _, terminated, _, info = envs.step(("finish", "no such action"))
    assert list(terminated) == [True, False] and list(info["steps_used"]) == [1, 1]
    _, reward, terminated, _, info = envs.step(("ignored on reset", "finish"))
    assert list(reward) == [0.0, 0.0]
    assert list(info["steps_used"]) == [0, 2] and list(terminated) == [False, True]
    envs.close()
    envs = gymnasium.make_vec(
        "chaingeo/Stacking-v0",
        num_envs=2,
        vector_kwargs={"autoreset_mode": AutoresetMode.SAME_STEP},
        **kw,
    )
    envs.reset(seed=0)
    _, _, terminated, _, info = envs.step(("finish", "no such action"))
    assert list(terminated) == [True, False] and list(info["_final_obs"]) == [True, False]
    assert "Steps left" in info["final_obs"][0]["text"] and list(info["steps_used"]) == [0, 1]
    envs.close()


def _random_run(seed: int, steps: int) -> list[Any]:
    """Seeded sub-environments, actions from each one's action mask by a seeded generator."""
    envs = SeedSequenceSeeds(
        gymnasium.make_vec("chaingeo/Stacking-v0", num_envs=3, **_kwargs("chaingeo/Stacking-v0"))
    )
    rng = np.random.default_rng(seed)
    obs, info = envs.reset(seed=seed)
    seen = [obs]
    catalogues = {lv.id: StackingEnv([lv], images=False) for lv in stacking()}
    for _ in range(steps):
        actions = []
        for i in range(3):
            env = catalogues[str(info["level_id"][i])]
            env.reset()
            legal = np.flatnonzero(info["action_mask"][i])  # none once solved: reset next
            pick = env.action_catalogue()[int(rng.choice(legal))] if len(legal) else "finish"
            actions.append(pick)
        obs, _, _, _, info = envs.step(tuple(actions))
        seen.append(obs)
    envs.close()
    return seen


def test_same_seed_same_batch_other_seed_other_batch() -> None:
    first, second, other = _random_run(5, 12), _random_run(5, 12), _random_run(6, 12)
    assert data_equivalence(first, second, exact=True)
    assert not data_equivalence(first, other, exact=True)


def test_vector_seeds_come_from_seed_sequence_and_do_not_overlap() -> None:
    seeds = vector_seeds(0, 4)
    assert seeds == vector_seeds(0, 4) and len(set(seeds)) == 4
    assert seeds[1] != vector_seeds(1, 4)[0]  # unlike Gymnasium's seed + i
    word = np.random.SeedSequence([0, 2]).generate_state(1, np.uint64)[0]
    assert seeds[2] == int(word) >> 1 and all(0 <= s < 2**63 for s in seeds)
    with pytest.raises(ValueError, match="non-negative"):
        vector_seeds(-1, 2)


def test_a_level_past_the_mask_length_is_refused_with_a_limit_error(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.setattr(gym_module, "MAX_STACKING_ACTIONS", 20)
    env = StackingEnv([soma_level()], images=False)
    with pytest.raises(LimitError, match="MAX_STACKING_ACTIONS"):
        env.reset(seed=0)
    with pytest.raises(ValueError, match="at least 128"):
        StackingEnv([soma_level()], image_size=64)


def test_observation_text_keeps_gymnasiums_layout_and_reads_live() -> None:
    from copy import deepcopy

    import gymnasium.vector.utils as vector_utils
    from gymnasium.spaces import Text
    from gymnasium.spaces.utils import flatten

    from chaingeo.envs.actions.text_space import ObservationText
    from chaingeo.envs.gym import CHARSET

    utils: Any = vector_utils  # annotated for arrays, dispatched on the space
    space = ObservationText(64, CHARSET)
    text = "place red (1,1,1)\n\tfinish ~"
    flat: Any = flatten(Text(64, charset=CHARSET), text)
    assert np.array_equal(space.encode(text), flat)
    shared = utils.create_shared_memory(space, n=2)
    live = utils.read_from_shared_memory(space, shared, n=2)
    utils.write_to_shared_memory(space, 1, text, shared)
    assert live[1] == text and live[0] == "" and deepcopy(live) == ("", text)
    utils.write_to_shared_memory(space, 1, "finish", shared)  # read after the write: the new text
    assert live[1] == "finish" and isinstance(deepcopy(live), tuple)
    with pytest.raises(ValueError, match="holds 64"):
        space.encode("x" * 65)
