"""Motion from silhouettes (judge_motion), on seeded boxes of colour: a jump, short or long,
from rest or within a motion, is a ``teleport``; a slide, fast or eased, and an occluder passing
are not. A box whose depth crosses another's where both lie (drawn by depth, as a renderer
draws two solids through each other) is a ``pass_through``; one passing wholly in front or
wholly behind is not."""

from __future__ import annotations

import numpy as np
import pytest

from chaingeo.worldmodel.judge_motion import EDGE, FILL, SilhouetteMotion, filled, pass_throughs
from chaingeo.worldmodel.judge_segment import dilate
from chaingeo.worldmodel.judge_shift import best_shift, moved

H, W, N = 120, 160, 16
NAMES = ("red", "blue")
LEAST = 40


def _box(y: float, x: float, h: int = 18, w: int = 24) -> np.ndarray:
    m = np.zeros((H, W), dtype=bool)
    y0, x0 = round(y), round(x)
    m[max(0, y0) : max(0, y0 + h), max(0, x0) : max(0, x0 + w)] = True
    return m


def _events(kept: list[list[np.ndarray]]) -> list[tuple[str, int, str]]:
    return [(e.kind, e.frame, e.piece) for e in SilhouetteMotion(kept, NAMES, LEAST).events()]


@pytest.mark.parametrize("seed", range(8))
def test_best_shift_finds_a_translation(seed: int) -> None:
    rng = np.random.default_rng(seed)
    a = _box(int(rng.integers(20, 60)), int(rng.integers(20, 60)), 20, 30)
    a |= _box(int(rng.integers(20, 60)), int(rng.integers(20, 60)), 12, 10)
    dy, dx = int(rng.integers(-15, 16)), int(rng.integers(-15, 16))
    s = best_shift(a, moved(a, dy, dx))
    assert (s.dy, s.dx, s.fit) == (dy, dx, 1.0)


@pytest.mark.parametrize("seed", range(8))
def test_a_jump_short_or_long_is_a_teleport(seed: int) -> None:
    rng = np.random.default_rng(seed)
    t = int(rng.integers(4, N - 4))
    jump = float(rng.uniform(0.07, 0.3)) * W
    speed = float(rng.choice([0.0, 2.0]))  # from rest, or within a slow slide
    y, x = 50.0, 20.0
    path = [(y, x + speed * i + (jump if i >= t else 0.0)) for i in range(N)]
    blue = _box(90, 120)
    kept = [[_box(*p), blue] for p in path]
    assert ("teleport", t, "red") in _events(kept)


