"""Counting by arrangement (chaingeo.solvers.assembly.btcongruent) against the plain count of
every labelled assembly (count_bt), arrangement weights against brute-force orbits, and both
against burrTxt, on seeded random puzzles with congruent pieces listed as separate shapes on
symmetric results (tests/support/congruent.py)."""

from __future__ import annotations

import itertools
from pathlib import Path

import numpy as np
import pytest

from chaingeo.core.formats.bt_level import level_puzzle
from chaingeo.core.formats.bt_write import write_xmpuzzle
from chaingeo.core.formats.burrtools import BTPuzzle
from chaingeo.core.level import load_level
from chaingeo.generator.counts import COUNT_LIMITS, PROGRAM, has_counts
from chaingeo.solvers.analysis import level_packing
from chaingeo.solvers.assembly import btcongruent as bc
from chaingeo.solvers.assembly.btassemble import Mirrors, bt_packing_spec, iter_classes
from chaingeo.solvers.assembly.btcount import count_bt
from chaingeo.solvers.cover.constrained import canonical_keys, compile_packing
from chaingeo.solvers.motion.btproof import verdict_for_all_orders
from tests.support import burrtxt as bt
from tests.support.congruent import KINDS, congruent_puzzle, regrouped
from tests.support.paths import LEVELS

SEED = 38
#: The default run's cases: three or four of each kind under a second of CPU, among them
#: reflections that stabilise arrangements while swapping chiral pieces with their mirrors
#: (turned 3, mirrored 4 and 13); the slow run has the rest of the first 40 of each kind.
CASES = [
    *(("turned", i) for i in (2, 3, 10)),
    *(("mirrored", i) for i in (0, 1, 4, 13)),
    *(("bars", i) for i in (0, 2, 4)),
]
MORE = [(kind, i) for i in range(40) for kind in KINDS if (kind, i) not in CASES]


def _puzzle(kind: str, index: int) -> BTPuzzle:
    rng = np.random.default_rng(np.random.SeedSequence([SEED, KINDS.index(kind), index]))
    return congruent_puzzle(rng, kind)


def _plan(puzzle: BTPuzzle) -> bc.Plan:
    plan = bc.arrangement_plan(compile_packing(bt_packing_spec(puzzle, 0)))
    assert plan is not None
    return plan


def _brute_weights(plan: bc.Plan, mirrors: Mirrors) -> list[int]:
    """Per arrangement: the distinct classes (canonical keys) of all its labellings."""
    maps = plan.labelled.row_maps(mirrors == "drop")
    out = []
    for rows in iter_classes(plan.merged, mirrors=mirrors):
        each = [sorted(set(itertools.permutations(lab.tolist()))) for lab in bc.first_labels(plan)]
        labelled = np.stack(
            [
                bc.labelled_rows(plan, rows, [np.asarray(c, dtype=np.int64) for c in combo])
                for combo in itertools.product(*each)
            ]
        )
        out.append(len({k.tobytes() for k in canonical_keys(maps, labelled)}))
    return out


def _same_as_plain(kind: str, index: int) -> None:
    puzzle = _puzzle(kind, index)
    plan = _plan(puzzle)
    for mirrors in ("keep", "drop"):
        by = bc.count_by_arrangement(plan, mirrors=mirrors, prove=mirrors == "drop")
        assert by.all_proven == (mirrors == "drop"), mirrors  # the count step's convention
        got = by.report
        want = count_bt(plan.labelled, mirrors=mirrors)
        assert (got.assemblies, got.solutions) == (want.assemblies, want.solutions), mirrors
        maps = plan.merged.row_maps(mirrors == "drop")
        group = plan.merged.group(mirrors == "drop")
        proper = np.array([plan.merged.symmetries[g].proper for g in group])
        weights = [
            bc.arrangement_weight(plan, rows, maps, proper)
            for rows in iter_classes(plan.merged, mirrors=mirrors)
        ]
        assert weights == _brute_weights(plan, mirrors)


@pytest.mark.parametrize(("kind", "index"), CASES)
def test_by_arrangement_is_the_plain_count(kind: str, index: int) -> None:
    _same_as_plain(kind, index)


@pytest.mark.slow
@pytest.mark.parametrize(("kind", "index"), MORE)
def test_by_arrangement_is_the_plain_count_on_more(kind: str, index: int) -> None:
    _same_as_plain(kind, index)


