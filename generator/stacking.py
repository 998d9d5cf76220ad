"""The stacking level generator, as the CHAIN appendix describes it.

``make(config, seed, index)`` is a pure function: it draws everything from its own
``numpy.random.Generator`` seeded by ``SeedSequence([seed, index])`` and returns a verified
:class:`~chaingeo.core.level.Level` or a :class:`GenerationRejection` saying why no level came
out. Modes:

- **easy**: cuboid pieces with at least two equal sides (rods, 2x2 plates, 2x2x2 cubes), a
  random multiset that fills the volume, packed (and so verified packable) by the exact-cover
  engine in a seeded random order;
- **mid**: the box carved into pieces each grown inside one plane, at least one not a cuboid;
- **hard**: free connected growth, every shape distinct up to rotation, at least one piece not
  flat, repaired by moving single voxels between adjacent pieces, and at least
  ``config.min_nodes`` exact-cover nodes to find a first packing.

Every level has connected pieces with sizes in ``[min_piece, max_piece_cells]``, no filled 2x3
face, no isolated piece, and (by default) a linear assembly. Attempts first use
``config.min_piece`` and then fall back to ``config.fallback_min_piece`` (4 then 3).

The stored solution is the carved (or, in easy mode, the engine's) packing; pieces are listed
in a random order (colours carry no hint) and handed to the agent in a random rotation.
``Level.stats``: ``mode``, ``min_piece`` (the stage that succeeded), ``pieces``, ``attempts``,
``rejected_attempts`` (reason -> count for the failed attempts before), ``repair_moves``,
``exact_cover`` (``nodes_first``: dancing-links nodes to a first packing; ``solutions`` and
``distinct`` packings when counted within ``count_budget`` nodes, else None; see
:mod:`chaingeo.generator.packing`) and ``linear_assembly`` (``[piece, direction it slides in]`` in
insertion order, or None).
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Final

import numpy as np

from chaingeo.core.colors import assign_colors
from chaingeo.core.geometry import ROTATIONS, Shape
from chaingeo.core.level import Level, stacking_level
from chaingeo.core.rules import StackingRules
from chaingeo.generator import packing
from chaingeo.generator.assembly import assembly_order, has_isolated_piece
from chaingeo.generator.config import StackingConfig, box_text
from chaingeo.generator.partition import (
    PieceRules,
    box_grid,
    grow,
    is_planar,
    piece_count_range,
    pieces_of,
    random_sizes,
    repair,
)
from chaingeo.generator.result import ATTEMPTS_KEY, GenerationRejection

GENERATOR: Final = "chaingeo.generator.stacking"
#: Bump when a change to the algorithm changes what a (config, seed, index) produces.
VERSION: Final = "1"


@dataclass(frozen=True)
class _Candidate:
    placements: list[Shape]
    assembly: list[tuple[int, str]] | None
    effort: packing.SearchEffort
    repair_moves: int


def level_id(config: StackingConfig, seed: int, index: int) -> str:
    return f"stacking-{box_text(config.box)}-{config.mode}-s{seed}-{index:06d}"


def make(config: StackingConfig, seed: int, index: int) -> Level | GenerationRejection:
    """One stacking level for item ``index`` of ``seed``, or why there is none."""
    rng = np.random.default_rng(np.random.SeedSequence([seed, index]))
    tally: Counter[str] = Counter()
    last = "no-attempts"
    for min_piece, budget in config.stages:
        impossible = stage_problem(config, min_piece)
        if impossible is not None:
            tally[impossible] += 1
            last = impossible
            continue
        for _ in range(budget):
            outcome = _attempt(config, min_piece, rng)
            if isinstance(outcome, str):
                tally[outcome] += 1
                last = outcome
                continue
            return _build(config, seed, index, min_piece, outcome, tally, rng)
    return GenerationRejection(
        reason=last, seed=seed, index=index, attempts=dict(sorted(tally.items()))
    )


def stage_problem(config: StackingConfig, min_piece: int) -> str | None:
    """Why no attempt with this ``min_piece`` can succeed (decided without randomness), or None."""
    counts = piece_count_range(config.volume, min_piece, config.max_piece_cells, config.max_pieces)
    if not counts:
        return "no-feasible-piece-count"
    if config.mode == "easy":
        parts = easy_cuboids(config.box, min_piece, config.max_piece_cells)
        if random_multiset(config.volume, parts, counts, np.random.default_rng(0)) is None:
            return "no-cuboid-multiset"
    return None


def _attempt(config: StackingConfig, min_piece: int, rng: np.random.Generator) -> _Candidate | str:
    if config.mode == "easy":
        return _attempt_easy(config, min_piece, rng)
    return _attempt_grown(config, min_piece, rng)


# ---------------------------------------------------------------------------------------------
# mid and hard: carve the box
# ---------------------------------------------------------------------------------------------


def _attempt_grown(
    config: StackingConfig, min_piece: int, rng: np.random.Generator
) -> _Candidate | str:
    grid = box_grid(config.box)
    hard = config.mode == "hard"
    ks = piece_count_range(grid.volume, min_piece, config.max_piece_cells, config.max_pieces)
    k = ks[int(rng.integers(len(ks)))]
    sizes = random_sizes(grid.volume, k, min_piece, config.max_piece_cells, rng)
    labels = grow(grid, sizes, rng, planar=not hard)
    rules = PieceRules(
        min_size=min_piece,
        max_size=config.max_piece_cells,
        planar=not hard and config.planar,
        distinct=hard,
    )
    labels, cost, moves = repair(grid, labels, rules, rng, max_moves=config.repair_moves)
    shapes = [grid.shape(cells) for cells in pieces_of(labels)]
    problem = piece_problem(shapes, rules)
    if problem is not None:
        return f"repair-failed:{problem}" if cost else problem
    if not hard and all(s.is_cuboid() for s in shapes):
        return "all-cuboids"
    if hard and all(is_planar(s) for s in shapes):
        return "all-planar"
    return _finish(config, shapes, moves)


def piece_problem(shapes: Sequence[Shape], rules: PieceRules) -> str | None:
    """The first rule a set of pieces breaks (a short kebab-case reason), or None."""
    for s in shapes:
        if not s.is_connected():
            return "disconnected-piece"
    for s in shapes:
        if not rules.min_size <= len(s) <= rules.max_size:
            return "piece-size"
    if rules.forbid_rect is not None:
        a, b = rules.forbid_rect
        if any(s.has_filled_rectangle(a, b) for s in shapes):
            return f"filled-{a}x{b}-face"
    if rules.planar and not all(is_planar(s) for s in shapes):
        return "not-planar"
    if rules.distinct and len({s.canonical() for s in shapes}) < len(shapes):
        return "repeated-shape"
    return None


def _finish(config: StackingConfig, placements: list[Shape], moves: int) -> _Candidate | str:
    if has_isolated_piece(placements):
        return "isolated-piece"
    order = assembly_order(placements, config.box)
    if config.linear_assembly and order is None:
        return "no-linear-assembly"
    nodes = packing.first_packing_nodes(placements, config.box)
    if nodes < config.min_nodes:
        return "too-little-search"
    effort = packing.search_effort(placements, config.box, nodes, count_limit=config.count_limit)
    return _Candidate(placements, order, effort, moves)


# ---------------------------------------------------------------------------------------------
# easy: cuboids packed by the exact-cover engine
# ---------------------------------------------------------------------------------------------


def easy_cuboids(box: Sequence[int], min_cells: int, max_cells: int) -> list[Shape]:
    """Cuboids with at least two equal sides that fit the box, sizes in range, no 2x3 face."""
    lim = max(box)
    out = []
    for p in range(1, lim + 1):
        for q in range(p, lim + 1):
            for r in range(q, lim + 1):
                if not (p == q or q == r) or not min_cells <= p * q * r <= max_cells:
                    continue
                cuboid = Shape([(x, y, z) for x in range(p) for y in range(q) for z in range(r)])
                if any(e > d for e, d in zip((p, q, r), sorted(box), strict=True)):
                    continue
                if cuboid.has_filled_rectangle(2, 3):
                    continue
                out.append(cuboid.canonical())
    return sorted(out, key=lambda s: (len(s), s.cells))


def random_multiset(
    volume: int, parts: Sequence[Shape], counts: range, rng: np.random.Generator
) -> list[Shape] | None:
    """A random multiset of ``parts`` filling ``volume`` with a piece count in ``counts``.

    The count is drawn uniformly among the feasible ones, then each piece uniformly among
    those that keep the rest fillable (a small dynamic programme over (cells, pieces)).
    """
    if not parts or not counts:
        return None
    top = counts[-1]
    sizes = sorted({len(p) for p in parts})
    fillable = np.zeros((volume + 1, top + 1), dtype=bool)
    fillable[0, 0] = True
    for j in range(1, top + 1):
        for v in range(1, volume + 1):
            fillable[v, j] = any(s <= v and fillable[v - s, j - 1] for s in sizes)
    feasible = [k for k in counts if fillable[volume, k]]
    if not feasible:
        return None
    k = feasible[int(rng.integers(len(feasible)))]
    chosen: list[Shape] = []
    left = volume
    for j in range(k, 0, -1):
        options = [p for p in parts if len(p) <= left and fillable[left - len(p), j - 1]]
        pick = options[int(rng.integers(len(options)))]
        chosen.append(pick)
        left -= len(pick)
    return chosen


def _attempt_easy(
    config: StackingConfig, min_piece: int, rng: np.random.Generator
) -> _Candidate | str:
    parts = easy_cuboids(config.box, min_piece, config.max_piece_cells)
    counts = piece_count_range(config.volume, min_piece, config.max_piece_cells, config.max_pieces)
    drawn = random_multiset(config.volume, parts, counts, rng)
    if drawn is None:  # pragma: no cover - stage_problem rules this out first
        return "no-cuboid-multiset"
    pieces = sorted(drawn, key=lambda s: (len(s), s.cells))
    found_any = False
    seed = int(rng.integers(2**63))
    for placements in packing.seeded_packings(pieces, config.box, seed, config.easy_packings):
        found_any = True
        outcome = _finish(config, placements, 0)
        if not isinstance(outcome, str) or outcome != "no-linear-assembly":
            return outcome
    return "no-linear-assembly" if found_any else "not-packable"


# ---------------------------------------------------------------------------------------------
# The level
# ---------------------------------------------------------------------------------------------


def _build(
    config: StackingConfig,
    seed: int,
    index: int,
    min_piece: int,
    cand: _Candidate,
    tally: Counter[str],
    rng: np.random.Generator,
) -> Level:
    """Shuffle the pieces (colours carry no hint), hand each in a random rotation, verify."""
    n = len(cand.placements)
    perm = [int(i) for i in rng.permutation(n)]
    placements = [cand.placements[i] for i in perm]
    handed = [
        p.rotate(ROTATIONS[int(rng.integers(len(ROTATIONS)))]).normalized() for p in placements
    ]
    position = {old: new for new, old in enumerate(perm)}
    names = [c.name for c in assign_colors(n)]  # the names stacking_level gives, in order
    stats: dict[str, Any] = {
        "mode": config.mode,
        "min_piece": min_piece,
        "pieces": n,
        "attempts": sum(tally.values()) + 1,
        ATTEMPTS_KEY: dict(sorted(tally.items())),
        "repair_moves": cand.repair_moves,
        "exact_cover": cand.effort.to_json(),
        "linear_assembly": None
        if cand.assembly is None
        else [[names[position[i]], d] for i, d in cand.assembly],
    }
    return stacking_level(
        level_id(config, seed, index),
        config.mode,
        config.box,
        placements,
        rules=StackingRules(support=config.support),
        handed=handed,
        generator=GENERATOR,
        version=VERSION,
        seed=seed,
        index=index,
        stats=stats,
    )
