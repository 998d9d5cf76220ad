"""The generator's thin layer over the exact-cover engine (:mod:`chaingeo.solvers.cover.packings`).

Two questions are asked of it: how hard is a packing to find (nodes of a plain dancing-links
search with MRV column choice to the first packing, the CHAIN generator's difficulty proxy;
the engine is pinned and the pieces are listed in canonical order, so the figure depends only
on the multiset of pieces and the box) and how many packings exist (counted on the same pinned
engine without symmetry reduction, up to a node budget, so whether a count finishes does not move
when the faster engines improve; only a finished count is recorded). Easy mode also draws
packings of a piece multiset in a seeded random order, on the pinned engine as well.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from typing import Any, Final

import numpy as np

from chaingeo.core.geometry import Shape
from chaingeo.solvers.cover.packings import (
    CoverLimitError,
    CoverSearch,
    count_packings,
    cover_problem,
    random_packings,
)

#: Engine whose node counts are the difficulty proxy (fixed: node counts differ by engine).
EFFORT_ENGINE: Final = "dlx"


@dataclass(frozen=True)
class SearchEffort:
    nodes_first: int  # dancing-links nodes to the first packing (no symmetry reduction)
    solutions: int | None  # every packing; None when counting exceeded the node budget
    distinct: int | None  # packings up to the box's rotations (and reflections if they apply)
    count_budget: int  # the node budget the count had (0: not counted)

    def to_json(self) -> dict[str, Any]:
        return {
            "engine": EFFORT_ENGINE,
            "nodes_first": self.nodes_first,
            "solutions": self.solutions,
            "distinct": self.distinct,
            "count_budget": self.count_budget,
        }


def _named(shapes: Sequence[Shape]) -> tuple[dict[str, Shape], list[str]]:
    """Pieces named in canonical order (so search figures do not depend on how the pieces
    are listed or turned), and the name given to each input shape."""
    canon = [s.canonical() for s in shapes]
    rank = sorted(range(len(shapes)), key=lambda i: (len(canon[i]), canon[i].cells, i))
    names = [""] * len(shapes)
    pieces: dict[str, Shape] = {}
    for r, i in enumerate(rank):
        names[i] = f"p{r:02d}"
        pieces[names[i]] = canon[i]
    return pieces, names


def first_packing_nodes(shapes: Sequence[Shape], box: Sequence[int]) -> int:
    """Dancing-links nodes to the first packing of ``shapes`` in ``box`` (ValueError if none)."""
    dims = tuple(int(v) for v in box)
    search = CoverSearch(cover_problem(_named(shapes)[0], dims), engine=EFFORT_ENGINE)
    if next(iter(search.batches(1)), None) is None:
        raise ValueError(f"the pieces do not pack the {list(dims)} box")
    return int(search.stats.nodes)


def search_effort(
    shapes: Sequence[Shape], box: Sequence[int], nodes_first: int, *, count_limit: int
) -> SearchEffort:
    """Add the packing count to ``nodes_first``; counting stops after ``count_limit`` nodes
    (the count is then None) and 0 skips it."""
    if count_limit <= 0:
        return SearchEffort(nodes_first, None, None, 0)
    counted = counted_packings(shapes, box, count_limit)
    if counted is None:
        return SearchEffort(nodes_first, None, None, count_limit)
    return SearchEffort(nodes_first, counted[0], counted[1], count_limit)


def counted_packings(
    shapes: Sequence[Shape], box: Sequence[int], node_limit: int | None
) -> tuple[int, int | None] | None:
    """``(packings, distinct packings)``, or None when the count needs more than
    ``node_limit`` nodes (None: no limit)."""
    dims = tuple(int(v) for v in box)
    try:
        # Pinned engine, no symmetry reduction: whether a count finishes inside the budget must
        # not change when the automatic engine or its anchoring gets faster.
        res = count_packings(
            _named(shapes)[0], dims, node_limit=node_limit, engine=EFFORT_ENGINE, symmetry=False
        )
    except CoverLimitError:
        return None
    return res.solutions, res.distinct


def seeded_packings(
    shapes: Sequence[Shape], box: Sequence[int], seed: int, limit: int
) -> Iterator[list[Shape]]:
    """Up to ``limit`` packings of ``shapes`` in a seeded random order, placements aligned to
    ``shapes`` (identical pieces are interchangeable, so each packing comes once)."""
    pieces, names = _named(shapes)
    dims = tuple(int(v) for v in box)
    rng = np.random.default_rng(seed)
    for n, sol in enumerate(random_packings(pieces, dims, rng, engine=EFFORT_ENGINE)):
        if n >= limit:
            return
        placed = dict(sol.placements)
        yield [placed[name] for name in names]
