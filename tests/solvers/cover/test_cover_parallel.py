"""Exact cover cut into subtrees (:mod:`chaingeo.solvers.cover.parallel`): the subtrees' covers
are the whole search's, each met once, and counting on workers gives the same figures."""

from __future__ import annotations

import numpy as np
import pytest

from chaingeo.core.piecesets import PENTOMINOES, SOMA
from chaingeo.solvers.cover import parallel
from chaingeo.solvers.cover.packings import _problem, count_packings
from chaingeo.solvers.cover.search import CoverSearch

CASES = [
    ("soma", SOMA.pieces, (3, 3, 3), "auto"),
    ("soma dlx", SOMA.pieces, (3, 3, 3), "dlx"),
    ("pentominoes 3x20", PENTOMINOES.pieces, (3, 20, 1), "auto"),
    pytest.param(
        "solid pentominoes 2x5x6",
        PENTOMINOES.pieces,
        (2, 5, 6),
        "bitboard-mrv",
        marks=pytest.mark.slow,
    ),
]


def _covers(problem: object, rows: np.ndarray, engine: str) -> list[tuple[int, ...]]:
    search = CoverSearch(problem, rows, engine=engine)  # type: ignore[arg-type]
    return [tuple(sorted(int(r) for r in s if r >= 0)) for b in search.batches(4096) for s in b]


@pytest.mark.parametrize(("name", "pieces", "box", "engine"), CASES[:3])
def test_subtrees_partition_the_covers(
    name: str, pieces: object, box: tuple[int, int, int], engine: str
) -> None:
    problem = _problem(pieces, box, None, True)  # type: ignore[arg-type]
    rows = np.arange(problem.n_rows, dtype=np.int32)
    whole = _covers(problem, rows, engine)
    parts = parallel.split_rows(problem, rows, engine)  # type: ignore[arg-type]
    assert len(parts) >= parallel.PARTS or name == "pentominoes 3x20"
    split = [c for p in parts for c in _covers(problem, p, engine)]
    assert len(split) == len(whole) == len(set(split)) and set(split) == set(whole)


@pytest.mark.parametrize(("name", "pieces", "box", "engine"), CASES)
def test_workers_count_the_same(
    name: str,
    pieces: object,
    box: tuple[int, int, int],
    engine: str,
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.setattr(parallel, "MIN_ROWS", 1)
    if name.startswith("solid"):
        monkeypatch.setattr(parallel, "PARTS", 4)
    runs = []
    for jobs in (1, 2):
        for symmetry in (True, False):
            r = count_packings(pieces, box, jobs=jobs, symmetry=symmetry, engine=engine)  # type: ignore[arg-type]
            runs.append((jobs, symmetry, r.solutions, r.distinct))
    assert {(s, d) for _, _, s, d in runs} == {(runs[0][2], runs[0][3])}


def test_jobs_must_be_positive() -> None:
    from chaingeo.solvers.cover.problem import CoverError

    with pytest.raises(CoverError, match="jobs"):
        count_packings(SOMA.pieces, (3, 3, 3), jobs=0)
