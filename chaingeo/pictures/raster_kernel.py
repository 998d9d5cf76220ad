"""Pillow's polygon fill, lines and 2x2 reduction as numba kernels on ``(h, w, 3)`` uint8 arrays.
The reference it must equal is :mod:`chaingeo.pictures.raster` (Pillow's drawing).

The renderer draws thousands of small polygons and lines per observation through Pillow, one
Python call each. These kernels follow Pillow's own C code (``libImaging/Draw.c``: vertices
truncated to ints, the float32 scanline fill with its corner rule, Bresenham lines without the
end point plus a last point, wide lines as quads; ``Reduce.c``: the box average rounded half up)
so that a whole list of shapes is drawn in one call with the very same pixels; the tests compare
them with Pillow on random shapes. Float32 steps are computed in float64 and rounded to float32
after each operation, which gives the float32 result (double rounding is innocuous for + - * /).

The per-pixel and per-row helpers are inlined into their callers in numba's own IR
(``inline="always"``): as separate functions each call passed the picture's array struct and
counted its references, about a tenth of a face's drawing.

Shapes are flat: ``kinds[i]`` (0 polygon fill, 1 polyline), ``starts[i]:starts[i+1]`` its
points in ``pts`` (float64 ``(m, 2)``), ``colors[i]`` its RGB and ``widths[i]`` its line width.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from functools import lru_cache
from typing import NamedTuple

import numpy as np
import numpy.typing as npt

from chaingeo.core.arrays import U8
from chaingeo.kernels.jit import njit
from chaingeo.pictures.raster import Flat

POLYGON = 0
POLYLINE = 1


@lru_cache(maxsize=16)
def blank(side: int, rgb: tuple[int, int, int]) -> U8:
    """A ``side`` square picture of one colour, read-only, to copy (filling an array from a
    colour triple is about 20 times slower than copying one)."""
    out = np.empty((side, side, 3), dtype=np.uint8)
    out[:] = rgb
    out.flags.writeable = False
    return out


#: Work arrays of the fill, made once per kernel call: edges (xmin, ymin, xmax, ymax, x0, y0),
#: their float32 slopes, the indices of the slanted ones, a row's crossings.
Scratch = tuple[
    npt.NDArray[np.int64], npt.NDArray[np.float64], npt.NDArray[np.int64], npt.NDArray[np.float64]
]


@njit(cache=True)
def scratch(points: int) -> Scratch:
    """Work arrays for shapes of up to ``points`` points."""
    n = points + 1
    return (
        np.zeros((n, 6), np.int64),
        np.zeros(n, np.float64),
        np.zeros(n, np.int64),
        np.zeros(2 * n + 1, np.float64),
    )


@njit(cache=True, inline="always")
def _f32(v: float) -> float:
    return float(np.float32(v))


@njit(cache=True, inline="always")
def _round_up(f: float) -> int:
    """Pillow's ROUND_UP on a float32 (``floor(f + 0.5F)``, symmetric about zero)."""
    if f >= 0.0:
        return math.floor(_f32(f + 0.5))
    return -math.floor(abs(f) + 0.5)  # fabs() is a double: double arithmetic


@njit(cache=True, inline="always")
def _round_down(f: float) -> int:
    if f >= 0.0:
        return math.ceil(_f32(f - 0.5))
    return -math.ceil(abs(f) - 0.5)


@njit(cache=True)
def _round_up_d(f: float) -> int:
    """ROUND_UP on a double (``0.5F`` promoted: double arithmetic)."""
    if f >= 0.0:
        return math.floor(f + 0.5)
    return -math.floor(abs(f) + 0.5)


@njit(cache=True)
def _round_down_d(f: float) -> int:
    if f >= 0.0:
        return math.ceil(f - 0.5)
    return -math.ceil(abs(f) - 0.5)


@njit(cache=True)
def _roundf(f: float) -> float:
    """C ``roundf`` of a float32: half away from zero (exact in float64)."""
    if f >= 0.0:
        return float(math.floor(f + 0.5))
    return -float(math.floor(-f + 0.5))


