"""Reading agent text: the tokenizer and grammar behind :func:`parse_action`.

Forgiving in syntax where that is unambiguous (case, spaces, commas, brackets, ``x+`` for
``+x``, ``inf``/``infinity``/``out``, a leading ``action:``, ``<action>`` tags), strict in
meaning. Cells are read through :func:`chaingeo.envs.actions.types.cell_from_agent` (1-based text ->
0-based code), the only place that converts.

Action syntaxes are plug-ins (:data:`SYNTAXES`, tried in order): CHAIN's JSON tool calls
(:mod:`chaingeo.envs.actions.chain_dialect`, a JSON object) and turn words
(:mod:`chaingeo.envs.actions.turn_text`); a text neither claims is read as ours
(``place red (1,1,1) ...``). In both a
stacking piece may be named by its colour or, on levels converted from CHAIN, by CHAIN's id
(``place 2 (1,1,1) ...``); ``state`` shows every piece's cells.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Hashable, Iterable, Sequence
from dataclasses import dataclass
from typing import Final, Protocol

from chaingeo.core import limits
from chaingeo.core.errors import ChainGeoError
from chaingeo.core.kinematics import Move
from chaingeo.core.level import Level
from chaingeo.core.registry import Registry
from chaingeo.core.rules import Rejection, StackingRules
from chaingeo.core.turns import TurnMove
from chaingeo.envs.actions import chain_dialect
from chaingeo.envs.actions.chain_dialect import PlacementCellsError
from chaingeo.envs.actions.turn_text import (
    TurnTextError,
    is_turn_text,
    parse_turn,
    tokenise,
)
from chaingeo.envs.actions.types import (
    Action,
    AmbiguousActionError,
    Cell,
    FinishAction,
    IllegalActionError,
    MoveAction,
    MoveRequest,
    PickupAction,
    PlaceAction,
    StateAction,
    TurnAction,
    TurnRequest,
    UnparseableActionError,
    cell_from_agent,
)

GRAMMAR: Final[dict[str, str]] = {
    "stacking": "expected 'place COLOUR (x,y,z) (x,y,z) ...' listing every cell the piece "
    "fills (1-based), 'pickup COLOUR' or 'finish'",
    "disassemble": "expected 'move COLOUR[+COLOUR...] DIRECTION DISTANCE' with DIRECTION one "
    "of +x -x +y -y +z -z and DISTANCE a whole number or 'inf', or 'finish'",
    "assemble": "expected 'move COLOUR[+COLOUR...] DIRECTION DISTANCE' with DIRECTION one of "
    "+x -x +y -y +z -z and DISTANCE a whole number or 'inf' (optionally followed by "
    "'into COLOUR[+COLOUR...] offset (dx,dy,dz)'), or 'finish'",
}

_TOKEN_RE: Final = re.compile(
    r"\s*(?:(?P<num>[0-9]+)|(?P<word>[a-z][a-z0-9_]*(?:-[a-z0-9_]+)*)|(?P<sym>[+\-()\[\]{},;:&]))"
)
_VERBS: Final[dict[str, str]] = {
    "place": "place",
    "put": "place",
    "pickup": "pickup",
    "pick-up": "pickup",
    "move": "move",
    "slide": "move",
    "finish": "finish",
    "finished": "finish",
    "done": "finish",
    "state": "state",
}
_INFINITY: Final = frozenset({"inf", "infinity", "infinite", "out"})
_AXES: Final = frozenset({"x", "y", "z"})
_PLACE_FILLER: Final = frozenset({"at", "on", "onto", "into", "in", "to", "cells", "cell"})
_MOVE_FILLER: Final = frozenset({"by", "to", "unit", "units", "step", "steps", "along"})
_OPEN: Final = "([{"
_CLOSE: Final = ")]}"


class _Unparseable(ChainGeoError):
    def __init__(self, hint: str) -> None:
        super().__init__(hint)
        self.hint = hint


class _Meaningless(ChainGeoError):
    """Well-formed text that no rule could accept (a cell listed twice, distance 0)."""

    def __init__(self, reason: str) -> None:
        super().__init__(reason)
        self.reason = reason


Token = tuple[str, str]  # (kind, value): kind is "num", "word" or "sym"


def _normalise(text: str) -> str:
    s = text.strip().lower()
    s = s.replace("\u2212", "-").replace("\u2013", "-").replace("\u2014", "-")
    s = s.replace("\u221e", " inf ")
    s = s.strip("`'\" \t\r\n")
    s = re.sub(r"^(?:action|answer)\s*:\s*", "", s)
    return s.rstrip(". \t\r\n")


def _tokenise(s: str) -> list[Token]:
    return tokenise(_TOKEN_RE, s, _Unparseable)


def _turn_text(text: str, normalised: str) -> TurnRequest:
    """A turn (:mod:`chaingeo.envs.actions.turn_text`), its errors as the parser's own."""
    try:
        return parse_turn(normalised)
    except TurnTextError as e:
        if e.meaningless:
            raise IllegalActionError(e.hint, text=text) from None
        raise UnparseableActionError(text, f"{e.hint}") from None


