"""Exact cover for polycube packing: count, enumerate, first, seeded-random solutions.

Public API (pieces: a ``{name: Shape}`` mapping, a list of :class:`Shape`, or a list of
:class:`PieceSpec` with ``min``/``max`` copies; target: any :class:`Shape` or box sizes
``(a, b, c)``; ``optional``: target cells that may stay empty)::

    count_packings(pieces, target, *, distinct=True, reflections=True, optional=None,
                    engine="auto", node_limit=None, symmetry=True) -> CoverResult
    iter_packings(pieces, target, *, distinct=False, symmetry=False, ...) -> Iterator[Solution]
    first_packing(pieces, target, ...) -> Solution | None
    random_packings(pieces, target, rng, ...) -> Iterator[Solution]
    cover_problem(pieces, target, ...) -> CoverProblem   # compiled + cached, reusable
    CoverSearch(problem, rows=None, engine=..., rng=..., node_limit=...)  # low level

*Solutions* are sets of placed shapes: identical pieces (same shape up to rotation) are
interchangeable, so they are never counted twice in different orders. ``distinct`` counts
solutions up to the target's own symmetries: its rotations, plus its reflections when
``reflections=True`` and the piece multiset is mirror-invariant (a reflection turns each
piece into its mirror image, so the count only makes sense if those are pieces too; BurrTools
style "rotations only" is ``reflections=False``).

*Symmetry reduction* (``symmetry=True``): the anchored rows (those of a piece used exactly
once, else those through a mandatory cell, under the subgroup fixing that cell) are cut to one
per orbit of the group. Then ``solutions = sum(orbit size x solutions with that anchor row)``
exactly. With an achiral unique piece under the whole group, ``distinct`` is the number of
free-orbit solutions plus the distinct canonical forms of the few solutions whose anchor
placement is itself symmetric; otherwise the reduced solutions are enumerated and
canonicalised (:func:`canonical_forms`). ``iter_packings(distinct=True, symmetry=True)``
lists one solution per class from the reduced search (the default keeps the plain order).

*Engines*: ``"bitboard"`` (the default, as ``"auto"``) or ``"dlx"`` (dancing links, MRV). The
bit-board branches on the first empty cell (``"bitboard-first"``, at most 64 cells) or on the
most constrained cell (``"bitboard-mrv"``, any size); ``"bitboard"`` picks between them by the
rule of :func:`chaingeo.solvers.cover.search.auto_kernel` (first cell for one-layer targets).
Every function
also accepts a compiled :class:`CoverProblem` in place of ``pieces`` (then no ``target``).
``nodes`` in :class:`CoverStats` are rows placed (the generator's difficulty proxy), ``updates``
the engine's unit of work. At ``node_limit`` nodes a :class:`CoverLimitError` (a
``SearchLimitError``) is raised carrying the solutions found so far and the stats; iterators
first yield what they found. Every function also takes a ``deadline``
(:class:`chaingeo.solvers.deadline.Deadline`): past it the search stops with the deadline's
``SearchLimitError`` (it names ``seconds``), iterators again first yielding what they found.
"""

from __future__ import annotations

import time
from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np

from chaingeo.core.arrays import I32
from chaingeo.core.geometry import Shape
from chaingeo.solvers.cover.problem import (
    CoverError,
    CoverProblem,
    PiecesLike,
    PieceSpec,
    TargetLike,
    cover_problem,
)
from chaingeo.solvers.cover.search import CoverLimitError, CoverSearch, CoverStats, Engine
from chaingeo.solvers.deadline import Deadline
from chaingeo.solvers.jobs import Farm

__all__ = [
    "AnchorPlan",
    "CoverError",
    "CoverLimitError",
    "CoverProblem",
    "CoverResult",
    "CoverSearch",
    "CoverStats",
    "PieceSpec",
    "Solution",
    "anchor_plan",
    "canonical_forms",
    "count_packings",
    "cover_problem",
    "first_packing",
    "iter_packings",
    "random_packings",
]


