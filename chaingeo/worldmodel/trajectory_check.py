"""The exact checker of pose trajectories (``chain check-trajectory``).

Frames where every piece sits on the lattice cut a trajectory into segments. In a segment the
pieces that move are grouped by their common motion, and each group's motion must be one the
engine allows: a slide along one axis between two lattice poses (every pose in between on that
line, between its ends) or one quarter turn about a lattice line parallel to an axis (every pose
in between a turn about that line by 0 to 90 degrees). What a group sweeps is then tested
exactly against the pieces at rest, with the engine's own geometry: cells passed along the axis
for a slide, :func:`chaingeo.core.turns.swept_by` for a turn. At every lattice frame the pieces'
cells are tested for overlap. Two groups moving at once whose swept regions may meet are not
decided (no exact test for that here): they are listed under ``undecided``. The lattice motions
are then replayed as a plan by the reference kinematics
(:mod:`chaingeo.worldmodel.trajectory_plan`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from functools import lru_cache
from typing import Any, Final

import numpy as np
import numpy.typing as npt

from chaingeo.core import limits
from chaingeo.core.arrays import F64
from chaingeo.core.geometry import ROTATIONS, Cell, Shape, rotation_index
from chaingeo.core.level import Level
from chaingeo.core.turns import AXES, lateral, quarter_matrix, spinning_rods, swept_by
from chaingeo.worldmodel.trajectory import Pose, Trajectory, TrajectoryError

#: Distance (lattice units, matrix entries) within which a number counts as its lattice value.
TOL: Final = 1e-6
#: Violations listed at most; past it the list ends with one "truncated" entry.
MAX_VIOLATIONS: Final = 1000
#: Widest turn swept exactly (cells from the axis); a wider one is undecided.
MAX_TURN_RADIUS: Final = 16


@dataclass
class Findings:
    """What the checker found: violations and undecided questions, as JSON-ready objects."""

    violations: list[dict[str, Any]] = field(default_factory=list)
    undecided: list[dict[str, Any]] = field(default_factory=list)

    def add(self, kind: str, frame: int, piece: str | None, reason: str, **extra: Any) -> None:
        if len(self.violations) == MAX_VIOLATIONS:
            self.violations.append(
                {
                    "kind": "truncated",
                    "frame": frame,
                    "piece": None,
                    "reason": f"more than {MAX_VIOLATIONS} violations",
                }
            )
        if len(self.violations) > MAX_VIOLATIONS:
            return
        self.violations.append(
            {"kind": kind, "frame": frame, "piece": piece, "reason": reason, **extra}
        )


@dataclass
class Poses:
    """The trajectory as arrays over (frame, piece of the level): ``ok`` (present and rigid),
    ``lat`` (on the lattice), the float pose, and the lattice pose (rotation index, offset:
    cells ``R v + offset``) where ``lat``."""

    names: list[str]
    ok: npt.NDArray[np.bool_]
    lat: npt.NDArray[np.bool_]
    rot: F64
    tr: F64
    ridx: npt.NDArray[np.int64]
    off: npt.NDArray[np.int64]


def _rigid_cells(
    shape_cells: frozenset[Cell], shape: Any, cells: Sequence[Cell]
) -> tuple[int, Cell] | None:
    """(rotation index, offset) taking the piece's cells onto ``cells``, or None."""
    target = frozenset(cells)
    if len(target) != len(cells) or len(target) != len(shape_cells):
        return None
    lo = np.array(cells).min(axis=0)
    for i, r in enumerate(ROTATIONS):
        turned = shape.rotate(r)
        off = lo - turned.min_corner
        if turned.translate(off).cell_set == target:
            return i, (int(off[0]), int(off[1]), int(off[2]))
    return None