#: A picture as the kernels write it: its bytes flat (C order), its height and width. Writing
#: through unsigned flat indices lets numba drop the negative-index checks of ``img[y, x, c]``
#: and vectorise a span's stores (a long span fills about ten times faster).
Canvas = tuple[U8, int, int]


@njit(cache=True)
def canvas(img: U8) -> Canvas:
    """The canvas of a C-contiguous ``(h, w, 3)`` picture (its bytes, not a copy)."""
    return img.reshape(img.size), img.shape[0], img.shape[1]


@njit(cache=True, inline="always")
def _hline(cv: Canvas, x0: int, y: int, x1: int, c: U8) -> None:
    flat, h, w = cv
    if y < 0 or y >= h:
        return
    if x0 < 0:
        x0 = 0
    elif x0 >= w:
        return
    if x1 < 0:
        return
    if x1 >= w:
        x1 = w - 1
    if x1 < x0:
        return
    c0, c1, c2 = c[0], c[1], c[2]
    base = np.uint64((y * w + x0) * 3)
    three, one, two = np.uint64(3), np.uint64(1), np.uint64(2)
    for k in range(np.uint64(x1 + 1 - x0)):
        j = base + three * k
        flat[j] = c0
        flat[j + one] = c1
        flat[j + two] = c2


@njit(cache=True, inline="always")
def _point(cv: Canvas, x: int, y: int, c: U8) -> None:
    flat, h, w = cv
    if 0 <= x < w and 0 <= y < h:
        j = (y * w + x) * 3
        flat[j] = c[0]
        flat[j + 1] = c[1]
        flat[j + 2] = c[2]


@njit(cache=True)
def _line(cv: Canvas, x0: int, y0: int, x1: int, y1: int, c: U8) -> None:
    """Pillow's ``line32``: Bresenham from (x0, y0), the end point left out."""
    dx, xs = x1 - x0, 1
    if dx < 0:
        dx, xs = -dx, -1
    dy, ys = y1 - y0, 1
    if dy < 0:
        dy, ys = -dy, -1
    if dx == 0:
        for _ in range(dy):
            _point(cv, x0, y0, c)
            y0 += ys
    elif dy == 0:
        for _ in range(dx):
            _point(cv, x0, y0, c)
            x0 += xs
    else:  # a step along the longer axis each point, along the shorter when the error says
        x_major = dx > dy
        n, m = (dx, dy) if x_major else (dy, dx)
        lx, ly = (xs, 0) if x_major else (0, ys)
        sx, sy = (0, ys) if x_major else (xs, 0)
        e = m + m - n
        for _ in range(n):
            _point(cv, x0, y0, c)
            if e >= 0:
                x0 += sx
                y0 += sy
                e -= n + n
            e += m + m
            x0 += lx
            y0 += ly


@njit(cache=True, inline="always")
def _add_edge(
    edges: npt.NDArray[np.int64],
    dxs: npt.NDArray[np.float64],
    i: int,
    x0: int,
    y0: int,
    x1: int,
    y1: int,
) -> None:
    """Edge ``i``: xmin, ymin, xmax, ymax, x0, y0 in ``edges[i]``, the float32 slope in dxs."""
    edges[i, 0], edges[i, 2] = min(x0, x1), max(x0, x1)
    edges[i, 1], edges[i, 3] = min(y0, y1), max(y0, y1)
    edges[i, 4], edges[i, 5] = x0, y0
    dxs[i] = 0.0 if y0 == y1 else _f32(_f32(x1 - x0) / _f32(y1 - y0))


@njit(cache=True, inline="always")
def _x_at(edges: npt.NDArray[np.int64], dxs: npt.NDArray[np.float64], i: int, y: int) -> float:
    # float32 operations themselves (the same result as rounding each float64 step)
    return float(np.float32(y - edges[i, 5]) * np.float32(dxs[i]) + np.float32(edges[i, 4]))


