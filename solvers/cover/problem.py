"""An exact-cover problem compiled from pieces and a target: rows, columns and symmetries.

Pieces of the same shape up to rotation are merged into one *piece type* whose copies are
interchangeable (a solution is a set of placed shapes, so identical copies are never permuted).
A type has a count range ``[lo, hi]``; the target's cells must each be covered exactly once,
except ``optional`` cells, which may stay empty (at most once).

Rows are ``(type, placement)`` pairs, numbered type by type in placement order. The problem's
symmetry group is the target's rotations, plus its reflections when ``reflections`` is asked for
and the problem is mirror-invariant (every type's mirror image is a type with the same range);
only symmetries mapping the optional cells onto themselves count, and elements acting
identically on the rows are merged, so the group acts faithfully.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from functools import cached_property, lru_cache

import numpy as np

from chaingeo.core.arrays import I32
from chaingeo.core.errors import ChainGeoError
from chaingeo.core.geometry import Shape, box_cells
from chaingeo.solvers.cover.placements import (
    IntArray,
    Placements,
    cell_permutation,
    placements,
    target_index,
    target_symmetries,
)


class CoverError(ChainGeoError, ValueError):
    """Bad input to the exact-cover engine (the message says which argument and why)."""


@dataclass(frozen=True)
class PieceSpec:
    """A named piece used between ``min`` and ``max`` times (default exactly once)."""

    shape: Shape
    name: str
    min: int = 1
    max: int = 1


PiecesLike = Mapping[str, Shape] | Sequence[Shape | PieceSpec]
TargetLike = Shape | Sequence[int]


@dataclass(frozen=True)
class PieceType:
    """Pieces of one shape (up to rotation): ``names`` lists one slot per possible copy."""

    shape: Shape  # canonical form
    slots: tuple[str, ...]  # name of each copy, mandatory copies first
    lo: int
    hi: int
    chiral: bool


def as_target(target: TargetLike) -> Shape:
    if isinstance(target, Shape):
        if len(target) == 0:
            raise CoverError("target: the voxel set is empty")
        return target
    dims = tuple(int(v) for v in target)
    if len(dims) != 3 or min(dims) < 1:
        raise CoverError(f"target: a box needs three positive sizes, got {list(target)}")
    return box_cells(dims)


def as_specs(pieces: PiecesLike) -> tuple[PieceSpec, ...]:
    """Normalise the accepted piece inputs to named specs (names default to P0, P1, ...)."""
    if isinstance(pieces, Mapping):
        items: list[Shape | PieceSpec] = [PieceSpec(s, str(n)) for n, s in pieces.items()]
    else:
        items = list(pieces)
    out: list[PieceSpec] = []
    for i, p in enumerate(items):
        spec = p if isinstance(p, PieceSpec) else PieceSpec(p, f"P{i}")
        if not isinstance(spec.shape, Shape) or len(spec.shape) == 0:
            raise CoverError(f"pieces[{i}] ({spec.name}): expected a non-empty Shape")
        if not 0 <= spec.min <= spec.max:
            raise CoverError(
                f"pieces[{i}] ({spec.name}): need 0 <= min <= max, got {spec.min}, {spec.max}"
            )
        out.append(spec)
    if not out:
        raise CoverError("pieces: no pieces given")
    names = [s.name for s in out]
    if len(set(names)) != len(names):
        raise CoverError(
            f"pieces: duplicate names {sorted({n for n in names if names.count(n) > 1})}"
        )
    return tuple(out)


def _merge_types(specs: Sequence[PieceSpec]) -> list[PieceType]:
    groups: dict[Shape, list[PieceSpec]] = {}
    for s in specs:
        groups.setdefault(s.shape.canonical(), []).append(s)
    types = []
    for canon, members in groups.items():  # first-appearance order
        mandatory = [m.name for m in members for _ in range(m.min)]
        optional = [m.name for m in members for _ in range(m.max - m.min)]
        lo, hi = len(mandatory), len(mandatory) + len(optional)
        if hi == 0:
            continue  # never used: no rows, no column
        types.append(PieceType(canon, tuple(mandatory + optional), lo, hi, canon.is_chiral()))
    return types


@dataclass(eq=False)
class CoverProblem:
    """A compiled exact-cover instance. Build with :func:`cover_problem` (cached)."""

    target: Shape
    optional: frozenset[int]  # indices of cells that may stay empty
    types: tuple[PieceType, ...]
    table: tuple[Placements, ...]  # placements of each type
    row_type: I32  # (R,) type of each row
    row_start: IntArray  # (T + 1,) rows of type t are row_start[t] : row_start[t + 1]
    reflections: bool  # reflections were asked for
    _cache: dict[object, object] = field(default_factory=dict, repr=False)
    _placed: dict[int, Shape] = field(default_factory=dict, repr=False)

    @property
    def n_cells(self) -> int:
        return len(self.target)

    @property
    def n_rows(self) -> int:
        return len(self.row_type)

    def row_cells(self, row: int) -> I32:
        t = int(self.row_type[row])
        cells: I32 = self.table[t].cells[row - int(self.row_start[t])]
        return cells

    @cached_property
    def row_ptr(self) -> IntArray:
        """CSR pointers into :attr:`flat_cells` (rows have different sizes across types)."""
        sizes = np.array([len(self.types[t].shape) for t in self.row_type], dtype=np.int64)
        ptr = np.zeros(self.n_rows + 1, dtype=np.int64)
        np.cumsum(sizes, out=ptr[1:])
        return ptr

    @cached_property
    def flat_cells(self) -> I32:
        parts = [p.cells.reshape(-1) for p in self.table]
        return np.concatenate(parts).astype(np.int32) if parts else np.zeros(0, np.int32)

    def placed_shape(self, row: int) -> Shape:
        """The row's voxels (kept: the assembler names the same rows for many assemblies)."""
        shape = self._placed.get(row)
        if shape is None:
            shape = self._placed[row] = Shape(self.target.voxels[self.row_cells(row)])
        return shape

    # -- symmetry ------------------------------------------------------------------------------
    @cached_property
    def mirror_invariant(self) -> bool:
        key = sorted((t.shape.cells, t.lo, t.hi) for t in self.types)
        mirrored = sorted((t.shape.mirrored().canonical().cells, t.lo, t.hi) for t in self.types)
        return key == mirrored

    @cached_property
    def symmetry(self) -> tuple[tuple[tuple[IntArray, IntArray], ...], I32]:
        """``(symmetries, row_maps)``: the faithful group and ``row_maps[g, r]`` = image row."""
        use_mirrors = self.reflections and self.mirror_invariant
        syms = target_symmetries(self.target, reflections=use_mirrors)
        kept: list[tuple[IntArray, IntArray]] = []
        maps: list[I32] = []
        seen: set[bytes] = set()
        opt = np.asarray(sorted(self.optional), dtype=np.int32)
        for m, t in syms:
            if len(opt) and not np.array_equal(
                np.sort(cell_permutation(self.target, m, t)[opt]), opt
            ):
                continue  # must map the optional cells onto themselves
            rmap = self._row_map(m, t)
            if rmap is None:
                continue
            key = rmap.tobytes()
            if key in seen:
                continue
            seen.add(key)
            kept.append((m, t))
            maps.append(rmap)
        return tuple(kept), np.stack(maps).astype(np.int32)

    @cached_property
    def mirror_types(self) -> list[int]:
        """The type index of each type's mirror image (-1 if it is not a type)."""
        by_shape = {t.shape: i for i, t in enumerate(self.types)}
        return [by_shape.get(t.shape.mirrored().canonical(), -1) for t in self.types]

    @cached_property
    def orientation_index(self) -> list[dict[bytes, int]]:
        """Per type: orientation key -> orientation number (see :func:`_orientation_keys`)."""
        return [{k: i for i, k in enumerate(_orientation_keys(_stacked(p)))} for p in self.table]

    def _row_map(self, m: IntArray, t: IntArray) -> I32 | None:
        origin = target_index(self.target).origin
        out = np.empty(self.n_rows, dtype=np.int32)
        for ti, table in enumerate(self.table):
            if len(table) == 0:
                continue
            image_type = ti if round(np.linalg.det(m)) > 0 else self.mirror_types[ti]
            if image_type < 0:
                return None
            dest = self.table[image_type]
            new_o, shift = _orientation_map(table, self.orientation_index[image_type], m)
            o_of = table.orientation.astype(np.int64)
            corner = table.offset @ np.asarray(m).T + np.asarray(t) + shift[o_of] - origin
            rows = dest.lookup[new_o[o_of], corner[:, 0], corner[:, 1], corner[:, 2]]
            if np.any(rows < 0):
                raise AssertionError("a target symmetry mapped a placement outside the target")
            s = int(self.row_start[ti])
            out[s : s + len(table)] = rows + int(self.row_start[image_type])
        return out

    def cell_permutations(self) -> I32:
        syms, _ = self.symmetry
        return np.stack([cell_permutation(self.target, m, t) for m, t in syms])


