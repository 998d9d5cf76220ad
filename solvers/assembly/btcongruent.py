"""BurrTools' counts when congruent pieces are separate shapes: one verdict an arrangement,
times the labelled classes over it.

BurrTools places each shape of a problem as its own piece (:func:`bt_packing_spec`,
``merge_congruent`` off), so 11 identical sticks listed as 11 shapes make 11! assemblies of one
arrangement. Here the merged packing (congruent parts one type) is enumerated instead, one
arrangement per class, and each stands for the labelled classes over it.

*Assemblies, exactly.* Let F be the group whose classes are counted (the result's rotations;
with ``mirrors="drop"`` its reflections too, a reflection taking each piece type ``t`` to its
paired mirror type ``mu(t)``, :attr:`Packing.mirror_type`). A labelled assembly is an
arrangement A with a labelling ``lab`` of its placements (type ``t`` gets ``c_t`` of its merged
type's placements; the rows of a labelled type are its merged type's rows, same order). F acts
on both and the forgetful map commutes with it, so the labelled classes over the class of A are
the orbits of A's stabiliser F_A on A's labellings; by Burnside their number is the mean over
``g`` in F_A of the labellings with ``lab(g p) = mu_g(lab(p))``: on a merged type ``g`` maps to
itself, ``lab`` is constant on ``g``'s cycles (``mu_g`` is the identity there: rotations, and
achiral pieces are their own mirror); on a chiral type swapped with its mirror, ``lab`` is free
on the cycles of ``g^2`` and determines the mirror's (:func:`fixed_labellings`).

*Solutions, checked.* BurrTools' disassembler stops at the first separation in piece order
(:mod:`chaingeo.solvers.motion.btsearch`), so a verdict may in principle depend on which
congruent piece sits where, and on which of an F-class's rotation classes is judged. Each
arrangement is judged on its first labelling, on its mirror image when that is in its class, and
on ``checks`` seeded random relabellings (every one when there are no more); judgements are
cached by labelled rows, and any disagreement raises :class:`RelabellingError`, never a count.
Unless ``max_group`` is set, the verdict is also proven for every labelling and turn at once
(:func:`chaingeo.solvers.motion.btproof.verdict_for_all_orders`, by geometry alone); it must
agree, and the report says how many arrangements it decided (the sample stays, a cross-check).
"""

from __future__ import annotations

import dataclasses
import itertools
import math
import time
from collections.abc import Iterator
from dataclasses import dataclass
from functools import cache

import numpy as np

from chaingeo.core.arrays import I32, I64
from chaingeo.core.errors import ChainGeoError
from chaingeo.core.geometry import Shape
from chaingeo.core.kinematics import SearchLimitError
from chaingeo.solvers.assembly import btassemble as bta
from chaingeo.solvers.assembly.btcount import BTReport, RowVerdicts, StuckCheck
from chaingeo.solvers.cover.constrained import Packing, compile_packing
from chaingeo.solvers.deadline import Deadline
from chaingeo.solvers.limits import SearchLimits
from chaingeo.solvers.motion.btproof import Memo, Verdict, verdict_for_all_orders

#: Relabellings judged an arrangement besides its first (all of them when there are fewer).
CHECKS = 64


class RelabellingError(ChainGeoError, ValueError):
    """Two labellings of one arrangement got different verdicts: count it the plain way."""


@dataclass(frozen=True)
class Plan:
    """How a labelled packing's types sit in its merged packing."""

    labelled: Packing
    merged: Packing
    members: tuple[tuple[int, ...], ...]  # per merged type: its labelled types, in order
    copies: tuple[tuple[int, ...], ...]  # per merged type: each member's count


@dataclass(frozen=True)
class ArrangementReport:
    """The counts (:class:`BTReport`) and what they took: arrangements met, labellings judged,
    arrangements whose verdict is proven for every labelling."""

    report: BTReport
    arrangements: int
    judged: int
    proven: int = 0

    @property
    def all_proven(self) -> bool:
        """Every arrangement's verdict holds for every labelling (not just the sampled)."""
        return self.report.complete and self.proven == self.arrangements


