"""CHAIN's dialect: JSON tool calls, CHAIN's piece ids, the ``state`` action, CHAIN's error names
on every refusal, chain_id in level files, and a model answering only in CHAIN's format."""

from __future__ import annotations

import copy
import json
from functools import cache
from pathlib import Path
from typing import Any

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from chaingeo.benchmarks.robustness import check_turn
from chaingeo.cli.commands.convert import import_chain_file
from chaingeo.cli.main import main
from chaingeo.core import limits
from chaingeo.core.level import LevelError, level_bytes, parse_level, save_level
from chaingeo.envs.actions.parse import parse_text
from chaingeo.envs.actions.types import (
    FinishAction,
    IllegalActionError,
    PickupAction,
    PlaceAction,
    StateAction,
    UnparseableActionError,
    action_from_json,
    action_to_json,
)
from chaingeo.envs.machines import new_state
from chaingeo.envs.machines.state import BaseState
from chaingeo.envs.observation import color_table, instruction
from tests.support.env_levels import puzzle_levels, soma_level
from tests.support.paths import DATA

DATA = DATA / "chain_runs"
TRAY = "tray_2x2x3_easy_001.json"
#: Piece "0" of the tray level (red, a 2x2 square) on the floor of the 2x2x3 box.
RED_FLOOR = [[1, 1, 1], [2, 1, 1], [1, 2, 1], [2, 2, 1]]


@cache
def _chain_state() -> BaseState:
    return new_state(import_chain_file(DATA / TRAY, None, None, "chain"))


def state() -> BaseState:
    return _chain_state().clone()


def call(tool: str, **args: Any) -> str:
    return json.dumps({"tool": tool, **args})


# ---------------------------------------------------------------------------------------------
# Reading tool calls
# ---------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "text",
    [
        call("place", piece_id="0", cells=RED_FLOOR),
        call("place", piece_id=0, cells=RED_FLOOR),
        call("place", piece_id="red", cells=RED_FLOOR),
        call("place_piece", piece_id=" 0 ", cells=RED_FLOOR),
        "<action>" + call("place", piece_id="0", cells=RED_FLOOR) + "</action>",
        "  <ACTION> " + call("place", piece_id="0", cells=RED_FLOOR) + " </action>\n",
        "```json\n" + call("place", piece_id="0", cells=RED_FLOOR) + "\n```",
        json.dumps({"name": "place", "arguments": {"piece_id": "0", "cells": RED_FLOOR}}),
        json.dumps(
            {"tool": "place", "arguments": json.dumps({"piece_id": "0", "cells": RED_FLOOR})}
        ),
        call("place", piece_id="0", cells=[[1.0, 1, 1], [2, 1, 1], [1, 2, 1], [2, 2, 1]]),
        "place 0 (1,1,1) (2,1,1) (1,2,1) (2,2,1)",
        "place 0: [1,1,1], [2,1,1], [1,2,1], [2,2,1]",
        "place 0 1 1 1 2 1 1 1 2 1 2 2 1",
        "<action>place red (1,1,1) (2,1,1) (1,2,1) (2,2,1)</action>",
    ],
)
def test_every_spelling_places_the_same_piece(text: str) -> None:
    s = state()
    result = s.step_text(text)
    assert result.legal, result.feedback
    assert result.action == PlaceAction(
        "red", tuple((x - 1, y - 1, z - 1) for x, y, z in RED_FLOOR)
    )
    assert result.feedback.startswith("OK: red (id 0) placed.")


def test_other_tools_and_their_aliases() -> None:
    s = state()
    assert s.step_text(call("place", piece_id="0", cells=RED_FLOOR)).legal
    for text in (call("pickup", piece_id="0"), call("pickup_piece", piece_id=0), "pickup 0"):
        t = s.clone()
        result = t.step_text(text)
        assert result.legal and result.action == PickupAction("red"), text
    for text, action in (
        (call("state"), StateAction()),
        (call("get_state"), StateAction()),
        ('{"tool": "STATE"}', StateAction()),
        (call("finish"), FinishAction()),
        (call("check"), FinishAction()),
    ):
        assert parse_text(text) == action


