"""Voxel shapes on the cubic lattice: rotations, canonical forms, predicates.

Everything above this module (solvers, generators, environments) speaks in :class:`Shape`
objects or in the flat ``int64`` arrays they wrap, so the exact-geometry rules live here once.
"""

from __future__ import annotations

import hashlib
from collections import deque
from collections.abc import Iterable, Iterator, Sequence
from functools import cached_property
from typing import Final

import numpy as np
import numpy.typing as npt

IntArray = npt.NDArray[np.int64]
Cell = tuple[int, int, int]

#: The six unit steps of 6-neighbour connectivity, in a fixed order.
NEIGHBOURS: Final[tuple[Cell, ...]] = (
    (1, 0, 0),
    (-1, 0, 0),
    (0, 1, 0),
    (0, -1, 0),
    (0, 0, 1),
    (0, 0, -1),
)


# ---------------------------------------------------------------------------------------------
# Rotations
# ---------------------------------------------------------------------------------------------

#: Quarter turns (+90 degrees, right hand) about x, y and z: the generators of the rotation group.
QUARTER_TURNS: Final[dict[str, IntArray]] = {
    "x": np.array([[1, 0, 0], [0, 0, -1], [0, 1, 0]], dtype=np.int64),
    "y": np.array([[0, 0, 1], [0, 1, 0], [-1, 0, 0]], dtype=np.int64),
    "z": np.array([[0, -1, 0], [1, 0, 0], [0, 0, 1]], dtype=np.int64),
}


def _freeze(m: IntArray) -> IntArray:
    m = np.ascontiguousarray(m, dtype=np.int64)
    m.setflags(write=False)
    return m


def _generate_rotations() -> tuple[tuple[IntArray, ...], IntArray]:
    """Close the quarter turns (both senses) under composition, breadth first.

    Returns the group in BFS order (identity first) and the quarter-turn distance of each
    element from the identity; both are deterministic because the generator order is fixed.
    """
    gens = [QUARTER_TURNS[a] for a in "xyz"] + [QUARTER_TURNS[a].T for a in "xyz"]
    identity = np.eye(3, dtype=np.int64)
    seen: dict[bytes, int] = {identity.tobytes(): 0}
    order: list[IntArray] = [identity]
    dist: list[int] = [0]
    queue: deque[int] = deque([0])
    while queue:
        i = queue.popleft()
        for g in gens:
            m = g @ order[i]
            key = m.tobytes()
            if key not in seen:
                seen[key] = len(order)
                order.append(m)
                dist.append(dist[i] + 1)
                queue.append(len(order) - 1)
    return tuple(_freeze(m) for m in order), np.array(dist, dtype=np.int64)


_GENERATED = _generate_rotations()
#: The 24 proper rotations of the cube, identity first, in breadth-first order from quarter turns.
ROTATIONS: Final[tuple[IntArray, ...]] = _GENERATED[0]
_ROTATION_DEPTH: Final[IntArray] = _GENERATED[1]

#: The 48 symmetries of the cube: the 24 rotations, then each composed with the point inversion.
SYMMETRIES: Final[tuple[IntArray, ...]] = ROTATIONS + tuple(_freeze(-r) for r in ROTATIONS)

#: All 24 rotations stacked as one (24, 3, 3) array for vectorised use.
ROTATION_STACK: Final[IntArray] = _freeze(np.stack(ROTATIONS))

_ROTATION_INDEX: Final[dict[bytes, int]] = {r.tobytes(): i for i, r in enumerate(ROTATIONS)}


def rotation_index(matrix: npt.ArrayLike) -> int:
    """Index into :data:`ROTATIONS` of a proper rotation matrix; ``ValueError`` if it is none."""
    m = np.asarray(matrix, dtype=np.int64)
    try:
        return _ROTATION_INDEX[np.ascontiguousarray(m).tobytes()]
    except KeyError:
        raise ValueError(f"not one of the 24 lattice rotations: {m.tolist()}") from None


def quarter_turn_distance(a: npt.ArrayLike, b: npt.ArrayLike) -> int:
    """Fewest 90-degree turns about x, y or z that take orientation ``a`` to orientation ``b``.

    The generating set is closed under conjugation, so turning in the world frame or in the
    body frame gives the same distance: it is the depth of ``b @ a.T`` in the Cayley graph.
    """
    ma = np.asarray(a, dtype=np.int64)
    mb = np.asarray(b, dtype=np.int64)
    return int(_ROTATION_DEPTH[rotation_index(mb @ ma.T)])