#: What a syntax reads: an action, or a move whose distance or destination is left open.
Parsed = Action | MoveRequest | TurnRequest


@dataclass(frozen=True)
class ActionSyntax:
    """One way an agent may write an action (our words, CHAIN's JSON calls, turn words): whether
    it claims a text (given the text and its body without ``<action>`` tags or a code fence)
    and how it reads one. The first registered syntax that claims a text reads it; a text no
    syntax claims is read as our words."""

    name: str
    claims: Callable[[str, str], bool]
    read: Callable[[str, str], Parsed]


#: Action syntaxes in the order they are tried; a name already taken is refused.
SYNTAXES: Registry[ActionSyntax] = Registry("action syntax")


def parse_text(text: str, family: str = "stacking") -> Parsed:
    """Parse agent text without a state: an action, or a move whose distance or (in assembly)
    destination is left open. :class:`UnparseableActionError` if it is not in the grammar.

    ``family`` only chooses the grammar hint of the error ("stacking", "disassemble",
    "assemble").
    """
    hint_all = GRAMMAR.get(family, GRAMMAR["stacking"])
    if len(text) > limits.MAX_TEXT_CHARS:
        raise UnparseableActionError(
            text,
            f"the text has {len(text)} characters; an action has at most "
            f"{limits.MAX_TEXT_CHARS}; {hint_all}",
        )
    body = chain_dialect.unwrap(text)
    try:
        for _, syntax in SYNTAXES.items():
            if syntax.claims(text, body):
                return syntax.read(text, body)
        return _read_words(text, body)
    except _Unparseable as e:
        raise UnparseableActionError(text, f"{e.hint}; {hint_all}") from None
    except _Meaningless as e:
        raise IllegalActionError(e.reason, text=text) from None


def _read_words(text: str, body: str) -> Parsed:
    """Our words: ``place red (1,1,1) ...``, ``move red +x 2``, ``pickup red``, ``finish``."""
    tokens = _tokenise(_normalise(body))
    if not tokens:
        raise _Unparseable("the text is empty")
    if tokens[0] == ("word", "pick") and len(tokens) > 1 and tokens[1] == ("word", "up"):
        tokens = [("word", "pickup"), *tokens[2:]]
    if tokens[0][0] != "word" or tokens[0][1] not in _VERBS:
        raise _Unparseable(f"unknown command {tokens[0][1]!r}")
    verb = _VERBS[tokens[0][1]]
    rest = tokens[1:]
    if verb in ("finish", "state"):
        if rest:
            raise _Unparseable(f"'{verb}' takes nothing after it")
        return FinishAction() if verb == "finish" else StateAction()
    if verb == "pickup":
        if len(rest) != 1 or rest[0][0] not in ("word", "num"):
            raise _Unparseable("'pickup' takes exactly one colour name")
        return PickupAction(rest[0][1])
    if verb == "place":
        return _parse_place(rest)
    return _parse_move(rest)


