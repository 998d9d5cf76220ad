"""Actions: their types, one canonical text form and a JSON form (the parser of agent text is
:mod:`chaingeo.envs.actions.parse`).

Coordinates. Code and files are 0-based; text shown to or read from an agent is 1-based, as in
the original benchmark. **This module is the only place that converts**: :func:`cell_from_agent`
subtracts 1 from every cell an agent writes (the parser, :mod:`chaingeo.envs.actions.parse`, reads
cells through it), :meth:`PlaceAction.to_text` and :func:`cell_text` add 1, and
:func:`rules_text` rewrites the 0-based cells that engine messages quote (``(x, y, z)`` tuples,
as :func:`chaingeo.core.rules.placement_problem` writes them) into the agent's 1-based ``(x,y,z)``.
Offset vectors of puzzle insertions are displacements, not cells, so they are never converted.

Parsing is forgiving in syntax where that is unambiguous (case, spaces, commas, brackets, ``x+``
for ``+x``, ``inf``/``infinity``/``out``) and strict in meaning. :func:`parse_action` has three
typed outcomes besides success, as python-chess has: :class:`UnparseableActionError`,
:class:`IllegalActionError` (with the reason) and :class:`AmbiguousActionError` (with the
candidates); each carries feedback text for the agent and the key of the unchanged state.

Grammar (``GROUP`` is colour names joined by ``+``; ``DIR`` is ``+x -x +y -y +z -z``)::

    place COLOUR (x,y,z) (x,y,z) ...      every cell the piece will fill, 1-based
    pickup COLOUR                         take a placed piece back to the tray
    move GROUP DIR K | inf                slide a group K units, or out to infinity
    move GROUP DIR inf into GROUP offset (dx,dy,dz)   assembly: the part it joins, and how
                                          far from its place in the target it lands
    rotate GROUP AXIS +90|-90 [about (x,y,z)]   levels with turns: turn a group a quarter turn
                                          (right hand about +AXIS) about the line parallel to
                                          AXIS through that point (see :class:`TurnAction`)
    finish                                declare the task done (ends the episode)
    state                                 show every piece's cells (changes nothing; a step)
"""

from __future__ import annotations

import re
from collections.abc import Hashable, Iterable, Mapping, Sequence
from dataclasses import dataclass
from functools import total_ordering
from itertools import pairwise
from typing import Any, ClassVar, Final

from chaingeo.core.errors import ChainGeoError
from chaingeo.core.kinematics import Move
from chaingeo.core.rules import ChainCode
from chaingeo.core.turns import ANGLES, TurnMove, half_text, turn_from_json

Cell = tuple[int, int, int]

# ---------------------------------------------------------------------------------------------
# Coordinates: the one conversion between code (0-based) and agent text (1-based)
# ---------------------------------------------------------------------------------------------


def cell_text(cell: Sequence[int]) -> str:
    """A 0-based cell as the agent reads it: ``(0, 0, 2)`` -> ``"(1,1,3)"``."""
    return "(" + ",".join(str(int(v) + 1) for v in cell) + ")"


def cells_text(cells: Iterable[Sequence[int]]) -> str:
    return " ".join(cell_text(c) for c in cells)


def cell_from_agent(values: Sequence[int]) -> Cell:
    """A 1-based cell an agent wrote, in code coordinates."""
    x, y, z = values
    return (x - 1, y - 1, z - 1)


def centre_text(centre2: Sequence[int]) -> str:
    """A turn centre (doubled, 0-based cell units) as the agent reads it, 1-based in cell
    units: the centre of cell (1,1,1) is ``(1,1,1)``, the corner between cells 3 and 4 along x
    is 3.5: ``(6, 0, 0)`` -> ``"(4,1,1)"``, ``(5, 7, 0)`` -> ``"(3.5,4.5,1)"``."""
    return "(" + ",".join(half_text(int(v) + 2) for v in centre2) + ")"


def centre_from_agent(values2: Sequence[int]) -> Cell:
    """A centre an agent wrote (1-based cell units, doubled: 3.5 -> 7), in code units."""
    x, y, z = values2
    return (x - 2, y - 2, z - 2)