@pytest.mark.parametrize("seed", range(8))
def test_motion_fast_eased_or_behind_a_passing_piece_is_no_teleport(seed: int) -> None:
    rng = np.random.default_rng(seed)
    top = float(rng.uniform(8, 14))
    # eased in and out: speed ramps up to ``top`` pixels a frame and down again
    speeds = np.minimum(np.arange(N), np.arange(N)[::-1]) * (top / (N // 2))
    xs = 5 + np.concatenate([[0.0], np.cumsum(speeds[1:])]) * (100 / max(1.0, speeds.sum()))
    blue = _box(90, 120)
    kept = [[_box(40, float(x)), blue] for x in xs]
    assert [e for e in _events(kept) if e[0] == "teleport"] == []
    # a blue bar slides over the red box at rest: red shows only on either side of it
    red = _box(40, 60, 20, 40)
    bars = [_box(30, 30 + 6 * i, 40, 14) for i in range(N)]
    hidden = [[red & ~bars[i], bars[i]] for i in range(N)]
    assert [e for e in _events(hidden) if e[0] == "teleport"] == []


def _drawn(depth_red: float, tilt: float, x: float) -> list[np.ndarray]:
    """Red (a box sliding along x) and blue (a box at rest) drawn by depth: red's depth is
    ``depth_red`` plus ``tilt`` per row down it, blue's is 10 everywhere."""
    red, blue = _box(40, x, 24, 40), _box(36, 70, 32, 60)
    rows = np.arange(H)[:, None] - 40
    nearer = depth_red + tilt * rows < 10.0
    both = red & blue
    return [red & ~(both & ~nearer), blue & ~(both & nearer)]


@pytest.mark.parametrize("seed", range(6))
def test_a_box_crossing_another_in_depth_is_a_pass_through(seed: int) -> None:
    rng = np.random.default_rng(seed)
    speed = float(rng.uniform(2.5, 4.0))
    sink = float(rng.uniform(0.8, 1.2))  # the red box goes deeper as it slides on
    kept = [_drawn(sink * i, 0.4, 30 + speed * i) for i in range(N)]
    found = [e for e in _events(kept) if e[0] == "pass_through"]
    assert found and {found[0][2]} <= set(NAMES)


@pytest.mark.parametrize("seed", range(6))
def test_a_box_passing_in_front_or_behind_is_no_pass_through(seed: int) -> None:
    rng = np.random.default_rng(seed)
    speed = float(rng.uniform(2.5, 4.0))
    for depth in (-5.0, 20.0):
        kept = [_drawn(depth, 0.05, 30 + speed * i) for i in range(N)]
        assert [e for e in _events(kept) if e[0] == "pass_through"] == []


@pytest.mark.parametrize("seed", range(8))
def test_filled_gives_dark_edges_to_the_nearer_colour_not_faces_nor_ground(seed: int) -> None:
    rng = np.random.default_rng(seed)
    gap, rim = (
        int(rng.integers(1, 2 * EDGE + 1)),
        int(rng.integers(1, FILL)),
    )  # FILL reaches the face
    y, x = int(rng.integers(10, 60)), int(rng.integers(10, 50))
    red, blue = _box(y, x, 30, 30), _box(y, x + 30 + gap, 30, 30)
    ground = ~_box(y - rim, x - rim, 30 + 2 * rim, 60 + gap + 2 * rim)  # a dark rim, then ground
    face = _box(y + 30 + rim, x, 2 * EDGE + 1, 60)  # a dark face in shade just below the rim
    ground &= ~face
    red_out, blue_out = filled([red, blue], ground)
    for was, now in ((red, red_out), (blue, blue_out)):
        assert (now & was).sum() == was.sum() and not (now & (ground | face)).any()
        assert not (now & ~dilate(was, FILL)).any()
    assert not (red_out & blue_out).any()
    # along a middle row: each takes its outer rim, and the gap in steps from both
    # sides (a pixel both reach in one step stays unclaimed)
    row = (red_out | blue_out)[y + 15]
    assert row.sum() == 60 + 2 * rim + gap - gap % 2


def _edged(kept: list[np.ndarray]) -> tuple[list[np.ndarray], np.ndarray]:
    """Two colours with a dark edge: every pixel of either within a pixel of the other is
    unclaimed (as a shaded render's edge lines and blends leave them); ground is the rest."""
    red, blue = kept
    ground = ~(red | blue)
    return [red & ~dilate(blue, 1), blue & ~dilate(red, 1)], ground


def test_a_crossing_behind_dark_edges_is_read_once_they_are_filled() -> None:
    kept = [_drawn(1.0 * i, 0.4, 30 + 3.0 * i) for i in range(N)]
    edged = [_edged(f) for f in kept]
    masks, grounds = [m for m, _ in edged], [g for _, g in edged]
    assert SilhouetteMotion(masks, NAMES, LEAST).pass_throughs() == []  # the edge eats the band
    assert [e.kind for e in pass_throughs(masks, grounds, NAMES, LEAST)] == ["pass_through"]


def test_a_stray_flip_before_a_crossing_does_not_date_it(monkeypatch: pytest.MonkeyPatch) -> None:
    counts = [0] * N
    counts[2] = 3 * LEAST  # one frame's misreading
    for t in range(7, 12):
        counts[t] = LEAST // 2  # the crossing: five frames, 2.5 least areas
    flat = np.zeros((H, W), dtype=bool)
    monkeypatch.setattr(SilhouetteMotion, "flips", lambda self, k, j, t: (counts[t], flat))
    kept = [[_box(40, 10 + 3 * i), _box(80, 100)] for i in range(N)]
    found = SilhouetteMotion(kept, NAMES, LEAST).pass_throughs()
    assert [(e.frame, e.last) for e in found] == [(7, 11)]


def test_a_crossing_against_the_pictures_border_is_not_read() -> None:
    """A silhouette cut by the border cannot be laid whole from its history: undecided."""
    kept = [_drawn(1.0 * i, 0.4, 30 + 3.0 * i) for i in range(N)]
    assert SilhouetteMotion(kept, NAMES, LEAST).pass_throughs() != []
    cut = [[moved(m, 0, 30) for m in f] for f in kept]  # the blue box now meets the edge
    assert SilhouetteMotion(cut, NAMES, LEAST).pass_throughs() == []