SYNTAXES.register(
    "chain",
    ActionSyntax(
        "chain",
        lambda t, b: chain_dialect.is_tool_call(b),
        lambda t, b: chain_dialect.parse_tool_call(t, b),
    ),
)
SYNTAXES.register(
    "turn",
    ActionSyntax(
        "turn", lambda t, b: is_turn_text(_normalise(t)), lambda t, b: _turn_text(t, _normalise(t))
    ),
)


def _leading_id(rest: Sequence[Token]) -> bool:
    """Whether a number right after 'place' is CHAIN's id of the piece (``place 2 (1,1,1)``):
    a bracket or a filler word follows it, or it is one number more than whole cells."""
    if not rest or rest[0][0] != "num":
        return False
    after = [t for t in rest[1:] if t not in (("sym", ","), ("sym", ":"))]
    if after and (after[0][1] in _OPEN or after[0][1] in _PLACE_FILLER):
        return True
    return sum(1 for k, _ in rest if k == "num") % 3 == 1


def _parse_place(rest: list[Token]) -> PlaceAction:
    named = bool(rest) and rest[0][0] == "word" and rest[0][1] not in _PLACE_FILLER
    if not (named or _leading_id(rest)):
        raise _Unparseable("'place' needs a colour name first")
    piece = rest[0][1]
    body = [t for t in rest[1:] if not (t[0] == "word" and t[1] in _PLACE_FILLER)]
    numbers = _signed_numbers(body, allow_words=False)
    if not numbers:
        raise _Unparseable("'place' needs the cells the piece will fill")
    groups = _innermost_groups(body)
    if groups is not None and any(len(g) != 3 for g in groups):
        raise _Unparseable("every cell needs three coordinates (x,y,z)")
    if len(numbers) % 3:
        raise _Unparseable(f"{len(numbers)} numbers do not make whole (x,y,z) cells")
    cells = [cell_from_agent(numbers[i : i + 3]) for i in range(0, len(numbers), 3)]
    try:
        return PlaceAction(piece, tuple(cells))
    except ValueError as e:  # a repeated cell
        raise PlacementCellsError(str(e), piece, len(cells), sorted(set(cells))) from None


def _number(digits: str) -> int:
    """A number token, bounded before it is converted (no huge int is ever built)."""
    if len(digits.lstrip("0")) > limits.MAX_AGENT_DIGITS or int(digits) > limits.MAX_AGENT_NUMBER:
        raise _Meaningless(f"numbers in an action are at most {limits.MAX_AGENT_NUMBER}")
    return int(digits)


def _signed_numbers(tokens: Sequence[Token], allow_words: bool) -> list[int]:
    """All integers of a cell list (a '-' right before a number makes it negative)."""
    out: list[int] = []
    sign = 1
    for kind, value in tokens:
        if kind == "num":
            out.append(sign * _number(value))
            sign = 1
        elif kind == "sym" and value == "-":
            sign = -1
        elif kind == "sym" and value in "+()[]{},;:":
            sign = 1
        elif kind == "word" and allow_words:
            continue
        else:
            raise _Unparseable(f"unexpected {value!r} in the cell list")
    return out


def _innermost_groups(tokens: Sequence[Token]) -> list[list[str]] | None:
    """The numbers inside each innermost bracket pair, or None when there are no brackets."""
    if not any(k == "sym" and v in _OPEN for k, v in tokens):
        return None
    groups: list[list[str]] = []
    stack: list[list[str]] = []
    depth_has_child: list[bool] = []
    outside: list[str] = []
    for kind, value in tokens:
        if kind == "sym" and value in _OPEN:
            if depth_has_child:
                depth_has_child[-1] = True
            stack.append([])
            depth_has_child.append(False)
        elif kind == "sym" and value in _CLOSE:
            if not stack:
                raise _Unparseable("a closing bracket without an opening one")
            group = stack.pop()
            if not depth_has_child.pop():
                groups.append(group)
        elif kind == "num":
            (stack[-1] if stack else outside).append(value)
    if stack:
        raise _Unparseable("a bracket is not closed")
    if outside:
        raise _Unparseable("numbers outside the brackets")
    return groups


