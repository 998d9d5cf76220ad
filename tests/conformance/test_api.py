"""The public API of ``import chaingeo``: cheap to import, every exported name resolves to what
the type checker sees, levels by id or path, one ``analyze`` whose JSON is ``chain analyze``'s,
and the quick-start script of the docs runs."""

from __future__ import annotations

import ast
import json
import subprocess
import sys
from pathlib import Path
from types import ModuleType
from typing import Any

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import chaingeo
import chaingeo.envs
import chaingeo.evaluation
from chaingeo.cli.commands.analyze import LIMIT_FLAGS
from chaingeo.cli.main import main
from chaingeo.solvers.figures import PuzzleFigures
from tests.support.paths import DATA, ROOT

PACKAGES = (chaingeo, chaingeo.envs, chaingeo.evaluation)
SOMA = DATA / "burrtools" / "soma_problems.xmpuzzle"
QUICKSTART = ROOT / "docs" / "examples" / "quickstart.py"


def _run(code: str, *args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, *(("-c", code) if code else ()), *args],
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
        cwd=ROOT.parent,  # not the checkout: the installed package, not files beside it
    )


def test_import_is_cheap_and_every_exported_name_resolves() -> None:
    code = """
import sys
import chaingeo, chaingeo.envs, chaingeo.evaluation
heavy = sorted({"numpy", "numba", "matplotlib", "trimesh", "gymnasium"} & set(sys.modules))
assert not heavy, heavy
for package in (chaingeo, chaingeo.envs, chaingeo.evaluation):
    for name in package.__all__:
        getattr(package, name)
print("ok")
"""
    done = _run(code)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "ok"


def _type_checking_names(package: ModuleType) -> dict[str, str]:
    """The names the ``if TYPE_CHECKING:`` block imports: public name -> "module:attribute"."""
    assert package.__file__ is not None
    tree = ast.parse(Path(package.__file__).read_text(encoding="utf-8"))
    block = next(
        node
        for node in tree.body
        if isinstance(node, ast.If) and ast.unparse(node.test) == "TYPE_CHECKING"
    )
    return {
        alias.asname or alias.name: f"{node.module}:{alias.name}"
        for node in block.body
        if isinstance(node, ast.ImportFrom)
        for alias in node.names
    }


@pytest.mark.parametrize("package", PACKAGES, ids=lambda p: p.__name__)
def test_all_the_lazy_table_and_the_type_checking_imports_agree(package: ModuleType) -> None:
    table: dict[str, str] = package._LAZY
    assert _type_checking_names(package) == table
    assert set(package.__all__) - {"__version__"} == set(table)
    assert set(package.__all__) <= set(dir(package))
    for name, target in table.items():
        module, _, attr = target.partition(":")
        assert getattr(package, name) is getattr(sys.modules[module], attr)
    with pytest.raises(AttributeError, match="no attribute 'nope'"):
        package.nope  # noqa: B018 - the look-up is the test


def test_shipped_levels_are_the_ids_by_family() -> None:
    every = chaingeo.shipped_levels()
    puzzles, stacks = chaingeo.shipped_levels("puzzle"), chaingeo.shipped_levels("stacking")
    assert every == sorted(puzzles + stacks) and not set(puzzles) & set(stacks)
    assert len(puzzles) == 32 and len(stacks) == 77
    with pytest.raises(ValueError, match="unknown family"):
        chaingeo.shipped_levels("bricks")


@settings(max_examples=12, deadline=None)
@given(st.sampled_from(chaingeo.shipped_levels()))
def test_a_level_by_id_is_the_level_of_its_file(level_id: str) -> None:
    from chaingeo.core.suite import suite_folder

    by_id = chaingeo.load_level(level_id)
    (path,) = suite_folder().rglob(f"{level_id}.json")
    assert by_id.id == level_id
    assert chaingeo.load_level(path) == by_id == chaingeo.load_level(str(path))
    assert isinstance(by_id, chaingeo.Level)


@pytest.mark.parametrize("spec", ["puzzle-easy-99-nothing", "no/such/level", "nowhere.json"])
def test_an_unknown_level_is_a_typed_error_saying_where_ids_are(spec: str) -> None:
    with pytest.raises(chaingeo.ChainGeoError) as caught:
        chaingeo.load_level(spec)
    if spec.endswith(".json"):  # a file name: the file is missing
        assert "nowhere.json" in str(caught.value)
        return
    assert isinstance(caught.value, chaingeo.UnknownLevelError | LookupError)
    assert "chaingeo.shipped_levels()" in str(caught.value) and repr(spec) in str(caught.value)


