"""The video palette finds every piece colour once under shading (lit and dark faces one
class, look-alike colours of one level apart, a colour with every face in shade), and the
drift test reads a gradual recolour but not another piece sliding over one, on seeded
synthetic pictures."""

from __future__ import annotations

import numpy as np
import pytest

from chaingeo.core.arrays import U8, Bools
from chaingeo.worldmodel.judge_drift import Drift
from chaingeo.worldmodel.judge_palette import video_model
from chaingeo.worldmodel.judge_segment import _table_index, classify
from chaingeo.worldmodel.judge_track import Obj

#: Colours of the judge's bench levels, look-alike pairs included (blue and cobalt, orange and
#: rust, red and purple).
COLOURS = (
    (67, 99, 216),
    (75, 75, 130),
    (11, 93, 30),
    (245, 130, 49),
    (183, 65, 14),
    (255, 225, 25),
    (60, 180, 75),
    (145, 30, 180),
    (230, 25, 75),
)
SIZE = (160, 240)


def _block(frame: np.ndarray, y: int, x: int, rgb: np.ndarray, shades: np.ndarray) -> Bools:
    """A 36 x 36 block of three faces (top, left, right), each ``rgb`` scaled by its shade."""
    mask = np.zeros(frame.shape[:2], dtype=bool)
    for k, (dy, dx, h, w) in enumerate(((0, 0, 12, 36), (12, 0, 24, 18), (12, 18, 24, 18))):
        frame[y + dy : y + dy + h, x + dx : x + dx + w] = np.clip(rgb * shades[k], 0, 255)
        mask[y + dy : y + dy + h, x + dx : x + dx + w] = True
    return mask


