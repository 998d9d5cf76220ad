"""Motion through another piece, where it is decidable: a video drawn by our own camera.

Our videos use one known orthographic camera (the iso view of :mod:`chaingeo.pictures.scene`), so
only its scale and offset are unknown; they are fitted on the first frame, whose pieces must
stand assembled (a disassembly level's start, the reference image a video model is given): the
silhouette of every piece together spans exactly the projected corners of the level's cells.
Then each piece's translation (along one lattice axis at a time, in quarter cells between
steps) is tracked by silhouette: the scene is drawn as a label image for a candidate pose and
compared with the segmented frame, near the last pose first and anywhere along the three axes
when that fails (a jump). Every change of pose is checked with the kinematics: the unit
positions a piece passes through must be free of the pieces that did not move with it (a
slide through another piece collides at a whole position on either side of it).

What cannot be checked this way is said in ``undecided``: a level that starts apart, a first
frame that is not our camera's, a piece that turns or leaves the lattice.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Final

import numpy as np
import numpy.typing as npt
from PIL import Image, ImageDraw

from chaingeo.core.arrays import F64, U8, Bools
from chaingeo.pictures.raster import Camera, visible_faces
from chaingeo.pictures.scene import CAMERAS
from chaingeo.worldmodel.judge_segment import dilate
from chaingeo.worldmodel.judge_track import Event

if TYPE_CHECKING:
    from chaingeo.core.level import Level

#: The first frame must agree with our drawing of the level this well (mean IoU per piece), and
#: the two scale estimates (width, height) within this share, for the camera to count as known.
MIN_FIT_IOU: Final = 0.6
MAX_SCALE_MISMATCH: Final = 0.06
#: Agreement lost before a piece is searched for; a best fit below LOST_IOU means the piece
#: turned or left the lattice (no longer followed); a move is checked when its fit reaches
#: SURE_IOU.
SLACK: Final = 0.06
LOST_IOU: Final = 0.5
SURE_IOU: Final = 0.85
#: A piece's drawn silhouette agrees with the seen one at least this well for a change of its
#: parts to be read as occlusion.
EXPLAIN_IOU: Final = 0.7
#: Frames on either side of a move during which another piece must stay put to be an obstacle.
STILL_FRAMES: Final = 4
#: Candidate offsets near the last pose (cells, along one axis).
NEAR: Final = tuple(float(d) for d in np.arange(-2.0, 2.01, 0.25) if abs(d) > 1e-9)


@dataclass(frozen=True)
class _Piece:
    """One piece's visible faces alone (camera plane corners, depth of each face's centre)."""

    label: int
    corners: F64  # (n, 4, 2)
    depth: F64  # (n,)
    cells: npt.NDArray[np.int64]


def _pieces(level: Level, cam: Camera) -> list[_Piece]:
    out = []
    v = np.array(cam.toward_viewer)
    for i, p in enumerate(level.pieces):
        cells = np.asarray(p.shape.voxels, dtype=np.int64)
        faces = visible_faces(cells, np.zeros((len(cells), 3)), cam)
        depth = (faces.cells + 0.5) @ v
        out.append(_Piece(i + 1, faces.corners, depth, cells))
    return out


class _PoseScene:
    """Draws label images of the pieces at translations, with the fitted camera."""

    def __init__(self, pieces: list[_Piece], cam: Camera, shape: tuple[int, int]) -> None:
        self.pieces = pieces
        self.right, self.up = np.array(cam.right), np.array(cam.up)
        self.v = np.array(cam.toward_viewer)
        self.shape = shape
        self.scale, self.origin = 1.0, np.zeros(2)
        # every face of every piece in one array, in piece order (the order ties keep)
        self._corners = np.concatenate([p.corners for p in pieces])
        self._depth = np.concatenate([p.depth for p in pieces])
        self._owner = np.repeat(np.arange(len(pieces)), [len(p.depth) for p in pieces])
        self._shifts: dict[tuple[float, ...], tuple[float, float, float]] = {}

    def fit(self, solid: Bools) -> float:
        """Scale and offset from the bounding box of ``solid``; the relative mismatch of the
        two scale estimates."""
        every = np.concatenate([p.corners.reshape(-1, 2) for p in self.pieces])
        ys, xs = np.nonzero(solid)
        w, h = np.ptp(every[:, 0]), np.ptp(every[:, 1])
        sx, sy = (xs.max() + 1 - xs.min()) / w, (ys.max() + 1 - ys.min()) / h
        self.scale = float(sx + sy) / 2
        self.origin = np.array(
            [xs.min() - every[:, 0].min() * self.scale, ys.min() + every[:, 1].max() * self.scale]
        )
        return abs(float(sx - sy)) / self.scale

    def agreement(self, seen: U8) -> list[float]:
        """IoU per piece of the assembled drawing with ``seen``."""
        drawn = self.draw(np.zeros((len(self.pieces), 3)))
        return [_iou(drawn == p.label, seen == p.label) for p in self.pieces]

    def refine(self, seen: U8) -> list[float]:
        """Scale and offset nudged (coordinate-wise, twice) to agree best with ``seen``; the
        agreement per piece."""
        best = self.agreement(seen)
        for _ in range(2):
            for which, deltas in (
                ("s", (-0.02, -0.01, 0.01, 0.02)),
                ("x", (-1.0, 1.0)),
                ("y", (-1.0, 1.0)),
            ):
                for d in deltas:
                    old = (self.scale, self.origin.copy())
                    self._nudge(which, d)
                    now = self.agreement(seen)
                    if np.mean(now) > np.mean(best) + 1e-6:
                        best = now
                    else:
                        self.scale, self.origin = old
        return best

    def _nudge(self, which: str, d: float) -> None:
        if which == "s":
            self.scale *= 1 + d
        else:
            self.origin = self.origin + (np.array([d, 0.0]) if which == "x" else np.array([0.0, d]))

    def _shift(self, off: tuple[float, ...]) -> tuple[float, float, float]:
        """A translation's shift on the picture plane and in depth, computed as the single
        drawing did (one dot product each: the same floats), once per translation."""
        out = self._shifts.get(off)
        if out is None:
            row = np.array(off)
            out = self._shifts[off] = (
                float(row @ self.right),
                float(row @ self.up),
                float(row @ self.v),
            )
        return out

    def _faces(self, t: F64) -> tuple[npt.NDArray[np.intp], list[list[float]]]:
        """Faces in drawing order (a stable sort by depth: ties keep piece, then face order)
        and each face's pixel corners (x0, y0, ... x3, y3), in that order."""
        s = np.array([self._shift(tuple(off)) for off in t.tolist()]).reshape(-1, 3)[self._owner]
        order = np.argsort(self._depth + s[:, 2], kind="stable")
        c = self._corners
        x = (c[:, :, 0] + s[:, 0:1]) * self.scale + self.origin[0] - 0.5
        y = -(c[:, :, 1] + s[:, 1:2]) * self.scale + self.origin[1] - 0.5
        xy: list[list[float]] = np.stack([x, y], axis=2)[order].reshape(-1, 8).tolist()
        return order, xy

    def _paint(self, t: F64, start: int | None = None) -> npt.NDArray[np.uint8]:
        """The label image of the faces in drawing order, from the first face of piece
        ``start`` on when given (earlier faces cannot show over it)."""
        order, xy = self._faces(t)
        labels: list[int] = (self._owner[order] + 1).tolist()
        first = 0 if start is None else int(np.argmax(self._owner[order] == start))
        h, w = self.shape
        img = Image.new("L", (w, h), 0)
        core = ImageDraw.Draw(img).draw  # ImageDraw.polygon(fill=) without its wrapper
        for k in range(first, len(xy)):
            core.draw_polygon(xy[k], labels[k], 1)
        return np.asarray(img, dtype=np.uint8)

    def draw(self, t: F64) -> npt.NDArray[np.uint8]:
        """The label image (0: nothing) with piece i translated by ``t[i]`` (cells)."""
        return self._paint(t)

    def mask(self, t: F64, i: int) -> Bools:
        """Where piece ``i`` shows in :meth:`draw` of ``t`` (the faces drawn before its first
        one are skipped: they are overdrawn or elsewhere)."""
        out: Bools = self._paint(t, i) == i + 1
        return out