@dataclass(frozen=True)
class CoverResult:
    solutions: int  # every solution
    distinct: int | None  # up to the symmetry group (None when not asked for)
    stats: CoverStats
    symmetry_order: int  # size of the (faithful) group ``distinct`` is taken under
    anchor: str | None  # the anchor piece used for symmetry reduction, if any


@dataclass(frozen=True)
class Solution:
    """One packing: ``placements`` are ``(piece name, placed shape)`` in the pieces' order."""

    placements: tuple[tuple[str, Shape], ...]
    rows: tuple[int, ...]  # the problem's row ids, sorted

    @property
    def shapes(self) -> list[Shape]:
        return [s for _, s in self.placements]


def make_solution(problem: CoverProblem, rows: I32) -> Solution:
    ids = sorted(int(r) for r in rows if r >= 0)
    per_type: dict[int, list[int]] = {}
    for r in ids:
        per_type.setdefault(int(problem.row_type[r]), []).append(r)
    named: list[tuple[str, Shape]] = []
    for t, ty in enumerate(problem.types):
        for slot, r in zip(ty.slots, per_type.get(t, []), strict=False):
            named.append((slot, problem.placed_shape(r)))
    order = {
        name: i for i, name in enumerate(dict.fromkeys(n for ty in problem.types for n in ty.slots))
    }
    named.sort(key=lambda p: order[p[0]])
    return Solution(tuple(named), tuple(ids))


# -- symmetry -----------------------------------------------------------------------------------


@dataclass(frozen=True)
class AnchorPlan:
    """Symmetry reduction: the anchored ``rows`` are cut to one per orbit of ``group``.

    The anchor is a piece used exactly once (its rows) or, failing that, a mandatory cell (the
    rows through it, under the subgroup fixing the cell). Every solution has exactly one
    anchored row, so restricting them to orbit representatives loses no symmetry class.
    """

    label: str  # the anchor piece's name, or "cell [x, y, z]"
    rows: I32  # every anchored row
    group: I32  # the subgroup used (indices into the problem's row maps)
    exact: bool  # a unique piece under the whole group: free-rep solutions are all distinct
    free_reps: I32  # reps whose stabiliser is trivial (orbit size len(group))
    fixed_reps: I32  # reps with a non-trivial stabiliser
    fixed_orbit: I32  # orbit size of each fixed rep