def _read_pose(p: Pose, shape: Any) -> tuple[str | None, F64, F64, int, Cell | None]:
    """(why it is not rigid or None, rotation, translation, rotation index or -1, lattice
    offset or None)."""
    if p.cells is not None:
        found = _rigid_cells(shape.cell_set, shape, p.cells)
        if found is None:
            why = "its cells are not the piece's shape moved rigidly (split, grown or swapped)"
            return why, np.eye(3), np.zeros(3), -1, None
        r = ROTATIONS[found[0]].astype(np.float64)
        t = np.asarray(found[1], dtype=np.float64) + 0.5 - 0.5 * r.sum(axis=1)
        return None, r, t, found[0], found[1]
    assert p.rotation is not None and p.translation is not None
    r, t = p.rotation, p.translation
    if np.abs(r.T @ r - np.eye(3)).max() > TOL:
        return "its rotation is not orthonormal (the piece is scaled or sheared)", r, t, -1, None
    if np.linalg.det(r) < 0:
        return "its rotation has determinant -1 (the piece is mirrored)", r, t, -1, None
    ri = np.rint(r)
    if np.abs(r - ri).max() > TOL:
        return None, r, t, -1, None
    o = t - 0.5 + 0.5 * ri.sum(axis=1)
    oi = np.rint(o)
    if np.abs(o - oi).max() > TOL:
        return None, r, t, -1, None
    return None, r, t, rotation_index(ri.astype(np.int64)), (int(oi[0]), int(oi[1]), int(oi[2]))


def read_poses(level: Level, traj: Trajectory, found: Findings) -> Poses:
    """The arrays of :class:`Poses`; identity and shape verdicts go to ``found``."""
    names = sorted(p.name for p in level.pieces)
    frames = traj.frames
    n_f, n_p = len(frames), len(names)
    if n_f * n_p > limits.MAX_TRAJECTORY_POSES:
        raise TrajectoryError(
            f"{n_f} frames of {n_p} pieces; at most {limits.MAX_TRAJECTORY_POSES} poses"
        )
    shapes = level.shapes
    ps = Poses(
        names,
        np.zeros((n_f, n_p), bool),
        np.zeros((n_f, n_p), bool),
        np.zeros((n_f, n_p, 3, 3)),
        np.zeros((n_f, n_p, 3)),
        np.full((n_f, n_p), -1, np.int64),
        np.zeros((n_f, n_p, 3), np.int64),
    )
    for f, n in traj.duplicates:
        found.add("duplicate", f, n, "the piece is listed twice in this frame")
    known = set(names)
    seen_unknown: set[str] = set()
    for i, frame in enumerate(frames):
        for n in sorted(set(frame) - known):
            if n not in seen_unknown:
                seen_unknown.add(n)
                found.add("appear", i, n, "a piece the level does not have appears")
        for j, n in enumerate(names):
            pose = frame.get(n)
            if pose is None:
                if i == 0 or n in frames[i - 1]:
                    found.add("disappear", i, n, "the piece is missing from this frame")
                continue
            if i > 0 and n not in frames[i - 1]:
                found.add("appear", i, n, "the piece appears again after missing")
            why, r, t, ri, off = _read_pose(pose, shapes[n])
            if why is not None:
                if i == 0 or ps.ok[i - 1, j] or n not in frames[i - 1]:
                    found.add("shape", i, n, why)
                continue
            ps.ok[i, j] = True
            ps.rot[i, j], ps.tr[i, j] = r, t
            if off is not None:
                ps.lat[i, j] = True
                ps.ridx[i, j] = ri
                ps.off[i, j] = off
    return ps


# ---------------------------------------------------------------------------------------------
# Motions of one segment
# ---------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Motion:
    """One group's lattice motion from frame ``a`` to ``b``: a slide by ``k`` along ``axis``
    or a turn by ``quarter`` about the line through ``pivot`` (a point) parallel to ``axis``."""

    pieces: tuple[str, ...]
    a: int
    b: int
    kind: str  # "slide" or "turn"
    axis: int
    k: int = 0
    quarter: int = 0
    pivot: tuple[float, float, float] = (0.0, 0.0, 0.0)


def _relative(ps: Poses, a: int, b: int, j: int) -> tuple[F64, F64]:
    """Motions of piece ``j`` from frame ``a``: rotations ``R_i R_a^T`` and translations."""
    ra, ta = ps.rot[a, j], ps.tr[a, j]
    rr = ps.rot[a : b + 1, j] @ ra.T
    tt = ps.tr[a : b + 1, j] - np.einsum("fij,j->fi", rr, ta)
    return rr, tt


def _first(bad: npt.NDArray[np.bool_]) -> int | None:
    """Index of the first True, or None."""
    hits = np.flatnonzero(bad)
    return int(hits[0]) if hits.size else None


