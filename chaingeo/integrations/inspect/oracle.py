"""The oracle as a model would answer: each level's stored plan written in the dialect.

``agent=oracle`` makes no model call; its replies go through the same reading
(:func:`~chaingeo.evaluation.agents.dialects.read_reply`) and playing as a model's, so a task
that scores 1.0 with NormDist 0 on every level has checked the observations, the dialects, the
tool translation and the scoring end to end.
"""

from __future__ import annotations

from typing import Any

from inspect_ai.model import ChatMessageAssistant, ModelOutput
from inspect_ai.tool import ToolCall

from chaingeo.core.level import Level
from chaingeo.core.turns import ANGLES
from chaingeo.envs.actions.parse import parse_text
from chaingeo.envs.actions.types import (
    FinishAction,
    MoveRequest,
    PickupAction,
    PlaceAction,
    StateAction,
    TurnRequest,
)
from chaingeo.evaluation.agents.baselines import oracle_plan
from chaingeo.evaluation.agents.dialects import DIALECTS
from chaingeo.evaluation.episode import Episode

ORACLE = "chaingeo/oracle"


def call_of(text: str, family: str) -> tuple[str, dict[str, Any]]:
    """An action's text as the tool call that says it (the inverse of the tools' translation;
    cells and offsets 1-based, as a model writes them)."""
    action = parse_text(text, family)
    if isinstance(action, PlaceAction):
        cells = [[c + 1 for c in cell] for cell in action.cells]
        return "place", {"piece": action.piece, "cells": cells}
    if isinstance(action, PickupAction):
        return "pickup", {"piece": action.piece}
    if isinstance(action, MoveRequest):
        args: dict[str, Any] = {
            "pieces": list(action.pieces),
            "direction": action.direction,
            "distance": "inf" if action.distance is None else action.distance,
        }
        if action.into is not None:
            args["into"] = list(action.into)
        if action.offset is not None:
            args["offset"] = list(action.offset)
        return "move", args
    if isinstance(action, TurnRequest):
        angle = int(ANGLES[action.quarter])
        return "rotate", {"pieces": list(action.pieces), "axis": action.axis, "angle": angle}
    if isinstance(action, StateAction | FinishAction):
        return ("state" if isinstance(action, StateAction) else "finish"), {}
    raise ValueError(f"no tool call says {text!r}")


def oracle_output(level: Level, episode: Episode, dialect: str, turn: int) -> ModelOutput:
    """The oracle's reply on ``turn``: the plan's next action (interactive) or all of it."""
    plan = oracle_plan(level)
    todo = plan if episode.oneshot else plan[turn : turn + 1] or ["finish"]
    if DIALECTS.get(dialect).uses_tools:
        calls = []
        for i, text in enumerate(todo):
            name, args = call_of(text, level.family)
            calls.append(ToolCall(id=f"oracle_{turn}_{i}", function=name, arguments=args))
        message = ChatMessageAssistant(content="", tool_calls=calls, model=ORACLE)
        return ModelOutput.from_message(message)
    if episode.oneshot:
        text = "<plan>\n" + "\n".join(todo) + "\n</plan>"
    else:
        text = f"<action>{todo[0]}</action>"
    return ModelOutput.from_content(ORACLE, text)
