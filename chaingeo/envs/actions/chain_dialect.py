"""CHAIN's dialect of agent actions: its JSON tool calls and its piece ids.

CHAIN's stacking game is driven by tool calls; an agent that speaks it writes one JSON object
per turn, optionally between ``<action>`` and ``</action>`` (or in a code fence)::

    {"tool": "place", "piece_id": "2", "cells": [[1, 1, 1], [2, 1, 1], [2, 2, 1]]}
    {"tool": "pickup", "piece_id": "0"}
    {"tool": "state"}
    {"tool": "finish"}

Cells are 1-based, as in our text. ``piece_id`` is CHAIN's id (a string or a number: the
piece's index in CHAIN's level file), or one of our colour names; ids resolve through the
level's :attr:`chaingeo.core.level.Piece.chain_id` (:func:`resolve_id`). The arguments may also
come nested, as tool-call APIs send them: ``{"tool": "place", "arguments": {...}}`` (an object
or a JSON string of one), and ``name`` may stand for ``tool``. Tool names are forgiving
(``place_piece``, ``pickup_piece``, ``get_state``, ``check``...); arguments are strict.

The text is read with ``json.loads`` only, after :mod:`chaingeo.core.limits` bounds its
length (by the caller) and nesting; integer literals longer than an agent number may be are
refused before Python builds them. Every problem is one of the typed action errors:
:class:`UnparseableActionError` for anything that is not such a call,
:class:`IllegalActionError` for well-formed calls no rule accepts (numbers too large), and
:class:`PlacementCellsError` for a placement whose cell list is empty or repeats a cell: which
of CHAIN's errors that is depends on the state (:func:`cells_rejection`).
"""

from __future__ import annotations

import json
from collections.abc import Mapping, Sequence
from typing import Any, Final, Protocol

from chaingeo.core import limits
from chaingeo.core.errors import ChainGeoError
from chaingeo.core.level import Level
from chaingeo.core.rules import Rejection, StackingRules
from chaingeo.envs.actions.types import (
    Action,
    Cell,
    FinishAction,
    IllegalActionError,
    MoveRequest,
    PickupAction,
    PlaceAction,
    StateAction,
    TurnRequest,
    UnparseableActionError,
    cell_from_agent,
    cell_text,
)

HINT: Final = (
    'a CHAIN tool call is one JSON object: {"tool": "place", "piece_id": "2", "cells": '
    '[[x,y,z], ...]} (every cell the piece fills, 1-based), {"tool": "pickup", "piece_id": '
    '"2"}, {"tool": "state"} or {"tool": "finish"}'
)
_TOOLS: Final[dict[str, str]] = {
    "place": "place",
    "place_piece": "place",
    "place_piece_by_cells": "place",
    "pickup": "pickup",
    "pick_up": "pickup",
    "pickup_piece": "pickup",
    "state": "state",
    "get_state": "state",
    "finish": "finish",
    "check": "finish",
    "done": "finish",
}
_ARGS: Final[dict[str, frozenset[str]]] = {
    "place": frozenset({"piece_id", "cells"}),
    "pickup": frozenset({"piece_id"}),
    "state": frozenset(),
    "finish": frozenset(),
}
_NESTED: Final = ("arguments", "parameters", "args")
_OPEN_TAG: Final = "<action>"
_CLOSE_TAG: Final = "</action>"
_FENCE: Final = "```"


class PlacementCellsError(IllegalActionError):
    """A placement listing no cell, or a cell twice. CHAIN checks the piece first (unknown,
    already placed), then counts the cells as given (repeats included): a wrong count is
    ``WrongCount``, the right count ``ShapeMismatch``. ``piece`` is as written (maybe an id);
    ``count`` counts the cells as given, ``cells`` the distinct ones (0-based)."""

    def __init__(self, reason: str, piece: str, count: int, cells: Sequence[Cell]) -> None:
        super().__init__(reason)
        self.piece = piece
        self.count = count
        self.cells = tuple(cells)


class _Bad(ChainGeoError):
    """Not a CHAIN tool call; ``hint`` says what is wrong."""

    def __init__(self, hint: str) -> None:
        super().__init__(hint)
        self.hint = hint


class _TooBig(ChainGeoError):
    pass


# ---------------------------------------------------------------------------------------------
# Recognising the dialect
# ---------------------------------------------------------------------------------------------


def unwrap(text: str) -> str:
    """The text between ``<action>`` and ``</action>`` and inside a code fence, if it is so
    wrapped (linear: no regular expression backtracks over hostile text)."""
    s = text.strip()
    if s[: len(_OPEN_TAG)].lower() == _OPEN_TAG and s[-len(_CLOSE_TAG) :].lower() == _CLOSE_TAG:
        s = s[len(_OPEN_TAG) : len(s) - len(_CLOSE_TAG)].strip()
    if len(s) >= 2 * len(_FENCE) and s.startswith(_FENCE) and s.endswith(_FENCE):
        s = s[len(_FENCE) : -len(_FENCE)].strip()
        if s[:4].lower() == "json":
            s = s[4:].strip()
    return s


