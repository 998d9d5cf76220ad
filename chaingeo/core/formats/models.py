"""CHAIN's own puzzle models (URDF + OBJ parts) imported exactly as lattice pieces and levels.

:func:`import_model` reads a puzzle folder (see :mod:`chaingeo.core.formats.mesh_lattice` for the
meshes, the lattice fit and the per-cell inside test) and either returns every part as a
:class:`~chaingeo.core.geometry.Shape` with what the import did to it, or raises one
:class:`ModelImportError` saying why the model is not a lattice model (too little axis-aligned
area, no unit that fits, cells that are neither full nor empty). Nothing is written here.

* **Puzzles** (parts in their assembled places): parts made with clearance sit a fraction of a
  unit off the common grid. Each is snapped to an integer offset: plain rounding, or its other
  neighbour where it sits a quarter unit or more off (any offset within one unit where rounding
  leaves an overlap); the choice with no overlap, then the most touching faces, then the least
  displacement wins, and every displacement is reported.
* **Stacking** (pieces laid out apart beside an open-top container): the container's cavity,
  measured in the pieces' unit, is the box; each piece is its voxels in the orientation laid out.

Building a level needs a plan (puzzles) or a packing (stacking) found by the solvers; this core
module takes them as arguments (:func:`model_puzzle_level`, :func:`model_stacking_level`) and
never imports a solver. Levels name the source model and its licence (Apache-2.0, copyright the
CHAIN authors) in ``provenance.generator`` and in ``stats.source``.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Final, Literal

import numpy as np

from chaingeo.core.colors import PALETTE, NamedColor
from chaingeo.core.formats.mesh_lattice import (
    MIN_ALIGNED_SHARE,
    LatticeFit,
    ModelImportError,
    PartMesh,
    PartVoxels,
    Planes,
    container_cavity,
    face_planes,
    find_container,
    fit_lattice,
    voxelize,
)
from chaingeo.core.formats.model_files import load_model_parts
from chaingeo.core.formats.rods import round_rods
from chaingeo.core.geometry import NEIGHBOURS, Cell, Shape, puzzle_signature
from chaingeo.core.kinematics import Move
from chaingeo.core.level import (
    Difficulty,
    Level,
    Piece,
    Provenance,
    PuzzleSolution,
    StackingSolution,
    default_step_budget,
    revalidate,
)
from chaingeo.core.rules import PuzzleRules, StackingRules, find_placing_order
from chaingeo.core.turns import TurnMove

__all__ = [
    "ImportedModel",
    "ImportedPart",
    "ModelImportError",
    "import_model",
    "model_puzzle_level",
    "model_stacking_level",
]

GENERATOR: Final = "chaingeo.core.formats.models"
VERSION: Final = "1"
SOURCE_REPOSITORY: Final = "https://github.com/Social-AI-Studio/CHAIN"
SOURCE_PATH: Final = "assets/pybullet/phobos_models"
LICENCE: Final = "Apache-2.0"
COPYRIGHT: Final = "the CHAIN authors"
#: A part this far (in units) off the grid along an axis may also snap to its other neighbour.
SNAP_CHOICE: Final = 0.25
#: Exhaustive snapping up to this many combinations; coordinate descent beyond.
SNAP_EXHAUSTIVE: Final = 4096

Kind = Literal["puzzle", "stacking"]


@dataclass(frozen=True)
class ImportedPart:
    """One part as imported: its colour (= piece name), voxels and what snapping did.

    ``moved``: the displacement from the model's place to the lattice place, in units;
    ``decided``: partly filled cells on the puzzle's outside (with their share of inside
    samples), kept when more than half is inside: no other part can reach them without passing
    through this part or leaving the puzzle's bounding box.
    """

    part: str
    color: NamedColor
    shape: Shape
    moved: tuple[float, float, float]
    decided: tuple[tuple[Cell, float], ...] = ()
    rods: tuple[tuple[Cell, int], ...] = ()  # round rods and their axes (formats.rods)

    @property
    def name(self) -> str:
        return self.color.name


@dataclass(frozen=True)
class ImportedModel:
    """A model on the lattice: pieces (assembled, or laid out for stacking) and the fit."""

    model: str
    kind: Kind
    fit: LatticeFit
    aligned_share: float
    parts: tuple[ImportedPart, ...]
    box: tuple[int, int, int] | None = None  # stacking: the container's cavity in cells
    container: str | None = None
    box_residual: float | None = None  # largest cavity size deviation from whole cells, units

    @property
    def shapes(self) -> dict[str, Shape]:
        return {p.name: p.shape for p in self.parts}

    @property
    def rods(self) -> dict[str, dict[Cell, int]]:
        """The round rods of the pieces that have any (:mod:`chaingeo.core.formats.rods`)."""
        return {p.name: dict(p.rods) for p in self.parts if p.rods}

    def moved_parts(self, at_least: float = 0.05) -> dict[str, tuple[float, float, float]]:
        """Parts displaced by ``at_least`` units or more along some axis, by source part name."""
        return {p.part: p.moved for p in self.parts if max(abs(m) for m in p.moved) >= at_least}

    def summary(self) -> dict[str, Any]:
        """The import's figures as plain JSON data (level stats and reports)."""
        return {
            "model": self.model,
            "kind": self.kind,
            "unit": round(self.fit.unit, 6),
            "rms_units": round(self.fit.rms, 4),
            "worst_units": round(self.fit.worst, 4),
            "aligned_share": round(self.aligned_share, 4),
            "parts": {p.name: p.part for p in self.parts},
            "cells": {p.name: len(p.shape) for p in self.parts},
            "moved_units": {
                p.name: [round(m, 3) + 0.0 for m in p.moved]  # + 0.0: no "-0.0" in files
                for p in self.parts
                if any(p.moved)
            },
            "decided_cells": {
                p.name: [[*c, s] for c, s in p.decided] for p in self.parts if p.decided
            },
            **(
                {"round_rods": {p.name: [[*c, a] for c, a in p.rods] for p in self.parts if p.rods}}
                if any(p.rods for p in self.parts)
                else {}
            ),
            **({"box": list(self.box)} if self.box is not None else {}),
            **({"container": self.container} if self.container is not None else {}),
            **(
                {"box_residual_units": round(self.box_residual, 4)}
                if self.box_residual is not None
                else {}
            ),
        }


