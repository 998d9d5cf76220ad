"""Differential tests against BurrTools' own solver: the same ``.xmpuzzle`` through ``burrTxt -d
-r`` and through our analysis (mirror images dropped, as burrTxt does) must give the same
assemblies, solutions and multiset of level strings (burrTxt prints one ``level:`` per
solution; the orders of the two assemblers differ, so the levels are compared sorted).

Cases: (a) seeded random boxes cut into pieces (holes, a non-box result, congruent bars), (b)
every shipped puzzle level written as BurrTools would get it (``assembled_puzzle``; levels that
turn are skipped: burrTxt has no turns), (c) items of every puzzle generator shape, (d) the
feature files and BurrTools' example files. A case burrTxt does not finish within its time is
skipped and counted; the counts are printed at the end of the session (tests/conftest.py).
The larger sweeps are ``-m slow``. burrTxt is built from ``../shared/burrtools-src`` with g++
(:mod:`tests.support.burrtxt`); without either the module skips and says why.
"""

from __future__ import annotations

import json
import os
import time
from pathlib import Path

import numpy as np
import pytest

from chaingeo.core.formats.bt_write import assembled_puzzle, write_xmpuzzle
from chaingeo.core.formats.burrtools import BurrToolsError, read_xmpuzzle
from chaingeo.core.kinematics import SearchLimitError
from chaingeo.core.level import Level, load_level
from chaingeo.core.rules import PuzzleRules
from chaingeo.solvers.assembly.btassemble import bt_packing_spec
from chaingeo.solvers.assembly.btcount import count_bt
from chaingeo.solvers.cover.constrained import compile_packing
from chaingeo.solvers.limits import SearchLimits
from tests.support import burrtxt as bt
from tests.support.paths import ROOT
from tests.support.shared_files import BT

LEVELS = sorted((ROOT / "levels" / "puzzle").glob("*.json"))
FEATURES = sorted((ROOT / "tests" / "data" / "burrtools").glob("*.xmpuzzle"))
SHARED = sorted(BT.glob("*.xmpuzzle")) if BT is not None else []
#: More of BurrTools' example files, where ``$CHAIN_BURRTOOLS_EXAMPLES`` names a folder of them
#: (test data only, never in the project; e.g. BurrTools' ``examples/``).
_MORE = Path(os.environ.get("CHAIN_BURRTOOLS_EXAMPLES", "/nonexistent"))
SHARED += sorted(
    p
    for p in (_MORE.glob("*.xmpuzzle") if _MORE.is_dir() else [])
    if p.name not in {q.name for q in SHARED}
)
SEED = 20


@pytest.fixture(scope="module")
def binary() -> Path:
    return bt.burrtxt_or_skip()


def compare(
    binary: Path, group: str, case: str, path: Path, seconds: float, problem: int = 0
) -> None:
    """Run both on problem ``problem`` of ``path``; skip (counted) when burrTxt needs more
    than ``seconds``; fail on any difference. Our analysis gets ten times burrTxt's time."""
    start = time.perf_counter()
    ref = bt.run(binary, path, seconds, problem)
    took = time.perf_counter() - start
    if ref is None:
        bt.OUTCOMES.append(bt.Outcome(group, case, "skip", f"burrTxt over {seconds:g} s"))
        pytest.skip(f"burrTxt takes more than {seconds} s")
    levels: list[str] = []
    try:
        packing = compile_packing(bt_packing_spec(read_xmpuzzle(path), problem))
        limits = SearchLimits(seconds=10 * took + 10)
        report = count_bt(packing, mirrors="drop", limits=limits, levels=levels)
        ours = (report.assemblies, report.solutions, sorted(levels))
    except SearchLimitError as e:
        ours = (-1, -1, [f"ours: {e}"])
    theirs = (ref.assemblies, ref.solutions, sorted(ref.levels))
    if ours == theirs:
        bt.OUTCOMES.append(bt.Outcome(group, case, "agree"))
    else:
        why = f"burrTxt {theirs[:2]} {theirs[2][:8]}, ours {ours[:2]} {ours[2][:8]}"
        bt.OUTCOMES.append(bt.Outcome(group, case, "disagree", why))
    assert ours == theirs


# -- (a) random puzzles ---------------------------------------------------------------------


