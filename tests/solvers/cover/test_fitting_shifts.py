"""The vectorised placement tables (``fitting_shifts``: every orientation advanced voxel by
voxel at once) against the plain definition, one orientation, one shift and one voxel at a time:
the same rows in the same order, colours and holes in the result included; and the placement
keys and shape tables of BurrTools' image (computed per orientation, per 48 matrices at once)
against the one-at-a-time lookups they replace."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from chaingeo.core.geometry import ROTATION_STACK, SYMMETRIES, Shape
from chaingeo.solvers.assembly.btassemble import bt_packing_spec
from chaingeo.solvers.assembly.btcount import RowVerdicts
from chaingeo.solvers.cover.constrained import (
    COLOR_BASE,
    ColoredPiece,
    ColorRules,
    _type_rows,
    compile_packing,
)
from chaingeo.solvers.cover.placements import _placements, target_index
from chaingeo.solvers.motion import btorient
from tests.support.burrtxt import random_puzzle


def _random_cells(rng: np.random.Generator, most: int, span: int) -> Shape:
    n = int(rng.integers(1, most + 1))
    return Shape(rng.integers(0, span, size=(n, 3)).tolist())


def _reference_rows(
    piece: ColoredPiece, target: Shape, cell_color: np.ndarray, ok: np.ndarray
) -> list[tuple[int, tuple[int, ...], tuple[int, ...]]]:
    """(orientation, offset, sorted codes) of every fitting placement, by brute force."""
    idx = target_index(target)
    out = []
    for o, orient in enumerate(piece.orientations()):
        vox = np.asarray(orient.voxels, dtype=np.int64)
        for shift in itertools.product(*(range(d) for d in idx.dims)):
            placed = vox + np.asarray(shift)
            if np.any(placed >= np.asarray(idx.dims)):
                continue
            cells = idx.grid[placed[:, 0], placed[:, 1], placed[:, 2]]
            if np.any(cells < 0):
                continue
            if not all(ok[c, cell_color[q]] for c, q in zip(orient.colors, cells, strict=True)):
                continue
            codes = sorted(
                int(q) * COLOR_BASE + c for q, c in zip(cells, orient.colors, strict=True)
            )
            out.append((o, tuple((np.asarray(shift) + idx.origin).tolist()), tuple(codes)))
    return out


@pytest.mark.parametrize("seed", range(30))
def test_coloured_rows_match_brute_force(seed: int) -> None:
    rng = np.random.default_rng(np.random.SeedSequence([2026_11_27, seed]))
    target = _random_cells(rng, 40, 4).translate(rng.integers(-3, 3, size=3))
    shape = _random_cells(rng, 5, 3)
    n_colors = int(rng.integers(0, 3))
    colors = {c: int(rng.integers(0, n_colors + 1)) for c in shape.cells}
    piece = ColoredPiece.of(shape, colors).canonical()
    pairs = {
        (p, r) for p in range(1, n_colors + 1) for r in range(1, n_colors + 1) if rng.random() < 0.6
    }
    ok = ColorRules(n_colors, frozenset(pairs)).table()
    cell_color = rng.integers(0, n_colors + 1, size=len(target))
    table, codes = _type_rows(piece, target, cell_color, ok)
    got = [
        (int(o), tuple(off.tolist()), tuple(c.tolist()))
        for o, off, c in zip(table.orientation, table.offset, codes, strict=True)
    ]
    assert got == _reference_rows(piece, target, cell_color, ok)
    assert np.array_equal(table.cells, codes // COLOR_BASE)
    assert [s.cells for s in table.orientations] == [p.voxels for p in piece.orientations()]
    distinct = list(dict.fromkeys(piece.transformed(m) for m in ROTATION_STACK))
    assert list(piece.orientations()) == distinct  # rotation order, first occurrences


@pytest.mark.parametrize("seed", range(30))
def test_plain_placements_match_brute_force(seed: int) -> None:
    rng = np.random.default_rng(np.random.SeedSequence([11, seed]))
    target = _random_cells(rng, 50, 5)
    canon = _random_cells(rng, 6, 3).canonical()
    table = _placements.__wrapped__(canon, target)
    piece = ColoredPiece.of(canon)
    want = _reference_rows(piece, target, np.zeros(len(target), np.int64), ColorRules().table())
    got = [
        (int(o), tuple(off.tolist()))
        for o, off in zip(table.orientation, table.offset, strict=True)
    ]
    assert got == [(o, off) for o, off, _ in want]
    assert np.array_equal(
        table.cells, np.asarray([c for *_, c in want]).reshape(table.cells.shape) // COLOR_BASE
    )
    for i, (o, off) in enumerate(got):
        rel = np.asarray(off) - target_index(target).origin
        assert table.lookup[o, rel[0], rel[1], rel[2]] == i
    assert (table.lookup >= 0).sum() == len(got)


def _tables_one_at_a_time(
    cells: np.ndarray,
) -> tuple[dict[bytes, tuple[int, np.ndarray]], list[tuple[int, tuple[int, ...]]]]:
    first: dict[bytes, tuple[int, np.ndarray]] = {}
    for t in range(24):
        rot = cells @ btorient._MATS[t].T
        first.setdefault(btorient._normal(rot), (t, rot.min(axis=0)))
    table = []
    for m in btorient._MATS:
        img = cells @ m.T
        hit = first.get(btorient._normal(img))
        table.append((-1, (0, 0, 0)) if hit is None else (hit[0], tuple(img.min(axis=0) - hit[1])))
    return first, table


@pytest.mark.parametrize("seed", range(40))
def test_shape_tables_match_one_matrix_at_a_time(seed: int) -> None:
    rng = np.random.default_rng(np.random.SeedSequence([5, seed]))
    if seed % 3:
        cells = _random_cells(rng, 8, 4).voxels
    else:  # a box: many symmetries
        dims = tuple(int(d) for d in rng.integers(1, 4, size=3))
        cells = np.argwhere(np.ones(dims)).astype(np.int64) + rng.integers(-3, 3, size=3)
    first, table = btorient._piece_tables.__wrapped__(cells.tobytes(), len(cells))
    want_first, want_table = _tables_one_at_a_time(cells)
    assert {k: (t, tuple(v)) for k, (t, v) in first.items()} == {
        k: (t, tuple(v)) for k, (t, v) in want_first.items()
    }
    assert [(t, tuple(v)) for t, v in table] == want_table
    base, want = cells.min(axis=0), btorient._normal(cells)
    expected = [
        (m.tolist(), tuple(base - (cells @ m.T).min(axis=0)))
        for m in map(np.asarray, SYMMETRIES)
        if btorient._normal(cells @ m.T) == want
    ]
    got = [(np.asarray(m).tolist(), tuple(s)) for m, s in btorient.symmetries_of(cells)]
    assert got == expected


@pytest.mark.parametrize("seed", range(12))
def test_row_keys_are_each_rows_placement_key(seed: int) -> None:
    rng = np.random.default_rng(np.random.SeedSequence([2026_11_27, 3, seed]))
    packing = compile_packing(bt_packing_spec(random_puzzle(rng), 0))
    verdicts = RowVerdicts(packing, None, want_levels=False)
    rows = np.flatnonzero(verdicts.piece).astype(np.int64)
    keys = verdicts._key(rows)
    bias = 1 << 15
    for r, key in zip(rows.tolist(), keys.tolist(), strict=True):
        name = verdicts.type_slot[int(verdicts.row_type[r])]
        t, x, y, z = verdicts.image.placement_key(name, packing.placed(r).voxels)
        assert key == (((t << 16 | x + bias) << 16 | y + bias) << 16) | z + bias


@pytest.mark.parametrize("seed", range(15))
def test_reflection_maps_extend_the_rotation_maps(seed: int) -> None:
    """All symmetries' row maps built on the rotations' (known first) are the maps built in
    one go."""
    puzzle = random_puzzle(np.random.default_rng(np.random.SeedSequence([9, seed])))
    first, fresh = (compile_packing(bt_packing_spec(puzzle, 0)) for _ in range(2))
    rotations = first.row_maps(False)
    both = first.row_maps(True)
    assert np.array_equal(both, fresh.row_maps(True))
    assert np.array_equal(both[: len(rotations)], rotations)
