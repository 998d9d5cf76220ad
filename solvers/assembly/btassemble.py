"""BurrTools' assembler on a compiled packing (:mod:`chaingeo.solvers.cover.constrained`):
assemblies, mirror images, holes, and the solutions the disassembler takes apart.

*Assemblies* are counted as BurrTools counts them: one per class of the result's symmetries
(rotations; colours and variable cells kept). ``mirrors="keep"`` keeps mirror images apart
(BurrTools' stored figures, its GUI option "keep mirror solutions"); ``mirrors="drop"`` also
identifies an assembly with its mirror image when the mirror image is itself an assembly of
the problem (every piece's mirror shape is a piece of the problem, in range): what BurrTools'
command-line solver ``burrTxt`` prints. A problem's ``max_holes`` drops assemblies leaving more
variable cells empty.

The search is cut by symmetry first: an anchor (a piece used exactly once, else a fixed cell
and the rotations keeping it in place) keeps one placement per orbit, so every class is met at
least once; canonical keys (:func:`chaingeo.solvers.cover.constrained.canonical_keys`) then keep
each class once, the first met in the engine's fixed order. *Solutions* are the classes the
disassembler takes apart (:func:`chaingeo.solvers.motion.disassemble.analyze_assembly`; with piece
groups
:func:`chaingeo.solvers.assembly.groups.analyze_grouped`), under the same moves as everything else
here.

*Time*: :func:`count_bt` runs the enumeration and every disassembly under one
:class:`chaingeo.solvers.deadline.Deadline` (the caller's, else one of ``limits.seconds``); past it
a :class:`SearchLimitError` naming ``seconds`` is raised, wherever the time went.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from typing import Literal

import numpy as np

from chaingeo.core.arrays import I32
from chaingeo.core.formats.burrtools import BTPuzzle
from chaingeo.core.geometry import Shape
from chaingeo.solvers.assembly.groups import PieceGroups, analyze_grouped
from chaingeo.solvers.cover.constrained import (
    ColoredPiece,
    ColorRules,
    Packing,
    PackingSpec,
    PartSpec,
    canonical_keys,
)
from chaingeo.solvers.cover.problem import CoverError
from chaingeo.solvers.cover.rowreduce import live_rows
from chaingeo.solvers.cover.search import CoverSearch
from chaingeo.solvers.deadline import Deadline
from chaingeo.solvers.limits import SearchLimits
from chaingeo.solvers.motion.btorient import BTImage
from chaingeo.solvers.motion.disassemble import Analysis, Separations, analyze_assembly

Mirrors = Literal["keep", "drop"]


def bt_packing_spec(puzzle: BTPuzzle, index: int, *, merge_congruent: bool = False) -> PackingSpec:
    """Problem ``index`` of a BurrTools puzzle as a packing: parts named ``s<shape id>``
    (``s<shape id>p<part>`` when a shape is listed twice), colours, variable result cells,
    colour rules and hole cap. A piece with variable voxels is refused, as BurrTools does.
    Congruent shapes listed separately stay distinguishable pieces unless ``merge_congruent``
    (BurrTools counts their permutations: ``assembler_0.cpp`` places each shape of the
    problem as its own piece)."""
    prob = puzzle.problem(index)
    res = puzzle.shapes[prob.result]
    ids = [p.shape for p in prob.parts]
    parts = []
    for k, part in enumerate(prob.parts):
        shape = puzzle.shapes[part.shape]
        where = f"problem {index}, shape {part.shape}"
        if len(shape.variable) and part.max:
            raise CoverError(f"{where}: a piece with variable voxels (BurrTools refuses those)")
        if len(shape.filled) == 0:
            if part.min:
                raise CoverError(f"{where}: an empty shape is a required piece")
            continue
        name = f"s{part.shape}" if ids.count(part.shape) == 1 else f"s{part.shape}p{k}"
        piece = ColoredPiece.of(shape.filled, shape.color_map)
        parts.append(PartSpec(name, piece, part.min, part.max, part.groups))
    return PackingSpec(
        tuple(parts),
        ColoredPiece.of(res.cells, res.color_map),
        frozenset(res.variable.cells),
        ColorRules(len(puzzle.colors), frozenset(prob.color_pairs)),
        prob.max_holes,
        merge_congruent,
    )


@dataclass(frozen=True)
class Anchor:
    label: str
    rows: I32  # the rows searched (every row but the anchored non-representatives)
    factor: float  # anchored rows before / after


def choose_anchor(packing: Packing) -> Anchor | None:
    """One placement per rotation orbit of a piece used exactly once, else of the rows through
    a fixed cell (under the rotations fixing it); None without symmetry. Among pieces, as the
    engine does (:func:`chaingeo.solvers.cover.packings.anchor_plan`): the fewest orientations first
    (the most symmetric piece, Knuth's choice for pentominoes), then the fewest representatives per
    placement, then the fewest representatives."""
    maps = packing.row_maps(False)
    if len(maps) == 1 or packing.n_rows == 0:
        return None
    starts = packing.problem.row_start
    best: tuple[tuple[int, float, int], str, I32, I32] | None = None
    for t, info in enumerate(packing.types):
        a, b = int(starts[t]), int(starts[t + 1])
        if info.lo != 1 or info.hi != 1 or a == b:
            continue
        rows = np.arange(a, b, dtype=np.int32)
        reps = np.unique(maps[:, rows].min(axis=0)).astype(np.int32)
        score = (len(info.piece.orientations()), len(reps) / len(rows), len(reps))
        if best is None or score < best[0]:
            best = (score, info.name, rows, reps)
    if best is not None:
        _, label, anchored, reps = best
    else:
        cell = _cell_anchor(packing, maps)
        if cell is None:
            return None
        _, label, anchored, reps = cell
    if len(reps) == len(anchored):
        return None
    keep = np.ones(packing.n_rows, dtype=bool)
    keep[anchored] = False
    keep[reps] = True
    return Anchor(label, np.flatnonzero(keep).astype(np.int32), len(anchored) / len(reps))


def _cell_anchor(packing: Packing, maps: I32) -> tuple[float, str, I32, I32] | None:
    problem = packing.problem
    perms = np.stack([packing.symmetries[g].perm for g in packing.group(False)])
    stab = (perms == np.arange(problem.n_cells)[None, :]).sum(axis=0)
    stab[sorted(problem.optional)] = 0
    if stab.max() <= 1:
        return None
    ptr = problem.row_ptr
    owner = np.repeat(np.arange(problem.n_rows, dtype=np.int32), np.diff(ptr))
    best: tuple[float, str, I32, I32] | None = None
    for c in np.flatnonzero(stab == stab.max()):
        group = np.flatnonzero(perms[:, c] == c)
        rows = np.unique(owner[problem.flat_cells == c]).astype(np.int32)
        if len(rows) == 0:
            continue
        reps = np.unique(maps[group][:, rows].min(axis=0)).astype(np.int32)
        factor = len(rows) / len(reps)
        if best is None or factor > best[0]:
            best = (factor, f"cell {problem.target.cells[int(c)]}", rows, reps)
    return best


def iter_classes(
    packing: Packing,
    *,
    mirrors: Mirrors = "keep",
    node_limit: int | None = None,
    anchor: Anchor | Literal["auto"] | None = "auto",
    deadline: Deadline | None = None,
) -> Iterator[I32]:
    """One assembly per class (its rows, sorted), in the search's fixed order. ``anchor``:
    the symmetry cut (:func:`choose_anchor` by default; None searches every row). Past
    ``deadline`` the search stops with its :class:`SearchLimitError`."""
    if mirrors not in ("keep", "drop"):
        raise ValueError(f"mirrors: 'keep' or 'drop', got {mirrors!r}")
    if packing.n_rows == 0:
        return
    if anchor == "auto":
        anchor = choose_anchor(packing)
    rot = packing.row_maps(False)
    full = packing.row_maps(True) if mirrors == "drop" else None
    # Rows no assembly can hold go first (BurrTools' -r): far fewer dead ends, same classes.
    rows = live_rows(packing.problem, None if anchor is None else anchor.rows)
    search = CoverSearch(packing.problem, rows, node_limit=node_limit, deadline=deadline)
    max_holes = packing.spec.max_holes if packing.hole_type < 0 else None  # else in the rows
    n_var = len(packing.problem.optional)
    seen: set[bytes] = set()
    seen_full: set[bytes] = set()
    for block in search.batches(4096):
        if max_holes is not None:
            covered = np.where(block >= 0, packing.row_variable[np.maximum(block, 0)], 0)
            block = block[n_var - covered.sum(axis=1) <= max_holes]
        keys = canonical_keys(rot, block)
        fresh = []
        for i, key in enumerate(keys):
            k = key.tobytes()
            if k not in seen:
                seen.add(k)
                fresh.append(i)
        if not fresh:
            continue
        sols = block[fresh]
        keep = np.ones(len(sols), dtype=bool)
        if full is not None:
            for i, key in enumerate(canonical_keys(full, sols)):
                k = key.tobytes()
                keep[i] = k not in seen_full
                seen_full.add(k)
        for sol in sols[keep]:
            yield np.sort(sol[sol >= 0]).astype(np.int32)


def named_assembly(packing: Packing, rows: I32) -> dict[str, Shape]:
    """``{piece name: placed voxels}``: copies of a type are ``name``, ``name_2``, ...; in
    BurrTools' piece order (the problem's parts in order, a part's copies together), the order
    its disassembler lists moves in."""
    used: dict[int, int] = {}
    out: dict[str, Shape] = {}
    for r in rows.tolist():
        t = packing.row_type(r)
        if t == packing.hole_type:
            continue
        used[t] = used.get(t, 0) + 1
        out[packing.problem.types[t].slots[used[t] - 1]] = packing.placed(r)
    return out


class BTFrame:
    """Turns an assembly into the symmetric image BurrTools' assembler reports
    (:class:`chaingeo.solvers.motion.btorient.BTImage`), whose disassembly BurrTools prints."""

    def __init__(self, packing: Packing) -> None:
        spec = packing.spec
        by_name = {p.name: np.asarray(p.piece.voxels, dtype=np.int64) for p in spec.parts}
        self.types = [(t, info) for t, info in enumerate(packing.types) if t != packing.hole_type]
        self.grids: dict[str, np.ndarray] = {}
        for t, info in self.types:
            grid = by_name.get(info.parts[0]) if len(info.parts) == 1 else None
            for slot in packing.problem.types[t].slots:
                self.grids[slot] = grid if grid is not None else info.piece.shape.voxels
        self.slots = [packing.problem.types[t].slots for t, _ in self.types]
        symmetries = [(sym.matrix, sym.shift) for sym in packing.symmetries]
        result = np.asarray(spec.result.voxels, dtype=np.int64)
        self.image = BTImage(self.grids, symmetries, result)

    def __call__(self, assembly: dict[str, Shape]) -> dict[str, Shape]:
        parts = [[n for n in slots if n in assembly] for slots in self.slots]
        parts = [p for p in parts if p]
        image, _ = self.image(assembly, parts)
        return image


def piece_groups(packing: Packing) -> PieceGroups:
    shape_of: dict[str, str] = {}
    groups_of: dict[str, tuple[tuple[int, int], ...]] = {}
    for t, (info, ty) in enumerate(zip(packing.types, packing.problem.types, strict=True)):
        if t == packing.hole_type:
            continue
        for slot in ty.slots:
            shape_of[slot] = info.name
            groups_of[slot] = info.groups
    return PieceGroups(shape_of, groups_of)


def disassemble(
    packing: Packing,
    assembly: dict[str, Shape],
    *,
    max_group: int | None = None,
    limits: SearchLimits | None = None,
    groups: PieceGroups | None = None,
    deadline: Deadline | None = None,
    separations: Separations = "first",
) -> Analysis:
    """The disassembler's verdict on one assembly (level and moves), groups honoured
    (``groups``: :func:`piece_groups` of the packing, when the caller has it already;
    ``deadline``: the analysis' shared one, else one of
    ``limits.seconds``;
    ``separations``: see :func:`chaingeo.solvers.motion.disassemble.analyze_assembly`). Pieces are
    searched
    in the assembly's order (:func:`named_assembly`: BurrTools')."""
    groups = piece_groups(packing) if groups is None else groups
    order = list(assembly)
    if groups.any():
        return analyze_grouped(
            assembly, groups, max_group=max_group, limits=limits, deadline=deadline,
            separations=separations, order=order,
        )  # fmt: skip
    return analyze_assembly(
        assembly, max_group=max_group, limits=limits, optimal=False, deadline=deadline,
        separations=separations, order=order, fallback=False,
    )  # fmt: skip
