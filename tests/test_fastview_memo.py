"""What the fast path keeps between pictures (drawn legends) gives the bytes drawing gives."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from PIL import Image

from chaingeo.envs.render.legend import clear_memo, draw_legend, paint_legend

names = st.text("abcdefghijklmnopqrstuvwxyz", min_size=1, max_size=9)
rgb = st.tuples(st.integers(0, 255), st.integers(0, 255), st.integers(0, 255))
entries = st.lists(st.tuples(names, rgb), min_size=0, max_size=14, unique_by=lambda e: e[0])


@settings(max_examples=60, deadline=None)
@given(entries, st.sampled_from([96, 128, 256]), st.integers(0, 2**32 - 1), st.booleans())
def test_kept_legends_are_the_drawn_ones(
    legend: list[tuple[str, tuple[int, int, int]]], size: int, seed: int, noisy: bool
) -> None:
    clear_memo()
    rng = np.random.default_rng(seed)
    plain = np.full((size, size, 3), 255, np.uint8)
    pictures = [plain, plain.copy()]
    if noisy:  # something under the legend: kept legends must not be reused there
        pictures[1][rng.integers(size // 2, size), rng.integers(0, size)] = rng.integers(0, 256, 3)
    pictures.append(rng.integers(0, 256, (size, size, 3)).astype(np.uint8))
    for _ in range(2):  # drawn, then (where the strip matches) reused
        for under in pictures:
            image = Image.fromarray(under)
            draw_legend(image, legend)
            got = under.copy()
            paint_legend(got, legend)
            assert np.array_equal(got, np.asarray(image))