def vector_text(vec: Sequence[int]) -> str:
    """A displacement (never shifted by one): ``(0, -1, 0)`` -> ``"(0,-1,0)"``."""
    return "(" + ",".join(str(int(v)) for v in vec) + ")"


_TUPLE_RE: Final = re.compile(r"\((-?\d+), (-?\d+), (-?\d+)\)")


def rules_text(sentence: str) -> str:
    """Rewrite the 0-based ``(x, y, z)`` cells an engine message quotes into 1-based text."""
    return _TUPLE_RE.sub(lambda m: cell_text([int(m.group(i)) for i in (1, 2, 3)]), sentence)


# ---------------------------------------------------------------------------------------------
# Action types
# ---------------------------------------------------------------------------------------------


@total_ordering
class _Ordered:
    """Actions of different kinds sort together: places, pickups, moves, then finish."""

    RANK: ClassVar[int] = 0

    def sort_key(self) -> tuple[Any, ...]:
        raise NotImplementedError

    def __lt__(self, other: object) -> bool:
        if not isinstance(other, _Ordered):
            return NotImplemented
        return (self.RANK, self.sort_key()) < (other.RANK, other.sort_key())


def _check_name(name: str) -> None:
    if not isinstance(name, str) or not name:
        raise ValueError(f"a piece name must be a non-empty string, got {name!r}")


@dataclass(frozen=True, eq=True)
class PlaceAction(_Ordered):
    """Put a tray piece into the box so that it fills exactly ``cells`` (0-based, sorted)."""

    piece: str
    cells: tuple[Cell, ...]
    RANK: ClassVar[int] = 0

    def __post_init__(self) -> None:
        _check_name(self.piece)
        cells = tuple(sorted((int(x), int(y), int(z)) for x, y, z in self.cells))
        if not cells:
            raise ValueError("a placement needs at least one cell")
        for a, b in pairwise(cells):  # sorted: a repeat is adjacent
            if a == b:
                raise ValueError(f"cell {cell_text(a)} is listed twice")
        object.__setattr__(self, "cells", cells)

    @classmethod
    def trusted(cls, piece: str, cells: tuple[Cell, ...]) -> PlaceAction:
        """A placement from cells the caller built sorted, distinct and of ints (the engine's
        own tables): skips the checks, which cost more than the rest of a table's build."""
        action = object.__new__(cls)
        object.__setattr__(action, "piece", piece)
        object.__setattr__(action, "cells", cells)
        return action

    def sort_key(self) -> tuple[Any, ...]:
        return (self.piece, self.cells)

    def to_text(self) -> str:
        return f"place {self.piece} {cells_text(self.cells)}"


@dataclass(frozen=True, eq=True)
class PickupAction(_Ordered):
    """Take a placed piece out of the box, back to the tray in its original orientation."""

    piece: str
    RANK: ClassVar[int] = 1

    def __post_init__(self) -> None:
        _check_name(self.piece)

    def sort_key(self) -> tuple[Any, ...]:
        return (self.piece,)

    def to_text(self) -> str:
        return f"pickup {self.piece}"