# ---------------------------------------------------------------------------------------------
# Colours
# ---------------------------------------------------------------------------------------------


def _lab(rgb: Sequence[float]) -> tuple[float, float, float]:
    """sRGB (0..1) to CIE L*a*b* (D65): distances there follow what people see as different."""

    def lin(c: float) -> float:
        return c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4

    r, g, b = (lin(float(c)) for c in rgb[:3])
    x = (0.4124 * r + 0.3576 * g + 0.1805 * b) / 0.95047
    y = 0.2126 * r + 0.7152 * g + 0.0722 * b
    z = (0.0193 * r + 0.1192 * g + 0.9505 * b) / 1.08883

    def f(t: float) -> float:
        return t ** (1 / 3) if t > 0.008856 else 7.787 * t + 16 / 116

    fx, fy, fz = f(x), f(y), f(z)
    return 116 * fy - 16, 500 * (fx - fy), 200 * (fy - fz)


def assign_model_colors(
    wanted: Sequence[tuple[float, float, float, float] | None],
) -> list[NamedColor]:
    """Distinct palette colours, each part's the nearest still free to its material colour.

    Greedy over all (part, colour) pairs by Lab distance, nearest first (ties: part order, then
    palette order), so many parts of one material get the nearest few shades; parts without a
    colour take the remaining palette colours in palette order.
    """
    if len(wanted) > len(PALETTE):
        raise ValueError(f"only {len(PALETTE)} named colours exist, {len(wanted)} parts given")
    labs = [_lab([c / 255 for c in p.rgb]) for p in PALETTE]
    pairs = sorted(
        (math.dist(_lab(w), lab), i, j)
        for i, w in enumerate(wanted)
        if w is not None
        for j, lab in enumerate(labs)
    )
    out: dict[int, int] = {}
    used: set[int] = set()
    for _, i, j in pairs:
        if i not in out and j not in used:
            out[i] = j
            used.add(j)
    free = (j for j in range(len(PALETTE)) if j not in used)
    return [PALETTE[out[i]] if i in out else PALETTE[next(free)] for i in range(len(wanted))]