def _take_group(tokens: list[Token], i: int) -> tuple[tuple[str, ...], int]:
    """Colour names joined by '+', ',', '&', 'and' or spaces (brackets allowed), from ``i``;
    stops before a direction. Returns the names and the next index."""
    names: list[str] = []
    while i < len(tokens):
        kind, value = tokens[i]
        nxt = tokens[i + 1] if i + 1 < len(tokens) else None
        if kind == "sym" and value in "+-" and nxt is not None and nxt[1] in _AXES:
            break  # '+x' / '-x': the direction
        if kind == "word" and value in _AXES and nxt is not None and nxt[1] in ("+", "-"):
            break  # 'x+' / 'x-': the direction
        joiner = (kind == "word" and value == "and" and bool(names)) or (
            kind == "sym" and value in "+,&[](){}"
        )
        if kind == "word" and value not in _AXES and value not in ("and", "into", "offset"):
            names.append(value)
        elif not joiner:
            break
        i += 1
    if not names:
        raise _Unparseable("a move needs the colour name(s) of what moves")
    return tuple(names), i


def _parse_move(rest: list[Token]) -> MoveRequest:
    pieces, i = _take_group(rest, 0)
    if i + 1 >= len(rest):
        raise _Unparseable("a move needs a direction such as +x or -z")
    a, b = rest[i], rest[i + 1]
    if a[0] == "sym" and a[1] in "+-" and b[1] in _AXES:
        direction = a[1] + b[1]
    elif a[1] in _AXES and b[0] == "sym" and b[1] in "+-":
        direction = b[1] + a[1]
    else:
        raise _Unparseable("a move needs a direction such as +x or -z")
    i += 2
    tail = [t for t in rest[i:] if not (t[0] == "word" and t[1] in _MOVE_FILLER)]
    distance: int | None = None
    given = False
    j = 0
    if j < len(tail) and tail[j][0] == "num":
        distance, given = _number(tail[j][1]), True
        j += 1
    elif j < len(tail) and tail[j][0] == "word" and tail[j][1] in _INFINITY:
        given = True
        j += 1
    into: tuple[str, ...] | None = None
    offset: Cell | None = None
    while j < len(tail):
        kind, value = tail[j]
        if kind == "word" and value == "into" and into is None:
            into, used = _take_group(tail[j + 1 :], 0)
            j += 1 + used
        elif kind == "word" and value == "offset" and offset is None:
            k = j + 1
            while k < len(tail) and tail[k][0] != "word":
                k += 1
            numbers = _signed_numbers(tail[j + 1 : k], allow_words=False)
            if len(numbers) != 3:
                raise _Unparseable("'offset' needs three whole numbers (dx,dy,dz)")
            offset = (numbers[0], numbers[1], numbers[2])
            j = k
        else:
            raise _Unparseable(f"unexpected {value!r} after the direction")
    if distance is not None and distance < 1:
        raise _Meaningless("a distance is a whole number of at least 1, or 'inf'")
    if (into is not None or offset is not None) and given and distance is not None:
        raise _Unparseable("'into' and 'offset' describe insertions, whose distance is 'inf'")
    if len(set(pieces)) != len(pieces):
        raise _Meaningless("a colour is named twice in the group")
    if into is not None and set(into) & set(pieces):
        raise _Meaningless("a part cannot go into itself")
    return MoveRequest(tuple(sorted(pieces)), direction, distance, given, into, offset)


class ResolvingState(Protocol):
    """What the parser needs of a state machine (both implement it): the level, the position's
    key for errors, and the two questions that turn a request into a legal action."""

    level: Level

    def key(self) -> Hashable: ...
    def resolve(self, action: Action | MoveRequest | TurnRequest) -> Action: ...
    def problem(self, action: Action) -> str | None: ...
    def rejection(self, action: Action) -> Rejection | None: ...


