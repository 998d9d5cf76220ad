"""Random exact-cover instances for the cover tests: small boxes with piece counts in ranges and
optional cells, and thin two-word boxes (65..120 cells)."""

from __future__ import annotations

from hypothesis import strategies as st

from chaingeo.core.geometry import Shape, box_cells
from chaingeo.solvers.cover.packings import PieceSpec
from tests.support.strategies import polycubes


@st.composite
def instances(draw: st.DrawFn) -> tuple[list[PieceSpec], tuple[int, int, int], Shape | None]:
    dims = (draw(st.integers(1, 3)), draw(st.integers(1, 3)), draw(st.integers(1, 2)))
    n = draw(st.integers(1, 3))
    specs = []
    for i in range(n):
        shape = draw(polycubes(min_size=1, max_size=4))
        lo = draw(st.integers(0, 2))
        hi = draw(st.integers(max(lo, 1), 4))
        specs.append(PieceSpec(shape, f"p{i}", lo, hi))
    optional = None
    if draw(st.booleans()):
        cells = box_cells(dims).cells
        picks = draw(st.sets(st.sampled_from(cells), max_size=max(len(cells) - 1, 0)))
        optional = Shape(sorted(picks)) if picks else None
    return specs, dims, optional


@st.composite
def wide_instances(draw: st.DrawFn) -> tuple[list[PieceSpec], tuple[int, int, int]]:
    """Thin boxes of 65..120 cells (two words) with pieces of four to six cells, each used a
    fixed number of times: few packings, deep searches across the word boundary."""
    a = draw(st.integers(1, 2))
    b = draw(st.integers(2, 3))
    c = draw(st.integers(-(-65 // (a * b)), 120 // (a * b)))
    cells = a * b * c
    specs: list[PieceSpec] = []
    left = cells
    while left > 0:
        shape = draw(polycubes(min_size=min(4, left), max_size=min(6, left)))
        copies = draw(st.integers(1, max(1, left // len(shape))))
        specs.append(PieceSpec(shape, f"p{len(specs)}", copies, copies))
        left -= copies * len(shape)
    if left < 0:  # overshot: let the last piece be used fewer times
        last = specs[-1]
        specs[-1] = PieceSpec(last.shape, last.name, 0, last.max)
    return specs, (a, b, c)