# ---------------------------------------------------------------------------------------------
# Snapping an assembly
# ---------------------------------------------------------------------------------------------


def _score(shapes: Sequence[Shape]) -> tuple[int, int]:
    """(cells claimed twice, minus faces shared between different parts): smaller is better."""
    owner: dict[Cell, int] = {}
    overlap = 0
    for i, s in enumerate(shapes):
        for c in s:
            if c in owner:
                overlap += 1
            else:
                owner[c] = i
    contacts = 0
    for i, s in enumerate(shapes):
        for x, y, z in s:
            for dx, dy, dz in NEIGHBOURS:
                j = owner.get((x + dx, y + dy, z + dz))
                contacts += j is not None and j != i
    return overlap, -contacts


def _options(phase: Sequence[float], overlapping: bool) -> list[tuple[int, int, int]]:
    """Integer shifts (from plain rounding) worth trying for one part, nearest first."""
    per_axis: list[list[int]] = []
    for ph in phase:
        if overlapping:
            per_axis.append([0, 1, -1] if ph >= 0 else [0, -1, 1])
        elif abs(ph) >= SNAP_CHOICE:
            per_axis.append([0, 1 if ph > 0 else -1])
        else:
            per_axis.append([0])
    combos = [(a, b, c) for a in per_axis[0] for b in per_axis[1] for c in per_axis[2]]
    return sorted(combos, key=lambda s: sum(abs(p - v) for p, v in zip(phase, s, strict=True)))


def snap_parts(
    voxels: Sequence[Shape], phases: Sequence[Sequence[float]]
) -> tuple[list[tuple[int, int, int]], tuple[int, int]]:
    """Integer shifts for every part (see the module docstring) and the resulting score."""
    owner: dict[Cell, int] = {}
    clash: set[int] = set()
    for i, s in enumerate(voxels):
        for c in s:
            if c in owner:
                clash.update((i, owner[c]))
            owner.setdefault(c, i)
    options = [_options(ph, i in clash) for i, ph in enumerate(phases)]

    def cost(choice: Sequence[tuple[int, int, int]]) -> tuple[int, int, float]:
        moved = [s.translate(c) if any(c) else s for s, c in zip(voxels, choice, strict=True)]
        far = sum(
            abs(p - v)
            for ph, c in zip(phases, choice, strict=True)
            for p, v in zip(ph, c, strict=True)
        )
        return (*_score(moved), round(far, 9))

    choice: list[tuple[int, int, int]]
    if math.prod(len(o) for o in options) <= SNAP_EXHAUSTIVE:
        combos: list[list[tuple[int, int, int]]] = [list(c) for c in itertools.product(*options)]
        choice = min(combos, key=cost)
    else:
        choice = [o[0] for o in options]
        current: tuple[int, int, float] = cost(choice)
        for _ in range(20):
            improved = False
            for i, opts in enumerate(options):
                for o in opts:
                    trial = [*choice[:i], o, *choice[i + 1 :]]
                    trial_cost = cost(trial)
                    if trial_cost < current:
                        choice, current, improved = trial, trial_cost, True
            if not improved:
                break
    final = cost(choice)
    return choice, (final[0], final[1])


