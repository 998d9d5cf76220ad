"""same-assembly: which of four pictures shows the solved level seen from another side.

The right picture is the solved assembly turned by one of the 23 other rotations; the wrong
ones are near copies seen the same way: its mirror image (when the assembly is chiral), one
piece shifted by a cell, two pieces' colours swapped. The proof lists each option's recipe (the
presentation draws it, :func:`recipes` finds it from the option) and whether its coloured cells
are a rotation of the solved level's.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from chaingeo.core.geometry import ROTATIONS, Cell, Shape
from chaingeo.core.level import Level, StackingSolution
from chaingeo.generator.questions.common import CATEGORIES, pick
from chaingeo.generator.questions.model import Option, Question, draft

Coloured = dict[str, Shape]
SHIFTS = ((1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1))
#: Pieces at most: more and one changed piece is hard to see at the picture's size.
MAX_PIECES = 12


def solved(level: Level) -> Coloured:
    """The level's pieces where its solution puts them (packed, or assembled)."""
    if isinstance(level.solution, StackingSolution):
        return {p.name: level.solution.placements[p.name] for p in level.pieces}
    return {p.name: p.shape for p in level.pieces}


def recipe_pieces(level: Level, recipe: Mapping[str, Any]) -> Coloured:
    """The pieces an option's recipe draws: change (mirror, shift, swap), then turn."""
    pieces = dict(solved(level))
    if recipe.get("mirror"):
        m = np.diag([-1, 1, 1])
        pieces = {n: s.rotate(m) for n, s in pieces.items()}
    if "shift" in recipe:
        n, v = recipe["shift"]
        pieces[n] = pieces[n].translate(v)
    if "swap" in recipe:
        a, b = recipe["swap"]
        pieces[a], pieces[b] = pieces[b], pieces[a]
    r = ROTATIONS[int(recipe["rotation"])]
    return {n: s.rotate(r) for n, s in pieces.items()}


def key(pieces: Mapping[str, Shape]) -> frozenset[tuple[str, Cell]]:
    """The coloured cells, moved so their least corner is the origin."""
    every = [c for s in pieces.values() for c in s.cells]
    lo = [min(c[i] for c in every) for i in range(3)]
    return frozenset(
        (n, (x - lo[0], y - lo[1], z - lo[2])) for n, s in pieces.items() for x, y, z in s.cells
    )


def same_up_to_rotation(a: Mapping[str, Shape], b: Mapping[str, Shape]) -> bool:
    """Is ``b`` (coloured) a rotation of ``a``?"""
    target = key(b)
    return any(key({n: s.rotate(r) for n, s in a.items()}) == target for r in ROTATIONS)


def _wrong_recipes(
    level: Level, rng: np.random.Generator, pieces: Coloured
) -> list[dict[str, Any]]:
    """Mirror image first, then colour swaps (the same outline), then one piece shifted."""

    def rot() -> int:
        return int(rng.integers(1, 24))

    out: list[dict[str, Any]] = [{"mirror": True, "rotation": rot()}]
    names = sorted(pieces)
    pairs = [(a, b) for i, a in enumerate(names) for b in names[i + 1 :]]
    out.extend({"swap": [a, b], "rotation": rot()} for a, b in pick(rng, pairs, 4))
    cells = {c for s in pieces.values() for c in s.cells}
    for n in pick(rng, names, 3):
        for v in pick(rng, list(SHIFTS), 6):
            moved = {(x + v[0], y + v[1], z + v[2]) for x, y, z in pieces[n].cells}
            if not moved & (cells - set(pieces[n].cells)):
                out.append({"shift": [n, list(v)], "rotation": rot()})
                break
    return out


@CATEGORIES.register("same-assembly")
def same_assembly_questions(level: Level, rng: np.random.Generator) -> list[Question]:
    """One question per level with at most :data:`MAX_PIECES` pieces."""
    if len(level.pieces) > MAX_PIECES:
        return []
    pieces = solved(level)
    right = {"rotation": int(rng.integers(1, 24))}
    wrong = [
        r
        for r in _wrong_recipes(level, rng, pieces)
        if not same_up_to_rotation(pieces, recipe_pieces(level, r))
    ]
    seen: list[frozenset[tuple[str, Cell]]] = []
    chosen: list[dict[str, Any]] = []
    for r in wrong:  # distinct pictures only
        k = key(recipe_pieces(level, {**r, "rotation": 0}))
        if k not in seen:
            seen.append(k)
            chosen.append(r)
    if len(chosen) < 3:
        return []
    chosen = chosen[:3]
    step = _solved_step(level)
    prompt = (
        "The top picture shows the solved level. Which of the four pictures below it shows "
        "the same assembly (every piece in the same place, the same colours) seen from "
        "another side?"
    )
    proof = {"options": [{**r, "same": i == 0} for i, r in enumerate([right, *chosen])]}
    options = [Option(_words(r)) for r in [right, *chosen]]
    return [draft("same-assembly", level, step, prompt, options[0], options[1:], proof)]


def _solved_step(level: Level) -> int:
    sol = level.solution
    if isinstance(sol, StackingSolution):
        return len(sol.order)
    return 0 if level.goal == "disassemble" else len(sol.moves)


def _words(recipe: Mapping[str, Any]) -> str:
    """The option's text: the picture it names (drawn by the presentation from ``proof``)."""
    return f"picture {_id(recipe)}"


def _id(recipe: Mapping[str, Any]) -> str:
    parts = [f"r{recipe['rotation']}"]
    if recipe.get("mirror"):
        parts.append("m")
    if "shift" in recipe:
        parts.append("s" + recipe["shift"][0])
    if "swap" in recipe:
        parts.append("w" + "-".join(recipe["swap"]))
    return "".join(parts)


def recipes(q: Question) -> Sequence[Mapping[str, Any]]:
    """The recipes of a same-assembly question's options, in the options' order."""
    by_text = {_words(r): r for r in q.proof["options"]}
    return [by_text[o.text] for o in q.options]
