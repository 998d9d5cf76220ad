"""The colour legend drawn along the bottom of every picture: a swatch and the name of each
piece, so a person can tell which colour a name means (blue and cobalt side by side, say)
without the observation's colour table."""

from __future__ import annotations

from collections.abc import Sequence
from functools import lru_cache
from typing import Final

import numpy as np
import numpy.typing as npt
from PIL import Image, ImageDraw

from chaingeo.pictures.raster import EDGE, RGB, put_text, text_length
from chaingeo.pictures.texts import Swatches, pack_swatches, paint_swatches

#: (name, colour) per entry, in the order drawn.
Entries = Sequence[tuple[str, RGB]]
_TEXT: Final[RGB] = (20, 20, 20)
_MIN_PX: Final = 8
#: The legend takes at most this share of the picture's height (smaller text past that).
_MAX_SHARE: Final = 0.2


def _rows(entries: Entries, px: int, width: int) -> list[list[tuple[str, RGB, float]]]:
    """Entries flowed into rows no wider than ``width``: (name, colour, x of the swatch)."""
    return [list(r) for r in _flow(tuple(entries), px, width)]


@lru_cache(maxsize=1024)
def _flow(
    entries: tuple[tuple[str, RGB], ...], px: int, width: int
) -> tuple[tuple[tuple[str, RGB, float], ...], ...]:
    margin, gap = px * 0.6, px * 1.1
    rows: list[list[tuple[str, RGB, float]]] = [[]]
    x = margin
    for name, rgb in entries:
        w = px * 1.4 + text_length(name, px)
        if rows[-1] and x + w > width - margin:
            rows.append([])
            x = margin
        rows[-1].append((name, rgb, x))
        x += w + gap
    return tuple(tuple(r) for r in rows)


def legend_layout(entries: Entries, size: int) -> tuple[int, float]:
    """(text size, height in pixels) of the legend of ``entries`` in a ``size`` picture; the
    text shrinks until the legend fits its share of the height. (0, 0.0) without entries."""
    if not entries:
        return 0, 0.0
    px = max(_MIN_PX + 1, size // 32)
    while True:
        height = len(_rows(entries, px, size)) * px * 1.5 + px * 0.5
        if height <= size * _MAX_SHARE or px <= _MIN_PX:
            return px, height
        px -= 1


def draw_legend(image: Image.Image, entries: Entries) -> None:
    """The legend along the bottom edge of ``image`` (square)."""
    size = image.size[0]
    px, height = legend_layout(entries, size)
    if not entries:
        return
    draw = ImageDraw.Draw(image)
    y = image.size[1] - height + px * 0.25
    for row in _rows(entries, px, size):
        for name, rgb, x in row:
            draw.rectangle([x, y, x + px, y + px], fill=rgb, outline=EDGE, width=1)
            put_text(image, (x + px * 1.4, y + px / 2), name, px, _TEXT, anchor="lm")
        y += px * 1.5


Pixels = npt.NDArray[np.uint8]
_EDGE_INK: Final = np.array(EDGE, dtype=np.uint8)


@lru_cache(maxsize=256)
def _swatches(entries: tuple[tuple[str, RGB], ...], size: int, bottom: int) -> Swatches:
    """The calls :func:`draw_legend` makes in a picture ``size`` wide and ``bottom`` high,
    packed for one kernel call."""
    px, height = legend_layout(entries, size)
    y = bottom - height + px * 0.25
    out = []
    for row in _rows(entries, px, size):
        for name, rgb, x in row:
            label = (x + px * 1.4, y + px / 2, name, px, _TEXT, "lm")
            out.append(((x, y, x + px, y + px), rgb, label))
        y += px * 1.5
    return pack_swatches(out, EDGE)


def paint_legend(pixels: Pixels, entries: Entries) -> None:
    """:func:`draw_legend` on an ``(size, size, 3)`` array, in place: each swatch and name by
    one kernel call (the same rectangles and pastes), laid out once per legend and size."""
    if entries:
        paint_swatches(
            pixels, _swatches(tuple(entries), pixels.shape[1], pixels.shape[0]), _EDGE_INK
        )


def clear_memo() -> None:
    """Forget every laid out legend."""
    _swatches.cache_clear()