def _exterior(cell: Cell, own: frozenset[Cell], lo: Sequence[int], hi: Sequence[int]) -> bool:
    """Every face neighbour is the part's own cell or outside the assembly's bounding box: no
    other part can reach this cell without passing through the part or leaving the puzzle."""
    for dx, dy, dz in NEIGHBOURS:
        n = (cell[0] + dx, cell[1] + dy, cell[2] + dz)
        inside = all(lo[a] <= n[a] <= hi[a] for a in range(3))
        if inside and n not in own:
            return False
    return True


# ---------------------------------------------------------------------------------------------
# Import
# ---------------------------------------------------------------------------------------------


def _planes(parts: Sequence[PartMesh]) -> list[Planes]:
    lo = np.min([p.bounds[0] for p in parts], axis=0)
    hi = np.max([p.bounds[1] for p in parts], axis=0)
    tolerance = 1e-4 * float((hi - lo).max())
    return [face_planes(p, tolerance) for p in parts]


def _check_share(source: str, parts: Sequence[PartMesh], planes: Sequence[Planes]) -> float:
    total = sum(p.total_area for p in planes)
    share = sum(p.aligned_area for p in planes) / total if total > 0 else 0.0
    worst = min(range(len(parts)), key=lambda i: planes[i].aligned_share)
    if share < MIN_ALIGNED_SHARE or planes[worst].aligned_share < MIN_ALIGNED_SHARE / 2:
        raise ModelImportError(
            source,
            "lattice",
            f"not a lattice model: only {share:.0%} of the surface area faces along x, y or z "
            f"(part {parts[worst].name}: {planes[worst].aligned_share:.0%}); at least "
            f"{MIN_ALIGNED_SHARE:.0%} is needed (curved parts or faces turned off the axes)",
        )
    return share


def _ambiguous_error(source: str, vox: PartVoxels, why: str) -> ModelImportError:
    shown = ", ".join(f"{list(c)} ({s:.0%} inside)" for c, s in vox.ambiguous[:4])
    more = f" and {len(vox.ambiguous) - 4} more" if len(vox.ambiguous) > 4 else ""
    return ModelImportError(
        source,
        f"parts.{vox.name}",
        f"{len(vox.ambiguous)} ambiguous cell(s) {why}: {shown}{more} "
        "(neither clearly full nor clearly empty, so the part is not lattice-shaped)",
    )


def import_model(model_dir: str | Path, kind: Kind | Literal["auto"] = "auto") -> ImportedModel:
    """Read a CHAIN puzzle folder and put every part on one cubic lattice (see module doc).

    ``kind='auto'``: a stacking model when one part is an open-top container, else a puzzle.
    Raises :class:`ModelImportError` (a :class:`~chaingeo.core.level.LevelError`) when it is not a
    lattice model, with the reason and the part concerned.
    """
    folder = Path(model_dir)
    source = str(folder)
    parts = load_model_parts(folder)
    planes = _planes(parts)
    share = _check_share(source, parts, planes)
    container: int | None = None
    if kind != "puzzle":
        container = find_container(parts)
        if kind == "stacking" and container is None:
            raise ModelImportError(source, "parts", "no part is an open-top container")
    pieces = [i for i in range(len(parts)) if i != container]
    if len(pieces) > len(PALETTE):
        raise ModelImportError(source, "parts", f"{len(pieces)} parts; at most {len(PALETTE)}")
    fit = fit_lattice(
        [parts[i] for i in pieces],
        [planes[i] for i in pieces],
        source,
        common=container is None,
    )
    voxels = [voxelize(parts[i], planes[i], fit, source) for i in pieces]
    for v in voxels:
        if len(v.cells) == 0:
            raise ModelImportError(source, f"parts.{v.name}", "no cell is inside the part")
    colors = assign_model_colors([parts[i].rgba for i in pieces])
    phases = [fit.phase[parts[i].name] for i in pieces]
    if container is not None:
        for v in voxels:
            if v.ambiguous:
                raise _ambiguous_error(source, v, "in a stacking piece")
        box, box_residual = container_cavity(parts[container], planes[container], fit.unit, source)
        total = sum(len(v.cells) for v in voxels)
        if total != box[0] * box[1] * box[2]:
            raise ModelImportError(
                source,
                "parts",
                f"the pieces have {total} cells; the {list(box)} box holds "
                f"{box[0] * box[1] * box[2]}",
            )
        out = tuple(
            ImportedPart(parts[i].name, c, v.cells.normalized(), (0.0, 0.0, 0.0))
            for i, c, v in zip(pieces, colors, voxels, strict=True)
        )
        return ImportedModel(
            folder.name, "stacking", fit, share, out, box, parts[container].name, box_residual
        )
    rods = [
        round_rods(parts[i], planes[i], fit, v.cells) for i, v in zip(pieces, voxels, strict=True)
    ]
    assembled = _assemble(source, parts, pieces, voxels, phases, colors, rods)
    return ImportedModel(folder.name, "puzzle", fit, share, assembled)


