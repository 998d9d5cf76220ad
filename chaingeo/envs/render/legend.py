"""The colour legend drawn along the bottom of every picture: a swatch and the name of each
piece, so a person can tell which colour a name means (blue and cobalt side by side, say)
without the observation's colour table."""

from __future__ import annotations

import math
from collections import OrderedDict
from collections.abc import Sequence
from functools import lru_cache
from typing import Final

import numpy as np
import numpy.typing as npt
from PIL import Image, ImageDraw

from chaingeo.envs.render.raster import EDGE, RGB, put_text, text_box, text_length

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
#: Legends kept: per (entries, size), a few (pixels under, pixels drawn) bottom strips.
_MEMO: OrderedDict[tuple[tuple[tuple[str, RGB], ...], int], list[tuple[Pixels, Pixels]]] = (
    OrderedDict()
)
MEMO_CAPACITY: Final = 64
_VARIANTS: Final = 4


@lru_cache(maxsize=1024)
def _strip_top(entries: tuple[tuple[str, RGB], ...], size: int) -> int:
    """The first row the legend may change: its first row's swatches and names (a text's box
    bounds every pixel it changes)."""
    px, height = legend_layout(entries, size)
    y = size - height + px * 0.25
    tops = [
        text_box((x + px * 1.4, y + px / 2), n, px, "lm")[1]
        for n, _, x in _rows(entries, px, size)[0]
    ]
    return max(0, min(math.floor(y) - 1, *tops))


def paint_legend(pixels: Pixels, entries: Entries) -> None:
    """:func:`draw_legend` on an ``(size, size, 3)`` array, in place.

    The legend is drawn over whatever lies under it (its text is blended), so a drawn legend
    is kept with the strip it was drawn on and reused only where that strip is the same: the
    same bytes as drawing, without Pillow. A drawing that changed a pixel above the strip is
    copied whole and not kept."""
    if not entries:
        return
    size = pixels.shape[1]
    key = (tuple(entries), size)
    top = _strip_top(key[0], size)
    strip = pixels[top:]
    kept = _MEMO.get(key)
    if kept is not None:
        _MEMO.move_to_end(key)
        for under, over in kept:
            if np.array_equal(under, strip):
                strip[...] = over
                return
    image = Image.fromarray(pixels)
    draw_legend(image, entries)
    drawn = np.asarray(image)
    if not np.array_equal(drawn[:top], pixels[:top]):
        pixels[...] = drawn
        return
    variants = _MEMO.setdefault(key, [])
    variants.insert(0, (strip.copy(), drawn[top:].copy()))
    del variants[_VARIANTS:]
    strip[...] = drawn[top:]
    while len(_MEMO) > MEMO_CAPACITY:
        _MEMO.popitem(last=False)


def clear_memo() -> None:
    """Forget every kept legend."""
    _MEMO.clear()
