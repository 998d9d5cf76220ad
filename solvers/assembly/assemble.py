"""The assembler: every assembly of a piece multiset into a target shape, then the disassembler
decides which of them can actually be taken apart ('assemblies' and 'solutions' as BurrTools
counts them).

Assemblies come from the exact-cover engine (:mod:`chaingeo.solvers.cover.packings`) with every
rotation of every piece, one per class of the target's rotations (symmetric duplicates removed;
mirror images are kept apart, BurrTools' default). A *solution* is an assembly the disassembler can
take apart completely under the reference kinematics. :func:`count_assemblies` runs the enumeration
and every disassembly under one :class:`chaingeo.solvers.deadline.Deadline` (``limits.seconds``).
"""

from __future__ import annotations

import time
from collections.abc import Iterator, Sequence
from dataclasses import dataclass

from chaingeo.core.geometry import Shape
from chaingeo.solvers.cover.packings import iter_packings
from chaingeo.solvers.cover.problem import PieceSpec
from chaingeo.solvers.deadline import Deadline
from chaingeo.solvers.limits import SearchLimits
from chaingeo.solvers.motion.disassemble import Analysis, analyze_assembly


@dataclass(frozen=True)
class AssemblyReport:
    assemblies: int
    solutions: int
    first_packing: dict[str, Shape] | None
    seconds: float
    solution_list: tuple[dict[str, Shape], ...] = ()


def iter_assemblies(
    pieces: Sequence[PieceSpec],
    target: Shape,
    *,
    optional: Shape | None = None,
    mirror_distinct: bool = True,
    node_limit: int | None = None,
    deadline: Deadline | None = None,
) -> Iterator[dict[str, Shape]]:
    """Every assembly, one per symmetry class of the target (rotations; reflections too when
    ``mirror_distinct`` is False), as ``{piece name: placed voxels}``. Copies of one piece are
    named ``name``, ``name_2``, ... in placement order. Past ``deadline`` the enumeration
    stops with its ``SearchLimitError``."""
    solutions = iter_packings(
        list(pieces),
        target,
        distinct=True,
        reflections=not mirror_distinct,
        optional=optional,
        node_limit=node_limit,
        deadline=deadline,
    )
    base_of = {p.name: p.name for p in pieces}
    for sol in solutions:
        out: dict[str, Shape] = {}
        counts: dict[str, int] = {}
        for slot, placed in sol.placements:
            base = base_of.get(slot, slot.split("#")[0])
            counts[base] = counts.get(base, 0) + 1
            name = base if counts[base] == 1 else f"{base}_{counts[base]}"
            out[name] = placed
        yield out


def count_assemblies(
    pieces: Sequence[PieceSpec],
    target: Shape,
    *,
    optional: Shape | None = None,
    mirror_distinct: bool = True,
    max_group: int | None = None,
    limits: SearchLimits | None = None,
    keep: int = 0,
    deadline: Deadline | None = None,
) -> AssemblyReport:
    """Count assemblies and those that come apart; keep the first ``keep`` solutions. The
    enumeration and every disassembly share ``deadline`` (default: one of ``limits.seconds``;
    without ``limits`` the enumeration has no time limit and each disassembly the default
    one)."""
    start = time.perf_counter()
    if deadline is None and limits is not None:
        deadline = Deadline(limits.seconds)
    n_asm = 0
    n_sol = 0
    first: dict[str, Shape] | None = None
    kept: list[dict[str, Shape]] = []
    assemblies = iter_assemblies(
        pieces, target, optional=optional, mirror_distinct=mirror_distinct, deadline=deadline
    )
    for asm in assemblies:
        n_asm += 1
        result: Analysis = analyze_assembly(
            asm, max_group=max_group, limits=limits, optimal=False, deadline=deadline
        )
        if result.disassemblable:
            n_sol += 1
            if first is None:
                first = asm
            if len(kept) < keep:
                kept.append(asm)
    return AssemblyReport(n_asm, n_sol, first, time.perf_counter() - start, tuple(kept))


def solid_burr_codes() -> tuple[int, ...]:
    """Recompute the burr catalogue: the codes of the notchable pieces used by any assembly
    of the whole notchable family (each 0..6 times) into the Solid Knot."""
    from chaingeo.core.piecesets.burrs import notchable_family, solid_knot

    family = notchable_family()
    code_of = {s.canonical(): c for c, s in family.items()}
    pieces = [PieceSpec(s, f"b{c:04x}", 0, 6) for c, s in family.items()]
    used: set[int] = set()
    for asm in iter_assemblies(pieces, solid_knot()):
        used.update(code_of[s.canonical()] for s in asm.values())
    return tuple(sorted(used))