def _random_case(binary: Path, index: int, tmp_path: Path) -> None:
    rng = np.random.default_rng(np.random.SeedSequence([SEED, index]))
    path = write_xmpuzzle(bt.random_puzzle(rng), tmp_path / f"random-{index}.xmpuzzle")
    compare(binary, "random", f"SeedSequence([{SEED}, {index}])", path, 20)


@pytest.mark.parametrize("index", range(20))
def test_random_puzzles_agree(binary: Path, index: int, tmp_path: Path) -> None:
    _random_case(binary, index, tmp_path)


@pytest.mark.slow
@pytest.mark.parametrize("index", range(20, 300))
def test_more_random_puzzles_agree(binary: Path, index: int, tmp_path: Path) -> None:
    _random_case(binary, index, tmp_path)


# -- (b) shipped levels ----------------------------------------------------------------------


def _level_case(binary: Path, path: Path, seconds: float, tmp_path: Path) -> None:
    level = load_level(path)
    if isinstance(level.rules, PuzzleRules) and level.rules.turns:
        bt.OUTCOMES.append(bt.Outcome("level", level.id, "skip", "turns (burrTxt has none)"))
        pytest.skip("a level that turns: burrTxt has no turns")
    file = write_xmpuzzle(assembled_puzzle(level.shapes), tmp_path / f"{level.id}.xmpuzzle")
    compare(binary, "level", level.id, file, seconds)


@pytest.mark.parametrize("path", LEVELS, ids=[p.stem for p in LEVELS])
def test_shipped_levels_agree(binary: Path, path: Path, tmp_path: Path) -> None:
    """Levels burrTxt finishes in 1 s (the rest: -m slow)."""
    _level_case(binary, path, 1, tmp_path)


@pytest.mark.slow
@pytest.mark.parametrize("path", LEVELS, ids=[p.stem for p in LEVELS])
def test_shipped_levels_agree_given_time(binary: Path, path: Path, tmp_path: Path) -> None:
    _level_case(binary, path, 150, tmp_path)


#: What burrTxt (built from ``../shared/burrtools-src``) printed for these levels written with
#: ``assembled_puzzle``: assemblies, solutions, sorted levels. Checked without burrTxt, so
#: that a run without g++ still pins BurrTools' semantics on real designs.
RECORDED = {
    "puzzle-mid-04-burr12": (2, 1, ["1.2.2"]),
    "puzzle-mid-05-burr6": (2, 2, ["2", "3.1.2"]),
    "puzzle-mid-07-burr6": (2, 2, ["4.4.2", "4.4.2"]),
    "puzzle-mid-12-cube4": (1, 1, ["3.2.2.1.2"]),
    "puzzle-hard-10-cube4": (1, 1, ["5.1.2.1.2"]),
    "puzzle-easy-04-burr6": (2, 2, ["2.2", "2.2"]),
}


@pytest.mark.parametrize("name", sorted(RECORDED))
def test_recorded_burrtxt_figures(name: str, tmp_path: Path) -> None:
    level = load_level(ROOT / "levels" / "puzzle" / f"{name}.json")
    file = write_xmpuzzle(assembled_puzzle(level.shapes), tmp_path / f"{name}.xmpuzzle")
    levels: list[str] = []
    packing = compile_packing(bt_packing_spec(read_xmpuzzle(file), 0))
    report = count_bt(packing, mirrors="drop", levels=levels)
    assert (report.assemblies, report.solutions, sorted(levels)) == RECORDED[name]


def test_a_level_string_is_the_one_burrtxt_prints_for_its_assembly() -> None:
    """The level's own assembly (written as BurrTools gets it) has BurrTools' level, which the
    stored ``level`` stat must be (puzzle-hard-10-cube4: burrTxt prints 5.1.2.1.2)."""
    level = load_level(ROOT / "levels" / "puzzle" / "puzzle-hard-10-cube4.json")
    assert _own_level(level) == level.stats["level"] == "5.1.2.1.2"


def _own_level(level: Level) -> str | None:
    from chaingeo.solvers.motion.disassemble import analyze_assembly

    return analyze_assembly(level.shapes, optimal=False).level


# -- (c) generator shapes --------------------------------------------------------------------

GENERATED: list[tuple[str, dict[str, int]]] = [("burr3", {}), ("plate3", {}), ("maze4", {})]
GENERATED_SLOW: list[tuple[str, dict[str, int]]] = [
    ("burr6", {}),
    ("cube3", {"pieces": 4}),
    ("cube4", {"pieces": 6}),
    ("burr6x8", {}),
    ("burr12", {}),
]