class _Target:
    """A seen silhouette and its one-pixel growth, scored against many drawn ones."""

    def __init__(self, seen: Bools) -> None:
        self.seen, self.grown, self.area = seen, dilate(seen, 1), np.count_nonzero(seen)

    def iou(self, drawn: Bools) -> float:
        """:func:`_iou` of ``drawn`` with the seen silhouette (the same sums)."""
        total = np.count_nonzero(drawn) + self.area
        if total == 0:
            return 1.0
        same = np.count_nonzero(drawn & self.grown) + np.count_nonzero(self.seen & dilate(drawn, 1))
        return float(same) / total


def _iou(a: Bools, b: Bools) -> float:
    """Agreement of two silhouettes, forgiving one pixel at the boundary (drawn edges and
    anti-aliasing move it): the Dice coefficient of each against the other grown by one."""
    total = np.count_nonzero(a) + np.count_nonzero(b)
    if total == 0:
        return 1.0
    return float(np.count_nonzero(a & dilate(b, 1)) + np.count_nonzero(b & dilate(a, 1))) / total


def _labels(masks: list[Bools]) -> U8:
    out = np.zeros(masks[0].shape, dtype=np.uint8)
    for i, m in enumerate(masks):
        out[m] = i + 1
    return out


class _Tracker:
    """Translations of every piece over the frames, and the moves they make. Each piece keeps
    the agreement of its last fit as its own baseline (drawn edges and anti-aliasing cost some
    pieces more than others), and is searched for only when it falls clearly below it."""

    def __init__(self, scene: _PoseScene, names: tuple[str, ...], base: list[float]) -> None:
        self.scene, self.names = scene, names
        self.t = np.zeros((len(names), 3))
        self.base = list(base)
        self.gone = np.zeros(len(names), dtype=bool)
        self.span = int(np.ceil(max(scene.shape) / max(scene.scale, 1e-9))) + 2

    def _score(self, i: int, t: F64, seen: _Target) -> float:
        return seen.iou(self.scene.mask(t, i))

    def _candidates(self, i: int, far: bool) -> list[F64]:
        """Poses one axis away from the piece's nearest lattice pose (no drift across axes)."""
        steps = [float(d) for d in range(-self.span, self.span + 1) if d] if far else list(NEAR)
        steps.sort(key=abs)
        snap = self.t.copy()
        snap[i] = np.rint(snap[i])
        out = [snap] if not far else []
        for d in steps:
            for a in range(3):
                t = snap.copy()
                t[i, a] += d
                out.append(t)
        return out

    def step(self, seen: U8) -> tuple[list[int], list[int]]:
        """Refit the pieces that no longer match ``seen``: (indices that moved, clearly seen
        after the move; indices that could not be followed: turned, or off the lattice)."""
        moved, lost = [], []
        drawn = self.scene.draw(self.t)
        for i in range(len(self.names)):
            if self.gone[i]:
                continue
            if not (seen == i + 1).any():
                self.gone[i] = True  # out of the picture, or hidden: not checked further
                continue
            now = _iou(drawn == i + 1, seen == i + 1)
            if now >= self.base[i] - SLACK:
                continue
            best, pose = self._search(i, seen, now)
            if best < LOST_IOU:
                self.gone[i] = True
                lost.append(i)
                continue
            if pose is not self.t and not np.array_equal(pose, self.t):
                self.t = pose
                if best >= SURE_IOU:
                    moved.append(i)
            self.base[i] = best
        return moved, lost

    def _search(self, i: int, seen: U8, now: float) -> tuple[float, F64]:
        """The best pose of piece ``i``: near its last one (nearest first, stopping at a match
        as good as its baseline), else anywhere along the three axes."""
        best, pose = now, self.t
        good = self.base[i] - SLACK / 2
        target = _Target(seen == i + 1)
        for far in (False, True):
            if far and best >= self.base[i] - 2 * SLACK:
                break
            for cand in self._candidates(i, far):
                s = self._score(i, cand, target)
                if s > best + 0.01:
                    best, pose = s, cand
                if best >= good:
                    return best, pose
        return best, pose

    def swept(self, i: int, before: F64, after: F64) -> list[set[tuple[int, ...]]]:
        """Cells piece ``i`` fills at each whole position from one pose to the next along the
        axis of the move, ends rounded (first and last: the two poses)."""
        d = after - before
        a = int(np.argmax(np.abs(d)))
        start, end = round(float(before[a])), round(float(after[a]))
        step = 1 if end >= start else -1
        base = np.rint(before).astype(np.int64)
        out = []
        for k in range(start, end + step, step):
            off = base.copy()
            off[a] = k
            out.append({tuple(c) for c in (self.scene.pieces[i].cells + off).tolist()})
        return out

    def cells(self, j: int, pose: F64) -> set[tuple[int, ...]]:
        off = np.rint(pose).astype(np.int64)
        return {tuple(c) for c in (self.scene.pieces[j].cells + off).tolist()}


