"""Pose trajectories: every trajectory of a legal plan is valid (shipped plans, random legal
walks, random stacking plans), each kind of corruption is caught with its reason, frame and
piece, and the commands (chain check-trajectory, chain video --trajectory-out)."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, Phase, assume, given, settings
from hypothesis import strategies as st

from chaingeo.cli.main import main
from chaingeo.core.kinematics import DIRECTIONS, Assembly, Move, state_key
from chaingeo.core.level import Level, load_level
from chaingeo.core.rules import StackingRules
from chaingeo.core.turns import TurnMove
from chaingeo.envs.actions.types import MoveAction, PlaceAction, TurnAction
from chaingeo.envs.machines import new_state
from chaingeo.generator.config import PuzzleConfig
from chaingeo.generator.puzzle import make
from chaingeo.worldmodel.trajectory import (
    FORMAT,
    TrajectoryError,
    parse_trajectory,
    puzzle_trajectory,
    stacking_trajectory,
    trajectory_json,
    write_trajectory,
)
from chaingeo.worldmodel.trajectory_verdict import TrajectoryVerdict, check_trajectory
from chaingeo.worldmodel.video import read_plan
from tests.support.paths import LEVELS

TURNS = load_level(LEVELS / "puzzle" / "puzzle-easy-01-luban-3-piece.json")  # has a turn
BURR_PATH = LEVELS / "puzzle" / "puzzle-easy-04-burr6.json"
BURR = load_level(BURR_PATH)  # slides only
SMALL = sorted(
    (p for p in (LEVELS / "puzzle").glob("puzzle-easy-*.json")), key=lambda p: p.name
) + sorted((LEVELS / "stacking").glob("stacking-2x2x*.json"))
RANDOM = PuzzleConfig(shape="cube3", pieces=3, min_level=2, hole_rate=0.3, hill_steps=10)
FAST = settings(
    max_examples=8,
    deadline=None,
    phases=[Phase.explicit, Phase.generate],  # examples are slow to shrink
    suppress_health_check=[HealthCheck.too_slow],
)


def _doc(level: Level, moves: Any = None) -> dict[str, Any]:
    if level.family == "puzzle":
        frames = puzzle_trajectory(level, moves)
    else:
        frames = stacking_trajectory(level, moves)
    return trajectory_json(level.id, frames)


def _check(level: Level, doc: dict[str, Any] | str) -> TrajectoryVerdict:
    text = doc if isinstance(doc, str) else json.dumps(doc)
    return check_trajectory(level, parse_trajectory(text))


#: Stacking levels whose own order would drop a piece through a placed one: the video's
#: order (chain.envs.video.carried_order) carries each piece in by a free way.
REORDERED = [
    LEVELS / "stacking" / f"{n}.json"
    for n in ("stacking-2x2x2-mid-s102-000000", "stacking-2x3x3-easy-s107-000000")
]


@pytest.mark.parametrize("path", SMALL[:6] + SMALL[-2:] + REORDERED, ids=lambda p: p.stem)
def test_the_levels_own_plan_is_valid_and_replays(path: Path) -> None:
    level = load_level(path)
    verdict = _check(level, _doc(level))
    assert verdict.valid, verdict.violations[:3]
    assert verdict.goal is True
    assert verdict.plan is not None and len(verdict.plan) == level.optimal_steps
    if level.family == "puzzle":  # the plan replays by the state machine to the goal
        moves, _ = read_plan(level, "\n".join(verdict.plan))
        assert len(moves) == level.optimal_steps


@settings(FAST, max_examples=4)
@given(st.integers(0, 1 << 20), st.sampled_from(["disassemble", "assemble"]))
def test_generated_levels_plans_are_valid(seed: int, goal: str) -> None:
    """Random small levels of the generator: their optimal plans' trajectories are valid."""
    config = dataclasses.replace(RANDOM, goal=goal)  # type: ignore[arg-type]
    level = make(config, seed, 0)
    assume(isinstance(level, Level))
    assert isinstance(level, Level)
    verdict = _check(level, _doc(level))
    assert verdict.valid and verdict.goal, verdict.violations[:3]
    assert verdict.plan is not None and len(verdict.plan) == level.optimal_steps


