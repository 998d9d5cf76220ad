"""A proven lower bound on o_i from blocks of pieces, for single-piece moves (``max_group=1``).

Large puzzles such as towers of burr units have state spaces that are products of their units'
spaces; the plain branch and bound (bound: one removal per piece) cannot close them. When every
move carries one piece, the units' own optima add up:

**Claim.** Let the pieces of a puzzle ``P`` (``n`` pieces, assembled) be split into blocks
``B_1 .. B_k`` (any partition), and let ``f`` be the fewest moves of a full disassembly with
one piece per move. Then ``f(P) >= (n - 1) + sum_j (f(B_j) - (|B_j| - 1))``, where ``B_j`` is
the block's pieces alone, in their assembled positions.

**Proof.** Take any full disassembly of ``P`` with ``m`` moves. Every removal splits one part
in two, and the end has ``n`` parts, so exactly ``n - 1`` moves are removals. Restrict the plan
to a block ``B``, keeping restricted parts (subsets of ``B``): a move of piece ``p`` in
``B`` becomes the same move of ``p`` inside its restricted part, and is dropped when ``p`` is
alone there; moves of other blocks' pieces are dropped. Restricted parts always refine the
original parts intersected with ``B``, so a restricted move meets a subset of the obstacles the
original met and is legal (a removal stays a removal: ``p`` clears its part for good, so it
clears the restricted one; a non-removal may become one); the original parts end as single
pieces, so the restricted ones do: the restricted plan takes ``B`` apart and has at least
``f(B)`` moves, ``|B| - 1`` of them removals. Each restricted non-removal comes from a
non-removal of ``P`` moving a piece of ``B`` (the image of a removal is a removal or nothing).
So the non-removals of ``P`` that move pieces of ``B`` number at least ``f(B) - (|B| - 1)``;
each non-removal moves one piece, of one block; summing over blocks,
``m - (n - 1) >= sum_j (f(B_j) - (|B_j| - 1))``. QED.

With moves of several pieces the claim fails (one move can advance two blocks at once), so
:func:`block_lower_bound` refuses any other ``max_group``.

A plan that meets the bound is optimal. :func:`analyze_by_blocks` looks for one cheaply before
searching: the BurrTools-style plan, then, for a stack of blocks, *block after block* from the
ends: a block's own optimal plan played in the whole puzzle (checked move by move with the
reference kinematics), its last piece
then taken out in one move (:func:`end_first_plan`).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence

from chaingeo.core.geometry import Shape
from chaingeo.core.kinematics import Assembly, Move, MoveError, SearchLimitError
from chaingeo.solvers.deadline import Deadline
from chaingeo.solvers.limits import SearchLimits
from chaingeo.solvers.motion.disassemble import Analysis, analyze_assembly, translations


def block_lower_bound(
    shapes: Mapping[str, Shape],
    blocks: Sequence[Sequence[str]],
    *,
    max_group: int | None,
    limits: SearchLimits | None = None,
) -> int:
    """The claim's bound (module docstring) for a partition ``blocks`` of ``shapes``'s names.

    Raises ``ValueError`` when ``max_group`` is not 1, the blocks are not a partition, or a
    block cannot be taken apart on its own (then the whole cannot either).
    """
    if max_group != 1:
        raise ValueError(f"the block bound holds for single-piece moves only, got {max_group}")
    names = sorted(shapes)
    flat = sorted(n for b in blocks for n in b)
    if flat != names:
        raise ValueError("the blocks must split the pieces: every name in exactly one block")
    plans = _block_plans(shapes, blocks, limits)
    return len(names) - 1 + sum(len(p) - (len(b) - 1) for p, b in zip(plans, blocks, strict=True))


def _block_plans(
    shapes: Mapping[str, Shape],
    blocks: Sequence[Sequence[str]],
    limits: SearchLimits | None,
    deadline: Deadline | None = None,
) -> list[list[Move]]:
    """One optimal single-piece plan per block (the block alone, assembled)."""
    plans: list[list[Move]] = []
    for block in blocks:
        if len(block) < 2:
            plans.append([])
            continue
        part = {n: shapes[n] for n in block}
        result = analyze_assembly(part, max_group=1, limits=limits, optimal=True, deadline=deadline)
        if result.optimal_steps is None:
            raise ValueError(f"block {sorted(block)} cannot be taken apart on its own")
        plans.append(translations(result.plan))
    return plans


def _boxes_touch(state: Assembly, *names: str) -> bool:
    """Do the bounding boxes of ``names`` and the rest of their part touch or overlap on every
    axis? (Played backwards, the removal is an insertion, which the assemble game allows only
    then: :mod:`chaingeo.envs.machines.puzzle`.)"""
    mine = [c for n in names for c in state.cells_of(n)]
    others = sorted(state.part_of(names[0]) - set(names))
    rest = [c for n in others for c in state.cells_of(n)]
    for a in range(3):
        lo, hi = min(c[a] for c in mine), max(c[a] for c in mine)
        rlo, rhi = min(c[a] for c in rest), max(c[a] for c in rest)
        if lo > rhi + 1 or rlo > hi + 1:
            return False
    return True


def removals_touch(shapes: Mapping[str, Shape], plan: Sequence[Move]) -> bool:
    """Does every removal of ``plan`` take out a group whose bounding box touches the rest of
    its part (:func:`_boxes_touch`, for groups)?"""
    state = Assembly.assembled(shapes)
    for move in plan:
        if state.removes(move) and not _boxes_touch(state, *move.pieces):
            return False
        state = state.apply(move)
    return True


def end_first_plan(
    shapes: Mapping[str, Shape],
    blocks: Sequence[Sequence[str]],
    plans: Sequence[Sequence[Move]],
    axis: str = "z",
) -> list[Move] | None:
    """A plan for a *stack* of blocks along ``axis`` (block ``i + 1`` above block ``i``, each
    within its own layers) of length ``sum(len(plans)) + len(blocks) - 1``, or None.

    The block at the top of what is left goes first when its plan never moves along
    ``-axis``: its pieces stay at or above their own layers, so the blocks below never meet
    them, and its last piece then leaves along ``+axis``. Otherwise the block at the bottom
    when its plan never moves along ``+axis`` (mirrored). Every move is checked with the
    reference kinematics, and a last piece must touch the rest of its part when it leaves (so
    the plan played backwards stays within the assemble game's insertions).
    """
    state = Assembly.assembled(shapes)
    out: list[Move] = []
    lo, hi = 0, len(blocks) - 1
    while lo <= hi:
        if all(m.direction != f"-{axis}" for m in plans[hi]):
            i, up = hi, f"+{axis}"
        elif all(m.direction != f"+{axis}" for m in plans[lo]):
            i, up = lo, f"-{axis}"
        else:
            return None
        try:
            for move in plans[i]:
                state = state.apply(move)
                out.append(move)
            for name in sorted(blocks[i]):
                if len(state.part_of(name)) > 1:
                    if not _boxes_touch(state, name):
                        return None
                    move = Move((name,), up, None)
                    state = state.apply(move)
                    out.append(move)
        except MoveError:
            return None
        if i == hi:
            hi -= 1
        else:
            lo += 1
    return out if state.is_separated() else None


def analyze_by_blocks(
    shapes: Mapping[str, Shape],
    blocks: Sequence[Sequence[str]],
    *,
    limits: SearchLimits | None = None,
    stacked: bool = False,
    search: bool = True,
    deadline: Deadline | None = None,
) -> Analysis:
    """:func:`chaingeo.solvers.motion.disassemble.analyze_assembly` with single-piece moves and the
    block
    bound: a plan whose length meets the bound is optimal. Tried in turn: the BurrTools-style plan,
    (when ``stacked``: the blocks form a stack along z, see :func:`end_first_plan`) the stack taken
    apart from its ends, and (when ``search``) the exact search, which stops once it meets
    the bound; without it, :class:`SearchLimitError` when no quick plan meets the bound.
    ``deadline``: one for all of these searches (default: one of ``limits.seconds``)."""
    if deadline is None:
        deadline = Deadline((limits or SearchLimits()).seconds)
    plans = _block_plans(shapes, blocks, limits, deadline)
    names = sorted(shapes)
    if sorted(n for b in blocks for n in b) != names:
        raise ValueError("the blocks must split the pieces: every name in exactly one block")
    bound = len(names) - 1 + sum(len(p) - (len(b) - 1) for p, b in zip(plans, blocks, strict=True))
    quick = analyze_assembly(shapes, max_group=1, limits=limits, optimal=False, deadline=deadline)
    if not quick.disassemblable:
        return quick
    if quick.moves == bound and (not stacked or removals_touch(shapes, translations(quick.plan))):
        return dataclasses.replace(quick, optimal_steps=quick.moves)
    if stacked:
        plan = end_first_plan(shapes, blocks, plans)
        if plan is not None and len(plan) == bound and removals_touch(shapes, plan):
            return dataclasses.replace(quick, optimal_steps=bound, plan=tuple(plan))
    if not search:
        raise SearchLimitError(f"no quick plan meets the block bound {bound} (best {quick.moves})")
    return analyze_assembly(
        shapes, max_group=1, limits=limits, optimal=True, lower_bound=bound, deadline=deadline
    )