def arrangement_plan(labelled: Packing) -> Plan | None:
    """The plan, or None where counting by arrangement does not apply: no congruent parts
    apart, a part whose count may vary, piece groups, holes, or mirror pairs the merged
    packing does not mirror type for type."""
    spec = labelled.spec
    if spec.merge_congruent or any(p.lo != p.hi or p.groups for p in spec.parts):
        return None
    merged = compile_packing(dataclasses.replace(spec, merge_congruent=True))
    if labelled.hole_type >= 0 or merged.hole_type >= 0:
        return None
    if all(len(info.parts) == 1 for info in merged.types):
        return None
    index = {info.parts[0]: t for t, info in enumerate(labelled.types)}
    members = tuple(tuple(index[name] for name in info.parts) for info in merged.types)
    copies = tuple(tuple(labelled.types[t].lo for t in ts) for ts in members)
    for m, ts in enumerate(members):
        for t in ts:
            same = np.array_equal(labelled.codes[t], merged.codes[m])
            if not same:
                raise AssertionError("a labelled type's rows differ from its merged type's")
        if not _pairs_mirror(labelled, merged, members, m):
            return None
    return Plan(labelled, merged, members, copies)


def _pairs_mirror(labelled: Packing, merged: Packing, members: tuple[tuple[int, ...], ...],
                  m: int) -> bool:  # fmt: skip
    """Whether the labelled mirror pairing of merged type ``m``'s members is a bijection onto
    its merged mirror's members with the same counts (or absent on both sides)."""
    mm = merged.mirror_type[m]
    mine = [labelled.mirror_type[t] for t in members[m]]
    if mm < 0:
        return all(t < 0 for t in mine)
    if mm == m:
        return mine == list(members[m])
    theirs = members[mm]
    return sorted(mine) == sorted(theirs) and all(
        labelled.types[t].lo == labelled.types[u].lo for t, u in zip(members[m], mine, strict=True)
    )


@cache
def _ways(cycles: tuple[int, ...], caps: tuple[int, ...]) -> int:
    """Assignments of the cycles (lengths) to types taking exactly ``caps`` placements each."""
    if not cycles:
        return int(not any(caps))
    n, rest = cycles[0], cycles[1:]
    return sum(
        _ways(rest, (*caps[:j], c - n, *caps[j + 1 :])) for j, c in enumerate(caps) if c >= n
    )


def _cycles(perm: I64) -> tuple[int, ...]:
    """Cycle lengths of a permutation of ``range(len(perm))``, sorted."""
    seen = np.zeros(len(perm), dtype=bool)
    out = []
    for s in range(len(perm)):
        n = 0
        while not seen[s]:
            seen[s] = True
            s = int(perm[s])
            n += 1
        if n:
            out.append(n)
    return tuple(sorted(out))


def fixed_labellings(plan: Plan, perm: I64, of_type: I64, proper: bool) -> int:
    """Labellings ``lab`` of an arrangement with ``lab(g p) = mu_g(lab(p))``, for the symmetry
    ``g`` acting on its placements as ``perm`` (``of_type``: each placement's merged type)."""
    total = 1
    for m, caps in enumerate(plan.copies):
        mm = plan.merged.mirror_type[m]
        at = np.flatnonzero(of_type == m)
        if proper or mm == m:
            sub = perm
        elif mm < m:
            continue  # counted with its mirror
        else:
            sub = perm[perm]  # g^2 on type m; the mirror's labels follow
        local = np.full(len(perm), -1, dtype=np.int64)
        local[at] = np.arange(len(at))
        total *= _ways(_cycles(local[sub[at]]), caps)
        if total == 0:
            return 0
    return total


def arrangement_weight(plan: Plan, rows: I32, maps: I32, proper: np.ndarray) -> int:
    """The labelled classes over an arrangement's class (its merged ``rows``): Burnside over
    its stabiliser in the group of ``maps``."""
    rows = np.sort(rows)
    of_type = plan.merged.problem.row_type[rows].astype(np.int64)
    fixed, size = 0, 0
    for g in range(len(maps)):
        img = maps[g, rows]
        if np.any(img < 0) or not np.array_equal(np.sort(img), rows):
            continue
        size += 1
        perm = np.searchsorted(rows, img).astype(np.int64)
        fixed += fixed_labellings(plan, perm, of_type, bool(proper[g]))
    weight, rest = divmod(fixed, size)
    if rest:
        raise AssertionError("Burnside's sum is not a multiple of the stabiliser's order")
    return weight


