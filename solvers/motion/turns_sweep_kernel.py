"""Exact quarter-turn sweeps in int64 (numba): the one stencil table, and the test for cells
beyond it. The reference it must equal is :mod:`chaingeo.core.turns`.

The question is :func:`chaingeo.core.turns.square_hit`'s: does unit square ``s``, turning
counter-clockwise through 90 degrees about O, overlap fixed unit square ``f`` (doubled
coordinates relative to O)? The argument is the same (the swept arc against ``f``'s arc at one
test radius between consecutive critical radii), decided here with int64 arithmetic only: in
quadrupled units a test point is ``(k, +-sqrt(h))`` with ``|k| <= 2 (S + 1)`` and
``h <= 8 (S + 1)^2`` for coordinates ``|.| <= S``, and every comparison squares products of two
such numbers, at most ``64 (S + 1)^4``: exact for ``S`` up to 1.5 :data:`FAR_LIMIT`. No floats.
(The reference stays the independent Python computation the tests compare against.)

A square's stencil (the squares it sweeps) depends only on where it stands relative to the axis
and on the sense, never on where the pieces are: one table for ``|s| <= BOUND`` serves every state
of every search. Cells further from the axis (pieces wandered apart) are tested pairwise against
the fixed cells of their own slice, so neither memory nor the table grows with how far pieces
wander.
"""

from __future__ import annotations

from functools import cache
from typing import NamedTuple

import numpy as np

from chaingeo.core.arrays import I64
from chaingeo.core.turns import edge_roots
from chaingeo.kernels.jit import njit

#: Stencils cover relative positions up to this (doubled units, both coordinates): every cell of
#: a 12-cell-wide part, about any centre in its box.
BOUND = 24
#: Doubled distances from the axis up to which the int64 arithmetic here is exact (see the module
#: docstring: a cell within this of the axis only ever meets fixed cells within 1.5 times it).
FAR_LIMIT = 8192


@njit(cache=True)
def rmin2(x: int, y: int) -> int:
    """Squared distance from O to the nearest point of square ``(x, y)`` (doubled units)."""
    dx = 0 if x - 1 <= 0 <= x + 1 else min(abs(x - 1), abs(x + 1))
    dy = 0 if y - 1 <= 0 <= y + 1 else min(abs(y - 1), abs(y + 1))
    return dx * dx + dy * dy


@njit(cache=True)
def rmax2(x: int, y: int) -> int:
    """Squared distance from O to the furthest point of square ``(x, y)`` (doubled units)."""
    return (abs(x) + 1) ** 2 + (abs(y) + 1) ** 2


@njit(cache=True)
def _sign(c: int, e: int) -> int:
    if c == 0 or e == 0:
        return 0
    return 1 if c > 0 else -1


@njit(cache=True)
def _sign_sum(c1: int, e1: int, c2: int, e2: int) -> int:
    """Sign of ``c1 sqrt(e1) + c2 sqrt(e2)``, exactly (squares compared when signs differ)."""
    sa = _sign(c1, e1)
    sb = _sign(c2, e2)
    if sa == 0:
        return sb
    if sb == 0 or sa == sb:
        return sa
    ma = c1 * c1 * e1
    mb = c2 * c2 * e2
    if ma > mb:
        return sa
    if mb > ma:
        return sb
    return 0


@njit(cache=True)
def _cross(p: I64, q: I64) -> int:
    """Sign of the cross product of points ``(cx, ex, cy, ey)`` = ``(cx sqrt ex, cy sqrt ey)``."""
    return _sign_sum(p[0] * q[2], p[1] * q[3], -p[2] * q[0], p[3] * q[1])


@njit(cache=True)
def _dot(p: I64, q: I64) -> int:
    return _sign_sum(p[0] * q[0], p[1] * q[1], p[2] * q[2], p[3] * q[3])


@njit(cache=True)
def _half(base: I64, w: I64) -> int:
    c = _cross(base, w)
    return 0 if c > 0 or (c == 0 and _dot(base, w) > 0) else 1


@njit(cache=True)
def _compare(base: I64, p: I64, q: I64) -> int:
    """Order of ``p`` and ``q`` by counter-clockwise angle from ``base`` in [0, 360)."""
    hp = _half(base, p)
    hq = _half(base, q)
    if hp != hq:
        return -1 if hp < hq else 1
    return -_cross(p, q)


#: The reference's own crossing test, compiled (inlined where it is called).
_edge_roots = njit(cache=True, inline="always")(edge_roots)


