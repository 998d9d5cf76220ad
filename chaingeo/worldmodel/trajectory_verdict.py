"""The verdict on a pose trajectory: its segments checked
(:mod:`chaingeo.worldmodel.trajectory_check`), its lattice motions replayed as a plan by the
reference kinematics (puzzles: the engine of :mod:`chaingeo.core.kinematics`, then the level's state
machine; stacking: the state machine), and the goal tested on the last frame.

An assembly level's trajectory is checked backwards, as the disassembly it undoes (the same
motions, the same sweeps), and reported with forward frame numbers.
"""

from __future__ import annotations

import dataclasses
import itertools
from dataclasses import dataclass
from typing import Any, Final

import numpy as np

from chaingeo.core.geometry import Cell
from chaingeo.core.kinematics import (
    disassembly_of_assembly_plan,
)
from chaingeo.core.level import Level
from chaingeo.core.turns import AXES
from chaingeo.worldmodel.trajectory import Trajectory
from chaingeo.worldmodel.trajectory_check import (
    TOL,
    Findings,
    Motion,
    Poses,
    cells_at,
    classify,
    direction_name,
    jump,
    read_poses,
    slide_hit,
    spinning_of,
    turn_swept,
)

#: Cubes tested for overlap at poses between lattice frames, per check (a few seconds).
BETWEEN_BUDGET: Final = 2_000_000


@dataclass(frozen=True)
class TrajectoryVerdict:
    """``valid``: no violation and nothing undecided; ``plan``: the actions the trajectory
    realises (None when it realises none); ``goal``: whether the last frame meets the level's
    goal (None: not known)."""

    valid: bool
    violations: list[dict[str, Any]]
    undecided: list[dict[str, Any]]
    plan: list[str] | None
    goal: bool | None

    def to_json(self) -> dict[str, Any]:
        return {
            "valid": self.valid,
            "violations": self.violations,
            "undecided": self.undecided,
            "plan": self.plan,
            "goal": self.goal,
        }


