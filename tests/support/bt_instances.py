"""Random small BurrTools problems (a box cut into pieces, with colours, variable cells, ranges
and a hole cap) and their translation to the naive oracle (:mod:`tests.support.bt_reference`)."""

from __future__ import annotations

import itertools

import numpy as np

from chaingeo.core.formats.burrtools import (
    BTPart,
    BTProblem,
    BTPuzzle,
    BTShape,
    colored_shape,
)
from chaingeo.core.geometry import SYMMETRIES, Shape
from tests.support.bt_reference import Cell, RefPart, Voxel

BOXES = ((2, 2, 2), (2, 2, 3), (2, 3, 3), (1, 3, 4))
SMALL_BOXES = ((2, 2, 2), (2, 2, 3), (1, 3, 4))
NEIGHBOURS = ((1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1))


def random_partition(
    box: tuple[int, int, int], k: int, rng: np.random.Generator
) -> list[list[Cell]]:
    """``k`` connected pieces covering the box, grown from random seeds."""
    cells: list[Cell] = [
        (x, y, z) for x, y, z in itertools.product(range(box[0]), range(box[1]), range(box[2]))
    ]
    seeds = rng.choice(len(cells), size=k, replace=False)
    owner = {cells[int(s)]: i for i, s in enumerate(seeds)}
    while len(owner) < len(cells):
        frontier = sorted(
            (c, owner[p])
            for p in owner
            for d in NEIGHBOURS
            if (c := (p[0] + d[0], p[1] + d[1], p[2] + d[2])) in set(cells) and c not in owner
        )
        c, i = frontier[int(rng.integers(len(frontier)))]
        owner[c] = i
    return [sorted(c for c, o in owner.items() if o == i) for i in range(k)]


def random_puzzle(seed: int, small: bool = False) -> BTPuzzle:
    """One problem: a box cut into 3-5 pieces; maybe one piece's cells made variable (that
    piece optional), colours on some voxels with the pairs the cut needs plus random ones,
    a range on one piece, a hole cap. ``small``: boxes of at most 12 cells, at most 4 pieces."""
    rng = np.random.default_rng(seed)
    boxes = SMALL_BOXES if small else BOXES
    box = boxes[int(rng.integers(len(boxes)))]
    k = int(rng.integers(3, 5 if small else 6))
    pieces = random_partition(box, k, rng)
    n_colors = int(rng.integers(0, 4))
    result_color: dict[Cell, int] = {}
    piece_colors: list[dict[Cell, int]] = [{} for _ in pieces]
    pairs: set[tuple[int, int]] = set()
    if n_colors:
        for i, p in enumerate(pieces):
            for c in p:
                if rng.random() < 0.5:
                    result_color[c] = int(rng.integers(1, n_colors + 1))
                if rng.random() < 0.4:
                    piece_colors[i][c] = int(rng.integers(1, n_colors + 1))
                    if c in result_color:
                        pairs.add((piece_colors[i][c], result_color[c]))
        for a in range(1, n_colors + 1):
            for b in range(1, n_colors + 1):
                if rng.random() < 0.25:
                    pairs.add((a, b))
    variable: set[Cell] = set()
    ranges = [(1, 1)] * len(pieces)
    if rng.random() < 0.5:
        j = int(rng.integers(len(pieces)))
        variable = set(pieces[j])
        ranges[j] = (0, 1)
    if rng.random() < 0.3:
        j = int(rng.integers(len(pieces)))
        ranges[j] = (ranges[j][0], 2)
    shapes: list[BTShape] = []
    for i, p in enumerate(pieces):
        lo = np.min(np.asarray(p), axis=0)
        norm = {
            (x - lo[0], y - lo[1], z - lo[2]): piece_colors[i].get((x, y, z), 0) for x, y, z in p
        }
        shapes.append(colored_shape(f"p{i}", Shape(list(norm)), None, norm))
    all_cells = [c for p in pieces for c in p]
    fixed = Shape([c for c in all_cells if c not in variable])
    shapes.append(colored_shape("result", fixed, Shape(sorted(variable)), result_color, size=box))
    max_holes = None if not variable or rng.random() < 0.5 else int(rng.integers(0, 3))
    problem = BTProblem(
        "random",
        tuple(BTPart(i, lo, hi) for i, (lo, hi) in enumerate(ranges)),
        len(pieces),
        color_pairs=tuple(sorted(pairs)),
        max_holes=max_holes,
    )
    colors = tuple((40 * i, 80, 200 - 40 * i) for i in range(n_colors))
    return BTPuzzle(tuple(shapes), (problem,), colors=colors)


def _canon(vox: frozenset[Voxel]) -> tuple[Voxel, ...]:
    forms = []
    for m in SYMMETRIES[:24]:
        rot = [(tuple(int(v) for v in m @ np.array(c)), k) for c, k in vox]
        lo = [min(r[0][i] for r in rot) for i in range(3)]
        forms.append(tuple(sorted(((c[0] - lo[0], c[1] - lo[1], c[2] - lo[2]), k) for c, k in rot)))
    return min(forms)


def reference_parts(puzzle: BTPuzzle, index: int = 0) -> list[RefPart]:
    """The problem's parts for the oracle, identical coloured shapes merged (as the engine
    does; BurrTools itself would count their permutations)."""
    merged: dict[tuple[Voxel, ...], RefPart] = {}
    for part in puzzle.problems[index].parts:
        s = puzzle.shapes[part.shape]
        vox = frozenset((c, s.color(c)) for c in s.filled.cells)
        key = _canon(vox)
        group = part.groups[0][0] if len(part.groups) == 1 else 0
        if key in merged:
            old = merged[key]
            merged[key] = RefPart(old.voxels, old.lo + part.min, old.hi + part.max, old.group)
        else:
            merged[key] = RefPart(vox, part.min, part.max, group)
    return [p for p in merged.values() if p.hi > 0]