@pytest.mark.parametrize(
    ("text", "hint"),
    [
        ("{", "not valid JSON"),
        ('{"tool": "place", "piece_id": "0", "cells": [[1,1,1]]} trailing', "not valid JSON"),
        ("[1, 2, 3]", "unknown command"),  # not an object: read by our grammar
        ('{"tool": "place", "piece_id": "0", "cells": [[1,1,1]], "rot": 3}', '"rot"'),
        ('{"tool": "fly"}', "unknown tool"),
        ('{"piece_id": "0"}', "no 'tool'"),
        ('{"tool": "place", "cells": [[1,1,1]]}', "'piece_id' is missing"),
        ('{"tool": "place", "piece_id": "0"}', "'cells' is missing"),
        ('{"tool": "place", "piece_id": true, "cells": [[1,1,1]]}', "'piece_id' must be"),
        ('{"tool": "place", "piece_id": "0", "cells": [[1,1]]}', "every cell is [x, y, z]"),
        ('{"tool": "place", "piece_id": "0", "cells": "1,1,1"}', "'cells' must be a list"),
        ('{"tool": "place", "piece_id": "0", "cells": [[1,1,"1"]]}', "whole numbers"),
        ('{"tool": "place", "piece_id": "0", "cells": [[1,1,1.5]]}', "whole numbers"),
        ('{"tool": "place", "piece_id": "0", "cells": [[1,1,NaN]]}', "NaN is not a number"),
        ('{"tool": "state", "arguments": {}, "x": 1}', "either flat or in"),
        ('{"tool": "state", "arguments": [1]}', "must be an object"),
        ('{"tool": "state", "arguments": "{oops"}', "not valid JSON"),
        ("{" * 100 + "}" * 100, "nested 100 deep"),
    ],
)
def test_malformed_tool_calls_are_unparseable(text: str, hint: str) -> None:
    s = state()
    key = s.key()
    result = s.step_text(text)
    assert result.error == "unparseable" and result.code is None, result.feedback
    assert hint in result.feedback and s.key() == key and s.steps_used == 1


@pytest.mark.parametrize(
    "text",
    [
        call("place", piece_id="0", cells=[[1, 1, 10**6], [2, 1, 1], [1, 2, 1], [2, 2, 1]]),
        '{"tool": "place", "piece_id": "0", "cells": [[1,1,' + "9" * 4000 + "]]}",
        '{"tool": "place", "piece_id": "0", "cells": [[1,1,1e999]]}',
        '{"tool": "place", "piece_id": "0", "cells": [[1,1,-1' + "0" * 30 + ".5]]}",
        '{"tool": "pickup", "piece_id": 12345678901234567890123}',
    ],
)
def test_huge_numbers_are_refused_before_use(text: str) -> None:
    with pytest.raises(IllegalActionError, match=f"at most {limits.MAX_AGENT_NUMBER}"):
        parse_text(text)
    result = state().step_text(text)
    assert result.error == "illegal" and "Nothing changed" in result.feedback


def test_text_past_the_length_limit_is_not_read() -> None:
    text = call("place", piece_id="0", cells=[[1, 1, 1]] * 1000)
    assert len(text) > limits.MAX_TEXT_CHARS
    with pytest.raises(UnparseableActionError, match="characters"):
        parse_text(text)


def test_empty_id_and_unknown_ids_are_piece_not_found() -> None:
    for text in (
        call("place", piece_id="", cells=RED_FLOOR),
        call("pickup", piece_id=""),
        call("place", piece_id=3, cells=RED_FLOOR),
        call("place", piece_id="03", cells=RED_FLOOR),  # ids are exact, as in CHAIN
        "place 9 (1,1,1)",
    ):
        result = state().step_text(text)
        assert result.code == "PieceNotFound", text
        assert "[PieceNotFound]" in result.feedback


def test_ids_only_mean_something_on_levels_that_have_them() -> None:
    s = new_state(soma_level())
    result = s.step_text(call("place", piece_id="0", cells=[[1, 1, 1]]))
    assert result.error == "illegal" and result.code == "PieceNotFound"
    assert "(id" not in result.feedback and "[PieceNotFound]" not in result.feedback
    assert s.step_text("pickup 2").code == "PieceNotFound"