def _classify_slide(rr: F64, tt: F64, axis: int, k: int) -> tuple[str, int] | None:
    """Why these relative poses are no slide by ``k`` along ``axis`` (and the first frame
    that shows it), or None."""
    others = [i for i in range(3) if i != axis]
    s = tt[:, axis]
    checks = (
        (np.abs(rr - np.eye(3)).max(axis=(1, 2)) > TOL, "it turns while it slides"),
        (np.abs(tt[:, others]).max(axis=1) > TOL, "it leaves the line of its slide"),
        (
            (s < min(0, k) - TOL) | (s > max(0, k) + TOL),
            "it overshoots its lattice pose and comes back",
        ),
    )
    found = [(i, why) for bad, why in checks if (i := _first(bad)) is not None]
    return None if not found else (min(found)[1], min(found)[0])


def _pivot(q: F64, u: F64, axis: int) -> F64 | None:
    """The point ``c`` (axis coordinate 0) with ``u = c - q c``, if the turn keeps cells on
    cells (its line through cell centres or cell corners)."""
    uu, vv = lateral(axis)
    m = np.eye(2) - q[np.ix_([uu, vv], [uu, vv])]
    c2 = np.linalg.solve(m, u[[uu, vv]])
    c = np.zeros(3)
    c[uu], c[vv] = c2
    d = 2 * (c2 - 0.5)
    if np.abs(d - np.rint(d)).max() > TOL or (np.rint(d[0]) - np.rint(d[1])) % 2:
        return None
    return c


def _classify_turn(rr: F64, tt: F64, axis: int, quarter: int) -> tuple[tuple[str, int] | None, F64]:
    q = rr[-1]
    last = len(rr) - 1
    if abs(tt[-1][axis]) > TOL:
        return ("it slides along its axis while it turns", last), np.zeros(3)
    c = _pivot(q, tt[-1], axis)
    if c is None:
        why = "its turn's line runs through neither cell centres nor cell corners"
        return (why, last), np.zeros(3)
    uu, vv = lateral(axis)
    for i, (r, t) in enumerate(zip(rr, tt, strict=True)):
        theta = math.atan2(r[vv, uu], r[uu, uu]) * quarter
        expect = np.eye(3)
        cs, sn = math.cos(theta * quarter), math.sin(theta * quarter)
        expect[uu, uu], expect[uu, vv], expect[vv, uu], expect[vv, vv] = cs, -sn, sn, cs
        if np.abs(r - expect).max() > TOL or not -TOL <= theta <= math.pi / 2 + TOL:
            return ("it does not turn about one axis by 0 to 90 degrees", i), c
        if np.abs(t - (c - r @ c)).max() > 1e-5:
            return ("its turn does not keep one line fixed", i), c
    return None, c


def classify(
    ps: Poses, a: int, b: int, j: int, turns: bool
) -> tuple[Motion | None, tuple[str, int] | None]:
    """Piece ``j``'s motion from lattice frame ``a`` to ``b`` (both ends on the lattice):
    (the motion, None), (None, (why it is no allowed motion, the frame that shows it)), or
    (None, None) at rest."""
    rr, tt = _relative(ps, a, b, j)
    off = (np.abs(rr - np.eye(3)).max(axis=(1, 2)) > TOL) | (np.abs(tt).max(axis=1) > TOL)
    first = _first(off)
    if first is None:
        return None, None
    at = a + first
    q = np.rint(rr[-1]).astype(np.int64)
    u = tt[-1]
    name = ps.names[j]
    if (q == np.eye(3, dtype=np.int64)).all():
        nz = [i for i in range(3) if abs(u[i]) > TOL]
        if not nz:
            return None, ("it drifts off the lattice at rest (and back)", at)
        if len(nz) > 1:
            return None, ("it moves along more than one axis at once (no slide)", at)
        axis = nz[0]
        k = round(float(u[axis]))
        why = _classify_slide(rr, tt, axis, k)
        if why is not None:
            return None, (why[0], a + why[1])
        return Motion((name,), a, b, "slide", axis, k=k), None
    for axis in range(3):
        for quarter in (1, -1):
            if (q == quarter_matrix(axis, quarter)).all():
                if not turns:
                    return None, ("it turns, and this level allows no turns", at)
                bad, c = _classify_turn(rr, tt, axis, quarter)
                if bad is not None:
                    return None, (bad[0], a + bad[1])
                piv = (float(c[0]), float(c[1]), float(c[2]))
                return Motion((name,), a, b, "turn", axis, quarter=quarter, pivot=piv), None
    return None, ("its rotation is neither one quarter turn nor none (no allowed motion)", at)


