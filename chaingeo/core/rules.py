"""The environment rules a level is solved under, and the stacking placement checks.

One set of rules serves the level validator, the stacking state machine and the generator, so a
level's ``optimal_steps`` means the same thing everywhere.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import Final, Literal, get_args

from chaingeo.core.geometry import NEIGHBOURS, Cell, Shape

SupportRule = Literal["contact", "drop"]
SUPPORT_RULES: Final[tuple[str, ...]] = ("contact", "drop")
StackingProfile = Literal["default", "chain"]
STACKING_PROFILES: Final[tuple[str, ...]] = ("default", "chain")

#: CHAIN's stacking error names, in the order its game checks them (``place``: the piece
#: exists, is not placed yet, has as many cubes as cells given, the cells are a proper rotation
#: of it, inside the box, overlap nothing, and do not float; ``pickup``: the piece is placed).
ChainCode = Literal[
    "PieceNotFound",
    "PieceAlreadyPlaced",
    "WrongCount",
    "ShapeMismatch",
    "OutOfBounds",
    "Collision",
    "Floating",
]
CHAIN_CODES: Final[tuple[ChainCode, ...]] = get_args(ChainCode)


@dataclass(frozen=True)
class Rejection:
    """Why an action is refused: our sentence, and CHAIN's error name for that kind of refusal
    (None where CHAIN has no such rule: the ``drop`` rule, a pickup that leaves a piece
    floating, anything about puzzles)."""

    reason: str
    code: ChainCode | None = None


@dataclass(frozen=True)
class StackingRules:
    """``contact``: a placed piece must touch the floor or a placed piece face to face.
    ``drop``: additionally it must be lowerable straight down from above without collision.

    ``profile``: ``default`` (ours: a pickup may not leave another piece floating) or
    ``chain`` (CHAIN's stacking game exactly: contact support, a pickup of a placed piece is
    always allowed, and every refusal is reported with CHAIN's error name first). Stored in a
    level file only when not ``default``, so existing files keep their bytes.
    """

    support: SupportRule = "contact"
    profile: StackingProfile = "default"

    def __post_init__(self) -> None:
        if self.support not in SUPPORT_RULES:
            raise ValueError(f"support: {self.support!r} is not one of {list(SUPPORT_RULES)}")
        if self.profile not in STACKING_PROFILES:
            raise ValueError(f"profile: {self.profile!r} is not one of {list(STACKING_PROFILES)}")
        if self.profile == "chain" and self.support != "contact":
            raise ValueError("profile: CHAIN's game has contact support only, not 'drop'")

    def to_json(self) -> dict[str, object]:
        out: dict[str, object] = {"support": self.support}
        if self.profile != "default":
            out["profile"] = self.profile
        return out

    def tag(self, rejection: Rejection) -> Rejection:
        """The rejection as the agent reads it: under the ``chain`` profile the reason starts
        with CHAIN's error name (``[Collision] collision with red at ...``)."""
        if self.profile != "chain" or rejection.code is None:
            return rejection
        return Rejection(f"[{rejection.code}] {rejection.reason}", rejection.code)


@dataclass(frozen=True)
class PuzzleRules:
    """``max_group``: the most pieces one move may carry (None: any group that moves together).
    ``turns``: groups may also turn 90 degrees (:mod:`chaingeo.core.turns`); written to a file
    only when true, so every level without turns keeps its bytes."""

    max_group: int | None = None
    turns: bool = False

    def to_json(self) -> dict[str, object]:
        out: dict[str, object] = {"max_group": self.max_group}
        if self.turns:
            out["turns"] = True
        return out


def placement_problem(
    cells: Shape,
    occupied: Mapping[Cell, str],
    box: Sequence[int],
    rules: StackingRules,
) -> str | None:
    """Why ``cells`` cannot be placed now (a sentence with 0-based cells), or None if it can.

    ``occupied`` maps every filled box cell to the name of the piece there.
    """
    why = placement_rejection(cells, occupied, box, rules)
    return None if why is None else why.reason


def placement_rejection(
    cells: Shape,
    occupied: Mapping[Cell, str],
    box: Sequence[int],
    rules: StackingRules,
) -> Rejection | None:
    """:func:`placement_problem` with CHAIN's error name: the box, overlaps, then support
    (CHAIN's order), then our ``drop`` rule (no CHAIN name)."""
    bx, by, bz = box
    for x, y, z in cells:
        if not (0 <= x < bx and 0 <= y < by and 0 <= z < bz):
            return Rejection(f"out of box at {(x, y, z)}", "OutOfBounds")
    for c in cells:
        if c in occupied:
            return Rejection(f"collision with {occupied[c]} at {c}", "Collision")
    supported = any(z == 0 for _, _, z in cells) or any(
        (x + dx, y + dy, z + dz) in occupied for x, y, z in cells for dx, dy, dz in NEIGHBOURS
    )
    if not supported:
        return Rejection("floating: it touches neither the floor nor another piece", "Floating")
    if rules.support == "drop":
        for x, y, z in cells:
            for zz in range(z + 1, bz):
                if (x, y, zz) in occupied:
                    who = occupied[(x, y, zz)]
                    why = f"cannot be lowered into place: {who} is above it at {(x, y, zz)}"
                    return Rejection(why)
    return None


def placement_order_problem(
    placements: Mapping[str, Shape], order: Iterable[str], box: Sequence[int], rules: StackingRules
) -> str | None:
    """Replay placements in ``order`` under ``rules``; the first problem found, or None."""
    occupied: dict[Cell, str] = {}
    for name in order:
        why = placement_problem(placements[name], occupied, box, rules)
        if why is not None:
            return f"placing {name}: {why}"
        occupied.update({c: name for c in placements[name]})
    return None


def find_placing_order(
    placements: Mapping[str, Shape], box: Sequence[int], rules: StackingRules
) -> list[str] | None:
    """A legal order to place a packing under ``rules`` (smallest names first), or None.

    Depth-first over subsets with memoised dead ends, so it stays exact for drop rules where a
    greedy order can paint itself into a corner.
    """
    names = sorted(placements)
    dead: set[frozenset[str]] = set()

    def extend(placed: list[str], occupied: dict[Cell, str]) -> list[str] | None:
        if len(placed) == len(names):
            return list(placed)
        key = frozenset(placed)
        if key in dead:
            return None
        for n in names:
            if n in placed:
                continue
            if placement_problem(placements[n], occupied, box, rules) is None:
                placed.append(n)
                occupied.update({c: n for c in placements[n]})
                found = extend(placed, occupied)
                if found is not None:
                    return found
                placed.pop()
                for c in placements[n]:
                    del occupied[c]
        dead.add(key)
        return None

    return extend([], {})