def _assemble(
    source: str,
    parts: Sequence[PartMesh],
    pieces: Sequence[int],
    voxels: Sequence[PartVoxels],
    phases: Sequence[tuple[float, float, float]],
    colors: Sequence[NamedColor],
    rods: Sequence[Mapping[Cell, int]],
) -> tuple[ImportedPart, ...]:
    """Snap the parts, settle partly filled cells on the outside, refuse anything else."""
    shifts, (overlap, _) = snap_parts([v.cells for v in voxels], phases)
    if overlap:
        raise ModelImportError(
            source, "parts", f"{overlap} cell(s) claimed by two parts whatever the snapping"
        )
    placed = [v.cells.translate(s) for v, s in zip(voxels, shifts, strict=True)]
    allc = np.concatenate([s.voxels for s in placed])
    lo, hi = allc.min(axis=0).tolist(), allc.max(axis=0).tolist()
    taken = {c for s in placed for c in s}
    result: list[ImportedPart] = []
    for i, v, s, ph, shape, color, rod in zip(
        pieces, voxels, shifts, phases, placed, colors, rods, strict=True
    ):
        shifted = [((c[0] + s[0], c[1] + s[1], c[2] + s[2]), f) for c, f in v.ambiguous]
        if any(not _exterior(c, shape.cell_set, lo, hi) for c, _ in shifted):
            raise _ambiguous_error(source, v, "inside the puzzle")
        keep = [c for c, f in shifted if f > 0.5 and c not in taken]
        if keep:
            shape = Shape([*shape.cells, *keep])
        if not shape.is_connected():
            raise ModelImportError(source, f"parts.{v.name}", "its cells are not face-connected")
        moved = tuple(round(sh - p, 6) for sh, p in zip(s, ph, strict=True))
        rod_cells = tuple(
            sorted(((c[0] + s[0], c[1] + s[1], c[2] + s[2]), a) for c, a in rod.items())
        )
        result.append(
            ImportedPart(
                parts[i].name, color, shape, (moved[0], moved[1], moved[2]), tuple(shifted),
                rod_cells,
            )
        )  # fmt: skip
    base = np.min(np.concatenate([p.shape.voxels for p in result]), axis=0)
    b = (int(base[0]), int(base[1]), int(base[2]))
    return tuple(
        ImportedPart(
            p.part,
            p.color,
            p.shape.translate(-base),
            p.moved,
            tuple(((c[0] - b[0], c[1] - b[1], c[2] - b[2]), f) for c, f in p.decided),
            tuple(((c[0] - b[0], c[1] - b[1], c[2] - b[2]), a) for c, a in p.rods),
        )
        for p in result
    )


# ---------------------------------------------------------------------------------------------
# Levels
# ---------------------------------------------------------------------------------------------