class _Segments:
    """Cuts each piece's frames at the frames where it sits on the lattice, checks each of
    its motions, sweeps each group's motion against the pieces at rest meanwhile, and tests
    the pieces on the lattice for overlap whenever one of them changes."""

    def __init__(self, level: Level, ps: Poses, found: Findings, max_jump: float | None) -> None:
        self.level, self.ps, self.found, self.max_jump = level, ps, found, max_jump
        self.turns = level.family == "stacking" or bool(getattr(level.rules, "turns", False))
        self.voxels = {n: level.piece(n).shape.voxels for n in ps.names}
        self.overlapping: set[tuple[str, str]] = set()
        self.budget = BETWEEN_BUDGET  # cubes tested off the lattice, in all
        self.motions: list[list[Motion]] = []
        # changes[f, j]: piece j's pose differs from frame f - 1 (prefix sums: at rest or not)
        step = (np.abs(np.diff(ps.rot, axis=0)).max(axis=(2, 3)) > TOL) | (
            np.abs(np.diff(ps.tr, axis=0)).max(axis=2) > TOL
        )
        step |= ~ps.ok[1:] | ~ps.ok[:-1]
        self.changes = np.concatenate(
            [np.zeros((1, len(ps.names)), np.int64), np.cumsum(step, axis=0)]
        )

    def at_rest(self, j: int, a: int, b: int) -> bool:
        return bool(self.changes[b, j] == self.changes[a, j]) and bool(self.ps.ok[a, j])

    def run(self) -> None:
        ps = self.ps
        n_f, n_p = ps.ok.shape
        moving: list[tuple[int, Motion]] = []
        for j in range(n_p):
            frames = [f for f in range(n_f) if ps.ok[f, j] and ps.lat[f, j]]
            for f, why in ((0, "starts"), (n_f - 1, "ends")):
                if ps.ok[f, j] and not ps.lat[f, j]:
                    self.found.add("off-lattice", f, ps.names[j], f"it {why} off the lattice")
            for a, b in itertools.pairwise(frames):
                if self.at_rest(j, a, b) or not ps.ok[a : b + 1, j].all():
                    continue
                motion = self.classified(j, a, b)
                if motion is not None:
                    moving.append((j, motion))
        groups = self.grouped(moving)
        boxes = [self.sweep(js, m) for js, m in groups]
        self.concurrent(groups, boxes)
        self.overlaps()
        order = sorted(groups, key=lambda g: (g[1].b, g[1].a, g[1].pieces))
        self.motions = _merged([[m] for _, m in order])

    def classified(self, j: int, a: int, b: int) -> Motion | None:
        ps = self.ps
        motion, why = classify(ps, a, b, j, self.turns)
        size = jump(ps, a, b, j, self.voxels[ps.names[j]])
        at = self.first_move(a, b, j)
        if self.max_jump is not None and size > self.max_jump + TOL:
            self.found.add(
                "teleport",
                at,
                ps.names[j],
                f"it moves {size:.3g} units in one frame (at most {self.max_jump:g})",
            )
        if why is not None:
            self.not_allowed(a, b, j, why[1], why[0], size)
            return None
        other = self.swapped(a, b, j)
        if other is not None:
            self.found.add(
                "swap",
                at,
                ps.names[j],
                f"it takes {other}'s place and {other} takes its (identities swapped)",
                other=other,
            )
            return None
        return motion

    def overlaps(self) -> None:
        """Pieces on the lattice that share a cell (each pair once while it lasts), tested at
        every frame where a piece on the lattice changes."""
        ps = self.ps
        last: tuple[Any, ...] | None = None
        for f in range(ps.ok.shape[0]):
            on = ps.ok[f] & ps.lat[f]
            key = (on.tobytes(), ps.ridx[f][on].tobytes(), ps.off[f][on].tobytes())
            if key != last:
                self.overlap(f, [j for j in range(len(ps.names)) if on[j]])
            last = key

    def overlap(self, f: int, js: list[int]) -> None:
        owner: dict[Cell, str] = {}
        now: dict[tuple[str, str], Cell] = {}
        for j in js:
            n = self.ps.names[j]
            for c in sorted(cells_at(self.level, self.ps, f, j)):
                other = owner.setdefault(c, n)
                if other != n:
                    now.setdefault((other, n), c)
        for (a, b), c in sorted(now.items()):
            if (a, b) not in self.overlapping:
                self.found.add("overlap", f, b, f"it overlaps {a} at cell {list(c)}", other=a)
        self.overlapping = set(now)

    def concurrent(self, groups: list[tuple[list[int], Motion]], boxes: list[Any]) -> None:
        """Two groups moving at the same time: decided only when their swept boxes are apart."""
        for (_, g1), (_, g2), b1, b2 in (
            (p[0], q[0], p[1], q[1])
            for p, q in itertools.combinations(zip(groups, boxes, strict=True), 2)
        ):
            if g1.a >= g2.b or g2.a >= g1.b:
                continue
            if b1 is None or b2 is None or _boxes_meet(b1, b2):
                self.found.undecided.append(
                    {
                        "frame": max(g1.a, g2.a),
                        "pieces": sorted(g1.pieces + g2.pieces),
                        "reason": "two groups move at once and their swept regions may meet",
                    }
                )

    def between(self, a: int, b: int, j: int) -> tuple[int, str, Cell] | None:
        """The first frame strictly between ``a`` and ``b`` where piece ``j``, turned by a
        lattice rotation but off the lattice, overlaps a piece at rest (exact for unit cubes
        with parallel faces: open intervals per axis), with that piece and its cell."""
        ps = self.ps
        still = [o for o in range(len(ps.names)) if o != j and self.at_rest(o, a, b)]
        owner = {
            c: ps.names[o] for o in still if ps.lat[a, o] for c in cells_at(self.level, ps, a, o)
        }
        centres = self.voxels[ps.names[j]] + 0.5
        corners = np.array(list(itertools.product((0, 1), repeat=3)))
        for f in range(a + 1, b):
            r = ps.rot[f, j]
            if np.abs(r - np.rint(r)).max() > TOL:
                continue
            self.budget -= len(centres)
            if self.budget < 0:
                why = "too many poses between lattice frames to test for overlap"
                self.found.undecided.append({"frame": f, "pieces": [ps.names[j]], "reason": why})
                return None
            lows = centres @ r.T + ps.tr[f, j] - 0.5  # each cube's lowest corner
            for p in lows:
                for c in np.floor(p).astype(np.int64) + corners:
                    cell = (int(c[0]), int(c[1]), int(c[2]))
                    if cell in owner and bool((np.abs(p - c) < 1 - TOL).all()):
                        return f, owner[cell], cell
        return None

    def swapped(self, a: int, b: int, j: int) -> str | None:
        """The piece that ``j`` changes places with from ``a`` to ``b`` (poses or cells
        exchanged, where the two differed), or None."""
        ps = self.ps
        if not (ps.lat[a, j] and ps.lat[b, j]):
            return None
        lv = self.level
        for o in range(len(ps.names)):
            if o == j or not (ps.ok[a, o] and ps.ok[b, o] and ps.lat[a, o] and ps.lat[b, o]):
                continue
            if _same(ps, b, j, a, o) and _same(ps, b, o, a, j) and not _same(ps, a, j, a, o):
                return ps.names[o]
            mine, theirs = cells_at(lv, ps, a, j), cells_at(lv, ps, a, o)
            if (
                mine != theirs
                and cells_at(lv, ps, b, j) == theirs
                and cells_at(lv, ps, b, o) == mine
            ):
                return ps.names[o]
        return None

    def first_move(self, a: int, b: int, j: int) -> int:
        ps = self.ps
        for i in range(a + 1, b + 1):
            if (
                np.abs(ps.rot[i, j] - ps.rot[a, j]).max() > TOL
                or np.abs(ps.tr[i, j] - ps.tr[a, j]).max() > TOL
            ):
                return i
        return b

    def not_allowed(self, a: int, b: int, j: int, at: int, why: str, size: float) -> None:
        ps = self.ps
        name = ps.names[j]
        other = self.swapped(a, b, j)
        if other is not None:
            self.found.add(
                "swap",
                at,
                name,
                f"it takes {other}'s place and {other} takes its (identities swapped)",
                other=other,
            )
            return
        hit = self.between(a, b, j)
        if hit is not None:
            f, other, cell = hit
            reason = f"between lattice poses it overlaps {other} (at cell {list(cell)})"
            self.found.add("overlap", f, name, reason, other=other)
        elif "drifts" in why or "overshoots" in why:
            self.found.add("off-lattice", at, name, why)
        elif size > 1 + TOL:
            self.found.add(
                "teleport", at, name, f"it jumps {size:.3g} units in one frame and {why}"
            )
        else:
            self.found.add("motion", at, name, f"not an allowed motion: {why}")

    def grouped(self, moving: list[tuple[int, Motion]]) -> list[tuple[list[int], Motion]]:
        """Pieces moving with the same motion over the same frames, as one group each."""
        ps = self.ps
        groups: list[tuple[list[int], Motion]] = []
        for j, m in moving:
            for js, g in groups:
                same = dataclasses.replace(g, pieces=(), pivot=m.pivot) == dataclasses.replace(
                    m, pieces=()
                )
                if same and _same_motion(ps, m.a, m.b, j, js[0]):
                    js.append(j)
                    break
            else:
                groups.append(([j], m))
        return [
            (
                js,
                dataclasses.replace(m, pieces=tuple(sorted(ps.names[j] for j in js))),
            )
            for js, m in groups
        ]

    def sweep(self, js: list[int], m: Motion) -> tuple[Cell, Cell] | None:
        """Test the group's swept region against the pieces at rest meanwhile; its bounding
        box (None: not known)."""
        ps = self.ps
        a = m.a
        still = [
            o
            for o in range(len(ps.names))
            if o not in js and self.at_rest(o, a, m.b) and ps.lat[a, o]
        ]
        fixed = {c: ps.names[o] for o in still for c in cells_at(self.level, ps, a, o)}
        cells = [c for j in js for c in cells_at(self.level, ps, a, j)]
        size = max(jump(ps, a, m.b, j, self.voxels[ps.names[j]]) for j in js)
        at = min(self.first_move(a, m.b, j) for j in js)
        kind = "teleport" if size > 1 + TOL else "collision"
        verb = (
            f"jumps {size:.3g} units in one frame, through"
            if kind == "teleport"
            else "passes through"
        )
        if m.kind == "slide":
            hit = slide_hit(cells, fixed, m.axis, m.k)
            if hit is not None:
                self.found.add(
                    kind,
                    at,
                    m.pieces[0],
                    f"sliding {direction_name(m.axis, m.k)} {abs(m.k)} it {verb} {hit[0]} "
                    f"at cell {list(hit[1])}",
                    other=hit[0],
                    group=list(m.pieces),
                )
            arr = np.array(cells)
            shifted = arr.copy()
            shifted[:, m.axis] += m.k
            both = np.concatenate([arr, shifted])
            return _box(both)
        swept = turn_swept(self.level, ps, a, js, m)
        if swept is None:
            self.found.undecided.append(
                {
                    "frame": at,
                    "pieces": list(m.pieces),
                    "reason": "a turn too wide to sweep exactly",
                }
            )
            return None
        spin = {c for j in still for c in spinning_of(self.level, ps, a, j, m)}
        hits = sorted(c for c in swept if c in fixed and c not in spin)
        if hits:
            other = fixed[hits[0]]
            self.found.add(
                kind,
                at,
                m.pieces[0],
                f"turning about {AXES[m.axis]} it {verb} {other} at cell {list(hits[0])}",
                other=other,
                group=list(m.pieces),
            )
        return _box(np.array(sorted(swept))) if swept else None


