"""The 3D player's picture of a state: every piece's cells, colour and place, as JSON.

The same scene the agent's pictures draw (:func:`chaingeo.envs.observation.scene`): a puzzle's
largest part where it is and every other part beside it along +x; a stacking level's placed
pieces in the box and the tray's pieces in a row in front of it (y below 0), each in the
orientation it is handed out. Cells are 0-based lattice cells (the browser draws unit cubes).
"""

from __future__ import annotations

from typing import Any, Final

from chaingeo.core.geometry import Shape
from chaingeo.envs.machines.state import BaseState
from chaingeo.envs.observation import ordered_parts, scene

#: Empty cells between tray pieces, and between the tray and the box.
TRAY_GAP: Final = 1


def _cells(shape: Shape) -> list[list[int]]:
    return [list(c) for c in shape.cells]


def _tray(tray: dict[str, tuple[Shape, str]]) -> dict[str, Shape]:
    """The tray's pieces in a row along +x, in front of the box (their largest y is -1 - gap)."""
    out: dict[str, Shape] = {}
    cursor = 0
    for name in sorted(tray):
        shape = tray[name][0]
        lo, hi = shape.min_corner, shape.extent
        out[name] = shape.translate(
            (cursor - int(lo[0]), -TRAY_GAP - int(hi[1]) - int(lo[1]), -int(lo[2]))
        )
        cursor += int(hi[0]) + TRAY_GAP
    return out


def scene_json(state: BaseState) -> dict[str, Any]:
    """``{"box": [a,b,c] or None, "turns": whether the rules allow turns, "pieces": [{name, rgb,
    cells, place, part}]}`` in the level's piece order; ``place`` is ``box`` / ``tray``
    (stacking) or ``puzzle``, ``part`` a puzzle piece's part (0 the largest)."""
    placed, box, tray = scene(state)
    trayed = _tray(tray)
    part_of: dict[str, int] = {}
    if state.level.family == "puzzle":
        for i, part in enumerate(ordered_parts(state)):
            part_of.update(dict.fromkeys(part, i))
    pieces = []
    for p in state.level.pieces:
        if p.name in placed:
            shape, place = placed[p.name][0], "box" if box is not None else "puzzle"
        else:
            shape, place = trayed[p.name], "tray"
        entry: dict[str, Any] = {
            "name": p.name,
            "rgb": p.rgb,
            "cells": _cells(shape),
            "place": place,
            "part": part_of.get(p.name),
        }
        if p.chain_id is not None:
            entry["chain_id"] = p.chain_id
        if place == "tray":
            entry["shape"] = _cells(state.level.piece(p.name).shape)
        pieces.append(entry)
    turns = bool(getattr(state.level.rules, "turns", False))
    return {"box": list(box) if box is not None else None, "turns": turns, "pieces": pieces}
