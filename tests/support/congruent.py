"""Random BurrTools puzzles with congruent pieces listed as separate shapes, on symmetric
results: a box half cut into pieces and doubled by a half-turn (congruent pairs) or by a mirror
(mirror pairs; achiral pieces congruent), or a box cut into straight bars (all congruent). The
shapes are listed in a random order (BurrTools' piece order is the shapes' order)."""

from __future__ import annotations

import dataclasses

import numpy as np

from chaingeo.core.formats.bt_model import BTPart, BTProblem, BTPuzzle, colored_shape
from chaingeo.core.geometry import Shape
from tests.support.burrtxt import _cut

Cell = tuple[int, int, int]
KINDS = ("turned", "mirrored", "bars")


def _half(rng: np.random.Generator) -> tuple[tuple[int, int, int], list[list[Cell]]]:
    """A box of 8-18 cells, 2 or more a side, cut into 3 connected pieces (winding ones
    interlock; solid ones may be chiral)."""
    dims = ((2, 2, 2), (2, 2, 3), (2, 3, 2), (2, 3, 3))[int(rng.integers(4))]
    box = [(x, y, z) for x in range(dims[0]) for y in range(dims[1]) for z in range(dims[2])]
    while True:
        found = _cut(box, 3, rng)
        if found is not None:
            return dims, found


def congruent_puzzle(rng: np.random.Generator, kind: str) -> BTPuzzle:
    """One puzzle of ``kind`` (:data:`KINDS`)."""
    if kind == "bars":
        while True:
            dims = [int(v) for v in rng.integers(1, 4, size=2)]
            if 3 <= dims[0] * dims[1] <= 6:
                break
        depth = int(rng.integers(2, 4))
        pieces = [[(x, y, z) for z in range(depth)] for x in range(dims[0]) for y in range(dims[1])]
    else:
        turned = kind == "turned"
        (a, b, _), half = _half(rng)
        other = [[(2 * a - 1 - x, b - 1 - y if turned else y, z) for x, y, z in p] for p in half]
        pieces = half + other
    order = rng.permutation(len(pieces)).tolist()
    shapes = [colored_shape(f"p{i}", Shape(pieces[k]).normalized()) for i, k in enumerate(order)]
    result = colored_shape("result", Shape([c for p in pieces for c in p]))
    problem = BTProblem(kind, tuple(BTPart(i, 1, 1) for i in range(len(shapes))), len(shapes))
    return BTPuzzle((*shapes, result), (problem,))


def regrouped(puzzle: BTPuzzle, counts: tuple[int, ...], *, first: bool = False) -> BTPuzzle:
    """Problem 0 of ``puzzle`` with its congruent single pieces (all but one, which stays on
    its own, last or ``first``) as shapes used ``counts`` times each: BurrTools then counts
    fewer relabellings of the same arrangements (hard-03's 11 sticks as 5 + 6: 462)."""
    prob = puzzle.problem(0)
    alone = [p for p in prob.parts if sum(q.shape == p.shape for q in prob.parts) == 1]
    key = next(p for p in alone if not _congruent_to_another(puzzle, p.shape, prob))
    rest = [p.shape for p in prob.parts if p.shape != key.shape]
    parts, at = [], 0
    for c in counts:
        parts.append(BTPart(rest[at], c, c))
        at += c
    assert at == len(rest), "the counts must use every congruent piece"
    parts.insert(0 if first else len(parts), key)
    problem = dataclasses.replace(prob, parts=tuple(parts))
    return dataclasses.replace(puzzle, problems=(problem,))


def _congruent_to_another(puzzle: BTPuzzle, shape: int, prob: BTProblem) -> bool:
    mine = puzzle.shapes[shape].filled.canonical()
    return any(
        puzzle.shapes[p.shape].filled.canonical() == mine for p in prob.parts if p.shape != shape
    )
