"""BurrTools' verdict on many assemblies of one packing, straight from the assembler's rows.

Counting solutions asks the same question of every assembly: does BurrTools' first-separation
disassembler (:func:`chaingeo.solvers.motion.btsearch.first_tree`) take it apart? The general path
builds named shapes, the symmetric image BurrTools reports
(:class:`chaingeo.solvers.assembly.btassemble.BTFrame`), a
:class:`chaingeo.solvers.motion.partsearch.PieceTable` and a decoded tree for each one (~0.1 ms of
Python a time). Here the same image is chosen on row indices (a symmetry maps rows to rows:
:meth:`chaingeo.solvers.cover.constrained.Packing.row_maps`), every row's voxels are sorted for the
gap kernel once, and one kernel call gathers the pieces and runs the disassembler. Whatever this
path does not model (a symmetry image outside the rows, a search past its node budget or a cap) goes
to the general path, which answers exactly as before.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from chaingeo.core.arrays import I32, I64
from chaingeo.core.geometry import Shape
from chaingeo.core.kinematics import SearchLimitError
from chaingeo.kernels.jit import njit
from chaingeo.solvers.assembly.btassemble import (
    BTFrame,
    Mirrors,
    choose_anchor,
    disassemble,
    iter_classes,
    named_assembly,
    piece_groups,
)
from chaingeo.solvers.assembly.btparallel import (
    NO,
    STUCK,
    YES,
    verdicts,
)
from chaingeo.solvers.cover.constrained import Packing
from chaingeo.solvers.deadline import Deadline
from chaingeo.solvers.jobs import check_jobs
from chaingeo.solvers.limits import SearchLimits
from chaingeo.solvers.motion import btsearch as bt
from chaingeo.solvers.motion import kinematics_kernel as mv
from chaingeo.solvers.motion import levelsearch as ls
from chaingeo.solvers.motion.disassemble import KERNEL_NODES, Analysis, Separations

#: Placement keys ``(transformation, x, y, z)`` packed into one ordered integer.
_BIAS = 1 << 15
_UNKNOWN = -1


@njit(cache=True)
def rows_tree(
    rows: I64, row_ptr: I64, row_vox: I64, row_lo: I64, row_hi: I64, params: I64, ctx: I64,
    nodes: I64, moves: I64,
) -> int:  # fmt: skip
    """:func:`chaingeo.solvers.motion.btsearch.first_tree` of the pieces placed by ``rows`` (in
    BurrTools' piece order), gathered from every row's pre-sorted voxels (``row_vox[a]``, rows
    ``row_ptr[r]:row_ptr[r + 1]``) and bounding boxes."""
    vox, starts, lo, hi = ls.part_arrays(row_vox, row_ptr, row_lo, row_hi, rows)
    start = np.zeros((rows.shape[0], 3), dtype=np.int64)
    return bt.first_tree(vox, starts, lo, hi, start, params, ctx, nodes, moves)


def level_of(nodes: I64, root: int) -> str:
    """BurrTools' level string of a :func:`rows_tree` tree (as
    :meth:`chaingeo.solvers.motion.disassemble.Separation.level_text`)."""
    multi: dict[int, bool] = {}

    def has_multi(i: int) -> bool:
        if i < 0:
            return False
        if i not in multi:
            _, length, removed, left = (int(v) for v in nodes[i])
            multi[i] = length > 1 or has_multi(left) or has_multi(removed)
        return multi[i]

    def text(i: int) -> str:
        _, length, removed, left = (int(v) for v in nodes[i])
        out = str(length)
        for sub in (left, removed):
            if has_multi(sub):
                out += "." + text(sub)
        return out

    return text(root)


class RowVerdicts:
    """BurrTools' verdict on assemblies of ``packing`` given as rows (no piece groups).

    ``verdict(rows)`` is True (a solution), False (none) or None (not decided here: ask the
    general path); :attr:`level` then holds the solution's level string when asked for."""

    def __init__(
        self,
        packing: Packing,
        limits: SearchLimits | None,
        want_levels: bool,
        frame: BTFrame | None = None,
    ) -> None:
        self.packing = packing
        self.want_levels = want_levels
        problem = packing.problem
        self.row_ptr = np.ascontiguousarray(problem.row_ptr, dtype=np.int64)
        every = problem.target.voxels.astype(np.int64)[problem.flat_cells]
        self.row_vox: I64 = (
            mv.sort_axes(every, self.row_ptr) if len(every) else np.zeros((3, 0, 3), np.int64)
        )
        self.row_lo = np.minimum.reduceat(every, self.row_ptr[:-1], axis=0)
        self.row_hi = np.maximum.reduceat(every, self.row_ptr[:-1], axis=0)
        self.row_type = problem.row_type.astype(np.int64)
        self.piece = self.row_type != packing.hole_type
        frame = BTFrame(packing) if frame is None else frame  # the caller's, when it has one
        self.image = frame.image
        self.type_slot = {t: packing.problem.types[t].slots[0] for t, _ in frame.types}
        reflections = len(self.image.symmetries) == len(packing.symmetries)
        self.maps = packing.row_maps(reflections).astype(np.int64)
        self.keys = np.full(packing.n_rows, _UNKNOWN, dtype=np.int64)
        self._orient_keys: dict[int, tuple[I64, I64]] = {}
        self.shared = {t: self.image.shared[slot] for t, slot in self.type_slot.items()}
        lim = limits or SearchLimits()
        total = -1 if lim.max_total_states is None else lim.max_total_states
        self.params = np.array(
            [lim.max_states, lim.group_limit, KERNEL_NODES, total], dtype=np.int64
        )
        self.level: str | None = None

    def _key(self, rows: I64) -> I64:
        """Each row's BurrTools placement key as one ordered integer (computed once a row).

        A row is an orientation of its type's table moved by its offset, so its key is the
        orientation's (BurrTools' rotation, its origin) moved by the same offset: one
        :meth:`BTImage.placement_key` per orientation met, the rest in numpy."""
        keys = self.keys[rows]
        todo = np.unique(rows[keys == _UNKNOWN])
        if len(todo):
            problem = self.packing.problem
            types = self.row_type[todo]
            for t in np.unique(types).tolist():
                mine = todo[types == t]
                local = mine - int(problem.row_start[t])
                table = problem.table[t]
                rot, origin = self._orientation_keys(t)
                o = table.orientation[local]
                p = table.offset[local] + origin[o] + _BIAS
                self.keys[mine] = (((rot[o] << 16 | p[:, 0]) << 16 | p[:, 1]) << 16) | p[:, 2]
        return self.keys[rows]

    def _orientation_keys(self, t: int) -> tuple[I64, I64]:
        """Per orientation of type ``t``'s table (at the origin): BurrTools' rotation and where
        the shape's origin lands (cached a type)."""
        hit = self._orient_keys.get(t)
        if hit is None:
            orients = self.packing.problem.table[t].orientations
            arr = self.image.placement_keys(
                self.type_slot[t], np.stack([o.voxels for o in orients])
            )
            hit = self._orient_keys[t] = (arr[:, 0], arr[:, 1:])
        return hit

    def image_rows(self, rows: I64) -> I64 | None:
        """The rows of the image BurrTools disassembles
        (:class:`chaingeo.solvers.motion.btorient.BTImage`), copies of a type ranked by placement;
        None where a symmetry leaves the rows."""
        if len(self.image.symmetries) < 2:
            return rows
        imgs = self.maps[:, rows]
        if np.any(imgs < 0):
            return None
        keys = self._key(imgs.reshape(-1)).reshape(imgs.shape)
        types = self.row_type[rows]
        bounds = np.flatnonzero(np.diff(types)) + 1
        segments = np.split(np.arange(len(rows)), bounds)
        if len(segments) < len(rows):
            for seg in segments:
                if len(seg) > 1:
                    keys[:, seg] = np.sort(keys[:, seg], axis=1)
        else:  # one piece a type: the pivot (fewest symmetries shared with the result) first
            at = int(np.argmin([self.shared[int(t)] for t in types]))
            keys = keys[:, [at, *range(at), *range(at + 1, len(rows))]]
        best = int(np.lexsort(keys.T[::-1])[0])
        image: I64 = imgs[best]
        for seg in segments:
            if len(seg) > 1:
                image[seg] = image[seg][np.argsort(self._key(image[seg]), kind="stable")]
        return image

    def verdict(self, rows: I32) -> bool | None:
        """Whether BurrTools takes the assembly ``rows`` apart (None: not decided here)."""
        self.level = None
        pieces = rows[self.piece[rows]].astype(np.int64)
        if len(pieces) < 2:
            return False  # BurrTools: one piece is no disassembly (disassembler_a.cpp)
        image = self.image_rows(pieces)
        if image is None:
            return None
        ctx = np.zeros(7, dtype=np.int64)
        cap = 4 * len(pieces)
        nodes = np.zeros((cap, 4), dtype=np.int64)
        moves = np.zeros((16 * cap, 3), dtype=np.int64)
        root = rows_tree(
            np.ascontiguousarray(image), self.row_ptr, self.row_vox, self.row_lo, self.row_hi,
            self.params, ctx, nodes, moves,
        )  # fmt: skip
        if ctx[ls.STATUS] != 0:
            return None  # buffers, node budget or a cap: the general path says what happens
        if root < 0:
            return False
        if self.want_levels:
            self.level = level_of(nodes, root)
        return True


