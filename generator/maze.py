"""Maze burrs: a generated two-piece puzzle family whose level grows with the maze.

A *plate* (three voxel layers) holds a channel in its middle layer and a slot above it in its
top layer, both following a random path; a *pin* (a plus-shaped knob in the channel with a stem
up through the slot) starts at one end of the path and leaves through the plate's side at the
other end. The stem keeps the knob's centre on the path (the top layer is solid elsewhere), the
knob's arms stop it from lifting out (a path cell has at most two path neighbours, the arms
reach four) and the solid bottom layer stops it going down, so every legal move slides the pin
along the path. The path is *induced* (cells adjacent on the grid are consecutive on the path),
so a straight move covers part of one straight run and never more: the fewest moves until the
pin comes free is the number of straight runs, the last one taking it out through the wall.

The path is a random self-avoiding induced walk on an ``n x n`` grid, biased to turn, cut at a
border cell; the best of ``attempts`` walks is kept. The level claimed is the one the
disassembly search measures (:func:`chaingeo.solvers.motion.disassemble.analyze_assembly`); the
number of
runs is what the construction predicts, and both are checked to agree.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from chaingeo.core.geometry import Shape

Cell2 = tuple[int, int]
STEPS: tuple[Cell2, ...] = ((1, 0), (-1, 0), (0, 1), (0, -1))
MARGIN = 2  # path cells start this far from the plate's side: arm + wall


def parse_maze_shape(shape: str) -> int:
    """``"maze7"`` -> 7 (the side of the path grid); ``ValueError`` otherwise."""
    try:
        n = int(shape[4:])
    except ValueError:
        raise ValueError(f"maze shapes are maze4..maze40, got {shape!r}") from None
    if not 4 <= n <= 40:
        raise ValueError(f"maze shapes are maze4..maze40, got {shape!r}")
    return n


def runs(path: Sequence[Cell2]) -> int:
    """Straight runs of a path (a single cell is one run)."""
    if len(path) < 2:
        return 1
    count = 1
    for i in range(2, len(path)):
        a = (path[i - 1][0] - path[i - 2][0], path[i - 1][1] - path[i - 2][1])
        b = (path[i][0] - path[i - 1][0], path[i][1] - path[i - 1][1])
        count += a != b
    return count


def _exit_step(cell: Cell2, n: int) -> Cell2 | None:
    """The outward step of a border cell of the grid (first in STEPS order), else None."""
    x, y = cell
    for d in STEPS:
        nx, ny = x + d[0], y + d[1]
        if not (0 <= nx < n and 0 <= ny < n):
            return d
    return None


def with_exit(path: Sequence[Cell2], n: int) -> list[Cell2]:
    """Grid path (ending on the border) continued straight through the wall, grid coordinates
    (the wall cells are at -MARGIN..-1 or n..n+MARGIN-1)."""
    d = _exit_step(path[-1], n)
    if d is None:
        raise ValueError("a maze path must end on the border of its grid")
    out = list(path)
    x, y = path[-1]
    for k in range(1, MARGIN + 1):
        out.append((x + k * d[0], y + k * d[1]))
    return out


def random_walk(n: int, rng: np.random.Generator, turn_bias: float = 0.7) -> list[Cell2]:
    """A self-avoiding induced walk on the ``n x n`` grid, turning with preference, until stuck;
    then cut to the prefix ending on the border with the most runs (through the exit)."""
    start = (int(rng.integers(n)), int(rng.integers(n)))
    path = [start]
    on_path = {start}
    while True:
        x, y = path[-1]
        options: list[Cell2] = []
        for d in STEPS:
            c = (x + d[0], y + d[1])
            if not (0 <= c[0] < n and 0 <= c[1] < n) or c in on_path:
                continue
            # Induced: the new cell touches no path cell but the current end.
            touching = [
                nb
                for e in STEPS
                if (nb := (c[0] + e[0], c[1] + e[1])) in on_path and nb != path[-1]
            ]
            if not touching:
                options.append(d)
        if not options:
            break
        last = (path[-1][0] - path[-2][0], path[-1][1] - path[-2][1]) if len(path) > 1 else None
        turning = [d for d in options if d != last]
        pool = turning if turning and rng.random() < turn_bias else options
        d = pool[int(rng.integers(len(pool)))]
        c = (x + d[0], y + d[1])
        path.append(c)
        on_path.add(c)
    best: list[Cell2] = []
    best_runs = 0
    for end in range(len(path)):
        if _exit_step(path[end], n) is None:
            continue
        r = runs(with_exit(path[: end + 1], n))
        if r > best_runs:
            best, best_runs = path[: end + 1], r
    return best


def maze_pieces(path: Sequence[Cell2], n: int) -> tuple[Shape, Shape]:
    """``(plate, pin)`` for a grid path that ends on the border; the pin at the path's start."""
    full = [(x + MARGIN, y + MARGIN) for x, y in with_exit(path, n)]
    side = n + 2 * MARGIN
    inside = {c for c in full if 0 <= c[0] < side and 0 <= c[1] < side}
    channel = {
        (x + d[0], y + d[1]) for x, y in inside for d in ((0, 0), *STEPS)
    }  # plus-dilation of the path
    plate = [
        (x, y, z)
        for x in range(side)
        for y in range(side)
        for z in range(3)
        if not (z == 1 and (x, y) in channel) and not (z == 2 and (x, y) in inside)
    ]
    sx, sy = full[0]
    pin = [(sx + d[0], sy + d[1], 1) for d in ((0, 0), *STEPS)] + [(sx, sy, 2), (sx, sy, 3)]
    return Shape(plate), Shape(pin)


def maze_search(
    n: int, min_runs: int, attempts: int, rng: np.random.Generator
) -> tuple[list[Cell2], Shape, Shape] | None:
    """The walk with the most runs among ``attempts`` (stopping early once ``min_runs`` is
    reached) whose plate is one connected piece, or None."""
    best: tuple[list[Cell2], Shape, Shape] | None = None
    best_runs = 0
    for _ in range(max(1, attempts)):
        path = random_walk(n, rng)
        if not path:
            continue
        r = runs(with_exit(path, n))
        if r <= best_runs:
            continue
        plate, pin = maze_pieces(path, n)
        if not plate.is_connected():
            continue
        best, best_runs = (path, plate, pin), r
        if r >= min_runs:
            break
    return best