def is_tool_call(body: str) -> bool:
    """True when unwrapped text is meant as JSON (it starts with ``{``)."""
    return body.startswith("{")


# ---------------------------------------------------------------------------------------------
# Parsing
# ---------------------------------------------------------------------------------------------


def _int(literal: str) -> int:
    if len(literal.lstrip("-").lstrip("0")) > limits.MAX_AGENT_DIGITS:
        raise _TooBig
    return int(literal)


def _constant(name: str) -> Any:
    raise _Bad(f"{name} is not a number")


class AgentJsonError(ChainGeoError, ValueError):
    """Agent JSON that is malformed or past a limit of :mod:`chaingeo.core.limits` (length,
    nesting, digits); ``too_big``: an integer longer than an agent number may be."""

    def __init__(self, reason: str, too_big: bool = False) -> None:
        super().__init__(reason)
        self.reason = reason
        self.too_big = too_big


def loads_agent_json(body: str, max_chars: int = limits.MAX_TEXT_CHARS) -> Any:
    """``json.loads`` on untrusted agent JSON (a CHAIN tool call, a model's tool-call
    arguments) within the agent-text limits: at most ``max_chars`` characters and
    :data:`~chaingeo.core.limits.MAX_JSON_DEPTH` levels (checked before the decoder recurses),
    integers of at most :data:`~chaingeo.core.limits.MAX_AGENT_DIGITS` digits (refused before
    Python builds them), no ``NaN``/``Infinity``. :class:`AgentJsonError` otherwise."""
    if len(body) > max_chars:
        raise AgentJsonError(f"{len(body)} characters of JSON; at most {max_chars}")
    depth = limits.json_depth(body)
    if depth > limits.MAX_JSON_DEPTH:
        raise AgentJsonError(f"JSON nested {depth} deep")
    try:
        return json.loads(body, parse_int=_int, parse_constant=_constant)
    except _TooBig:
        raise AgentJsonError(
            f"a number of more than {limits.MAX_AGENT_DIGITS} digits", too_big=True
        ) from None
    except _Bad as e:
        raise AgentJsonError(e.hint) from None
    except json.JSONDecodeError as e:
        raise AgentJsonError(f"not valid JSON ({e.msg} at character {e.pos + 1})") from None
    except (RecursionError, ValueError) as e:  # defensive: json's own limits
        raise AgentJsonError(f"not valid JSON ({type(e).__name__})") from None


def _loads(body: str) -> Any:
    try:
        return loads_agent_json(body)
    except AgentJsonError as e:
        if e.too_big:
            raise _TooBig from None
        raise _Bad(e.reason) from None


def _number(value: Any, where: str) -> int:
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise _Bad(f"{where} must be whole numbers, got {_shown(value)}")
    if isinstance(value, float):
        if value != value or value in (float("inf"), float("-inf")):
            raise _TooBig
        if not value.is_integer():
            raise _Bad(f"{where} must be whole numbers, got {value}")
        value = int(value)
    if abs(value) > limits.MAX_AGENT_NUMBER:
        raise _TooBig
    return int(value)


def _shown(value: Any) -> str:
    text = json.dumps(value)
    return text if len(text) <= 40 else text[:37] + "..."


def _arguments(obj: Mapping[str, Any]) -> tuple[str, Mapping[str, Any]]:
    """The tool (one of ours) and its arguments, flat or nested."""
    key = "tool" if "tool" in obj else "name" if "name" in obj else None
    if key is None:
        raise _Bad("the object has no 'tool'")
    tool = obj[key]
    if not isinstance(tool, str) or tool.strip().lower() not in _TOOLS:
        raise _Bad(f"unknown tool {_shown(tool)}")
    rest = {k: v for k, v in obj.items() if k != key}
    nested = [k for k in _NESTED if k in rest]
    if nested:
        if len(rest) != 1:
            raise _Bad(f"give the arguments either flat or in '{nested[0]}', not both")
        inner = rest[nested[0]]
        if isinstance(inner, str):
            inner = _loads(inner.strip() or "{}")
        if not isinstance(inner, dict):
            raise _Bad(f"'{nested[0]}' must be an object")
        rest = inner
    return _TOOLS[tool.strip().lower()], rest


def _piece(args: Mapping[str, Any]) -> str:
    if "piece_id" not in args:
        raise _Bad("'piece_id' is missing")
    value = args["piece_id"]
    if isinstance(value, str):
        return value.strip().lower()
    if isinstance(value, int | float) and not isinstance(value, bool):
        return str(_number(value, "piece_id"))
    raise _Bad(f"'piece_id' must be a string or a number, got {_shown(value)}")