def jump(ps: Poses, a: int, b: int, j: int, shape_cells: npt.NDArray[np.int64]) -> float:
    """The farthest any corner of the piece's box moves between two consecutive frames."""
    lo, hi = shape_cells.min(axis=0), shape_cells.max(axis=0) + 1
    corners = np.array(
        [[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])],
        dtype=np.float64,
    )
    pts = np.einsum("fij,cj->fci", ps.rot[a : b + 1, j], corners) + ps.tr[a : b + 1, j][:, None, :]
    if len(pts) < 2:
        return 0.0
    return float(np.linalg.norm(np.diff(pts, axis=0), axis=2).max())


# ---------------------------------------------------------------------------------------------
# Swept regions
# ---------------------------------------------------------------------------------------------


def cells_at(level: Level, ps: Poses, f: int, j: int) -> frozenset[Cell]:
    """The cells piece ``j`` fills at frame ``f`` (where it is on the lattice)."""
    o = ps.off[f, j]
    offset = (int(o[0]), int(o[1]), int(o[2]))
    return _cells(level.piece(ps.names[j]).shape, int(ps.ridx[f, j]), offset)


@lru_cache(maxsize=1 << 14)
def _cells(shape: Shape, ridx: int, offset: Cell) -> frozenset[Cell]:
    moved = shape.voxels @ ROTATIONS[ridx].T + np.asarray(offset)
    return frozenset((int(x), int(y), int(z)) for x, y, z in moved.tolist())


def slide_hit(
    group: Sequence[Cell], fixed: dict[Cell, str], axis: int, k: int
) -> tuple[str, Cell] | None:
    """The first fixed cell (and its piece) that the group's cells pass sliding ``k`` along
    ``axis`` (cells strictly between, and the end): work bounded by the cells, not by ``k``."""
    lines: dict[tuple[int, ...], list[int]] = {}
    for c in fixed:
        key = tuple(c[i] for i in range(3) if i != axis)
        lines.setdefault(key, []).append(c[axis])
    lo, hi = (1, k) if k > 0 else (k, -1)
    best: tuple[int, Cell] | None = None
    for g in group:
        key = tuple(g[i] for i in range(3) if i != axis)
        for at in lines.get(key, ()):
            d = at - g[axis]
            if lo <= d <= hi and (best is None or abs(d) < best[0]):
                cell = list(g)
                cell[axis] = at
                best = (abs(d), (cell[0], cell[1], cell[2]))
    return None if best is None else (fixed[best[1]], best[1])


def turn_swept(level: Level, ps: Poses, f: int, js: Sequence[int], m: Motion) -> set[Cell] | None:
    """Every cell the group sweeps turning (round rods on the line spin in place), or None
    when the group reaches farther than :data:`MAX_TURN_RADIUS` from the line."""
    c2 = [round(2 * (v - 0.5)) for v in m.pivot]
    c2[m.axis] = 0
    cells: list[Cell] = []
    spin: set[Cell] = set()
    for j in js:
        piece = level.piece(ps.names[j])
        own = cells_at(level, ps, f, j)
        if piece.rods:
            spin |= spinning_rods(
                piece.rods, ROTATIONS[int(ps.ridx[f, j])], tuple(ps.off[f, j]), m.axis, c2
            )
        cells += [c for c in own if c not in spin]
    uu, vv = lateral(m.axis)
    if (
        cells
        and max(max(abs(2 * c[uu] - c2[uu]), abs(2 * c[vv] - c2[vv])) for c in cells)
        > 2 * MAX_TURN_RADIUS
    ):
        return None
    return swept_by(cells, m.axis, m.quarter, c2) | spin


def spinning_of(level: Level, ps: Poses, f: int, j: int, m: Motion) -> set[Cell]:
    piece = level.piece(ps.names[j])
    if not piece.rods or m.kind != "turn":
        return set()
    c2 = [round(2 * (v - 0.5)) for v in m.pivot]
    c2[m.axis] = 0
    return spinning_rods(piece.rods, ROTATIONS[int(ps.ridx[f, j])], tuple(ps.off[f, j]), m.axis, c2)


def direction_name(axis: int, k: int) -> str:
    return ("+" if k > 0 else "-") + AXES[axis]
