"""Existence over time from where each colour is: pixels of a piece's colour that come out of
open background (or go into it) between two frames, with no matching pixels gone (or come)
elsewhere, and that hold for :data:`HOLD` frames after a frame of rest before.

The object tracker (:mod:`chaingeo.worldmodel.judge_track`) reads changes of counts; a copy of
a piece put down against it, or a piece that jumps beside another, keeps every count. Here a
change is read from the pixels themselves: a region of a colour that was open background in
the frame before and not that colour two frames before (no flicker), away from the picture's
border (no entrance) and not covered by another piece (no disclosure), still there for HOLD
frames, is a ``duplicate`` (the colour also stays where it was) or an ``appear``; the reverse,
a region left to open background, is a ``disappear``; a region gone and one alike come far
away, the piece at rest on both sides, is a ``teleport`` (motion passes through places).
"""

from __future__ import annotations

from typing import Final

import numpy as np

from chaingeo.core.arrays import F64, Bools
from chaingeo.worldmodel.judge_segment import components, dilate, on_border
from chaingeo.worldmodel.judge_track import JUMP_SHARE, Event

#: Frames a change must hold after its first frame (its least duration).
HOLD: Final = 2
#: Share of a region that must look like the background for it to count as open ground.
OPEN: Final = 0.7
#: Share of a region its colour must keep (lose) on each frame it holds.
KEEP: Final = 0.6
#: Share of a region its colour may show two frames before a change (flicker otherwise).
FLICKER: Final = 0.2
#: Least share of the region a piece at rest still covers one frame on.
REST: Final = 0.7
#: Share of a colour's pixels within reach of its pixels a frame before, for it to be at rest.
STILL: Final = 0.9
#: Share of a region's area a colour's whole area must gain (lose) with it.
AREA: Final = 0.6
#: A region is this many times the least area at least (a sliver is no piece).
LEAST_TIMES: Final = 2


def _share(pixels: Bools, region: Bools) -> float:
    return float((pixels & region).sum()) / max(1.0, float(region.sum()))


def _centre(m: Bools) -> F64:
    out: F64 = np.argwhere(m).mean(axis=0)
    return out