def test_the_random_puzzles_have_symmetric_results_and_stabilisers() -> None:
    """The cases exercise what the weights are about: symmetric results, arrangements fixed by
    a symmetry, reflections pairing chiral pieces, and several arrangements."""
    seen = {"symmetric": 0, "stabilised": 0, "chiral pair": 0, "arrangements > 1": 0}
    for kind, index in CASES:
        plan = _plan(_puzzle(kind, index))
        maps = plan.merged.row_maps(True)
        classes = list(iter_classes(plan.merged, mirrors="drop"))
        seen["symmetric"] += len(maps) > 1
        seen["arrangements > 1"] += len(classes) > 1
        stabilisers = [_stabiliser(maps, rows) for rows in classes]
        seen["stabilised"] += any(len(g) > 1 for g in stabilisers)
        row_type = plan.merged.problem.row_type
        seen["chiral pair"] += any(
            np.any(row_type[maps[g, rows]] != row_type[rows])
            for rows, gs in zip(classes, stabilisers, strict=True)
            for g in gs
        )
    assert all(v >= 2 for v in seen.values()), seen


def _stabiliser(maps: np.ndarray, rows: np.ndarray) -> list[int]:
    return [
        g
        for g in range(len(maps))
        if np.all(maps[g, rows] >= 0) and np.array_equal(np.sort(maps[g, rows]), np.sort(rows))
    ]


def test_by_arrangement_gives_the_shipped_levels_plain_counts() -> None:
    """Shipped levels with congruent pieces apart, counted the plain way (every labelled
    assembly judged) when they were shipped: among them non-solutions (easy-01: 1 assembly, no
    solution; mid-01: 96 and 16) and 6!5!3! relabellings of one arrangement (mid-03)."""
    checked = []
    for path in sorted((LEVELS / "puzzle").glob("puzzle-*.json")):
        level = load_level(path)
        plan = bc.arrangement_plan(level_packing(level))
        if plan is None or not has_counts(level) or level.stats["counts"]["program"] != PROGRAM:
            continue
        got = bc.count_by_arrangement(plan, mirrors="drop", limits=COUNT_LIMITS).report
        assert (got.assemblies, got.solutions) == (
            level.stats["assemblies"],
            level.stats["solutions"],
        ), level.id
        checked.append(level.id)
    assert len(checked) >= 10 and "puzzle-mid-03-luban-15-piece" in checked


def test_a_verdict_that_depends_on_labels_is_refused(monkeypatch: pytest.MonkeyPatch) -> None:
    """Labellings of one arrangement judged differently raise, never count."""
    plan = _plan(_puzzle("bars", 0))
    monkeypatch.setattr(bc.ArrangementJudge, "_judge", lambda self, rows: bool(rows[0] % 2))
    with pytest.raises(bc.RelabellingError):
        bc.count_by_arrangement(plan, mirrors="drop")


@pytest.mark.parametrize(("kind", "index"), CASES)
def test_the_proof_is_every_labellings_verdict(kind: str, index: int) -> None:
    """Each arrangement's verdict for every labelling (btproof) is the judged verdict of
    every one of its labellings, all enumerated."""
    plan = _plan(_puzzle(kind, index))
    judge = bc.ArrangementJudge(plan.labelled, None, None, None)
    every = bc.relabelling_count(plan)
    for rows in iter_classes(plan.merged, mirrors="drop"):
        base = bc.labelled_rows(plan, rows, bc.first_labels(plan))
        proof = verdict_for_all_orders(judge.image(base))
        labellings = [base, *(bc.labelled_rows(plan, rows, lab)
                              for lab in bc.relabellings(plan, every, 0))]  # fmt: skip
        assert proof is not None and {judge(r) for r in labellings} == {proof}


def test_a_proof_that_disagrees_is_refused(monkeypatch: pytest.MonkeyPatch) -> None:
    """A proven verdict that is not the judged one raises, never counts."""
    plan = _plan(_puzzle("bars", 0))
    monkeypatch.setattr(bc, "verdict_for_all_orders", lambda *a: False)
    with pytest.raises(bc.RelabellingError, match="proven False"):
        bc.count_by_arrangement(plan, mirrors="drop")
    monkeypatch.setattr(bc, "verdict_for_all_orders", lambda *a: None)
    got = bc.count_by_arrangement(plan, mirrors="drop")
    assert got.proven == 0 and not got.all_proven and got.report.complete


def test_a_plan_only_where_congruent_parts_are_apart() -> None:
    puzzle = _puzzle("turned", 0)
    labelled = compile_packing(bt_packing_spec(puzzle, 0))
    assert bc.arrangement_plan(labelled) is not None
    assert bc.arrangement_plan(compile_packing(bt_packing_spec(puzzle, 0, merge_congruent=True)))\
        is None  # fmt: skip
    one = load_level(LEVELS / "puzzle" / "puzzle-easy-02-luban-6-piece.json")
    assert bc.arrangement_plan(level_packing(one)) is None  # no two pieces congruent