@FAST
@given(st.sampled_from([TURNS, BURR]), st.lists(st.integers(0, 1 << 30), max_size=6))
def test_random_legal_walks_are_valid(level: Level, picks: list[int]) -> None:
    """A random walk of legal steps (turns too where the level has them): its trajectory is
    valid and the plan read back leads to the same position."""
    machine = new_state(level)
    moves: list[Move | TurnMove] = []
    for pick in picks:
        steps = [a for a in machine.legal_actions() if isinstance(a, MoveAction | TurnAction)]
        if not steps:
            break
        action = steps[pick % len(steps)]
        machine.apply(action)
        moves.append(action.move if isinstance(action, MoveAction) else action.turn)
    state = Assembly.assembled(level.shapes, level.rods)
    for m in moves:
        state = state.apply(m)
    verdict = _check(level, _doc(level, moves))
    assert {v["kind"] for v in verdict.violations} <= {"goal"}, verdict.violations[:3]
    assert verdict.goal == verdict.valid == state.is_separated()
    assert verdict.plan is not None
    again = Assembly.assembled(level.shapes, level.rods)
    for m in read_plan(level, "\n".join(verdict.plan))[0]:
        again = again.apply(m)
    assert state_key(again) == state_key(state)


@FAST
@given(st.sampled_from(SMALL[-6:]), st.lists(st.integers(0, 1 << 30), max_size=8))
def test_random_stacking_plans_with_drop_support_are_valid(path: Path, picks: list[int]) -> None:
    """Under the drop rule every placement can be lowered straight down, so the video's
    carry never passes through a piece; the box is full exactly when the plan fills it."""
    level = dataclasses.replace(load_level(path), rules=StackingRules(support="drop"))
    state = new_state(level)
    places = []
    for pick in picks:
        legal = [a for a in state.legal_actions() if isinstance(a, PlaceAction)]
        if not legal:
            break
        action = legal[pick % len(legal)]
        state.apply(action)
        places.append((action.piece, action.cells))
    from chaingeo.core.geometry import Shape

    verdict = _check(level, _doc(level, [(n, Shape(c)) for n, c in places]))
    kinds = {v["kind"] for v in verdict.violations}
    assert kinds <= {"goal"} and not verdict.undecided, verdict.violations[:3]
    assert verdict.goal == state.is_success()
    assert verdict.plan == [PlaceAction(n, c).to_text() for n, c in places]


# ---------------------------------------------------------------------------------------------
# Corruptions
# ---------------------------------------------------------------------------------------------


def _copy(doc: dict[str, Any]) -> dict[str, Any]:
    """A deep copy of a JSON object (through the C codec: ``copy.deepcopy`` of a whole
    trajectory cost more than checking it)."""
    out: dict[str, Any] = json.loads(json.dumps(doc))
    return out


BASE = _doc(BURR)
N_FRAMES = len(BASE["frames"])
NAMES = sorted(p.name for p in BURR.pieces)


def _has(verdict: TrajectoryVerdict, kind: str, frame: int, piece: str) -> None:
    assert not verdict.valid
    hits = [v for v in verdict.violations if (v["kind"], v["frame"]) == (kind, frame)]
    assert any(piece in (v["piece"], v.get("other")) for v in hits), verdict.violations[:4]


def _blocked(name: str) -> tuple[str, int]:
    """A direction in which ``name`` is blocked in the assembled puzzle, and a distance that
    carries it past every other piece."""
    state = Assembly.assembled(BURR.shapes)
    for d in DIRECTIONS:
        if state.blockers(name, d):
            return d, state.clearance([name], d) + 1
    raise AssertionError(f"{name} is free every way")


def _shifted(pose: dict[str, Any], vector: Any) -> dict[str, Any]:
    out = _copy(pose)
    out["translation"] = [a + float(b) for a, b in zip(out["translation"], vector, strict=True)]
    return out


def _there_and_back(name: str, far: float | None) -> dict[str, Any]:
    """The trajectory with two frames put after the first: ``name`` moved toward a piece that
    blocks it (by ``far``, None: past every piece), then back where it was."""
    d, past = _blocked(name)
    doc = _copy(BASE)
    moved = _copy(doc["frames"][0])
    step = np.array(DIRECTIONS[d]) * (past if far is None else far)
    moved["poses"][name] = _shifted(moved["poses"][name], step)
    doc["frames"][1:1] = [moved, _copy(doc["frames"][0])]
    return doc


@FAST
@given(st.sampled_from(NAMES))
def test_a_teleport_through_a_piece(name: str) -> None:
    _has(_check(BURR, _there_and_back(name, None)), "teleport", 1, name)


@FAST
@given(st.sampled_from(NAMES), st.sampled_from([0.5, 0.01, 0.99]))
def test_an_interpenetration_between_lattice_poses(name: str, depth: float) -> None:
    _has(_check(BURR, _there_and_back(name, depth)), "overlap", 1, name)


