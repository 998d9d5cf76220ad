"""Breaks read from silhouettes against the ground (judge_shape), on seeded boxes of colour: a
rigid piece, however occluders cut it, has a translation laying it on no ground; a piece whose
half drifts off behind a piece in front does not. Two pieces of two hues in one colour class
parting are no break."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from chaingeo.worldmodel import judge_shape
from chaingeo.worldmodel.judge_segment import components
from chaingeo.worldmodel.judge_shape import LAG, broken_pieces, least_on_ground
from chaingeo.worldmodel.judge_shift import moved

H, W, N = 120, 160, 14
LEAST = 40
GROUND = (200, 200, 200)
RED, ORANGE, BLUE = (200, 40, 40), (215, 120, 30), (40, 60, 200)


def _box(y: int, x: int, h: int, w: int) -> np.ndarray:
    m = np.zeros((H, W), dtype=bool)
    m[max(0, y) : max(0, y + h), max(0, x) : max(0, x + w)] = True
    return m


Layer = list[tuple[np.ndarray, tuple[int, int, int], int]]
Inputs = tuple[list[np.ndarray], list[list[np.ndarray]], list[np.ndarray], list[list[int]]]


def _clip(layers: list[Layer]) -> Inputs:
    """Frames drawn from (silhouette, colour, class) layers, back to front, and the judge's
    inputs: per-class pixels, ground, part counts."""
    frames: list[np.ndarray] = []
    kept: list[list[np.ndarray]] = []
    grounds: list[np.ndarray] = []
    parts: list[list[int]] = []
    for layer in layers:
        img = np.empty((H, W, 3), dtype=np.uint8)
        img[:] = GROUND
        cls = [np.zeros((H, W), dtype=bool) for _ in range(2)]
        for m, rgb, k in layer:
            img[m] = rgb
            for c in cls:
                c &= ~m
            cls[k] |= m
        frames.append(img)
        kept.append(cls)
        grounds.append(~np.logical_or.reduce(cls))
        parts.append([len(components(c, LEAST)) for c in cls])
    return frames, kept, grounds, parts


def _splits(layers: list[Layer]) -> list[tuple[str, int, str]]:
    frames, kept, grounds, parts = _clip(layers)
    found = broken_pieces(frames, kept, grounds, parts, ("red", "blue"), LEAST)
    return [(e.kind, e.frame, e.piece) for e in found]


def _bar_behind_strip(
    seed: int, drift: int, far_rgb: tuple[int, int, int] = RED
) -> tuple[list[Layer], int]:
    """A red bar at rest, joined only along its bottom under a blue strip in front of its
    middle; from frame t its right half drifts ``drift`` px right over three frames."""
    rng = np.random.default_rng(seed)
    y, x, h, w = int(rng.integers(25, 50)), int(rng.integers(10, 30)), 30, 80
    cut = x + w // 2
    strip = _box(y - 5, cut - 8, h - 6, 16)
    t = int(rng.integers(LAG + 1, N - 5))
    layers = []
    for i in range(N):
        d = drift * min(3, max(0, i - t + 1)) // 3
        near, far = _box(y, x, h, w // 2), _box(y, cut + d, h, w // 2)
        layers.append([(near, RED, 0), (far, far_rgb, 0), (strip, BLUE, 1)])
    return layers, t


@pytest.mark.parametrize("seed", range(8))
def test_a_half_drifting_off_behind_a_piece_is_a_split(seed: int) -> None:
    layers, t = _bar_behind_strip(seed, int(np.random.default_rng(seed).integers(12, 24)))
    got = _splits(layers)
    assert len(got) == 1 and got[0][0] == "split" and got[0][2] == "red"
    assert t <= got[0][1] <= t + 2


@pytest.mark.parametrize("seed", range(8))
def test_the_same_bar_at_rest_is_no_split(seed: int) -> None:
    layers, _ = _bar_behind_strip(seed, 0)
    assert _splits(layers) == []


@pytest.mark.parametrize("seed", range(8))
def test_two_pieces_of_one_class_parting_are_no_split(seed: int) -> None:
    # an orange piece the palette read as red slides off the red one: two hues, two pieces
    layers, _ = _bar_behind_strip(seed, 20, far_rgb=ORANGE)
    assert _splits(layers) == []


@pytest.mark.parametrize("seed", range(8))
def test_an_occluder_passing_over_a_moving_piece_is_no_split(seed: int) -> None:
    rng = np.random.default_rng(seed)
    y, x = int(rng.integers(20, 50)), int(rng.integers(5, 20))
    speed = int(rng.integers(0, 4))
    layers = []
    for i in range(N):
        red = _box(y, x + speed * i, 24, 60) | _box(y + 24, x + speed * i, 16, 16)
        bar = _box(y - 10, 5 + 9 * i, 60, 12)
        layers.append([(red, RED, 0), (bar, BLUE, 1)])
    assert _splits(layers) == []


def test_far_shifts_onto_other_pieces_do_not_explain_a_break(monkeypatch) -> None:  # type: ignore[no-untyped-def]
    # a bar whose right half moved 20 px into a hole of ground among other pieces: a shift
    # far up or down lays both silhouettes on those pieces, and on nothing of their own
    was = _box(50, 20, 20, 60)
    now = _box(50, 20, 20, 30) | _box(50, 70, 20, 30)
    hole = _box(40, 10, 40, 100)
    ground_was, ground_now = hole & ~was, hole & ~now
    assert least_on_ground(was, now, ground_was, ground_now)[2] > 0
    monkeypatch.setattr(judge_shape, "OVERLAP", 0.0)
    assert least_on_ground(was, now, ground_was, ground_now)[2] == 0


boxes = st.tuples(st.integers(0, 30), st.integers(0, 40), st.integers(6, 20), st.integers(6, 30))


@settings(max_examples=60, deadline=None)
@given(
    parts=st.lists(boxes, min_size=1, max_size=4),
    shift=st.tuples(st.integers(-20, 20), st.integers(-20, 20)),
    covers=st.lists(st.tuples(st.integers(0, 110), st.integers(0, 150)), max_size=2),
)
def test_a_rigid_piece_always_has_a_translation_off_the_ground(
    parts: list[tuple[int, int, int, int]],
    shift: tuple[int, int],
    covers: list[tuple[int, int]],
) -> None:
    piece = np.logical_or.reduce([_box(30 + y, 40 + x, h, w) for y, x, h, w in parts])
    later = moved(piece, *shift)
    area = int(piece.sum())
    side = max(2, int(np.sqrt(0.15 * area)))  # each occluder hides at most 15% of the piece
    occ = [_box(y, x, side, side) for y, x in covers]
    occ_was = occ[0] if occ else np.zeros_like(piece)
    occ_now = occ[-1] if occ else np.zeros_like(piece)
    seen_was, seen_now = piece & ~occ_was, later & ~occ_now
    if not seen_was.any() or not seen_now.any():
        return
    got = least_on_ground(seen_was, seen_now, ~(piece | occ_was), ~(later | occ_now))
    assert got[2] == 0


@pytest.mark.parametrize("seed", range(20))
def test_the_at_rest_shortcut_agrees_with_the_full_search(seed: int) -> None:
    rng = np.random.default_rng(seed)
    was = _box(*[int(v) for v in rng.integers([20, 20, 10, 10], [60, 80, 40, 60])])
    now = moved(was, *[int(v) for v in rng.integers(-3, 4, 2)])
    now |= _box(*[int(v) for v in rng.integers([20, 20, 5, 5], [90, 130, 20, 20])])
    ground_was = ~was & (rng.random((H, W)) < 0.9)
    ground_now = ~now & (rng.random((H, W)) < 0.9)
    most = float(rng.integers(1, 400))
    if judge_shape._laid_at_rest(was, now, ground_was, ground_now, most):
        assert least_on_ground(was, now, ground_was, ground_now)[2] < most
