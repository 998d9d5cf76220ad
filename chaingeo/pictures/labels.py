"""The text and arrows of a view (titles, axis ticks, depth labels) as drawing steps that know
the pixels they may touch.

A step's ``box`` bounds every pixel it can change, so :mod:`chaingeo.pictures.scene_kernel` can keep
a view's labels drawn once and redraw only the steps that overlap the part of the picture the
pieces changed; drawing every step in order is exactly what the renderer always did.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Sequence
from functools import lru_cache
from typing import Final, NamedTuple

import numpy as np
import numpy.typing as npt
from PIL import Image, ImageDraw

from chaingeo.core.arrays import F64
from chaingeo.pictures import raster_kernel
from chaingeo.pictures.raster import (
    RGB,
    Box,
    Camera,
    Faces,
    Projector,
    arrow_points,
    arrow_shapes,
    draw_flat,
    put_text,
    text_color_of,
    text_glyph,
)
from chaingeo.pictures.texts import TextItem, pack_texts, paint_texts

Pixels = npt.NDArray[np.uint8]
TEXT: Final[RGB] = (20, 20, 20)
AXIS_COLORS: Final[tuple[RGB, RGB, RGB]] = ((190, 30, 30), (20, 130, 40), (30, 60, 200))
AXIS_NAMES: Final = "xyz"


class Step(NamedTuple):
    """One drawing call and a box around every pixel it may change (a tuple: views make
    dozens per picture)."""

    box: Box
    run: Callable[[Image.Image], None]
    paint: Callable[[Pixels], None]  # the same on an (h, w, 3) array, by the kernels


def overlaps(a: Box, b: Box) -> bool:
    return a[0] < b[2] and b[0] < a[2] and a[1] < b[3] and b[1] < a[3]


def run_steps(image: Image.Image, steps: Sequence[Step]) -> None:
    for step in steps:
        step.run(image)


def paint_steps(pixels: Pixels, steps: Sequence[Step]) -> None:
    for step in steps:
        step.paint(pixels)


@lru_cache(maxsize=256)
def ink(fill: RGB) -> Pixels:
    """A colour as a read-only ``uint8`` array (the kernels' ink), made once."""
    out = np.array(fill, dtype=np.uint8)
    out.flags.writeable = False
    return out


def text_step(xy: Sequence[float] | F64, text: str, px: int, fill: RGB, anchor: str = "mm") -> Step:
    at = (float(xy[0]), float(xy[1]))
    mask, dx, dy = text_glyph(text, px, anchor)
    x, y = round(at[0]) + dx, round(at[1]) + dy
    box = (x, y, x + mask.shape[1], y + mask.shape[0])  # text_box, from the kept glyph
    color = ink(fill)
    return Step(
        box,
        lambda im: put_text(im, at, text, px, fill, anchor),
        lambda arr: raster_kernel.paste_mask(arr, mask, box[0], box[1], color),
    )


def item_step(item: TextItem) -> Step:
    """:func:`text_step` of one label."""
    x, y, text, px, fill, anchor = item
    return text_step((x, y), text, px, fill, anchor)


def texts_step(items: Sequence[TextItem]) -> Step:
    """A run of labels (at least one) as one step: pasted by one kernel call
    (:mod:`chaingeo.pictures.texts`), or one :func:`put_text` each with Pillow."""
    texts = pack_texts(items)
    return Step(
        texts.box,
        lambda im: run_steps(im, [item_step(i) for i in items]),
        lambda arr: paint_texts(arr, texts),
    )


def grouped(marks: Iterable[TextItem | Step]) -> list[Step]:
    """``marks`` in order, each run of consecutive labels as one :func:`texts_step` (the
    kernels' path: a step per label cost more than its pasting)."""
    out: list[Step] = []
    run: list[TextItem] = []
    for mark in marks:
        if isinstance(mark, Step):
            if run:
                out.append(texts_step(run))
                run = []
            out.append(mark)
        else:
            run.append(mark)
    if run:
        out.append(texts_step(run))
    return out


def one_by_one(marks: Iterable[TextItem | Step]) -> list[Step]:
    """``marks`` in order, a step per label (the reference's path)."""
    return [m if isinstance(m, Step) else item_step(m) for m in marks]


def arrow_step(a: F64, b: F64, fill: RGB, width: int) -> Step:
    reach = max(4.0, 3.2 * width) + width + 2
    ax, ay, bx, by = float(a[0]), float(a[1]), float(b[0]), float(b[1])
    box = (
        math.floor(min(ax, bx) - reach),
        math.floor(min(ay, by) - reach),
        math.ceil(max(ax, bx) + reach) + 1,
        math.ceil(max(ay, by) + reach) + 1,
    )
    pts = arrow_points(a, b, width)
    packed = None  # arrow_shapes, packed for the kernels without the list (views paint often)
    if pts is not None:
        packed = raster_kernel.Packed(
            np.array([(1, 2, width), (0, 3, 0)], dtype=np.int64),
            np.array(pts),
            np.array([fill, fill], dtype=np.uint8),
        )
    return Step(
        box,
        lambda im: draw_flat(ImageDraw.Draw(im), arrow_shapes(a, b, fill, width)),
        lambda arr: raster_kernel.paint_packed(arr, packed),
    )


def tick_steps(
    lo: Sequence[int], hi: Sequence[int], cam: Camera, proj: Projector, tick_px: int
) -> list[Step]:
    """:func:`tick_marks`, a step each."""
    return one_by_one(tick_marks(lo, hi, cam, proj, tick_px))


def tick_marks(
    lo: Sequence[int], hi: Sequence[int], cam: Camera, proj: Projector, tick_px: int
) -> list[TextItem | Step]:
    """1-based cell indices along one frame edge per displayed axis, then the axis name and an
    arrow pointing the way the index grows. The edge's geometry is plain float arithmetic, in
    the order the array expressions it replaces took (a view whose frame moves makes these on
    every picture, and two-element arrays cost more than the numbers)."""
    out: list[TextItem | Step] = []
    centre = proj(np.add(lo, hi) / 2.0)
    cx, cy = float(centre[0]), float(centre[1])
    for axis, spec in cam.tick_edges:
        base = np.array(
            [0.0 if s == "*" else float(lo[i] if s == "lo" else hi[i]) for i, s in enumerate(spec)]
        )
        start, end = base.copy(), base.copy()
        start[axis], end[axis] = lo[axis], hi[axis]
        (ax, ay), (bx, by) = proj(start).tolist(), proj(end).tolist()
        dx, dy = bx - ax, by - ay
        length = float(np.hypot(dx, dy))
        if length < 1e-6:
            continue
        dx, dy = dx / length, dy / length
        nx, ny = -dy, dx
        if nx * ((ax + bx) / 2 - cx) + ny * ((ay + by) / 2 - cy) < 0:  # far from zero
            nx, ny = -nx, -ny
        count = hi[axis] - lo[axis]
        cell_px = length / count
        px = int(min(tick_px, max(8, cell_px * 0.8)))
        every = max(1, math.ceil(px * 1.4 / cell_px))
        reach = px * 0.95 + 3
        ox, oy = nx * reach, ny * reach
        out.extend(_ticks(base, axis, range(lo[axis], hi[axis]), every, proj, (ox, oy), px))
        # The arrow continues the row of numbers; the axis name sits just outside it.
        color = AXIS_COLORS[axis]
        tx, ty = bx + ox + dx * (px * 0.5), by + oy + dy * (px * 0.5)
        hx, hy = tx + dx * (tick_px * 1.2), ty + dy * (tick_px * 1.2)
        out.append(arrow_step(np.array([tx, ty]), np.array([hx, hy]), color, max(2, tick_px // 8)))
        away = tick_px * 0.9
        name_at = ((tx + hx) / 2 + nx * away, (ty + hy) / 2 + ny * away)
        out.append((name_at[0], name_at[1], AXIS_NAMES[axis], tick_px + 3, color, "mm"))
    return out


def _ticks(
    base: F64,
    axis: int,
    cells: range,
    every: int,
    proj: Projector,
    offset: tuple[float, float],
    px: int,
) -> list[TextItem]:
    """The numbers along one edge: ``proj(p) + offset`` per shown cell, on scalars.

    A label lands at its point rounded, and nothing else of the point is used. The dot
    products are taken on Python floats, which may differ from numpy's (as
    :meth:`Projector.__call__` takes them) in the last bits; the two round alike unless the
    point lies within :data:`_HALF_GUARD` of a half pixel, where numpy's is taken."""
    p = base.copy()
    right, up, scale = proj.right, proj.up, proj.scale
    r0, r1, r2 = right.tolist()
    u0, u1, u2 = up.tolist()
    b = base.tolist()
    ox, oy = proj.origin
    dx, dy = offset
    out: list[TextItem] = []
    for i, c in enumerate(cells):
        if i % every and c != cells[-1]:
            continue
        b[axis] = c + 0.5
        x = (b[0] * r0 + b[1] * r1 + b[2] * r2) * scale + ox + dx
        y = -(b[0] * u0 + b[1] * u1 + b[2] * u2) * scale + oy + dy
        if _near_half(x) or _near_half(y):
            p[axis] = c + 0.5
            x = float(p @ right) * scale + ox + dx
            y = -float(p @ up) * scale + oy + dy
        out.append((x, y, str(c + 1), px, TEXT, "mm"))
    return out


#: How near a half pixel a label's point may be before the scalar dot products are not
#: trusted to round as numpy's do. Both are within a few units in the last place of a dot
#: of three terms below a few hundred (about 1e-13), times a scale of at most a few hundred
#: pixels: far below this.
_HALF_GUARD: Final = 1e-6


def _near_half(v: float) -> bool:
    return abs(v - math.floor(v) - 0.5) < _HALF_GUARD


def depth_label_steps(faces: Faces, cam: Camera, proj: Projector) -> list[Step]:
    """:func:`depth_labels`, a step each."""
    return one_by_one(depth_labels(faces, cam, proj))


def depth_labels(faces: Faces, cam: Camera, proj: Projector) -> list[TextItem]:
    """On each visible face of an axis view, the 1-based coordinate along the line of sight."""
    depth = cam.depth_axis
    assert depth is not None
    nearest: dict[tuple[int, int], int] = {}
    a, b = [i for i in range(3) if i != depth]
    cells = faces.cells.tolist()
    for i, cell in enumerate(cells):
        nearest[(cell[a], cell[b])] = i  # far to near: the last one is in front
    cell_px = proj.scale
    px = int(min(22, max(9, cell_px * 0.24)))
    if cell_px < 1.6 * px:
        return []  # too small to print legibly
    prefix = f"{AXIS_NAMES[depth]}=" if cell_px >= 3.2 * px else ""  # small cells: number only
    shown = sorted(nearest.values())
    centres = proj.screen(faces.corners[shown].mean(axis=1)).tolist()
    fills = faces.fills.tolist()
    return [
        (
            centres[j][0],
            centres[j][1],
            f"{prefix}{cells[i][depth] + 1}",
            px,
            text_color_of((fills[i][0], fills[i][1], fills[i][2])),
            "mm",
        )
        for j, i in enumerate(shown)
    ]


def title_steps(lines: Sequence[str], size: int, title_px: int) -> list[Step]:
    return one_by_one(titles(lines, size, title_px))


def titles(lines: Sequence[str], size: int, title_px: int) -> list[TextItem]:
    """The title lines down the top left corner."""
    y = max(4, size // 100)
    out: list[TextItem] = []
    for text in lines:
        out.append((float(max(4, size // 64)), float(y), text, title_px, TEXT, "la"))
        y += int(title_px * 1.25)
    return out