def source_stats(model: str) -> dict[str, str]:
    """Where the geometry comes from and under which licence (for ``stats.source``)."""
    return {
        "model": model,
        "repository": SOURCE_REPOSITORY,
        "path": f"{SOURCE_PATH}/{model}",
        "licence": LICENCE,
        "copyright": COPYRIGHT,
    }


def provenance_generator(model: str) -> str:
    """The provenance's generator text: the importer, the source model and its licence."""
    return f"{GENERATOR} from CHAIN model {model} ({LICENCE}, copyright {COPYRIGHT})"


def model_puzzle_level(
    model: ImportedModel,
    disassembly: Sequence[Move | TurnMove],
    *,
    goal: Literal["disassemble", "assemble"] = "disassemble",
    difficulty: Difficulty,
    max_group: int | None = None,
    turns: bool = False,
    stats: Mapping[str, Any] | None = None,
    level_id: str | None = None,
) -> Level:
    """A verified puzzle level from an imported model and an optimal disassembly plan found by
    the caller (o_i = its length); for 'assemble' the plan is reversed with each move inverted,
    as :func:`chaingeo.generator.puzzle.puzzle_level` does. With ``turns`` the rules allow turns and
    the pieces carry their round rods (a level without turns carries none: they change nothing
    there)."""
    if model.kind != "puzzle":
        raise ValueError(f"{model.model} is a {model.kind} model, not a puzzle")
    moves = list(disassembly) if goal == "disassemble" else [m.inverse() for m in disassembly[::-1]]
    shapes = [p.shape for p in model.parts]
    steps = len(moves)
    level = Level(
        id=level_id or f"chain-{model.model}" + ("-assemble" if goal == "assemble" else ""),
        family="puzzle",
        difficulty=difficulty,
        goal=goal,
        box=None,
        pieces=tuple(
            Piece(p.name, p.color.hex, p.shape, rods=dict(p.rods) if turns else {})
            for p in model.parts
        ),
        solution=PuzzleSolution(tuple(moves)),
        optimal_steps=steps,
        max_steps=max(default_step_budget(steps), 2 * steps),
        rules=PuzzleRules(max_group=max_group, turns=turns),
        provenance=Provenance(
            provenance_generator(model.model), VERSION, None, None, puzzle_signature(shapes)
        ),
        stats={"source": source_stats(model.model), "import": model.summary(), **(stats or {})},
    )
    return revalidate(level)


def model_stacking_level(
    model: ImportedModel,
    placements: Mapping[str, Shape],
    *,
    difficulty: Difficulty,
    rules: StackingRules = StackingRules(),
    stats: Mapping[str, Any] | None = None,
    level_id: str | None = None,
) -> Level:
    """A verified stacking level: the pieces as laid out in the model, the box the container's
    cavity, and a packing (piece name -> cells in the box) found by the caller."""
    if model.kind != "stacking" or model.box is None:
        raise ValueError(f"{model.model} is a {model.kind} model, not a stacking one")
    order = find_placing_order(placements, model.box, rules)
    lid = level_id or f"chain-{model.model}"
    if order is None:
        raise ModelImportError(f"<level {lid}>", "solution.order", f"no legal order under {rules}")
    n = len(model.parts)
    level = Level(
        id=lid,
        family="stacking",
        difficulty=difficulty,
        goal="pack",
        box=model.box,
        pieces=tuple(Piece(p.name, p.color.hex, p.shape) for p in model.parts),
        solution=StackingSolution(placements=dict(placements), order=tuple(order)),
        optimal_steps=n,
        max_steps=default_step_budget(n),
        rules=rules,
        provenance=Provenance(
            provenance_generator(model.model),
            VERSION,
            None,
            None,
            puzzle_signature(p.shape for p in model.parts),
        ),
        stats={"source": source_stats(model.model), "import": model.summary(), **(stats or {})},
    )
    return revalidate(level)
