"""Native tool calling: one function per action kind, and its translation into action text.

A model that speaks OpenAI tool calls is offered the functions its level's actions need:
``place {piece, cells}`` and ``pickup {piece}`` in stacking, ``move {pieces, direction,
distance}`` in puzzles (plus ``into``/``offset`` in assembly), ``rotate {pieces, axis, angle}``
only where the level's rules allow turns, and ``state {}``/``finish {}`` everywhere. Each call is
translated into the canonical action text of :mod:`chaingeo.envs.actions.types` by plain string
building (``place red (1,1,1) (2,1,1)``, ``pickup red``, ``move red+blue -z inf``), so the
environment's own parser judges it like any typed action. The arguments are read with
``json.loads`` only, within the agent-text limits of :mod:`chaingeo.core.limits` (length,
nesting, digits: :func:`chaingeo.envs.actions.chain_dialect.loads_agent_json`), and checked strictly
against the schema offered (types, allowed fields); a call that fails becomes an action text
starting with ``!``, which no grammar accepts: the environment rejects it as unparseable and
counts the step, and the agent is told why.
"""

from __future__ import annotations

import json
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any, Final

from chaingeo.core import limits
from chaingeo.core.errors import ChainGeoError
from chaingeo.core.level import Level
from chaingeo.envs.actions.chain_dialect import AgentJsonError, loads_agent_json

DIRECTIONS: Final = ("+x", "-x", "+y", "-y", "+z", "-z")
AXES: Final = ("x", "y", "z")
#: Quarter turns either way (right hand about +axis), as ``rotate GROUP AXIS +90|-90`` reads.
ANGLES: Final = (90, -90)
#: Fields of a level's rules that, when exactly ``True``, allow turning pieces.
TURN_FIELDS: Final = ("turns", "rotations")
#: What a malformed call's action text starts with: a character no action grammar accepts.
MALFORMED: Final = "!"

# A piece name as the environment's tokeniser reads one (colour names such as ``light-blue``).
_NAME_RE: Final = re.compile(r"[A-Za-z][A-Za-z0-9_]*(?:-[A-Za-z0-9_]+)*")
_MAX_SHOWN: Final = 40  # characters of a model-supplied string quoted in a problem


def _name_schema(what: str) -> dict[str, Any]:
    return {"type": "string", "description": what}


def _group_schema(what: str) -> dict[str, Any]:
    return {
        "type": "array",
        "items": {"type": "string"},
        "minItems": 1,
        "description": what,
    }


def _triple(what: str) -> dict[str, Any]:
    return {
        "type": "array",
        "items": {"type": "integer"},
        "minItems": 3,
        "maxItems": 3,
        "description": what,
    }


def _function(
    name: str, description: str, properties: dict[str, Any], required: Sequence[str] = ()
) -> dict[str, Any]:
    return {
        "type": "function",
        "function": {
            "name": name,
            "description": description,
            "parameters": {
                "type": "object",
                "properties": properties,
                "required": list(required),
                "additionalProperties": False,
            },
        },
    }


PLACE: Final = _function(
    "place",
    "Put a tray piece into the box so that it fills exactly the cells listed (1-based); the "
    "engine finds the rotation.",
    {
        "piece": _name_schema("the piece's colour name, e.g. red"),
        "cells": {
            "type": "array",
            "items": _triple("one cell [x, y, z], 1-based"),
            "minItems": 1,
            "description": "every cell the piece will fill",
        },
    },
    ("piece", "cells"),
)
PICKUP: Final = _function(
    "pickup",
    "Take a placed piece back to the tray.",
    {"piece": _name_schema("the piece's colour name")},
    ("piece",),
)
_MOVE_PROPS: Final[dict[str, Any]] = {
    "pieces": _group_schema("the colour names of the pieces moving together"),
    "direction": {"type": "string", "enum": list(DIRECTIONS)},
    "distance": {
        "anyOf": [{"type": "integer", "minimum": 1}, {"type": "string", "enum": ["inf"]}],
        "description": 'how many units, or "inf" to slide out (or in) from afar',
    },
}


