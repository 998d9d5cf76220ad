"""Hypothesis strategies shared by the geometry tests."""

from __future__ import annotations

from hypothesis import strategies as st

from chaingeo.core.geometry import NEIGHBOURS, ROTATIONS, Shape


@st.composite
def polycubes(draw: st.DrawFn, min_size: int = 1, max_size: int = 8) -> Shape:
    """A random connected polycube grown one face-neighbour at a time."""
    n = draw(st.integers(min_size, max_size))
    steps = draw(st.lists(st.tuples(st.integers(0, 63), st.integers(0, 5)), max_size=n))
    cells = [(0, 0, 0)]
    for i, d in steps:
        base = cells[i % len(cells)]
        dx, dy, dz = NEIGHBOURS[d]
        c = (base[0] + dx, base[1] + dy, base[2] + dz)
        if c not in cells and len(cells) < n:
            cells.append(c)
    while len(cells) < n:  # top up along +x beyond the far end: always new, always connected
        far = max(cells)
        cells.append((far[0] + 1, far[1], far[2]))
    return Shape(cells)


rotations = st.sampled_from(ROTATIONS)
offsets = st.tuples(*(st.integers(-20, 20) for _ in range(3)))
