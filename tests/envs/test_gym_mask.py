"""The stacking action mask marks exactly the legal actions, however it looks them up."""

from __future__ import annotations

import random

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from chaingeo.envs.gym import StackingEnv

ENV = StackingEnv(images=False)


@settings(max_examples=15, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_mask_is_the_legal_actions_along_random_trajectories(seed: int) -> None:
    rng = random.Random(seed)
    _, info = ENV.reset(seed=seed)
    for _ in range(6):
        catalogue = ENV.action_catalogue()
        legal = [a.to_text() for a in ENV.state.legal_actions()]
        want = np.zeros_like(info["action_mask"])
        want[[catalogue.index(t) for t in legal]] = 1
        assert np.array_equal(info["action_mask"], want)
        moves = [t for t in legal if t not in ("finish", "state")]
        if not moves:
            break
        _, _, terminated, _, info = ENV.step(rng.choice(moves))
        if terminated:
            break