class StuckCheck:
    """:func:`chaingeo.solvers.motion.kinematics_kernel.stuck` on a packing's rows: an assembly in
    which
    nothing can move is no solution, so its disassembly search (~0.1 ms of setup) is never built."""

    def __init__(self, packing: Packing) -> None:
        problem = packing.problem
        vox = problem.target.voxels.astype(np.int64)
        lo = vox.min(axis=0) if len(vox) else np.zeros(3, dtype=np.int64)
        self.box = (vox.max(axis=0) - lo + 1) if len(vox) else np.ones(3, dtype=np.int64)
        self.pos = (vox - lo) @ np.array([self.box[1] * self.box[2], self.box[2], 1])
        self.row_ptr = problem.row_ptr
        self.cells = problem.flat_cells
        self.piece = problem.row_type != packing.hole_type

    def __call__(self, rows: I32) -> bool:
        return bool(mv.stuck(self.pos, self.box, self.row_ptr, self.cells, rows[self.piece[rows]]))


class WorkerChecks:
    """How a worker builds its checks of one packing (picklable, for spawned workers)."""

    def __init__(self, packing: Packing, limits: SearchLimits | None, want_levels: bool) -> None:
        self.packing = packing
        self.limits = limits
        self.want_levels = want_levels

    def __call__(self) -> tuple[StuckCheck, RowVerdicts]:
        return StuckCheck(self.packing), RowVerdicts(self.packing, self.limits, self.want_levels)


