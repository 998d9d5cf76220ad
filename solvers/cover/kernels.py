"""Shared pieces of the numba search kernels: status codes, register layout, a seeded PRNG.

Both engines (:mod:`chaingeo.solvers.cover.dlx`, :mod:`chaingeo.solvers.cover.bitboard`) run a
resumable depth-first search: all search state lives in arrays owned by the Python wrapper, so a
call can stop after a batch of solutions (or at a node limit) and a later call continues exactly
where it stopped.
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