def _scene(seed: int) -> tuple[list[U8], list[Bools], list[int]]:
    """Frames of 3 to 5 shaded blocks of distinct colours on a grey ground with noise."""
    rng = np.random.default_rng(seed)
    picks = rng.choice(len(COLOURS), size=int(rng.integers(3, 6)), replace=False)
    shades = rng.uniform(0.35, 1.2, (len(picks), 3))
    grey = rng.uniform(90, 200)
    frames, masks = [], []
    for _ in range(8):
        f = np.full((*SIZE, 3), grey)
        ms = [
            _block(f, 20 + 70 * (i // 4), 10 + 56 * (i % 4), np.array(COLOURS[c], float), s)
            for i, (c, s) in enumerate(zip(picks, shades, strict=True))
        ]
        f += rng.normal(0, 2.0, f.shape)
        frames.append(np.clip(f, 0, 255).astype(np.uint8))
        masks = ms
    return frames, masks, [int(c) for c in picks]


@pytest.mark.parametrize("seed", range(12))
def test_every_colour_is_one_class_under_shading(seed: int) -> None:
    frames, masks, picks = _scene(seed)
    model = video_model(frames)
    assert len(model.names) == len(picks), model.names
    labels = classify(frames[0], model)
    owners = []
    for m in masks:
        got = np.bincount(labels[m], minlength=len(model.names) + 1)
        owners.append(int(np.argmax(got[1:])) + 1)
        assert got[owners[-1]] >= 0.9 * m.sum(), got
    assert len(set(owners)) == len(owners)


def _objects(masks: list[list[tuple[int, Bools]]]) -> list[list[Obj]]:
    return [[Obj(k, m, 1) for k, m in frame] for frame in masks]


@pytest.mark.parametrize("seed", range(6))
def test_a_gradual_recolour_drifts_and_a_piece_sliding_over_does_not(seed: int) -> None:
    rng = np.random.default_rng(seed)
    a, b = (np.array(COLOURS[c], float) for c in rng.choice([0, 3, 5, 6, 8], 2, replace=False))
    start, steps = int(rng.integers(3, 8)), int(rng.integers(4, 9))
    grey, shades = rng.uniform(90, 200), rng.uniform(0.5, 1.1, 3)
    frames, slid, objs, objs_slid = [], [], [], []
    for t in range(26):
        w = min(1.0, max(0.0, (t - start + 1) / steps))
        f = np.full((*SIZE, 3), grey)
        m = _block(f, 40, 40, (1 - w) * a + w * b, shades)
        other = _block(f, 40, 160, b, shades)
        frames.append(np.clip(f + rng.normal(0, 2.0, f.shape), 0, 255).astype(np.uint8))
        objs.append([(0 if w < 0.5 else 1, m), (1, other)])  # classed as it looks
        g = np.full((*SIZE, 3), grey)  # the b block slides over the a block instead
        m2 = _block(g, 40, 40, a, shades)
        x = round(160 - 120 * w)
        over = _block(g, 40, x, b, shades)
        slid.append(np.clip(g + rng.normal(0, 2.0, g.shape), 0, 255).astype(np.uint8))
        objs_slid.append([(0, m2 & ~over), (1, over)])
    events = Drift(frames, _objects(objs), ("a", "b")).events()
    assert [(e.kind, e.piece, e.other) for e in events] == [("recolour", "a", "b")]
    assert abs(events[0].frame - start) <= 1 and events[0].until <= start + steps + 1
    assert Drift(slid, _objects(objs_slid), ("a", "b")).events() == []


def _lit_scene(seed: int) -> tuple[list[U8], list[Bools]]:
    """Blocks whose top face is lit as the shaded renderer lights one: its colour scaled up
    and white added (a highlight), clipped; the other two faces in shade."""
    rng = np.random.default_rng(seed)
    # no look-alike pair: a lit forest is a green (motion tells them apart, not colour)
    picks = rng.choice([0, 3, 5, 6, 7], size=int(rng.integers(2, 5)), replace=False)
    grey = rng.uniform(90, 160)
    f = np.full((*SIZE, 3), grey)
    masks = []
    for i, c in enumerate(picks):
        rgb = np.array(COLOURS[c], float)
        masks.append(
            _block(f, 20 + 70 * (i // 4), 10 + 56 * (i % 4), rgb, rng.uniform(0.5, 1.0, 3))
        )
        y, x = 20 + 70 * (i // 4), 10 + 56 * (i % 4)
        k, white = rng.uniform(1.0, 1.3), rng.uniform(0.2, 0.4) * 255
        glow = np.linspace(0.0, 1.0, 36)[None, :, None] ** 2  # the highlight's falloff
        f[y : y + 12, x : x + 36] = np.clip(rgb * (0.8 + 0.2 * k * glow) + white * glow, 0, 255)
    frames = [np.clip(f + rng.normal(0, 2.0, f.shape), 0, 255).astype(np.uint8) for _ in range(6)]
    return frames, masks


@pytest.mark.parametrize("seed", range(10))
def test_a_lit_face_joins_its_colour(seed: int) -> None:
    frames, masks = _lit_scene(seed)
    model = video_model(frames)
    labels = classify(frames[0], model)
    owners = []
    for m in masks:
        got = np.bincount(labels[m], minlength=len(model.names) + 1)
        owners.append(int(np.argmax(got[1:])) + 1)
        assert got[owners[-1]] >= 0.9 * m.sum(), (model.names, got)
    assert len(set(owners)) == len(owners)


@pytest.mark.parametrize("seed", range(4))
def test_a_colour_seen_in_two_frames_is_in_the_palette(seed: int) -> None:
    """A piece shown only briefly (brought in, then recoloured) still has its class."""
    rng = np.random.default_rng(seed)
    a, b = rng.choice(len(COLOURS), 2, replace=False)
    n, when = 36, int(rng.integers(1, 34))
    frames = []
    for t in range(n):
        f = np.full((*SIZE, 3), 128.0)
        _block(f, 20, 20, np.array(COLOURS[a], float), np.array([1.0, 0.8, 0.6]))
        if t in (when, when + 1):
            _block(f, 90, 150, np.array(COLOURS[b], float), np.array([1.0, 0.8, 0.6]))
        frames.append(np.clip(f + rng.normal(0, 2.0, f.shape), 0, 255).astype(np.uint8))
    assert len(video_model(frames).names) == 2


@pytest.mark.parametrize("seed", range(3))
def test_the_vote_kernel_matches_numpy(seed: int) -> None:
    """One pass (flat inside, chromaticity histogram, table counts) equals the array code."""
    from chaingeo.worldmodel import judge_palette as P

    rng = np.random.default_rng(seed)
    frame = np.repeat(np.repeat(rng.integers(0, 256, (20, 30, 3)), 3, 0), 3, 1).astype(np.uint8)
    frame = np.clip(frame + rng.integers(-8, 9, frame.shape), 0, 255).astype(np.uint8)
    hist, counts = np.zeros(P.CHROMA_BINS**2), np.zeros(32768)
    total = P._votes(frame, hist, counts)
    f = frame.astype(np.int16)
    pad = np.pad(f, ((1, 1), (1, 1), (0, 0)), mode="edge")
    shifts = [pad[dy : dy + 60, dx : dx + 90] for dy in range(3) for dx in range(3)]
    flat = (np.max(shifts, axis=0) - np.min(shifts, axis=0)).max(axis=2) <= P.FLAT_RANGE
    px = frame[flat].astype(np.float64)
    chroma, ok = P._chromaticity(px)
    hi, lo = px.max(axis=1), px.min(axis=1)
    vivid = (hi >= P.DARK_VOTE_BRIGHT) & (hi - lo >= P.DARK_VOTE_SATURATION * hi)
    ok |= vivid & (hi - lo >= P.MIN_SATURATION * hi)
    cell = np.clip((chroma[ok] * P.CHROMA_BINS).astype(np.int64), 0, P.CHROMA_BINS - 1)
    want = np.bincount(cell[:, 0] * P.CHROMA_BINS + cell[:, 1], minlength=P.CHROMA_BINS**2)
    assert total == int(ok.sum()) and np.array_equal(hist, want)
    idx = _table_index(frame)[flat]
    assert np.array_equal(counts, np.bincount(idx, minlength=32768))


@pytest.mark.parametrize("seed", range(8))
def test_a_dark_vivid_piece_is_a_colour_of_its_own(seed: int) -> None:
    """A forest green whose every face is in shade (brightest channel under MIN_BRIGHT) still
    has a class, apart from the lit piece beside it; grey shadows on the ground make none."""
    from chaingeo.worldmodel import judge_palette as P

    rng = np.random.default_rng(seed)
    forest, other = np.array(COLOURS[2], float), np.array(COLOURS[int(rng.choice([0, 3, 5]))])
    shades = rng.uniform(P.DARK_VOTE_BRIGHT + 4, P.MIN_BRIGHT - 6, 3) / forest.max()
    grey = rng.uniform(110, 190)
    frames, masks = [], []
    for _ in range(8):
        f = np.full((*SIZE, 3), grey)
        f[100:150, 20:220] = grey * rng.uniform(0.25, 0.45)  # a shadow on the ground
        masks = [
            _block(f, 30, 40, forest, shades),
            _block(f, 30, 150, other.astype(float), np.array([1.0, 0.8, 0.6])),
        ]
        frames.append(np.clip(f + rng.normal(0, 2.0, f.shape), 0, 255).astype(np.uint8))
    model = video_model(frames)
    assert len(model.names) == 2, model.names
    labels = classify(frames[0], model)
    owners = []
    for m in masks:
        got = np.bincount(labels[m], minlength=3)
        owners.append(int(np.argmax(got[1:])) + 1)
        assert got[owners[-1]] >= 0.9 * m.sum(), (model.names, got)
    assert owners[0] != owners[1]
