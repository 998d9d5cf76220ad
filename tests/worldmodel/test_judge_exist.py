"""Existence read from each colour's pixels (judge_exist): seeded boxes of colour on open
ground that are copied, deleted or moved in one frame, at rest before and after, give
``duplicate``, ``disappear`` and ``teleport``; boxes that slide (motion) or are covered by
another piece give nothing."""

from __future__ import annotations

import numpy as np
import pytest

from chaingeo.worldmodel.judge_exist import Existence

H, W, N = 120, 160, 12
NAMES = ("red", "blue")


def _box(y: int, x: int, h: int = 18, w: int = 24) -> np.ndarray:
    m = np.zeros((H, W), dtype=bool)
    m[y : y + h, x : x + w] = True
    return m


def _run(kept: list[list[np.ndarray]]) -> list[tuple[str, int, str]]:
    ground = [~(f[0] | f[1]) for f in kept]
    found = Existence(kept, ground, NAMES, 40).events()
    return [(e.kind, e.frame, e.piece) for e in found]


def _scene(rng: np.random.Generator) -> tuple[tuple[int, int], tuple[int, int], int]:
    a = (int(rng.integers(10, 40)), int(rng.integers(10, 40)))
    b = (int(rng.integers(70, 90)), int(rng.integers(100, 125)))
    return a, b, int(rng.integers(3, N - 4))


@pytest.mark.parametrize("seed", range(6))
def test_a_copy_a_deletion_and_a_jump_are_read(seed: int) -> None:
    rng = np.random.default_rng(seed)
    a, b, t = _scene(rng)
    blue = [_box(*b) for _ in range(N)]
    copy = [[_box(*a) | (_box(a[0], a[1] + 60) if i >= t else False), blue[i]] for i in range(N)]
    assert ("duplicate", t, "red") in _run(copy)
    gone = [[_box(*a) if i < t else np.zeros((H, W), bool), blue[i]] for i in range(N)]
    assert ("disappear", t, "red") in _run(gone)
    jump = [[_box(*a) if i < t else _box(a[0] + 50, a[1] + 50), blue[i]] for i in range(N)]
    assert ("teleport", t, "red") in _run(jump)


@pytest.mark.parametrize("seed", range(6))
def test_motion_and_occlusion_are_no_event(seed: int) -> None:
    rng = np.random.default_rng(seed)
    a, b, t = _scene(rng)
    blue = [_box(*b) for _ in range(N)]
    slide = [[_box(a[0], a[1] + 4 * i), blue[i]] for i in range(N)]
    assert _run(slide) == []
    # the red box goes behind a blue one put down over it: covered, not gone
    over = [_box(a[0] - 2, a[1] - 2, 22, 28) if i >= t else blue[i] for i in range(N)]
    hidden = [[_box(*a) & ~over[i], over[i]] for i in range(N)]
    assert not [e for e in _run(hidden) if e[2] == "red"]


@pytest.mark.parametrize("seed", range(6))
def test_a_jump_out_from_behind_a_piece_is_a_teleport(seed: int) -> None:
    # red, mostly behind a blue box, shows far off in open ground whole the next frame: the
    # one red piece left its place (what shows there is blue and ground), so it jumped
    rng = np.random.default_rng(seed)
    a, b, t = _scene(rng)
    cover = _box(a[0] - 2, a[1] - 2, 22, 20)
    there = _box(a[0] + 50, a[1] + 50)
    kept = [[_box(*a) & ~cover if i < t else there, cover | _box(*b)] for i in range(N)]
    got = _run(kept)
    assert ("teleport", t, "red") in got
    assert not [e for e in got if e[0] in ("appear", "disappear")]
