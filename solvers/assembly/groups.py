"""BurrTools' piece groups in the disassembler: pieces of one group need not come apart.

A BurrTools problem may put the pieces of a shape in groups (``group=`` on the problem's shape,
or ``(group, count)`` pairs). When a separation leaves a part, BurrTools accepts it without
taking it apart further when

1. every piece of the part belongs to exactly one group, the same one for all; or
2. it cannot be taken apart, but its pieces can be put in one group together: each piece's
   shape has that group, and over all parts accepted this way no shape is put in a group more
   often than its count there.

The whole puzzle is always searched (a first separation is needed). :class:`GroupedSolver` is
the plain disassembler (:mod:`chaingeo.solvers.motion.disassemble`) with that rule at its one hook
(``subpart``); rule 2's counts are shared by everything one analysis accepts, and a part
accepted on a branch that is later abandoned keeps its share (BurrTools never abandons one: it
stops at the first separation, the default here too). The optimal full disassembly (o_i) is not
searched with groups: its lower bounds assume every piece comes apart.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from chaingeo.core.geometry import Shape
from chaingeo.solvers.deadline import Deadline
from chaingeo.solvers.limits import SearchLimits
from chaingeo.solvers.motion.disassemble import Analysis, Separation, Separations, _Solver

#: A piece's groups: ``(group id, count)`` pairs of its shape (the count is the shape's).
GroupSpec = tuple[tuple[int, int], ...]


@dataclass(frozen=True)
class PieceGroups:
    """Per piece name: its shape's name (pieces of one shape share the counts) and groups."""

    shape_of: Mapping[str, str]
    groups_of: Mapping[str, GroupSpec]

    def any(self) -> bool:
        return any(self.groups_of.values())

    def single_group(self, names: Sequence[str]) -> int:
        """Rule 1: the one group every piece belongs to (and no other), else 0."""
        gid = 0
        for n in names:
            spec = self.groups_of.get(n, ())
            if len(spec) != 1 or (gid and spec[0][0] != gid):
                return 0
            gid = spec[0][0]
        return gid


def assignable(sets: Sequence[Sequence[str]], groups: PieceGroups) -> bool:
    """Rule 2 for all ``sets`` together: each set goes into one group that all its pieces'
    shapes have, and no shape is used in a group more often than its count there."""
    left: dict[tuple[str, int], int] = {}
    for name, spec in groups.groups_of.items():
        for gid, count in spec:
            left[(groups.shape_of[name], gid)] = count
    order = sorted(range(len(sets)), key=lambda i: -len(sets[i]))

    def place(k: int) -> bool:
        if k == len(order):
            return True
        names = sets[order[k]]
        options = set.intersection(*(set(g for g, _ in groups.groups_of.get(n, ())) for n in names))
        for gid in sorted(options):
            need: dict[tuple[str, int], int] = {}
            for n in names:
                key = (groups.shape_of[n], gid)
                need[key] = need.get(key, 0) + 1
            if all(left.get(key, 0) >= c for key, c in need.items()):
                for key, c in need.items():
                    left[key] -= c
                if place(k + 1):
                    return True
                for key, c in need.items():
                    left[key] += c
        return False

    return bool(sets) and all(sets) and place(0)


class GroupedSolver(_Solver):
    """The disassembler with BurrTools' group rule for the parts a separation leaves."""

    def __init__(
        self,
        shapes: Mapping[str, Shape],
        groups: PieceGroups,
        max_group: int | None,
        limits: SearchLimits,
        deadline: Deadline | None = None,
        separations: Separations = "first",
        order: Sequence[str] | None = None,
    ) -> None:
        super().__init__(
            shapes, max_group, limits, deadline=deadline, separations=separations, order=order
        )
        self.groups = groups
        self.grouped: list[list[str]] = []  # the parts accepted by rule 2

    def subpart(
        self, members: tuple[int, ...], offsets: np.ndarray
    ) -> tuple[bool, Separation | None]:
        if len(members) == 1:
            return True, None
        names = [self.table.names[m] for m in members]
        if self.groups.single_group(names):
            return True, None
        tree = self.part_tree(members, offsets)
        if tree is not None:
            return True, tree
        if assignable([*self.grouped, names], self.groups):
            self.grouped.append(names)
            return True, None
        return False, None


def analyze_grouped(
    shapes: Mapping[str, Shape],
    groups: PieceGroups,
    *,
    max_group: int | None = None,
    limits: SearchLimits | None = None,
    deadline: Deadline | None = None,
    separations: Separations = "first",
    order: Sequence[str] | None = None,
) -> Analysis:
    """Level and moves of an assembly under the group rule (``optimal_steps`` is None;
    ``deadline``, ``separations``, ``order``: as in
    :func:`chaingeo.solvers.motion.disassemble.analyze_assembly`)."""
    solver = GroupedSolver(
        shapes, groups, max_group, limits or SearchLimits(), deadline, separations, order
    )
    n = len(solver.table.names)
    if n == 1:
        return Analysis(True, "0", 0, None)
    tree = solver.part_tree(tuple(range(n)), np.zeros((n, 3), dtype=np.int64))
    if tree is None:
        return Analysis(False, None, None, None, states=solver.states)
    return Analysis(
        disassemblable=True,
        level=tree.level_text(),
        moves=tree.total_moves(),
        optimal_steps=None,
        plan=tuple(tree.all_moves()),
        tree=tree,
        states=solver.states,
        first_level=len(tree.moves),
    )