class Fit:
    """Where the tracker put every piece in every frame, with the fitted camera: the level
    drawn at those poses tells occlusion (a piece seen in parts round another) from a break."""

    def __init__(self, scene: _PoseScene, poses: dict[int, F64], gone: dict[int, Bools]):
        self.scene, self.poses, self.gone = scene, poses, gone

    def _best(self, g: int, i: int, seen: Bools) -> tuple[float, F64, Bools]:
        """Piece ``i``'s best agreement with ``seen`` at frame ``g``: at its tracked pose or
        up to a cell from it along one axis (the tracker refits only on a clear loss)."""
        best: tuple[float, F64, Bools] = (-1.0, self.poses[g][i], seen)
        steps = [(0, 0.0)] + [(a, d) for a in range(3) for d in NEAR if abs(d) <= 1.0]
        target = _Target(seen)
        for a, d in steps:
            t = self.poses[g].copy()
            t[self.gone[g]] = 1e4  # pieces no longer followed: far off the picture
            t[i, a] += d
            drawn = self.scene.mask(t, i)
            score = target.iou(drawn)
            if score > best[0] + 1e-9:
                best = (score, t[i], drawn)
        return best

    def explains(self, masks: list[list[Bools]], f: int, i: int, area: int) -> bool:
        """Whether piece ``i`` is seen in frames ``f - 1`` and ``f`` as the level drawn near
        its tracked poses shows it (no jump; no part missing in open view; no extra part):
        what changed there is occlusion, not a break, a copy or a loss."""
        if any(g not in self.poses or self.gone[g][i] for g in (f - 1, f)):
            return False
        fits = [self._best(g, i, masks[g][i]) for g in (f - 1, f)]
        if float(np.abs(fits[1][1] - fits[0][1]).max()) > 1.0:
            return False
        for g, (score, _, drawn) in zip((f - 1, f), fits, strict=True):
            seen = masks[g][i]
            anything = dilate(np.logical_or.reduce(masks[g]), 2)
            if score < EXPLAIN_IOU:
                return False
            if (drawn & ~anything).sum() > area / 2 or (seen & ~dilate(drawn, 2)).sum() > area / 2:
                return False
        return True


