"""The resumable depth-first search the numba exact-cover engines share, and its pieces: status
codes, register layout, a seeded PRNG, solution storage.

Every engine (:mod:`chaingeo.solvers.cover.dlx`, :mod:`chaingeo.solvers.cover.bitboard`,
:mod:`chaingeo.solvers.cover.bitmrv`, :mod:`chaingeo.solvers.cover.boxmrv`) runs
:func:`depth_first` with its own steps: all search state lives in arrays owned by the Python
wrapper, so a call can stop after a batch of solutions (or at a node limit) and a later call
continues exactly where it stopped. The protocol (status, counters, limits, solutions) is written
once here; an engine says only how a level is opened, walked, entered and left.
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np
import numpy.typing as npt

from chaingeo.kernels.jit import njit

# Status codes (REG_STATUS).
FRESH = 0
RUNNING = 1
DONE = 2
LIMIT = 3

# What an engine's ``place`` step made of a branch.
DEAD = 0  # no cover below it (the engine undid the branch)
COVER = 1  # a solution: every mandatory cell covered and every count met (undone too)
DOWN = 2  # the next level is open

#: What an engine step returns: a branch or an outcome, and the work it did (``updates``).
Step = tuple[int, int]

# Register layout of the int64 ``regs`` array shared with Python.
REG_STATUS = 0
REG_DEPTH = 1
REG_NODES = 2
REG_UPDATES = 3
REG_SOLUTIONS = 4
N_REGS = 5


def new_regs() -> np.ndarray:
    return np.zeros(N_REGS, dtype=np.int64)


class Control(NamedTuple):
    """What one call of any engine's kernel runs under and writes to (numba sees a tuple):
    the registers it resumes from, the shuffle's PRNG state, and where the solutions go."""

    regs: npt.NDArray[np.int64]
    rng: npt.NDArray[np.uint64]
    shuffle: bool
    out: npt.NDArray[np.int32]
    max_store: int
    stop_after: int
    node_limit: int


class Levels(NamedTuple):
    """Per-level search state of the DLX and first-cell kernels: type counts, the branch lists
    (``buf``), each level's end and position in them, an engine's own per-level value
    (``aux``: the column, or the candidate base) and the row chosen."""

    cnt: npt.NDArray[np.int32]
    buf: npt.NDArray[np.int32]
    nbuf: npt.NDArray[np.int64]
    pos: npt.NDArray[np.int64]
    aux: npt.NDArray[np.int64]
    chosen: npt.NDArray[np.int32]


@njit(cache=True)
def save_registers(regs: np.ndarray, k: int, nodes: int, updates: int, found: int) -> None:
    """Leave the counters where the next call resumes."""
    regs[REG_DEPTH] = k
    regs[REG_NODES] = nodes
    regs[REG_UPDATES] = updates
    regs[REG_SOLUTIONS] += found


