"""BurrTools example puzzles built from our own pieces, one per problem feature, written with
the ``.xmpuzzle`` writer (:mod:`chaingeo.core.formats.burrtools`). Deterministic: the same
call gives the same file. Each builder returns a :class:`BTPuzzle`; :data:`EXAMPLES` lists
them by name (``tests/data/burrtools/<name>.xmpuzzle`` holds each one as written).

* ``colour_pentominoes``: the 12 pentominoes in a 3x4x5 box (7880 assemblies up to rotation)
  where every corner must be a pentomino's end and the X's centre must lie inside the box:
  colour rules leave a handful.
* ``linked_rings``: two linked rings in one piece group on a base, the top layer variable and
  an optional lid: the rings never come apart, and need not.
* ``ring_maze``: a maze burr (:mod:`chaingeo.generator.maze`) whose pin carries a ring it can never
  lose (pin and ring in one group); the ring sits at either of two heights (variable cells).
* ``deep_maze``: a maze burr on a staircase path, level above 50.
* ``soma_problems``: three problems in one file: the Soma cube; the Soma pieces with ranges
  into a smaller box; the same without the left screw (a chiral piece without its mirror).
* ``solid_burrs``: the 25 pieces of solid six-piece burrs, each 0..6 times, into the Solid
  Knot (our catalogue, :mod:`chaingeo.core.piecesets.burrs`; BurrTools' own example file
  holds the same problem: 1063 / 314 with mirror images kept, 588 / 179 without).
"""

from __future__ import annotations

import os
import sys
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path

import numpy as np

from chaingeo.core.formats.burrtools import (
    BTPart,
    BTProblem,
    BTPuzzle,
    BTShape,
    colored_shape,
    write_xmpuzzle,
)
from chaingeo.core.geometry import Cell, Shape, box_cells
from chaingeo.core.piecesets import PENTOMINOES, SOMA
from chaingeo.core.piecesets.burrs import SOLID_BURR_CODES, burr_piece, solid_knot
from chaingeo.generator.maze import maze_pieces, maze_search

_STEPS = ((1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1))


def _normalized(
    name: str, cells: Sequence[Cell] | Shape, colors: Mapping[Cell, int] | None = None
) -> BTShape:
    """A shape moved to the origin (colours move with it)."""
    shape = Shape(list(cells))
    lo = shape.min_corner
    moved = {(c[0] - lo[0], c[1] - lo[1], c[2] - lo[2]): k for c, k in (colors or {}).items()}
    return colored_shape(name, shape.normalized(), None, moved)


def _ends(shape: Shape) -> set[Cell]:
    cells = shape.cell_set
    return {
        c
        for c in cells
        if sum((c[0] + d[0], c[1] + d[1], c[2] + d[2]) in cells for d in _STEPS) == 1
    }


def colour_pentominoes() -> BTPuzzle:
    """Colour 1 (red): a pentomino's ends, and the box's corners; colour 3 (blue): the X's
    centre, and the six cells inside the box; colour 2 (grey): every other voxel. A piece colour
    may sit on a result colour when the pair is listed: red anywhere (an end may go anywhere),
    grey on grey or blue, blue on blue only: so corners take ends, and X's centre goes
    inside."""
    shapes: list[BTShape] = []
    for name, s in PENTOMINOES.pieces.items():
        ends = _ends(s)
        cols = {c: (1 if c in ends else 3 if name == "X" else 2) for c in s.cells}
        shapes.append(colored_shape(name, s, None, cols))
    box = box_cells((3, 4, 5))
    corners = {
        c for c in box.cells if all(v in (0, m - 1) for v, m in zip(c, (3, 4, 5), strict=True))
    }
    inside = {c for c in box.cells if all(0 < v < m - 1 for v, m in zip(c, (3, 4, 5), strict=True))}
    result = {c: (1 if c in corners else 3 if c in inside else 2) for c in box.cells}
    shapes.append(colored_shape("box", box, None, result))
    problem = BTProblem(
        "corners are ends, X inside",
        tuple(BTPart(i, 1, 1) for i in range(12)),
        12,
        color_pairs=((1, 1), (1, 2), (1, 3), (2, 2), (2, 3), (3, 3)),
    )
    colors = ((220, 40, 40), (150, 150, 150), (40, 80, 220))
    return BTPuzzle(tuple(shapes), (problem,), "CHAIN-geo example: colour rules", colors)


def linked_rings() -> BTPuzzle:
    """Rings A (flat) and B (upright) linked through each other, sitting on a base C; the top
    layer of the 4x3x3 box is variable, where an optional lid D may go. A and B form group 1."""
    ring_a = {(x, y, 1) for x in range(3) for y in range(3)} - {(1, 1, 1)}
    ring_b = {(x, 1, z) for x in range(1, 4) for z in range(3)} - {(2, 1, 1)}
    base = {(x, y, 0) for x in range(4) for y in range(3)} - ring_b
    top = {(x, y, 2) for x in range(4) for y in range(3)} - ring_b
    posts = {(3, 0, 1), (3, 2, 1)}
    fixed = Shape(sorted(ring_a | ring_b | base))
    shapes = (
        _normalized("A", sorted(ring_a)),
        _normalized("B", sorted(ring_b)),
        _normalized("C", sorted(base)),
        _normalized("D", sorted(top)),
        colored_shape("box", fixed, Shape(sorted(top | posts))),
    )
    problem = BTProblem(
        "linked rings",
        (BTPart(0, 1, 1, ((1, 1),)), BTPart(1, 1, 1, ((1, 1),)), BTPart(2, 1, 1), BTPart(3, 0, 1)),
        4,
    )
    return BTPuzzle(shapes, (problem,), "CHAIN-geo example: piece groups, variable cells")