def _move(description: str, **extra: dict[str, Any]) -> dict[str, Any]:
    """The ``move`` tool: the slide's own arguments, required, and any optional ``extra``."""
    return _function("move", description, {**_MOVE_PROPS, **extra}, tuple(_MOVE_PROPS))


MOVE: Final = _move("Slide a group of pieces along an axis by a number of units, or to infinity.")
MOVE_ASSEMBLE: Final = _move(
    "Slide a group of pieces along an axis by a number of units, or bring a whole part in "
    'from afar (distance "inf"), optionally saying which part it joins and where it lands.',
    into=_group_schema("assembly: the part it joins (colour names)"),
    offset=_triple("assembly: [dx, dy, dz] from its place in the target; [0,0,0] exact"),
)
ROTATE: Final = _function(
    "rotate",
    "Turn a group of pieces a quarter turn about a line parallel to an axis (right hand about "
    "+axis for 90, the other way for -90); the engine finds the turn centre when only one fits.",
    {
        "pieces": _group_schema("the colour names of the pieces turning together"),
        "axis": {"type": "string", "enum": list(AXES)},
        "angle": {"type": "integer", "enum": list(ANGLES), "description": "degrees"},
    },
    ("pieces", "axis", "angle"),
)
STATE: Final = _function(
    "state",
    "Show the current state as text (every piece's cells). Costs a step like any action.",
    {},
)
FINISH: Final = _function("finish", "Declare the task done; the episode ends.", {})


def turns_allowed(level: Level) -> bool:
    """Whether the level's rules allow turning pieces (a rules field such as ``turns`` that is
    exactly ``True``: :class:`chaingeo.core.rules.PuzzleRules` ``turns``)."""
    return any(getattr(level.rules, f, False) is True for f in TURN_FIELDS)


def tool_specs(level: Level, *, state: bool = True) -> list[dict[str, Any]]:
    """The functions offered for ``level``, in a fixed order (``state`` only when asked: it is
    useless in the one-shot protocol, which never sees a result)."""
    tools: list[dict[str, Any]] = []
    if level.family == "stacking":
        tools += [PLACE, PICKUP]
    else:
        tools.append(MOVE_ASSEMBLE if level.goal == "assemble" else MOVE)
    if turns_allowed(level):
        tools.append(ROTATE)
    if state:
        tools.append(STATE)
    tools.append(FINISH)
    return tools


# ---------------------------------------------------------------------------------------------
# Translation
# ---------------------------------------------------------------------------------------------


class _Malformed(ChainGeoError):
    pass


def _shown(value: Any) -> str:
    text = " ".join(str(value).split())
    return repr(text if len(text) <= _MAX_SHOWN else text[: _MAX_SHOWN - 3] + "...")


def _is_int(value: Any) -> bool:
    return isinstance(value, int) and not isinstance(value, bool)


def _name(value: Any, where: str) -> str:
    if not isinstance(value, str) or not _NAME_RE.fullmatch(value):
        raise _Malformed(f"{where} must be a colour name, got {_shown(value)}")
    return value


def _group(value: Any, where: str) -> str:
    if not isinstance(value, list) or not value:
        raise _Malformed(f"{where} must be a non-empty list of colour names")
    return "+".join(_name(v, f"{where}[{i}]") for i, v in enumerate(value))


def _ints(value: Any, where: str) -> list[int]:
    if not isinstance(value, list) or len(value) != 3 or not all(_is_int(v) for v in value):
        raise _Malformed(f"{where} must be three integers [x, y, z]")
    return list(value)


def _cells(value: Any) -> str:
    if not isinstance(value, list) or not value:
        raise _Malformed("cells must be a non-empty list of [x, y, z] cells")
    return " ".join("({},{},{})".format(*_ints(c, f"cells[{i}]")) for i, c in enumerate(value))


def _distance(value: Any) -> str:
    if value == "inf" and isinstance(value, str):
        return "inf"
    if not _is_int(value) or value < 1:
        raise _Malformed(f'distance must be a positive integer or "inf", got {_shown(value)}')
    return str(value)


