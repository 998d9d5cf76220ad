"""Breadth-first search of one part with translations *and* turns (levels whose rules allow
turns; the translation-only search stays :class:`chaingeo.solvers.motion.partsearch.PartSearch`).

A turned piece changes orientation, so a state is every piece's *pose*: a rotation index (into
:data:`chaingeo.core.geometry.ROTATIONS`) and an offset, pieces pre-rotated in
:class:`chaingeo.solvers.motion.turns_kernel.TurnTable`. The first piece (the anchor) never moves:
when
it belongs to the group that moves, the rest moves the opposite way (for a turn: turns back about
the same line), which is the same relative motion. States are therefore seen in a *search frame*
that differs from the real positions by a rigid motion ``T`` (a rotation and a translation, in
doubled cell units), tracked along each path: a move recorded in the search frame is reported
as the group's own move mapped by ``T``, and when the anchor's group moved, ``T`` composes with
that motion. Removals, plans and the poses handed to sub-searches are all in real coordinates,
so they replay as they are with :mod:`chaingeo.core.kinematics`.

Same interface as :class:`~chaingeo.solvers.motion.partsearch.PartSearch` (poses are ``(n, 4)``
rows: offset, then rotation index); the expansion is the numba kernel
:func:`chaingeo.solvers.motion.turns_kernel.expand_turns`.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from chaingeo.core.geometry import ROTATIONS, rotation_index
from chaingeo.core.kinematics import DIRECTIONS, Assembly, Move, SearchLimitError
from chaingeo.core.turns import AXES, TurnMove, centre_inside, lateral
from chaingeo.kernels.jit import Pinned
from chaingeo.solvers.motion import bfs_kernel as bfs
from chaingeo.solvers.motion import kinematics_kernel as mv
from chaingeo.solvers.motion import turns_kernel as tm
from chaingeo.solvers.motion.partsearch import LayeredSearch, Removal, Split
from chaingeo.solvers.motion.turns_sweep_kernel import FAR_LIMIT, Stencils, stencils, swept_through

_DIR_NAMES: tuple[str, ...] = tuple(DIRECTIONS)
_DIR_VECS = np.array([DIRECTIONS[d] for d in _DIR_NAMES], dtype=np.int64)

#: A rigid motion in doubled cell units: ``x -> R x + t``.
Frame = tuple[np.ndarray, np.ndarray]


def _direction(vec: np.ndarray) -> int:
    return int(np.flatnonzero(np.all(vec == _DIR_VECS, axis=1))[0])


#: :func:`chaingeo.solvers.motion.turns_kernel.expand_turns` as :class:`TurnPartSearch` calls it:
#: the types of its arguments are fixed by TurnPartSearch's constructor (see :class:`Pinned`).
_expand_turns = Pinned(tm.expand_turns)


class TurnPartSearch(LayeredSearch[tm.TurnTable]):
    """Layered breadth-first search of one part from one configuration, turns included."""

    CHUNK = 2000

    def _begin(self, poses: np.ndarray) -> None:
        n, limits = self.n, self.limits
        self.vox, self.starts, self.lo, self.hi, self.rod = self.table.part_arrays(self.members)
        cap = max(2, min(1024, limits.max_states))
        self.states = np.zeros((cap, 4 * n), dtype=np.int16)
        self.parent = np.full(cap, -1, dtype=np.int64)
        self.move = np.zeros((cap, 5), dtype=np.int64)
        self.hash = np.full(1 << (4 * cap - 1).bit_length(), -1, dtype=np.int64)
        self.seps = np.zeros((256, 3), dtype=np.int64)
        self.moves_buf = np.zeros((256, 4), dtype=np.int64)
        self.turns_buf = np.zeros((256, 6), dtype=np.int64)
        self.groups_buf = np.zeros(min(limits.group_limit, 1 << 16) + 1, dtype=np.uint64)
        start = np.asarray(poses, dtype=np.int64).reshape(n, 4)
        self.origin = start[0, :3].copy()  # the anchor's real offset: T starts as this shift
        row = np.concatenate([(start[:, :3] - self.origin).reshape(-1), start[:, 3]])
        mv.find_or_insert(self.states, 0, self.hash, row.astype(np.int16))
        self.layers: list[int] = [0, 1]

    @property
    def depth(self) -> int:
        return len(self.layers) - 2

    @property
    def exhausted(self) -> bool:
        return self.layers[-1] == self.layers[-2]

    def _grow_states(self) -> None:
        cap = self.states.shape[0]
        if self.n_states + 1 >= cap:
            new_cap = self.next_capacity(cap)
            self.states = np.concatenate([self.states, np.zeros_like(self.states)])[:new_cap]
            self.parent = np.concatenate([self.parent, np.full(cap, -1, dtype=np.int64)])[:new_cap]
            self.move = np.concatenate([self.move, np.zeros_like(self.move)])[:new_cap]
        if self.hash.shape[0] < 4 * self.states.shape[0]:
            size = 1 << (4 * self.states.shape[0] - 1).bit_length()
            self.hash = np.full(size, -1, dtype=np.int64)
            mv.rebuild_table(self.states, self.n_states, self.hash)

    def expand_layers(self, max_depth: int | None = None) -> list[Removal]:
        """Layer after layer up to the first with removals (returned); ``[]`` once every state
        is expanded or the next layer would be deeper than ``max_depth`` (as
        :meth:`chaingeo.solvers.motion.partsearch.PartSearch.expand_layers`)."""
        while not self.exhausted and (max_depth is None or self.depth <= max_depth):
            found = self.expand_layer()
            if found:
                return found
        return []

    def expand_layer(self) -> list[Removal]:
        """Expand the deepest layer; return its removals (directions in the search frame)."""
        d = self.depth
        lo, hi = self.layers[d], self.layers[d + 1]
        first_sep = self.n_seps
        node = lo
        while node < hi:
            self.deadline.check()
            end = min(hi, node + self.chunk)
            tree = bfs.Tree(self.states, self.parent, self.move, self.hash)
            pieces = tm.TurnPieces(
                self.vox, self.starts, self.lo, self.hi, self.rod, self.max_group,
                self.group_limit, self.moves_buf, self.turns_buf, self.groups_buf,
            )  # fmt: skip
            status, node, self.n_states, self.n_seps, _ = _expand_turns(
                tree, self.n_states, node, end, pieces, stencils().arrays, self.seps, self.n_seps
            )
            if status == bfs.NEED_STATES:
                self._grow_states()
            elif status == bfs.NEED_MOVES:
                self.moves_buf = np.zeros((2 * self.moves_buf.shape[0], 4), dtype=np.int64)
            elif status == tm.NEED_TURNS:
                self.turns_buf = np.zeros((2 * self.turns_buf.shape[0], 6), dtype=np.int64)
            elif status == bfs.NEED_SEPS:
                self.seps = np.concatenate([self.seps, np.zeros_like(self.seps)])
            elif status == tm.TOO_FAR:
                raise SearchLimitError(
                    f"pieces more than {FAR_LIMIT // 2} cells from a turn's axis: beyond the "
                    "exact integer range of the turn kernel"
                )
            elif status == bfs.TOO_MANY_GROUPS:
                raise SearchLimitError(
                    f"more than {self.limits.group_limit} movable groups of one move in one state",
                    "group_limit",
                )
        self.layers.append(self.n_states)
        return [
            Removal(int(s[0]), d, int(s[1]), int(s[2])) for s in self.seps[first_sep : self.n_seps]
        ]

    # -- from the search frame to real coordinates ------------------------------------------
    def _pieces(self, mask: int) -> tuple[str, ...]:
        names = self.table.names
        return tuple(names[self.members[i]] for i in range(self.n) if mask >> i & 1)

    def _walk(self, node: int) -> tuple[list[Move | TurnMove], Frame]:
        """The real moves from the start to ``node`` and the frame ``T`` at ``node``."""
        edges: list[int] = []
        while node > 0:
            edges.append(node)
            node = int(self.parent[node])
        rot = np.eye(3, dtype=np.int64)
        shift = 2 * self.origin
        out: list[Move | TurnMove] = []
        for e in reversed(edges):
            mask, kind, p0, p1, p2 = (int(v) for v in self.move[e])
            anchor = bool(mask & 1)
            if kind < tm.TURN_BASE:
                vec = rot @ _DIR_VECS[kind]
                out.append(Move(self._pieces(mask), _DIR_NAMES[_direction(vec)], p0))
                if anchor:
                    shift = shift + 2 * p0 * vec
                continue
            axis, sense = divmod(kind - tm.TURN_BASE, 2)
            centre = np.array([p0, p1, p2], dtype=np.int64)
            col = rot[:, axis]
            real_axis = int(np.flatnonzero(col)[0])
            quarter = (1 if sense == 0 else -1) * int(col[real_axis])
            real_centre = rot @ centre + shift
            real_centre[real_axis] = 0
            out.append(
                TurnMove(
                    self._pieces(mask),
                    AXES[real_axis],
                    quarter,
                    (int(real_centre[0]), int(real_centre[1]), int(real_centre[2])),
                )
            )
            if anchor:
                q = ROTATIONS[int(tm.QUARTERS[axis, sense])]
                shift = rot @ (centre - q @ centre) + shift
                rot = rot @ q
        return out, (rot, shift)

    def path_to(self, node: int) -> list[Move | TurnMove]:
        """The moves (real coordinates) from the start state to ``node``."""
        return self._walk(node)[0]

    def removal_move(self, removal: Removal) -> Move:
        """The removal as a move in real coordinates."""
        rot, _ = self._walk(removal.node)[1]
        vec = rot @ _DIR_VECS[removal.direction]
        return Move(self._pieces(removal.mask), _DIR_NAMES[_direction(vec)], None)

    def poses_of(self, node: int) -> np.ndarray:
        """Every piece's real pose at ``node``: ``(n, 4)`` rows of offset and rotation."""
        rot, shift = self._walk(node)[1]
        row = self.states[node].astype(np.int64)
        out = np.zeros((self.n, 4), dtype=np.int64)
        for i in range(self.n):
            out[i, :3] = (rot @ (2 * row[3 * i : 3 * i + 3]) + shift) // 2
            out[i, 3] = rotation_index(rot @ ROTATIONS[int(row[3 * self.n + i])])
        return out

    def unique_splits(self, removals: Sequence[Removal]) -> list[Split]:
        """The removals that lead to different sub-problems (which pieces go, and the poses of
        both sides relative to their first pieces, in the search frame), first kept, in order."""
        n = self.n
        full = (1 << n) - 1
        seen: set[tuple[int, bytes]] = set()
        out: list[Split] = []
        for r in removals:
            canon = min(r.mask, full ^ r.mask)
            row = self.states[r.node].astype(np.int64)
            off = row[: 3 * n].reshape(n, 3)
            key = b""
            for side in (canon, full ^ canon):
                idx = [i for i in range(n) if side >> i & 1]
                key += (off[idx] - off[idx[0]]).tobytes() + row[3 * n + np.array(idx)].tobytes()
            if (canon, key) in seen:
                continue
            seen.add((canon, key))
            poses = self.poses_of(r.node)
            inside = [i for i in range(n) if r.mask >> i & 1]
            outside = [i for i in range(n) if not r.mask >> i & 1]
            out.append(
                Split(
                    r,
                    tuple(self.members[i] for i in inside),
                    poses[inside],
                    tuple(self.members[i] for i in outside),
                    poses[outside],
                )
            )
        return out


