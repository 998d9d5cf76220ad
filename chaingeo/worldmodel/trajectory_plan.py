"""The plan a checked trajectory realises, replayed by the reference kinematics.

Puzzles: each group motion is a move of the engine (:class:`chaingeo.core.kinematics.Assembly`);
a part already taken out of the rest moves freely as a whole (a displacement on top of the
engine's offsets, no step), and every segment's end is compared with the engine's cells.
Stacking: a piece that comes to rest inside the box is placed, one that leaves it is picked up,
both by the level's state machine.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from chaingeo.core.geometry import Cell
from chaingeo.core.kinematics import DIRECTIONS, Assembly, Move, MoveError
from chaingeo.core.level import Level
from chaingeo.core.turns import AXES, TurnMove
from chaingeo.worldmodel.trajectory_check import (
    Findings,
    Motion,
    Poses,
    cells_at,
    direction_name,
)

Step = Move | TurnMove


class _Replay:
    def __init__(self, level: Level, ps: Poses, found: Findings) -> None:
        self.level, self.ps, self.found = level, ps, found
        self.engine = Assembly.assembled(level.shapes, level.rods)
        self.disp: dict[str, np.ndarray] = {}
        self.steps: list[Step] = []

    def start(self) -> bool:
        """The first frame must be the assembled puzzle (moved as a whole by a lattice vector)."""
        ps = self.ps
        offsets = {tuple(ps.off[0, j]) for j in range(len(ps.names))}
        if not (
            ps.ok[0].all() and ps.lat[0].all() and (ps.ridx[0] == 0).all() and len(offsets) == 1
        ):
            self.found.add("start", 0, None, "the first frame is not the assembled puzzle")
            return False
        d0 = np.array(next(iter(offsets)), dtype=np.int64)
        self.disp = {n: d0.copy() for n in ps.names}
        return True

    def apply(self, m: Motion) -> bool:
        parts = [sorted(set(m.pieces) & p) for p in self.engine.parts]
        for sub in (s for s in parts if s):
            whole = set(sub) == self.engine.part_of(sub[0])
            d = self.disp[sub[0]]
            if m.kind == "slide":
                e = np.zeros(3, dtype=np.int64)
                e[m.axis] = m.k
                if whole:
                    for n in sub:
                        self.disp[n] = self.disp[n] + e
                    continue
                move: Step = Move(tuple(sub), direction_name(m.axis, m.k), abs(m.k))
            else:
                c2 = [round(2 * (m.pivot[i] - 0.5 - d[i])) for i in range(3)]
                c2[m.axis] = 0
                move = TurnMove(tuple(sub), AXES[m.axis], m.quarter, (c2[0], c2[1], c2[2]))
                if whole:
                    self.engine = self.engine.turned(move)
                    continue
            if not self.step(m, move):
                return False
        return self.agrees(m.b)

    def step(self, m: Motion, move: Step) -> bool:
        try:
            removes = self.engine.removes(move) if isinstance(move, Move) else False
            self.engine = self.engine.apply(move)
        except MoveError as e:
            self.found.add(
                "illegal",
                m.a + 1,
                move.pieces[0],
                f"the engine refuses it: {e}",
                group=list(move.pieces),
            )
            return False
        if removes:
            assert isinstance(move, Move) and move.distance is not None
            shift = np.array(DIRECTIONS[move.direction], dtype=np.int64) * move.distance
            for n in move.pieces:
                self.disp[n] = self.disp[n] + shift
        self.steps.append(move)
        return True

    def agrees(self, f: int) -> bool:
        for j, n in enumerate(self.ps.names):
            d = self.disp[n]
            want = {
                (x + int(d[0]), y + int(d[1]), z + int(d[2])) for x, y, z in self.engine.cells_of(n)
            }
            if want != cells_at(self.level, self.ps, f, j):
                self.found.add("replay", f, n, "the piece is not where the engine's replay puts it")
                return False
        return True


def replay_puzzle(
    level: Level, ps: Poses, motions: Sequence[Sequence[Motion]], found: Findings
) -> tuple[list[Step] | None, bool | None]:
    """(the disassembly's moves, whether it separates every piece), or (None, None) when the
    trajectory realises no plan of the engine."""
    run = _Replay(level, ps, found)
    if not run.start():
        return None, None
    for segment in motions:
        for m in segment:
            if not run.apply(m):
                return None, None
    return run.steps, run.engine.is_separated()


def machine_problem(level: Level, texts: Sequence[str]) -> tuple[int, str] | None:
    """(index, why) of the first action the level's state machine refuses, or None."""
    from chaingeo.envs.actions.parse import parse_action
    from chaingeo.envs.actions.types import ActionError
    from chaingeo.envs.machines import new_state

    state = new_state(level)
    for i, text in enumerate(texts):
        try:
            state.apply(parse_action(text, state))
        except ActionError as e:
            return i, str(e)
    return None


def _inside(cells: frozenset[Cell], box: Sequence[int]) -> bool:
    return all(0 <= c[i] < box[i] for c in cells for i in range(3))


def replay_stacking(
    level: Level, ps: Poses, motions: Sequence[Sequence[Motion]], found: Findings
) -> tuple[list[str] | None, bool | None]:
    """(the place and pickup actions, whether the box ends full), or (None, None)."""
    from chaingeo.envs.actions.types import ActionError, PickupAction, PlaceAction
    from chaingeo.envs.machines import new_state

    assert level.box is not None
    box = level.box
    state = new_state(level)
    start = [
        n
        for j, n in enumerate(ps.names)
        if any(_inside(frozenset([c]), box) for c in cells_at(level, ps, 0, j))
    ]
    if start:
        found.add("start", 0, start[0], "a piece is in the box at the start")
        return None, None
    placed: dict[str, frozenset[Cell]] = {}
    texts: list[str] = []
    for segment in motions:
        for m in segment:
            for n in m.pieces:
                j = ps.names.index(n)
                cells = cells_at(level, ps, m.b, j)
                actions: list[PickupAction | PlaceAction] = []
                if n in placed and placed[n] != cells:
                    actions.append(PickupAction(n))
                    del placed[n]
                if n not in placed and _inside(cells, box):
                    actions.append(PlaceAction(n, tuple(sorted(cells))))
                    placed[n] = cells
                for action in actions:
                    try:
                        state.apply(action)
                    except ActionError as e:
                        found.add(
                            "illegal",
                            m.a + 1,
                            n,
                            f"the state machine refuses {action.to_text()!r}: {e}",
                        )
                        return None, None
                    texts.append(action.to_text())
    return texts, state.is_success()
