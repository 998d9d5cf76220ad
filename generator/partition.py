"""Carving a box into connected pieces: seeded growth, leftover filling, and voxel-move repair.

A partition is a list of piece labels, one per box cell (cells indexed by :class:`BoxGrid`).
Every function here is a pure function of its arguments and one ``numpy.random.Generator``;
sets are sorted before any random choice so the same generator state gives the same pieces
on every machine.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from chaingeo.core.geometry import NEIGHBOURS, Cell, Shape

Labels = list[int]


@dataclass(frozen=True)
class BoxGrid:
    """The cells of an ``a x b x c`` box, flat-indexed ``(x * b + y) * c + z``, with neighbours."""

    box: tuple[int, int, int]
    coords: tuple[Cell, ...]
    neighbours: tuple[tuple[int, ...], ...]

    @property
    def volume(self) -> int:
        return len(self.coords)

    def index(self, cell: Cell) -> int:
        _, b, c = self.box
        return (cell[0] * b + cell[1]) * c + cell[2]

    def shape(self, cells: Sequence[int] | frozenset[int] | set[int]) -> Shape:
        return Shape([self.coords[i] for i in sorted(cells)])


@lru_cache(maxsize=64)
def box_grid(box: tuple[int, int, int]) -> BoxGrid:
    a, b, c = box
    coords = tuple((x, y, z) for x in range(a) for y in range(b) for z in range(c))
    neighbours = []
    for x, y, z in coords:
        nbs = []
        for dx, dy, dz in NEIGHBOURS:
            nx, ny, nz = x + dx, y + dy, z + dz
            if 0 <= nx < a and 0 <= ny < b and 0 <= nz < c:
                nbs.append((nx * b + ny) * c + nz)
        neighbours.append(tuple(sorted(nbs)))
    return BoxGrid(box, coords, tuple(neighbours))


def pieces_of(labels: Labels) -> list[list[int]]:
    """The cells of each piece, sorted, indexed by label."""
    out: list[list[int]] = [[] for _ in range(max(labels) + 1)]
    for cell, p in enumerate(labels):
        out[p].append(cell)
    return out


# ---------------------------------------------------------------------------------------------
# Piece counts and sizes
# ---------------------------------------------------------------------------------------------


def piece_count_range(volume: int, min_size: int, max_size: int, max_pieces: int) -> range:
    """Feasible numbers of pieces (at least two) for sizes within ``[min_size, max_size]``."""
    lo = max(2, -(-volume // max_size))
    hi = min(max_pieces, volume // min_size)
    return range(lo, hi + 1)


def random_sizes(volume: int, k: int, lo: int, hi: int, rng: np.random.Generator) -> list[int]:
    """``k`` sizes in ``[lo, hi]`` summing to ``volume``: all start at ``lo``, units added at
    random."""
    if not k * lo <= volume <= k * hi:
        raise ValueError(f"{k} pieces of {lo}..{hi} cells cannot fill {volume} cells")
    sizes = [lo] * k
    for _ in range(volume - k * lo):
        open_ = [i for i in range(k) if sizes[i] < hi]
        sizes[open_[int(rng.integers(len(open_)))]] += 1
    return sizes


# ---------------------------------------------------------------------------------------------
# Growth
# ---------------------------------------------------------------------------------------------


def grow(grid: BoxGrid, sizes: Sequence[int], rng: np.random.Generator, *, planar: bool) -> Labels:
    """Grow one piece per target size from random seed cells, then fill what is left.

    Each step picks a random piece that is still short of its size and adds a random free
    face-neighbour; with ``planar`` the neighbour must lie in the piece's own plane (an axis
    chosen at random among those whose plane through the seed is large enough). Cells that no
    growth reached go to the smallest adjacent piece, so pieces may leave their plane there;
    :func:`repair` can restore it.
    """
    k = len(sizes)
    n = grid.volume
    seeds = [int(s) for s in rng.choice(n, size=k, replace=False)]
    labels: Labels = [-1] * n
    members: list[list[int]] = []
    plane: list[tuple[int, int] | None] = []
    for p, s in enumerate(seeds):
        labels[s] = p
        members.append([s])
        plane.append(_pick_plane(grid, s, sizes[p], rng) if planar else None)
    active = [p for p in range(k) if sizes[p] > 1]
    while active:
        j = int(rng.integers(len(active)))
        p = active[j]
        pl = plane[p]
        frontier = sorted(
            {
                q
                for cell in members[p]
                for q in grid.neighbours[cell]
                if labels[q] < 0 and (pl is None or grid.coords[q][pl[0]] == pl[1])
            }
        )
        if not frontier:
            active.pop(j)
            continue
        q = frontier[int(rng.integers(len(frontier)))]
        labels[q] = p
        members[p].append(q)
        if len(members[p]) >= sizes[p]:
            active.pop(j)
    fill_leftovers(grid, labels)
    return labels


def _pick_plane(
    grid: BoxGrid, seed: int, size: int, rng: np.random.Generator
) -> tuple[int, int] | None:
    dims = grid.box
    areas = [dims[(a + 1) % 3] * dims[(a + 2) % 3] for a in range(3)]
    axes = [a for a in range(3) if areas[a] >= size] or [int(np.argmax(areas))]
    axis = axes[int(rng.integers(len(axes)))]
    return axis, grid.coords[seed][axis]


def fill_leftovers(grid: BoxGrid, labels: Labels) -> None:
    """Give every unlabelled cell to its smallest adjacent piece (ties: lowest label), in place."""
    sizes = Counter(p for p in labels if p >= 0)
    while True:
        changed = False
        missing = False
        for cell in range(grid.volume):
            if labels[cell] >= 0:
                continue
            adjacent = sorted({labels[q] for q in grid.neighbours[cell] if labels[q] >= 0})
            if not adjacent:
                missing = True
                continue
            p = min(adjacent, key=lambda lab: (sizes[lab], lab))
            labels[cell] = p
            sizes[p] += 1
            changed = True
        if not missing:
            return
        if not changed:  # pragma: no cover - a box is connected and has at least one seed
            raise ValueError("cells unreachable from every piece")


# ---------------------------------------------------------------------------------------------
# Piece rules and repair
# ---------------------------------------------------------------------------------------------


def is_planar(shape: Shape) -> bool:
    """All voxels in one axis-aligned plane."""
    v = shape.voxels
    return bool(len(v)) and any(int(v[:, a].min()) == int(v[:, a].max()) for a in range(3))


@dataclass(frozen=True)
class PieceRules:
    """What every piece of a partition must satisfy (the repair's objective)."""

    min_size: int
    max_size: int
    forbid_rect: tuple[int, int] | None = (2, 3)
    planar: bool = False
    distinct: bool = False

    def violations(self, shape: Shape) -> int:
        n = len(shape)
        cost = max(0, self.min_size - n) + max(0, n - self.max_size)
        if self.forbid_rect is not None and shape.has_filled_rectangle(*self.forbid_rect):
            cost += 1
        if self.planar and not is_planar(shape):
            cost += 1
        return cost


def _connected_without(grid: BoxGrid, cells: set[int], removed: int) -> bool:
    rest = cells - {removed}
    if not rest:
        return False
    start = min(rest)
    seen = {start}
    stack = [start]
    while stack:
        c = stack.pop()
        for q in grid.neighbours[c]:
            if q in rest and q not in seen:
                seen.add(q)
                stack.append(q)
    return len(seen) == len(rest)


def _duplicates(keys: Counter[tuple[Cell, ...]]) -> int:
    return sum(c - 1 for c in keys.values() if c > 1)


class _PartitionEvaluator:
    """Memoised piece cost and canonical form per cell set (repair revisits the same sets)."""

    def __init__(self, grid: BoxGrid, rules: PieceRules) -> None:
        self.grid = grid
        self.rules = rules
        self.memo: dict[frozenset[int], tuple[int, tuple[Cell, ...]]] = {}

    def __call__(self, cells: frozenset[int]) -> tuple[int, tuple[Cell, ...]]:
        hit = self.memo.get(cells)
        if hit is None:
            shape = self.grid.shape(cells)
            key = shape.canonical().cells if self.rules.distinct else ()
            hit = (self.rules.violations(shape), key)
            self.memo[cells] = hit
        return hit


def partition_cost(grid: BoxGrid, labels: Labels, rules: PieceRules) -> int:
    """Total rule violations of a partition: per-piece costs plus repeated shapes if distinct."""
    ev = _PartitionEvaluator(grid, rules)
    evals = [ev(frozenset(cells)) for cells in pieces_of(labels)]
    dup = _duplicates(Counter(k for _, k in evals)) if rules.distinct else 0
    return sum(c for c, _ in evals) + dup


def repair(
    grid: BoxGrid,
    labels: Labels,
    rules: PieceRules,
    rng: np.random.Generator,
    *,
    max_moves: int,
    sideways: int = 8,
) -> tuple[Labels, int, int]:
    """Move single voxels between adjacent pieces until no rule is broken (steepest descent).

    A move gives a cell of piece A to a face-adjacent piece B when A stays connected and
    non-empty (B stays connected because the cell touches it); only moves touching a piece
    that breaks a rule are considered. Among the best moves one is drawn at random; moves that
    leave the cost unchanged are allowed ``sideways`` times (never undoing the previous move).
    Returns ``(labels, remaining cost, moves made)``; cost 0 means repaired.
    """
    labels = list(labels)
    ev = _PartitionEvaluator(grid, rules)
    members = [set(cells) for cells in pieces_of(labels)]
    evals = [ev(frozenset(m)) for m in members]
    keys: Counter[tuple[Cell, ...]] = Counter(k for _, k in evals)
    cost = sum(c for c, _ in evals) + (_duplicates(keys) if rules.distinct else 0)
    last: tuple[int, int] | None = None  # (cell, piece it left) of the previous move
    moves = 0
    while cost > 0 and moves < max_moves:
        bad = {p for p, (c, k) in enumerate(evals) if c > 0 or (rules.distinct and keys[k] > 1)}
        best: list[tuple[int, int, int]] = []
        best_delta = 1
        for cell in range(grid.volume):
            a = labels[cell]
            targets = sorted({labels[q] for q in grid.neighbours[cell]} - {a})
            for b in targets:
                if (a not in bad and b not in bad) or last == (cell, b):
                    continue
                if not _connected_without(grid, members[a], cell):
                    continue
                new_a = ev(frozenset(members[a] - {cell}))
                new_b = ev(frozenset(members[b] | {cell}))
                delta = new_a[0] + new_b[0] - evals[a][0] - evals[b][0]
                if rules.distinct:
                    after = keys.copy()
                    after.subtract([evals[a][1], evals[b][1]])
                    after.update([new_a[1], new_b[1]])
                    delta += _duplicates(after) - _duplicates(keys)
                if delta < best_delta:
                    best_delta, best = delta, [(cell, a, b)]
                elif delta == best_delta:
                    best.append((cell, a, b))
        if not best or best_delta > 0 or (best_delta == 0 and sideways <= 0):
            break
        if best_delta == 0:
            sideways -= 1
        cell, a, b = best[int(rng.integers(len(best)))]
        members[a].discard(cell)
        members[b].add(cell)
        labels[cell] = b
        keys.subtract([evals[a][1], evals[b][1]])
        evals[a] = ev(frozenset(members[a]))
        evals[b] = ev(frozenset(members[b]))
        keys.update([evals[a][1], evals[b][1]])
        keys = +keys
        cost += best_delta
        last = (cell, a)
        moves += 1
    return labels, cost, moves