# -------------------------------------------------------------------------------------------
# Per-state turns (for environments and for the conformance tests against the reference)
# -------------------------------------------------------------------------------------------


def turn_rows(
    state: Assembly,
    max_group: int | None,
    table: tm.TurnTable,
    group_limit: int = 4096,
    st: Stencils | None = None,
) -> list[tuple[tuple[str, ...], np.ndarray]]:
    """The legal turns of ``state`` in the kernel's raw form: per part of two or more pieces,
    its piece names (sorted) and int64 rows ``(mask, axis, sense, c0, c1, c2)`` (see
    :func:`chaingeo.solvers.motion.turns_kernel.node_turns`). ``table`` holds the state's pieces and
    rods; ``st`` is the stencil table (the one of
    :func:`chaingeo.solvers.motion.turns_sweep_kernel.stencils`
    unless a test asks for another reach)."""
    out: list[tuple[tuple[str, ...], np.ndarray]] = []
    st = stencils() if st is None else st
    for part in sorted(state.parts, key=lambda p: sorted(p)):
        if len(part) < 2:
            continue
        names = tuple(sorted(part))
        members = [table.names.index(p) for p in names]
        vox_all, starts_all, lo_all, hi_all, rod_all = table.part_arrays(members)
        rot = np.array([state.rotation_of(p) for p in names], dtype=np.int64)
        vox, starts, lo, hi, rod = tm.gather(vox_all, starts_all, lo_all, hi_all, rod_all, rot)
        off = np.array([state.offsets[p] for p in names], dtype=np.int64)
        groups = np.zeros(group_limit + 1, dtype=np.uint64)
        while True:
            buf = table.rows_buf
            rows = tm.node_turns(
                vox, starts, lo, hi, rod, off, st.start, st.end, st.cells, st.bound,
                -1 if max_group is None else max_group, group_limit, groups, buf,
            )  # fmt: skip
            if rows != -1:
                break
            table.rows_buf = np.zeros((2 * buf.shape[0], 6), dtype=np.int64)
        if rows == -2:
            raise SearchLimitError(f"more than {group_limit} groups of one turn in one state")
        if rows == -3:
            raise SearchLimitError(
                f"pieces more than {FAR_LIMIT // 2} cells from a turn's axis: beyond the exact "
                "integer range of the turn kernel"
            )
        out.append((names, buf[:rows].copy()))
    return out


