"""Packing problems with BurrTools' constraints, compiled to exact-cover rows.

On top of the plain engine's problem (:mod:`chaingeo.solvers.cover.problem`): voxels carry colours
and a placement is a row only when every coloured piece voxel may sit on the result voxel under it
(:class:`ColorRules`, BurrTools' ``<bitmap>``); result cells may be *variable* (covered at most
once, the secondary columns of the engine; when a piece fits wholly on variable cells, where
the kernels never branch, variable cells become fixed ones covered by a piece or a *hole*,
see :func:`compile_packing`). Parts of the same coloured shape (and groups) are merged into
one type whose copies are interchangeable. A piece is a coloured voxel set, so a piece whose
shape is symmetric but whose colouring is not has more orientations than its shape; rows are
``(type, coloured placement)`` and two rows may cover the same cells.

Rows are filtered here, before the kernels (:mod:`chaingeo.solvers.cover.bitboard`,
:mod:`chaingeo.solvers.cover.dlx`), and the engine searches them as they are. Symmetry is this
module's business: the group is the result's own (cells, variable marks and colours kept) and acts
on rows by :meth:`row_maps`; a reflection sends a row to its mirror piece's row when that piece is
in the problem (else -1), and :func:`canonical_keys` picks one key per orbit of an assembly, so two
assemblies are the same exactly when a symmetry maps one onto the other.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from chaingeo.core.arrays import I32
from chaingeo.core.geometry import ROTATION_STACK, SYMMETRIES, Shape
from chaingeo.kernels.jit import njit
from chaingeo.solvers.cover.placements import (
    IntArray,
    Placements,
    fitting_shifts,
    target_index,
)
from chaingeo.solvers.cover.problem import CoverError, CoverProblem, PieceType

Cell = tuple[int, int, int]
#: Colour codes pack ``cell * COLOR_BASE + colour`` (BurrTools has at most 63 colours).
COLOR_BASE = 64
_MIRROR = np.diag([-1, 1, 1]).astype(np.int64)
#: The name of the holes type (never a part's name: parts are named by the caller).
HOLE = "(hole)"


@dataclass(frozen=True)
class ColoredPiece:
    """Voxels (sorted) with a colour each (0: uncoloured)."""

    voxels: tuple[Cell, ...]
    colors: tuple[int, ...]

    @staticmethod
    def of(shape: Shape, colors: Mapping[Cell, int] | None = None) -> ColoredPiece:
        cmap = colors or {}
        return ColoredPiece(shape.cells, tuple(int(cmap.get(c, 0)) for c in shape.cells))

    @property
    def shape(self) -> Shape:
        return Shape(self.voxels)

    @cached_property
    def _keys(self) -> tuple[IntArray, int]:
        """Per rotation (:data:`ROTATION_STACK` order): the normalised voxels as sorted codes
        ``((x * base + y) * base + z) * COLOR_BASE + colour``, and ``base``."""
        vox = np.asarray(self.voxels, dtype=np.int64).reshape(-1, 3)
        rot = np.einsum("rij,nj->rni", ROTATION_STACK, vox)
        rot -= rot.min(axis=1, keepdims=True)
        base = int(rot.max()) + 1 if len(vox) else 1
        keys = (rot[..., 0] * base + rot[..., 1]) * base + rot[..., 2]
        keys = keys * COLOR_BASE + np.asarray(self.colors, dtype=np.int64)[None, :]
        keys.sort(axis=1)
        return keys, base

    @staticmethod
    def _decode(rows: IntArray, base: int) -> list[ColoredPiece]:
        """The pieces of rows of codes, decoded together (one at a time took 0.02 s for the
        orientations of SolidSixPieceBurrs' 25 pieces)."""
        k = rows // COLOR_BASE
        coded = np.stack([k // (base * base), (k // base) % base, k % base, rows % COLOR_BASE], -1)
        return [
            ColoredPiece(tuple((x, y, z) for x, y, z, _ in r), tuple(c for *_, c in r))
            for r in coded.tolist()
        ]

    def transformed(self, m: IntArray) -> ColoredPiece:
        """Image under the matrix ``m``, normalised to the origin."""
        v = np.asarray(self.voxels, dtype=np.int64).reshape(-1, 3) @ np.asarray(m).T
        v -= v.min(axis=0)
        base = int(v.max()) + 1 if len(v) else 1
        row = ((v[:, 0] * base + v[:, 1]) * base + v[:, 2]) * COLOR_BASE
        return ColoredPiece._decode(
            np.sort(row + np.asarray(self.colors, dtype=np.int64))[None], base
        )[0]

    @cached_property
    def _orientation_codes(self) -> tuple[IntArray, int]:
        """The distinct orientations' sorted codes (first occurrences, in rotation order)."""
        keys, base = self._keys
        _, first = np.unique(keys, axis=0, return_index=True)
        return keys[np.sort(first)], base

    @cached_property
    def orientation_arrays(self) -> tuple[IntArray, IntArray]:
        """:meth:`orientations` as arrays, voxels ``(o, k, 3)`` (sorted, at the origin) and
        colours ``(o, k)``: what the placements need, without a Python tuple a voxel."""
        codes, base = self._orientation_codes
        k = codes // COLOR_BASE
        vox = np.stack([k // (base * base), (k // base) % base, k % base], axis=-1)
        return vox, codes % COLOR_BASE

    @cached_property
    def _orientations(self) -> tuple[ColoredPiece, ...]:
        return tuple(ColoredPiece._decode(*self._orientation_codes))

    def orientations(self) -> tuple[ColoredPiece, ...]:
        """The distinct coloured orientations, in :data:`ROTATIONS` order."""
        return self._orientations

    @cached_property
    def _canonical(self) -> ColoredPiece:
        keys, base = self._keys
        return ColoredPiece._decode(keys[[int(np.lexsort(keys.T[::-1])[0])]], base)[0]

    def canonical(self) -> ColoredPiece:
        """One orientation standing for all: equal for two pieces exactly when one is a
        rotation of the other (colours included)."""
        return self._canonical

    def mirrored(self) -> ColoredPiece:
        return self.transformed(_MIRROR)

    @cached_property
    def mirror_canonical(self) -> ColoredPiece:
        return self.mirrored().canonical()


@dataclass(frozen=True)
class ColorRules:
    """Which piece colour may sit on which result colour (BurrTools' ``<bitmap>``): with no
    colours defined, or on an uncoloured voxel, anything goes."""

    n_colors: int = 0
    pairs: frozenset[tuple[int, int]] = frozenset()

    def allowed(self, piece_color: int, result_color: int) -> bool:
        if self.n_colors == 0 or piece_color == 0 or result_color == 0:
            return True
        return (piece_color, result_color) in self.pairs

    def table(self) -> np.ndarray:
        """``ok[piece colour, result colour]`` for colours ``0..n_colors``."""
        n = self.n_colors + 1
        return np.array([[self.allowed(p, r) for r in range(n)] for p in range(n)], dtype=bool)


@dataclass(frozen=True)
class PartSpec:
    """A piece used ``lo..hi`` times; ``groups`` are ``(group id, count)`` pairs."""

    name: str
    piece: ColoredPiece
    lo: int = 1
    hi: int = 1
    groups: tuple[tuple[int, int], ...] = ()


@dataclass(frozen=True)
class PackingSpec:
    """The pieces, the result (coloured cells, the variable ones may stay empty), the colour
    rules and an optional cap on the variable cells left empty. ``merge_congruent``: parts of
    the same coloured shape (and groups) become one type whose copies are interchangeable;
    off, each part is its own type and swapping two congruent parts is another assembly (as
    BurrTools counts shapes listed separately)."""

    parts: tuple[PartSpec, ...]
    result: ColoredPiece
    variable: frozenset[Cell] = frozenset()
    rules: ColorRules = ColorRules()
    max_holes: int | None = None
    merge_congruent: bool = True


@dataclass(frozen=True)
class TypeInfo:
    """Parts merged into one piece type (same coloured shape up to rotation, same groups)."""

    name: str
    piece: ColoredPiece  # canonical
    lo: int
    hi: int
    groups: tuple[tuple[int, int], ...]
    parts: tuple[str, ...]


@dataclass(frozen=True)
class Symmetry:
    matrix: IntArray
    shift: IntArray
    perm: I32  # cell i -> cell perm[i]
    proper: bool


@dataclass(eq=False)
class Packing:
    """A compiled :class:`PackingSpec`: the engine's :class:`CoverProblem` (its tables hold
    the colour-filtered placements; the engine's own symmetry machinery is not used on it),
    row codes, and the result's symmetries acting on rows."""

    spec: PackingSpec
    problem: CoverProblem
    types: tuple[TypeInfo, ...]
    codes: tuple[IntArray, ...]  # per type: (n, k) sorted codes cell * COLOR_BASE + colour
    symmetries: tuple[Symmetry, ...]  # identity first, rotations before reflections
    mirror_type: tuple[int, ...]  # per type: its mirror image's type, or -1
    hole_type: int = -1  # the type of holes (see compile_packing), or -1
    _maps: dict[bool, I32] = field(default_factory=dict, repr=False)

    @property
    def n_rows(self) -> int:
        return self.problem.n_rows

    @cached_property
    def row_variable(self) -> IntArray:
        """How many variable cells each row covers."""
        opt = np.zeros(self.problem.n_cells, dtype=np.int64)
        opt[sorted(self.problem.optional)] = 1
        ptr, flat = self.problem.row_ptr, self.problem.flat_cells
        return np.add.reduceat(opt[flat], ptr[:-1]) if self.n_rows else np.zeros(0, np.int64)

    def group(self, reflections: bool) -> list[int]:
        """Indices into :attr:`symmetries`: rotations only, or every symmetry."""
        return [i for i, s in enumerate(self.symmetries) if reflections or s.proper]

    def row_maps(self, reflections: bool) -> I32:
        """``maps[g, r]``: the row that symmetry ``g`` of :meth:`group` makes of row ``r``
        (-1: its image is a piece the problem does not have). A symmetry's row is its own
        business, so with the rotations' maps known only the reflections are looked up."""
        hit = self._maps.get(reflections)
        if hit is None:
            rot = self._maps.get(False) if reflections else None
            if rot is None or self.group(False) != list(range(len(rot))):
                hit = self._row_maps([self.symmetries[g] for g in self.group(reflections)])
            else:  # rotations come first and are known: map rows by the reflections only
                flips = [s for s in self.symmetries if not s.proper]
                hit = np.concatenate([rot, self._row_maps(flips)]) if flips else rot
            self._maps[reflections] = hit
        return hit

    def _row_maps(self, syms: list[Symmetry]) -> I32:
        """Every symmetry at once, type by type (one lookup per type and handedness, not one
        per symmetry and type: 0.05 s on SolidSixPieceBurrs' 12 rotations and 25 pieces)."""
        out = np.full((len(syms), self.n_rows), -1, dtype=np.int32)
        starts = self.problem.row_start
        perms = np.stack([sym.perm for sym in syms]).astype(np.int64)
        proper = np.array([sym.proper for sym in syms])
        for t, codes in enumerate(self.codes):
            if len(codes) == 0:
                continue
            img = perms[:, codes // COLOR_BASE] * COLOR_BASE + codes % COLOR_BASE
            img.sort(axis=2)
            a, b = int(starts[t]), int(starts[t + 1])
            for dest, chosen in ((t, proper), (self.mirror_type[t], ~proper)):
                if dest < 0 or not chosen.any():
                    continue
                queries = img[chosen].reshape(-1, codes.shape[1])
                rows = _lookup_rows(self.codes[dest], queries).reshape(-1, b - a)
                if dest == t and chosen is proper and np.any(rows < 0):
                    raise AssertionError("a rotation of the result mapped a row outside the rows")
                out[np.flatnonzero(chosen), a:b] = np.where(rows >= 0, rows + int(starts[dest]), -1)
        return out

    def row_type(self, row: int) -> int:
        return int(self.problem.row_type[row])

    def placed(self, row: int) -> Shape:
        return self.problem.placed_shape(row)


def _lookup_rows(table: IntArray, queries: IntArray) -> I32:
    """Index of each query row in ``table`` (rows of equal width; equal rows of ``table``: the
    last one), or -1. Rows compared as raw bytes, sorted and bisected in numpy: ~10 ms for
    48 000 queries, and no kernel to load (the first numba load of a process costs ~0.15 s)."""
    out = np.full(len(queries), -1, dtype=np.int32)
    if len(table) == 0 or len(queries) == 0:
        return out
    row = np.dtype((np.void, table.dtype.itemsize * table.shape[1]))
    keys = np.ascontiguousarray(table).view(row).ravel()
    asked = np.ascontiguousarray(queries, dtype=table.dtype).view(row).ravel()
    order = np.argsort(keys, kind="stable")  # equal rows keep their order: the last is found
    pos = np.maximum(np.searchsorted(keys[order], asked, side="right") - 1, 0)
    hit = keys[order][pos] == asked
    out[hit] = order[pos[hit]]
    return out


def _merge(parts: Sequence[PartSpec], merge: bool = True) -> list[TypeInfo]:
    """One type per coloured shape and groups (``merge``), else one per part."""
    groups: dict[tuple[ColoredPiece, tuple[tuple[int, int], ...], str], list[PartSpec]] = {}
    for p in parts:
        if len(p.piece.voxels) == 0:
            raise CoverError(f"part {p.name}: a piece needs at least one voxel")
        if not 0 <= p.lo <= p.hi:
            raise CoverError(f"part {p.name}: need 0 <= min <= max, got {p.lo}, {p.hi}")
        key = (p.piece.canonical(), tuple(sorted(p.groups)), "" if merge else p.name)
        groups.setdefault(key, []).append(p)
    out = []
    for (canon, _groups, _name), members in groups.items():
        lo = sum(m.lo for m in members)
        hi = sum(m.hi for m in members)
        if hi == 0:
            continue
        merged: dict[int, int] = {}
        for m in members:
            for gid, count in m.groups:
                merged[gid] = merged.get(gid, 0) + count
        names = tuple(m.name for m in members)
        out.append(TypeInfo(names[0], canon, lo, hi, tuple(sorted(merged.items())), names))
    return out


def _result_symmetries(spec: PackingSpec, target: Shape) -> tuple[Symmetry, ...]:
    """The result's symmetries keeping colours and variable marks (identity first, rotations
    before reflections)."""
    idx = target_index(target)
    colors = np.zeros(len(target), dtype=np.int64)
    colors[idx.index_of(np.asarray(spec.result.voxels))] = spec.result.colors
    var = np.zeros(len(target), dtype=bool)
    if spec.variable:
        var[idx.index_of(np.asarray(sorted(spec.variable)))] = True
    ext = np.asarray(target.extent)
    out = []
    for m in SYMMETRIES:
        if not np.array_equal(np.abs(m) @ ext, ext):
            continue  # the bounding box would not map onto itself
        img = target.voxels @ np.asarray(m).T
        shift = target.min_corner - img.min(axis=0)
        perm = idx.index_of(img + shift)
        if np.any(perm < 0):
            continue
        if np.array_equal(colors[perm], colors) and np.array_equal(var[perm], var):
            proper = round(float(np.linalg.det(m))) > 0
            out.append(Symmetry(np.asarray(m), shift, perm, proper))
    out.sort(key=lambda s: not s.proper)  # stable: the identity stays first
    return tuple(out)


def _type_rows(
    piece: ColoredPiece, target: Shape, cell_color: np.ndarray, ok: np.ndarray
) -> tuple[Placements, IntArray]:
    """Every colour-compatible placement of ``piece`` in ``target`` and its sorted codes."""
    idx = target_index(target)
    occ = idx.grid >= 0
    color_grid = np.zeros(idx.dims, dtype=np.int64)
    rel = target.voxels - idx.origin
    color_grid[rel[:, 0], rel[:, 1], rel[:, 2]] = cell_color
    vox, colors = piece.orientation_arrays
    used, layer = np.unique(colors, return_inverse=True)
    fits = occ[None] & ok[used][:, color_grid]
    orient, shifts = fitting_shifts(fits, vox, layer.reshape(colors.shape))
    placed = vox[orient] + shifts[:, None, :]
    cells = idx.grid[placed[..., 0], placed[..., 1], placed[..., 2]].astype(np.int64)
    order = np.argsort(cells, axis=1)
    codes = np.take_along_axis(cells * COLOR_BASE + colors[orient], order, axis=1)
    table = Placements(
        shape=piece.shape,
        orientations=tuple(Shape.from_sorted(v) for v in vox),
        cells=np.take_along_axis(cells, order, axis=1).astype(np.int32),
        orientation=orient.astype(np.int32),
        offset=shifts + idx.origin,
        lookup=np.full((len(vox), 1, 1, 1), -1, dtype=np.int32),  # not used here
        origin=idx.origin,
    )
    return table, codes


def compile_packing(spec: PackingSpec) -> Packing:
    """Rows, types and symmetries of a packing problem (raises :class:`CoverError` on bad
    input: an empty result, variable cells outside it, a malformed part)."""
    if len(spec.result.voxels) == 0:
        raise CoverError("result: the voxel set is empty")
    target = Shape(spec.result.voxels)
    if not spec.variable <= target.cell_set:
        raise CoverError("result: some variable cells are not in the result")
    if len(spec.variable) == len(target):
        raise CoverError("result: at least one result cell must be fixed (not variable)")
    idx = target_index(target)
    optional = frozenset(int(i) for i in idx.index_of(np.asarray(sorted(spec.variable))))
    if not spec.variable:
        optional = frozenset()
    cell_color = np.zeros(len(target), dtype=np.int64)
    cell_color[idx.index_of(np.asarray(spec.result.voxels))] = spec.result.colors
    ok = spec.rules.table()
    top = max([*cell_color.tolist(), *(c for p in spec.parts for c in p.piece.colors), 0])
    if top > spec.rules.n_colors:
        raise CoverError(f"colour {top} is used but only {spec.rules.n_colors} are defined")
    infos = _merge(spec.parts, spec.merge_congruent)
    tables, codes = [], []
    for info in infos:
        table, c = _type_rows(info.piece, target, cell_color, ok)
        tables.append(table)
        codes.append(c)
    opt = np.zeros(len(target), dtype=bool)
    opt[sorted(optional)] = True
    hole_type = -1
    if any(len(tb) and opt[tb.cells].all(axis=1).any() for tb in tables):
        # Some piece fits wholly on variable cells, where the kernels never branch (they only
        # branch on fixed cells). Then every variable cell becomes fixed, covered either by a
        # piece or by a "hole" (a monocube that may only sit on variable cells, at most
        # max_holes of them), so every placement is reachable and each assembly is met once.
        n_holes = len(optional) if spec.max_holes is None else min(spec.max_holes, len(optional))
        if n_holes:
            hole_type = len(infos)
            hole = ColoredPiece(((0, 0, 0),), (0,))
            infos.append(TypeInfo(HOLE, hole, 0, n_holes, (), ()))
            tables.append(_hole_rows(target, sorted(optional)))
            codes.append(np.asarray(sorted(optional), dtype=np.int64)[:, None] * COLOR_BASE)
        optional = frozenset()
    sizes = np.array([len(t) for t in tables], dtype=np.int64)
    row_start = np.zeros(len(infos) + 1, dtype=np.int64)
    np.cumsum(sizes, out=row_start[1:])
    row_type = np.repeat(np.arange(len(infos), dtype=np.int32), sizes)
    types = tuple(
        PieceType(
            info.piece.shape,
            tuple(info.name if i == 0 else f"{info.name}_{i + 1}" for i in range(info.hi)),
            info.lo,
            info.hi,
            info.piece != info.piece.mirror_canonical,
        )
        for info in infos
    )
    problem = CoverProblem(target, optional, types, tuple(tables), row_type, row_start, False)
    # Congruent types kept apart (merge_congruent off) pair with their mirror types in order:
    # the k-th type of a piece with the k-th of its mirror piece (itself when achiral).
    by_key: dict[tuple[ColoredPiece, tuple[tuple[int, int], ...]], list[int]] = {}
    by_piece: dict[ColoredPiece, list[int]] = {}
    for i, info in enumerate(infos):
        if i != hole_type:
            by_key.setdefault((info.piece, info.groups), []).append(i)
            by_piece.setdefault(info.piece, []).append(i)
    mirror = []
    for i, info in enumerate(infos):
        m = info.piece.mirror_canonical
        if i == hole_type or m == info.piece:
            mirror.append(i)
            continue
        rank = by_key[(info.piece, info.groups)].index(i)
        same = by_key.get((m, info.groups)) or by_piece.get(m) or []
        mirror.append(same[rank] if rank < len(same) else -1)
    syms = _result_symmetries(spec, target)
    return Packing(spec, problem, tuple(infos), tuple(codes), syms, tuple(mirror), hole_type)


def _hole_rows(target: Shape, cells: list[int]) -> Placements:
    idx = target_index(target)
    one = Shape([(0, 0, 0)])
    return Placements(
        shape=one,
        orientations=(one,),
        cells=np.asarray(cells, dtype=np.int32)[:, None],
        orientation=np.zeros(len(cells), dtype=np.int32),
        offset=target.voxels[cells],
        lookup=np.full((1, 1, 1, 1), -1, dtype=np.int32),  # not used here
        origin=idx.origin,
    )


def canonical_keys(maps: I32, solutions: I32) -> I32:
    """Per solution (rows, -1 padded), the least sorted row set among its images under the
    group of ``maps`` (images through a -1 are skipped: not assemblies of this problem)."""
    out = np.empty(solutions.shape, dtype=np.int32)
    _least_images(np.ascontiguousarray(maps), np.ascontiguousarray(solutions), out)
    return out


@njit(cache=True)
def _least_images(maps: I32, solutions: I32, out: I32) -> None:
    """:func:`canonical_keys` in one pass per solution, over its real rows only (numpy's
    version built every image of every solution, padding included: 0.05 s of
    SolidSixPieceBurrs' 4199 raw assemblies)."""
    k = solutions.shape[1]
    rows = np.empty(k, dtype=np.int32)
    img = np.empty(k, dtype=np.int32)
    best = np.empty(k, dtype=np.int32)
    for s in range(solutions.shape[0]):
        m = 0
        for p in range(k):
            if solutions[s, p] >= 0:
                rows[m] = solutions[s, p]
                m += 1
        have = False
        for g in range(maps.shape[0]):
            ok = True
            for p in range(m):  # insertion sort: a handful of rows
                v = maps[g, rows[p]]
                if v < 0:
                    ok = False
                    break
                q = p
                while q > 0 and img[q - 1] > v:
                    img[q] = img[q - 1]
                    q -= 1
                img[q] = v
            if not ok:
                continue
            if not have:
                best[:m] = img[:m]
                have = True
                continue
            for p in range(m):
                if img[p] != best[p]:
                    if img[p] < best[p]:
                        best[:m] = img[:m]
                    break
        for p in range(k):
            out[s, p] = best[p] if have and p < m else -1