def ring_maze(seed: int = 10, n: int = 8, min_runs: int = 12) -> BTPuzzle:
    """A maze burr whose pin's stem is lengthened and capped, with a ring around it between
    the plate and the cap: the ring rides with the pin and never comes off. Pin and ring are
    group 1; the ring's two possible heights are variable cells."""
    found = maze_search(n, min_runs, 400, np.random.default_rng(seed))
    if found is None:
        raise ValueError(f"no maze of {min_runs} runs for seed {seed}")
    _, plate, pin = found
    sx, sy = next((x, y) for x, y, z in pin.cells if z == 3)
    plus = [(0, 0), (1, 0), (-1, 0), (0, 1), (0, -1)]
    pin_cells = [*pin.cells, (sx, sy, 4), *((sx + dx, sy + dy, 5) for dx, dy in plus)]
    around = [(sx + dx, sy + dy) for dx in (-1, 0, 1) for dy in (-1, 0, 1) if (dx, dy) != (0, 0)]
    ring = [(x, y, 3) for x, y in around]
    heights = [(x, y, z) for x, y in around for z in (3, 4)]
    fixed = Shape([*plate.cells, *pin_cells])
    shapes = (
        _normalized("plate", plate),
        _normalized("pin", pin_cells),
        _normalized("ring", ring),
        colored_shape("result", fixed, Shape(heights)),
    )
    problem = BTProblem(
        "ring on a pin",
        (BTPart(0, 1, 1), BTPart(1, 1, 1, ((1, 1),)), BTPart(2, 1, 1, ((1, 1),))),
        3,
    )
    return BTPuzzle(shapes, (problem,), f"CHAIN-geo example: ring maze (seed {seed}, maze{n})")


def staircase(n: int) -> list[tuple[int, int]]:
    """A path turning at every cell across the ``n x n`` grid, ending on its far corner."""
    path = [(0, 0)]
    while path[-1] != (n - 1, n - 1):
        x, y = path[-1]
        path.append((x + 1, y) if len(path) % 2 else (x, y + 1))
    return path


def deep_maze(n: int = 26) -> BTPuzzle:
    """A maze burr on a staircase path: one move per path cell, level above 50 for n >= 26."""
    plate, pin = maze_pieces(staircase(n), n)
    shapes = (
        _normalized("plate", plate),
        _normalized("pin", pin),
        colored_shape("result", Shape([*plate.cells, *pin.cells]), None),
    )
    problem = BTProblem("staircase", (BTPart(0, 1, 1), BTPart(1, 1, 1)), 2)
    return BTPuzzle(shapes, (problem,), f"CHAIN-geo example: staircase maze ({n}x{n})")


def soma_problems() -> BTPuzzle:
    """Problem 0: the Soma cube. Problem 1: the Soma pieces, each 0..1 times, into a 2x3x4
    box (mirror images count as one assembly: the screws A and B are each other's mirror).
    Problem 2: the pieces but B, each 0..2 times, into a 2x2x4 box: an assembly and its mirror
    image merge only when the right screw A is unused (its mirror is not in the problem)."""
    names = list(SOMA.pieces)
    shapes = [colored_shape(k, s) for k, s in SOMA.pieces.items()]
    shapes.append(colored_shape("cube", box_cells((3, 3, 3))))
    shapes.append(colored_shape("box", box_cells((2, 3, 4))))
    shapes.append(colored_shape("bar", box_cells((2, 2, 4))))
    cube, box, bar = len(names), len(names) + 1, len(names) + 2
    b = names.index("B")
    problems = (
        BTProblem("soma cube", tuple(BTPart(i, 1, 1) for i in range(len(names))), cube),
        BTProblem("any of them", tuple(BTPart(i, 0, 1) for i in range(len(names))), box),
        BTProblem("without B", tuple(BTPart(i, 0, 2) for i in range(len(names)) if i != b), bar),
    )
    return BTPuzzle(tuple(shapes), problems, "CHAIN-geo example: several problems, ranges")


def solid_burrs() -> BTPuzzle:
    shapes = [colored_shape(f"b{code:04x}", burr_piece(code)) for code in SOLID_BURR_CODES]
    shapes.append(colored_shape("Solid Knot", solid_knot()))
    problem = BTProblem(
        "solid six-piece burrs",
        tuple(BTPart(i, 0, 6) for i in range(len(SOLID_BURR_CODES))),
        len(SOLID_BURR_CODES),
    )
    return BTPuzzle(tuple(shapes), (problem,), "CHAIN-geo example: the solid burr catalogue")


EXAMPLES: dict[str, Callable[[], BTPuzzle]] = {
    "colour_pentominoes": colour_pentominoes,
    "linked_rings": linked_rings,
    "ring_maze": ring_maze,
    "deep_maze": deep_maze,
    "soma_problems": soma_problems,
    "solid_burrs": solid_burrs,
}


def write_examples(folder: str | os.PathLike[str]) -> list[Path]:
    """Write every example as ``<name>.xmpuzzle`` into ``folder``."""
    return [
        write_xmpuzzle(build(), Path(folder) / f"{name}.xmpuzzle")
        for name, build in EXAMPLES.items()
    ]


if __name__ == "__main__":  # python -m chaingeo.generator.bt_examples tests/data/burrtools
    for path in write_examples(sys.argv[1] if len(sys.argv) > 1 else "."):
        print(path)