def _known(names: Iterable[str], state: ResolvingState) -> None:
    """Raise IllegalActionError for the first name that is no piece of the level."""
    known = {p.name for p in state.level.pieces}
    for n in names:
        if n not in known:
            why = Rejection(
                f"unknown piece {n!r}; the pieces are {chain_dialect.piece_list(state.level)}",
                "PieceNotFound" if state.level.family == "stacking" else None,
            )
            raise _illegal(why, state, None)


def _illegal(
    why: Rejection, state: ResolvingState, text: str | None, action: Action | None = None
) -> IllegalActionError:
    """A refusal as the agent reads it (CHAIN's error name first under the chain profile)."""
    rules = state.level.rules
    if isinstance(rules, StackingRules):
        why = rules.tag(why)
    return IllegalActionError(
        why.reason, action=action, text=text, state_key=state.key(), code=why.code
    )


def parse_action(text: str, state: ResolvingState) -> Action:
    """Read agent text as a legal action of ``state`` (which is not changed).

    Raises :class:`UnparseableActionError`, :class:`IllegalActionError` or
    :class:`AmbiguousActionError`; every one carries feedback and the state key.
    """
    mode = state.level.goal if state.level.family == "puzzle" else "stacking"
    try:
        parsed = chain_dialect.resolve_ids(parse_text(text, mode), state.level)
    except UnparseableActionError as e:
        raise UnparseableActionError(text, e.hint, state.key()) from None
    except PlacementCellsError as e:
        raise _cells_error(e, text, state) from None
    except IllegalActionError as e:
        raise _illegal(Rejection(e.reason, e.code), state, text) from None
    try:
        names: list[str] = []
        if isinstance(parsed, PlaceAction | PickupAction):
            names = [parsed.piece]
        elif isinstance(parsed, MoveRequest):
            names = [*parsed.pieces, *(parsed.into or ())]
        elif isinstance(parsed, TurnRequest):
            names = list(parsed.pieces)
        _known(names, state)
        action = state.resolve(parsed)
        why = state.rejection(action)
    except IllegalActionError as e:
        raise IllegalActionError(
            e.reason, action=e.action, text=text, state_key=state.key(), code=e.code
        ) from None
    except AmbiguousActionError as e:
        raise AmbiguousActionError(text, e.candidates, state.key()) from None
    if why is not None:
        raise IllegalActionError(
            why.reason, action=action, text=text, state_key=state.key(), code=why.code
        )
    return action


def _cells_error(e: PlacementCellsError, text: str, state: ResolvingState) -> IllegalActionError:
    """An empty or repeating cell list, judged in CHAIN's order (the piece first)."""
    name = chain_dialect.resolve_id(e.piece, state.level)
    try:
        _known([name], state)
    except IllegalActionError as unknown:
        return IllegalActionError(
            unknown.reason, text=text, state_key=state.key(), code=unknown.code
        )
    why = chain_dialect.cells_rejection(e, name, state.level, state)
    return IllegalActionError(why.reason, text=text, state_key=state.key(), code=why.code)


def action_from_text(text: str) -> Action:
    """Parse the canonical text of an action without a state (moves must give a distance,
    turns their centre)."""
    parsed = parse_text(text, "assemble")
    if isinstance(parsed, TurnRequest):
        if parsed.centre2 is None:
            raise UnparseableActionError(text, "a stand-alone turn needs its centre")
        return TurnAction(TurnMove(parsed.pieces, parsed.axis, parsed.quarter, parsed.centre2))
    if isinstance(parsed, MoveRequest):
        if not parsed.distance_given:
            raise UnparseableActionError(text, "a stand-alone move needs its distance")
        try:
            return MoveAction(
                Move(parsed.pieces, parsed.direction, parsed.distance),
                into=parsed.into,
                offset=parsed.offset,
            )
        except ValueError as e:
            raise UnparseableActionError(text, str(e)) from None
    return parsed
