"""Gradual recolour: a piece whose colour slides toward another piece's over several frames.

The tracker reads identity from colour classes, and a colour in the middle of its slide from
one class to another belongs to neither, or flips class half way while another piece moves
elsewhere (what the tracker takes for that piece coming over this one). Here a piece is
watched where it lies: the median chromaticity (r, g) of its pixels, which shading leaves
alone, frame by frame. A recolour moves that median along the straight line from the piece's
colour to another class's (a blend of two colours lies on the line between their
chromaticities) and keeps every pixel of the piece near the median (the whole piece changes
at once); another piece sliding over it or revealed behind it instead splits the pixels in
two groups, one of each colour, and a highlight moves them toward white, off the line.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Final

import numpy as np
import numpy.typing as npt

from chaingeo.core.arrays import F64, U8, Bools
from chaingeo.worldmodel.judge_segment import dilate, on_border
from chaingeo.worldmodel.judge_track import Event, Obj


@dataclass(frozen=True)
class DriftRule:
    """The thresholds of a slide (chromaticity in (r, g) units, progress from 0, the old
    colour, to 1, the new).

    A slide is looked for over ``window`` frames, with at least ``middle`` frames in its
    middle, and its end must hold for ``held`` frames (unless the piece moves off its place: a
    merged piece moves on with the other). ``start``, ``middle_range`` and ``end`` are the
    progress that counts as the start, the middle and the end. A median lies at most
    ``off_line`` from the line between the two colours; at least ``together`` of a piece's
    pixels lie within ``spread`` (progress) of the median on each frame; at least ``cover`` of
    the region still shows a bright piece (not the ground) on every frame; two colours closer
    than ``apart`` are not told apart. A pixel's chromaticity is used when its brightest
    channel reaches ``bright``, its channel spread ``saturated`` of that, and it lies
    ``ground`` from the ground's chromaticity.
    """

    window: int = 14
    middle: int = 1
    held: int = 2
    start: float = 0.15
    middle_range: tuple[float, float] = (0.2, 0.8)
    end: float = 0.8
    off_line: float = 0.04
    together: float = 0.7
    spread: float = 0.25
    cover: float = 0.8
    apart: float = 0.08
    bright: int = 45
    saturated: float = 0.15
    ground: float = 0.04


RULE: Final = DriftRule()


def chromaticities(frame: U8) -> tuple[F64, Bools]:
    """(r, g) per pixel, and whether the pixel can be a piece's: bright and saturated enough
    for a reliable chromaticity, and away from the ground's (the median of the picture's
    border): a piece moving off shows the ground, which lies between two complementary
    colours on the line joining them."""
    f = frame.astype(np.float64)
    total = f.sum(axis=2) + 1e-9
    out = np.stack([f[..., 0] / total, f[..., 1] / total], axis=-1)
    hi, lo = f.max(axis=2), f.min(axis=2)
    ring = np.concatenate([out[:2].reshape(-1, 2), out[-2:].reshape(-1, 2),
                           out[:, :2].reshape(-1, 2), out[:, -2:].reshape(-1, 2)])  # fmt: skip
    ground = np.median(ring, axis=0)
    away = np.hypot(out[..., 0] - ground[0], out[..., 1] - ground[1]) >= RULE.ground
    ok: Bools = (hi >= RULE.bright) & (hi - lo >= RULE.saturated * hi) & away
    return out, ok


def class_centres(chroma: list[F64], bright: list[Bools], objects: list[list[Obj]], n: int) -> F64:
    """Each class's median chromaticity over its objects' bright pixels (NaN: never seen)."""
    out = np.full((n, 2), np.nan)
    for k in range(n):
        got = [c[o.mask & b] for c, b, objs in zip(chroma, bright, objects, strict=True)
               for o in objs if o.cls == k]  # fmt: skip
        if got and sum(len(g) for g in got):
            out[k] = np.median(np.concatenate(got), axis=0)
    return out


class Drift:
    """Gradual recolours of a video's objects (see the module docstring)."""

    def __init__(self, frames: list[U8], objects: list[list[Obj]], names: tuple[str, ...]) -> None:
        pairs = [chromaticities(f) for f in frames]
        self.chroma = [c for c, _ in pairs]
        self.bright = [b for _, b in pairs]
        self.objects, self.names = objects, names
        self.centres = class_centres(self.chroma, self.bright, objects, len(names))

    def events(self) -> list[Event]:
        out: list[Event] = []
        done: dict[int, int] = {}
        for b in range(1, len(self.objects) - 2):
            for p in self.objects[b - 1]:
                if done.get(p.cls, -1) >= b or on_border(p.mask):
                    continue
                ev = self._slide(p, b)
                if ev is not None:
                    out.append(ev)
                    done[p.cls] = ev.until
        return out

    def _pixels(self, idx: npt.NDArray[np.intp], t: int) -> F64 | None:
        """The chromaticities of the bright pixels ``idx`` (flat) at frame ``t``; None when
        fewer than ``cover`` of them are bright (the piece left, or the ground shows)."""
        ok = self.bright[t].ravel()[idx]
        if ok.sum() < RULE.cover * len(idx):
            return None
        out: F64 = self.chroma[t].reshape(-1, 2)[idx[ok]]
        return out

    def _slide(self, p: Obj, b: int) -> Event | None:
        region = p.mask & ~dilate(~p.mask, 1)
        a = self.centres[p.cls]
        if region.sum() < 12 or np.isnan(a).any():
            return None
        idx = np.flatnonzero(region)
        last = min(len(self.objects) - 1, b + RULE.window)
        seen = [self._pixels(idx, t) for t in range(b - 1, last + 1)]
        far = [x is not None and float(np.hypot(*(np.median(x, axis=0) - a))) > RULE.apart / 2
               for x in seen]  # fmt: skip
        if seen[0] is None or not any(far):
            return None
        for j in range(len(self.names)):
            d = self.centres[j] - a
            if j == p.cls or np.isnan(d).any() or float(np.hypot(*d)) < RULE.apart:
                continue
            got = _slid([_progress(x, a, d) for x in seen])
            if got is not None:
                first, end = b - 1 + got[0], b - 1 + got[1]
                name, other = self.names[p.cls], self.names[j]
                detail = f"the {name} piece turned {other} gradually, frames {first} to {end}"
                return Event("recolour", first, name, other, detail, (p.mask, region), last=end)
        return None