def labelled_rows(plan: Plan, rows: I32, labels: list[I64]) -> I32:
    """The labelled assembly giving merged type ``m``'s placements (in row order) the labelled
    types ``labels[m]``; sorted (BurrTools' piece order)."""
    rows = np.sort(rows)
    mtype = plan.merged.problem.row_type[rows]
    out = np.empty(len(rows), dtype=np.int64)
    for m, lab in enumerate(labels):
        at = np.flatnonzero(mtype == m)
        local = rows[at] - int(plan.merged.problem.row_start[m])
        out[at] = plan.labelled.problem.row_start[lab] + local
    return np.sort(out).astype(np.int32)


def first_labels(plan: Plan) -> list[I64]:
    """Each merged type's placements to its members in order, ``c_t`` each."""
    return [np.repeat(np.asarray(ts, dtype=np.int64), cs) for ts, cs in zip(plan.members,
            plan.copies, strict=True)]  # fmt: skip


def relabellings(plan: Plan, checks: int, seed: int) -> Iterator[list[I64]]:
    """Every other labelling when there are at most ``checks`` of them, else ``checks``
    seeded random ones."""
    first = first_labels(plan)
    if relabelling_count(plan) - 1 <= checks:
        each = [list(_distinct_permutations(lab.tolist())) for lab in first]
        for combo in itertools.islice(itertools.product(*each), 1, None):
            yield [np.asarray(c, dtype=np.int64) for c in combo]
        return
    rng = np.random.default_rng(seed)
    for _ in range(checks):
        yield [rng.permutation(lab) for lab in first]


def _distinct_permutations(items: list[int]) -> Iterator[tuple[int, ...]]:
    """Every distinct ordering of ``items``, in lexicographic order from the sorted one (the
    next permutation, so repeated items cost nothing)."""
    a = sorted(items)
    while True:
        yield tuple(a)
        i = len(a) - 2
        while i >= 0 and a[i] >= a[i + 1]:
            i -= 1
        if i < 0:
            return
        j = len(a) - 1
        while a[j] <= a[i]:
            j -= 1
        a[i], a[j] = a[j], a[i]
        a[i + 1 :] = reversed(a[i + 1 :])


def relabelling_count(plan: Plan) -> int:
    """The labellings of one arrangement (relabellings of its congruent pieces)."""
    return math.prod(_multinomial(cs) for cs in plan.copies)


def _multinomial(counts: tuple[int, ...]) -> int:
    return math.factorial(sum(counts)) // math.prod(math.factorial(c) for c in counts)


class ArrangementJudge:
    """BurrTools' verdict on a labelled assembly (sorted rows), as :func:`count_bt` gives it:
    nothing moves, the row kernel, else the general path; cached by rows."""

    def __init__(self, packing: Packing, max_group: int | None, limits: SearchLimits | None,
                 deadline: Deadline | None) -> None:  # fmt: skip
        self.packing = packing
        self.max_group = max_group
        self.limits = limits
        self.deadline = deadline
        self.stuck = StuckCheck(packing)
        self.on_rows = RowVerdicts(packing, limits, False)
        self.frame = bta.BTFrame(packing)
        self.cache: dict[bytes, bool] = {}
        self.proofs: Memo = {}  # parts' verdicts for every labelling, by geometry

    def __call__(self, rows: I32) -> bool:
        key = rows.tobytes()
        hit = self.cache.get(key)
        if hit is None:
            if self.deadline is not None:
                self.deadline.check()
            hit = self.cache[key] = self._judge(rows)
        return hit

    def _judge(self, rows: I32) -> bool:
        if self.stuck(rows):
            return False
        fast = self.on_rows.verdict(rows)
        if fast is not None:
            return fast
        asm = bta.named_assembly(self.packing, rows)
        if len(asm) < 2:
            return False  # BurrTools: one piece is no disassembly (disassembler_a.cpp)
        return bta.disassemble(
            self.packing, self.frame(asm), max_group=self.max_group, limits=self.limits,
            deadline=self.deadline,
        ).disassemblable  # fmt: skip

    def image(self, rows: I32) -> dict[str, Shape]:
        return self.frame(bta.named_assembly(self.packing, rows))


