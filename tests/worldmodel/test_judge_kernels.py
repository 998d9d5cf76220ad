"""The video judge's fast paths give what the plain formulations they replaced gave, bit for
bit (the references are those formulations, kept here): the verdicts must not move."""

from __future__ import annotations

from functools import lru_cache

import numpy as np
import numpy.typing as npt
from hypothesis import given, settings
from hypothesis import strategies as st
from PIL import Image, ImageDraw

from chaingeo.core.arrays import F64, U8, Bools
from chaingeo.core.level import Level, load_level
from chaingeo.core.suite import suite_folder
from chaingeo.pictures.scene import CAMERAS
from chaingeo.worldmodel.judge_gap import _distances
from chaingeo.worldmodel.judge_pose import _iou, _pieces, _PoseScene, _Target
from chaingeo.worldmodel.judge_segment import (
    _spread,
    _table_index,
    classify,
    components,
    dilate,
    palette_model,
)
from chaingeo.worldmodel.judge_video import _wire

LEVELS = ("puzzle-easy-09-cube3", "puzzle-mid-08-burr3", "puzzle-hard-10-cube4")


def _spread_ref(mask: Bools, r: int, grow: bool) -> Bools:
    out = mask.copy()
    for axis in (0, 1):
        src = out.copy()
        for s in range(1, r + 1):
            for sign in (s, -s):
                shifted = np.zeros_like(src)
                if axis == 0:
                    if sign > 0:
                        shifted[sign:] = src[:-sign]
                    else:
                        shifted[:sign] = src[-sign:]
                elif sign > 0:
                    shifted[:, sign:] = src[:, :-sign]
                else:
                    shifted[:, :sign] = src[:, -sign:]
                out = out | shifted if grow else out & shifted
    return out


def _distances_ref(mask: Bools, r: int) -> npt.NDArray[np.int64]:
    out = np.full(mask.shape, r + 1, dtype=np.int64)
    out[mask] = 0
    grown = mask
    for d in range(1, r + 1):
        nxt = _spread_ref(grown, 1, True)
        out[nxt & ~grown] = d
        grown = nxt
    return out


@st.composite
def masks(draw: st.DrawFn) -> Bools:
    h, w = draw(st.integers(1, 40)), draw(st.integers(1, 40))
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    out: Bools = rng.random((h, w)) < draw(st.sampled_from([0.002, 0.05, 0.3, 0.7, 0.97]))
    return out


@settings(max_examples=300, deadline=None)
@given(masks(), st.integers(-1, 25), st.booleans())
def test_spread_is_the_shifted_copies(mask: Bools, r: int, grow: bool) -> None:
    want, got = _spread_ref(mask, r, grow), _spread(mask, r, grow)
    assert got.dtype == want.dtype and np.array_equal(got, want)
    view = _spread(mask[:, ::2], r, grow)  # a strided view
    assert np.array_equal(view, _spread_ref(mask[:, ::2], r, grow))


@settings(max_examples=200, deadline=None)
@given(masks(), st.integers(0, 30))
def test_distances_are_the_repeated_growths(mask: Bools, r: int) -> None:
    want, got = _distances_ref(mask, r), _distances(mask, r)
    assert got.dtype == want.dtype and np.array_equal(got, want)


@lru_cache(maxsize=4)
def _level(name: str) -> Level:
    return load_level(suite_folder("puzzle") / f"{name}.json")


def _draw_ref(scene: _PoseScene, t: F64) -> U8:
    """The drawing as it was: a list sorted by depth, one ImageDraw.polygon a face."""
    polys: list[tuple[float, F64, int]] = []
    for p, off in zip(scene.pieces, t, strict=True):
        shift = np.array([off @ scene.right, off @ scene.up])
        depth = p.depth + float(off @ scene.v)
        polys.extend(zip(depth.tolist(), p.corners + shift, [p.label] * len(depth), strict=True))
    polys.sort(key=lambda q: q[0])
    h, w = scene.shape
    img = Image.new("L", (w, h), 0)
    draw = ImageDraw.Draw(img)
    for _, c, label in polys:
        x = c[:, 0] * scene.scale + scene.origin[0] - 0.5
        y = -c[:, 1] * scene.scale + scene.origin[1] - 0.5
        draw.polygon(list(zip(x.tolist(), y.tolist(), strict=True)), fill=label)
    return np.asarray(img, dtype=np.uint8)