def _merged(segments: list[list[Motion]]) -> list[list[Motion]]:
    """One slide passing a lattice pose without stopping (a lone group going on the same
    way in the next segment) is one move, not two."""
    out: list[list[Motion]] = []
    for seg in segments:
        if out and len(seg) == len(out[-1]) == 1:
            p, m = out[-1][0], seg[0]
            if (
                p.kind == m.kind == "slide"
                and p.b == m.a
                and (p.pieces, p.axis) == (m.pieces, m.axis)
                and p.k * m.k > 0
            ):
                out[-1] = [Motion(p.pieces, p.a, m.b, "slide", p.axis, k=p.k + m.k)]
                continue
        out.append(seg)
    return out


def _box(arr: Any) -> tuple[Cell, Cell]:
    lo, hi = arr.min(axis=0), arr.max(axis=0)
    return (int(lo[0]), int(lo[1]), int(lo[2])), (int(hi[0]), int(hi[1]), int(hi[2]))


def _boxes_meet(p: tuple[Cell, Cell], q: tuple[Cell, Cell]) -> bool:
    return all(p[0][i] <= q[1][i] and q[0][i] <= p[1][i] for i in range(3))


def _same(ps: Poses, f: int, j: int, g: int, o: int) -> bool:
    return bool(
        ps.lat[f, j]
        and ps.lat[g, o]
        and ps.ridx[f, j] == ps.ridx[g, o]
        and (ps.off[f, j] == ps.off[g, o]).all()
    )