def pass_through(
    level: Level, masks: list[list[Bools]], names: tuple[str, ...]
) -> tuple[list[Event], list[str], Fit | None]:
    """Pass-through violations of a video drawn by our camera, and why not when undecidable.
    The camera is fitted on the first frame, or on the last one played backwards (a video
    of an assembly ends assembled): a collision is one either way."""
    if level.family != "puzzle":
        return [], ["pass_through: checked only for puzzles"], None
    cam = CAMERAS["iso"]
    pieces = _pieces(level, cam)
    agree = 0.0
    for order in (list(range(len(masks))), list(range(len(masks) - 1, -1, -1))):
        scene = _PoseScene(pieces, cam, masks[0][0].shape)
        first = _labels(masks[order[0]])
        mismatch = scene.fit(first > 0) if (first > 0).any() else 1.0
        base = scene.refine(first) if mismatch <= MAX_SCALE_MISMATCH else [0.0]
        score = float(np.mean(base))
        agree = max(agree, score)
        if score >= MIN_FIT_IOU:
            return _follow(scene, names, masks, order, base)
    why = f"neither end frame is our camera's view of the level assembled (agreement {agree:.2f})"
    return [], [f"pass_through: not decidable: {why}"], None


def _follow(
    scene: _PoseScene,
    names: tuple[str, ...],
    masks: list[list[Bools]],
    order: list[int],
    base: list[float],
) -> tuple[list[Event], list[str], Fit]:
    track = _Tracker(scene, names, base)
    why: list[str] = []
    poses = [track.t.copy()]
    gone = [track.gone.copy()]
    moves: list[list[int]] = [[]]
    for f in order[1:]:
        moved, lost = track.step(_labels(masks[f]))
        poses.append(track.t.copy())
        gone.append(track.gone.copy())
        moves.append(moved)
        why.extend(
            f"pass_through: the {names[i]} piece turned or left the lattice at frame {f}; "
            "its motion is not checked from there"
            for i in lost
        )
    events: list[Event] = []
    blamed: set[tuple[int, int]] = set()
    for n in range(1, len(order)):
        shown = max(order[n - 1], order[n])  # the frame where the change is seen
        for i in moves[n]:
            path = track.swept(i, poses[n - 1][i], poses[n][i])
            for j in _still(poses, gone, n, i):
                theirs = track.cells(j, poses[n][j])
                # both poses free of it (a fit that ends inside a piece is as likely a misfit)
                # and a whole position between them inside it
                clear = not (path[0] & theirs or path[-1] & theirs)
                if (i, j) not in blamed and clear and any(p & theirs for p in path[1:-1]):
                    blamed.add((i, j))
                    detail = f"the {names[i]} piece moved through the {names[j]} piece"
                    masks_ = (masks[shown][i], masks[shown][j])
                    events.append(
                        Event("pass_through", shown, names[i], names[j], detail, masks_, before=0)
                    )
    fit = Fit(scene, dict(zip(order, poses, strict=True)), dict(zip(order, gone, strict=True)))
    return events, why, fit


def _still(poses: list[F64], gone: list[npt.NDArray[np.bool_]], n: int, i: int) -> list[int]:
    """The pieces other than ``i`` that stay put for STILL_FRAMES around step ``n`` (a piece
    moving at the same time may be moving with it: not checked against it)."""
    lo, hi = max(0, n - STILL_FRAMES), min(len(poses), n + STILL_FRAMES + 1)
    out = []
    for j in range(len(poses[n])):
        if j == i or any(g[j] for g in gone[lo:hi]):
            continue
        if all(np.array_equal(p[j], poses[n][j]) for p in poses[lo:hi]):
            out.append(j)
    return out
