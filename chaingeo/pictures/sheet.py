"""The piece sheet (the tray) drawn on an array by the kernels, byte for byte the picture of
:func:`chaingeo.pictures.scene.render_tray_image`.

The tray changes with every piece placed or taken back, so it is drawn anew on most steps.
Through Pillow its pieces were drawn by the kernels but then turned into an image for the
titles, swatches, names and grid lines, and back into an array for the environments; here
every call is a kernel on the same array, in the renderer's order (swatches by
:func:`chaingeo.pictures.raster_kernel.rectangle`, tested against Pillow, each with its name in
one kernel call).
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from chaingeo.kernels.jit import mode as jit_mode
from chaingeo.pictures import raster_kernel
from chaingeo.pictures.labels import ink, paint_steps, title_steps
from chaingeo.pictures.raster import EDGE, Flat, text_length
from chaingeo.pictures.scene import (
    _BACKGROUND,
    _GRID,
    _SHEET_NOTE,
    _SUPERSAMPLE,
    _TEXT,
    TRAY_TITLE,
    PieceMap,
    _check_tray,
    _Layout,
    _Sheet,
    _sheet_layout,
    render_tray_image_with,
)
from chaingeo.pictures.texts import pack_swatches, paint_swatches

Pixels = npt.NDArray[np.uint8]
_EDGE = ink(EDGE)


def tray_pixels(pieces: PieceMap, size: int, title: str = TRAY_TITLE) -> Pixels:
    """:func:`chaingeo.pictures.scene.render_tray_image` as a writable array."""
    _check_tray(pieces, size)
    lay = _Layout.of(size)
    width = lay.edge_px(_SUPERSAMPLE)
    sheet = _sheet_layout(pieces, size, True) if pieces else None
    if sheet is None or width > 4 or jit_mode() != "numba":  # no pieces, or round joints
        image = render_tray_image_with(pieces, size, title, fast=True)
        return np.array(image, dtype=np.uint8)
    big = raster_kernel.blank(size * _SUPERSAMPLE, _BACKGROUND).copy()
    corners = np.concatenate([p.screen(f.corners) for f, p in sheet.drawn])
    fills = np.concatenate([f.fills for f, _ in sheet.drawn])
    raster_kernel.draw_faces(big, corners, fills, _EDGE, width)
    pixels = raster_kernel.reduce2(big)
    paint_steps(pixels, title_steps([title, _SHEET_NOTE], size, lay.title_px))
    _labels(pixels, sheet)
    raster_kernel.draw_flat(pixels, _grid(sheet, size))
    return pixels


def _labels(pixels: Pixels, sheet: _Sheet) -> None:
    """Each piece's swatch and name, as ``_render_tray`` draws them."""
    px = sheet.label_px
    swatches = []
    for text, rgb, x, y in sheet.slots:
        left = x - (text_length(text, px) + px * 1.4) / 2
        label = (left + px * 1.4, y, text, px, _TEXT, "lm")
        swatches.append(((left, y - px / 2, left + px, y + px / 2), rgb, label))
    paint_swatches(pixels, pack_swatches(swatches, EDGE), _EDGE)


def _grid(sheet: _Sheet, size: int) -> list[Flat]:
    """The lines between the sheet's cells."""
    out: list[Flat] = []
    for c in range(1, sheet.cols):
        x = c * sheet.cell_w
        out.append((1, np.array([(x, sheet.title_h), (x, size)], dtype=np.float64), _GRID, 1))
    for r in range(1, sheet.rows):
        y = sheet.title_h + r * sheet.cell_h
        out.append((1, np.array([(0, y), (size, y)], dtype=np.float64), _GRID, 1))
    return out