def _same_motion(ps: Poses, a: int, b: int, j: int, k: int) -> bool:
    from chaingeo.worldmodel.trajectory_check import _relative

    rj, tj = _relative(ps, a, b, j)
    rk, tk = _relative(ps, a, b, k)
    return bool(np.abs(rj - rk).max() <= 1e-5 and np.abs(tj - tk).max() <= 1e-5)


_FORWARD = {"appear": "disappear", "disappear": "appear"}


def _forward(found: Findings, n_frames: int) -> None:
    """Frame numbers (and appear/disappear) of a backwards check, as the file runs: its start
    is the assembly's goal."""
    for v in found.violations:
        back = v["frame"]
        v["frame"] = n_frames - 1 - back
        if v["kind"] in _FORWARD and back > 0:  # a run of absence, seen from its other end
            v["kind"] = _FORWARD[v["kind"]]
            v["frame"] += 1
        if v["kind"] == "start" and v["frame"] == n_frames - 1 and v["piece"] is None:
            v["kind"], v["reason"] = (
                "goal",
                "the last frame misses the goal: it is not the assembled puzzle",
            )
    for u in found.undecided:
        u["frame"] = n_frames - 1 - u["frame"]


def check_trajectory(
    level: Level, traj: Trajectory, max_jump: float | None = None
) -> TrajectoryVerdict:
    """Check a trajectory against a level (see the module docstrings)."""
    found = Findings()
    backwards = level.family == "puzzle" and level.goal == "assemble"
    n_f = len(traj.frames)
    if backwards:
        traj = Trajectory(
            traj.level, traj.frames[::-1], tuple((n_f - 1 - f, n) for f, n in traj.duplicates)
        )
    if traj.level is not None and traj.level != level.id:
        found.add("level", 0, None, f"the trajectory names level {traj.level!r}, not {level.id!r}")
    ps = read_poses(level, traj, found)
    walk = _Segments(level, ps, found, max_jump)
    walk.run()
    plan: list[str] | None = None
    goal: bool | None = None
    structural = {
        "appear",
        "disappear",
        "duplicate",
        "shape",
        "motion",
        "teleport",
        "off-lattice",
        "swap",
    }
    if not any(v["kind"] in structural for v in found.violations):
        plan, goal = _replayed(level, ps, walk.motions, found)
        if backwards and goal is False:  # the disassembly does not end apart
            found.add("start", n_f - 1, None, "the first frame is not the pieces apart")
    if backwards:
        _forward(found, n_f)
        goal = None if goal is None else not any(v["kind"] == "goal" for v in found.violations)
    elif goal is False:
        words = (
            "the box is not full" if level.family == "stacking" else "the pieces are not all apart"
        )
        found.add("goal", n_f - 1, None, f"the last frame misses the goal: {words}")
    valid = not found.violations and not found.undecided
    return TrajectoryVerdict(valid, found.violations, found.undecided, plan, goal)


def _replayed(
    level: Level, ps: Poses, motions: list[list[Motion]], found: Findings
) -> tuple[list[str] | None, bool | None]:
    from chaingeo.envs.actions.types import action_of_move
    from chaingeo.worldmodel.trajectory_plan import (
        machine_problem,
        replay_puzzle,
        replay_stacking,
    )

    if level.family == "stacking":
        return replay_stacking(level, ps, motions, found)
    steps, goal = replay_puzzle(level, ps, motions, found)
    if steps is None:
        return None, None
    moves = steps if level.goal == "disassemble" else disassembly_of_assembly_plan(steps)
    texts = [action_of_move(m).to_text() for m in moves]
    if level.goal == "disassemble":
        problem = machine_problem(level, texts)
        if problem is not None:
            found.add(
                "illegal",
                0,
                None,
                f"the state machine refuses action {problem[0] + 1} "
                f"({texts[problem[0]]!r}): {problem[1]}",
            )
            return texts, goal
    return texts, goal