@settings(max_examples=60, deadline=None)
@given(
    st.sampled_from(LEVELS),
    st.floats(4.0, 40.0),
    st.tuples(st.floats(-50.0, 250.0), st.floats(-50.0, 250.0)),
    st.integers(0, 2**32 - 1),
)
def test_scene_draws_as_imagedraw_polygon(
    name: str, scale: float, origin: tuple[float, float], seed: int
) -> None:
    """Pixel for pixel, over scales, offsets and translations (quarter cells, ties of depth
    between pieces included); and a piece's mask alone is its label in the whole drawing."""
    cam = CAMERAS["iso"]
    scene = _PoseScene(_pieces(_level(name), cam), cam, (120, 160))
    scene.scale, scene.origin = scale, np.array(origin)
    rng = np.random.default_rng(seed)
    n = len(scene.pieces)
    for t in (np.zeros((n, 3)), rng.integers(-8, 9, (n, 3)) / 4.0, rng.normal(0, 2, (n, 3))):
        want = _draw_ref(scene, t)
        assert np.array_equal(scene.draw(t), want)
        i = int(rng.integers(n))
        assert np.array_equal(scene.mask(t, i), want == i + 1)
        seen = rng.random(want.shape) < 0.1
        target = _Target(seen)
        assert target.iou(want == i + 1) == _iou(want == i + 1, seen)


@settings(max_examples=50, deadline=None)
@given(st.integers(0, 2**32 - 1), st.sampled_from([0, 40, 90, 130]))
def test_wire_is_the_channel_statistics(seed: int, level: int) -> None:
    rng = np.random.default_rng(seed)
    frame = np.clip(level + rng.integers(-60, 61, (30, 40, 3)), 0, 255).astype(np.uint8)
    masks = [rng.random((30, 40)) < 0.2]
    rgb = frame.astype(np.int64)
    grey = (rgb.max(axis=2) - rgb.min(axis=2) <= 12) & (np.abs(rgb.mean(axis=2) - 90.0) <= 35.0)
    assert np.array_equal(_wire(frame, masks), grey & ~np.logical_or.reduce(masks))


def test_dilate_of_an_empty_or_full_picture() -> None:
    assert not dilate(np.zeros((5, 7), dtype=bool), 3).any()
    assert dilate(np.ones((5, 7), dtype=bool), 3).all()
    assert not _spread(np.ones((5, 7), dtype=bool), 3, False).any()


def test_table_index_is_the_64_bit_one() -> None:
    frame = np.random.default_rng(0).integers(0, 256, (64, 48, 3)).astype(np.uint8)
    c = frame.astype(np.int64) >> 3
    assert np.array_equal(_table_index(frame), (c[..., 0] << 10) | (c[..., 1] << 5) | c[..., 2])


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(1, 40), st.integers(1, 40))
def test_classify_and_components_are_the_plain_ones(seed: int, h: int, w: int) -> None:
    rng = np.random.default_rng(seed)
    frame = rng.integers(0, 256, (h, w, 3)).astype(np.uint8)
    model = palette_model([("red", (230, 25, 75)), ("blue", (67, 99, 216))])
    assert np.array_equal(classify(frame, model), model.table[_table_index(frame)])
    assert np.array_equal(
        classify(frame[:, ::-1], model), model.table[_table_index(frame[:, ::-1])]
    )
    mask = rng.random((h, w)) < 0.4
    parts = components(mask, 1)
    assert sum(int(p.sum()) for p in parts) == int(mask.sum())
    assert all(not (a & b).any() for i, a in enumerate(parts) for b in parts[i + 1 :])