def _orbits(maps: I32, group: I32, rows: I32) -> tuple[I32, I32, I32]:
    """Orbit representatives of ``rows`` under ``group``: free, fixed, and fixed orbit sizes."""
    sub = maps[group]
    reps = np.unique(sub[:, rows].min(axis=0))
    stab = (sub[:, reps] == reps[None, :]).sum(axis=0)
    free = reps[stab == 1].astype(np.int32)
    fixed = reps[stab > 1].astype(np.int32)
    return free, fixed, (len(group) // stab[stab > 1]).astype(np.int32)


def anchor_plan(problem: CoverProblem, prefer: str | None = None) -> AnchorPlan | None:
    """The anchor for symmetry reduction (None when the problem has no symmetry).

    A piece used exactly once is preferred: the named one if given, else an achiral one (the
    whole group applies) with the fewest orientations (the most symmetric piece goes first,
    as in Knuth's pentomino runs), then the fewest representatives per placement. Without such
    a piece, a mandatory cell with the largest stabiliser anchors instead.
    """
    syms, maps = problem.symmetry
    if len(syms) == 1:
        return None
    proper = np.array([round(np.linalg.det(m)) > 0 for m, _ in syms])
    best: tuple[tuple[int, int, int, float, int], AnchorPlan] | None = None
    for t, ty in enumerate(problem.types):
        a, b = int(problem.row_start[t]), int(problem.row_start[t + 1])
        if not (ty.lo == 1 and ty.hi == 1) or b == a:
            continue
        full = not ty.chiral or bool(proper.all())
        group = np.flatnonzero(np.ones(len(syms), bool) if full else proper).astype(np.int32)
        rows = np.arange(a, b, dtype=np.int32)
        free, fixed, orbit = _orbits(maps, group, rows)
        plan = AnchorPlan(ty.slots[0], rows, group, full, free, fixed, orbit)
        n_reps = len(free) + len(fixed)
        score = (
            0 if ty.slots[0] == prefer else 1,
            0 if full else 1,
            len(problem.table[t].orientations),
            n_reps / (b - a),
            n_reps,
        )
        if best is None or score < best[0]:
            best = (score, plan)
    return best[1] if best is not None else _cell_anchor(problem)


def _cell_anchor(problem: CoverProblem) -> AnchorPlan | None:
    _, maps = problem.symmetry
    perms = problem.cell_permutations()
    stab = (perms == np.arange(problem.n_cells)[None, :]).sum(axis=0)
    mandatory = np.ones(problem.n_cells, dtype=bool)
    mandatory[sorted(problem.optional)] = False
    stab[~mandatory] = 0
    if stab.max() <= 1:
        return None
    ptr = problem.row_ptr
    owner = np.repeat(np.arange(problem.n_rows, dtype=np.int32), np.diff(ptr))
    best: tuple[int, AnchorPlan] | None = None
    for c in np.flatnonzero(stab == stab.max()):
        group = np.flatnonzero(perms[:, c] == c).astype(np.int32)
        rows = np.unique(owner[problem.flat_cells == c]).astype(np.int32)
        if len(rows) == 0:
            continue
        free, fixed, orbit = _orbits(maps, group, rows)
        label = f"cell {problem.target.cells[int(c)]}"
        plan = AnchorPlan(label, rows, group, False, free, fixed, orbit)
        if best is None or len(free) + len(fixed) < best[0]:
            best = (len(free) + len(fixed), plan)
    return None if best is None else best[1]


def canonical_forms(problem: CoverProblem, solutions: I32, chunk: int = 4096) -> I32:
    """Lexicographically least sorted row set of each solution over the symmetry group.

    ``solutions`` is ``(n, k)`` row ids, ``-1`` padded; the result is ``(n, k)`` (padding last).
    """
    _, maps = problem.symmetry
    big = np.int32(np.iinfo(np.int32).max)
    out = np.empty(solutions.shape, dtype=np.int32)
    for s in range(0, len(solutions), chunk):
        sol = solutions[s : s + chunk]
        imgs = np.where(sol[None] >= 0, maps[:, np.maximum(sol, 0)], big)  # (G, n, k)
        imgs.sort(axis=2)
        alive = np.ones(imgs.shape[:2], dtype=bool)
        for p in range(imgs.shape[2]):
            col = np.where(alive, imgs[:, :, p], big)
            m = col.min(axis=0)
            alive &= imgs[:, :, p] == m[None, :]
            out[s : s + chunk, p] = m
    return np.where(out == big, -1, out)


def _count_distinct_forms(problem: CoverProblem, blocks: list[I32]) -> int:
    if not blocks:
        return 0
    width = max(b.shape[1] for b in blocks)
    sols = np.concatenate(
        [np.pad(b, ((0, 0), (0, width - b.shape[1])), constant_values=-1) for b in blocks]
    )
    return len(np.unique(canonical_forms(problem, sols), axis=0))


def _restricted_rows(problem: CoverProblem, plan: AnchorPlan, reps: I32) -> I32:
    keep = np.ones(problem.n_rows, dtype=bool)
    keep[plan.rows] = False
    keep[reps] = True
    return np.flatnonzero(keep).astype(np.int32)


def count_packings(
    pieces: PiecesLike | CoverProblem,
    target: TargetLike | None = None,
    *,
    distinct: bool = True,
    reflections: bool = True,
    optional: Shape | None = None,
    engine: Engine = "auto",
    node_limit: int | None = None,
    symmetry: bool = True,
    anchor: str | None = None,
    deadline: Deadline | None = None,
    jobs: int | Farm = 1,
) -> CoverResult:
    """Count all solutions and (if asked) the distinct ones up to the target's symmetries.
    ``jobs`` > 1: the searches' subtrees on that many worker processes, or on the Dask cluster
    of a :class:`chaingeo.solvers.jobs.Farm` (:mod:`chaingeo.solvers.cover.parallel`; not with
    a node limit or a deadline), the same counts."""
    problem = _problem(pieces, target, optional, reflections)
    syms, _ = problem.symmetry
    plan = anchor_plan(problem, anchor) if symmetry else None
    budget = _CoverBudget(node_limit, deadline, jobs, engine)
    if plan is None:
        search = budget.search(problem, None, engine)
        if not distinct:
            total = budget.count(search)
            return CoverResult(total, None, budget.stats, len(syms), None)
        every = budget.collect(search)
        return CoverResult(
            sum(len(b) for b in every),
            _count_distinct_forms(problem, every),
            budget.stats,
            len(syms),
            None,
        )
    h = len(plan.group)
    total = 0
    n_distinct = 0
    blocks: list[I32] = []
    if len(plan.free_reps):
        search = budget.search(problem, _restricted_rows(problem, plan, plan.free_reps), engine)
        if distinct and not plan.exact:
            found = budget.collect(search)
            blocks.extend(found)
            total += h * sum(len(b) for b in found)
        else:
            n = budget.count(search)
            total += h * n
            n_distinct += n
    if len(plan.fixed_reps):
        search = budget.search(problem, _restricted_rows(problem, plan, plan.fixed_reps), engine)
        found = budget.collect(search)
        blocks.extend(found)
        orbit_of = dict(zip(plan.fixed_reps.tolist(), plan.fixed_orbit.tolist(), strict=True))
        anchor_rows = set(orbit_of)
        for block in found:
            for sol in block:
                r = next(int(x) for x in sol if int(x) in anchor_rows)
                total += orbit_of[r]
    if distinct:
        n_distinct += _count_distinct_forms(problem, blocks)
    return CoverResult(total, n_distinct if distinct else None, budget.stats, len(syms), plan.label)


class _CoverBudget:
    """Shares one node limit (and the deadline) across the several searches of a count."""

    def __init__(
        self,
        node_limit: int | None,
        deadline: Deadline | None,
        jobs: int | Farm = 1,
        engine: Engine = "auto",
    ) -> None:
        if node_limit is not None and node_limit < 0:
            raise CoverError(f"node_limit: must be >= 0, got {node_limit}")
        if not isinstance(jobs, Farm) and (
            isinstance(jobs, bool) or not isinstance(jobs, int) or jobs < 1
        ):
            raise CoverError(f"jobs: expected a positive number of processes, got {jobs!r}")
        self.limit = node_limit
        self.deadline = deadline
        self.stats = CoverStats()
        self.found = 0
        bounded = deadline is not None and deadline.bounded
        farm = jobs if isinstance(jobs, Farm) else Farm(jobs)
        self.farm = farm if node_limit is None and not bounded else Farm(1)
        self.engine = engine

    def _parallel(self, search: CoverSearch, collect: bool) -> list[I32]:
        """The search's subtrees on the workers (its own kernel never runs)."""
        from chaingeo.solvers.cover import parallel

        t0 = time.perf_counter()
        if collect:
            blocks, nodes = parallel.collect_parallel(
                search.problem, search.rows, self.engine, self.farm
            )
            found = sum(len(b) for b in blocks)
        else:
            blocks = []
            found, nodes = parallel.count_parallel(
                search.problem, search.rows, self.engine, self.farm
            )
        seconds = time.perf_counter() - t0
        self.stats += CoverStats(nodes, 0, seconds, search.engine, search.kernel)
        self.found += found
        self.parallel_found = found
        return blocks

    def _worth_workers(self, search: CoverSearch) -> bool:
        from chaingeo.solvers.cover.parallel import MIN_ROWS

        return self.farm.parallel and len(search.rows) >= MIN_ROWS

    def search(self, problem: CoverProblem, rows: I32 | None, engine: Engine) -> CoverSearch:
        left = None if self.limit is None else max(self.limit - self.stats.nodes, 0)
        return CoverSearch(problem, rows, engine=engine, node_limit=left, deadline=self.deadline)

    def _run(self, search: CoverSearch, collect: bool) -> list[I32]:
        blocks: list[I32] = []
        try:
            if collect:
                blocks.extend(search.batches(4096))
            else:
                search.count()
        except CoverLimitError:
            self.stats += search.stats
            raise CoverLimitError(self.limit or 0, self.found + search.found, self.stats) from None
        self.stats += search.stats
        self.found += search.found
        return blocks

    def count(self, search: CoverSearch) -> int:
        if self._worth_workers(search):
            self._parallel(search, False)
            return self.parallel_found
        self._run(search, False)
        return search.found

    def collect(self, search: CoverSearch) -> list[I32]:
        if self._worth_workers(search):
            return self._parallel(search, True)
        return self._run(search, True)


def _problem(
    pieces: PiecesLike | CoverProblem,
    target: TargetLike | None,
    optional: Shape | None,
    reflections: bool,
) -> CoverProblem:
    if isinstance(pieces, CoverProblem):
        return pieces
    if target is None:
        raise CoverError("target: required unless a compiled CoverProblem is given")
    return cover_problem(pieces, target, optional=optional, reflections=reflections)


def iter_packings(
    pieces: PiecesLike | CoverProblem,
    target: TargetLike | None = None,
    *,
    distinct: bool = False,
    reflections: bool = True,
    optional: Shape | None = None,
    engine: Engine = "auto",
    node_limit: int | None = None,
    symmetry: bool = False,
    deadline: Deadline | None = None,
) -> Iterator[Solution]:
    """Every solution, lazily, in the engine's fixed order; ``distinct=True`` yields one per
    symmetry class (the first met), remembering the canonical form of each class.

    ``symmetry=True`` (with ``distinct``) searches the anchor-reduced problem instead, up to
    the group's order faster; the classes then come in a different order and each is
    represented by a solution with its anchor at an orbit representative.
    """
    problem = _problem(pieces, target, optional, reflections)
    plan = anchor_plan(problem) if distinct and symmetry else None
    rows = None
    if plan is not None:
        rows = _restricted_rows(problem, plan, np.concatenate([plan.free_reps, plan.fixed_reps]))
    search = CoverSearch(problem, rows, engine=engine, node_limit=node_limit, deadline=deadline)
    seen: set[bytes] = set()
    for block in search.batches(64):
        forms = canonical_forms(problem, block) if distinct else block
        for sol, form in zip(block, forms, strict=True):
            if distinct:
                key = form.tobytes()
                if key in seen:
                    continue
                seen.add(key)
            yield make_solution(problem, sol)


def first_packing(
    pieces: PiecesLike | CoverProblem,
    target: TargetLike | None = None,
    *,
    reflections: bool = True,
    optional: Shape | None = None,
    engine: Engine = "auto",
    node_limit: int | None = None,
    deadline: Deadline | None = None,
) -> Solution | None:
    """The first solution in the engine's fixed order, or ``None`` if there is none."""
    problem = _problem(pieces, target, optional, reflections)
    search = CoverSearch(problem, engine=engine, node_limit=node_limit, deadline=deadline)
    for block in search.batches(1):
        return make_solution(problem, block[0])
    return None


def random_packings(
    pieces: PiecesLike | CoverProblem,
    target: TargetLike | None = None,
    rng: np.random.Generator | None = None,
    *,
    reflections: bool = True,
    optional: Shape | None = None,
    engine: Engine = "auto",
    node_limit: int | None = None,
    deadline: Deadline | None = None,
) -> Iterator[Solution]:
    """All solutions, each once, in an order shuffled at every search node by ``rng``.

    The same generator state gives the same sequence on any machine (the kernel runs its own
    SplitMix64 seeded from one draw of ``rng``).
    """
    if rng is None:
        raise CoverError("rng: random_packings needs a numpy.random.Generator")
    problem = _problem(pieces, target, optional, reflections)
    search = CoverSearch(problem, engine=engine, rng=rng, node_limit=node_limit, deadline=deadline)
    for block in search.batches(1):
        yield make_solution(problem, block[0])