def test_relabellings_are_all_of_them_or_a_seeded_sample() -> None:
    plan = _plan(_puzzle("bars", 1))
    total = bc.relabelling_count(plan)
    every = [tuple(np.concatenate(lab).tolist()) for lab in bc.relabellings(plan, total, 0)]
    assert len(set(every)) == len(every) == total - 1
    a = [np.concatenate(lab).tolist() for lab in bc.relabellings(plan, 2, 5)]
    assert a == [np.concatenate(lab).tolist() for lab in bc.relabellings(plan, 2, 5)]


# -- burrTxt -----------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def binary() -> Path:
    return bt.burrtxt_or_skip()


def _agrees_with_burrtxt(binary: Path, kind: str, index: int, tmp_path: Path) -> None:
    puzzle = _puzzle(kind, index)
    path = write_xmpuzzle(puzzle, tmp_path / f"{kind}-{index}.xmpuzzle")
    ref = bt.run(binary, path, 60)
    if ref is None:
        pytest.skip("burrTxt takes more than 60 s")
    got = bc.count_by_arrangement(_plan(puzzle), mirrors="drop").report
    assert (got.assemblies, got.solutions) == (ref.assemblies, ref.solutions)


@pytest.mark.parametrize(("kind", "index"), CASES)
def test_by_arrangement_is_burrtxts_count(
    binary: Path, kind: str, index: int, tmp_path: Path
) -> None:
    _agrees_with_burrtxt(binary, kind, index, tmp_path)


@pytest.mark.slow
@pytest.mark.parametrize(("kind", "index"), MORE)
def test_by_arrangement_is_burrtxts_count_on_more(
    binary: Path, kind: str, index: int, tmp_path: Path
) -> None:
    _agrees_with_burrtxt(binary, kind, index, tmp_path)


#: hard-03 (11 congruent sticks and a key) with its sticks as fewer shapes used several times:
#: BurrTools then judges every relabelling class of the one arrangement itself.
HARD_03 = LEVELS / "puzzle" / "puzzle-hard-03-luban-separate-pieces.json"
REGROUPED = {(5, 6): (462, False), (3, 4, 4): (11550, True), (2, 3, 3, 3): (92400, True)}


def _regrouped_agrees(binary: Path, counts: tuple[int, ...], first: bool, tmp_path: Path) -> None:
    puzzle = regrouped(level_puzzle(load_level(HARD_03)), counts, first=first)
    path = write_xmpuzzle(puzzle, tmp_path / "hard-03-regrouped.xmpuzzle")
    ref = bt.run(binary, path, 600)
    assert ref is not None
    got = bc.count_by_arrangement(_plan(puzzle), mirrors="drop", limits=COUNT_LIMITS).report
    want = REGROUPED[counts][0]
    assert (got.assemblies, got.solutions) == (ref.assemblies, ref.solutions) == (want, want)


@pytest.mark.parametrize("first", [False, True])
def test_hard_03_regrouped_is_burrtxts_count(binary: Path, first: bool, tmp_path: Path) -> None:
    _regrouped_agrees(binary, (5, 6), first, tmp_path)


@pytest.mark.slow
@pytest.mark.parametrize("counts", [c for c, (_, slow) in REGROUPED.items() if slow])
def test_hard_03_regrouped_more_is_burrtxts_count(
    binary: Path, counts: tuple[int, ...], tmp_path: Path
) -> None:
    _regrouped_agrees(binary, counts, False, tmp_path)


def test_distinct_permutations_are_each_ordering_once() -> None:
    rng = np.random.default_rng(SEED)
    for _ in range(100):
        items = rng.integers(0, 3, size=int(rng.integers(0, 7))).tolist()
        got = list(bc._distinct_permutations(items))
        assert got == sorted(set(itertools.permutations(items)))


def test_hard_03_regrouped_as_burrtxt_printed_it() -> None:
    """burrTxt (built from ../shared/burrtools-src) on hard-03 with its sticks as shapes used
    1, 2, 2, 2, 2 and 2 times, the key last, printed 1,247,400 assemblies and as many solutions
    (about 650 s of its CPU): checked here without it."""
    puzzle = regrouped(level_puzzle(load_level(HARD_03)), (1, 2, 2, 2, 2, 2))
    got = bc.count_by_arrangement(_plan(puzzle), mirrors="drop", limits=COUNT_LIMITS).report
    assert (got.assemblies, got.solutions) == (1_247_400, 1_247_400)
