"""Pieces tracked over a video's frames, and the changes no rigid piece can make.

Per frame, each colour class's components are grouped into objects: two components of one
colour are one piece seen round an occluder when the straight gap between their nearest points
is mostly covered by other pieces (a beam behind a crossing beam shows as two parts); a gap of
background between them is a break. Objects are compared frame to frame by the overlap of
their (slightly grown) masks.

Temporal smoothing: a class's object count is median-filtered over :data:`WINDOW` frames, so a
single noisy frame changes nothing; an identity change must persist for :data:`PERSIST` frames.
A piece that enters or leaves through the picture's border is not a violation (our own videos
carry removed pieces out of the picture), and a piece that disappears behind another, which
keeps its area, is reported as undecided rather than lost.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Final

import numpy as np

from chaingeo.core.arrays import F64, Bools
from chaingeo.worldmodel.judge_gap import gap_covered
from chaingeo.worldmodel.judge_segment import close, components, dilate, on_border
from chaingeo.worldmodel.judge_shift import FIT, best_shift, moved

#: Frames of the median filter over object counts (odd), and frames an identity change must
#: hold.
WINDOW: Final = 5
PERSIST: Final = 3
#: Frames a vanished piece's place may take to settle on its new colour (a blend passes
#: through others on the way).
SETTLE: Final = 3
#: Pixels a piece at rest may seem to move by between frames (camera drift, blur), and the
#: share of a vanished piece's area the pieces around it may change by and still be at rest.
DRIFT: Final = 2
STILL_SHARE: Final = 0.2
#: Furthest move (share of the frame's longer side) of a piece between two frames.
FAST_SHARE: Final = 0.25
#: Frames after which a piece's place is looked at again for another colour.
LAGS: Final = (2, 6, 11)
#: Another colour that moved took a piece's place by moving over it when its own step lays
#: its earlier pixels on this share of what it took; past OVER_LAG frames one step cannot be
#: followed (the silhouette changes as the piece turns, hides and shows), so it is assumed.
OVER_EXPLAINED: Final = 0.5
OVER_LAG: Final = 6
#: Least jump of a teleport (share of the frame's longer side).
JUMP_SHARE: Final = 0.1
#: Growth (share of the frame's longer side) of a mask when matching across one frame.
MOTION_SHARE: Final = 0.03


@dataclass(frozen=True, eq=False)
class Obj:
    """One piece as seen in one frame: its colour class (0-based), pixels and parts. Objects
    compare by identity: two of one colour are two pieces however alike (and masks have no
    truth value to compare by)."""

    cls: int
    mask: Bools
    parts: int

    @property
    def area(self) -> int:
        return int(self.mask.sum())

    def touches_border(self) -> bool:
        return on_border(self.mask)


@dataclass(frozen=True)
class Event:
    """A change between frames ``frame - 1`` and ``frame``: a violation kind (disappear, appear,
    split, merge, recolour), or a note (entered, left, hidden)."""

    kind: str
    frame: int
    piece: str
    other: str | None = None
    detail: str = ""
    masks: tuple[Bools, ...] = field(default=(), compare=False, repr=False)
    #: How many of ``masks`` (the first ones) are seen in frame ``frame - 1``; the rest in
    #: ``frame``.
    before: int = 1
    #: The last frame the change shows in (None: ``frame`` alone).
    last: int | None = None

    @property
    def until(self) -> int:
        return self.frame if self.last is None else self.last


VIOLATIONS: Final = (
    "disappear",
    "appear",
    "recolour",
    "split",
    "merge",
    "duplicate",
    "teleport",
    "pass_through",
)


def _centroid(mask: Bools) -> F64:
    out: F64 = np.argwhere(mask).mean(axis=0)
    return out


def forest_root(group: list[int], i: int) -> int:
    """The root of ``i`` in a union-find forest of parent indices."""
    while group[i] != i:
        i = group[i]
    return i


def solid_of(masks: list[Bools]) -> Bools:
    """Every piece pixel of a frame, closed so that the drawn edges between two pieces of
    different colours count as piece, not background."""
    solid = np.zeros_like(masks[0]) if masks else np.zeros((1, 1), bool)
    for m in masks:
        solid |= m
    return close(solid)


def frame_objects(
    masks: list[Bools],
    min_area: int,
    occluders: Bools | None = None,
    unknown: Bools | None = None,
) -> tuple[list[Obj], Bools]:
    """Objects of one frame (each class's components grouped across occluders), and the
    frame's piece pixels (:func:`solid_of`) with ``occluders`` (a box's wire frame drawn over
    the pieces), which hide pieces as pieces do; ``unknown`` pixels (neither a piece's colour
    nor the background's) join two parts of a colour as an occluder would, and count for
    nothing else."""
    solid = solid_of(masks if occluders is None else [*masks, occluders])
    out: list[Obj] = []
    for k, mask in enumerate(masks):
        comps = components(mask, min_area)
        group = list(range(len(comps)))
        others = (solid if unknown is None else solid | unknown) & ~mask
        for i in range(len(comps)):
            for j in range(i + 1, len(comps)):
                ri, rj = forest_root(group, i), forest_root(group, j)
                if ri != rj and gap_covered(comps[i], comps[j], others):
                    group[rj] = ri
        for r in sorted({forest_root(group, i) for i in range(len(comps))}):
            members = [c for i, c in enumerate(comps) if forest_root(group, i) == r]
            out.append(Obj(k, np.logical_or.reduce(members), len(members)))
    return out, solid


def _counts(frames: list[list[Obj]], classes: int) -> np.ndarray:
    c = np.zeros((len(frames), classes), dtype=np.int64)
    for t, objs in enumerate(frames):
        for o in objs:
            c[t, o.cls] += 1
    return c


def smoothed_counts(raw: np.ndarray) -> np.ndarray:
    """Median of each class's count over WINDOW frames (clipped at the ends)."""
    n = len(raw)
    half = WINDOW // 2
    out = np.empty_like(raw)
    for t in range(n):
        out[t] = np.median(raw[max(0, t - half) : min(n, t + half + 1)], axis=0).round()
    return out


class Tracker:
    """Finds the events of a sequence of per-frame objects (see the module docstring)."""

    def __init__(self, frames: list[tuple[list[Obj], Bools]], names: tuple[str, ...]) -> None:
        self.frames = [objs for objs, _ in frames]
        self.solid = [solid for _, solid in frames]
        self.names = names
        shape = self.solid[0].shape if self.solid else (1, 1)
        self.reach = max(2, round(MOTION_SHARE * max(shape)))
        self.raw = _counts(self.frames, len(names))
        self.smooth = smoothed_counts(self.raw)

    def _of(self, t: int, k: int) -> list[Obj]:
        return [o for o in self.frames[t] if o.cls == k]

    def _change_frame(self, t: int, k: int) -> int:
        """The raw frame pair nearest ``t`` where class ``k``'s count makes the smoothed step."""
        old, new = self.smooth[t - 1, k], self.smooth[t, k]
        for d in (0, -1, 1, -2, 2):
            b = t + d
            if 1 <= b < len(self.frames) and self.raw[b - 1, k] == old and self.raw[b, k] == new:
                return b
        return t

    def events(self) -> list[Event]:
        out: list[Event] = []
        for t in range(1, len(self.frames)):
            for k in range(len(self.names)):
                if self.smooth[t, k] == self.smooth[t - 1, k]:
                    continue
                b = self._change_frame(t, k)
                if self.smooth[t, k] > self.smooth[t - 1, k]:
                    out.extend(self._more(b, k))
                else:
                    out.extend(self._fewer(b, k))
        out.extend(self._swaps())
        out.extend(self._jumps())
        for e in self._identity():
            if not any(
                o.piece == e.piece
                and o.kind in ("recolour", "merge")
                and abs(o.frame - e.frame) <= 3
                for o in out
            ):
                out.append(e)
        return sorted(out, key=lambda e: (e.frame, e.kind, e.piece))

    def _class_pixels(self, t: int, k: int) -> Bools:
        out = np.zeros_like(self.solid[t])
        for o in self._of(t, k):
            out |= o.mask
        return out

    def _identity(self) -> list[Event]:
        """Recolours and merges, abrupt or gradual: a piece at rest whose place shows another
        colour LAGS frames later (and still two frames after), its own colour nowhere near, while
        that other colour changed nowhere else (the other piece did not move over it)."""
        out: list[Event] = []
        seen: set[str] = set()
        n = len(self.frames)
        for b in range(2, n):
            for p in self.frames[b - 1]:
                name = self.names[p.cls]
                if name in seen or p.touches_border() or not self._resting(p, b - 2):
                    continue
                if _share(self._class_pixels(b, p.cls), p.mask) >= 0.8:
                    continue  # still its colour in the next frame: nothing starts here
                ev = self._changed(p, b)
                if ev is not None:
                    seen.add(name)
                    out.append(ev)
        return out

    def _went_elsewhere(self, p: Obj, b: int, t: int) -> bool:
        """Whether ``p``'s colour kept its area by frame ``t`` (the piece moved away and what
        it hid shows now) or reached the border on the way (carried out)."""
        area = [int(self._class_pixels(u, p.cls).sum()) for u in (b - 1, t)]
        border = any(o.touches_border() for u in range(b - 1, t + 1) for o in self._of(u, p.cls))
        return border or area[1] > area[0] - 0.6 * p.area

    def _changed(self, p: Obj, b: int) -> Event | None:
        """The recolour of ``p`` (seen at frame ``b - 1``) read LAGS frames on, if any; dated at
        the first frame the new colour covers half its place (a piece passing over it may have
        dimmed its colour a few frames before)."""
        n = len(self.frames)
        for lag in LAGS:
            t = b + lag
            if t + 2 >= n:
                return None
            if any(_share(self._class_pixels(u, p.cls), dilate(p.mask, self.reach)) > 0.2
                   for u in (t, t + 2)):  # fmt: skip
                continue
            if self._went_elsewhere(p, b, t):
                return None
            for j in range(len(self.names)):
                if j == p.cls:
                    continue
                now = [self._class_pixels(u, j) for u in (t, t + 2)]
                was = self._class_pixels(b - 1, j)
                if min(_share(m, p.mask) for m in now) < 0.6 or _share(was, p.mask) > 0.2:
                    continue
                if self._came_over(p, j, (was, now[0]), (b, t)):
                    continue
                name, other = self.names[p.cls], self.names[j]
                # beside a piece of the new colour it reads as fused: still a recolour, as the
                # piece keeps its place (a merge moves on with the other)
                joined = bool((dilate(p.mask, 2) & was).any())
                kind = "recolour"
                how = "turned (as if fused into)" if joined else "turned"
                detail = f"the {name} piece {how} {other} over {lag} frames"
                first = next(
                    u for u in range(b, t + 1) if _share(self._class_pixels(u, j), p.mask) >= 0.5
                )
                return Event(kind, first, name, other, detail, (p.mask, now[0]), last=t)
        return None

    def _came_over(
        self, p: Obj, j: int, pixels: tuple[Bools, Bools], frames: tuple[int, int]
    ) -> bool:
        """Whether colour ``j`` (its ``pixels`` in frames ``b - 1`` and ``t``, ``frames`` being
        ``(b, t)``) took ``p``'s place by moving over it: it changed elsewhere too (by 0.3 of
        ``p``'s area, outside ``p``), and its own step lays its earlier pixels on
        OVER_EXPLAINED of what it took, or cannot be read (a lag past OVER_LAG, a poor fit, a
        piece at the picture's border, which shows in part)."""
        (was, now), (b, t) = pixels, frames
        ring = ~dilate(p.mask, 3)
        if float((now & ring ^ was & ring).sum()) <= 0.3 * p.area:
            return False
        if t - b > OVER_LAG or any(
            o.touches_border() for u in range(b - 1, t + 1) for o in self._of(u, j)
        ):
            return True
        step = best_shift(was, now)
        if step.fit < FIT:
            return True
        took = now & p.mask
        laid = dilate(moved(was, step.dy, step.dx), 1) & took
        return bool(laid.sum() >= OVER_EXPLAINED * took.sum())

    def _jumps(self) -> list[Event]:
        """Teleports: a piece at rest in one place, then at rest in another JUMP_SHARE of the
        frame or more away, with no frame between (motion, however fast, passes through
        places; our own videos ease every move in and out)."""
        out: list[Event] = []
        for b in range(1, len(self.frames)):
            for k in range(len(self.names)):
                before, now = self._of(b - 1, k), self._of(b, k)
                gone = [p for p in before if not self._touching(p, now) and not p.touches_border()]
                new = [c for c in now if not self._touching(c, before) and not c.touches_border()]
                for p in gone:
                    far = [c for c in new if _alike(p, c) and self._jump(p, c)]
                    if far and self._resting(p, b - 2) and self._resting(far[0], b + 1):
                        new.remove(far[0])
                        name = self.names[k]
                        detail = f"the {name} piece jumped to another place between two frames"
                        out.append(Event("teleport", b, name, None, detail, (p.mask, far[0].mask)))
        return out

    def _jump(self, p: Obj, c: Obj) -> bool:
        d = float(np.hypot(*(_centroid(c.mask) - _centroid(p.mask))))
        return bool(d >= JUMP_SHARE * max(p.mask.shape))

    def _resting(self, o: Obj, t: int) -> bool:
        """Whether frame ``t`` shows ``o``'s colour where ``o`` is (half of it, or more), or
        ``t`` is outside the video."""
        if not 0 <= t < len(self.frames):
            return True
        return any(_overlaps(x, o) for x in self._of(t, o.cls))

    def _touching(self, a: Obj, objs: list[Obj]) -> list[Obj]:
        grown = dilate(a.mask, self.reach)
        return [o for o in objs if (grown & o.mask).any()]

    def _against_others(self, c: Obj, t: int) -> bool:
        """Whether a part borders other pieces (so it may have come out from behind one)."""
        ring = dilate(c.mask, 2) & ~c.mask
        others = self.solid[t] & ~np.logical_or.reduce([o.mask for o in self._of(t, c.cls)])
        return float((ring & others).sum()) >= 0.15 * max(1, int(ring.sum()))

    def _more(self, b: int, k: int) -> list[Event]:
        before, now = self._of(b - 1, k), self._of(b, k)
        name = self.names[k]
        for p in before:
            hit = self._touching(p, now)
            if len(hit) >= 2:
                masks = (p.mask, *[h.mask for h in hit])
                if self._under_others(p.mask, hit, b):
                    detail = f"part of the {name} piece went behind another piece"
                    return [Event("hidden", b, name, None, detail, masks)]
                detail = f"one {name} piece became {len(hit)} separate parts (background between)"
                return [Event("split", b, name, None, detail, masks)]
        out: list[Event] = []
        unmatched = [p for p in before if not self._touching(p, now)]
        for c in now:
            if self._touching(c, before):
                continue
            fast = [p for p in unmatched if self._fast_move(p, c)]
            if fast:
                unmatched.remove(fast[0])
                out.append(Event("moved", b, name, None, "moved further than one frame's reach"))
                continue
            if c.touches_border() or self._from_border(k, b) or self._heading_out(c, b, 1):
                out.append(Event("entered", b, name, None, "came in through the border"))
                continue
            gone = [
                o
                for o in self.frames[b - 1]
                if o.cls != k
                and not self._touching(o, self._of(b, o.cls))
                and (self._carried(o, b - 1) & c.mask).sum() >= 0.5 * min(o.area, c.area)
            ]
            if gone:
                other = self.names[gone[0].cls]
                detail = f"the {other} piece turned {name}"
                out.append(Event("recolour", b, other, name, detail, (gone[0].mask, c.mask)))
            elif self._against_others(c, b):
                detail = f"a {name} part came into sight beside another piece"
                out.append(Event("revealed", b, name, None, detail))
            elif any(self._touching(o, before) for o in now if o is not c):
                detail = f"a second {name} piece appeared in open view beside the first"
                out.append(Event("duplicate", b, name, None, detail, (c.mask,), before=0))
            else:
                detail = f"a {name} piece appeared in open view, away from the border"
                out.append(Event("appear", b, name, None, detail, (c.mask,), before=0))
        return out

    def _carried(self, o: Obj, t: int) -> Bools:
        """``o`` (seen at frame ``t``) and where it is one step further along its own motion
        (its centroid's step from frame ``t - 1``, when the piece kept its area): a piece
        that changes colour while it moves shows the new colour there."""
        was = [x for x in self._of(t - 1, o.cls) if (dilate(x.mask, self.reach) & o.mask).any()]
        if t < 1 or len(was) != 1 or not _alike(was[0], o):
            return o.mask
        dy, dx = np.round(_centroid(o.mask) - _centroid(was[0].mask)).astype(int).tolist()
        return _translated(o.mask, dy, dx) | o.mask

    def _fast_move(self, p: Obj, c: Obj) -> bool:
        """Whether ``c`` may be ``p`` moved fast: alike in area, within FAST_SHARE of the
        frame (a piece matched nowhere before and one matched nowhere now)."""
        d = _centroid(c.mask) - _centroid(p.mask)
        far = float(np.hypot(*d)) <= FAST_SHARE * max(p.mask.shape)
        return far and _alike(p, c)

    def _from_border(self, k: int, b: int) -> bool:
        """Whether a piece of class ``k`` touched the border a frame or two before ``b``: one
        carried in at speed (our videos bring pieces in fast) is past the reach of one frame."""
        return any(o.touches_border() for t in (b - 1, b - 2) if t >= 0 for o in self._of(t, k))

    def _under_others(self, whole: Bools, parts: list[Obj], t: int) -> bool:
        """Whether what ``whole`` has beyond ``parts`` lies, at frame ``t``, mostly on other
        pieces: the parts are one piece seen round an occluder, not a break or a fusion."""
        rest = whole & ~dilate(np.logical_or.reduce([o.mask for o in parts]), 1)
        if not rest.any():
            return False
        own = np.zeros_like(rest)
        for o in self._of(t, parts[0].cls):
            own |= o.mask
        return float((rest & self.solid[t] & ~own).sum()) >= 0.5 * float(rest.sum())

    def _fewer(self, b: int, k: int) -> list[Event]:
        before, now = self._of(b - 1, k), self._of(b, k)
        name = self.names[k]
        for c in now:
            hit = self._touching(c, before)
            if len(hit) >= 2 and c.parts == 1:
                masks = (*[h.mask for h in hit], c.mask)
                if self._under_others(c.mask, hit, b - 1):
                    detail = f"a hidden part of the {name} piece came into sight"
                    return [Event("revealed", b, name, None, detail, masks)]
                detail = f"{len(hit)} separate {name} parts fused into one"
                return [Event("merge", b, name, name, detail, masks, before=len(hit))]
        out = [self._vanished(p, b) for p in before if not self._touching(p, now)]
        # a recolour is reported by the new class, unless the new colour's piece just grew
        return [replace(e, kind="recolour") if e.kind == "fused" else e for e in out
                if e.kind != "recolour"]  # fmt: skip

    def _vanished(self, p: Obj, b: int) -> Event:
        name = self.names[p.cls]
        if p.touches_border() or self._heading_out(p, b - 1):
            return Event("left", b, name, None, "went out through the border")
        if self._shrinking(p, b - 1) and self._against_others(p, b - 1):
            detail = f"the {name} piece shrank out of sight beside another piece"
            return Event("hidden", b, name, None, detail, (p.mask,))
        u = self._settled(p, b)
        if float((self.solid[u] & p.mask).sum()) < 0.5 * p.area:
            return Event(
                "disappear", b, name, None, f"the {name} piece vanished in open view", (p.mask,)
            )
        others = [o for o in self.frames[u] if o.cls != p.cls]
        if not others:
            return Event("hidden", b, name, None, f"the {name} piece shrank out of sight")
        cover = max(others, key=lambda o: int((o.mask & p.mask).sum()))
        other = self.names[cover.cls]
        was = [o for o in self.frames[b - 1] if o.cls == cover.cls]
        was_there = [o for o in was if (dilate(o.mask, self.reach) & cover.mask).any()]
        if not was_there:
            return Event("recolour", b, name, other, f"the {name} piece turned {other}")
        grew = cover.area - sum(o.area for o in was_there)
        if grew >= 0.7 * p.area and not self._of(u, p.cls):
            # the pixels took the other piece's colour; whether the two then move as one is
            # not seen here, so it is named for what shows
            detail = f"the {name} piece turned {other}, joined to the {other} piece (+{grew} px)"
            return Event("fused", b, name, other, detail, (p.mask, cover.mask))
        if self._resting(p, b - 2) and self._still_around(p, b, u):
            detail = f"the {name} piece vanished at rest (what it hid shows in its place)"
            return Event("disappear", b, name, None, detail, (p.mask,))
        detail = f"the {name} piece went out of sight behind the {other} piece"
        return Event("hidden", b, name, other, detail, (p.mask, cover.mask))

    def _still_around(self, p: Obj, b: int, u: int) -> bool:
        """Whether the pieces covering ``p``'s place at frame ``u`` kept their pixels beyond
        it from frame ``b - 1`` (within a camera's drift): nothing came in front of ``p``, so
        what shows there was behind it (to go behind a piece at rest, ``p`` must move)."""
        place = dilate(p.mask, 2)
        over = [o for o in self.frames[u] if o.cls != p.cls and (o.mask & p.mask).any()]
        if not over:
            return False
        changed = 0
        for k in {o.cls for o in over}:
            now, was = self._class_pixels(u, k) & ~place, self._class_pixels(b - 1, k) & ~place
            changed += int((now & ~dilate(was, DRIFT)).sum() + (was & ~dilate(now, DRIFT)).sum())
        return changed < STILL_SHARE * p.area

    def _settled(self, p: Obj, b: int) -> int:
        """The frame from ``b`` on (within SETTLE) where ``p``'s place shows what it turned
        into: a colour blended gradually passes through colours (or none) for a frame or two,
        which the tracker's smoothing never reports. Skipped: frames where no piece covers the
        place, or a colour that shows neither before ``b`` nor two frames later covers it."""
        last = len(self.frames) - 1
        for u in range(b, min(b + SETTLE, last + 1)):
            c = self._cover(p, u)
            if c is not None and (self._of(b - 1, c) or self._of(min(u + 2, last), c)):
                return u
        return b

    def _cover(self, p: Obj, u: int) -> int | None:
        """The class of the other piece covering half of ``p``'s place (grown by a frame's
        reach: it may move on at once) at frame ``u``; None if none does."""
        place = dilate(p.mask, self.reach)
        best = max(self.frames[u], key=lambda o: int((o.mask & place).sum()), default=None)
        if best is None or best.cls == p.cls or (best.mask & place).sum() < 0.5 * p.area:
            return None
        return best.cls

    def _shrinking(self, p: Obj, t: int) -> bool:
        """Whether ``p`` (seen at frame ``t``) is under half the area its colour showed near it
        within WINDOW frames before: it was going behind something, not deleted in view."""
        near = dilate(p.mask, 2 * self.reach)
        seen = [
            o.area
            for u in range(max(0, t - WINDOW), t)
            for o in self._of(u, p.cls)
            if (o.mask & near).any()
        ]
        return bool(seen) and p.area < 0.5 * max(seen)

    def _heading_out(self, p: Obj, t: int, step: int = -1) -> bool:
        """Whether ``p`` (seen at frame ``t``) moves fast enough to be out of the picture two
        frames later (our videos carry removed pieces out at speed); with ``step`` 1, two
        frames earlier (carried in at speed)."""
        if not 0 <= t + step < len(self.frames):
            return False
        other = self._of(t + step, p.cls)
        if not other:
            return False
        here = _centroid(p.mask)
        d = here - min(
            (_centroid(o.mask) for o in other), key=lambda c: float(((here - c) ** 2).sum())
        )
        ys, xs = np.nonzero(p.mask)
        h, w = p.mask.shape
        lo = np.array([ys.min(), xs.min()]) + 2 * d
        hi = np.array([ys.max(), xs.max()]) + 2 * d
        return bool(hi[0] < 0 or hi[1] < 0 or lo[0] >= h or lo[1] >= w)

    def _swaps(self) -> list[Event]:
        """Identity changes that keep every count: a colour now where another colour was,
        nowhere near where it was itself, for PERSIST frames."""
        out: list[Event] = []
        for b in range(1, len(self.frames) - PERSIST + 1):
            if not np.array_equal(self.raw[b - 1], self.raw[b]):
                continue
            for k in range(len(self.names)):
                ev = self._swap_at(b, k)
                if ev is not None and not any(e.piece == ev.piece for e in out):
                    out.append(ev)
        return out

    def _swap_at(self, b: int, k: int) -> Event | None:
        before, now = self._of(b - 1, k), self._of(b, k)
        if len(now) != 1 or len(before) != 1:
            return None
        c, was = now[0], before[0]
        if (c.mask & was.mask).sum() >= 0.2 * c.area:
            return None
        for o in self.frames[b - 1]:
            near = dilate(o.mask, self.reach)  # the other piece may be moving
            if o.cls == k or (near & c.mask).sum() < 0.5 * min(c.area, o.area):
                continue
            # mutual: where this piece was now shows the other colour, moved off its own place
            partner = [x for x in self._of(b, o.cls) if _overlaps(x, was)]
            if len(partner) != 1 or (partner[0].mask & o.mask).sum() >= 0.2 * partner[0].area:
                continue
            if not (_alike(c, o) and _alike(partner[0], was)):
                continue  # a swap of colours keeps both silhouettes; a reveal changes them
            later = [self._of(b + d, k) for d in range(1, PERSIST)]
            if all(len(x) == 1 and (x[0].mask & was.mask).sum() < 0.2 * x[0].area for x in later):
                other = self.names[o.cls]
                detail = f"the {other} piece now shows as {self.names[k]} (and the reverse)"
                return Event("recolour", b, other, self.names[k], detail, (o.mask, c.mask))
        return None


def _translated(mask: Bools, dy: int, dx: int) -> Bools:
    """``mask`` moved by (dy, dx), what leaves the picture dropped."""
    h, w = mask.shape
    out = np.zeros_like(mask)
    if abs(dy) < h and abs(dx) < w:
        src = mask[max(0, -dy) : h - max(0, dy), max(0, -dx) : w - max(0, dx)]
        out[max(0, dy) : max(0, dy) + src.shape[0], max(0, dx) : max(0, dx) + src.shape[1]] = src
    return out


def _alike(a: Obj, b: Obj) -> bool:
    """Areas within a factor of two (one silhouette seen twice, not a piece and a sliver)."""
    return min(a.area, b.area) >= 0.5 * max(a.area, b.area)


def _share(pixels: Bools, region: Bools) -> float:
    """The share of ``region`` that ``pixels`` cover."""
    return float((pixels & region).sum()) / max(1.0, float(region.sum()))


def _overlaps(a: Obj, b: Obj) -> bool:
    """At least half of the smaller of two objects lies on the other."""
    return bool((a.mask & b.mask).sum() >= 0.5 * min(a.area, b.area))
