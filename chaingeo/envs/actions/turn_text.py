"""Reading a turn from agent text: ``rotate GROUP AXIS +90|-90 [about (x,y,z)]``.

Kept apart from the rest of the grammar (:mod:`chaingeo.envs.actions.parse` hands over any text
whose verb is ``rotate`` or ``turn``), because a turn's centre may be a half: the axis runs
through cell centres (whole numbers) or cell corners (numbers ending in .5), 1-based in cell
units; :func:`chaingeo.envs.actions.types.centre_from_agent` converts it. Forgiving in syntax (case,
brackets, commas, ``about z``, ``by 90 degrees``; an unsigned 90 is +90; words such as
``clockwise`` are not guessed, the sign says the sense) and strict in meaning.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from typing import Final

from chaingeo.core import limits
from chaingeo.core.errors import ChainGeoError
from chaingeo.envs.actions.types import TurnRequest, centre_from_agent

VERBS: Final = frozenset({"rotate", "turn"})
HINT: Final = (
    "expected 'rotate COLOUR[+COLOUR...] AXIS ANGLE [about (x,y,z)]' with AXIS one of x y z, "
    "ANGLE +90 or -90 (right hand about the positive axis), and the centre of the turn in "
    "1-based cell units (a cell's own coordinates, or .5 for the corner between cells)"
)
_TOKEN_RE: Final = re.compile(
    r"\s*(?:(?P<num>[0-9]+(?:\.[0-9]+)?)|(?P<word>[a-z][a-z0-9_]*(?:-[a-z0-9_]+)*)"
    r"|(?P<sym>[+\-()\[\]{},;:&\u00b0]))"
)
_AXES: Final = ("x", "y", "z")
_FILLER: Final = frozenset({"by", "degrees", "degree", "deg", "around", "axis", "the", "of"})


class TurnTextError(ChainGeoError, ValueError):
    """Text that is no turn (``meaningless`` False: a hint; True: well-formed but impossible,
    such as a centre at a quarter)."""

    def __init__(self, hint: str, meaningless: bool = False) -> None:
        super().__init__(hint)
        self.hint = hint
        self.meaningless = meaningless


def is_turn_text(normalised: str) -> bool:
    """Does the (normalised, lower-case) text start with a turn verb?"""
    m = re.match(r"[a-z]+", normalised)
    return m is not None and m.group(0) in VERBS


def tokenise(
    pattern: re.Pattern[str], s: str, error: Callable[[str], Exception]
) -> list[tuple[str, str]]:
    """``s`` (trailing space dropped) as ``(kind, text)`` tokens, ``kind`` the name of the group
    of ``pattern`` that matched; ``error(hint)`` is raised at the first character none matches.
    Both action grammars (ours and the turn words) read text through it."""
    out: list[tuple[str, str]] = []
    pos = 0
    s = s.rstrip()
    while pos < len(s):
        m = pattern.match(s, pos)
        if m is None or m.end() == pos:
            raise error(f"unexpected character {s[pos:].strip()[:1]!r}")
        kind = m.lastgroup
        assert kind is not None
        out.append((kind, m.group(kind)))
        pos = m.end()
    return out


def _half(digits: str) -> int:
    """A number of the text, doubled (``3.5`` -> 7); whole numbers and halves only."""
    whole, _, frac = digits.partition(".")
    if len(whole.lstrip("0")) > limits.MAX_AGENT_DIGITS or int(whole) > limits.MAX_AGENT_NUMBER:
        raise TurnTextError(f"numbers are at most {limits.MAX_AGENT_NUMBER}", meaningless=True)
    frac = frac.rstrip("0")
    if frac not in ("", "5"):
        raise TurnTextError(
            f"{digits} is no turn centre: the axis runs through cell centres (whole numbers) "
            "or cell corners (numbers ending in .5)",
            meaningless=True,
        )
    return 2 * int(whole) + (1 if frac else 0)


def parse_turn(normalised: str) -> TurnRequest:
    """Read a turn; :class:`TurnTextError` if it is not one."""
    words = tokenise(_TOKEN_RE, normalised, TurnTextError)
    tokens = [t for t in words if not (t[0] == "word" and t[1] in _FILLER)]
    tokens = [t for t in tokens if t != ("sym", "\u00b0")]
    i = 1  # after the verb
    names: list[str] = []
    while i < len(tokens):
        kind, value = tokens[i]
        if kind == "word" and value in _AXES:
            break
        if kind == "word" and value not in ("and", "about"):
            names.append(value)
        elif kind == "word" and value == "about" and names:
            pass  # "rotate red about z": 'about' before the axis
        elif not ((kind == "sym" and value in "+,&[](){}") or value == "and"):
            raise TurnTextError(f"unexpected {value!r} in the group")
        i += 1
    if not names:
        raise TurnTextError("a turn needs the colour name(s) of what turns")
    if len(set(names)) != len(names):
        raise TurnTextError("a colour is named twice in the group", meaningless=True)
    if i >= len(tokens):
        raise TurnTextError("a turn needs an axis: x, y or z")
    axis = tokens[i][1]
    i += 1
    sign = 1
    if i < len(tokens) and tokens[i] in (("sym", "+"), ("sym", "-")):
        sign = -1 if tokens[i][1] == "-" else 1
        i += 1
    if i >= len(tokens) or tokens[i][0] != "num":
        raise TurnTextError("a turn needs its angle: +90 or -90")
    if len(tokens[i][1]) > 12 or float(tokens[i][1]) != 90:
        raise TurnTextError(f"a turn is a quarter turn, +90 or -90, not {tokens[i][1]}", True)
    i += 1
    centre: tuple[int, int, int] | None = None
    if i < len(tokens):
        if tokens[i] not in (("word", "about"), ("word", "at"), ("word", "through")):
            raise TurnTextError(f"unexpected {tokens[i][1]!r} after the angle")
        values: list[int] = []
        neg = False
        for kind, value in tokens[i + 1 :]:
            if kind == "num":
                values.append(-_half(value) if neg else _half(value))
                neg = False
            elif kind == "sym" and value == "-":
                neg = True
            elif not (kind == "sym" and value in "()[]{},;"):
                raise TurnTextError(f"unexpected {value!r} in the centre")
        if len(values) != 3:
            raise TurnTextError("the centre needs three coordinates (x,y,z)")
        c = list(centre_from_agent(values))
        a = _AXES.index(axis)
        c[a] = 0  # the line's position along itself does not matter
        centre = (c[0], c[1], c[2])
        u, v = (a + 1) % 3, (a + 2) % 3
        if (centre[u] - centre[v]) % 2:
            raise TurnTextError(
                f"the axis must run through cell centres or cell corners: its two coordinates "
                f"across {axis} must both be whole or both end in .5",
                meaningless=True,
            )
    return TurnRequest(tuple(sorted(names)), axis, sign, centre)