def count_by_arrangement(
    plan: Plan,
    *,
    mirrors: bta.Mirrors = "keep",
    max_group: int | None = None,
    limits: SearchLimits | None = None,
    deadline: Deadline | None = None,
    checks: int = CHECKS,
    seed: int = 0,
    prove: bool = True,
) -> ArrangementReport:
    """BurrTools' assemblies and solutions of ``plan.labelled`` (as :func:`count_bt` counts
    them) from the merged packing's arrangements (see the module's docstring); ``prove``: each
    verdict also proven for every labelling (unless ``max_group``). A cap reached ends the
    count: the report then holds lower bounds and the error."""
    start = time.perf_counter()
    drop = mirrors == "drop"
    maps = plan.merged.row_maps(drop)
    syms = [plan.merged.symmetries[g] for g in plan.merged.group(drop)]
    proper = np.array([s.proper for s in syms])
    flips = np.flatnonzero(~proper)
    full = plan.labelled.row_maps(drop)
    judge = ArrangementJudge(plan.labelled, max_group, limits, deadline)
    assemblies = solutions = arrangements = proven = 0
    first: dict[str, Shape] | None = None
    limit: SearchLimitError | None = None
    try:
        for rows in bta.iter_classes(plan.merged, mirrors=mirrors, deadline=deadline):
            arrangements += 1
            weight = arrangement_weight(plan, rows, maps, proper)
            verdict = _verdict(plan, rows, judge, full, flips, checks, seed)
            if prove and max_group is None:
                proven += _proven(plan, rows, judge, verdict) is not None
            assemblies += weight
            if verdict:
                solutions += weight
                if first is None:
                    first = judge.image(labelled_rows(plan, rows, first_labels(plan)))
    except SearchLimitError as e:
        limit = e
    anchor = bta.choose_anchor(plan.merged) if plan.merged.n_rows else None
    label = None if anchor is None else anchor.label
    seconds = time.perf_counter() - start
    rep = BTReport(assemblies, solutions, first, None, seconds, label, limit)
    return ArrangementReport(rep, arrangements, len(judge.cache), proven)


def _proven(plan: Plan, rows: I32, judge: ArrangementJudge, verdict: bool) -> Verdict:
    """The arrangement's verdict for every labelling (None: not decided within the caps);
    :class:`RelabellingError` when it is not the judged one."""
    image = judge.image(labelled_rows(plan, rows, first_labels(plan)))
    try:
        proof = verdict_for_all_orders(image, judge.limits, judge.deadline, judge.proofs)
    except SearchLimitError as e:
        if e.cap == "seconds":
            raise
        return None
    if proof is not None and proof != verdict:
        raise RelabellingError(
            f"arrangement {rows.tolist()}: judged {verdict}, proven {proof} for every labelling"
        )
    return proof


def _verdict(plan: Plan, rows: I32, judge: ArrangementJudge, full: I32, flips: I64, checks: int,
             seed: int) -> bool:  # fmt: skip
    """One arrangement's verdict: its first labelling's, checked against its mirror image's
    and its relabellings' (:class:`RelabellingError` when they differ)."""
    base = labelled_rows(plan, rows, first_labels(plan))
    verdict = judge(base)
    others = [labelled_rows(plan, rows, lab) for lab in relabellings(plan, checks, seed)]
    if len(flips):
        mirror = full[int(flips[0]), base]
        if np.all(mirror >= 0):
            others.append(np.sort(mirror).astype(np.int32))
    for other in others:
        if judge(other) != verdict:
            raise RelabellingError(
                f"arrangement {rows.tolist()}: labellings {base.tolist()} and {other.tolist()} "
                "get different verdicts"
            )
    return verdict
