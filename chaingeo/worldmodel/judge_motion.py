"""Motion read from silhouettes alone: teleports and pass-throughs, no level needed.

Each colour's pixels are laid on the next frame's by the translation that best fits them
(cross-correlation of the two masks): a rigid piece keeps its silhouette while it moves, so a
good fit gives its displacement per frame.

``teleport``: a displacement far beyond what the piece did just before and just after (its own
speed, which holds camera motion too), with the silhouette kept: motion, however fast, passes
through places, and our own videos ease every move in and out.

``pass_through``: where the silhouettes of two pieces both lie, each pixel shows the nearer of
the two. Rigid pieces that do not meet keep their depth order there: a pixel inside both
silhouettes in two frames shows the same piece in both, except where a piece's own fold sweeps
by. A pixel that turns from one piece to the other while it stays inside both silhouettes means
the two surfaces crossed in depth there: one piece moved through the other. The moving piece's
silhouette is laid by whole-pixel steps, so a pixel of its edge is uncertain; the other's is its
own pixels; and turned pixels count in blobs two pixels across (ragged colour edges turn single
pixels). Pixels of no colour and no ground (dark edges, blends) first go to the colour next to
them (:func:`filled`), or the edge between two colours eats the band that turns. Flips on
:data:`FLIP_FRAMES` frames within :data:`FLIP_WINDOW` of a motion make the event (one frame's
flips are a misreading); a silhouette cut by the picture's border is not read. A crossing
hidden behind other pieces, or along the line of sight, shows nothing here: only the level's
geometry decides it. Nor does a crossing whose cut moves with the moving piece (a face sliding
into a face along a lattice axis, as drawn with a depth buffer): a notched piece sliding past
another draws the same pixels.
"""

from __future__ import annotations

from typing import Final

import numpy as np

from chaingeo.core.arrays import Bools
from chaingeo.worldmodel.judge_segment import dilate, erode, on_border
from chaingeo.worldmodel.judge_shift import FIT, NONE, MaskShift, Shift, best_shift, moved
from chaingeo.worldmodel.judge_track import Event

#: Least jump (share of the frame's longer side), and how many times the piece's own speed
#: just before and after must go into the jump less the mean of those two steps.
JUMP_MIN: Final = 0.05
JUMP_RATIO: Final = 2.0
#: Speed (pixels a frame) below which a piece counts as still when bounding a jump.
JUMP_FLOOR: Final = 2.0
#: Least area ratio of a silhouette across a jump (occlusion may change what shows of it).
JUMP_AREA: Final = 0.3
#: Share of the place a piece left (or took) that a moving piece covering it makes the change
#: an occlusion, not a jump.
COVERED: Final = 0.25
#: Frames of past silhouettes laid together (by their displacements) as a piece's full shape:
#: two whole-pixel steps err by a pixel at most, which MOVER_EDGE takes off (over three, a
#: notched piece's silhouette smeared into its notch and the piece seen through it flipped).
HISTORY: Final = 2
#: A pass-through: within FLIP_WINDOW frames, FLIP_FRAMES frames with flips over FLIP_SHARE of
#: the least area each, and FLIP_TOTAL of it in all (a single frame's flips are misreadings;
#: a notched piece's fold sweeping past another, over a smeared silhouette, turns less than
#: twice the least area; chosen on the tuning seeds).
FLIP_WINDOW: Final = 8
FLIP_SHARE: Final = 0.05
FLIP_FRAMES: Final = 4
FLIP_TOTAL: Final = 2.0
#: Erosion (pixels) of the moving colour's silhouette before a pixel counts as inside it: the
#: rounding of HISTORY whole-pixel steps.
MOVER_EDGE: Final = 1
#: Steps (one pixel each) by which each colour takes the pixels next to it that are neither a
#: colour nor ground, in strips narrower than 2 EDGE + 1 pixels, before pass-throughs are read:
#: a piece's dark edges, a moving edge's blend. The band where one piece cuts into another is a
#: few pixels wide, and an unclaimed edge between the two colours would eat it. Wider dark
#: regions are faces in shade, which a neighbour taking them would flip as it slides past them
#: (on the tuning seeds, filling those too caught more crossings but raised clean clips' alarms
#: threefold).
FILL: Final = 3
EDGE: Final = 2