@njit(cache=True)
def _corner(
    edges: npt.NDArray[np.int64],
    dxs: npt.NDArray[np.float64],
    table: npt.NDArray[np.int64],
    ii: int,
    y: int,
    x: float,
) -> float:
    """Pillow's "connect discontiguous corners" adjustment of crossing ``x`` of edge
    ``table[ii]`` on row ``y``."""
    cur = table[ii]
    for k in range(ii):
        o = table[k]
        if (y != edges[o, 1] and y != edges[o, 3]) or dxs[o] == 0.0:
            continue
        if _roundf(x) != _roundf(_x_at(edges, dxs, o, y)):
            continue
        offset = -1 if y == edges[cur, 3] else 1
        adj = _x_at(edges, dxs, cur, y + offset)
        if edges[o, 1] <= y + offset <= edges[o, 3]:
            adj_o = _x_at(edges, dxs, o, y + offset)
            if x > _f32(adj + 1) and x > _f32(adj_o + 1):
                return _f32(_roundf(_f32(max(adj, adj_o))) + 1)
            if x < _f32(adj - 1) and x < _f32(adj_o - 1):
                return _f32(_roundf(_f32(min(adj, adj_o))) - 1)
            return x
    return x


@njit(cache=True)
def _polygon_generic(cv: Canvas, sc: Scratch, n: int, c: U8) -> None:
    """Pillow's scanline fill of the first ``n`` edges (``polygon_generic``, no alpha)."""
    edges, dxs, table, xx = sc
    ymin, ymax = cv[1] - 1, 0
    count = 0
    for i in range(n):
        ymin = min(ymin, edges[i, 1])
        ymax = max(ymax, edges[i, 3])
        if edges[i, 1] == edges[i, 3]:
            _hline(cv, edges[i, 0], edges[i, 1], edges[i, 2], c)
            continue
        table[count] = i
        count += 1
    ymin = max(ymin, 0)
    ymax = min(ymax, cv[1])
    for y in range(ymin, ymax + 1):
        j = 0
        for ii in range(count):
            e = table[ii]
            if y < edges[e, 1] or y > edges[e, 3]:
                continue
            xx[j] = _x_at(edges, dxs, e, y)
            j += 1
            if y == edges[e, 3] and y < ymax:
                xx[j] = xx[j - 1]
                j += 1
            elif (y == edges[e, 1] or y == edges[e, 3]) and dxs[e] != 0.0:
                xx[j - 1] = _corner(edges, dxs, table, ii, y, xx[j - 1])
        for i in range(1, j):  # qsort's order (equal crossings are interchangeable)
            v = xx[i]
            k = i
            while k > 0 and xx[k - 1] > v:
                xx[k] = xx[k - 1]
                k -= 1
            xx[k] = v
        for i in range(1, j, 2):
            _hline(cv, _round_up(xx[i - 1]), y, _round_down(xx[i]), c)


@njit(cache=True)
def _fill_polygon(cv: Canvas, xy: npt.NDArray[np.float64], c: U8, sc: Scratch) -> None:
    """``ImageDraw.polygon(xy, fill=c)``: ``ImagingDrawPolygon`` with its merged horizontals."""
    m = xy.shape[0]
    edges, dxs = sc[0], sc[1]
    n = 0
    px, py = int(xy[0, 0]), int(xy[0, 1])  # C's (int) cast truncates
    x0, y0 = px, py
    for i in range(m - 1):
        x1, y1 = int(xy[i + 1, 0]), int(xy[i + 1, 1])
        merged = False
        if y0 == y1 and i != 0 and y0 == py:
            if x1 > x0 and x0 > px:
                edges[n - 1, 2] = x1
                merged = True
            elif x1 < x0 and x0 < px:
                edges[n - 1, 0] = x1
                merged = True
        if not merged:
            _add_edge(edges, dxs, n, x0, y0, x1, y1)
            n += 1
        px, py, x0, y0 = x0, y0, x1, y1
    fx, fy = int(xy[0, 0]), int(xy[0, 1])
    if x0 != fx or y0 != fy:
        _add_edge(edges, dxs, n, x0, y0, fx, fy)
        n += 1
    _polygon_generic(cv, sc, n, c)