@njit(cache=True)
def splitmix64(state: np.ndarray) -> Any:
    """Next 64-bit output of SplitMix64; ``state`` is a length-1 uint64 array (advanced)."""
    z = state[0] + np.uint64(0x9E3779B97F4A7C15)
    state[0] = z
    z = (z ^ (z >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
    z = (z ^ (z >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
    return z ^ (z >> np.uint64(31))


@njit(cache=True)
def shuffle_prefix(buf: np.ndarray, n: int, state: np.ndarray) -> None:
    """Fisher-Yates shuffle of ``buf[:n]`` driven by :func:`splitmix64`."""
    for i in range(n - 1, 0, -1):
        j = np.int64(splitmix64(state) % np.uint64(i + 1))
        tmp = buf[i]
        buf[i] = buf[j]
        buf[j] = tmp


@njit(cache=True, inline="always")
def counts_met(counters: Any, cnt: Any, lo: Any, t: int) -> bool:
    """Whether every counted type has its least count, type ``t`` counted once more than
    ``cnt`` says (``t = -1``: none): the last test before a full cover is a solution."""
    for q in counters:  # noqa: SIM110 (numba compiles no generator passed to all())
        if cnt[q] + (1 if q == t else 0) < lo[q]:
            return False
    return True


@njit(cache=True)
def store_solution(
    out: np.ndarray, n_out: int, chosen: np.ndarray, row_ids: np.ndarray, k: int
) -> int:
    """Write the rows ``row_ids[chosen[0..k]]`` of a solution into ``out[n_out]`` (the rest of
    the row -1); return the new solution count."""
    for d in range(k + 1):
        out[n_out, d] = row_ids[chosen[d]]
    for d in range(k + 1, out.shape[1]):
        out[n_out, d] = -1
    return n_out + 1


@njit(cache=True, inline="always")
def open_level(br: Any, nbr: Any, pos: Any, k: int, n: int, rng: Any, shuffle: bool) -> None:
    """Level ``k`` branches on ``br[k, :n]`` from the first (shuffled in random mode)."""
    nbr[k] = n
    pos[k] = 0
    if shuffle:
        shuffle_prefix(br[k], n, rng)


@njit(cache=True, inline="always")
def next_listed(br: Any, nbr: Any, pos: Any, k: int) -> Step:
    """``peek`` of an engine whose levels list their branches (:func:`open_level`)."""
    if pos[k] < nbr[k]:
        return br[k, pos[k]], 0
    return -1, 0


@njit(cache=True, inline="always")
def depth_first(
    root: Any, peek: Any, place: Any, back: Any, problem: Any, state: Any, chosen: Any,
    row_ids: Any, ctl: Control,
) -> int:  # fmt: skip
    """Run (or resume) one engine's search; returns how many solutions were written to ``out``.

    Stops when ``max_store`` solutions are stored (if > 0), ``stop_after`` solutions were found
    in this call (if > 0), the tree is exhausted (status DONE) or ``node_limit`` total nodes were
    spent (status LIMIT). ``out[i, :depth]`` holds the chosen rows' ``row_ids``, -1 padded.

    The engine's steps, each given its ``problem`` and ``state`` (and returning the work done,
    added to ``updates``): ``root(rng, shuffle)`` opens level 0; ``peek(k, shuffle)`` is level
    ``k``'s next branch, not yet taken (-1: none left); ``place(k, b, rng, shuffle)`` takes it,
    sets ``chosen[k]`` and says :data:`DEAD`, :data:`COVER` or :data:`DOWN`; ``back(k)`` leaves
    level ``k``, undoing the branch taken at ``k - 1``.

    Inlined into each engine's kernel, as are its steps: there they are the engine's own
    functions (a call with functions as arguments would hold them as Python objects at run time,
    and the kernel could not be cached). The kernel is compiled without reference counting
    (numba's ``_nrt=False``): an inlined step binds the engine's tuples of arrays, and counting
    references to each array at every node would cost more than the search. So nothing inlined
    may allocate (numba refuses to compile it).
    """
    regs, rng, shuffle, out, max_store, stop_after, node_limit = ctl
    status = regs[REG_STATUS]
    if status == DONE:
        return 0
    nodes = regs[REG_NODES]
    updates = regs[REG_UPDATES]
    found = 0
    n_out = 0
    if status == FRESH:
        k = 0
        updates += root(problem, state, rng, shuffle)
    else:
        k = regs[REG_DEPTH]
    regs[REG_STATUS] = RUNNING
    while True:
        b, work = peek(problem, state, k, shuffle)
        updates += work
        if b < 0:
            back(problem, state, k)
            if k == 0:
                regs[REG_STATUS] = DONE
                break
            k -= 1
            continue
        if nodes >= node_limit:
            regs[REG_STATUS] = LIMIT
            break
        nodes += 1
        outcome, work = place(problem, state, k, b, rng, shuffle)
        updates += work
        if outcome == DOWN:
            k += 1
        elif outcome == COVER:
            found += 1
            if max_store > 0:
                n_out = store_solution(out, n_out, chosen, row_ids, k)
            if (max_store > 0 and n_out == max_store) or found == stop_after:
                break
    save_registers(regs, k, nodes, updates, found)
    return n_out