#: A window's flipped frames and its flips in all.
Window = tuple[list[int], int]


def _share(pixels: Bools, region: Bools) -> float:
    return float((pixels & region).sum()) / max(1.0, float(region.sum()))


def _thick(m: Bools) -> Bools:
    """``m`` opened by a 2x2 square: one-pixel slivers go (two colours' edge jittering by a
    pixel, anti-aliasing), while a surface sweeping through another turns a band at least
    its step wide. (Eroding the silhouettes instead, as before, erased the crossings of thin
    arms and of faces whose hidden side is never seen, both common in burrs.)"""
    core = m[:-1, :-1] & m[1:, :-1] & m[:-1, 1:] & m[1:, 1:]
    out = np.zeros_like(m)
    out[:-1, :-1] |= core
    out[1:, :-1] |= core
    out[:-1, 1:] |= core
    out[1:, 1:] |= core
    return out


def filled(frame: list[Bools], ground: Bools, steps: int = FILL) -> list[Bools]:
    """A frame's colour masks, each grown by ``steps`` one-pixel steps into the pixels of no
    colour and no ground that lie in strips narrower than 2 EDGE + 1 pixels; a pixel two
    colours reach in the same step stays unclaimed."""
    out = [m.copy() for m in frame]
    if not out:
        return out
    free = ~ground & ~np.logical_or.reduce(out)
    edges = free & ~dilate(erode(free, EDGE), EDGE)
    for _ in range(steps):
        claims = [dilate(m, 1) & edges for m in out]
        once = np.sum(claims, axis=0) == 1
        for m, c in zip(out, claims, strict=True):
            m |= c & once
        edges &= ~np.logical_or.reduce(out)
    return out


def pass_throughs(
    kept: list[list[Bools]], grounds: list[Bools], names: tuple[str, ...], least: int
) -> list[Event]:
    """The pass-throughs of :class:`SilhouetteMotion` over the colour masks :func:`filled`."""
    solid = [filled(f, g) for f, g in zip(kept, grounds, strict=True)]
    return SilhouetteMotion(solid, names, least).pass_throughs()


def _rank(w: Window | None) -> tuple[int, int]:
    return (-1, -1) if w is None else (len(w[0]), w[1])