def _progress(px: F64 | None, a: F64, d: F64) -> tuple[float, float, float]:
    """Median progress of chromaticities ``px`` from ``a`` along ``d``, the median distance
    off that line, and the share of pixels within ``spread`` of the median (NaN: no pixels)."""
    if px is None:
        return np.nan, np.nan, 0.0
    c = px - a
    along = c @ d / float(d @ d)
    off = np.abs(c @ np.array([-d[1], d[0]])) / float(np.hypot(*d))
    m = float(np.median(along))
    return m, float(np.median(off)), float((np.abs(along - m) <= RULE.spread).mean())


def _slid(rows: list[tuple[float, float, float]]) -> tuple[int, int] | None:
    """The first and last rows of a slide (None: no slide): the first row at the start, then
    rows in the middle for at least ``middle`` frames (all on the line, pixels together, never
    going back by more than ``spread``), ending at ``end``, held for ``held`` more frames (or
    until the piece leaves its place)."""
    if not rows or not (rows[0][0] <= RULE.start and rows[0][1] <= RULE.off_line):
        return None
    middle, best, first = 0, rows[0][0], 0
    for i, (m, off, together) in enumerate(rows[1:], start=1):
        if np.isnan(m) or off > RULE.off_line or together < RULE.together or m < best - RULE.spread:
            return None
        best = max(best, m)
        if m <= RULE.start:
            first = i
        if m >= RULE.end:
            held = all(np.isnan(x[0]) or x[0] >= RULE.end for x in rows[i + 1 : i + 1 + RULE.held])
            return (first + 1, i) if held and middle >= RULE.middle else None
        if RULE.middle_range[0] <= m <= RULE.middle_range[1]:
            middle += 1
        elif m < RULE.middle_range[0] and middle:
            return None
    return None