class Existence:
    """The existence events of a video's per-class piece masks (``kept[t][k]``) and piece
    background pixels per frame (``ground[t]``)."""

    def __init__(
        self, kept: list[list[Bools]], ground: list[Bools], names: tuple[str, ...], least: int
    ) -> None:
        self.kept, self.ground, self.names = kept, ground, names
        shape = ground[0].shape if ground else (1, 1)
        self.reach = max(2, round(0.03 * max(shape)))
        self.least = LEAST_TIMES * least
        self.jump = JUMP_SHARE * max(shape)
        self.grown: list[list[Bools]] = []

    def events(self) -> list[Event]:
        out: list[Event] = []
        n = len(self.kept)
        grown = [[dilate(m, self.reach) for m in frame] for frame in self.kept]
        self.grown = grown
        for b in range(2, n - HOLD):  # a change seen whole: steady before, held after
            for k in range(len(self.names)):
                if not (self._rest(k, b - 1) and self._rest(k, b + 1)):
                    continue  # a change between two frames of rest, not within a motion
                came = components(self.kept[b][k] & ~grown[b - 1][k], self.least)
                went = components(self.kept[b - 1][k] & ~grown[b][k], self.least)
                out.extend(self._at(b, k, came, went))
        return out

    def _rest(self, k: int, t: int) -> bool:
        """Whether colour ``k`` stands still from frame ``t - 1`` to ``t`` (each frame's
        pixels within reach of the other's): a change from rest is no motion."""
        if t < 1:
            return True
        a, b = self.kept[t - 1][k], self.kept[t][k]
        ga, gb = self.grown[t - 1][k], self.grown[t][k]
        return (not b.any() or _share(ga, b) >= STILL) and (not a.any() or _share(gb, a) >= STILL)

    def _area_moved(self, k: int, b: int, by: int) -> bool:
        """Whether colour ``k``'s whole area changed by ``by`` (most of it) from frame
        ``b - 1`` on, for HOLD frames: a piece gained or lost, not one moved into view."""
        was = int(self.kept[b - 1][k].sum())
        for u in range(b, min(len(self.kept), b + HOLD + 1)):
            d = int(self.kept[u][k].sum()) - was
            if (d < AREA * by) if by > 0 else (d > AREA * by):
                return False
        return True

    def _held(self, region: Bools, k: int, b: int, present: bool) -> bool:
        """Whether ``region`` shows (or not) colour ``k`` from frame ``b`` for HOLD frames."""
        for u in range(b + 1, min(len(self.kept), b + HOLD + 1)):
            s = _share(self.kept[u][k], region)
            if (s < KEEP) if present else (s > 1 - KEEP):
                return False
        return True

    def _steady(self, region: Bools, k: int, b: int, present: bool) -> bool:
        """Whether frame ``b - 2`` shows ``region`` as frame ``b - 1`` does (no flicker)."""
        if b < 2:
            return True
        s = _share(self.kept[b - 2][k], region)
        return s >= REST if present else s <= FLICKER

    def _left_from(self, c: Bools, went: list[Bools], k: int, b: int) -> Bools | None:
        """The place colour ``k`` left, far from ``c``, in the frame ``c`` came out of open
        ground, the colour steady there before: one piece, so the one that appeared is the one
        that left (a teleport), whatever its old place shows now (a piece it hid, partly)."""
        for g in went:
            far = float(np.hypot(*(_centre(c) - _centre(g)))) >= self.jump
            if far and self._steady(g, k, b, True):
                return g
        return None

    def _at(self, b: int, k: int, came: list[Bools], went: list[Bools]) -> list[Event]:
        out: list[Event] = []
        name = self.names[k]
        for c in list(came):
            pair = [g for g in went if min(c.sum(), g.sum()) >= 0.4 * max(c.sum(), g.sum())]
            if not pair:
                continue
            g = pair[0]
            came = [x for x in came if x is not c]
            went = [x for x in went if x is not g]
            if on_border(c) or on_border(g) or not self._held(c, k, b, True):
                continue  # motion in or out through the border
            far = float(np.hypot(*(_centre(c) - _centre(g)))) >= self.jump
            if far and self._steady(g, k, b, True) and _share(self.ground[b], g) >= OPEN:
                detail = f"the {name} piece jumped to another place between two frames"
                out.append(Event("teleport", b, name, None, detail, (g, c)))
        came = [c for c in came if not on_border(c) and self._held(c, k, b, True)]
        went = [g for g in went if not on_border(g) and self._held(g, k, b, False)]
        for c in came:
            if _share(self.ground[b - 1], c) < OPEN or not self._steady(c, k, b, False):
                continue
            if not self._area_moved(k, b, int(c.sum())):
                continue
            stays = self.kept[b][k] & self.kept[b - 1][k] & ~dilate(c, self.reach)
            left = self._left_from(c, went, k, b)
            if left is not None:
                went = [g for g in went if g is not left]
                detail = f"the {name} piece jumped to another place between two frames"
                out.append(Event("teleport", b, name, None, detail, (left, c)))
            elif int(stays.sum()) >= self.least:
                detail = f"a second {name} piece appeared in open view beside the first"
                out.append(Event("duplicate", b, name, None, detail, (c,), before=0))
            else:
                detail = f"a {name} piece appeared in open view, away from the border"
                out.append(Event("appear", b, name, None, detail, (c,), before=0))
        for g in went:
            if _share(self.ground[b], g) < OPEN or not self._steady(g, k, b, True):
                continue
            if not self._area_moved(k, b, -int(g.sum())):
                continue
            detail = f"the {name} piece vanished in open view"
            out.append(Event("disappear", b, name, None, detail, (g,)))
        return out


def join(events: list[Event], more: list[Event], near: int = 3) -> list[Event]:
    """``events`` with those of ``more`` that no event of the same piece and kind within
    ``near`` frames already says."""
    out = list(events)
    for e in more:
        if not any(o.piece == e.piece and o.kind == e.kind and abs(o.frame - e.frame) <= near
                   for o in out):  # fmt: skip
            out.append(e)
    return sorted(out, key=lambda e: (e.frame, e.kind, e.piece))
