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
stops at the first separation, the default here too).

*o_i with groups* (:func:`optimal_grouped`): the fewest moves to a state whose every part is one
piece or pieces all of one group (rule 1). The search's bound on the removals a part still needs
counts the part's *classes* (the pieces of one group together, every other piece alone): any
finished state has at least one part per class. Rule 2 accepts a part because it is stuck, which
a shortest plan does not aim at: where the analysis needs it, o_i is not searched.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from chaingeo.core.geometry import Shape
from chaingeo.core.kinematics import SearchLimitError
from chaingeo.solvers.deadline import Deadline
from chaingeo.solvers.limits import SearchLimits
from chaingeo.solvers.motion.disassemble import (
    Analysis,
    OptimalLimitError,
    Separation,
    Separations,
    _Solver,
)

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
        self.peel = False  # a piece of a group may stay: taking it out first is no longer exact
        self.grouped: list[list[str]] = []  # the parts accepted by rule 2

    def min_removals(self, members: tuple[int, ...]) -> int:
        """One part per class at the end (rule 1): the pieces of one group together, every
        other piece alone; so at least classes - 1 removals."""
        classes: set[int | str] = set()
        for m in members:
            name = self.table.names[m]
            spec = self.groups.groups_of.get(name, ())
            classes.add(spec[0][0] if len(spec) == 1 else name)
        return len(classes) - 1

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
    return Analysis.taken_apart(
        tree, tree.total_moves(), None, tree.all_moves(), solver.states, len(tree.moves)
    )


#: Why o_i is not given when the analysis accepts a stuck part by its group (rule 2).
RULE_TWO = "o_i is not searched where a stuck part is accepted by its group (BurrTools' rule 2)"


def optimal_grouped(
    shapes: Mapping[str, Shape],
    groups: PieceGroups,
    *,
    max_group: int | None = None,
    limits: SearchLimits | None = None,
    deadline: Deadline | None = None,
) -> Analysis:
    """o_i and an optimal plan under rule 1 (see the module's docstring), seeded by a
    disassembly over any separation; ``optimal_steps`` None when that disassembly needs rule 2.
    A cap reached raises :class:`chaingeo.solvers.motion.disassemble.OptimalLimitError` with the
    bounds proved."""
    solver = GroupedSolver(shapes, groups, max_group, limits or SearchLimits(), deadline, "any")
    n = len(solver.table.names)
    members = tuple(range(n))
    tree = solver.part_tree(members, np.zeros((n, 3), dtype=np.int64)) if n > 1 else None
    if tree is None or solver.grouped:
        done = n == 1 or solver.min_removals(members) == 0
        return Analysis(done or tree is not None, None, None, 0 if done else None)
    bound = tree.total_moves()
    steps, plan = bound, tree.all_moves()
    least = solver.min_removals(members)
    if bound > least:
        solver.bounds = [least, bound]
        try:
            found, better = solver.optimal(members, np.zeros((n, 3), dtype=np.int64), bound)
        except SearchLimitError as e:
            lo, hi = solver.bounds or (least, bound)
            raise OptimalLimitError(e, lo, hi) from None
        if better is not None:
            steps, plan = found, better
    return Analysis.taken_apart(tree, bound, steps, plan, solver.states)