@njit(cache=True)
def _wide_line(
    cv: Canvas, x0: int, y0: int, x1: int, y1: int, width: int, c: U8, sc: Scratch
) -> None:
    """Pillow's ``ImagingDrawWideLine``: the segment's quad, filled."""
    dx, dy = x1 - x0, y1 - y0
    if dx == 0 and dy == 0:
        _point(cv, x0, y0, c)
        return
    big = math.hypot(dx, dy)
    small = (width - 1) / 2.0
    ratio_max = _round_up_d(small) / big
    ratio_min = _round_down_d(small) / big
    dxmin, dxmax = _round_down_d(ratio_min * dy), _round_down_d(ratio_max * dy)
    dymin, dymax = _round_down_d(ratio_min * dx), _round_down_d(ratio_max * dx)
    vx = (x0 - dxmin, x1 - dxmin, x1 + dxmax, x0 + dxmax)
    vy = (y0 + dymax, y1 + dymax, y1 - dymin, y0 - dymin)
    for i in range(4):
        k = (i + 1) % 4
        _add_edge(sc[0], sc[1], i, vx[i], vy[i], vx[k], vy[k])
    _polygon_generic(cv, sc, 4, c)


@njit(cache=True)
def _polyline(cv: Canvas, xy: npt.NDArray[np.float64], width: int, c: U8, sc: Scratch) -> None:
    """``ImageDraw.line(xy, fill=c, width=width)`` without round joints (``draw_lines``)."""
    m = xy.shape[0]
    for i in range(m - 1):
        x0, y0 = int(xy[i, 0]), int(xy[i, 1])
        x1, y1 = int(xy[i + 1, 0]), int(xy[i + 1, 1])
        if width <= 1:
            _line(cv, x0, y0, x1, y1, c)
        else:
            _wide_line(cv, x0, y0, x1, y1, width, c, sc)
    if width <= 1 and m > 1:
        _point(cv, int(xy[m - 1, 0]), int(xy[m - 1, 1]), c)


@njit(cache=True)
def draw_shapes(
    img: U8,
    kinds: npt.NDArray[np.int64],
    starts: npt.NDArray[np.int64],
    pts: npt.NDArray[np.float64],
    colors: U8,
    widths: npt.NDArray[np.int64],
) -> None:
    """Every shape in order, as Pillow would draw them one call at a time."""
    most = 4
    for i in range(kinds.shape[0]):
        most = max(most, starts[i + 1] - starts[i])
    sc = scratch(most)
    cv = canvas(img)
    for i in range(kinds.shape[0]):
        xy = pts[starts[i] : starts[i + 1]]
        if kinds[i] == POLYGON:
            _fill_polygon(cv, xy, colors[i], sc)
        else:
            _polyline(cv, xy, widths[i], colors[i], sc)


@njit(cache=True)
def draw_packed(
    img: U8, meta: npt.NDArray[np.int64], pts: npt.NDArray[np.float64], colors: U8
) -> None:
    """:func:`draw_shapes` of a :class:`Packed` list (``meta`` rows: kind, points, width)."""
    n = meta.shape[0]
    starts = np.zeros(n + 1, np.int64)
    for i in range(n):
        starts[i + 1] = starts[i] + meta[i, 1]
    draw_shapes(img, meta[:, 0].copy(), starts, pts, colors, meta[:, 2].copy())


@njit(cache=True)
def draw_faces(img: U8, corners: npt.NDArray[np.float64], fills: U8, edge: U8, width: int) -> None:
    """Each face (``corners`` (n, 4, 2) in pixels) filled, then its closed outline: the calls
    :func:`chaingeo.pictures.raster.draw_faces` makes."""
    ring = np.empty((5, 2), np.float64)
    sc = scratch(5)
    cv = canvas(img)
    for i in range(corners.shape[0]):
        _fill_polygon(cv, corners[i], fills[i], sc)
        ring[:4] = corners[i]
        ring[4] = corners[i, 0]
        _polyline(cv, ring, width, edge, sc)


@njit(cache=True)
def rectangle(img: U8, box: npt.NDArray[np.float64], fill: U8, outline: U8, edged: bool) -> None:
    """``ImageDraw.rectangle(box, fill=fill, outline=outline)`` (width 1): corners truncated
    to ints, the rows filled end inclusive, then (``edged``: the two colours differ) the
    outline's rows and the columns between them (``ImagingDrawRectangle``)."""
    x0, y0, x1, y1 = int(box[0]), int(box[1]), int(box[2]), int(box[3])
    if y0 > y1:
        y0, y1 = y1, y0
    top, bottom = max(y0, 0), min(y1, img.shape[0])
    cv = canvas(img)
    for y in range(top, bottom + 1):
        _hline(cv, x0, y, x1, fill)
    if edged:
        _hline(cv, x0, y0, x1, outline)
        _hline(cv, x0, y1, x1, outline)
        _line(cv, x1, y0 + 1, x1, y1, outline)
        _line(cv, x0, y0 + 1, x0, y1, outline)