@settings(max_examples=20, deadline=None)
@given(st.sampled_from(chaingeo.shipped_levels()), st.data())
def test_a_near_miss_names_the_level_meant(level_id: str, data: st.DataObject) -> None:
    """One character dropped, doubled or changed: the error says "did you mean" the id, in the
    library and in every command (one resolver)."""
    from chaingeo.cli.errors import CommandError
    from chaingeo.cli.level_arg import find_level
    from chaingeo.core.suite import MAX_SUGGESTIONS, nearest

    i = data.draw(st.integers(0, len(level_id) - 1))
    typo = data.draw(st.sampled_from([
        level_id[:i] + level_id[i + 1 :],
        level_id[:i] + level_id[i] + level_id[i:],
        level_id[:i] + ("x" if level_id[i] != "x" else "y") + level_id[i + 1 :],
    ]))  # fmt: skip
    with pytest.raises(chaingeo.UnknownLevelError) as caught:
        chaingeo.load_level(typo)
    near = caught.value.near
    assert "did you mean" in str(caught.value) and near == tuple(sorted(near))
    ties = [i for i in chaingeo.shipped_levels() if nearest(typo, [i]) == [i]]
    assert level_id in near or len(ties) > MAX_SUGGESTIONS
    with pytest.raises(CommandError, match="did you mean"):
        find_level(typo)


def test_ids_are_looked_up_in_the_folder_given(tmp_path: Path) -> None:
    from chaingeo.core.suite import resolve_level, suite_folder

    (src,) = suite_folder().rglob("puzzle-easy-07-burr3.json")
    (tmp_path / "mine.json").write_bytes(src.read_bytes())
    path, level = resolve_level("puzzle-easy-07-burr3", tmp_path)
    assert path == tmp_path / "mine.json" and level.id == "puzzle-easy-07-burr3"
    with pytest.raises(chaingeo.UnknownLevelError, match=str(tmp_path)):
        resolve_level("puzzle-easy-01-luban-3-piece", tmp_path)


def _without_timing(row: dict[str, Any]) -> dict[str, Any]:
    return {k: v for k, v in row.items() if k not in ("seconds", "kernels", "file", "plan")}


def test_analyze_takes_a_level_its_id_or_its_file_and_gives_the_old_figures() -> None:
    from chaingeo.core.suite import suite_folder
    from chaingeo.solvers.analysis import DEFAULT_LIMITS, RowOptions, level_analysis_row

    level = chaingeo.load_level("puzzle-easy-07-burr3")
    old = level_analysis_row(level, RowOptions(DEFAULT_LIMITS))
    by_level = chaingeo.analyze(level)
    by_id = chaingeo.analyze(level.id)
    by_path = chaingeo.analyze(suite_folder("puzzle") / f"{level.id}.json")
    assert by_level.file is None and by_id.file == level.id
    for figures in (by_level, by_id, by_path):
        assert isinstance(figures, chaingeo.PuzzleFigures)
        assert _without_timing(figures.to_dict()) == _without_timing(old)
        assert figures.o_i == figures.optimal_steps == level.optimal_steps
        assert len(figures.plan) == figures.o_i


def test_analyze_refuses_a_stacking_level_with_a_typed_error() -> None:
    stacking = chaingeo.shipped_levels("stacking")[0]
    with pytest.raises(chaingeo.ChainGeoError, match="analyze takes puzzle levels"):
        chaingeo.analyze(stacking)


def test_analyze_of_a_burrtools_file_gives_the_old_figures_and_the_command_s_line(
    capsys: pytest.CaptureFixture[str],
) -> None:
    from chaingeo.solvers.analysis import DEFAULT_LIMITS, RowOptions, problem_analysis_row

    puzzle = chaingeo.read_burrtools(SOMA)
    whole = chaingeo.analyze(SOMA)
    assert whole.several and len(whole.problems) == len(puzzle.problems) == 3
    assert whole.level is None and whole.cut_short() == []
    for i, figures in enumerate(whole.problems):
        old = problem_analysis_row(puzzle, i, RowOptions(DEFAULT_LIMITS))
        assert _without_timing(figures.to_dict()) == _without_timing(old)
        one = chaingeo.analyze(puzzle, problem=i)
        assert not one.several
        assert _without_timing(one.to_dict()) == _without_timing(figures.to_dict())
    assert main(["analyze", str(SOMA), "--jit", "numba"]) == 0
    printed = json.loads(capsys.readouterr().out)
    assert _without_timing(printed) == _without_timing(whole.to_dict(LIMIT_FLAGS))
    assert printed["file"] == whole.file == str(SOMA)


