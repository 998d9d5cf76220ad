"""Hypothesis strategies for small interlocking scenes (random partitions of a small box)."""

from __future__ import annotations

import numpy as np
from hypothesis import strategies as st

from chaingeo.core.geometry import NEIGHBOURS, Shape


def random_partition(dims: tuple[int, int, int], k: int, seed: int) -> dict[str, Shape]:
    """Split the box into ``k`` face-connected pieces grown from random seeds."""
    rng = np.random.default_rng(seed)
    cells = [(x, y, z) for x in range(dims[0]) for y in range(dims[1]) for z in range(dims[2])]
    order = rng.permutation(len(cells))
    owner: dict[tuple[int, int, int], int] = {}
    for i in range(k):
        owner[cells[int(order[i])]] = i
    while len(owner) < len(cells):
        frontier = sorted(
            (c, owner[o])
            for o in owner
            for d in NEIGHBOURS
            if (c := (o[0] + d[0], o[1] + d[1], o[2] + d[2])) in set(cells) and c not in owner
        )
        c, who = frontier[int(rng.integers(len(frontier)))]
        owner.setdefault(c, who)
    pieces: dict[int, list[tuple[int, int, int]]] = {}
    for c, who in sorted(owner.items()):
        pieces.setdefault(who, []).append(c)
    names = ["red", "green", "blue", "yellow", "orange", "purple"]
    return {names[i]: Shape(v) for i, v in sorted(pieces.items())}


@st.composite
def small_scenes(draw: st.DrawFn, max_pieces: int = 4) -> dict[str, Shape]:
    dims = (draw(st.integers(2, 3)), draw(st.integers(2, 3)), draw(st.integers(1, 2)))
    k = draw(st.integers(2, min(max_pieces, dims[0] * dims[1] * dims[2])))
    return random_partition(dims, k, draw(st.integers(0, 2**32 - 1)))


def random_blocks(names: list[str], data: st.DataObject, most: int = 3) -> list[list[str]]:
    """A random partition of ``names`` into at most ``most`` non-empty blocks."""
    labels = data.draw(st.lists(st.integers(0, most - 1), min_size=len(names), max_size=len(names)))
    return [
        b
        for k in range(most)
        if (b := [n for n, lab in zip(names, labels, strict=True) if lab == k])
    ]


@st.composite
def scenes(draw: st.DrawFn) -> dict[str, Shape]:
    """A small box shared out among 2-4 pieces, some cells left empty so that moves vary
    (pieces need not be connected: the kinematics takes any voxel sets)."""
    dims = draw(
        st.tuples(*(st.integers(1, 3) for _ in range(3))).filter(lambda d: d[0] * d[1] * d[2] >= 2)
    )
    cells = [(x, y, z) for x in range(dims[0]) for y in range(dims[1]) for z in range(dims[2])]
    n = draw(st.integers(2, 4))
    owner = draw(st.lists(st.integers(-1, n - 1), min_size=len(cells), max_size=len(cells)))
    pieces = {
        f"p{k}": Shape([c for c, o in zip(cells, owner, strict=True) if o == k]) for k in range(n)
    }
    pieces = {name: s for name, s in pieces.items() if len(s)}
    if len(pieces) < 2:  # force two pieces: the first two cells
        pieces = {"p0": Shape([cells[0]]), "p1": Shape([cells[1]])}
    return pieces
