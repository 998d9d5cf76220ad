"""Two colour classes are one piece when they show, sit and move together (a lit face and a
shaded face clustered apart), and stay two when the pieces part, on seeded synthetic clips."""

from __future__ import annotations

import numpy as np
import pytest

from chaingeo.core.arrays import U8
from chaingeo.worldmodel.judge_video import judge_frames

GREEN, FOREST, BLUE = (60, 180, 75), (11, 93, 30), (67, 99, 216)
SIZE = (120, 200)


def _clip(seed: int, one_piece: bool) -> list[U8]:
    """A blue block at rest and a block with a green top over forest sides, moving right for
    a while (``one_piece``); else a green block leaving a forest block at rest beside it."""
    rng = np.random.default_rng(seed)
    grey = rng.uniform(110, 170)
    start, speed = int(rng.integers(3, 8)), int(rng.integers(3, 6))
    frames = []
    for t in range(24):
        f = np.full((*SIZE, 3), grey)
        f[60:96, 20:50] = np.array(BLUE) * 0.8
        x = 70 + speed * min(max(t - start, 0), 12)
        if one_piece:
            f[40:52, x : x + 40] = GREEN
            f[52:80, x : x + 40] = np.array(FOREST) * rng.uniform(0.8, 1.0)
        else:
            f[52:80, 70:110] = np.array(FOREST) * rng.uniform(0.8, 1.0)
            f[40:52, x : x + 40] = GREEN
        frames.append(np.clip(f + rng.normal(0, 2.0, f.shape), 0, 255).astype(np.uint8))
    return frames


@pytest.mark.parametrize("seed", range(4))
def test_faces_that_move_together_are_one_piece(seed: int) -> None:
    verdict = judge_frames(_clip(seed, True))
    assert len(verdict.model.names) == 2, verdict.model.names
    assert verdict.valid, verdict.violations


@pytest.mark.parametrize("seed", range(4))
def test_pieces_that_part_stay_two(seed: int) -> None:
    verdict = judge_frames(_clip(seed, False))
    assert len(verdict.model.names) == 3, verdict.model.names
