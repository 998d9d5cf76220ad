"""The tracker on seeded synthetic clips without a level: a colour blended into a touching
piece's through a passing colour is still caught, a piece at rest that vanishes while what it
hid shows is lost (not hidden), a recolour to a colour moving elsewhere is read and a piece
sliding over another is not, and a recolour is dated when the new colour shows."""

from __future__ import annotations

import numpy as np
import pytest

from chaingeo.core.arrays import U8, Bools
from chaingeo.worldmodel.judge_track import Obj, Tracker, frame_objects
from chaingeo.worldmodel.judge_video import judge_frames

BLUE, ORANGE, GREEN, PURPLE = (67, 99, 216), (245, 130, 49), (60, 180, 75), (145, 30, 180)
SIZE = (160, 240)


def _noisy(f: np.ndarray, rng: np.random.Generator) -> U8:
    return np.clip(f + rng.normal(0, 2.0, f.shape), 0, 255).astype(np.uint8)


@pytest.mark.parametrize("seed", range(4))
def test_a_blend_through_a_passing_colour_into_a_neighbour_is_caught(seed: int) -> None:
    rng = np.random.default_rng(seed)
    grey, s = rng.uniform(110, 170), int(rng.integers(8, 14))
    frames = []
    for t in range(30):
        f = np.full((*SIZE, 3), grey)
        x = 40 + 6 * max(0, t - s - 1)  # the two move on together once fused
        colour = BLUE if t < s else PURPLE if t < s + 2 else ORANGE
        f[50:90, x : x + 40] = colour
        f[50:90, x + 40 : x + 80] = ORANGE
        frames.append(_noisy(f, rng))
    v = judge_frames(frames)
    assert any(
        e.kind in ("recolour", "merge", "disappear") and s - 1 <= e.frame <= s + 3
        for e in v.violations
    ), (v.model.names, v.violations)


@pytest.mark.parametrize("seed", range(4))
def test_a_piece_at_rest_vanishing_before_another_is_lost(seed: int) -> None:
    rng = np.random.default_rng(seed)
    grey, s = rng.uniform(110, 170), int(rng.integers(8, 14))
    frames = []
    for t in range(24):
        f = np.full((*SIZE, 3), grey)
        f[40:100, 64:170] = GREEN  # behind: the blue block's right part lies on it
        if t < s:
            f[40:100, 40:100] = BLUE
        frames.append(_noisy(f, rng))
    v = judge_frames(frames)
    assert any(e.kind == "disappear" and abs(e.frame - s) <= 1 for e in v.violations), v


def _identity(blue: list[Bools], orange: list[Bools]) -> list[tuple[str, int, str]]:
    frames = [frame_objects([b, o], 40) for b, o in zip(blue, orange, strict=True)]
    found = Tracker(frames, ("blue", "orange"))._identity()
    return [(e.kind, e.frame, e.piece) for e in found]


def _box(y: int, x: int, h: int, w: int) -> Bools:
    m = np.zeros(SIZE, dtype=bool)
    m[y : y + h, x : x + w] = True
    return m


@pytest.mark.parametrize("seed", range(6))
def test_a_recolour_while_that_colour_moves_elsewhere_is_read(seed: int) -> None:
    """The blue box turns orange while an orange box slides on elsewhere: the orange colour
    changed outside the blue box too, but its own step explains none of the blue box's place."""
    rng = np.random.default_rng(seed)
    s, speed = int(rng.integers(6, 12)), int(rng.integers(6, 10))
    place = _box(30, 40, 40, 40)
    blue = [place if t < s else ~place & place for t in range(26)]
    orange = [(place if t >= s else ~place & place) | _box(110, 5 + speed * t, 30, 40)
              for t in range(26)]  # fmt: skip
    assert _identity(blue, orange) == [("recolour", s, "blue")]


@pytest.mark.parametrize("seed", range(6))
def test_a_box_sliding_over_another_is_no_recolour(seed: int) -> None:
    """The orange box slides over the blue one and stays: its own step explains the cover."""
    rng = np.random.default_rng(seed)
    speed = int(rng.integers(6, 10))
    place = _box(30, 40, 40, 40)
    orange = [_box(26, max(30, 200 - speed * t), 48, 60) for t in range(26)]
    blue = [place & ~o for o in orange]
    assert _identity(blue, orange) == []


def test_objects_compare_by_identity() -> None:
    """A list of one colour's objects drops the one asked for (value equality would compare
    masks, which have no truth value, and fail)."""
    a, b = Obj(0, _box(0, 0, 4, 4), 1), Obj(0, _box(9, 9, 4, 4), 1)
    objs = [a, b]
    objs.remove(b)
    assert objs == [a] and a != Obj(0, a.mask, 1)


@pytest.mark.parametrize("seed", range(4))
def test_a_recolour_is_dated_when_the_new_colour_shows(seed: int) -> None:
    """A strip passing over the blue box just before it turns orange dims it first: the
    recolour is dated at the frame orange takes the place, not at the dimming."""
    rng = np.random.default_rng(seed)
    s, width = int(rng.integers(8, 14)), int(rng.integers(10, 16))
    place, none = _box(30, 40, 40, 40), np.zeros(SIZE, dtype=bool)
    strip = [_box(20, 40, 60, width) if s - 3 <= t < s else none for t in range(26)]
    blue = [place & ~strip[t] if t < s else none for t in range(26)]
    orange = [place if t >= s else none for t in range(26)]
    frames = [frame_objects(list(m), 40) for m in zip(blue, orange, strip, strict=True)]
    found = Tracker(frames, ("blue", "orange", "green"))._identity()
    assert [(e.kind, e.frame, e.piece) for e in found] == [("recolour", s, "blue")]