def fast_legal_turns(
    state: Assembly,
    max_group: int | None = None,
    table: tm.TurnTable | None = None,
    st: Stencils | None = None,
) -> list[TurnMove]:
    """Every legal turn of ``state``, as :func:`chaingeo.core.kinematics.legal_turns` lists
    them, computed by the numba kernel (stencils from ``st``, as :func:`turn_rows`)."""
    table = tm.TurnTable(state.shapes, state.rods) if table is None else table
    out: list[TurnMove] = []
    for names, rows in turn_rows(state, max_group, table, st=st):
        for mask, axis, sense, c0, c1, c2 in rows.tolist():
            pieces = tuple(names[i] for i in range(len(names)) if mask >> i & 1)
            out.append(TurnMove.listed(pieces, AXES[axis], 1 - 2 * sense, (c0, c1, c2)))
    return sorted(out)


def turn_problem(state: Assembly, move: TurnMove) -> str | None:
    """:meth:`chaingeo.core.kinematics.Assembly.turn_problem` (the same answer, the same words)
    from the exact pair test of :mod:`chaingeo.solvers.motion.turns_sweep_kernel`, whose cost does
    not grow with
    how far the group stands from the axis (the reference lists every cell each cell sweeps)."""
    a = move.axis_index
    group = [c for n in move.pieces for c in state.cells_of(n)]
    if not centre_inside(group, a, move.centre2):
        return "the axis must pass through the group's bounding box"
    spin = state.spinning(move.pieces, a, move.centre2)
    moving = np.array([c for c in group if c not in spin], dtype=np.int64).reshape(-1, 3)
    centre = np.array(move.centre2, dtype=np.int64)
    lat = list(lateral(a))
    if moving.size and int(np.abs(2 * moving[:, lat] - centre[lat]).max()) > FAR_LIMIT:
        return state.turn_problem(move)  # beyond the int64 range: the reference decides
    sense = 0 if move.quarter == 1 else 1
    for other in sorted(state.part_of(move.pieces[0]) - set(move.pieces)):
        fixed = sorted(state.cells_of(other) - state.spinning([other], a, move.centre2))
        cells = np.array(fixed, dtype=np.int64).reshape(-1, 3)
        flags = swept_through(moving, cells, a, sense, centre)
        hit = spin.intersection(fixed) | {
            f for f, h in zip(fixed, flags.tolist(), strict=True) if h
        }
        if hit:
            return f"it would sweep through {other} at {min(hit)}"
    return None