@dataclass(frozen=True, eq=True)
class MoveAction(_Ordered):
    """A puzzle move (:class:`chaingeo.core.kinematics.Move`).

    ``into`` and ``offset`` only occur in assembly, on insertions (distance None): the whole
    part ``move.pieces`` comes in along ``move.direction`` from infinitely far and joins the
    part ``into`` (all its pieces, sorted). ``offset`` is where it lands, as a displacement
    from its place in the target relative to ``into``, measured between the first pieces (by
    name) of the two parts: ``(0, 0, 0)`` puts it exactly where the target has it. Left as
    None they are open, and the state resolves them (see
    :meth:`chaingeo.envs.machines.puzzle.PuzzleState.resolve`).
    """

    move: Move
    into: tuple[str, ...] | None = None
    offset: Cell | None = None
    RANK: ClassVar[int] = 2

    def __post_init__(self) -> None:
        if self.into is not None:
            if not self.into:
                raise ValueError("'into' needs at least one piece")
            for n in self.into:
                _check_name(n)
            into = tuple(sorted(set(self.into)))
            if set(into) & set(self.move.pieces):
                raise ValueError("a part cannot join itself")
            object.__setattr__(self, "into", into)
        if self.offset is not None:
            x, y, z = self.offset
            object.__setattr__(self, "offset", (int(x), int(y), int(z)))
        if (self.into is not None or self.offset is not None) and self.move.distance is not None:
            raise ValueError("'into' and 'offset' belong to insertions, which have distance inf")

    @property
    def pieces(self) -> tuple[str, ...]:
        return self.move.pieces

    def sort_key(self) -> tuple[Any, ...]:
        m = self.move
        return (
            m.pieces,
            m.direction,
            m.distance is None,
            m.distance or 0,
            self.into is not None,
            self.into or (),
            self.offset is not None,
            self.offset or (0, 0, 0),
        )

    def to_text(self) -> str:
        text = self.move.describe()
        if self.into is not None:
            text += f" into {'+'.join(self.into)}"
        if self.offset is not None:
            text += f" offset {vector_text(self.offset)}"
        return text


@dataclass(frozen=True, eq=True)
class TurnAction(_Ordered):
    """A puzzle turn (:class:`chaingeo.core.turns.TurnMove`, levels whose rules allow turns):
    the group turns by 90 degrees, right hand about the positive axis for ``+90``, about the
    line parallel to the axis through the centre. Text ``rotate GROUP AXIS +90|-90 about
    (x,y,z)``: the centre in 1-based cell units (:func:`centre_text`), its coordinate along the
    axis irrelevant and written as 1."""

    turn: TurnMove
    RANK: ClassVar[int] = 3

    @property
    def pieces(self) -> tuple[str, ...]:
        return self.turn.pieces

    def sort_key(self) -> tuple[Any, ...]:
        t = self.turn
        return (t.pieces, t.axis, -t.quarter, t.centre2)

    def to_text(self) -> str:
        t = self.turn
        return (
            f"rotate {'+'.join(t.pieces)} {t.axis} {ANGLES[t.quarter]} "
            f"about {centre_text(t.centre2)}"
        )


@dataclass(frozen=True, eq=True)
class FinishAction(_Ordered):
    """Declare the task done; the episode ends (solved or not)."""

    RANK: ClassVar[int] = 4

    def sort_key(self) -> tuple[Any, ...]:
        return ()

    def to_text(self) -> str:
        return "finish"


@dataclass(frozen=True, eq=True)
class StateAction(_Ordered):
    """Ask for the text state (every piece's cells): legal in both families while the game is
    not finished, costs a step and changes nothing else. Not listed by ``legal_actions()``
    (it never advances a game, so searches and baselines have no use for it)."""

    RANK: ClassVar[int] = 5

    def sort_key(self) -> tuple[Any, ...]:
        return ()

    def to_text(self) -> str:
        return "state"


Action = PlaceAction | PickupAction | MoveAction | TurnAction | FinishAction | StateAction


def action_of_move(move: Move | TurnMove) -> MoveAction | TurnAction:
    """The action that plays a move of a plan."""
    return TurnAction(move) if isinstance(move, TurnMove) else MoveAction(move)


@dataclass(frozen=True)
class MoveRequest:
    """A move as written, before the state resolves what it leaves open: the distance
    (``distance_given`` False) and, in assembly, the part it joins and where it lands."""

    pieces: tuple[str, ...]
    direction: str
    distance: int | None
    distance_given: bool
    into: tuple[str, ...] | None = None
    offset: Cell | None = None

    def text(self) -> str:
        dist = ""
        if self.distance_given:
            dist = " inf" if self.distance is None else f" {self.distance}"
        out = f"move {'+'.join(self.pieces)} {self.direction}{dist}"
        if self.into is not None:
            out += f" into {'+'.join(self.into)}"
        if self.offset is not None:
            out += f" offset {vector_text(self.offset)}"
        return out


