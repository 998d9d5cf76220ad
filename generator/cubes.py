"""Interlocking n x n x n cubes: random partitions steered until no piece can leave at once.

**A full cube is never interlocking.** If a group can take one unit step along ``+x`` in a
cube without empty cells, every voxel of the group has its ``+x`` neighbour in the group or
outside the cube, so on each line the group runs up to the face and nothing lies ahead of it:
it can leave for good. Every legal first move is then a removal (level 1), which is why the old
suite's cubes all came out at level 1. So a few cells are left empty (:func:`void_sites`: the
interior, and for a 3-cube also the face centres; edges and corners stay, the outline is a
cube): the first move slides a group into the empty cells, and only later can a part leave.

Random cuts still nearly always have a piece that lifts straight off, and closing the last
way out usually jams the cube. So the search steers by the *progress* towards a target level
``L`` (:func:`progress`): while some group comes free within fewer than ``L`` moves, fewer
pieces with a way out are better (and a start with no slide at all is worse); once nothing
does, the design either comes apart at level ``>= L`` (done) or is stuck, and then the state
where one piece is nearest to leaving (fewest voxels of other pieces ahead of it) is the
gradient towards a slide that opens the cube. Single-voxel changes (a cell to a neighbouring
piece, or an empty cell moved) that do not lower the progress are kept (worse ones now and
then: annealing); a walk that does not get there in its budget restarts from a new random cut.
Once there, the same steering aims one level higher at a time, for ``hill_steps`` changes.

Everything random comes from the caller's generator (``SeedSequence([seed, index])``); every
search is capped by states, never by time, so the same (seed, index) gives the same cube.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from chaingeo.core.arrays import I16, I64
from chaingeo.core.geometry import NEIGHBOURS, Shape
from chaingeo.core.kinematics import Assembly, SearchLimitError
from chaingeo.generator.candidate import Candidate, evaluate, piece_names, probe_limits
from chaingeo.generator.config import PuzzleConfig
from chaingeo.kernels.jit import njit
from chaingeo.solvers.deadline import Deadline
from chaingeo.solvers.motion.disassemble import fast_legal_moves
from chaingeo.solvers.motion.partsearch import PartSearch, PieceTable, Removal

#: Progress of a candidate: (levels still missing, closeness within that); (0, 0) is reached.
Progress = tuple[int, int]
_WORST: Progress = (1 << 20, 0)
#: Owner code of an empty cell.
VOID = -1
#: Changes per annealing walk before starting again from a new random cut; walks; temperature.
STEER_STEPS = 8000
RESTARTS = 3
TEMPERATURE = 1.0


def interlocking_target(min_level: int) -> int:
    """Level the cube search steers to: at least 2 (level 1 is not an interlocking cube)."""
    return max(2, min_level)


def min_piece_size(n: int, pieces: int) -> int:
    """Smallest piece kept: 3 voxels when the cube has room for it (no loose single cubes)."""
    return 3 if 3 * pieces <= n**3 else 1


@njit(cache=True)
def nearest_to_leaving(vox: I64, starts: I64, states: I16, count: int) -> int:
    """Over the first ``count`` states (rows of piece offsets), the fewest (voxel, blocker)
    pairs that stop one piece from leaving along one direction: for piece ``q`` and direction
    ``d``, the pairs of a voxel of ``q`` and a voxel of another piece ahead of it on the same
    line. Zero means some piece can leave in that state."""
    k = starts.shape[0] - 1
    nv = vox.shape[0]
    owner = np.empty(nv, dtype=np.int64)
    for p in range(k):
        for i in range(starts[p], starts[p + 1]):
            owner[i] = p
    pos = np.empty((nv, 3), dtype=np.int64)
    mass = np.zeros((k, 6), dtype=np.int64)
    best = 1 << 40
    for s in range(count):
        for i in range(nv):
            p = owner[i]
            for a in range(3):
                pos[i, a] = vox[i, a] + states[s, 3 * p + a]
        mass[:, :] = 0
        for i in range(nv):
            for j in range(nv):
                if owner[i] == owner[j]:
                    continue
                dx = pos[j, 0] - pos[i, 0]
                dy = pos[j, 1] - pos[i, 1]
                dz = pos[j, 2] - pos[i, 2]
                if dy == 0 and dz == 0 and dx != 0:
                    mass[owner[i], 0 if dx > 0 else 1] += 1
                elif dx == 0 and dz == 0 and dy != 0:
                    mass[owner[i], 2 if dy > 0 else 3] += 1
                elif dx == 0 and dy == 0 and dz != 0:
                    mass[owner[i], 4 if dz > 0 else 5] += 1
        for p in range(k):
            for d in range(6):
                if mass[p, d] < best:
                    best = mass[p, d]
    return best


def _neighbours(c: tuple[int, ...], n: int) -> list[tuple[int, int, int]]:
    """The face neighbours of cell ``c`` inside the cube."""
    out = [(c[0] + d[0], c[1] + d[1], c[2] + d[2]) for d in NEIGHBOURS]
    return [nb for nb in out if all(0 <= v < n for v in nb)]


def void_sites(n: int) -> list[tuple[int, int, int]]:
    """Cells that may be left empty: the interior, and for a 3-cube (whose interior is one
    cell) the face centres too; edges and corners always stay, so the outline is a cube."""
    inner = [
        (x, y, z)
        for x in range(n)
        for y in range(n)
        for z in range(n)
        if sum(0 < v < n - 1 for v in (x, y, z)) >= (3 if n > 3 else 2)
    ]
    return inner


def void_count(n: int, hole_rate: float) -> int:
    """Empty cells of an ``n``-cube: ``hole_rate`` of its :func:`void_sites`, at least one (a
    cube without an empty cell always has a piece that lifts straight off)."""
    sites = len(void_sites(n))
    if sites == 0:
        raise ValueError(
            f"a {n}x{n}x{n} cube has no inner cell to leave empty, and a cube without an "
            "empty cell always has a piece that lifts straight off: use cube3 or larger"
        )
    return min(sites, max(1, round(hole_rate * sites)))


def random_partition(
    n: int, pieces: int, voids: int, min_size: int, rng: np.random.Generator
) -> I64:
    """Owner of each cell of the cube (an ``(n, n, n)`` array, ``VOID`` for the ``voids``
    random interior cells left empty): ``pieces`` random seeds grown one random frontier cell
    at a time (pieces under ``min_size`` first, while they can), so every piece is
    face-connected."""
    if not 2 <= pieces <= n**3 - voids:
        raise ValueError(f"a {n}x{n}x{n} cube cannot be cut into {pieces} pieces")
    free = -2
    owner = np.full((n, n, n), free, dtype=np.int64)
    sites = void_sites(n)
    for i in rng.permutation(len(sites))[:voids]:
        owner[sites[int(i)]] = VOID
    cells = np.flatnonzero(owner == free)
    for i, flat in enumerate(rng.permutation(cells)[:pieces]):
        owner.flat[int(flat)] = i
    while (owner == free).any():
        frontier = sorted(
            {
                (nb, int(owner[c]))
                for c in map(tuple, np.argwhere(owner >= 0).tolist())
                for nb in _neighbours(c, n)
                if owner[nb] == free
            }
        )
        if not frontier:  # a cell walled in by voids (a 3-cube with all face centres empty)
            raise ValueError("voids cut the cube apart")
        sizes = np.bincount(owner[owner >= 0], minlength=pieces)
        small = [f for f in frontier if sizes[f[1]] < min_size]
        choices = small or frontier
        cell, who = choices[int(rng.integers(len(choices)))]
        owner[cell] = who
    return owner


def shapes_of(owner: I64, pieces: int) -> list[Shape]:
    """The pieces of a partition, in owner order."""
    return [Shape([tuple(c) for c in np.argwhere(owner == i).tolist()]) for i in range(pieces)]


def _still_whole(owner: I64, piece: int, min_size: int) -> bool:
    cells = [tuple(v) for v in np.argwhere(owner == piece).tolist()]
    return len(cells) >= min_size and Shape(cells).is_connected()


def transfer(owner: I64, min_size: int, rng: np.random.Generator) -> I64 | None:
    """A copy with one random cell given to a face neighbour's piece, or None when that
    would leave its old piece too small or in two."""
    n = owner.shape[0]
    filled = np.argwhere(owner >= 0)
    c = tuple(int(v) for v in filled[int(rng.integers(len(filled)))])
    near = sorted({int(owner[nb]) for nb in _neighbours(c, n) if owner[nb] not in (VOID, owner[c])})
    if not near:
        return None
    old = int(owner[c])
    out = owner.copy()
    out[c] = near[int(rng.integers(len(near)))]
    return out if _still_whole(out, old, min_size) else None


def shift_void(owner: I64, min_size: int, rng: np.random.Generator) -> I64 | None:
    """A copy with one void moved to a neighbouring interior cell, the old void cell given to
    a piece next to it; None when a piece would break or shrink too much."""
    n = owner.shape[0]
    voids = np.argwhere(owner == VOID)
    v = tuple(int(x) for x in voids[int(rng.integers(len(voids)))])
    sites = set(void_sites(n))
    inner = [c for c in _neighbours(v, n) if owner[c] >= 0 and c in sites]
    if not inner:
        return None
    c = inner[int(rng.integers(len(inner)))]
    out = owner.copy()
    old = int(out[c])
    out[c] = VOID
    near = sorted({int(out[nb]) for nb in _neighbours(v, n) if out[nb] >= 0})
    if not near:
        return None
    out[v] = near[int(rng.integers(len(near)))]
    return out if _still_whole(out, old, min_size) else None


def mutate(owner: I64, min_size: int, rng: np.random.Generator) -> I64 | None:
    """One random change: mostly a cell transfer, sometimes a void shift."""
    if rng.random() < 0.2:
        return shift_void(owner, min_size, rng)
    return transfer(owner, min_size, rng)


def progress(
    shapes: Sequence[Shape], target: int, config: PuzzleConfig
) -> tuple[Progress, Candidate | None]:
    """How far the design is from coming apart at level ``>= target``; the candidate when
    it does.

    ``(m, w)``: when some group comes free within ``target - m`` moves (``m >= 1``), ``w`` is
    the number of distinct ways out (group, direction) found at that depth. ``m = 0`` when
    nothing comes free sooner: ``(0, 0)`` if the design comes apart (its level is then at
    least ``target``), else ``(0, 1 + b)`` with ``b`` the fewest blockers of one piece in one
    direction over the states visited (:func:`nearest_to_leaving`). Searches over their caps
    give the worst progress.
    """
    named = piece_names(shapes)
    table = PieceTable(named)
    k = len(shapes)
    limits = probe_limits(config)
    search = PartSearch(
        table,
        tuple(range(k)),
        np.zeros((k, 3), dtype=np.int64),
        max_group=config.max_group,
        limits=limits,
        deadline=Deadline(limits.seconds),
    )
    try:
        for depth in range(target):
            removals = search.expand_layer()
            if removals and depth + 1 < target:
                stuck = 0 if _can_slide(named, config.max_group) else 6 * k
                return (target - 1 - depth, stuck + _pieces_with_a_way_out(removals)), None
            if removals or search.exhausted:
                break
    except SearchLimitError:
        return _WORST, None
    analysis = evaluate(shapes, config)
    if analysis is not None and (analysis.first_level or 0) >= target:
        return (0, 0), Candidate(list(shapes), analysis)
    vox = np.concatenate([table.voxels[i] for i in range(k)])
    starts = np.zeros(k + 1, dtype=np.int64)
    starts[1:] = np.cumsum([len(v) for v in table.voxels])
    return (0, 1 + nearest_to_leaving(vox, starts, search.states, search.n_states)), None


def _can_slide(named: dict[str, Shape], max_group: int | None) -> bool:
    """Can some group move at the start without being able to leave that way? (In a cube
    only into an empty interior cell; without such a slide nothing opens once the ways
    out are closed.)"""
    moves = fast_legal_moves(Assembly.assembled(named), max_group)
    leaving = {(m.pieces, m.direction) for m in moves if m.distance is None}
    return any((m.pieces, m.direction) not in leaving for m in moves)


def _pieces_with_a_way_out(removals: Sequence[Removal]) -> int:
    """Sum over directions of the pieces that some removal along it carries: a count that
    drops one piece at a time as the ways out close (counting groups would explode)."""
    union = [0] * 6
    for r in removals:
        union[r.direction] |= r.mask
    return sum(m.bit_count() for m in union)


def _steer(
    owner: I64,
    target: int,
    config: PuzzleConfig,
    min_size: int,
    rng: np.random.Generator,
    steps: int = STEER_STEPS,
) -> tuple[tuple[I64, Candidate] | None, int]:
    """Anneal from ``owner`` for up to ``steps`` changes: a change that misses more levels is
    refused, one that misses fewer is kept, and within the same level a change that opens
    ``w`` more ways is kept with probability ``exp(-w / TEMPERATURE)``. Returns the partition
    and candidate once it comes apart at level ``>= target`` (or None), and the steps used."""
    k = int(owner.max()) + 1
    current, found = progress(shapes_of(owner, k), target, config)
    for step in range(steps):
        if found is not None:
            return (owner, found), step
        nxt = mutate(owner, min_size, rng)
        if nxt is None:
            continue
        score, cand = progress(shapes_of(nxt, k), target, config)
        if score[0] > current[0]:
            continue
        worse = score[1] - current[1] if score[0] == current[0] else 0
        if worse <= 0 or rng.random() < np.exp(-worse / TEMPERATURE):
            owner, current, found = nxt, score, cand
    return ((owner, found) if found is not None else None), steps


def cube_search(config: PuzzleConfig, n: int, rng: np.random.Generator) -> Candidate | None:
    """An interlocking partition of the n x n x n cube: steered to level
    :func:`interlocking_target` (up to :data:`RESTARTS` walks), then steered one level deeper
    at a time while ``hill_steps`` changes last. None when no walk reached the target."""
    k = config.pieces or max(3, n)
    voids = void_count(n, config.hole_rate)
    min_size = min_piece_size(n, k)
    reached: tuple[I64, Candidate] | None = None
    for _ in range(RESTARTS):
        start = random_partition(n, k, voids, min_size, rng)
        reached, _used = _steer(start, interlocking_target(config.min_level), config, min_size, rng)
        if reached is not None:
            break
    if reached is None:
        return None
    owner, best = reached
    left = config.hill_steps
    while left > 0:
        deeper, used = _steer(
            owner, (best.analysis.first_level or 0) + 1, config, min_size, rng, left
        )
        left -= used
        if deeper is None:
            break
        owner, best = deeper
    return best