@njit(cache=True)
def _on_circle(x: int, y: int, m: int, out: I64) -> int:
    """Write into ``out`` the points where the circle of squared radius ``m`` (quadrupled units)
    crosses the edges of square ``(x, y)``; return how many."""
    n = 0
    for i in range(2):
        s_i = x if i == 0 else y
        s_o = y if i == 0 else x
        for k in (2 * s_i - 2, 2 * s_i + 2):
            roots = _edge_roots(m, k, 2 * s_o - 2, 2 * s_o + 2)
            h = m - k * k
            for j in range(2):
                if roots >> j & 1:
                    sign = 1 - 2 * j
                    if i == 0:
                        out[n, 0], out[n, 1], out[n, 2], out[n, 3] = k, 1, sign, h
                    else:
                        out[n, 0], out[n, 1], out[n, 2], out[n, 3] = sign, h, k, 1
                    n += 1
    return n


@njit(cache=True)
def _extremes(pts: I64, n: int) -> tuple[int, int]:
    """Rows of the clockwise-most and counter-clockwise-most points (within 90 degrees)."""
    first = -1
    last = -1
    for i in range(n):
        is_first = first < 0
        is_last = last < 0
        for j in range(n):
            is_first = is_first and _cross(pts[i], pts[j]) >= 0
            is_last = is_last and _cross(pts[j], pts[i]) >= 0
        if is_first:
            first = i
        if is_last:
            last = i
    return first, last


@njit(cache=True)
def _arcs_overlap(sx: int, sy: int, fx: int, fy: int, m: int) -> bool:
    """At squared radius ``m`` (quadrupled units, between critical radii): does the arc swept
    by ``s`` overlap ``f``'s arc?"""
    ps = np.empty((8, 4), dtype=np.int64)
    pf = np.empty((8, 4), dtype=np.int64)
    a_s, b_s = _extremes(ps, _on_circle(sx, sy, m, ps))
    a_f, b_f = _extremes(pf, _on_circle(fx, fy, m, pf))
    end = np.empty(4, dtype=np.int64)  # b_s turned by +90 degrees
    end[0], end[1], end[2], end[3] = -ps[b_s, 2], ps[b_s, 3], ps[b_s, 0], ps[b_s, 1]
    if _compare(ps[a_s], pf[a_f], end) < 0:
        return True
    return _compare(ps[a_s], pf[b_f], pf[a_f]) < 0 and _compare(ps[a_s], ps[a_s], pf[b_f]) < 0


@njit(cache=True)
def _critical(x: int, y: int, out: I64, n: int) -> int:
    """Append square ``(x, y)``'s critical squared radii (corners, edge lines) to ``out``."""
    for dx in (-1, 1):
        for dy in (-1, 1):
            out[n] = (x + dx) ** 2 + (y + dy) ** 2
            n += 1
    if y - 1 <= 0 <= y + 1:
        out[n] = (x - 1) ** 2
        out[n + 1] = (x + 1) ** 2
        n += 2
    if x - 1 <= 0 <= x + 1:
        out[n] = (y - 1) ** 2
        out[n + 1] = (y + 1) ** 2
        n += 2
    return n


@njit(cache=True)
def square_hit(sx: int, sy: int, fx: int, fy: int) -> bool:
    """Does square ``s`` turning +90 degrees about O overlap square ``f`` (interiors)? Doubled
    coordinates relative to O, of one parity class, within 1.5 :data:`FAR_LIMIT`."""
    if sx == fx and sy == fy:
        return True
    if sx == 0 and sy == 0:
        return rmin2(fx, fy) < 2
    if fx == 0 and fy == 0:
        return rmin2(sx, sy) < 2
    lo = max(rmin2(sx, sy), rmin2(fx, fy))
    hi = min(rmax2(sx, sy), rmax2(fx, fy))
    if lo >= hi:
        return False  # no common open range of radii
    raw = np.empty(16, dtype=np.int64)
    n = _critical(fx, fy, raw, _critical(sx, sy, raw, 0))
    cuts = np.empty(18, dtype=np.int64)
    cuts[0] = lo
    cuts[1] = hi
    k = 2
    for i in range(n):
        if lo < raw[i] < hi:
            cuts[k] = raw[i]
            k += 1
    cuts = np.sort(cuts[:k])
    prev = cuts[0]
    for i in range(1, k):
        if cuts[i] == prev:
            continue
        if _arcs_overlap(sx, sy, fx, fy, 2 * (prev + cuts[i])):
            return True
        prev = cuts[i]
    return False


@njit(cache=True)
def turn_hit(su: int, sv: int, fu: int, fv: int, sense: int) -> bool:
    """:func:`square_hit` for sense 0 (+90) or 1 (-90: the mirror image, v -> -v)."""
    if sense == 0:
        return square_hit(su, sv, fu, fv)
    return square_hit(su, -sv, fu, -fv)


