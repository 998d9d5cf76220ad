"""The exact-cover search under a deadline: the kernels run in slices of a node budget and
resume exactly where they stopped (the same solutions in the same order, the same counters,
for any budget), and a search far too big stops at the time limit with a
:class:`SearchLimitError` naming ``seconds``, from Python, through the assemblers and from
``chain analyze``."""

from __future__ import annotations

import json
import math
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from chaingeo.cli.main import main
from chaingeo.core.formats.burrtools import (
    BTPart,
    BTProblem,
    BTPuzzle,
    colored_shape,
    write_xmpuzzle,
)
from chaingeo.core.geometry import Shape, box_cells
from chaingeo.core.kinematics import SearchLimitError
from chaingeo.core.piecesets import SOMA
from chaingeo.solvers.assembly import assemble
from chaingeo.solvers.assembly.btassemble import bt_packing_spec, iter_classes
from chaingeo.solvers.assembly.btcount import count_bt
from chaingeo.solvers.cover.constrained import compile_packing
from chaingeo.solvers.cover.packings import (
    CoverLimitError,
    CoverSearch,
    PieceSpec,
    count_packings,
    cover_problem,
    first_packing,
    iter_packings,
)
from chaingeo.solvers.cover.problem import CoverProblem
from chaingeo.solvers.deadline import Deadline
from chaingeo.solvers.limits import SearchLimits
from chaingeo.solvers.motion.disassemble import analyze_assembly
from tests.support.cover_instances import instances, wide_instances

KERNELS = ("dlx", "bitboard-first", "bitboard-mrv")
BUDGETS = (1, 7, 1000)
#: A generous bound on how long a search stopped by a tiny time limit may take (machines are
#: shared and noisy; the point is that it stops at all, where it would run for hours).
STOPS_WITHIN = 30.0

Run = tuple[list[bytes], tuple[int, int, int], bool]


def _run(
    problem: CoverProblem,
    engine: str,
    *,
    slice_nodes: int | None = None,
    node_limit: int | None = None,
    seed: int | None = None,
    batch: int = 5,
) -> Run:
    """Every batch of a search (as bytes), its counters (nodes, updates, solutions) and whether
    it stopped at its node limit; sliced under a far deadline when ``slice_nodes`` is given."""
    search = CoverSearch(
        problem,
        engine=engine,  # type: ignore[arg-type]
        rng=None if seed is None else np.random.default_rng(seed),
        node_limit=node_limit,
        deadline=None if slice_nodes is None else Deadline(3600.0),
        slice_nodes=slice_nodes,
    )
    blocks: list[bytes] = []
    limited = False
    try:
        blocks.extend(b.tobytes() for b in search.batches(batch))
    except CoverLimitError:
        limited = True
    s = search.stats
    return blocks, (s.nodes, s.updates, search.found), limited


def _kernels(problem: CoverProblem) -> list[str]:
    return [k for k in KERNELS if k != "bitboard-first" or problem.n_cells <= 64]


@settings(max_examples=60, deadline=None)
@given(instances(), st.sampled_from(BUDGETS), st.none() | st.integers(0, 2**31))
def test_slices_of_any_budget_give_the_same_solutions_in_the_same_order(
    inst: tuple[list[PieceSpec], tuple[int, int, int], Shape | None],
    budget: int,
    seed: int | None,
) -> None:
    specs, dims, optional = inst
    problem = cover_problem(specs, dims, optional=optional)
    if not problem.types:
        return
    for k in _kernels(problem):
        for limit in (None, 9):  # and a node limit falling inside a slice
            whole = _run(problem, k, node_limit=limit, seed=seed)
            assert _run(problem, k, slice_nodes=budget, node_limit=limit, seed=seed) == whole, k


@settings(max_examples=15, deadline=None)
@given(wide_instances(), st.sampled_from(BUDGETS))
def test_slices_on_multiword_masks(
    inst: tuple[list[PieceSpec], tuple[int, int, int]], budget: int
) -> None:
    specs, dims = inst
    problem = cover_problem(specs, dims)
    for k in ("dlx", "bitboard-mrv"):
        whole = _run(problem, k, node_limit=20_000)
        assert _run(problem, k, slice_nodes=budget, node_limit=20_000) == whole, k