def test_numbers_after_place_without_an_id_stay_unparseable() -> None:
    for text in ("place 1 1 1 2 1 1", "place (1,1,1) (2,1,1)", "pickup"):
        assert state().step_text(text).error == "unparseable", text


# ---------------------------------------------------------------------------------------------
# The state action
# ---------------------------------------------------------------------------------------------


@pytest.mark.parametrize("family", ["stacking", "disassemble", "assemble"])
def test_state_costs_a_step_and_changes_nothing(family: str) -> None:
    if family == "stacking":
        s = new_state(soma_level())
    else:
        s = new_state(next(lv for lv in puzzle_levels() if lv.goal == family))
    key, legal = s.key(), list(s.legal_actions())
    result = s.step_text("state")
    assert result.legal and result.action == StateAction() and result.code is None
    assert s.steps_used == 1 and s.key() == key and list(s.legal_actions()) == legal
    assert StateAction() not in legal  # not offered: baselines and searches never see it
    assert result.feedback.startswith("OK: nothing changed. The state:\n")
    assert s.history[-1].feedback == result.feedback
    assert s.pop() == StateAction() and s.steps_used == 0
    s.apply(FinishAction())
    after = s.step_text(call("state"))
    assert after.error == "illegal" and "game is over" in after.feedback


def test_state_action_round_trips() -> None:
    action = StateAction()
    assert action.to_text() == "state" and parse_text("state") == action
    assert action_from_json(action_to_json(action)) == action
    assert sorted([StateAction(), FinishAction()]) == [FinishAction(), StateAction()]


# ---------------------------------------------------------------------------------------------
# Levels: ids in the file, the profile in the prompt
# ---------------------------------------------------------------------------------------------


def _chain_level_json() -> dict[str, Any]:
    level = import_chain_file(DATA / TRAY, None, None, "chain")
    data: dict[str, Any] = json.loads(level_bytes(level))
    return data


def test_chain_ids_round_trip_and_are_validated() -> None:
    data = _chain_level_json()
    level = parse_level(copy.deepcopy(data))
    assert json.loads(level_bytes(level)) == data
    bad: list[tuple[Any, str]] = [(7, "expected a string"), ("01", "index"), ("a", "index")]
    for value, why in bad:
        broken = copy.deepcopy(data)
        broken["pieces"][1]["chain_id"] = value
        with pytest.raises(LevelError, match=why):
            parse_level(broken)
    broken = copy.deepcopy(data)
    broken["pieces"][1]["chain_id"] = "0"
    with pytest.raises(LevelError, match="duplicate chain_id"):
        parse_level(broken)
    broken = copy.deepcopy(data)
    del broken["pieces"][1]["chain_id"]
    with pytest.raises(LevelError, match="every piece or none"):
        parse_level(broken)
    broken = copy.deepcopy(data)
    broken["pieces"][1]["chainid"] = "1"
    with pytest.raises(LevelError, match="unknown field"):
        parse_level(broken)
    broken = copy.deepcopy(data)
    broken["rules"]["profile"] = "default"  # the default is never written
    with pytest.raises(LevelError, match=r"rules\.profile"):
        parse_level(broken)


def test_prompt_tells_the_chain_rules_only_on_chain_levels() -> None:
    s = state()
    text = instruction(s)
    assert '{"tool": "place"' in text and "state  show" in text
    assert "may not leave another piece floating" not in text
    assert color_table(s)["red"].endswith(", CHAIN id 0")
    plain = new_state(soma_level())
    assert "tool" not in instruction(plain) and "may not leave" in instruction(plain)
    assert "CHAIN" not in "".join(color_table(plain).values())


# ---------------------------------------------------------------------------------------------
# Hostile text in the dialect
# ---------------------------------------------------------------------------------------------

_JSON_TOKENS = (
    *('{"tool": "place"', '{"tool": "pickup"', '{"tool": "state"}', '"piece_id":', '"cells":'),
    *("[", "]", "{", "}", ",", ":", '"0"', "0", "1", "2", "-1", "1e400", "NaN", "true", "null"),
    *("9" * 30, "1.5", '"', "\\", "<action>", "</action>", "```", '"arguments":', "\u0661"),
)


