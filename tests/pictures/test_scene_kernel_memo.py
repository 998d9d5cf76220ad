"""The fast path's newer parts (legends and swatches by the kernels, the tray on arrays) give
the bytes the reference renderer gives, on random input."""

from __future__ import annotations

import random
from functools import cache

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from PIL import Image, ImageDraw

from chaingeo.core.geometry import Shape
from chaingeo.core.level import Level
from chaingeo.envs.frames import render_frames
from chaingeo.envs.gym import StackingEnv
from chaingeo.envs.machines import new_state
from chaingeo.envs.observation import state_images
from chaingeo.pictures import raster_kernel, scene_kernel
from chaingeo.pictures.legend import clear_memo, draw_legend, paint_legend
from chaingeo.pictures.scene import render_tray_image
from chaingeo.pictures.sheet import tray_pixels

names = st.text("abcdefghijklmnopqrstuvwxyz", min_size=1, max_size=9)
rgb = st.tuples(st.integers(0, 255), st.integers(0, 255), st.integers(0, 255))
entries = st.lists(st.tuples(names, rgb), min_size=0, max_size=14, unique_by=lambda e: e[0])


@settings(max_examples=60, deadline=None)
@given(entries, st.sampled_from([96, 128, 256]), st.integers(0, 2**32 - 1), st.booleans())
def test_legends_on_arrays_are_the_drawn_ones(
    legend: list[tuple[str, tuple[int, int, int]]], size: int, seed: int, noisy: bool
) -> None:
    clear_memo()
    rng = np.random.default_rng(seed)
    plain = np.full((size, size, 3), 255, np.uint8)
    pictures = [plain, plain.copy()]
    if noisy:  # something under the legend: its names are blended onto it
        pictures[1][rng.integers(size // 2, size), rng.integers(0, size)] = rng.integers(0, 256, 3)
    pictures.append(rng.integers(0, 256, (size, size, 3)).astype(np.uint8))
    for _ in range(2):  # laid out, then painted from the kept layout
        for under in pictures:
            image = Image.fromarray(under)
            draw_legend(image, legend)
            got = under.copy()
            paint_legend(got, legend)
            assert np.array_equal(got, np.asarray(image))


box_coord = st.floats(-6.0, 70.0, allow_nan=False).map(lambda v: round(v * 8) / 8)


@settings(max_examples=200, deadline=None)
@given(box_coord, box_coord, st.floats(0.0, 30.0), st.floats(0.0, 30.0), rgb, st.booleans())
def test_rectangle_kernel_is_pillows_rectangle(
    x: float, y: float, w: float, h: float, fill: tuple[int, int, int], black: bool
) -> None:
    image = Image.new("RGB", (64, 64), (255, 255, 255))
    arr = np.full((64, 64, 3), 255, np.uint8)
    fill = (0, 0, 0) if black else fill  # the outline is left out when it is the fill
    ImageDraw.Draw(image).rectangle([x, y, x + w, y + h], fill=fill, outline=(0, 0, 0))
    box = np.array([x, y, x + w, y + h])
    raster_kernel.rectangle(
        arr, box, np.array(fill, np.uint8), np.zeros(3, np.uint8), fill != (0, 0, 0)
    )
    assert np.array_equal(np.asarray(image), arr)


cell = st.tuples(st.integers(0, 3), st.integers(0, 2), st.integers(0, 2))
piece = st.tuples(st.sets(cell, min_size=1, max_size=7), rgb | st.just((0, 0, 0)))


@settings(max_examples=25, deadline=None)
@given(st.dictionaries(names, piece, min_size=0, max_size=7), st.sampled_from([128, 256]))
def test_tray_on_arrays_is_the_reference_tray(
    pieces: dict[str, tuple[set[tuple[int, int, int]], tuple[int, int, int]]], size: int
) -> None:
    scene_pieces = {n: (Shape(cells), color) for n, (cells, color) in pieces.items()}
    expected = np.asarray(render_tray_image(scene_pieces, size))
    assert np.array_equal(tray_pixels(scene_pieces, size), expected)


@cache
def _stacking_levels() -> tuple[Level, ...]:
    return tuple(StackingEnv(images=False).levels.values())


@settings(max_examples=12, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_frames_along_random_placements_and_pickups_are_the_references(seed: int) -> None:
    """Views reuse kept layouts, work pictures and legends across steps and sizes; every
    picture must still be the reference's, and the one drawn from scratch."""
    rng = random.Random(seed)
    state = new_state(rng.choice(_stacking_levels()))
    for _ in range(5):
        moves = [a for a in state.legal_actions() if a.to_text() not in ("finish", "state")]
        if not moves:
            break
        state.step_text(rng.choice(moves).to_text())
        size = rng.choice([128, 256])
        got = render_frames(state, size)
        want = {n: np.asarray(im) for n, im in state_images(state, size, reference=True).items()}
        assert list(got) == list(want)
        assert all(np.array_equal(got[n], want[n]) for n in want)
        scene_kernel.clear()
        fresh = render_frames(state, size)
        assert all(np.array_equal(fresh[n], want[n]) for n in want)


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 32), st.integers(0, 32), st.integers(0, 32), st.integers(0, 32))
def test_reducing_a_rectangle_is_that_part_of_the_reduction(a: int, b: int, c: int, d: int) -> None:
    big = np.random.default_rng(a * 33 + b).integers(0, 256, (64, 64, 3)).astype(np.uint8)
    x0, x1, y0, y1 = min(a, c), max(a, c), min(b, d), max(b, d)
    out = np.zeros((32, 32, 3), np.uint8)
    raster_kernel.reduce2_into(big, out, x0, y0, x1, y1)
    want = np.zeros_like(out)
    want[y0:y1, x0:x1] = raster_kernel.reduce2(big)[y0:y1, x0:x1]
    assert np.array_equal(out, want)
