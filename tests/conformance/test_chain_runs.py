"""CHAIN's stacking game, replayed: hand-written runs in CHAIN's form (``tests/data/chain_runs``)
through our state machine under the ``chain`` rules profile, with the same verdict and error
name at every step; and ``chain convert --from chain`` on CHAIN's level files."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from chaingeo.cli.commands.convert import import_chain_file
from chaingeo.cli.main import main
from chaingeo.core.formats.chain_json import (
    ChainStacking,
    chain_level,
    load_chain_file,
    read_chain_stacking,
)
from chaingeo.core.geometry import Shape
from chaingeo.core.level import (
    Level,
    LevelError,
    StackingSolution,
    level_bytes,
    load_level,
    parse_level,
)
from chaingeo.core.rules import CHAIN_CODES, StackingRules
from chaingeo.envs.actions.types import StateAction
from chaingeo.envs.machines import new_state
from chaingeo.envs.machines.stacking import StackingState
from tests.support.paths import DATA

DATA = DATA / "chain_runs"
RUNS: list[dict[str, Any]] = json.loads((DATA / "runs.json").read_text())["runs"]


def _sent(step: dict[str, Any]) -> str:
    send = step["send"]
    return send if isinstance(send, str) else json.dumps(send)


def _level(name: str, rules: str = "chain") -> Level:
    return import_chain_file(DATA / name, None, None, rules)


@pytest.mark.parametrize("run", RUNS, ids=[r["level"] for r in RUNS])
def test_chain_runs_replay_with_chain_verdicts(run: dict[str, Any]) -> None:
    state = new_state(_level(run["level"]))
    assert isinstance(state, StackingState)
    for i, step in enumerate(run["steps"]):
        text = _sent(step)
        key, used = state.key(), state.steps_used
        result = state.step_text(text)
        verdict = "ok" if result.legal else result.code
        assert verdict == step["verdict"], f"step {i}: {text}: {result.feedback}"
        assert state.steps_used == used + 1  # every turn costs a step
        if not result.legal:
            assert result.error == "illegal" and state.key() == key  # nothing changed
            assert f"[{result.code}] " in result.feedback  # CHAIN's name beside our reason
        elif isinstance(result.action, StateAction):
            assert state.key() == key and "In the box" in result.feedback
    assert state.is_success() == run["solved"]
    assert state.finished


def test_the_runs_name_every_chain_error() -> None:
    verdicts = {s["verdict"] for r in RUNS for s in r["steps"]}
    assert verdicts == {"ok", *CHAIN_CODES}


def test_our_default_profile_refuses_the_floating_pickup_chain_allows() -> None:
    run = RUNS[1]
    state = new_state(_level(run["level"], "default"))
    for step in run["steps"][:3]:
        state.step_text(_sent(step))
    result = state.step_text("pickup 0")
    assert result.error == "illegal" and result.code is None
    assert "would be left floating" in result.feedback and "[" not in result.feedback
    # The same refusals carry CHAIN's names under our rules too, not shown in the feedback.
    result = state.step_text("pickup 5")
    assert result.code == "PieceNotFound" and "[PieceNotFound]" not in result.feedback


# ---------------------------------------------------------------------------------------------
# chain convert --from chain
# ---------------------------------------------------------------------------------------------


def test_tray_file_becomes_a_verified_level(tmp_path: Path) -> None:
    target = tmp_path / "level.json"
    source = DATA / "tray_2x2x3_easy_001.json"
    assert (
        main(["convert", "--from", "chain", str(source), "--out", str(target), "--rules", "chain"])
        == 0
    )
    level = load_level(target)  # validated in full on load
    assert level.id == "tray_2x2x3_easy_001" and level.difficulty == "easy"
    assert level.rules == StackingRules(profile="chain") and level.optimal_steps == 3
    assert [p.chain_id for p in level.pieces] == ["0", "1", "2"]
    spec = load_chain_file(source)
    assert not spec.packed
    for piece, tray in zip(level.pieces, spec.pieces, strict=True):
        assert piece.shape == tray.normalized()  # handed out as it lies in CHAIN's tray
    data = json.loads(target.read_text())
    assert data["rules"] == {"profile": "chain", "support": "contact"}
    assert data["pieces"][2]["chain_id"] == "2"


def test_packed_file_still_converts_and_keeps_its_packing(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    source = DATA / "packed_3x2x2_mid_002.json"
    assert main(["convert", "--from", "chain", str(source)]) == 0  # the level on stdout
    out = capsys.readouterr().out
    level = _level("packed_3x2x2_mid_002.json", "default")
    assert out.encode() == level_bytes(level)
    assert level.difficulty == "mid" and "profile" not in json.loads(out)["rules"]
    assert isinstance(level.solution, StackingSolution)
    raw = json.loads(source.read_text())["pieces"]
    for p, cells in zip(level.pieces, raw, strict=True):
        assert level.solution.placements[p.name] == Shape(cells)
    assert read_chain_stacking(source).solution == level.solution


def test_old_flag_reads_tray_files_too(tmp_path: Path) -> None:
    target = tmp_path / "t.json"
    source = DATA / "tray_2x2x3_easy_001.json"
    args = [
        "convert",
        str(source),
        "--out",
        str(target),
        "--to",
        "chain-level",
        "--difficulty",
        "hard",
    ]
    assert main(args) == 0
    assert load_level(target).difficulty == "hard"


def test_core_import_of_a_tray_file_says_to_pack_it_first() -> None:
    with pytest.raises(LevelError, match="tray form"):
        read_chain_stacking(DATA / "tray_2x2x3_easy_001.json")


@pytest.mark.parametrize(
    ("data", "why"),
    [
        ({"box": [2, 2, 2], "pieces": [[[5, 0, 0], [6, 0, 0]], [[9, 0, 0]]]}, "cannot fill"),
        (
            {"box": [2, 1, 2], "pieces": [[[5, 0, 0], [6, 0, 0], [7, 0, 0]], [[9, 0, 0]]]},
            "cannot fill the box in any way",
        ),
        ({"box": [1, 1, 1], "pieces": [[[0, 0, 0], [0, 0, 0]]]}, "listed twice"),
        ({"box": [1, 1, 2000], "pieces": [[[0, 0, 0]]]}, "box"),
        ({"box": [1, 1, 2], "pieces": [[[0, 0, 0]], [[0, 0, 1 << 40]]]}, "pieces"),
    ],
)
def test_bad_chain_files_give_one_line_errors(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], data: Any, why: str
) -> None:
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(data))
    assert main(["convert", "--from", "chain", str(path), "--out", str(tmp_path / "out.json")]) != 0
    err = capsys.readouterr().err
    assert why in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "out.json").exists()


def test_chain_profile_keeps_the_optimum_and_rejects_drop() -> None:
    """Both profiles place exactly as CHAIN does (contact support), so a packing's legal order
    is legal under both and the optimum stays the number of pieces; CHAIN has no drop rule."""
    spec = ChainStacking((3, 2, 2), load_chain_file(DATA / "packed_3x2x2_mid_002.json").pieces)
    ours = chain_level(spec, "x")
    theirs = chain_level(spec, "x", rules=StackingRules(profile="chain"))
    assert ours.optimal_steps == theirs.optimal_steps == 3
    assert ours.solution == theirs.solution
    with pytest.raises(ValueError, match="contact support only"):
        StackingRules(support="drop", profile="chain")
    data = json.loads(level_bytes(theirs))
    data["rules"]["support"] = "drop"
    with pytest.raises(LevelError, match=r"rules\.support"):
        parse_level(data)