def _place(args: Mapping[str, Any]) -> PlaceAction:
    piece = _piece(args)
    if "cells" not in args:
        raise _Bad("'cells' is missing")
    raw = args["cells"]
    if not isinstance(raw, list):
        raise _Bad(f"'cells' must be a list of [x, y, z], got {_shown(raw)}")
    cells: list[Cell] = []
    for c in raw:
        if not isinstance(c, list) or len(c) != 3:
            raise _Bad(f"every cell is [x, y, z], got {_shown(c)}")
        cells.append(cell_from_agent([_number(v, "coordinates") for v in c]))
    distinct = sorted(set(cells))
    if not piece:
        raise IllegalActionError("unknown piece ''", code="PieceNotFound")
    if not cells:
        raise PlacementCellsError("no cells were given", piece, 0, ())
    if len(distinct) != len(cells):
        twice = next(c for c in distinct if cells.count(c) > 1)
        raise PlacementCellsError(
            f"cell {cell_text(twice)} is listed twice", piece, len(cells), distinct
        )
    return PlaceAction(piece, tuple(cells))


def parse_tool_call(text: str, body: str) -> Action:
    """Read one CHAIN tool call (``body``: the unwrapped ``text``) as a stateless action:
    piece ids stay as written (see :func:`resolve_id`). Raises the typed action errors."""
    try:
        obj = _loads(body)
        if not isinstance(obj, dict):
            raise _Bad("a tool call is a JSON object")
        tool, args = _arguments(obj)
        extra = sorted(set(args) - _ARGS[tool])
        if extra:
            raise _Bad(f"{_shown(extra[0])} is not an argument of {tool}")
        if tool == "place":
            return _place(args)
        if tool == "pickup":
            piece = _piece(args)
            if not piece:
                raise IllegalActionError("unknown piece ''", code="PieceNotFound")
            return PickupAction(piece)
        return StateAction() if tool == "state" else FinishAction()
    except _Bad as e:
        raise UnparseableActionError(text, f"{e.hint}; {HINT}") from None
    except _TooBig:
        raise IllegalActionError(
            f"numbers in an action are at most {limits.MAX_AGENT_NUMBER}", text=text
        ) from None


# ---------------------------------------------------------------------------------------------
# CHAIN's piece ids, and refusals that depend on the state
# ---------------------------------------------------------------------------------------------


def resolve_id(name: str, level: Level) -> str:
    """The colour name a piece is called by: ``name`` itself if it is one, else the piece
    whose CHAIN id it is, else ``name`` unchanged (unknown: the caller says so)."""
    for p in level.pieces:
        if p.name == name:
            return name
    for p in level.pieces:
        if p.chain_id is not None and p.chain_id == name:
            return p.name
    return name


def resolve_ids(
    action: Action | MoveRequest | TurnRequest, level: Level
) -> Action | MoveRequest | TurnRequest:
    """A parsed place or pickup with a CHAIN id replaced by the colour name (else as is)."""
    if isinstance(action, PlaceAction):
        name = resolve_id(action.piece, level)
        return action if name == action.piece else PlaceAction(name, action.cells)
    if isinstance(action, PickupAction):
        name = resolve_id(action.piece, level)
        return action if name == action.piece else PickupAction(name)
    return action


class _Rejecting(Protocol):
    def rejection(self, action: Action) -> Rejection | None: ...


def cells_rejection(
    error: PlacementCellsError, name: str, level: Level, state: _Rejecting
) -> Rejection:
    """CHAIN's verdict on an empty or repeating cell list for the known piece ``name``:
    ``PieceAlreadyPlaced`` if it is, else ``WrongCount`` / ``ShapeMismatch`` by the count of
    cells as given. Puzzle levels: no code."""
    over = state.rejection(FinishAction())
    if over is not None:  # the game is over
        return over
    if not isinstance(level.rules, StackingRules):
        return Rejection(error.reason)
    probe = state.rejection(PlaceAction(name, error.cells or ((0, 0, 0),)))
    if probe is not None and probe.code == "PieceAlreadyPlaced":
        return probe
    size = len(level.piece(name).shape)
    if error.count != size:
        why = Rejection(
            f"{name} has {size} cubes but {error.count} cells were given ({error.reason})",
            "WrongCount",
        )
    else:
        why = Rejection(error.reason, "ShapeMismatch")
    return level.rules.tag(why)


def piece_list(level: Level) -> str:
    """The pieces as an unknown-piece refusal lists them (with CHAIN's ids where present)."""
    return ", ".join(
        sorted(
            p.name if p.chain_id is None else f"{p.name} (id {p.chain_id})" for p in level.pieces
        )
    )