_TEXT = st.none() | st.text(max_size=12)
_COUNT = st.none() | st.integers(0, 10**9)


def _figures(problems: st.SearchStrategy[tuple[PuzzleFigures, ...]]) -> Any:
    return st.builds(
        PuzzleFigures,
        assemblies=_COUNT,
        solutions=_COUNT,
        level=_TEXT,
        moves=_COUNT,
        optimal_steps=_COUNT,
        counts_complete=st.booleans(),
        limit=_TEXT,
        limit_cap=st.none() | st.sampled_from(["seconds", "max_states", "other"]),
        optimal_error=_TEXT,
        optimal_limit_cap=st.none() | st.sampled_from(["optimal_seconds", "other"]),
        disassembly_error=_TEXT,
        problem=st.none() | st.integers(0, 9),
        name=_TEXT,
        problems=problems,
        several=st.just(False),
        file=_TEXT,
        kernels=st.none() | st.sampled_from(["numba", "aot", "python"]),
        seconds=st.none() | st.floats(0, 1e4, allow_nan=False),
    )


def _whole(problems: tuple[PuzzleFigures, ...]) -> Any:
    return st.builds(PuzzleFigures, problems=st.just(problems), several=st.just(True), file=_TEXT)


FIGURES = _figures(st.just(())) | st.lists(_figures(st.just(())), max_size=3).map(tuple).flatmap(
    _whole
)


@settings(max_examples=150, deadline=None)
@given(FIGURES)
def test_figures_round_trip_through_json(figures: PuzzleFigures) -> None:
    text = figures.to_json()
    assert json.loads(text) == figures.to_dict()
    assert PuzzleFigures.from_json(text) == figures
    assert text == json.dumps(json.loads(text), sort_keys=True)
    flagged = figures.to_dict(LIMIT_FLAGS)
    for row in [flagged, *flagged.get("problems", [])]:
        assert "limit_cap" not in row and "optimal_limit_cap" not in row
        assert ("counts_complete" in row) == (row.get("counts_complete") is False)


def test_a_cap_is_named_by_its_flag_only_when_asked() -> None:
    figures = PuzzleFigures(counts_complete=False, limit="time limit", limit_cap="seconds")
    assert figures.to_dict()["limit"] == "time limit"
    assert figures.to_dict(LIMIT_FLAGS)["limit"] == "time limit; raise it with --seconds"
    assert figures.cut_short() == [figures]
    with pytest.raises(ValueError, match="not a figures key: levle"):
        PuzzleFigures.from_dict({"levle": "1"})


def test_count_packings_of_the_soma_cube() -> None:
    result = chaingeo.count_packings(chaingeo.PIECESETS["soma"].pieces, (3, 3, 3))
    assert (result.solutions, result.distinct) == (11520, 240)
    first = next(chaingeo.iter_packings(chaingeo.PIECESETS["soma"].pieces, (3, 3, 3)))
    assert sum(len(s) for s in first.shapes) == 27


def test_the_shipped_example_is_the_generator_s_file() -> None:
    from chaingeo.core.formats.burrtools import xmpuzzle_bytes
    from chaingeo.generator.bt_examples import EXAMPLES

    shipped = (chaingeo.EXAMPLES / "soma_problems.xmpuzzle").read_bytes()
    assert shipped == xmpuzzle_bytes(EXAMPLES["soma_problems"]()) == SOMA.read_bytes()


def test_the_quickstart_runs_with_import_chaingeo_alone() -> None:
    source = QUICKSTART.read_text(encoding="utf-8")
    code = [line for line in source.splitlines() if line.strip()]
    assert len(code) <= 13
    imports = [line for line in code if line.startswith(("import ", "from "))]
    assert imports == ["import chaingeo"]
    done = _run("", str(QUICKSTART))
    assert done.returncode == 0, done.stderr
    action, figures, distinct, line = done.stdout.splitlines()
    assert action.startswith("move ") and "-> OK" in action
    assert figures == "2 3 3" and distinct == "240"
    row = json.loads(line)
    assert (row["name"], row["assemblies"], row["solutions"], row["level"]) == (
        "soma cube",
        240,
        240,
        "1",
    )  # burrTxt's figures: an assembly and its mirror image are one
    assert row["convention"] == "burrtxt"