def _rod(n: int) -> Shape:
    return Shape([(0, 0, z) for z in range(n)])


SOMA_CUBE = cover_problem(SOMA.pieces, (3, 3, 3))  # 11520 packings, ~300k nodes
RODS_70 = cover_problem(  # 63862 tilings of a line of 70 cells (two-word masks)
    [PieceSpec(_rod(3), "r3", 0, 30), PieceSpec(_rod(5), "r5", 0, 20)], (1, 1, 70)
)


@pytest.mark.parametrize("budget", BUDGETS)
@pytest.mark.parametrize("case", ["soma", "rods"])
def test_slices_on_whole_searches(case: str, budget: int) -> None:
    problem = SOMA_CUBE if case == "soma" else RODS_70
    # One node per call is slow in Python (~4 us a call): stop those at a node limit.
    limit = 20_000 if budget == 1 else None
    for k in _kernels(problem):
        whole = _run(problem, k, node_limit=limit, batch=4096)
        assert whole[1][2] > 100
        assert _run(problem, k, slice_nodes=budget, node_limit=limit, batch=4096) == whole, k


def test_the_adaptive_budget_changes_nothing() -> None:
    for k in _kernels(SOMA_CUBE):
        search = CoverSearch(SOMA_CUBE, engine=k, deadline=Deadline(3600.0))  # type: ignore[arg-type]
        assert search.count() == 11520
        plain = CoverSearch(SOMA_CUBE, engine=k)  # type: ignore[arg-type]
        assert plain.count() == 11520 and plain.stats.nodes == search.stats.nodes
        assert plain.stats.updates == search.stats.updates


class EveryThirdCheck(Deadline):
    """A deadline that has passed at every third look (resumption made deterministic)."""

    def __init__(self) -> None:
        super().__init__(1.0)
        self.looks = 0

    def expired(self) -> bool:
        self.looks += 1
        return self.looks % 3 == 0


@pytest.mark.parametrize("engine", KERNELS)
def test_a_search_resumes_after_its_deadline(engine: str) -> None:
    whole = _run(SOMA_CUBE, engine, batch=700)[0]
    search = CoverSearch(
        SOMA_CUBE,
        engine=engine,  # type: ignore[arg-type]
        deadline=EveryThirdCheck(),
        slice_nodes=5000,
    )
    got: list[bytes] = []
    stops = 0
    while not search.done:
        try:
            got.extend(b.tobytes() for b in search.batches(700))
        except SearchLimitError as e:
            assert "seconds" in str(e)
            stops += 1
    assert stops > 10
    rows = np.frombuffer(b"".join(got), dtype=np.int32)
    assert np.array_equal(rows, np.frombuffer(b"".join(whole), dtype=np.int32))


# -- far too big: the time limit stops it --------------------------------------------------------

#: 27 bricks 1x2x4 never fill a 6x6x6 box (de Bruijn: no side is a multiple of 4), and no
#: engine sees it coming: an endless search (216 cells, four-word masks).
BRICK = box_cells((1, 2, 4))
HOPELESS = (box_cells((6, 6, 6)), [PieceSpec(BRICK, "brick", 27, 27)])
#: Every way to fill a 4x4x4 cube with L-tetrominoes: far too many to count (64 cells, the
#: first-cell bit-board's size).
ELL = Shape([(0, 0, 0), (1, 0, 0), (2, 0, 0), (2, 1, 0)])
COUNTLESS = (box_cells((4, 4, 4)), [PieceSpec(ELL, "L", 0, 16)])


def _stops(fn: Callable[[], object], seconds: float) -> str:
    """Run ``fn`` (it must raise the time limit) and return the message."""
    t0 = time.monotonic()
    with pytest.raises(SearchLimitError) as info:
        fn()
    assert time.monotonic() - t0 < STOPS_WITHIN
    message = str(info.value)
    assert f"time limit of {seconds:g} s" in message and "seconds" in message
    return message