@FAST
@given(st.integers(1, N_FRAMES - 2), st.sampled_from(NAMES))
def test_a_deleted_piece(frame: int, name: str) -> None:
    doc = _copy(BASE)
    del doc["frames"][frame]["poses"][name]
    verdict = _check(BURR, doc)
    _has(verdict, "disappear", frame, name)
    _has(verdict, "appear", frame + 1, name)


@FAST
@given(st.integers(0, N_FRAMES - 1), st.sampled_from(NAMES))
def test_a_duplicated_piece(frame: int, name: str) -> None:
    doc = _copy(BASE)
    poses = doc["frames"][frame]["poses"]
    poses[f"copy-of-{name}"] = poses[name]
    _has(_check(BURR, doc), "appear", frame, f"copy-of-{name}")
    # the same name twice in one frame (JSON allows it; a trajectory does not)
    text = json.dumps(BASE)
    frames = json.loads(text)["frames"]
    one = json.dumps(frames[frame]["poses"][name])
    head, _, tail = json.dumps(frames[frame]).rpartition("}}")
    frames_text = [json.dumps(f) for f in frames]
    frames_text[frame] = f'{head}, "{name}": {one}}}{tail}}}'
    joined = ", ".join(frames_text)
    doubled = f'{{"format": "{FORMAT}", "frames": [{joined}]}}'
    _has(_check(BURR, doubled), "duplicate", frame, name)


def _lattice_frames(name: str) -> list[int]:
    verdict_cells = []
    for i, f in enumerate(BASE["frames"]):
        t = np.array(f["poses"][name]["translation"])
        if np.allclose(t, np.rint(t)):
            verdict_cells.append(i)
    return verdict_cells


@FAST
@given(st.data(), st.sampled_from(NAMES))
def test_a_split_piece(data: st.DataObject, name: str) -> None:
    frame = data.draw(st.sampled_from(_lattice_frames(name)))
    doc = _copy(BASE)
    t = np.rint(doc["frames"][frame]["poses"][name]["translation"]).astype(int)
    cells = [list(map(int, c + t)) for c in BURR.piece(name).shape.voxels]
    k = len(cells) // 2
    cells[k:] = [[x, y, z + 50] for x, y, z in cells[k:]]
    doc["frames"][frame]["poses"][name] = {"cells": cells}
    _has(_check(BURR, doc), "shape", frame, name)


@FAST
@given(st.data())
def test_an_identity_swap(data: st.DataObject) -> None:
    """Two pieces at rest exchange their poses (their names swapped) from some frame on."""
    doc = _copy(BASE)
    frames = doc["frames"]
    end = frames[-1]["poses"]
    pairs = [(a, b) for a in NAMES for b in NAMES if a < b]
    rests = {
        (a, b): [
            i
            for i in range(1, N_FRAMES)
            if all(frames[k]["poses"][n] == end[n] for k in (i - 1, i) for n in (a, b))
        ]
        for a, b in pairs
    }
    a, b = data.draw(st.sampled_from([p for p in pairs if rests[p]]))
    frame = data.draw(st.sampled_from(rests[a, b]))
    for f in frames[frame:]:
        f["poses"][a], f["poses"][b] = f["poses"][b], f["poses"][a]
    _has(_check(BURR, doc), "swap", frame, a)


@FAST
@given(st.sampled_from(NAMES), st.sampled_from([0.25, -0.4, 1e-3]), st.integers(0, 2))
def test_jitter_off_the_lattice(name: str, amount: float, axis: int) -> None:
    """At the end every piece rests alone in its place: a pose off the lattice in a held
    frame is a drift, in the last frame the trajectory ends off the lattice."""
    doc = _copy(BASE)
    last = doc["frames"][-1]
    doc["frames"] += [_copy(last), _copy(last)]
    shift = np.zeros(3)
    shift[axis] = amount
    held = doc["frames"][-2]["poses"]
    held[name] = _shifted(held[name], shift)
    _has(_check(BURR, doc), "off-lattice", N_FRAMES, name)
    end = doc["frames"][-1]["poses"]
    end[name] = _shifted(end[name], shift)
    _has(_check(BURR, doc), "off-lattice", N_FRAMES + 1, name)


