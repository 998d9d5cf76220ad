"""Colour classes that are one piece: a lit face and a shadowed face clustered apart.

Colour alone cannot tell a lit face of one piece from a piece of a look-alike colour. Motion
can: the faces of one rigid piece always stay side by side, show and hide together and move by
the same step each frame, while two pieces part as soon as one moves without the other. Two
classes are made one when, over the video, they are seen together (each seen without the other
in at most :data:`ALONE_SHARE` of their frames), side by side in nearly every frame where both
show, the same step apart in every frame where both can be followed, and moving against the
camera in at least :data:`MOVE_FRAMES` frames (two pieces at rest side by side prove nothing).
"""

from __future__ import annotations

from typing import Final

import numpy as np
import numpy.typing as npt

from chaingeo.core.arrays import Bools
from chaingeo.worldmodel.judge_segment import ColorModel, dilate
from chaingeo.worldmodel.judge_shift import FIT, NONE, MaskShift, best_shift
from chaingeo.worldmodel.judge_track import forest_root

#: Least frames both classes show in; share of the frames either shows in that the other may be
#: missing from (one face hidden behind another piece a moment).
BOTH_FRAMES: Final = 4
ALONE_SHARE: Final = 0.15
#: The faces of one piece keep their areas' ratio: its 90th percentile over the frames both
#: show in at most RATIO_SPREAD times its 10th (occlusion moves it some).
RATIO_SPREAD: Final = 2.5
#: Side by side: the pixels of one within TOUCH pixels of the other, at least TOUCH_SHARE of
#: the smaller's area, in SIDE_SHARE of the frames where both show.
TOUCH: Final = 2
TOUCH_SHARE: Final = 0.02
SIDE_SHARE: Final = 0.9
#: One step: the two classes' steps within STEP_TOL pixels in every frame where both fit; a
#: move is a step of MOVE_PX or more against the camera (the least step of any class), and it
#: takes MOVE_FRAMES of them.
STEP_TOL: Final = 2.0
MOVE_PX: Final = 3.0
MOVE_FRAMES: Final = 2


def _steps(masks: list[list[Bools]], k: int, least: int) -> list[MaskShift]:
    """Class ``k``'s best translation from each frame to the next (NONE where it is missing)."""
    out = [NONE]
    for t in range(1, len(masks)):
        a, b = masks[t - 1][k], masks[t][k]
        fits = int(a.sum()) >= least and int(b.sum()) >= least
        out.append(best_shift(a, b) if fits else NONE)
    return out


def _camera(steps: dict[int, list[MaskShift]], t: int) -> tuple[int, int]:
    """The least well-fitted step of any class at frame ``t`` (a piece at rest shows it)."""
    got = [s[t] for s in steps.values() if s[t].fit >= FIT]
    if not got:
        return 0, 0
    least = min(got, key=lambda s: s.length)
    return least.dy, least.dx


def _together(
    masks: list[list[Bools]], area: npt.NDArray[np.int64], i: int, j: int, least: int
) -> bool:
    """Whether classes ``i`` and ``j`` (``area``: per frame and class) show together and side
    by side (see the module)."""
    seen_i, seen_j = area[:, i] >= least, area[:, j] >= least
    both = np.flatnonzero(seen_i & seen_j).tolist()
    either = int((seen_i | seen_j).sum())
    if len(both) < BOTH_FRAMES or either - len(both) > ALONE_SHARE * either:
        return False
    ratio = area[both, i] / area[both, j]
    lo, hi = np.percentile(ratio, [10, 90])
    if hi > RATIO_SPREAD * lo:
        return False  # one class is also something else some of the time
    side = 0
    for t in both:
        small = min(int(area[t, i]), int(area[t, j]))
        side += int((dilate(masks[t][i], TOUCH) & masks[t][j]).sum()) >= TOUCH_SHARE * small
    return side >= SIDE_SHARE * len(both)


def _comoving(steps: dict[int, list[MaskShift]], i: int, j: int) -> bool:
    """Whether ``i`` and ``j`` take the same step wherever both fit, and move together against
    the camera in MOVE_FRAMES frames."""
    moves = 0
    for t in range(1, len(steps[i])):
        a, b = steps[i][t], steps[j][t]
        if a.fit < FIT or b.fit < FIT:
            continue
        if np.hypot(a.dy - b.dy, a.dx - b.dx) > STEP_TOL:
            return False
        cy, cx = _camera(steps, t)
        moves += bool(np.hypot(a.dy - cy, a.dx - cx) >= MOVE_PX)
    return moves >= MOVE_FRAMES


def one_piece_groups(masks: list[list[Bools]], classes: int, least: int) -> list[int]:
    """For each class, the class it is one piece with (itself when none): the lowest index of
    its group of classes that show, sit and move together."""
    area = np.array([[int(m.sum()) for m in f] for f in masks], dtype=np.int64)
    pairs = [
        (i, j)
        for i in range(classes)
        for j in range(i + 1, classes)
        if _together(masks, area.reshape(len(masks), classes), i, j, least)
    ]
    owner = list(range(classes))
    if not pairs:
        return owner
    steps = {k: _steps(masks, k, least) for k in range(classes)}
    for i, j in pairs:
        if _comoving(steps, i, j):
            ri, rj = forest_root(owner, i), forest_root(owner, j)
            owner[max(ri, rj)] = min(ri, rj)
    return [forest_root(owner, k) for k in range(classes)]


def unified(model: ColorModel, owner: list[int]) -> ColorModel:
    """``model`` with every class folded into its group's first class (named after it)."""
    keep = sorted(set(owner))
    index = {k: n for n, k in enumerate(keep)}
    remap = np.zeros(len(owner) + 1, dtype=np.uint8)
    for k, o in enumerate(owner):
        remap[k + 1] = index[o] + 1
    names = tuple(model.names[k] for k in keep)
    return ColorModel(names, model.lab[keep], remap[model.table], model.source)