class SilhouetteMotion:
    """The per-frame steps of each colour of ``kept[t][k]`` (a class's piece pixels), and the
    motion events they show."""

    def __init__(self, kept: list[list[Bools]], names: tuple[str, ...], least: int) -> None:
        self.kept, self.names, self.least = kept, names, least
        shape = kept[0][0].shape if kept and kept[0] else (1, 1)
        self.side = max(shape)
        self.area = [[int(m.sum()) for m in frame] for frame in kept]
        n, c = len(kept), len(names)
        self.steps: list[list[MaskShift]] = [[NONE] * c]
        for t in range(1, n):
            row = []
            for k in range(c):
                if self.area[t - 1][k] < least or self.area[t][k] < least:
                    row.append(NONE)
                else:
                    p = self.steps[-1][k]
                    prior = (p.dy, p.dx) if p.fit >= FIT else (0, 0)
                    row.append(best_shift(kept[t - 1][k], kept[t][k], prior))
            self.steps.append(row)
        self._shapes: dict[tuple[int, int], Bools] = {}

    def events(self) -> list[Event]:
        return self.teleports() + self.pass_throughs()

    # -- teleports ----------------------------------------------------------------------------

    def _spike(self, k: int, b: int) -> tuple[float, float] | None:
        """Colour ``k``'s step at frame ``b`` less the mean of its steps just before and just
        after (what smooth motion, eased or not, would have done), and the larger of those
        two; None when a neighbouring frame lacks the colour or fits badly (undecidable)."""
        if not 2 <= b < len(self.kept) - 1:
            return None
        s, p, q = self.steps[b][k], self.steps[b - 1][k], self.steps[b + 1][k]
        if p.fit < FIT or q.fit < FIT:
            return None
        off = np.hypot(s.dy - (p.dy + q.dy) / 2, s.dx - (p.dx + q.dx) / 2)
        return float(off), max(p.length, q.length)

    def teleports(self) -> list[Event]:
        out: list[Event] = []
        for k, name in enumerate(self.names):
            for b in range(2, len(self.kept) - 1):
                s = self.steps[b][k]
                if s.fit < FIT or s.length < JUMP_MIN * self.side:
                    continue
                a, c = self.area[b - 1][k], self.area[b][k]
                if min(a, c) < JUMP_AREA * max(a, c):
                    continue
                was, now = self.kept[b - 1][k], self.kept[b][k]
                if on_border(was) or on_border(now):
                    continue
                spike = self._spike(k, b)
                if spike is None or spike[0] < JUMP_RATIO * max(spike[1], JUMP_FLOOR):
                    continue
                if self._covered(k, b):
                    continue
                detail = (
                    f"the {name} piece jumped {s.length:.0f} px between two frames "
                    f"(at most {spike[1]:.0f} px a frame just before and after)"
                )
                out.append(Event("teleport", b, name, None, detail, (was, now)))
        return out

    def _camera(self, t: int) -> Shift:
        """The camera's step at frame ``t``: the least step of the well-fitted colours (a
        piece at rest shows it)."""
        got = [s for s in self.steps[t] if s.fit >= FIT]
        if not got:
            return (0, 0)
        still = min(got, key=lambda s: (s.length, s.dy, s.dx))
        return (still.dy, still.dx)

    def _mover(self, j: int, t: int) -> bool:
        """Whether colour ``j`` moves against the camera at frame ``t`` (or cannot be followed)."""
        s = self.steps[t][j]
        if s.fit < FIT:
            return True
        cy, cx = self._camera(t)
        return bool(np.hypot(s.dy - cy, s.dx - cx) > JUMP_FLOOR)

    def _covered(self, k: int, b: int) -> bool:
        """Whether the place colour ``k`` left at frame ``b`` is now under a moving piece, or
        the place it took was under one a frame before: an occluder passed, the piece did not
        jump."""
        was, now = self.kept[b - 1][k], self.kept[b][k]
        left, took = was & ~now, now & ~was
        for j in range(len(self.names)):
            if j == k:
                continue
            if not (self._mover(j, b) or self._mover(j, min(b + 1, len(self.kept) - 1))):
                continue
            hid = _share(self.kept[b][j], left) >= COVERED
            if hid or _share(self.kept[b - 1][j], took) >= COVERED:
                return True
        return False

    # -- pass-throughs ------------------------------------------------------------------------

    def _shape(self, k: int, t: int) -> Bools:
        """Colour ``k``'s full silhouette at frame ``t``: its pixels of HISTORY frames on each
        side laid where they are at ``t`` by the steps between (parts hidden at ``t`` but seen
        before or after add up), along well-fitted steps only."""
        key = (k, t)
        if key in self._shapes:
            return self._shapes[key]
        out = self.kept[t][k].copy()
        dy = dx = 0
        for u in range(t, max(0, t - HISTORY), -1):
            s = self.steps[u][k]
            if s.fit < FIT:
                break
            dy, dx = dy + s.dy, dx + s.dx
            out |= moved(self.kept[u - 1][k], dy, dx)
        dy = dx = 0
        for u in range(t + 1, min(len(self.kept), t + 1 + HISTORY)):
            s = self.steps[u][k]
            if s.fit < FIT:
                break
            dy, dx = dy - s.dy, dx - s.dx
            out |= moved(self.kept[u][k], dy, dx)
        self._shapes[key] = out
        return out

    def flips(self, k: int, j: int, t: int) -> tuple[int, Bools]:
        """Pixels inside both silhouettes in frames ``t - 1`` and ``t`` that turn from one of
        the two colours to the other, in blobs two pixels across or more (:func:`_thick`).
        The silhouette of the colour moving against the camera is eroded by MOVER_EDGE (it is
        laid by whole-pixel steps); the other's is its own pixels, unshifted."""
        mover = k if self._off_camera(k, t) >= self._off_camera(j, t) else j
        inside = np.ones_like(self.kept[t][k])
        for u in (t - 1, t):
            for q in (k, j):
                shape = self._shape(q, u)
                inside &= erode(shape, MOVER_EDGE) if q == mover else shape
        a0, a1 = self.kept[t - 1][k], self.kept[t][k]
        b0, b1 = self.kept[t - 1][j], self.kept[t][j]
        turned = _thick(inside & ((a0 & b1) | (b0 & a1)))
        return int(turned.sum()), turned

    def _off_camera(self, k: int, t: int) -> float:
        s, (cy, cx) = self.steps[t][k], self._camera(t)
        return float(np.hypot(s.dy - cy, s.dx - cx))

    def _apart(self, k: int, j: int, t: int) -> bool:
        """Whether colours ``k`` and ``j`` both follow well and step differently at frame
        ``t``: only pieces moving against each other can cross in depth (a still scene's
        flicker, or a camera drift that moves both alike, cannot)."""
        a, b = self.steps[t][k], self.steps[t][j]
        return a.fit >= FIT and b.fit >= FIT and (a.dy, a.dx) != (b.dy, b.dx)

    def pass_throughs(self) -> list[Event]:
        out: list[Event] = []
        c = len(self.names)
        for k in range(c):
            for j in range(k + 1, c):
                out.extend(self._pair(k, j))
        return out

    def _pair(self, k: int, j: int) -> list[Event]:
        """Windows of FLIP_WINDOW frames, while one of colours ``k`` and ``j`` moves, with
        flips on FLIP_FRAMES of them and FLIP_TOTAL of the least area in all; overlapping
        windows are one event, dated by the one with the most flipped frames."""
        empty = np.zeros_like(self.kept[0][k])
        counts, turned = [0], [empty]
        for t in range(1, len(self.kept)):
            n, m = 0, empty
            if self._readable(k, j, t):
                n, m = self.flips(k, j, t)
            counts.append(n)
            turned.append(m)
        windows: list[Window | None] = [None]
        windows += [self._window(counts, s) for s in range(1, len(counts))]
        out: list[Event] = []
        s = 1
        while s < len(counts):
            if windows[s] is None:
                s += 1
                continue
            # of the windows overlapping this one, the one with the most flipped frames (then
            # the most flips): a stray flip just before a crossing does not date it
            near = range(s, min(len(counts), s + FLIP_WINDOW))
            best = max(near, key=lambda u: _rank(windows[u]))
            got = windows[best]
            assert got is not None  # it ranks as high as the window from s, which qualifies
            on, total = got
            out.append(self._event(k, j, on, total, turned[on[0]]))
            s = best + FLIP_WINDOW
        return out

    def _window(self, counts: list[int], s: int) -> Window | None:
        """The flipped frames and the flips of the window from frame ``s``, if they make an
        event: FLIP_FRAMES frames over FLIP_SHARE of the least area, FLIP_TOTAL of it in all."""
        w = range(s, min(len(counts), s + FLIP_WINDOW))
        on = [t for t in w if counts[t] >= FLIP_SHARE * self.least]
        total = sum(counts[t] for t in w)
        if len(on) < FLIP_FRAMES or total < FLIP_TOTAL * self.least:
            return None
        return on, total

    def _readable(self, k: int, j: int, t: int) -> bool:
        """Whether frame ``t``'s flips between colours ``k`` and ``j`` can be read: both show,
        move against each other (:meth:`_apart`), and keep off the picture's border in this
        frame and the one before (a piece entering or leaving the picture has a silhouette its
        history cannot lay whole)."""
        if min(self.area[t][k], self.area[t][j]) < self.least or not self._apart(k, j, t):
            return False
        return not any(on_border(self.kept[u][q]) for u in (t - 1, t) for q in (k, j))

    def _event(self, k: int, j: int, on: list[int], total: int, turned: Bools) -> Event:
        """The pass-through over frames ``on``: named for the piece that travelled further,
        with both silhouettes before and at its first frame and the pixels that turned."""
        first, last = on[0], on[-1]
        mover = k if self._travel(k, first, last) >= self._travel(j, first, last) else j
        still = j if mover == k else k
        a, b = self.names[mover], self.names[still]
        detail = (
            f"the {a} piece moved through the {b} piece: {total} px inside both silhouettes "
            f"turned from one to the other over frames {first}-{last}"
        )
        f = first
        masks = (
            self.kept[f - 1][mover],
            self.kept[f - 1][still],
            self.kept[f][mover],
            self.kept[f][still],
            turned,
        )
        return Event("pass_through", first, a, b, detail, masks, before=2, last=last)

    def _travel(self, k: int, first: int, last: int) -> float:
        dy = sum(self.steps[u][k].dy for u in range(first, last + 1))
        dx = sum(self.steps[u][k].dx for u in range(first, last + 1))
        return float(np.hypot(dy, dx))