def _choice(value: Any, options: Sequence[Any], where: str) -> str:
    if isinstance(value, bool) or value not in options or type(value) is not type(options[0]):
        listed = ", ".join(str(o) for o in options)
        raise _Malformed(f"{where} must be one of {listed}, got {_shown(value)}")
    return str(value)


def _text(name: str, args: Mapping[str, Any]) -> str:
    if name == "place":
        return f"place {_name(args['piece'], 'piece')} {_cells(args['cells'])}"
    if name == "pickup":
        return f"pickup {_name(args['piece'], 'piece')}"
    if name == "move":
        text = (
            f"move {_group(args['pieces'], 'pieces')}"
            f" {_choice(args['direction'], DIRECTIONS, 'direction')}"
            f" {_distance(args['distance'])}"
        )
        if "into" in args:
            text += f" into {_group(args['into'], 'into')}"
        if "offset" in args:
            text += " offset ({},{},{})".format(*_ints(args["offset"], "offset"))
        return text
    if name == "rotate":
        return (
            f"rotate {_group(args['pieces'], 'pieces')} {_choice(args['axis'], AXES, 'axis')}"
            f" {int(_choice(args['angle'], ANGLES, 'angle')):+d}"
        )
    if name in ("state", "finish"):
        return name
    raise AssertionError(f"no translation for tool {name!r}")


@dataclass(frozen=True)
class Translation:
    action: str  # the action text sent to the environment
    problem: str | None = None  # why the call was malformed (its action text then starts "!")


def _arguments(arguments: Any) -> Any:
    """A call's arguments decoded; :class:`_Malformed` saying why when its text is not JSON
    within the agent-text limits (length, nesting, digits of every number). Arguments a server
    sent already decoded go through the same limits as their JSON text."""
    if arguments is None:
        return {}
    if not isinstance(arguments, str):  # decoded by the server: measured as the text it was
        try:
            arguments = json.dumps(arguments)
        except (TypeError, ValueError, RecursionError):
            return arguments  # no JSON value at all: refused as not an object
    if not arguments.strip():
        return {}  # an empty argument string: a call with no arguments
    try:
        return loads_agent_json(arguments, limits.MAX_TOOL_ARGUMENT_CHARS)
    except AgentJsonError as e:
        raise _Malformed(f"the arguments are not usable JSON: {e.reason}") from None


def parse_arguments(arguments: Any) -> Any:
    """A call's arguments: a JSON object's text (decoded with ``json.loads`` only, within the
    agent-text limits), or an object some servers send already decoded (none or empty text: no
    arguments). Anything else, or text past a limit, comes back as is, to be refused."""
    try:
        return _arguments(arguments)
    except _Malformed:
        return arguments


def translate(name: Any, arguments: Any, offered: Sequence[Mapping[str, Any]]) -> Translation:
    """The action text of one tool call, checked against the functions ``offered``."""
    schemas = {t["function"]["name"]: t["function"]["parameters"] for t in offered}
    shown_name = name if isinstance(name, str) and _NAME_RE.fullmatch(name) else "tool"
    try:
        if not isinstance(name, str) or name not in schemas:
            raise _Malformed(f"there is no tool named {_shown(name)} here")
        args = _arguments(arguments)
        if not isinstance(args, dict):
            raise _Malformed("the arguments are not a JSON object")
        schema = schemas[name]
        extra = sorted(set(args) - set(schema["properties"]))
        if extra:
            raise _Malformed(f"unexpected field {_shown(extra[0])}")
        missing = [k for k in schema["required"] if k not in args]
        if missing:
            raise _Malformed(f"missing field {missing[0]!r}")
        return Translation(_text(name, args))
    except _Malformed as e:
        problem = str(e)
        return Translation(f"{MALFORMED}malformed {shown_name} call: {problem}", problem)


def skipped_result(rejected: int) -> str:
    """The tool result of a call that was not executed (calls are 1-based in the text)."""
    return (
        f"Not executed: call {rejected + 1} of this reply was rejected, so the calls after it "
        "were skipped. Nothing changed."
    )