def test_a_mirrored_or_scaled_piece_and_a_wrong_goal() -> None:
    doc = _copy(BASE)
    pose = doc["frames"][3]["poses"][NAMES[0]]
    pose["rotation"] = [[-1, 0, 0], [0, 1, 0], [0, 0, 1]]
    _has(_check(BURR, doc), "shape", 3, NAMES[0])
    pose["rotation"] = [[1.5, 0, 0], [0, 1, 0], [0, 0, 1]]
    _has(_check(BURR, doc), "shape", 3, NAMES[0])
    short = _copy(BASE)
    on = [set(_lattice_frames(n)) for n in NAMES]
    cut = [i for i in range(1, N_FRAMES - 1) if all(i in frames for frames in on)]
    short["frames"] = short["frames"][: cut[len(cut) // 2] + 1]
    verdict = _check(BURR, short)
    assert [v["kind"] for v in verdict.violations] == ["goal"] and verdict.goal is False


@pytest.mark.parametrize(
    "text",
    [
        "[]",
        '{"format": "chain-trajectory/1", "frames": []}',
        '{"format": "chain-trajectory/1", "frames": [{"poses": {"a": {"rotation": 1}}}]}',
        '{"format": "chain-trajectory/1", "frames": [{"poses": {"a": {"cells": [[0.5,0,0]]}}}]}',
        '{"format": "chain-trajectory/1", "frames": [{"poses": {"a": {"rotation": '
        '[[1,0,0],[0,1,0],[0,0,1]], "translation": [1e999, 0, 0]}}}]}',
        "[" * 100,
    ],
)
def test_unreadable_trajectories_are_typed_errors(text: str) -> None:
    with pytest.raises(TrajectoryError):
        parse_trajectory(text)


# ---------------------------------------------------------------------------------------------
# Commands
# ---------------------------------------------------------------------------------------------


def test_commands(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    level = LEVELS / "puzzle" / "puzzle-easy-07-burr3.json"
    traj = tmp_path / "t.json"
    assert (
        main(
            [
                "video",
                str(level),
                "--out",
                str(tmp_path / "v.gif"),
                "--size",
                "128",
                "--trajectory-out",
                str(traj),
            ]
        )
        == 0
    )
    capsys.readouterr()
    assert main(["check-trajectory", str(level), str(traj)]) == 0
    out = json.loads(capsys.readouterr().out.splitlines()[-1])
    assert out["valid"] is True and out["goal"] is True and len(out["plan"]) == 3
    doc = json.loads(traj.read_text())
    del doc["frames"][5]["poses"][sorted(doc["frames"][5]["poses"])[0]]
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps(doc))
    assert main(["check-trajectory", str(level), str(bad)]) == 1
    lines = capsys.readouterr().out.splitlines()
    found = json.loads(lines[-1])["violations"]
    assert {(v["kind"], v["frame"]) for v in found} == {("disappear", 5), ("appear", 6)}
    bad.write_text('{"format": "other"}')
    assert main(["check-trajectory", str(level), str(bad)]) == 2
    assert "chain-trajectory/1" in capsys.readouterr().err
    again = tmp_path / "again.json"
    write_trajectory(load_level(level), None, again)  # the same plan gives the same bytes
    assert again.read_bytes() == traj.read_bytes()


# ---------------------------------------------------------------------------------------------
# Issue #37, item 1: no in-band sentinel. The parser kept a piece named twice in a frame under
# the key "\0dup", which a file can write too: an int there crashed, a string or list invented
# "listed twice" violations.
# ---------------------------------------------------------------------------------------------


@pytest.mark.parametrize("value", [7, "red", ["red", "blue"], {"cells": [[0, 0, 0]]}, None])
def test_the_parsers_old_sentinel_key_is_an_ordinary_piece_name(value: Any) -> None:
    doc = _doc(BURR)
    doc["frames"][0]["poses"]["\u0000dup"] = value
    try:
        verdict = _check(BURR, doc)
    except TrajectoryError:
        return  # a malformed pose: a typed refusal
    assert not verdict.valid
    assert not any("twice" in v["reason"] for v in verdict.violations), verdict.violations[:3]


def test_a_piece_named_twice_in_a_frame_is_still_reported() -> None:
    text = json.dumps(_doc(BURR))
    name = sorted(p.name for p in BURR.pieces)[0]
    head, sep, tail = text.partition(f'"{name}": ')
    pose = tail[: tail.index("}") + 1]
    doubled = head + f'"{name}": {pose}, ' + sep + tail
    verdict = _check(BURR, doubled)
    assert any(v["frame"] == 0 and v["piece"] == name for v in verdict.violations)


@pytest.mark.parametrize("special", ["/dev/zero", "fifo"])
def test_check_trajectory_refuses_a_non_regular_file(
    tmp_path: Path, special: str, capsys: pytest.CaptureFixture[str]
) -> None:
    import os

    path = Path(special)
    if special == "fifo":
        path = tmp_path / "t.json"
        os.mkfifo(path)
    assert main(["check-trajectory", str(BURR_PATH), str(path)]) == 2
    assert "not a regular file" in capsys.readouterr().err
