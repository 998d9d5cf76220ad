"""BurrTools' command-line solver burrTxt as an oracle: build it, run it, read its figures.

The sources live beside the checkout (``../shared/burrtools-src``, or ``$CHAIN_BURRTOOLS_SRC``)
with their build script; the binary goes to its cache directory (``$CHAIN_BURRTXT_CACHE``, else
the script's default) and is rebuilt only when a source is newer. Without the sources or g++
:func:`burrtxt` returns None and :data:`REASON` says why. Also here: the random puzzles the
differential tests draw (boxes cut into connected pieces, written as ``.xmpuzzle``).
"""

from __future__ import annotations

import subprocess
from dataclasses import dataclass
from functools import cache
from pathlib import Path

import numpy as np
import pytest

from chaingeo.benchmarks import burrtxt as oracle
from chaingeo.core.formats.bt_model import BTPart, BTProblem, BTPuzzle, colored_shape
from chaingeo.core.geometry import Shape


@dataclass
class _Why:
    text: str = ""


REASON = _Why()


@cache
def burrtxt() -> Path | None:
    """The burrTxt binary, built if needed (:mod:`chaingeo.benchmarks.burrtxt`); None, and
    :data:`REASON`, when it cannot be had here."""
    reason = oracle.why_unavailable()
    if reason is not None:
        REASON.text = reason
        return None
    try:
        return oracle.burrtxt_binary()
    except oracle.BurrTxtError as e:
        REASON.text = str(e)
        return None


def burrtxt_or_skip() -> Path:
    """The burrTxt binary, or the calling test skipped with the reason it cannot be had."""
    path = burrtxt()
    if path is None:
        pytest.skip(f"burrTxt unavailable: {REASON.text}")
    return path


@dataclass(frozen=True)
class Figures:
    """What burrTxt prints for one problem: assemblies, solutions, one level per solution."""

    assemblies: int
    solutions: int
    levels: tuple[str, ...]


def run(binary: Path, path: Path, seconds: float, problem: int = 0) -> Figures | None:
    """``burrTxt -d -r -o PROBLEM FILE``; None past ``seconds``."""
    try:
        done = oracle.run_burrtxt(binary, path, timeout=seconds, problem=problem)
    except subprocess.TimeoutExpired:
        return None
    return Figures(done.assemblies, done.solutions, done.levels)


# -- what the differential tests found (printed at the end of the session by conftest) -------


@dataclass(frozen=True)
class Outcome:
    group: str  # random, level, generator, file
    case: str
    status: str  # agree, disagree, skip
    why: str = ""


OUTCOMES: list[Outcome] = []


def summary_lines(outcomes: list[Outcome] | None = None) -> list[str]:
    """Per group: cases, agreeing, disagreeing, skipped (with the reasons counted)."""
    outcomes = OUTCOMES if outcomes is None else outcomes
    lines = []
    for group in sorted({o.group for o in outcomes}):
        mine = [o for o in outcomes if o.group == group]
        count = {k: sum(o.status == k for o in mine) for k in ("agree", "disagree", "skip")}
        reasons: dict[str, int] = {}
        for o in mine:
            if o.status == "skip":
                reasons[o.why] = reasons.get(o.why, 0) + 1
        why = "; ".join(f"{n} {r}" for r, n in sorted(reasons.items()))
        lines.append(
            f"{group}: {len(mine)} cases, {count['agree']} agree, {count['disagree']} disagree, "
            f"{count['skip']} skipped" + (f" ({why})" if why else "")
        )
        lines.extend(f"  disagree: {o.case}: {o.why}" for o in mine if o.status == "disagree")
    return lines


# -- random puzzles ------------------------------------------------------------------------------

_STEPS = ((1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1))
Cell = tuple[int, int, int]


def _cut(cells: list[Cell], k: int, rng: np.random.Generator) -> list[list[Cell]] | None:
    """``cells`` cut into ``k`` connected pieces grown from random seeds together, each
    mostly from its newest cell (winding pieces interlock; blobs come apart in one move);
    None when some cell is cut off from every piece."""
    free = set(cells)
    seeds = [cells[i] for i in rng.choice(len(cells), size=k, replace=False)]
    pieces = [[s] for s in seeds]
    free -= set(seeds)

    def border(around: list[Cell]) -> list[Cell]:
        return sorted(
            {
                (x + dx, y + dy, z + dz)
                for x, y, z in around
                for dx, dy, dz in _STEPS
                if (x + dx, y + dy, z + dz) in free
            }
        )

    while free:
        grown = False
        for i in rng.permutation(k).tolist():
            near = border(pieces[i][-1:]) if rng.random() < 0.9 else []
            options = near or border(pieces[i])
            if options:
                c = options[int(rng.integers(len(options)))]
                pieces[i].append(c)
                free.discard(c)
                grown = True
        if not grown:
            return None
    return pieces


def random_puzzle(rng: np.random.Generator) -> BTPuzzle:
    """A box (2-4 units a side, 18-36 cells) cut into 3-7 connected pieces of 4 cells or more
    on average, each its own shape (congruent ones too). One in three leaves a cell or two of
    the result variable and empty (holes); one in six drops a corner cell from the result (not
    a box); one in six is cut into straight bars along z, congruent pieces whose permutations
    BurrTools counts. Smaller pieces would make hundreds of thousands of assemblies."""
    while True:
        dims = [int(v) for v in rng.integers(2, 5, size=3)]
        if 18 <= dims[0] * dims[1] * dims[2] <= 36:
            break
    box = [(x, y, z) for x in range(dims[0]) for y in range(dims[1]) for z in range(dims[2])]
    kind = int(rng.integers(6))
    holes: list[Cell] = []
    if kind in (0, 1):
        holes = [box[int(i)] for i in rng.choice(len(box), size=1 + kind, replace=False)]
    elif kind == 2:
        box.remove((0, 0, 0))
    filled = [c for c in box if c not in holes]
    k = int(rng.integers(3, 1 + min(7, len(filled) // 4)))
    if kind == 3 and 3 <= dims[0] * dims[1] <= 7:
        pieces = [
            [c for c in box if c[:2] == (x, y)] for x in range(dims[0]) for y in range(dims[1])
        ]
    else:
        while True:
            found = _cut(filled, min(k, len(filled)), rng)
            if found is not None:
                pieces = found
                break
    shapes = [colored_shape(f"p{i}", Shape(p).normalized()) for i, p in enumerate(pieces)]
    result = colored_shape("result", Shape(filled), Shape(holes) if holes else None)
    problem = BTProblem("random", tuple(BTPart(i, 1, 1) for i in range(len(shapes))), len(shapes))
    return BTPuzzle((*shapes, result), (problem,))
