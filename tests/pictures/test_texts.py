"""Runs of labels pasted by one kernel call give the bytes of Pillow pasting them one by one,
and the tick labels' scalar arithmetic rounds as numpy's does."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from PIL import Image

from chaingeo.pictures import labels, texts
from chaingeo.pictures.raster import Projector, put_text, text_box
from chaingeo.pictures.texts import TextItem, pack_texts, paint_texts

SIZE = 64
rgb = st.tuples(st.integers(0, 255), st.integers(0, 255), st.integers(0, 255))
item = st.tuples(
    st.floats(-20.0, SIZE + 20.0, allow_nan=False),
    st.floats(-20.0, SIZE + 20.0, allow_nan=False),
    st.text("0123456789xyz=ABCjg ", min_size=1, max_size=6),
    st.integers(8, 20),
    rgb,
    st.sampled_from(["mm", "la", "lm"]),
)


def _pillow(under: np.ndarray, items: list[TextItem]) -> np.ndarray:
    image = Image.fromarray(under)
    for x, y, text, px, fill, anchor in items:
        put_text(image, (x, y), text, px, fill, anchor)
    return np.asarray(image)


@settings(max_examples=150, deadline=None)
@given(st.lists(item, min_size=1, max_size=8), st.integers(0, 2**32 - 1))
def test_a_run_of_labels_is_pillows_pastes(items: list[TextItem], seed: int) -> None:
    under = np.random.default_rng(seed).integers(0, 256, (SIZE, SIZE, 3)).astype(np.uint8)
    got = under.copy()
    run = pack_texts(items)
    paint_texts(got, run)
    assert np.array_equal(got, _pillow(under, items))
    boxes = [text_box((x, y), t, px, a) for x, y, t, px, _, a in items]
    assert run.box == (
        min(b[0] for b in boxes),
        min(b[1] for b in boxes),
        max(b[2] for b in boxes),
        max(b[3] for b in boxes),
    )


def test_runs_stay_valid_when_the_atlas_grows_or_restarts(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(texts, "_ATLAS", texts._Atlas())
    monkeypatch.setattr(texts, "ATLAS_BYTES", 6000)
    under = np.full((SIZE, SIZE, 3), 255, np.uint8)
    runs = []
    for i in range(40):  # distinct texts: the atlas grows, restarts between runs, grows again
        items: list[TextItem] = [
            (10.0 + j, 20.0 + i % 30, f"label {i}.{j}", 12, (20, 20, 20), "la") for j in range(3)
        ]
        runs.append((pack_texts(items), items))
    assert texts._ATLAS.used < 2 * 6000
    assert len({id(r.atlas) for r, _ in runs}) > 1
    for run, items in runs:
        got = under.copy()
        paint_texts(got, run)
        assert np.array_equal(got, _pillow(under, items))


unit = st.floats(-1.0, 1.0, allow_nan=False)
coord = st.floats(-300.0, 300.0, allow_nan=False)


@settings(max_examples=300, deadline=None)
@given(
    st.tuples(st.integers(-3, 12), st.integers(-3, 12), st.integers(-3, 12)),
    st.integers(0, 2),
    st.integers(1, 14),
    st.integers(1, 3),
    st.tuples(unit, unit, unit),
    st.tuples(unit, unit, unit),
    st.floats(0.5, 300.0),
    st.tuples(coord, coord),
    st.tuples(st.floats(-30.0, 30.0), st.floats(-30.0, 30.0)),
)
def test_tick_numbers_land_where_numpys_arithmetic_puts_them(
    base: tuple[int, int, int],
    axis: int,
    count: int,
    every: int,
    right: tuple[float, float, float],
    up: tuple[float, float, float],
    scale: float,
    origin: tuple[float, float],
    offset: tuple[float, float],
) -> None:
    proj = Projector(np.array(right), np.array(up), scale, origin)
    cells = range(base[axis], base[axis] + count)
    got = labels._ticks(np.array(base, dtype=np.float64), axis, cells, every, proj, offset, 10)
    p = np.array(base, dtype=np.float64)
    expected = []
    for i, c in enumerate(cells):  # the projector's one-point arithmetic, as it was
        if i % every and c != cells[-1]:
            continue
        p[axis] = c + 0.5
        x = float(p @ proj.right) * scale + origin[0] + offset[0]
        y = -float(p @ proj.up) * scale + origin[1] + offset[1]
        expected.append((x, y, str(c + 1)))
    assert [(round(x), round(y), t) for x, y, t, *_ in got] == [
        (round(x), round(y), t) for x, y, t in expected
    ]


def test_tick_numbers_on_a_half_pixel_round_as_numpys() -> None:
    """Axis-aligned projections put labels on exact half pixels: the guard's own case."""
    proj = Projector(np.array([1.0, 0.0, 0.0]), np.array([0.0, 0.0, 1.0]), 3.0, (0.0, 0.0))
    got = labels._ticks(np.zeros(3), 0, range(0, 6), 1, proj, (0.0, 0.0), 10)
    assert [round(x) for x, *_ in got] == [round((c + 0.5) * 3.0) for c in range(6)]
    assert all(labels._near_half(x) for x, *_ in got)


def test_a_point_near_a_half_pixel_takes_numpys_dot_products() -> None:
    assert labels._near_half(2.5) and labels._near_half(-3.5 + 1e-9)
    assert not labels._near_half(2.5 + 1e-5) and not labels._near_half(7.0)