@njit(cache=True)
def swept_through(moving: I64, fixed: I64, axis: int, sense: int, centre2: I64) -> I64:
    """Which ``fixed`` cells (rows 1, else 0) some ``moving`` cell sweeps through turning about
    the line through doubled ``centre2`` parallel to ``axis`` (sense 0: +90, 1: -90): the exact
    pair test within each slice. Coordinates relative to the axis within :data:`FAR_LIMIT`."""
    u = (axis + 1) % 3
    v = (axis + 2) % 3
    out = np.zeros(fixed.shape[0], dtype=np.int64)
    for j in range(fixed.shape[0]):
        fu = 2 * fixed[j, u] - centre2[u]
        fv = 2 * fixed[j, v] - centre2[v]
        for i in range(moving.shape[0]):
            if moving[i, axis] == fixed[j, axis] and turn_hit(
                2 * moving[i, u] - centre2[u], 2 * moving[i, v] - centre2[v], fu, fv, sense
            ):
                out[j] = 1
                break
    return out


@njit(cache=True)
def _push(cells: I64, total: int, x: int, y: int) -> I64:
    """``cells`` with row ``total`` set to ``(x, y)`` (grown by doubling when full)."""
    if total == cells.shape[0]:
        grown = np.empty((2 * total, 2), dtype=np.int64)
        grown[:total] = cells
        cells = grown
    cells[total, 0] = x
    cells[total, 1] = y
    return cells


@njit(cache=True)
def build_stencils(bound: int) -> tuple[I64, I64, I64]:
    """``(start, end, cells)``: ``cells[start[k, i, j]:end[k, i, j]]`` are the squares
    (relative to the axis) that square ``(i - bound, j - bound)`` sweeps turning +90 (``k`` 0) or
    -90 (``k`` 1). Only squares with ``x > 0, y >= 0`` (and the one on the axis) are computed:
    the others are those turned by quarter turns, and -90 is the mirror image (v -> -v)."""
    w = 2 * bound + 1
    start = np.zeros((2, w, w), dtype=np.int64)
    end = np.zeros((2, w, w), dtype=np.int64)
    cells = np.empty((1024, 2), dtype=np.int64)
    total = 0
    for i in range(bound, w):
        for j in range(bound, w):
            sx = i - bound
            sy = j - bound
            if (sx - sy) % 2 != 0 or (sx == 0 and sy > 0):
                continue  # not a square of either lattice, or not in the quadrant
            reach = int(np.sqrt(rmax2(sx, sy))) + 2
            first = -reach - 2 if (reach - sx) % 2 == 0 else -reach - 3  # sx's parity
            start[0, i, j] = total
            for fx in range(first, reach + 1, 2):
                for fy in range(first, reach + 1, 2):
                    if square_hit(sx, sy, fx, fy):
                        cells = _push(cells, total, fx, fy)
                        total += 1
            end[0, i, j] = total
    for i in range(w):
        for j in range(w):
            x = i - bound
            y = j - bound
            if (x - y) % 2 != 0 or (x > 0 and y >= 0) or (x == 0 and y == 0):
                continue
            k = 0
            while not (x > 0 and y >= 0):  # turn back into the quadrant
                x, y = y, -x
                k += 1
            a = start[0, x + bound, y + bound]
            start[0, i, j] = total
            for e in range(a, end[0, x + bound, y + bound]):
                fx, fy = cells[e, 0], cells[e, 1]
                for _ in range(k):
                    fx, fy = -fy, fx
                cells = _push(cells, total, fx, fy)
                total += 1
            end[0, i, j] = total
    out = np.empty((2 * total, 2), dtype=np.int64)
    out[:total] = cells[:total]
    for i in range(w):
        for j in range(w):
            if (i - j) % 2 != 0:
                continue
            m = 2 * bound - j  # the mirror image of (i - bound, j - bound)
            a = start[0, i, m]
            n = end[0, i, m] - a
            start[1, i, j] = total + a
            end[1, i, j] = total + a + n
            for e in range(n):
                out[total + a + e, 0] = cells[a + e, 0]
                out[total + a + e, 1] = -cells[a + e, 1]
    return start, end, out


class StencilArrays(NamedTuple):
    """The stencil table as the turn kernels take it (:func:`build_stencils`, and its
    ``bound``)."""

    start: I64
    end: I64
    cells: I64
    bound: int


class Stencils:
    """The stencil table (:func:`build_stencils`) for relative positions within ``bound``."""

    def __init__(self, bound: int) -> None:
        self.bound = bound
        self.start, self.end, self.cells = build_stencils(bound)
        self.arrays = StencilArrays(self.start, self.end, self.cells, bound)


@cache
def stencils() -> Stencils:
    """The one table every turn kernel uses (built once per process, a few hundred KB)."""
    return Stencils(BOUND)