def _generated_case(binary: Path, shape: str, extra: dict[str, int], index: int, tmp: Path) -> None:
    from chaingeo.generator.config import PuzzleConfig
    from chaingeo.generator.puzzle import make

    item = make(PuzzleConfig(shape=shape, **extra), 1, index)  # type: ignore[arg-type]
    if not isinstance(item, Level):
        bt.OUTCOMES.append(bt.Outcome("generator", f"{shape}-{index}", "skip", "rejected item"))
        pytest.skip(f"the generator rejected item {index}: {item}")
    file = write_xmpuzzle(assembled_puzzle(item.shapes), tmp / f"{shape}-{index}.xmpuzzle")
    compare(binary, "generator", f"{shape} seed 1 item {index}", file, 60)


@pytest.mark.parametrize(("shape", "extra"), GENERATED, ids=[s for s, _ in GENERATED])
def test_generated_puzzles_agree(
    binary: Path, shape: str, extra: dict[str, int], tmp_path: Path
) -> None:
    _generated_case(binary, shape, extra, 0, tmp_path)


@pytest.mark.slow
@pytest.mark.parametrize("index", range(3))
@pytest.mark.parametrize(
    ("shape", "extra"), GENERATED + GENERATED_SLOW, ids=[s for s, _ in GENERATED + GENERATED_SLOW]
)
def test_more_generated_puzzles_agree(
    binary: Path, shape: str, extra: dict[str, int], index: int, tmp_path: Path
) -> None:
    _generated_case(binary, shape, extra, index, tmp_path)


# -- (d) feature files and BurrTools' files ----------------------------------------------------


def _problems(path: Path) -> list[tuple[Path, int]]:
    """The problems of a file; none for one of BurrTools' other grids (we read cubes only)."""
    try:
        puzzle = read_xmpuzzle(path)
    except BurrToolsError:
        if path.parent == _MORE:
            return []
        raise
    return [(path, i) for i in range(len(puzzle.problems))]


FILES = [pi for p in FEATURES for pi in _problems(p)]


@pytest.mark.parametrize(("path", "problem"), FILES, ids=[f"{p.stem}-{i}" for p, i in FILES])
def test_feature_files_agree(binary: Path, path: Path, problem: int) -> None:
    compare(binary, "file", f"{path.name} problem {problem}", path, 3, problem)


SHARED_FILES = [pi for p in SHARED for pi in _problems(p)]


@pytest.mark.parametrize(
    ("path", "problem"), SHARED_FILES, ids=[f"{p.stem}-{i}" for p, i in SHARED_FILES]
)
def test_burrtools_files_agree(binary: Path, path: Path, problem: int) -> None:
    """BurrTools' own files that burrTxt finishes in 5 s (the rest: -m slow)."""
    compare(binary, "file", f"{path.name} problem {problem}", path, 5, problem)


@pytest.mark.slow
@pytest.mark.parametrize(
    ("path", "problem"), SHARED_FILES, ids=[f"{p.stem}-{i}" for p, i in SHARED_FILES]
)
def test_burrtools_files_agree_given_time(binary: Path, path: Path, problem: int) -> None:
    compare(binary, "file", f"{path.name} problem {problem}", path, 300, problem)


@pytest.mark.parametrize(
    ("path", "problem"), SHARED_FILES, ids=[f"{p.stem}-{i}" for p, i in SHARED_FILES]
)
def test_chain_analyze_prints_burrtxt_figures_by_default(
    binary: Path, path: Path, problem: int, capsys: pytest.CaptureFixture[str]
) -> None:
    """``chain analyze FILE`` with no option: burrTxt's assemblies and solutions, one of its
    levels, and the convention named (files burrTxt finishes in 5 s)."""
    from chaingeo.cli.main import main

    ref = bt.run(binary, path, 5, problem)
    if ref is None:
        pytest.skip("burrTxt takes more than 5 s")
    args = ["analyze", str(path), "--problem", str(problem), "--no-optimal", "--jit", "numba"]
    assert main(args) in (0, 1)
    row = json.loads(capsys.readouterr().out)
    assert (row["assemblies"], row["solutions"]) == (ref.assemblies, ref.solutions)
    assert row["convention"] == "burrtxt"
    assert row["level"] in ref.levels or (not ref.levels and row["level"] is None)