def _orientation_keys(vox: IntArray) -> list[bytes]:
    """One key per normalised orientation in ``vox`` (n_orientations, k, 3)."""
    rel = vox - vox.min(axis=1, keepdims=True)
    base = int(rel.max()) + 1 if rel.size else 1
    keys = np.sort((rel[..., 0] * base + rel[..., 1]) * base + rel[..., 2], axis=1)
    return [base.to_bytes(4, "little") + row.tobytes() for row in keys]


def _stacked(p: Placements) -> IntArray:
    return np.stack([o.voxels for o in p.orientations])


def _orientation_map(
    src: Placements, dest_index: dict[bytes, int], m: IntArray
) -> tuple[IntArray, IntArray]:
    """For each orientation of ``src``: the destination orientation its image under ``m`` is,
    and the min corner of that image (so image = destination orientation + corner)."""
    img = _stacked(src) @ np.asarray(m).T
    new_o = np.array([dest_index[key] for key in _orientation_keys(img)], dtype=np.int64)
    return new_o, img.min(axis=1)


def cover_problem(
    pieces: PiecesLike,
    target: TargetLike,
    *,
    optional: Shape | None = None,
    reflections: bool = True,
) -> CoverProblem:
    """Compile (and cache) the exact-cover problem of packing ``pieces`` into ``target``."""
    return _cover_problem(as_specs(pieces), as_target(target), optional, reflections)


@lru_cache(maxsize=64)
def _cover_problem(
    specs: tuple[PieceSpec, ...], target: Shape, optional: Shape | None, reflections: bool
) -> CoverProblem:
    idx = target_index(target)
    opt: frozenset[int] = frozenset()
    if optional is not None:
        where = idx.index_of(optional.voxels)
        if np.any(where < 0):
            raise CoverError("optional: some optional cells are not in the target")
        opt = frozenset(int(i) for i in where)
        if len(opt) == len(target):
            raise CoverError("optional: at least one target cell must be mandatory")
    types = _merge_types(specs)
    table = tuple(placements(t.shape, target) for t in types)
    sizes = np.array([len(p) for p in table], dtype=np.int64)
    row_start = np.zeros(len(types) + 1, dtype=np.int64)
    np.cumsum(sizes, out=row_start[1:])
    row_type = np.repeat(np.arange(len(types), dtype=np.int32), sizes)
    return CoverProblem(target, opt, tuple(types), table, row_type, row_start, reflections)