@settings(max_examples=300, suppress_health_check=[HealthCheck.too_slow], deadline=None)
@given(parts=st.lists(st.sampled_from(_JSON_TOKENS), max_size=16), sep=st.sampled_from(" ,"))
def test_step_text_on_json_shaped_text(parts: list[str], sep: str) -> None:
    _, seconds = check_turn(state(), sep.join(parts))
    assert seconds < 1.0


# ---------------------------------------------------------------------------------------------
# A model that only speaks CHAIN's format plays a whole level
# ---------------------------------------------------------------------------------------------

PLAN = [
    call("state"),
    call("place", piece_id="1", cells=[[1, 1, 2], [2, 1, 2], [1, 2, 2], [1, 1, 3]]),  # floats
    call("place", piece_id="0", cells=RED_FLOOR),
    call("place", piece_id="1", cells=[[1, 1, 2], [2, 1, 2], [1, 2, 2], [1, 1, 3]]),
    call("place", piece_id="2", cells=[[2, 2, 2], [2, 1, 3], [1, 2, 3], [2, 2, 3]]),
    call("finish"),
]


def test_replay_agent_plays_a_converted_level_in_chain_json(tmp_path: Path) -> None:
    level = import_chain_file(DATA / TRAY, None, None, "chain")
    save_level(level, tmp_path / "levels" / f"{level.id}.json")
    plans = tmp_path / "plans.json"
    plans.write_text(json.dumps({level.id: PLAN}))
    out = tmp_path / "runs"
    args = ["eval", "--levels", str(tmp_path / "levels"), "--agent", "replay"]
    args += ["--agent-option", f"file={plans}", "--out", str(out), "--no-progress"]
    assert main(args) == 0
    (rec,) = [json.loads(x) for x in (out / "replay-interactive" / "episodes.jsonl").open()]
    assert rec["success"] is True
    # The episode ends on the solving step, before the plan's finish.
    assert [s["legal"] for s in rec["steps"]] == [True, False, True, True, True]
    assert rec["steps"][0]["action"] == "state"
    assert "[Floating]" in rec["steps"][1]["feedback"]


def test_a_model_answering_in_chain_json_solves_a_converted_level(tmp_path: Path) -> None:
    from tests.support.fake_openai import Script, fake_openai, reply

    level = import_chain_file(DATA / TRAY, None, None, "chain")
    path = save_level(level, tmp_path / f"{level.id}.json")
    script = Script([reply(f"I will call a tool. <action>{a}</action>") for a in PLAN])
    with fake_openai(script) as url:
        args = ["eval", "--levels", str(path), "--agent", "openai", "--model", "fake"]
        args += ["--base-url", url, "--out", str(tmp_path / "m"), "--no-progress"]
        assert main(args) == 0
    assert script.problems == []
    (rec,) = [
        json.loads(x) for x in (tmp_path / "m" / "fake-interactive" / "episodes.jsonl").open()
    ]
    assert rec["success"] is True and len(rec["steps"]) == 5
    assert rec["steps"][1]["error"] == "illegal" and "[Floating]" in rec["steps"][1]["feedback"]
    # The model saw the state action's answer in its next observation.
    assert "In the tray" in json.dumps(script.requests[1])


def test_gym_env_on_a_chain_level_reports_codes_and_state() -> None:
    import warnings

    from gymnasium.utils.env_checker import check_env

    from chaingeo.envs.gym import StackingEnv

    level = import_chain_file(DATA / TRAY, None, None, "chain")
    env = StackingEnv([level], images=False, text_state=True)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        warnings.filterwarnings("ignore", message=".*environment not having a spec.*")
        check_env(env, skip_render_check=True)
    env.reset(options={"level": level.id})
    _, _, terminated, _, info = env.step(call("state"))
    assert info["legal"] and info["code"] is None and info["steps_used"] == 1
    assert "In the tray" in info["feedback"] and not terminated
    floating = call("place", piece_id="1", cells=[[1, 1, 2], [2, 1, 2], [1, 2, 2], [1, 1, 3]])
    info = env.step(floating)[4]
    assert info["error"] == "illegal" and info["code"] == "Floating"
