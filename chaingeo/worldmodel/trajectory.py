"""Pose trajectories (``chain-trajectory/1``): every piece's rigid pose, frame by frame.

A trajectory file is one JSON object::

    {"format": "chain-trajectory/1", "level": "<level id>",
     "frames": [{"poses": {"A": {"rotation": [[1,0,0],[0,1,0],[0,0,1]],
                                 "translation": [0.0, 0.0, 2.5]},
                           "B": {"cells": [[0,0,0], [1,0,0]]}, ...}}, ...]}

A pose maps the piece's own cubes (the level file's cells: the assembled position of a puzzle
piece, the tray shape of a stacking piece; voxel ``v`` is the cube ``[v, v+1]^3``) by the point
map ``p -> R p + t``: ``rotation`` is a 3x3 real matrix (row-major), ``translation`` real, in
lattice units. A lattice pose puts every cube on a cell. ``cells`` instead lists the cells the
piece fills (a lattice pose written cell by cell; the checker finds the rigid motion).

:func:`plan_trajectory` makes the trajectory of a plan, following the video of
:mod:`chaingeo.worldmodel.video` frame by frame, except that no piece ever leaves: a group
taken out of its part slides out as in the video, then is carried (up, across, down) to a parking
place of its own, far from every other part, where its own disassembly goes on.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Final

import numpy as np
import numpy.typing as npt

from chaingeo.core.arrays import F64
from chaingeo.core.errors import ChainGeoError
from chaingeo.core.files import UnreadableFile, atomic_write, parse_json
from chaingeo.core.geometry import ROTATIONS, Cell, Shape
from chaingeo.core.kinematics import DIRECTIONS, Assembly, Move, disassembly_of_assembly_plan
from chaingeo.core.level import Level, PuzzleSolution, StackingSolution
from chaingeo.core.turns import AXES, TurnMove
from chaingeo.worldmodel.video import (
    OUT_FRAMES,
    SLIDE_FRAMES,
    TURN_FRAMES,
    VideoError,
    _ease,
    _stacking_shots,
    _turn_matrix,
    carried_order,
    read_plan,
)

FORMAT: Final = "chain-trajectory/1"


class TrajectoryError(ChainGeoError, ValueError):
    """A trajectory file that cannot be read as ``chain-trajectory/1``; the message says where."""


@dataclass(frozen=True)
class Pose:
    """A rigid pose ``p -> rotation @ p + translation`` (floats), or the cells a piece fills."""

    rotation: F64 | None = None
    translation: F64 | None = None
    cells: tuple[Cell, ...] | None = None


Frame = dict[str, Pose]


@dataclass(frozen=True)
class Trajectory:
    """The frames; ``duplicates`` lists (frame, piece) of names written twice in one frame."""

    level: str | None
    frames: tuple[Frame, ...]
    duplicates: tuple[tuple[int, str], ...] = ()


# ---------------------------------------------------------------------------------------------
# Reading and writing
# ---------------------------------------------------------------------------------------------


def _numbers(raw: Any, n: int, where: str, bound: float) -> list[float]:
    if not isinstance(raw, list) or len(raw) != n:
        raise TrajectoryError(f"{where}: expected {n} numbers")
    out = []
    for v in raw:
        if isinstance(v, bool) or not isinstance(v, int | float):
            raise TrajectoryError(f"{where}: expected numbers, got {v!r:.40}")
        if abs(v) > bound:
            raise TrajectoryError(f"{where}: {v!r:.40} is larger than {bound:g}")
        out.append(float(v))
    return out


def _pose(raw: Any, where: str, limits: Any) -> Pose:
    if not isinstance(raw, dict):
        raise TrajectoryError(f"{where}: expected an object")
    if "cells" in raw:
        cells = raw["cells"]
        if not isinstance(cells, list) or not 0 < len(cells) <= limits.MAX_PIECE_VOXELS:
            raise TrajectoryError(f"{where}.cells: expected 1 to {limits.MAX_PIECE_VOXELS} cells")
        out = []
        for i, c in enumerate(cells):
            xyz = _numbers(c, 3, f"{where}.cells[{i}]", limits.MAX_TRAJECTORY_COORD)
            if any(v != int(v) for v in xyz):
                raise TrajectoryError(f"{where}.cells[{i}]: cells are whole numbers")
            out.append((int(xyz[0]), int(xyz[1]), int(xyz[2])))
        return Pose(cells=tuple(out))
    rot = raw.get("rotation")
    if not isinstance(rot, list) or len(rot) != 3:
        raise TrajectoryError(f"{where}.rotation: expected a 3x3 matrix (three rows)")
    rows = [_numbers(r, 3, f"{where}.rotation[{i}]", 1e3) for i, r in enumerate(rot)]
    t = _numbers(raw.get("translation"), 3, f"{where}.translation", limits.MAX_TRAJECTORY_COORD)
    return Pose(np.array(rows, dtype=np.float64), np.array(t, dtype=np.float64))


def parse_trajectory(text: str | bytes) -> Trajectory:
    """A ``chain-trajectory/1`` document (already read, bounded); TrajectoryError otherwise. A
    piece named twice in one frame is a verdict, not a parse error: the reader keeps the keys
    written twice beside each object (:class:`chaingeo.core.files.JsonObject`), never in it."""
    from chaingeo.core import limits

    try:
        data = parse_json(text)
    except UnreadableFile as e:
        raise TrajectoryError(e.reason) from None
    if not isinstance(data, dict) or data.get("format") != FORMAT:
        raise TrajectoryError(f'expected an object with "format": "{FORMAT}"')
    frames = data.get("frames")
    if not isinstance(frames, list) or not frames:
        raise TrajectoryError("frames: expected a non-empty list")
    if len(frames) > limits.MAX_TRAJECTORY_FRAMES:
        raise TrajectoryError(f"frames: {len(frames)}; at most {limits.MAX_TRAJECTORY_FRAMES}")
    level = data.get("level")
    if level is not None and not isinstance(level, str):
        raise TrajectoryError("level: expected a level id")
    out: list[Frame] = []
    dups: list[tuple[int, str]] = []
    total = 0
    for i, fr in enumerate(frames):
        poses = fr.get("poses") if isinstance(fr, dict) else None
        if not isinstance(poses, dict):
            raise TrajectoryError(f"frames[{i}].poses: expected an object keyed by piece name")
        dups += [(i, k) for k in getattr(poses, "repeated", ())]
        total += len(poses)
        if len(poses) > limits.MAX_PIECES or total > limits.MAX_TRAJECTORY_POSES:
            raise TrajectoryError(
                f"frames[{i}]: more than {limits.MAX_PIECES} poses a frame or "
                f"{limits.MAX_TRAJECTORY_POSES} in all"
            )
        out.append(
            {str(n): _pose(p, f"frames[{i}].poses.{n[:40]}", limits) for n, p in poses.items()}
        )
    return Trajectory(level, tuple(out), tuple(dups))


def _num(v: float) -> float | int:
    r = round(float(v), 9)
    return int(r) if r == int(r) else r  # also turns -0.0 into 0


def pose_json(p: Pose) -> dict[str, Any]:
    if p.cells is not None:
        return {"cells": [list(c) for c in p.cells]}
    assert p.rotation is not None and p.translation is not None
    return {
        "rotation": [[_num(v) for v in row] for row in p.rotation.tolist()],
        "translation": [_num(v) for v in p.translation.tolist()],
    }


def trajectory_json(level_id: str | None, frames: Sequence[Mapping[str, Pose]]) -> dict[str, Any]:
    out: dict[str, Any] = {"format": FORMAT}
    if level_id is not None:
        out["level"] = level_id
    out["frames"] = [{"poses": {n: pose_json(f[n]) for n in sorted(f)}} for f in frames]
    return out


# ---------------------------------------------------------------------------------------------
# The trajectory of a plan
# ---------------------------------------------------------------------------------------------


def lattice_pose(rotation: npt.ArrayLike, offset: npt.ArrayLike) -> Pose:
    """The pose whose cubes fill the cells ``rotation @ v + offset`` (integers)."""
    r = np.asarray(rotation, dtype=np.float64)
    t = np.asarray(offset, dtype=np.float64) + 0.5 - 0.5 * r.sum(axis=1)
    return Pose(r, t)


class _Parking:
    """Poses of a disassembly with every part kept: part displacements on top of the engine's
    offsets, one parking place per part taken out (spaced so that no two places' motions
    meet), and the frames of each step."""

    def __init__(self, level: Level, plan: Sequence[Move | TurnMove]) -> None:
        self.engine = Assembly.assembled(level.shapes, level.rods)
        lo = np.full(3, 1 << 40)
        hi = -lo
        state = self.engine
        for m in [None, *plan]:
            if m is not None:
                state = state.apply(m)
            cells = np.array([c for n in level.shapes for c in state.cells_of(n)])
            lo, hi = np.minimum(lo, cells.min(axis=0)), np.maximum(hi, cells.max(axis=0))
        self.lo, self.hi = lo, hi
        self.span = int((hi - lo).max()) + 1
        every = np.concatenate([s.voxels for s in level.shapes.values()])
        self.away = max(3 * int(np.ptp(every, axis=0).max() + 1) + 4, self.span + 1)
        self.spacing = 4 * (self.span + self.away)
        self.disp: dict[str, F64] = {n: np.zeros(3) for n in level.shapes}
        self.places = 0
        self.frames: list[Frame] = [self.poses()]

    def poses(self, moving: Sequence[str] = (), extra: tuple[F64, F64] | None = None) -> Frame:
        out: Frame = {}
        for n in self.engine.shapes:
            p = lattice_pose(ROTATIONS[self.engine.rotation_of(n)], self.engine.offsets[n])
            assert p.rotation is not None and p.translation is not None
            rot, t = p.rotation, p.translation + self.disp[n]
            if extra is not None and n in moving:
                rot, t = extra[0] @ rot, extra[0] @ t + extra[1]
            out[n] = Pose(rot, t)
        return out

    def slide(self, group: Sequence[str], vector: npt.ArrayLike, frames: int) -> None:
        """Slide the group by ``vector`` over ``frames`` eased frames (the displacement kept)."""
        v = np.asarray(vector, dtype=np.float64)
        for i in range(1, frames + 1):
            self.frames.append(self.poses(group, (np.eye(3), v * _ease(i, frames))))
        for n in group:
            self.disp[n] = self.disp[n] + v
        self.frames[-1] = self.poses()

    def step(self, move: Move | TurnMove) -> None:
        group = list(move.pieces)
        if isinstance(move, TurnMove):
            a = AXES.index(move.axis)
            pivot = np.array(move.centre2, dtype=np.float64) / 2.0 + 0.5 + self.disp[group[0]]
            for i in range(1, TURN_FRAMES + 1):
                r = _turn_matrix(a, move.quarter * math.pi / 2 * _ease(i, TURN_FRAMES))
                self.frames.append(self.poses(group, (r, pivot - r @ pivot)))
            self.engine = self.engine.apply(move)
            self.frames[-1] = self.poses()
            return
        d = np.array(DIRECTIONS[move.direction], dtype=np.float64)
        if not self.engine.removes(move):
            assert move.distance is not None
            for i in range(1, SLIDE_FRAMES + 1):
                shift = d * move.distance * _ease(i, SLIDE_FRAMES)
                self.frames.append(self.poses(group, (np.eye(3), shift)))
            self.engine = self.engine.apply(move)
            self.frames[-1] = self.poses()
            return
        far = max(self.away, self.engine.clearance(group, move.direction))
        self.engine = self.engine.apply(move)
        self._park(group, d, far)

    def _park(self, group: Sequence[str], d: F64, far: int) -> None:
        """Out by ``far`` (as the video shows it), then up, across to a new place, and down."""
        self.slide(group, d * far, OUT_FRAMES)
        if d[2] < 0:  # below its part: first step aside, out of the part's column
            self.slide(group, (2 * self.span + self.away, 0, 0), OUT_FRAMES)
        lift = 2 * (self.span + self.away) + far
        self.slide(group, (0, 0, lift), OUT_FRAMES)
        self.places += 1
        at = self.disp[group[0]]
        self.slide(group, (self.places * self.spacing - at[0], 0, 0), OUT_FRAMES)
        if at[1]:
            self.slide(group, (0, -at[1], 0), OUT_FRAMES)
        self.slide(group, (0, 0, -self.disp[group[0]][2]), OUT_FRAMES)


def puzzle_trajectory(level: Level, moves: Sequence[Move | TurnMove] | None = None) -> list[Frame]:
    """The frames of a puzzle plan (None: the level's own): an assembly plan as the
    disassembly that undoes it, played backwards."""
    if not isinstance(level.solution, PuzzleSolution):
        raise VideoError(f"{level.id} is a {level.family} level, not a puzzle")
    plan = list(level.solution.moves) if moves is None else list(moves)
    undo = plan if level.goal == "disassemble" else disassembly_of_assembly_plan(plan)
    park = _Parking(level, undo)
    for m in undo:
        park.step(m)
    return park.frames if level.goal == "disassemble" else park.frames[::-1]


def _placing(shape: Shape, cells: Shape) -> tuple[F64, F64]:
    """The rotation and offset that take the tray ``shape`` onto ``cells``."""
    target = cells.cell_set
    for r in ROTATIONS:
        turned = shape.rotate(r)
        off = cells.min_corner - turned.min_corner
        if turned.translate(off).cell_set == target:
            return r.astype(np.float64), off.astype(np.float64)
    raise VideoError(f"internal: placed cells {sorted(target)[:3]}... are no turn of the piece")


def stacking_trajectory(
    level: Level, order: Sequence[tuple[str, Shape]] | None = None
) -> list[Frame]:
    """The frames of a stacking plan (None: the level's own solution, in the video's order),
    the video's motion:
    each piece rises from its place beside the box, travels over it and is lowered in."""
    if not isinstance(level.solution, StackingSolution):
        raise VideoError(f"{level.id} is a {level.family} level, not a stacking level")
    plan = carried_order(level) if order is None else list(order)
    shots, _, _ = _stacking_shots(level, plan)
    base = {p.name: (np.eye(3), np.zeros(3)) for p in level.pieces}  # still waiting: as given
    base.update({n: _placing(level.piece(n).shape, cells) for n, cells in plan})
    frames: list[Frame] = []
    for shot in shots:
        frame: Frame = {}
        for n, _, t in shot:
            r, off = base[n]
            at = lattice_pose(r, off).translation
            assert at is not None
            frame[n] = Pose(r, at + t)
        frames.append(frame)
    return frames


def plan_trajectory(level: Level, plan_text: str | None = None) -> list[Frame]:
    """The frames of a plan written as text (:func:`chaingeo.worldmodel.video.read_plan`), or
    of the level's own (None), whatever the level's family."""
    moves, places = (None, None) if plan_text is None else read_plan(level, plan_text)
    if isinstance(level.solution, PuzzleSolution):
        return puzzle_trajectory(level, moves)
    return stacking_trajectory(level, places)


def write_trajectory(level: Level, plan_text: str | None, path: Path) -> Path:
    """The plan's trajectory as canonical JSON (sorted keys, one frame a line), atomically."""
    data = trajectory_json(level.id, plan_trajectory(level, plan_text))
    head = json.dumps({k: v for k, v in data.items() if k != "frames"}, sort_keys=True)
    lines = [json.dumps(f, sort_keys=True, separators=(",", ":")) for f in data["frames"]]
    text = head[:-1] + ', "frames": [\n' + ",\n".join(lines) + "\n]}\n"
    return atomic_write(path, text.encode("utf-8"))
