"""Runs of text labels pasted by one kernel call, from glyph masks kept in one flat atlas.

A view prints dozens of labels (titles, tick numbers, axis names, depth labels). Made as one
step and one kernel call each, building and dispatching them cost several times the pasting
itself. Here a run of labels is one :class:`Texts`: a row per label (where its glyphs lie in
the atlas, their size, the top-left pixel) and its colour, pasted in order by
:func:`paste_texts` with the very blend of :func:`chaingeo.pictures.raster_kernel.paste_mask`
(Pillow's ``fill_mask_L``), so the pixels are the same as pasting them one by one.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Final, NamedTuple

import numpy as np
import numpy.typing as npt

from chaingeo.core.arrays import I64, U8
from chaingeo.kernels.jit import njit
from chaingeo.pictures.raster import RGB, Box, text_glyph
from chaingeo.pictures.raster_kernel import Canvas, canvas, rectangle

#: One label: the anchor point (x, y), the text, its pixel size, colour and Pillow anchor.
TextItem = tuple[float, float, str, int, RGB, str]
#: Bytes of glyphs past which the next run starts a fresh atlas.
ATLAS_BYTES: Final = 16 * 1024 * 1024


class _Atlas:
    """Glyph masks laid end to end in one byte array, each placed once.

    Glyphs are only ever appended: a full array is copied into a larger one (offsets stay),
    and a run that finds more than :data:`ATLAS_BYTES` used starts a fresh one first, never
    midway. A :class:`Texts` keeps the array it was made against, so its rows stay valid
    whatever happens to the atlas later."""

    def __init__(self) -> None:
        self.data = np.zeros(0, dtype=np.uint8)
        self.used = 0
        self.slots: dict[tuple[str, int, str], tuple[int, int, int, int, int]] = {}
        self.restart()

    def restart(self) -> None:
        """Start a fresh array (the old one stays with the runs made against it)."""
        self.data = np.zeros(1 << 16, dtype=np.uint8)
        self.used = 0
        self.slots = {}

    def slot(self, text: str, px: int, anchor: str) -> tuple[int, int, int, int, int]:
        """(offset, height, width, dx, dy) of the glyphs of ``text``: where they lie in
        :attr:`data` and their offset from the anchor point, as :func:`text_glyph` gives it."""
        key = (text, px, anchor)
        found = self.slots.get(key)
        if found is not None:
            return found
        mask, dx, dy = text_glyph(text, px, anchor)
        n = mask.size
        if self.used + n > len(self.data):
            grown = np.zeros(max(2 * len(self.data), self.used + n), dtype=np.uint8)
            grown[: self.used] = self.data[: self.used]
            self.data = grown
        self.data[self.used : self.used + n] = mask.reshape(-1)
        made = (self.used, mask.shape[0], mask.shape[1], dx, dy)
        self.used += n
        self.slots[key] = made
        return made


_ATLAS = _Atlas()


class Texts(NamedTuple):
    """A run of labels ready for :func:`paste_texts`, and the box around every pixel it may
    change."""

    atlas: U8
    rows: I64  # (n, 5): offset in the atlas, height, width, left, top
    colors: U8  # (n, 3)
    box: Box


def pack_texts(items: Sequence[TextItem]) -> Texts:
    """The labels of ``items`` (at least one) in order. A label's top-left pixel is its anchor
    point rounded (Python's ``round``) plus its glyphs' offset, as :func:`put_text` places it."""
    atlas = _ATLAS
    if atlas.used > ATLAS_BYTES:
        atlas.restart()
    rows = []
    x0 = y0 = 1 << 30
    x1 = y1 = -(1 << 30)
    for x, y, text, px, _, anchor in items:
        off, h, w, dx, dy = atlas.slot(text, px, anchor)
        left, top = round(x) + dx, round(y) + dy
        rows.append((off, h, w, left, top))
        x0, y0 = min(x0, left), min(y0, top)
        x1, y1 = max(x1, left + w), max(y1, top + h)
    colors = np.array([item[4] for item in items], dtype=np.uint8)
    return Texts(atlas.data, np.array(rows, dtype=np.int64), colors, (x0, y0, x1, y1))


@njit(cache=True, inline="always")
def _paste(cv: Canvas, atlas: U8, rows: I64, colors: U8, i: int) -> None:
    """Label ``i``: its glyph mask pasted in its colour, clipped (``Image.paste(c, box, mask)``:
    ``(out * (255 - m) + c * m) / 255`` rounded Pillow's way; where the mask is zero that
    blend leaves the pixel as it is, so it is skipped)."""
    flat, h_img, w_img = cv
    off, h, w, x0, y0 = rows[i, 0], rows[i, 1], rows[i, 2], rows[i, 3], rows[i, 4]
    c0, c1, c2 = np.int64(colors[i, 0]), np.int64(colors[i, 1]), np.int64(colors[i, 2])
    for my in range(max(0, -y0), min(h, h_img - y0)):
        src = off + my * w
        dst = ((y0 + my) * w_img + x0) * 3
        for mx in range(max(0, -x0), min(w, w_img - x0)):
            m = np.int64(atlas[src + mx])
            if m == 0:
                continue
            j = dst + 3 * mx
            t = np.int64(flat[j]) * (255 - m) + c0 * m + 128
            flat[j] = ((t >> 8) + t) >> 8
            t = np.int64(flat[j + 1]) * (255 - m) + c1 * m + 128
            flat[j + 1] = ((t >> 8) + t) >> 8
            t = np.int64(flat[j + 2]) * (255 - m) + c2 * m + 128
            flat[j + 2] = ((t >> 8) + t) >> 8


@njit(cache=True)
def paste_texts(img: U8, atlas: U8, rows: I64, colors: U8) -> None:
    """Every label of a run, in order."""
    cv = canvas(img)
    for i in range(rows.shape[0]):
        _paste(cv, atlas, rows, colors, i)


def paint_texts(img: U8, texts: Texts) -> None:
    paste_texts(img, texts.atlas, texts.rows, texts.colors)


class Swatches(NamedTuple):
    """Colour swatches, each followed by its label (the legend's and the tray's names)."""

    boxes: npt.NDArray[np.float64]  # (n, 4): the rectangles as ``ImageDraw.rectangle`` takes
    fills: U8  # (n, 3)
    edged: npt.NDArray[np.bool_]  # (n,): outlined (the outline's colour is not the fill)
    texts: Texts  # label i after swatch i


def pack_swatches(
    swatches: Sequence[tuple[tuple[float, float, float, float], RGB, TextItem]], outline: RGB
) -> Swatches:
    """Swatches (box, fill, then the label drawn after it), at least one, outlined in
    ``outline`` where the fill differs."""
    return Swatches(
        np.array([box for box, _, _ in swatches], dtype=np.float64),
        np.array([fill for _, fill, _ in swatches], dtype=np.uint8),
        np.array([fill != outline for _, fill, _ in swatches], dtype=np.bool_),
        pack_texts([label for _, _, label in swatches]),
    )


@njit(cache=True)
def _paint_swatches(
    img: U8,
    boxes: npt.NDArray[np.float64],
    fills: U8,
    outline: U8,
    edged: npt.NDArray[np.bool_],
    atlas: U8,
    rows: I64,
    colors: U8,
) -> None:
    cv = canvas(img)
    for i in range(boxes.shape[0]):
        rectangle(img, boxes[i], fills[i], outline, edged[i])
        _paste(cv, atlas, rows, colors, i)


def paint_swatches(img: U8, swatches: Swatches, outline: U8) -> None:
    """Each swatch (:func:`chaingeo.pictures.raster_kernel.rectangle`, width 1), then its label,
    in order: one kernel call."""
    t = swatches.texts
    _paint_swatches(
        img, swatches.boxes, swatches.fills, outline, swatches.edged, t.atlas, t.rows, t.colors
    )