@dataclass(frozen=True)
class TurnRequest:
    """A turn as written, before the state resolves its centre (``centre2`` None: left open)."""

    pieces: tuple[str, ...]
    axis: str
    quarter: int
    centre2: Cell | None = None

    def text(self) -> str:
        out = f"rotate {'+'.join(self.pieces)} {self.axis} {ANGLES[self.quarter]}"
        if self.centre2 is not None:
            out += f" about {centre_text(self.centre2)}"
        return out


# ---------------------------------------------------------------------------------------------
# JSON form (0-based cells, as in files)
# ---------------------------------------------------------------------------------------------


class ActionFormatError(ChainGeoError, ValueError):
    """A JSON object that is not an action; the message says which field and why."""


def action_to_json(action: Action) -> dict[str, Any]:
    if isinstance(action, PlaceAction):
        return {"type": "place", "piece": action.piece, "cells": [list(c) for c in action.cells]}
    if isinstance(action, PickupAction):
        return {"type": "pickup", "piece": action.piece}
    if isinstance(action, MoveAction):
        out: dict[str, Any] = {"type": "move", **action.move.to_json()}
        if action.into is not None:
            out["into"] = list(action.into)
        if action.offset is not None:
            out["offset"] = list(action.offset)
        return out
    if isinstance(action, StateAction):
        return {"type": "state"}
    if isinstance(action, TurnAction):
        return {"type": "rotate", **action.turn.to_json()}
    return {"type": "finish"}


def _json_int(value: Any, where: str) -> int:
    if isinstance(value, bool) or not isinstance(value, int):
        raise ActionFormatError(f"{where}: expected an integer, got {value!r}")
    return value


def _json_triple(value: Any, where: str) -> Cell:
    if not isinstance(value, list | tuple) or len(value) != 3:
        raise ActionFormatError(f"{where}: expected three integers, got {value!r}")
    return (
        _json_int(value[0], where),
        _json_int(value[1], where),
        _json_int(value[2], where),
    )


def _json_names(value: Any, where: str) -> tuple[str, ...]:
    if not isinstance(value, list | tuple) or not all(isinstance(v, str) for v in value):
        raise ActionFormatError(f"{where}: expected a list of piece names, got {value!r}")
    return tuple(value)


_JSON_KEYS: Final[dict[str, set[str]]] = {
    "place": {"type", "piece", "cells"},
    "pickup": {"type", "piece"},
    "move": {"type", "pieces", "direction", "distance", "into", "offset"},
    "rotate": {"type", "pieces", "axis", "angle", "about"},
    "finish": {"type"},
    "state": {"type"},
}


def action_from_json(obj: Any) -> Action:
    """The inverse of :func:`action_to_json`; :class:`ActionFormatError` on anything else."""
    if not isinstance(obj, Mapping):
        raise ActionFormatError(f"an action is a JSON object, got {obj!r}")
    kind = obj.get("type")
    if kind not in _JSON_KEYS:
        raise ActionFormatError(f"type: expected one of {sorted(_JSON_KEYS)}, got {kind!r}")
    extra = sorted(set(obj) - _JSON_KEYS[kind])
    if extra:
        raise ActionFormatError(f"{extra[0]}: not a field of a {kind} action")
    try:
        if kind == "place":
            piece = obj.get("piece")
            if not isinstance(piece, str):
                raise ActionFormatError(f"piece: expected a string, got {piece!r}")
            cells = obj.get("cells")
            if not isinstance(cells, list):
                raise ActionFormatError(f"cells: expected a list, got {cells!r}")
            return PlaceAction(piece, tuple(_json_triple(c, "cells") for c in cells))
        if kind == "pickup":
            piece = obj.get("piece")
            if not isinstance(piece, str):
                raise ActionFormatError(f"piece: expected a string, got {piece!r}")
            return PickupAction(piece)
        if kind == "move":
            direction = obj.get("direction")
            if not isinstance(direction, str):
                raise ActionFormatError(f"direction: expected a string, got {direction!r}")
            if "distance" not in obj:
                raise ActionFormatError("distance: missing (null means to infinity)")
            dist = obj["distance"]
            distance = None if dist is None else _json_int(dist, "distance")
            into = obj.get("into")
            offset = obj.get("offset")
            return MoveAction(
                Move(_json_names(obj.get("pieces"), "pieces"), direction, distance),
                into=None if into is None else _json_names(into, "into"),
                offset=None if offset is None else _json_triple(offset, "offset"),
            )
        if kind == "state":
            return StateAction()
        if kind == "rotate":
            return TurnAction(turn_from_json(obj))
        return FinishAction()
    except ActionFormatError:
        raise
    except ValueError as e:
        raise ActionFormatError(str(e)) from None


