"""Turns in the puzzle state machine (levels whose rules allow them).

A turn is legal exactly when :meth:`chaingeo.core.kinematics.Assembly.turn_problem` says so
(decided by its fast equal, :func:`chaingeo.solvers.motion.turnsearch.turn_problem`), in both goals:
it turns a proper group of one part (never a whole part: parts apart never interact, and assembling
is disassembly played backwards, where no part turns alone). Text may leave the centre open
(``rotate red z +90``): it resolves to the only legal centre for that group, axis and sense, else
it is ambiguous and lists the candidates, else illegal with the reason.
"""

from __future__ import annotations

from collections.abc import Hashable, Sequence

import numpy as np

from chaingeo.core.geometry import ROTATIONS, Cell, rotation_index
from chaingeo.core.kinematics import Assembly
from chaingeo.core.turns import AXES, TurnMove, lateral
from chaingeo.envs.actions.types import (
    AmbiguousActionError,
    IllegalActionError,
    TurnAction,
    TurnRequest,
    rules_text,
)
from chaingeo.solvers.motion.turnsearch import turn_problem as turn_sweep_problem

NO_TURNS = "this level does not allow turns; use move or finish"

#: A part in a position key: each piece's name and offset relative to the part's first piece,
#: and its relative orientation where not 0 (:func:`chaingeo.envs.machines.puzzle.normal_key`).
PartKey = tuple[tuple[str, Cell] | tuple[str, Cell, int], ...]


def turned_part_key(asm: Assembly, names: Sequence[str]) -> PartKey:
    """A part with turned pieces, seen from its first piece's pose (the whole part turned back
    so that piece stands as assembled): relative offsets and, where not 0, orientations."""
    back = ROTATIONS[asm.rotation_of(names[0])].T
    base = np.asarray(asm.offsets[names[0]], dtype=np.int64)
    out: list[tuple[str, Cell] | tuple[str, Cell, int]] = []
    for n in names:
        x, y, z = (int(v) for v in back @ (np.asarray(asm.offsets[n], dtype=np.int64) - base))
        r = rotation_index(back @ ROTATIONS[asm.rotation_of(n)])
        out.append((n, (x, y, z), r) if r else (n, (x, y, z)))
    return tuple(out)


def turn_problem(
    asm: Assembly, action: TurnAction, allowed: bool, max_group: int | None
) -> str | None:
    """Why the turn is illegal here (agent text, 1-based), or None."""
    if not allowed:
        return NO_TURNS
    turn = action.turn
    unknown = sorted(set(turn.pieces) - set(asm.shapes))
    if unknown:
        return f"unknown piece {unknown[0]!r}"
    if max_group is not None and len(turn.pieces) > max_group:
        return f"the rules let one move carry at most {max_group} piece(s)"
    parts = {asm.part_of(n) for n in turn.pieces}
    if len(parts) > 1:
        return f"{'+'.join(turn.pieces)} are in different parts; a turn carries one part"
    if parts.pop() == frozenset(turn.pieces):
        return f"{'+'.join(turn.pieces)} is a whole part: nothing to turn it against"
    why = turn_sweep_problem(asm, turn)
    return None if why is None else rules_text(why)


def resolve_turn(
    req: TurnRequest,
    listed: Sequence[TurnAction],
    asm: Assembly,
    allowed: bool,
    max_group: int | None,
    key: Hashable,
) -> TurnAction:
    """The action a turn request stands for (its centre filled in from the legal turns)."""
    text = req.text()
    if not allowed:
        raise IllegalActionError(NO_TURNS, text=text, state_key=key)
    if req.centre2 is not None:
        return TurnAction(TurnMove(req.pieces, req.axis, req.quarter, req.centre2))
    cands = [
        a
        for a in listed
        if a.turn.pieces == req.pieces and a.turn.axis == req.axis and a.turn.quarter == req.quarter
    ]
    if len(cands) == 1:
        return cands[0]
    if cands:
        raise AmbiguousActionError(text, cands, key)
    probe = TurnAction(TurnMove(req.pieces, req.axis, req.quarter, _middle(asm, req)))
    why = turn_problem(asm, probe, allowed, max_group)
    reason = (
        f"no line parallel to {req.axis} through its bounding box lets it turn "
        f"{'+90' if req.quarter == 1 else '-90'}"
    )
    if why is not None and "sweep" not in why:
        reason = why  # unknown pieces, a whole part, too many pieces...
    raise IllegalActionError(reason, text=text, state_key=key)


def _middle(asm: Assembly, req: TurnRequest) -> tuple[int, int, int]:
    """A valid centre near the middle of the group (only to ask why nothing works)."""
    cells = [c for n in req.pieces if n in asm.shapes for c in asm.cells_of(n)]
    a = AXES.index(req.axis)
    u, v = lateral(a)
    out = [0, 0, 0]
    if cells:
        for b in (u, v):
            out[b] = min(c[b] for c in cells) + max(c[b] for c in cells)
        if (out[u] - out[v]) % 2:
            out[v] += 1
    return (out[0], out[1], out[2])


def describe_turn(action: TurnAction) -> str:
    t = action.turn
    sense = "+90" if t.quarter == 1 else "-90"
    return f"OK: {'+'.join(t.pieces)} turned {sense} degrees about {t.axis}."
