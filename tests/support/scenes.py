"""Scenes and walks the motion tests share: a fixed three-piece scene, states reached by random
legal moves (translations; translations and turns), the three-stick Lu Ban lock, and a
solver's level tree or its cap error."""

from __future__ import annotations

import random

import numpy as np

from chaingeo.core.geometry import Cell, Shape
from chaingeo.core.kinematics import Assembly, SearchLimitError, legal_moves, legal_steps
from chaingeo.solvers.motion.disassemble import _Solver

SCENE = {
    "red": Shape([(0, 0, 0), (1, 0, 0), (2, 0, 0)]),
    "blue": Shape([(0, 1, 0), (1, 1, 0), (2, 1, 0), (3, 1, 0), (3, 0, 0)]),
    "green": Shape([(0, 0, 1), (1, 0, 1), (2, 0, 1), (3, 0, 1)]),
}


def random_walk(shapes: dict[str, Shape], seed: int, steps: int) -> Assembly:
    """A state reached by random legal moves of the reference (removals included)."""
    rng = random.Random(seed)
    state = Assembly.assembled(shapes)
    for _ in range(steps):
        moves = legal_moves(state)
        if not moves:
            break
        state = state.apply(rng.choice(moves))
    return state


def turning_walk(shapes: dict[str, Shape], seed: int, steps: int) -> Assembly:
    """A state reached by random legal translations and turns (pieces end up turned)."""
    rng = np.random.default_rng(seed)
    state = Assembly.assembled(shapes)
    for _ in range(steps):
        moves = [m for m in legal_steps(state, turns=True) if not state.removes(m)]
        if not moves:
            break
        state = state.apply(moves[int(rng.integers(len(moves)))])
    return state


def luban3(length: int = 10) -> tuple[dict[str, Shape], dict[str, dict[Cell, int]]]:
    """The three-stick Lu Ban lock of CHAIN's models (``chain import luban-3-piece``), with
    sticks of any even length: 2 x 2 sticks crossing in a 2 x 2 x 2 core, where the x stick
    keeps one row of the core, the z stick four cells and the y stick a single round rod (the
    model's rod is a cylinder of diameter one, voxelised as full cells)."""
    m = length // 2 - 1  # the core is [m, m + 1] on every axis
    side = (m, m + 1)
    rust = {(x, y, z) for x in range(length) for y in side for z in side}
    rust -= {(x, y, z) for x in side for y in side for z in side if (y, z) != (m, m)}
    blue = {(x, y, z) for z in range(length) for x in side for y in side}
    blue -= {(x, m, m) for x in side} | {(m + 1, y, m + 1) for y in side}
    forest = {(x, y, z) for y in range(length) for x in side for z in side}
    forest -= {(x, y, z) for y in side for x in side for z in side if (x, z) != (m + 1, m + 1)}
    shapes = {
        "rust": Shape(sorted(rust)),
        "blue": Shape(sorted(blue)),
        "forest": Shape(sorted(forest)),
    }
    return shapes, {"forest": {(m + 1, y, m + 1): 1 for y in side}}


def level_or_error(solver: _Solver, fast: bool) -> tuple[object, int]:
    """The level tree and its state count, or the cap error's text and -1."""
    n = len(solver.table.names)
    try:
        if fast:
            return solver.level_tree(), solver.states
        return solver.part_tree(tuple(range(n)), np.zeros((n, 3), dtype=np.int64)), solver.states
    except SearchLimitError as err:
        return str(err), -1