# ---------------------------------------------------------------------------------------------
# The three agent-input errors
# ---------------------------------------------------------------------------------------------


#: Characters of agent text quoted back in feedback (the rest is elided).
SHOWN_CHARS: Final = 200


def shown_text(text: str) -> str:
    """Agent text as quoted in feedback: stripped, and cut to :data:`SHOWN_CHARS`."""
    s = text.strip()
    return s if len(s) <= SHOWN_CHARS else s[:SHOWN_CHARS] + f"... ({len(s)} characters)"


class ActionError(ChainGeoError):
    """Agent input that was not carried out. Nothing changed; ``feedback`` is for the agent.
    ``code`` is CHAIN's error name for the refusal (stacking levels), else None."""

    kind: ClassVar[str] = "error"
    code: ChainCode | None = None

    def __init__(self, text: str, feedback: str, state_key: Hashable | None) -> None:
        super().__init__(feedback)
        self.text = text
        self.feedback = feedback
        self.state_key = state_key


class UnparseableActionError(ActionError):
    """The text is not an action of the grammar; ``hint`` says what was expected."""

    kind = "unparseable"

    def __init__(self, text: str, hint: str, state_key: Hashable | None = None) -> None:
        shown = shown_text(text) or "(empty)"
        feedback = f"Could not read the action {shown!r}: {hint}. Nothing changed."
        super().__init__(text, feedback, state_key)
        self.hint = hint


class IllegalActionError(ActionError):
    """A well-formed action the rules forbid here; ``reason`` says why (1-based cells), and
    ``code`` is CHAIN's name for it where CHAIN's stacking game has one."""

    kind = "illegal"

    def __init__(
        self,
        reason: str,
        *,
        action: Action | None = None,
        text: str | None = None,
        state_key: Hashable | None = None,
        code: ChainCode | None = None,
    ) -> None:
        shown = text if text is not None else action.to_text() if action is not None else ""
        feedback = f"Illegal action '{shown_text(shown)}': {reason}. Nothing changed."
        super().__init__(shown, feedback, state_key)
        self.reason = reason
        self.action = action
        self.code = code


class AmbiguousActionError(ActionError):
    """The text fits several legal actions; ``candidates`` lists them (sorted)."""

    kind = "ambiguous"
    SHOWN: ClassVar[int] = 6

    def __init__(
        self, text: str, candidates: Sequence[Action], state_key: Hashable | None = None
    ) -> None:
        cands = sorted(candidates)
        listed = "; ".join(a.to_text() for a in cands[: self.SHOWN])
        more = f" (and {len(cands) - self.SHOWN} more)" if len(cands) > self.SHOWN else ""
        feedback = (
            f"Ambiguous action '{shown_text(text)}': it fits {len(cands)} legal actions: "
            f"{listed}{more}. Nothing changed; say which one."
        )
        super().__init__(text, feedback, state_key)
        self.candidates = cands


__all__ = [
    "Action",
    "ActionError",
    "ActionFormatError",
    "AmbiguousActionError",
    "FinishAction",
    "IllegalActionError",
    "MoveAction",
    "MoveRequest",
    "PickupAction",
    "PlaceAction",
    "StateAction",
    "TurnAction",
    "TurnRequest",
    "UnparseableActionError",
    "action_from_json",
    "action_of_move",
    "action_to_json",
    "cell_from_agent",
    "cell_text",
    "cells_text",
    "centre_from_agent",
    "centre_text",
    "rules_text",
    "vector_text",
]