@dataclass(frozen=True)
class BTReport:
    assemblies: int
    solutions: int
    first_packing: dict[str, Shape] | None
    first_analysis: Analysis | None
    seconds: float
    anchor: str | None
    limit: SearchLimitError | None = None  # the cap that ended a partial count

    @property
    def complete(self) -> bool:
        """Whether every assembly was counted (else the counts are lower bounds)."""
        return self.limit is None


def count_bt(
    packing: Packing,
    *,
    mirrors: Mirrors = "keep",
    max_group: int | None = None,
    limits: SearchLimits | None = None,
    node_limit: int | None = None,
    deadline: Deadline | None = None,
    separations: Separations = "first",
    levels: list[str] | None = None,
    partial: bool = False,
    fast: bool = True,
    jobs: int | None = 1,
) -> BTReport:
    """BurrTools' assemblies and solutions of a packing, and the first solution. The search
    and every disassembly share ``deadline`` (default: one of ``limits.seconds``; without
    ``limits`` the enumeration has no time limit and each disassembly the default one).
    ``separations``: see :func:`chaingeo.solvers.motion.disassemble.analyze_assembly`; ``levels``,
    when
    given, gets every solution's level string in the order found. A cap reached raises its
    :class:`SearchLimitError`, or with ``partial`` ends the count: the report then holds what
    was counted (lower bounds) and the error. The running counts are kept in the deadline's
    :class:`chaingeo.solvers.deadline.Progress` as the search goes. ``fast``: BurrTools' verdicts on
    rows (:class:`RowVerdicts`) where they apply; False sends every assembly through the
    general path (the two are compared in the tests). ``jobs``: processes that take the
    assemblies apart (None: the machine's cores; :mod:`chaingeo.solvers.assembly.btparallel`),
    the same figures whatever it is."""
    start = time.perf_counter()
    if deadline is None and limits is not None:
        deadline = Deadline(limits.seconds)
    tally = _Tally(levels)
    anchor = choose_anchor(packing) if packing.n_rows else None
    groups = piece_groups(packing)
    # With piece groups a part may be done without moving (pieces of one group stay together).
    stuck = None if groups.any() else StuckCheck(packing)
    classes = iter_classes(
        packing, mirrors=mirrors, node_limit=node_limit, anchor=anchor, deadline=deadline
    )
    frame = BTFrame(packing) if separations == "first" else None
    on_rows = None
    if fast and frame is not None and stuck is not None:
        on_rows = RowVerdicts(packing, limits, levels is not None, frame)
    counts = deadline.progress.counts if deadline is not None else {}
    limit: SearchLimitError | None = None
    worker = None
    if on_rows is not None:
        worker = WorkerChecks(packing, limits, levels is not None)
    stream = verdicts(
        classes, stuck, on_rows, jobs=check_jobs(jobs), deadline=deadline, worker=worker
    )
    try:
        for rows, code, level in stream:
            tally.assemblies += 1
            counts["assemblies"] = tally.assemblies
            if code in (STUCK, NO):
                continue
            if code == YES and tally.first is not None:
                tally.solution(level, counts)
                continue
            asm = named_assembly(packing, rows)
            if frame is not None:
                if len(asm) < 2:
                    continue  # BurrTools: one piece is no disassembly (disassembler_a.cpp)
                asm = frame(asm)
            result = disassemble(
                packing, asm, max_group=max_group, limits=limits, groups=groups,
                deadline=deadline, separations=separations,
            )  # fmt: skip
            if result.disassemblable:
                tally.solution(result.level, counts)
                if tally.first is None:
                    tally.first, tally.first_analysis = asm, result
    except SearchLimitError as e:
        if not partial:
            raise
        limit = e  # an assembly being taken apart then is counted, its verdict is not
    finally:
        stream.close()  # stops the workers, if any
    label = None if anchor is None else anchor.label
    seconds = time.perf_counter() - start
    return BTReport(
        tally.assemblies, tally.solutions, tally.first, tally.first_analysis, seconds, label, limit
    )


@dataclass
class _Tally:
    """The running counts of :func:`count_bt`."""

    levels: list[str] | None
    assemblies: int = 0
    solutions: int = 0
    first: dict[str, Shape] | None = None
    first_analysis: Analysis | None = None

    def solution(self, level: str | None, counts: dict[str, int]) -> None:
        self.solutions += 1
        counts["solutions"] = self.solutions
        if self.levels is not None:
            self.levels.append(level or "")