# ---------------------------------------------------------------------------------------------
# Shapes
# ---------------------------------------------------------------------------------------------


def _as_cells(cells: npt.ArrayLike) -> IntArray:
    try:
        arr = np.asarray(cells, dtype=np.int64)
    except OverflowError:
        raise ValueError("voxel coordinates must fit in 64-bit integers") from None
    if arr.size == 0:
        return np.zeros((0, 3), dtype=np.int64)
    if arr.ndim != 2 or arr.shape[1] != 3:
        raise ValueError(f"voxels must be an (n, 3) integer array, got shape {arr.shape}")
    return arr


def _sort_unique(arr: IntArray) -> IntArray:
    """Rows sorted (x, then y, then z), repeats dropped: ``np.unique(arr, axis=0)`` five times
    faster on a piece's few voxels (it sorts a structured view; every Shape goes through here)."""
    if len(arr) == 0:
        return np.zeros((0, 3), dtype=np.int64)
    rows = arr[np.lexsort(arr.T[::-1])]
    keep = np.empty(len(rows), dtype=bool)
    keep[0] = True
    np.any(rows[1:] != rows[:-1], axis=1, out=keep[1:])
    out: IntArray = rows[keep]
    return out


class Shape:
    """An immutable set of integer voxels, stored sorted (x, then y, then z) without repeats.

    Equality and hashing are by the exact voxel set, so a shape and its translate differ;
    use :meth:`normalized` or :meth:`canonical` to compare up to translation or rotation.
    """

    def __init__(self, cells: npt.ArrayLike | Iterable[Sequence[int]]) -> None:
        raw = cells if isinstance(cells, np.ndarray) else np.array(list(cells))  # type: ignore[arg-type]
        arr = _as_cells(raw)
        vox = _sort_unique(arr)
        vox.setflags(write=False)
        self._voxels: IntArray = vox
        self._key: tuple[Cell, ...] = tuple(map(tuple, vox.tolist()))

    @classmethod
    def _from_sorted(cls, vox: IntArray) -> Shape:
        """Wrap an array already known to be sorted and unique (internal fast path)."""
        obj = cls.__new__(cls)
        vox = np.ascontiguousarray(vox, dtype=np.int64)
        vox.setflags(write=False)
        obj._voxels = vox
        obj._key = tuple(map(tuple, vox.tolist()))
        return obj

    @classmethod
    def from_sorted(cls, vox: IntArray) -> Shape:
        """A shape of voxels the caller knows to be sorted and unique (decoded from sorted
        codes, say): skips the sort every other constructor pays."""
        return cls._from_sorted(vox)

    # -- basic protocol ---------------------------------------------------------------------
    @property
    def voxels(self) -> IntArray:
        """Read-only ``(n, 3)`` int64 array, lexicographically sorted."""
        return self._voxels

    @property
    def cells(self) -> tuple[Cell, ...]:
        """The voxels as a sorted tuple of ``(x, y, z)`` tuples (hashable, JSON-friendly)."""
        return self._key

    def __len__(self) -> int:
        return len(self._key)

    def __iter__(self) -> Iterator[Cell]:
        return iter(self._key)

    def __contains__(self, cell: object) -> bool:
        return cell in self.cell_set

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Shape) and self._key == other._key

    def __hash__(self) -> int:
        return hash(self._key)

    def __repr__(self) -> str:
        return f"Shape({[list(c) for c in self._key]})"

    @cached_property
    def cell_set(self) -> frozenset[Cell]:
        return frozenset(self._key)

    # -- placement --------------------------------------------------------------------------
    def translate(self, offset: npt.ArrayLike) -> Shape:
        off = np.asarray(offset, dtype=np.int64).reshape(3)
        return Shape._from_sorted(self._voxels + off)  # translation keeps the order

    def rotate(self, rotation: npt.ArrayLike) -> Shape:
        """Apply a 3x3 integer matrix to every voxel (about the origin)."""
        m = np.asarray(rotation, dtype=np.int64)
        return Shape._from_sorted(_sort_unique(self._voxels @ m.T))

    @property
    def min_corner(self) -> IntArray:
        if len(self) == 0:
            return np.zeros(3, dtype=np.int64)
        return np.asarray(self._voxels.min(axis=0), dtype=np.int64)

    @property
    def max_corner(self) -> IntArray:
        if len(self) == 0:
            return np.full(3, -1, dtype=np.int64)
        return np.asarray(self._voxels.max(axis=0), dtype=np.int64)

    @property
    def extent(self) -> tuple[int, int, int]:
        """Bounding-box size along x, y, z."""
        e = self.max_corner - self.min_corner + 1
        return int(e[0]), int(e[1]), int(e[2])

    def normalized(self) -> Shape:
        """The translate with its minimum corner at the origin."""
        return self.translate(-self.min_corner)

    def occupancy(self) -> npt.NDArray[np.bool_]:
        """Boolean grid of the normalised shape, indexed ``[x, y, z]``."""
        n = self.normalized().voxels
        grid = np.zeros(self.extent, dtype=bool)
        grid[n[:, 0], n[:, 1], n[:, 2]] = True
        return grid

    # -- rotation classes -------------------------------------------------------------------
    def _orientation_keys(self) -> tuple[IntArray, int]:
        """Sorted scalar keys of the 24 rotated, normalised copies, shape (24, n)."""
        rotated = np.einsum("rij,nj->rni", ROTATION_STACK, self._voxels)
        rotated -= rotated.min(axis=1, keepdims=True)
        base = int(rotated.max()) + 1 if len(self) else 1
        keys = (rotated[:, :, 0] * base + rotated[:, :, 1]) * base + rotated[:, :, 2]
        keys.sort(axis=1)
        return keys, base

    @staticmethod
    def _from_keys(keys: IntArray, base: int) -> Shape:
        z = keys % base
        y = (keys // base) % base
        x = keys // (base * base)
        return Shape._from_sorted(np.stack([x, y, z], axis=1))

    def canonical(self) -> Shape:
        """The lexicographically smallest normalised voxel list over the 24 rotations.

        Two shapes have the same canonical form exactly when one is a rotated translate of the
        other; mirror images (chiral pairs) have different canonical forms.
        """
        if len(self) == 0:
            return self
        keys, base = self._cached_keys
        best = int(np.lexsort(keys.T[::-1])[0])
        return Shape._from_keys(keys[best], base)

    @cached_property
    def _cached_keys(self) -> tuple[IntArray, int]:
        return self._orientation_keys()

    def orientations(self) -> tuple[Shape, ...]:
        """The distinct normalised rotations of this shape, in :data:`ROTATIONS` order."""
        return self._cached_orientations

    @cached_property
    def _cached_orientations(self) -> tuple[Shape, ...]:
        if len(self) == 0:
            return (self,)
        keys, base = self._cached_keys
        seen: set[bytes] = set()
        out: list[Shape] = []
        for row in keys:
            b = row.tobytes()
            if b not in seen:
                seen.add(b)
                out.append(Shape._from_keys(row, base))
        return tuple(out)

    def mirrored(self) -> Shape:
        """Reflection through the plane x = 0 (then normalised)."""
        return self.rotate(np.diag([-1, 1, 1])).normalized()

    def is_chiral(self) -> bool:
        return self.canonical() != self.mirrored().canonical()

    # -- predicates -------------------------------------------------------------------------
    def is_connected(self) -> bool:
        """True when the voxels form one 6-connected component (the empty shape is not).

        One flood fill from the first voxel, stopping at nothing else: the generators ask this
        of hundreds of thousands of candidate pieces (:func:`components` also sorts and lists
        every component, ~3x the time)."""
        return connected(self._key)

    def overlaps(self, other: Shape) -> bool:
        return not self.cell_set.isdisjoint(other.cell_set)

    def contact(self, other: Shape) -> int:
        """Number of unit faces this shape shares with ``other`` (0 when they do not touch)."""
        mine, theirs = self.cell_set, other.cell_set
        return sum(
            (x + dx, y + dy, z + dz) in theirs for (x, y, z) in mine for (dx, dy, dz) in NEIGHBOURS
        )

    def is_cuboid(self) -> bool:
        ex, ey, ez = self.extent
        return len(self) > 0 and len(self) == ex * ey * ez

    def has_filled_rectangle(self, a: int = 2, b: int = 3) -> bool:
        """True if some ``a x b`` (or ``b x a``) rectangle in an axis-aligned plane is all filled.

        The CHAIN generator rejects pieces with a filled 2x3 face: they make packing too easy.
        """
        if len(self) < a * b:
            return False
        grid = self.occupancy()
        for normal in range(3):
            u, v = (ax for ax in range(3) if ax != normal)
            for du, dv in {(a, b), (b, a)}:
                window = [1, 1, 1]
                window[u], window[v] = du, dv
                if _window_all(grid, (window[0], window[1], window[2])):
                    return True
        return False

    def size_within(self, lo: int, hi: int) -> bool:
        return lo <= len(self) <= hi


def _window_all(grid: npt.NDArray[np.bool_], window: tuple[int, int, int]) -> bool:
    """Does some placement of an all-true box of size ``window`` fit inside ``grid``?"""
    sx, sy, sz = grid.shape
    wx, wy, wz = window
    if wx > sx or wy > sy or wz > sz:
        return False
    acc = np.ones((sx - wx + 1, sy - wy + 1, sz - wz + 1), dtype=bool)
    for i in range(wx):
        for j in range(wy):
            for k in range(wz):
                acc &= grid[i : i + acc.shape[0], j : j + acc.shape[1], k : k + acc.shape[2]]
    return bool(acc.any())


def connected(cells: Sequence[Cell]) -> bool:
    """Whether ``cells`` form one 6-connected component (no cells: not), by one flood fill from
    the first cell that stops when everything is reached."""
    if not cells:
        return False
    first = cells[0]
    remaining = set(cells)
    remaining.discard(first)
    stack = [first]
    while stack and remaining:
        x, y, z = stack.pop()
        for n in (
            (x + 1, y, z), (x - 1, y, z), (x, y + 1, z), (x, y - 1, z), (x, y, z + 1), (x, y, z - 1)
        ):  # fmt: skip
            if n in remaining:
                remaining.discard(n)
                stack.append(n)
    return not remaining


def components(cells: Iterable[Cell]) -> list[list[Cell]]:
    """6-connected components of a voxel set, each sorted, listed by their smallest voxel."""
    remaining = set(cells)
    out: list[list[Cell]] = []
    for start in sorted(remaining):
        if start not in remaining:
            continue
        remaining.discard(start)
        comp = [start]
        queue = deque([start])
        while queue:
            x, y, z = queue.popleft()
            for dx, dy, dz in NEIGHBOURS:
                n = (x + dx, y + dy, z + dz)
                if n in remaining:
                    remaining.discard(n)
                    comp.append(n)
                    queue.append(n)
        out.append(sorted(comp))
    return out


def box_cells(box: Sequence[int]) -> Shape:
    """All cells of an ``a x b x c`` box with its corner at the origin."""
    a, b, c = (int(v) for v in box)
    grid = np.stack(np.meshgrid(np.arange(a), np.arange(b), np.arange(c), indexing="ij"), axis=-1)
    return Shape(grid.reshape(-1, 3))


def box_symmetries(box: Sequence[int]) -> list[tuple[IntArray, IntArray]]:
    """The symmetries ``v -> M v + t`` (of the 48) that map the box onto itself, identity first.

    Used to count solutions up to the box's own rotations and reflections.
    """
    dims = np.asarray(box, dtype=np.int64)
    out: list[tuple[IntArray, IntArray]] = []
    for m in SYMMETRIES:
        if not np.array_equal(np.abs(m) @ dims, dims):
            continue
        # The image of [0, dims-1] under m spans [min, max]; shift it back to the origin.
        corner = m @ (dims - 1)
        t = np.where(corner < 0, -corner, 0).astype(np.int64)
        out.append((m, _freeze(t)))
    return out


def puzzle_signature(shapes: Iterable[Shape]) -> str:
    """SHA-1 of the sorted canonical piece forms: equal for the same multiset of shapes."""
    forms = sorted(s.canonical().cells for s in shapes)
    text = ";".join(",".join(f"{x} {y} {z}" for x, y, z in f) for f in forms)
    return hashlib.sha1(text.encode("ascii")).hexdigest()