@njit(cache=True)
def reduce2(img: U8) -> U8:
    """``Image.reduce(2)`` of an even-sized picture: each 2x2 block's mean, rounded half up."""
    out = np.empty((img.shape[0] // 2, img.shape[1] // 2, 3), np.uint8)
    reduce2_into(img, out, 0, 0, out.shape[1], out.shape[0])
    return out


@njit(cache=True)
def reduce2_into(img: U8, out: U8, x0: int, y0: int, x1: int, y1: int) -> None:
    """:func:`reduce2` of the output rectangle ``[x0, x1) x [y0, y1)`` only, into ``out``
    (flat unsigned indices, as :func:`_hline`: about twice as fast as ``img[y, x, c]``)."""
    if x1 <= x0:
        return
    src, dst = img.reshape(img.size), out.reshape(out.size)
    row = np.uint64(img.shape[1] * 3)
    zero, one, two = np.uint64(0), np.uint64(1), np.uint64(2)
    three, six = np.uint64(3), np.uint64(6)
    for y in range(y0, y1):
        top = np.uint64(2 * y) * row + np.uint64(6 * x0)
        at = np.uint64((y * out.shape[1] + x0) * 3)
        for x in range(np.uint64(x1 - x0)):
            i, o = top + six * x, at + three * x
            for ch in (zero, one, two):
                s = (
                    np.uint16(src[i + ch])
                    + np.uint16(src[i + ch + three])
                    + np.uint16(src[i + ch + row])
                    + np.uint16(src[i + ch + row + three])
                    + np.uint16(2)
                )
                dst[o + ch] = s >> np.uint16(2)


@njit(cache=True)
def paste_mask(img: U8, mask: U8, x0: int, y0: int, c: U8) -> None:
    """``Image.paste(c, (x0, y0), mask)`` of an 8-bit mask (Pillow's ``fill_mask_L``: each
    channel blended as ``(out * (255 - m) + c * m) / 255``, rounded its way), clipped."""
    h, w = mask.shape[0], mask.shape[1]
    for my in range(max(0, -y0), min(h, img.shape[0] - y0)):
        y = y0 + my
        for mx in range(max(0, -x0), min(w, img.shape[1] - x0)):
            m = np.int64(mask[my, mx])
            x = x0 + mx
            for ch in range(3):
                t = np.int64(img[y, x, ch]) * (255 - m) + np.int64(c[ch]) * m + 128
                img[y, x, ch] = ((t >> 8) + t) >> 8


class Packed(NamedTuple):
    """Flat shapes as the arrays :func:`draw_packed` takes: packed once, drawn any number of
    times (packing a short list costs about eight times the drawing of an arrow)."""

    meta: npt.NDArray[np.int64]  # (n, 3): kind, number of points, line width
    pts: npt.NDArray[np.float64]  # (m, 2)
    colors: U8  # (n, 3)


def pack(shapes: Sequence[Flat]) -> Packed:
    """The arrays of ``shapes`` (at least one), in drawing order."""
    pts = np.concatenate([p for _, p, _, _ in shapes])
    return Packed(
        np.array([(kind, len(p), w) for kind, p, _, w in shapes], dtype=np.int64),
        pts if pts.dtype == np.float64 else pts.astype(np.float64),
        np.array([rgb for _, _, rgb, _ in shapes], dtype=np.uint8),
    )


def paint_packed(img: U8, packed: Packed | None) -> None:
    """Draw packed shapes (None: nothing)."""
    if packed is not None:
        draw_packed(img, packed.meta, packed.pts, packed.colors)


def draw_flat(img: U8, shapes: Sequence[Flat]) -> None:
    """Flat shapes drawn in one kernel call, as :func:`chaingeo.pictures.raster.draw_flat`
    would."""
    if shapes:
        paint_packed(img, pack(shapes))
