"""Standard six-piece burrs: six 2x2x8 sticks, holey pieces, searched for high levels.

Bill Cutler's exhaustive analysis of all standard six-piece burrs (pieces 2x2x8, any of the 12
inner cubes of a piece removable) found level 12 at most (Love's Dozen), no level 11, a few
unique level-10 designs and level 5 as the best unique notchable design. The ``burr6`` layout
uses 2x2x6 sticks, which leave the knot after fewer moves; this module keeps Cutler's geometry:
the classic three-pairs arrangement of :data:`chaingeo.core.piecesets.burrs.SLOTS`, every stick
lengthened by one unit at both ends (8 x 8 x 8 bounding cube).

A *design* says, for each of the 32 cells where two or three sticks cross, which stick owns it
or that it stays empty (:class:`chaingeo.generator.layouts.Layout`). Those cells are exactly the 12
inner cubes of each stick, so every piece is a 2x2x8 stick minus any subset of its inner cubes
(holey pieces, not only notchable ones) and any design is a non-overlapping assembly. A piece must
stay connected; that test runs on 32-bit masks (one bit per cell of the stick), memoised per code.

The search (:func:`standard_burr_search`) is simulated annealing on single cubes with restarts:
each restart draws a random connected design that comes apart, then changes one cube at a time
(give it to another stick, or empty it), scoring by (level, moves) from
:func:`chaingeo.solvers.motion.disassemble.analyze_assembly` and accepting a worse design with a
probability
that falls to zero over the restart (a pure hill climb at the end). Designs that do not come apart
completely are never accepted. With ``unique`` the kept design must also assemble in exactly
one way (:func:`assembly_counts`). Only state caps bound the work, so a (seed, index) gives the
same design on every machine.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from functools import cache

import numpy as np

from chaingeo.core.geometry import Cell, Shape
from chaingeo.core.kinematics import SearchLimitError
from chaingeo.core.piecesets.burrs import SLOTS
from chaingeo.generator.candidate import (
    Candidate,
    Score,
    evaluate,
    piece_names,
    probe_search,
)
from chaingeo.generator.config import PuzzleConfig
from chaingeo.generator.layouts import Layout
from chaingeo.solvers.assembly.assemble import iter_assemblies
from chaingeo.solvers.cover.problem import PieceSpec
from chaingeo.solvers.limits import SearchLimits
from chaingeo.solvers.motion.disassemble import Analysis, analyze_assembly
from chaingeo.solvers.motion.partsearch import PieceTable

#: Stick length of Cutler's standard six-piece burr.
STICK_LENGTH = 8
Design = tuple[int, ...]


def standard_slot(axis: int, corner: Cell) -> Shape:
    """The 2x2x8 box of a slot of :data:`SLOTS`, lengthened by one unit at each end (and
    shifted by one on the other axes so that every coordinate is 0..7)."""
    lo = [c + 1 for c in corner]
    lo[axis] = 0
    size = [2, 2, 2]
    size[axis] = STICK_LENGTH
    return Shape(
        [
            (lo[0] + i, lo[1] + j, lo[2] + k)
            for i in range(size[0])
            for j in range(size[1])
            for k in range(size[2])
        ]
    )


@cache
def standard_layout() -> Layout:
    """The standard six-piece burr as a layout: 32 shared cells (24 in two sticks, the 2x2x2
    core in three), i.e. the 12 inner cubes of each stick."""
    return Layout(
        "burr6x8",
        tuple(standard_slot(a, c) for a, c in SLOTS),
        "standard six-piece burr: six 2x2x8 sticks, three pairs crossing, holey pieces",
    )


@dataclass(frozen=True)
class _Stick:
    """One slot's cells in a fixed order, its inner cubes, and the cells' neighbour masks."""

    cells: tuple[Cell, ...]
    inner: tuple[int, ...]  # index into ``cells`` of each shared cell the slot may own
    neighbours: tuple[int, ...]  # bit mask of the face neighbours of each cell


@cache
def _sticks() -> tuple[_Stick, ...]:
    layout = standard_layout()
    shared = set(layout.shared)
    out = []
    for slot in layout.slots:
        cells = tuple(sorted(slot.cells))
        where = {c: i for i, c in enumerate(cells)}
        inner = tuple(i for i, c in enumerate(cells) if c in shared)
        if len(cells) != 4 * STICK_LENGTH or len(inner) != 12:
            raise RuntimeError("a standard burr stick has 32 cells, 12 of them inner")
        neighbours = []
        for x, y, z in cells:
            mask = 0
            for d in ((1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1)):
                j = where.get((x + d[0], y + d[1], z + d[2]))
                if j is not None:
                    mask |= 1 << j
            neighbours.append(mask)
        out.append(_Stick(cells, inner, tuple(neighbours)))
    return tuple(out)


@cache
def _slot_cell_of_shared() -> tuple[tuple[tuple[int, int], ...], ...]:
    """For each shared cell (layout order): the (slot, bit of the slot's cell) of each owner."""
    layout = standard_layout()
    sticks = _sticks()
    out = []
    for cell in layout.shared:
        out.append(tuple((k, sticks[k].cells.index(cell)) for k in layout.owners(cell)))
    return tuple(out)


@cache
def _mask_connected(slot: int, mask: int) -> bool:
    """Are the cells of ``mask`` (bits of the slot's cells) one face-connected piece?"""
    if mask == 0:
        return False
    nb = _sticks()[slot].neighbours
    seen = mask & -mask
    frontier = seen
    while frontier:
        grow = 0
        while frontier:
            low = frontier & -frontier
            grow |= nb[low.bit_length() - 1]
            frontier ^= low
        frontier = grow & mask & ~seen
        seen |= frontier
    return seen == mask


def piece_masks(design: Sequence[int]) -> list[int]:
    """Each piece as a bit mask over its slot's 32 cells."""
    sticks = _sticks()
    masks = []
    for st in sticks:
        inner = 0
        for i in st.inner:
            inner |= 1 << i
        masks.append(((1 << len(st.cells)) - 1) & ~inner)
    for cell_owners, owner in zip(_slot_cell_of_shared(), design, strict=True):
        for k, bit in cell_owners:
            if k == owner:
                masks[k] |= 1 << bit
    return masks


def broken_pieces(design: Sequence[int]) -> int:
    """How many pieces of ``design`` are not connected."""
    return sum(not _mask_connected(k, m) for k, m in enumerate(piece_masks(design)))


@cache
def _piece_shape(slot: int, mask: int) -> Shape:
    cells = _sticks()[slot].cells
    return Shape([cells[i] for i in range(len(cells)) if mask >> i & 1])


def design_pieces(design: Sequence[int]) -> list[Shape]:
    """The six pieces of ``design`` in their assembled places (slot order)."""
    return [_piece_shape(k, m) for k, m in enumerate(piece_masks(design))]


# -- assembly count --------------------------------------------------------------------------


def assembly_counts(
    shapes: Sequence[Shape],
    limits: SearchLimits,
    stop_at: int | None = None,
    max_group: int | None = None,
) -> tuple[int, int]:
    """``(assemblies, solutions)`` of the pieces in the standard burr's shape, BurrTools' way:
    the 72 outer cubes of the sticks must be filled and the 32 inner cells may be (a holey
    burr may leave different cells empty in another assembly). Identical pieces are one piece
    type used that many times, so swapping them is not another assembly. A *solution* is an
    assembly that comes apart; the pieces "assemble uniquely" when there is exactly one, since
    an assembly that cannot be taken apart cannot be put together either. ``stop_at``: stop
    counting once that many solutions are found (then both figures are lower bounds); asking
    "unique?" needs ``stop_at=2``, which rejects most designs after a few assemblies."""
    layout = standard_layout()
    knot = sorted({c for s in layout.slots for c in s.cells})
    groups: dict[Shape, list[Shape]] = {}
    for s in shapes:
        groups.setdefault(s.canonical(), []).append(s)
    specs = [
        PieceSpec(members[0], f"q{i}", len(members), len(members))
        for i, (_, members) in enumerate(sorted(groups.items(), key=lambda kv: kv[0].cells))
    ]
    assemblies = solutions = 0
    for asm in iter_assemblies(specs, Shape(knot), optional=Shape(layout.shared)):
        assemblies += 1
        if analyze_assembly(asm, max_group=max_group, limits=limits, optimal=False).disassemblable:
            solutions += 1
            if stop_at is not None and solutions >= stop_at:
                break
    return assemblies, solutions


# -- the search ------------------------------------------------------------------------------


def _energy(score: Score) -> float:
    """One number for annealing: the level first, total moves as a fraction below one level."""
    level, moves = score
    return level + min(moves, 99) / 100.0


def _mutate(design: list[int], hole_rate: float, rng: np.random.Generator) -> tuple[int, int]:
    """Change one cube: empty it (chance ``hole_rate``) or give it to another stick that
    crosses it. Returns (cell index, old owner)."""
    owners_of = _slot_cell_of_shared()
    i = int(rng.integers(len(design)))
    old = design[i]
    owners = [k for k, _ in owners_of[i] if k != old]
    if old >= 0 and rng.random() < hole_rate:
        design[i] = -1
    else:
        design[i] = int(owners[int(rng.integers(len(owners)))])
    return i, old


def _random_connected(hole_rate: float, rng: np.random.Generator) -> list[int] | None:
    """A random design repaired towards connected pieces one cube at a time (None: failed)."""
    owners_of = _slot_cell_of_shared()
    design = [
        -1 if rng.random() < hole_rate else int(o[int(rng.integers(len(o)))][0]) for o in owners_of
    ]
    broken = broken_pieces(design)
    for _ in range(400):
        if broken == 0:
            return design
        i, old = _mutate(design, hole_rate, rng)
        now = broken_pieces(design)
        if now > broken:
            design[i] = old
        else:
            broken = now
    return None


@dataclass(frozen=True)
class _Verdict:
    """A design's analysis (None unless it comes apart) and its annealing energy."""

    analysis: Analysis | None
    energy: float


def _graph_depth(shapes: Sequence[Shape], config: PuzzleConfig) -> int | None:
    """For a design that does not come apart: how many moves deep its reachable configurations
    go (breadth-first from the assembled state). A deep locked design is one opened exit away
    from a high level, so the walk may cross it; None past the probe's state cap."""
    table = PieceTable(piece_names(shapes))
    n = len(shapes)
    try:
        search = probe_search(table, n, config)
        while not search.exhausted:
            search.expand_layer()
    except SearchLimitError:
        return None
    return search.depth - 1


class _Evaluator:
    """The verdict per design, memoised (the walk revisits designs often)."""

    def __init__(self, config: PuzzleConfig) -> None:
        self.config = config
        self.memo: dict[Design, _Verdict | None] = {}

    def __call__(self, design: Sequence[int]) -> _Verdict | None:
        key = tuple(design)
        if key not in self.memo:
            self.memo[key] = self._judge(key)
        return self.memo[key]

    def _judge(self, design: Design) -> _Verdict | None:
        if broken_pieces(design):
            return None
        shapes = design_pieces(design)
        analysis = evaluate(shapes, self.config)
        if analysis is not None:
            return _Verdict(analysis, _energy((analysis.first_level or 0, analysis.moves or 0)))
        depth = _graph_depth(shapes, self.config)
        return None if depth is None else _Verdict(None, depth - LOCKED_PENALTY)


@dataclass
class SearchOutcome:
    """The design kept, with what the search measured (written into the level's stats)."""

    candidate: Candidate
    design: Design
    evaluations: int
    assemblies: int | None = None
    solutions: int | None = None

    def stats(self) -> dict[str, object]:
        out: dict[str, object] = {
            "design": "".join("." if o < 0 else str(o) for o in self.design),
            "evaluations": self.evaluations,
        }
        if self.assemblies is not None:
            out["assemblies"] = self.assemblies
            out["solutions"] = self.solutions
        return out


def _anneal(
    start: list[int], evaluator: _Evaluator, config: PuzzleConfig, rng: np.random.Generator
) -> dict[Design, Score]:
    """One restart: ``hill_steps`` single-cube changes from ``start`` (connected, within the
    caps, maybe locked); returns every design met
    that comes apart, with its score. Locked designs may be crossed (see :func:`_graph_depth`)
    but are never returned."""
    design = list(start)
    verdict = evaluator(design)
    assert verdict is not None
    energy = verdict.energy
    seen: dict[Design, Score] = {}
    steps = max(1, config.hill_steps)
    for step in range(steps):
        temperature = TEMPERATURE * (1.0 - step / steps)
        i, old = _mutate(design, config.hole_rate, rng)
        verdict = evaluator(design)
        draw = rng.random()
        if verdict is None:
            design[i] = old
            continue
        if verdict.analysis is not None:
            a = verdict.analysis
            seen[tuple(design)] = (a.first_level or 0, a.moves or 0)
        delta = verdict.energy - energy
        if delta >= 0 or (temperature > 0 and draw < math.exp(delta / temperature)):
            energy = verdict.energy
        else:
            design[i] = old
    return seen


def _kick(
    design: Design, hole_rate: float, evaluator: _Evaluator, rng: np.random.Generator
) -> list[int] | None:
    """``design`` after :data:`KICK` random single-cube changes that keep it connected and
    within the caps (a restart near the best design, not from scratch)."""
    out = list(design)
    for _ in range(KICK):
        for _ in range(20):
            i, old = _mutate(out, hole_rate, rng)
            if evaluator(out) is not None:
                break
            out[i] = old
    return out if evaluator(out) is not None else None


#: Restarts after the first begin from the best design so far, ``KICK`` cubes changed
#: (iterated local search); a fresh random design when False.
RESTART_FROM_BEST = True
KICK = 4
#: Starting temperature (in levels) of each restart: a design one level worse is accepted with
#: chance exp(-1 / T) at the start, falling to a pure hill climb at the end.
TEMPERATURE = 0.6
#: Energy below its depth of a locked design (a design that comes apart scores its level);
#: 1 did worse (mean level 5.6 over 8 items) than 2 to 4 (6.4 to 6.5).
LOCKED_PENALTY = 3.0
#: Random connected designs tried per restart before giving up on finding one that comes apart.
START_TRIES = 60
#: Best distinct designs checked for a unique assembly (best first) when ``unique`` is asked:
#: about one design of the walk in 25 assembles uniquely (27 sampled from one walk: 1), and a
#: check that stops at the second solution takes about 0.2 s.
UNIQUE_CANDIDATES = 200
#: Designs checked for uniqueness differ from one another in at least this many cells: what
#: makes a design assemble twice (a piece that fits another slot) survives small changes, so
#: the 200 best designs, neighbours of one another, all failed together (seed 2026, item 0).
UNIQUE_SPREAD = 4


def _unique_climb(
    found: SearchOutcome,
    evaluator: _Evaluator,
    config: PuzzleConfig,
    limits: SearchLimits,
    rng: np.random.Generator,
) -> SearchOutcome:
    """Hill climb from a uniquely assembling design, keeping a single-cube change when the
    design still comes apart, its (level, moves) does not drop and it still assembles uniquely
    (checked only for changes that pass the first two tests, as that check is ~50 times the
    cost of an evaluation). ``hill_steps / 3`` changes."""
    best = found
    design = list(found.design)
    memo: dict[Design, tuple[int, int]] = {}
    for _ in range(config.hill_steps // 3):
        i, old = _mutate(design, config.hole_rate, rng)
        verdict = evaluator(design)
        a = None if verdict is None else verdict.analysis
        if a is None or (a.first_level or 0, a.moves or 0) < best.candidate.score:
            design[i] = old
            continue
        trial = SearchOutcome(Candidate(design_pieces(design), a), tuple(design), 0)
        if trial.design not in memo:
            try:
                memo[trial.design] = assembly_counts(
                    trial.candidate.shapes, limits, 2, config.max_group
                )
            except SearchLimitError:
                memo[trial.design] = (0, 0)  # undecided within the caps: not proven unique
        counts = memo[trial.design]
        if counts[1] != 1:
            design[i] = old
            continue
        trial.assemblies, trial.solutions = counts
        best = trial
    best.evaluations = len(evaluator.memo)
    return best


def _outcome(design: Design, evaluator: _Evaluator, evaluations: int) -> SearchOutcome:
    verdict = evaluator(design)
    assert verdict is not None and verdict.analysis is not None
    return SearchOutcome(Candidate(design_pieces(design), verdict.analysis), design, evaluations)


def standard_burr_search(config: PuzzleConfig, rng: np.random.Generator) -> SearchOutcome | None:
    """``config.restarts`` annealing runs of ``config.hill_steps`` single-cube changes; the
    best design (by level, then moves) over all of them, or with ``unique`` the best that
    assembles in exactly one way. None when no restart found a design that comes apart."""
    evaluator = _Evaluator(config)
    pool: dict[Design, Score] = {}
    for _ in range(max(1, config.restarts)):
        start: list[int] | None = None
        if pool and RESTART_FROM_BEST:
            best = min(pool.items(), key=lambda kv: (-kv[1][0], -kv[1][1], kv[0]))[0]
            start = _kick(best, config.hole_rate, evaluator, rng)
        for _ in range(START_TRIES if start is None else 0):
            design = _random_connected(config.hole_rate, rng)
            if design is not None and evaluator(design) is not None:
                start = design
                break
        if start is None:
            continue
        pool.update(_anneal(start, evaluator, config, rng))
    if not pool:
        return None
    ranked = sorted(pool.items(), key=lambda kv: (-kv[1][0], -kv[1][1], kv[0]))
    evaluations = len(evaluator.memo)
    if not (config.unique or config.shape.endswith("u")):
        return _outcome(ranked[0][0], evaluator, evaluations)
    limits = SearchLimits(max_states=config.probe_states, seconds=config.seconds)
    checked: list[np.ndarray] = []
    for kept, _ in ranked:
        if len(checked) >= UNIQUE_CANDIDATES:
            break
        row = np.array(kept, dtype=np.int8)
        if any(int(np.count_nonzero(row != c)) < UNIQUE_SPREAD for c in checked):
            continue  # too close to a design already found not unique
        checked.append(row)
        outcome = _outcome(kept, evaluator, evaluations)
        try:
            outcome.assemblies, outcome.solutions = assembly_counts(
                outcome.candidate.shapes, limits, stop_at=2, max_group=config.max_group
            )
        except SearchLimitError:
            continue  # some assembly could not be decided within the caps: not proven unique
        if outcome.solutions == 1:
            return _unique_climb(outcome, evaluator, config, limits, rng)
    return None
