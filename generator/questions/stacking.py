"""Stacking questions about one placement of a tray piece: fits, supported, completes,
dead-end.

The candidate placements are every orientation of the piece at every offset that keeps its
bounding box within one cell of the box, so a wrong option is a near miss: one cell out of the
box, onto a filled cell, floating one cell up, or legal but leaving a space the rest cannot
fill. ``completes``/``dead-end`` are decided by exact cover of the empty cells by the pieces
left in the tray (:func:`chaingeo.solvers.cover.packings.first_packing`: a packing, or a proof
there is none).
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

import numpy as np

from chaingeo.core.geometry import Cell, Shape, box_cells
from chaingeo.core.level import Level
from chaingeo.core.rules import StackingRules, placement_rejection
from chaingeo.generator.questions.common import CATEGORIES, pick
from chaingeo.generator.questions.model import CELLS_FIELD, Option, Question, draft
from chaingeo.generator.questions.states import ShownStacking, stacking_views
from chaingeo.solvers.cover.packings import first_packing
from chaingeo.solvers.graphs import contact_graph

#: Tray pieces per state asked about, at most.
PIECES_PER_STATE = 1
#: Legal placements tried per piece for completes / dead-end, at most.
TRIED = 8


@dataclass(frozen=True)
class PlacementOption:
    cells: tuple[Cell, ...]
    outside: tuple[Cell, ...]
    overlaps: dict[str, list[Cell]]
    rejection: str | None  # the rules' reason (the box, overlap, support), None if legal

    @property
    def fits(self) -> bool:
        return not self.outside and not self.overlaps

    def to_json(self) -> dict[str, Any]:
        return {
            "cells": [list(c) for c in self.cells],
            "outside": [list(c) for c in self.outside],
            "overlaps": {k: [list(c) for c in v] for k, v in sorted(self.overlaps.items())},
            "rejection": self.rejection,
        }


_CACHE: dict[tuple[str, str, int, str], list[PlacementOption]] = {}
_COMPLETIONS: dict[tuple[str, str, int, str, tuple[Cell, ...]], dict[str, Any]] = {}


def candidates(level: Level, view: ShownStacking, name: str) -> list[PlacementOption]:
    """Every orientation of ``name`` at every offset within one cell of the box, in a fixed
    order, classified against the pieces placed (remembered for the level last asked about:
    four categories ask about the same placements)."""
    key = (level.id, level.provenance.signature, view.step, name)
    if key not in _CACHE:
        if _CACHE and next(iter(_CACHE))[:2] != key[:2]:
            _CACHE.clear()
            _COMPLETIONS.clear()
        _CACHE[key] = list(_candidates(level, view, name))
    return _CACHE[key]


def _candidates(level: Level, view: ShownStacking, name: str) -> Iterator[PlacementOption]:
    assert level.box is not None and isinstance(level.rules, StackingRules)
    box = level.box
    occupied = view.occupied
    for shape in level.piece(name).shape.orientations():
        ext = shape.extent
        ranges = [range(-1, box[i] - ext[i] + 2) for i in range(3)]
        for dx in ranges[0]:
            for dy in ranges[1]:
                for dz in ranges[2]:
                    cells = tuple((x + dx, y + dy, z + dz) for x, y, z in shape.cells)
                    yield _classify(cells, occupied, box, level.rules)


def _classify(
    cells: tuple[Cell, ...],
    occupied: dict[Cell, str],
    box: tuple[int, int, int],
    rules: StackingRules,
) -> PlacementOption:
    outside = tuple(c for c in cells if not all(0 <= c[i] < box[i] for i in range(3)))
    overlaps: dict[str, list[Cell]] = {}
    for c in cells:
        if c in occupied:
            overlaps.setdefault(occupied[c], []).append(c)
    if outside or overlaps:  # the rules refuse it for the same reason; no need to ask them
        return PlacementOption(
            cells, outside, overlaps, "outside the box" if outside else "overlap"
        )
    why = placement_rejection(Shape(cells), occupied, box, rules)
    return PlacementOption(cells, outside, overlaps, None if why is None else why.reason)


def _option(name: str, c: PlacementOption) -> Option:
    return Option(f"{name} at {CELLS_FIELD}", c.cells)


def _near(
    rng: np.random.Generator, right: PlacementOption, pool: list[PlacementOption], k: int
) -> list[PlacementOption]:
    """``k`` of ``pool`` nearest ``right`` (cells' centre), ties broken at random."""
    centre = np.mean(right.cells, axis=0)
    noise = rng.random(len(pool))
    order = sorted(
        range(len(pool)),
        key=lambda i: (
            round(float(np.abs(np.mean(pool[i].cells, axis=0) - centre).sum()), 6),
            noise[i],
        ),
    )
    return [pool[i] for i in order[:k]]


def _views(level: Level) -> list[ShownStacking]:
    return list(stacking_views(level)) if level.family == "stacking" else []


@CATEGORIES.register("fits")
def fits_questions(level: Level, rng: np.random.Generator) -> list[Question]:
    """Which placement lies inside the box on empty cells only (support aside)."""
    out: list[Question] = []
    for view in _views(level):
        for name in pick(rng, list(view.tray), PIECES_PER_STATE):
            every = list(candidates(level, view, name))
            good = [c for c in every if c.fits]
            bad = [c for c in every if not c.fits]
            if not good or len(bad) < 3:
                continue
            right = pick(rng, good, 1)[0]
            wrong = _near(rng, right, bad, 3)
            prompt = (
                f"Which of these placements of {name} fits: every cell it would fill is "
                "inside the box and not yet filled by another piece? (Cells are (x,y,z), "
                "counted from 1.)"
            )
            proof = {"piece": name, "options": [c.to_json() for c in [right, *wrong]]}
            answer, decoys = _option(name, right), [_option(name, w) for w in wrong]
            out.append(draft("fits", level, view.step, prompt, answer, decoys, proof))
    return out


def _touches(view: ShownStacking, c: PlacementOption) -> list[str]:
    g = contact_graph({**view.placed, "?": c.cells})
    return sorted(g.neighbors("?"))


@CATEGORIES.register("supported")
def supported_questions(level: Level, rng: np.random.Generator) -> list[Question]:
    """Which of four placements that fit the rules accept: it touches the floor or a placed
    piece face to face (the contact graph), and under the drop rule nothing is above it."""
    assert level.family != "stacking" or isinstance(level.rules, StackingRules)
    out: list[Question] = []
    for view in _views(level):
        for name in pick(rng, list(view.tray), PIECES_PER_STATE):
            fitting = [c for c in candidates(level, view, name) if c.fits]
            good = [c for c in fitting if c.rejection is None]
            bad = [c for c in fitting if c.rejection is not None]
            if not good or len(bad) < 3:
                continue
            right = pick(rng, good, 1)[0]
            wrong = _near(rng, right, bad, 3)
            drop = isinstance(level.rules, StackingRules) and level.rules.support == "drop"
            rule = " and nothing already placed lies above any of its cells" if drop else ""
            prompt = (
                f"Every placement of {name} below fits in the box. Which one is supported: "
                f"it touches the floor or a piece already placed, face to face{rule}? "
                "(Cells are (x,y,z), counted from 1; z points up.)"
            )
            proof = {
                "piece": name,
                "rule": "drop" if drop else "contact",
                "options": [{**c.to_json(), "touches": _touches(view, c)} for c in [right, *wrong]],
            }
            answer, decoys = _option(name, right), [_option(name, w) for w in wrong]
            out.append(draft("supported", level, view.step, prompt, answer, decoys, proof))
    return out


def _completion(level: Level, view: ShownStacking, name: str, c: PlacementOption) -> dict[str, Any]:
    """Can the tray's other pieces fill the box's empty cells once ``c`` is placed? With a
    packing as the witness, or none (the exact-cover search found none: a proof)."""
    key = (level.id, level.provenance.signature, view.step, name, c.cells)
    if key not in _COMPLETIONS:
        _COMPLETIONS[key] = _complete(level, view, name, c)
    return _COMPLETIONS[key]


def _complete(level: Level, view: ShownStacking, name: str, c: PlacementOption) -> dict[str, Any]:
    assert level.box is not None
    filled = set(view.occupied) | set(c.cells)
    empty = [cell for cell in box_cells(level.box).cells if cell not in filled]
    rest = {n: level.piece(n).shape for n in view.tray if n != name}
    if not empty:
        return {"completable": not rest, "packing": {} if not rest else None}
    if not rest or sum(len(s) for s in rest.values()) != len(empty):
        return {
            "completable": False,
            "packing": None,
            "cells_left": len(empty),
            "cells_in_tray": sum(len(s) for s in rest.values()),
        }
    found = first_packing(rest, Shape(empty))
    if found is None:
        return {"completable": False, "packing": None}
    return {
        "completable": True,
        "packing": {n: [list(x) for x in s.cells] for n, s in found.placements},
    }


def _cover_questions(level: Level, rng: np.random.Generator, category: str) -> list[Question]:
    out: list[Question] = []
    want = category == "completes"  # the right option completes; for dead-end it does not
    for view in _views(level):
        if len(view.tray) < 2:
            continue
        for name in pick(rng, list(view.tray), 1):
            legal = [c for c in candidates(level, view, name) if c.rejection is None]
            yes: list[tuple[PlacementOption, dict[str, Any]]] = []
            no: list[tuple[PlacementOption, dict[str, Any]]] = []
            for c in pick(rng, legal, TRIED):
                proof = _completion(level, view, name, c)
                (yes if proof["completable"] else no).append((c, proof))
            right_pool, wrong_pool = (yes, no) if want else (no, yes)
            if not right_pool or len(wrong_pool) < 3:
                continue
            right = right_pool[0]
            wrong = wrong_pool[:3]
            if want:
                prompt = (
                    f"Each option places {name} legally. After which placement can the "
                    "pieces left in the tray still fill every empty cell of the box "
                    "exactly (turned as needed)? (Cells are (x,y,z), counted from 1.)"
                )
            else:
                prompt = (
                    f"Each option places {name} legally. Which placement is a dead end: "
                    "afterwards the pieces left in the tray can no longer fill every "
                    "empty cell of the box exactly, however they are turned? (Cells are "
                    "(x,y,z), counted from 1.)"
                )
            proof = {"piece": name, "options": [{**c.to_json(), **p} for c, p in [right, *wrong]]}
            answer, decoys = _option(name, right[0]), [_option(name, w) for w, _ in wrong]
            out.append(draft(category, level, view.step, prompt, answer, decoys, proof))
    return out


@CATEGORIES.register("completes")
def completes_questions(level: Level, rng: np.random.Generator) -> list[Question]:
    """Which legal placement still lets the tray fill the box (exact cover exists)."""
    return _cover_questions(level, rng, "completes")


@CATEGORIES.register("dead-end")
def dead_end_questions(level: Level, rng: np.random.Generator) -> list[Question]:
    """Which legal placement leaves a space the tray cannot fill (no exact cover)."""
    return _cover_questions(level, rng, "dead-end")