@pytest.mark.parametrize("engine", KERNELS)
def test_a_hopeless_search_stops_at_the_time_limit(engine: str) -> None:
    target, pieces = COUNTLESS if engine == "bitboard-first" else HOPELESS
    problem = cover_problem(pieces, target)
    search = CoverSearch(problem, engine=engine, deadline=Deadline(0.2))  # type: ignore[arg-type]
    message = _stops(search.count, 0.2)
    assert "exact-cover search" in message and search.stats.nodes > 0 and not search.done
    assert not search.limited  # the time limit, not a node limit


def test_every_entry_point_takes_the_deadline() -> None:
    target, pieces = HOPELESS
    _stops(lambda: count_packings(pieces, target, deadline=Deadline(0.1)), 0.1)
    _stops(lambda: list(iter_packings(pieces, target, deadline=Deadline(0.1))), 0.1)
    _stops(lambda: first_packing(pieces, target, deadline=Deadline(0.1)), 0.1)
    box, ells = COUNTLESS
    _stops(lambda: count_packings(ells, box, distinct=False, deadline=Deadline(0.1)), 0.1)
    # the assembler of our levels: enumeration and disassembly under limits.seconds
    _stops(lambda: assemble.count_assemblies(pieces, target, limits=SearchLimits(seconds=0.1)), 0.1)


def _bricks(tmp: Path) -> Path:
    puzzle = BTPuzzle(
        (colored_shape("brick", BRICK), colored_shape("box", box_cells((6, 6, 6)))),
        (BTProblem("27 bricks", (BTPart(0, 27, 27),), 1),),
        "no packing, and no quick proof of it",
    )
    return write_xmpuzzle(puzzle, tmp / "bricks.xmpuzzle")


def test_burrtools_assembler_stops(tmp_path: Path) -> None:
    from chaingeo.core.formats.burrtools import read_xmpuzzle

    packing = compile_packing(bt_packing_spec(read_xmpuzzle(_bricks(tmp_path)), 0))
    _stops(lambda: count_bt(packing, limits=SearchLimits(seconds=0.2)), 0.2)
    _stops(lambda: list(iter_classes(packing, deadline=Deadline(0.2))), 0.2)


def test_one_deadline_covers_the_disassembler_too() -> None:
    spent = Deadline(0.0)
    time.sleep(0.01)
    small = cover_problem(SOMA.pieces, (3, 3, 3))
    with pytest.raises(SearchLimitError, match="seconds"):
        CoverSearch(small, deadline=spent).count()  # nothing runs past a spent deadline
    with pytest.raises(SearchLimitError, match="seconds"):
        analyze_assembly({"a": Shape([(0, 0, 0)]), "b": Shape([(1, 0, 0)])}, deadline=spent)


def test_chain_analyze_stops_at_its_time_limit(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = _bricks(tmp_path)
    t0 = time.monotonic()
    assert main(["analyze", str(path), "--seconds", "0.5"]) == 1  # cut short, not failed
    assert time.monotonic() - t0 < STOPS_WITHIN
    captured = capsys.readouterr()
    out = json.loads(captured.out)
    assert out["counts_complete"] is False and out["assemblies"] == out["solutions"] == 0
    assert out["limit"].startswith("time limit of 0.5 s reached")
    assert out["limit"].endswith("raise it with --seconds")
    assert out["level"] is None  # nothing stored and nothing found: no assembly to take apart
    assert "counting stopped" in captured.err and "lower bounds" in captured.err


@pytest.mark.parametrize("seconds", ["0", "-1", "nan", "inf"])
def test_chain_analyze_refuses_a_meaningless_time_limit(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], seconds: str
) -> None:
    assert main(["analyze", str(_bricks(tmp_path)), "--seconds", seconds]) == 2
    assert "--seconds: expected a positive number of seconds" in capsys.readouterr().err


def test_a_deadline_needs_a_number() -> None:
    for bad in (-1.0, math.nan):
        with pytest.raises(ValueError, match="seconds"):
            Deadline(bad)
    assert not Deadline(None).bounded and not Deadline(None).expired()
