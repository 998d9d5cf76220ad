"""The puzzle state machine: take an interlocking puzzle apart, or put it together.

**Disassemble** plays the moves of :mod:`chaingeo.core.kinematics` exactly: a group of pieces of one
part slides along an axis by ``k`` units or out to infinity (one step whatever ``k``; a finite
move long enough to clear the rest is a removal). Success: every piece stands alone.

**Assemble** is the same machine played backwards, so that a level's assembly plan (its
optimal disassembly reversed, each move inverted) is an optimal plan here too:

* Start: every piece apart, each at its *home* coordinates (where it sits in the target).
* Slide: a group of one part moves ``k`` units along an axis, exactly as in disassembly (every
  unit step collision free, at most ``max_group`` pieces, never passing entirely beyond the
  rest of its part). One refinement keeps it the exact reverse: a group lying clear of the rest
  on the side it moves away from, free to leave that way, may not slide (the disassembly move
  that this would undo is a removal; bring the group in by an insertion instead).
* Insertion (the inverse of a removal): a whole part ``A`` (at most ``max_group`` pieces)
  travels along a direction from infinitely far and joins another whole part ``B``. Where it
  lands is its ``offset``: the displacement of ``A``'s first piece (by name) from where the
  target puts it relative to ``B``'s first piece; ``(0,0,0)`` is the target placement, and the
  text never needs absolute coordinates. Legal when it overlaps nothing there,
  its path in from infinity is free, and the bounding boxes of ``A`` and ``B`` touch or overlap
  on every axis (that bound keeps the action set finite; the conformance test checks every
  level's plan stays within it). Nothing ever leaves a part while assembling.
* Success: one part, every piece at home relative to the others (the target shape).

Text may leave an insertion's destination open (``move red +x inf``, as a stored plan does).
It resolves to the single legal candidate if there is one; otherwise to the candidate whose
result lies on the level's recorded optimal plan (the furthest along, if several); otherwise to
the unique candidate whose merged part is a piece of the target (its pieces at home relative
to each other); otherwise it is an :class:`AmbiguousActionError` listing the candidates. So the
oracle replays the stored moves as they are and ``optimal_steps`` is the plan length.

Parts apart never interact, so ``key()`` records each part's offsets relative to its first
piece (by name): where a separated part happens to lie does not matter.

**Turns** (levels whose rules allow them, :mod:`chaingeo.envs.machines.puzzle_turns`): a proper
group of a part turns 90 degrees about a line parallel to an axis (``rotate red z +90 about
(2,3,1)``). A turned piece keeps its orientation; keys then see each part from its first piece's
pose. When assembling, the pieces start apart in the orientations the level's plan leaves them in
(so the plan, reversed, plays as it is).
"""

from __future__ import annotations

from collections.abc import Hashable, Iterable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from chaingeo.core.geometry import Cell
from chaingeo.core.kinematics import (
    DIRECTIONS,
    OPPOSITE,
    Assembly,
    Move,
)
from chaingeo.core.level import Level
from chaingeo.envs.actions.lists import ActionList
from chaingeo.envs.actions.types import (
    Action,
    AmbiguousActionError,
    IllegalActionError,
    MoveAction,
    MoveRequest,
    TurnAction,
    TurnRequest,
    cell_text,
    vector_text,
)
from chaingeo.envs.machines.move_table import GroupMoves
from chaingeo.envs.machines.puzzle_actions import (
    assembly_actions,
    disassembly_actions,
    oriented_table,
    part_cells,
    shifts,
    turn_actions,
)
from chaingeo.envs.machines.puzzle_tables import PositionKey as PositionKey
from chaingeo.envs.machines.puzzle_tables import PuzzleTables as PuzzleTables
from chaingeo.envs.machines.puzzle_tables import join_shifts, part_key
from chaingeo.envs.machines.puzzle_tables import normal_key as normal_key
from chaingeo.envs.machines.puzzle_turns import PartKey, describe_turn, resolve_turn, turn_problem
from chaingeo.envs.machines.state import BaseState

#: a position (kept alive so its id stays its own), its moves by (group, direction), its turns,
#: its actions
_Listed = tuple[Assembly, GroupMoves, list[TurnAction], ActionList]
_CACHED_POSITIONS = 8


def group_text(names: Iterable[str]) -> str:
    return "+".join(sorted(names))


def _axis(direction: str) -> tuple[int, int]:
    d = DIRECTIONS[direction]
    axis = next(i for i in range(3) if d[i])
    return axis, d[axis]


#: the other parts' keys, and the offsets at which a part joins another on the plan (its key)
_Joins = tuple[list[PartKey], dict[Cell, PartKey]]


@dataclass(frozen=True)
class Insertion:
    """A resolved insertion: part ``part`` joins ``into`` moving along ``direction``."""

    part: frozenset[str]
    into: frozenset[str]
    direction: str
    offset: Cell


class PuzzleState(BaseState):
    """One puzzle level being played (see the module docstring)."""

    def __init__(self, level: Level, tables: PuzzleTables | None = None) -> None:
        super().__init__(level)
        self.tables = tables if tables is not None else PuzzleTables(level)
        if self.tables.mode == "assemble":
            self._asm = Assembly(
                shapes=dict(self.tables.shapes),
                offsets={n: (0, 0, 0) for n in self.tables.names},
                parts=tuple(frozenset([n]) for n in self.tables.names),
                rotations=dict(self.tables.start_rotations),
                rods=self.tables.rods,
            )
        else:
            self._asm = Assembly.assembled(self.tables.shapes, self.tables.rods)
        #: legal actions of recent positions by id(assembly), shared with clones (an agent's
        #: clone and the state it came from look at the same position)
        self._legal_cache: dict[int, _Listed] = {}

    # -- position -----------------------------------------------------------------------------
    @property
    def _position(self) -> Any:
        return self._asm

    @_position.setter
    def _position(self, value: Any) -> None:
        self._asm = value

    def _position_key(self) -> Hashable:
        return normal_key(self._asm)

    @property
    def assembly(self) -> Assembly:
        """The current pieces, offsets and parts (immutable)."""
        return self._asm

    @property
    def mode(self) -> str:
        return self.tables.mode

    def cells_of(self, name: str) -> tuple[Cell, ...]:
        """The cells piece ``name`` fills now (0-based, in its part's coordinates)."""
        return tuple(sorted(self._asm.cells_of(name)))

    def is_success(self) -> bool:
        if self.mode == "disassemble":
            return self._asm.is_separated()
        target = self.tables.target_key  # one entry per part: a count that differs decides
        return len(self._asm.parts) == len(target) and normal_key(self._asm) == target

    # -- legal actions ------------------------------------------------------------------------
    def _legal_moves(self) -> Sequence[Action]:
        return self._actions()[2]

    def _actions(self) -> tuple[GroupMoves, list[TurnAction], ActionList]:
        """(the moves of groups within a part by (group, direction), the legal turns, every
        legal action) of this position, computed once per position. Disassembling, the first
        are every move."""
        cached = self._legal_cache.get(id(self._asm))
        if cached is not None and cached[0] is self._asm:
            return cached[1], cached[2], cached[3]
        mg = self.tables.max_group
        table = oriented_table(self._asm, self.tables.piece_table, self.tables.oriented)
        tt = self.tables.turn_table
        turns = [] if tt is None else turn_actions(self._asm, mg, tt)
        by_group: GroupMoves
        if self.mode == "disassemble":
            by_group = disassembly_actions(self._asm, mg, table)
            actions = ActionList([by_group, turns])
        else:
            ranges, listed = assembly_actions(self._asm, mg, table)
            actions = ActionList([listed, turns])
            by_group = {(r.pieces, r.direction): r for r in ranges}
        if len(self._legal_cache) >= _CACHED_POSITIONS:
            del self._legal_cache[next(iter(self._legal_cache))]
        self._legal_cache[id(self._asm)] = (self._asm, by_group, turns, actions)
        return by_group, turns, actions

    def _slides(self, pieces: Sequence[str], direction: str) -> list[Action]:
        """The moves of one group along one direction (assembling: its slides)."""
        moves = self._actions()[0].get((tuple(sorted(pieces)), direction))
        return [] if moves is None else list(moves)

    def _undoes_removal(self, group: Sequence[str], direction: str) -> bool:
        """Clear of the rest on the side it moves away from, and free to leave that way."""
        back = OPPOSITE[direction]
        return (
            self._asm.clearance(group, back) <= 0 and self._asm.free_distance(group, back) is None
        )

    def _insertions(
        self,
        part: frozenset[str] | None = None,
        direction: str | None = None,
        into: frozenset[str] | None = None,
    ) -> list[Insertion]:
        out: list[Insertion] = []
        parts = self._asm.parts
        for a in parts if part is None else (part,):
            if self.tables.max_group is not None and len(a) > self.tables.max_group:
                continue
            for b in parts if into is None else (into,):
                if b == a:
                    continue
                # _offset_of, its two offsets looked up once per pair (rows run to thousands)
                oa, ob = self._asm.offsets[min(a)], self._asm.offsets[min(b)]
                dx, dy, dz = oa[0] - ob[0], oa[1] - ob[1], oa[2] - ob[2]
                for d in DIRECTIONS if direction is None else (direction,):
                    out.extend(
                        Insertion(a, b, d, (dx + x, dy + y, dz + z))
                        for x, y, z in self._shift_rows(a, b, d).tolist()
                    )
        return out

    def _offset_of(self, a: frozenset[str], b: frozenset[str], t: Cell) -> Cell:
        """The agent's offset of an insertion that translates part ``a`` by ``t``."""
        oa, ob = self._asm.offsets[min(a)], self._asm.offsets[min(b)]
        return (oa[0] + t[0] - ob[0], oa[1] + t[1] - ob[1], oa[2] + t[2] - ob[2])

    def _shift_of(self, a: frozenset[str], b: frozenset[str], offset: Cell) -> Cell:
        """The translation of part ``a`` that an insertion at ``offset`` makes."""
        oa, ob = self._asm.offsets[min(a)], self._asm.offsets[min(b)]
        return (
            offset[0] + ob[0] - oa[0],
            offset[1] + ob[1] - oa[1],
            offset[2] + ob[2] - oa[2],
        )

    def _shift_rows(self, a: frozenset[str], b: frozenset[str], direction: str) -> np.ndarray:
        """Every translation of part ``a`` that makes it come in along ``direction`` and join
        ``b`` (:func:`chaingeo.core.kinematics.insertion_shifts`, computed by the fast kernel), as
        int64 rows in lexicographic order."""
        return shifts(part_cells(self._asm, a), part_cells(self._asm, b), direction)

    def _insertion_action(self, ins: Insertion) -> MoveAction:
        return MoveAction(
            Move(tuple(sorted(ins.part)), ins.direction, None),
            into=tuple(sorted(ins.into)),
            offset=ins.offset,
        )

    # -- resolving what the text leaves open --------------------------------------------------
    def resolve(self, action: Action | MoveRequest | TurnRequest) -> Action:
        if isinstance(action, TurnRequest):
            t = self.tables
            return resolve_turn(
                action, self._actions()[1], self._asm, t.turns, t.max_group, self.key()
            )
        if isinstance(action, MoveRequest):
            return self._resolve_request(action)
        if (
            isinstance(action, MoveAction)
            and self.mode == "assemble"
            and (action.into is None or action.offset is None)
        ):
            req = MoveRequest(
                action.move.pieces,
                action.move.direction,
                action.move.distance,
                True,
                action.into,
                action.offset,
            )
            return self._resolve_request(req)
        return action

    def _resolve_request(self, req: MoveRequest) -> Action:
        text = req.text()
        key = self.key()
        unknown = sorted(set(req.pieces) - set(self.tables.names))
        if unknown:
            raise IllegalActionError(f"unknown piece {unknown[0]!r}", text=text, state_key=key)
        if self.mode == "disassemble":
            if req.into is not None or req.offset is not None:
                raise IllegalActionError(
                    "'into' and 'offset' only apply when assembling", text=text, state_key=key
                )
            if req.distance_given:
                return MoveAction(Move(req.pieces, req.direction, req.distance))
            cands = self._slides(req.pieces, req.direction)
            return self._one_of(cands, Move(req.pieces, req.direction, 1), text)
        part = self._part_of_group(req.pieces, text)
        if part == frozenset(req.pieces):  # a whole part: an insertion
            # (a finite distance is allowed: a stored plan may say how far a removal went, but a
            # part apart comes in from afar whatever it says)
            return self._resolve_insertion(req, part, text)
        if (
            req.into is not None
            or req.offset is not None
            or (req.distance_given and req.distance is None)
        ):
            raise IllegalActionError(
                f"{group_text(req.pieces)} is inside a part with "
                f"{group_text(part - set(req.pieces))}: nothing leaves a part while assembling; "
                "slide it by a number of units",
                text=text,
                state_key=key,
            )
        if req.distance_given:
            return MoveAction(Move(req.pieces, req.direction, req.distance))
        slides = self._slides(req.pieces, req.direction)
        return self._one_of(slides, Move(req.pieces, req.direction, 1), text)

    def _one_of(self, cands: list[Action], probe: Move, text: str) -> Action:
        if len(cands) == 1:
            return cands[0]
        if not cands:
            reason = self._move_problem(MoveAction(probe)) or "no distance works"
            raise IllegalActionError(reason, text=text, state_key=self.key())
        raise AmbiguousActionError(text, cands, self.key())

    def _part_of_group(self, pieces: Sequence[str], text: str) -> frozenset[str]:
        parts = {self._asm.part_of(n) for n in pieces}
        if len(parts) > 1:
            raise IllegalActionError(
                f"{group_text(pieces)} are in different parts; a move carries pieces of one part",
                text=text,
                state_key=self.key(),
            )
        return parts.pop()

    def _resolve_insertion(self, req: MoveRequest, part: frozenset[str], text: str) -> Action:
        into: frozenset[str] | None = None
        if req.into is not None:
            unknown = sorted(set(req.into) - set(self.tables.names))
            if unknown:
                raise IllegalActionError(
                    f"unknown piece {unknown[0]!r}", text=text, state_key=self.key()
                )
            into = self._part_of_group(req.into, text)
            if into == part:
                raise IllegalActionError("a part cannot join itself", text=text)
        if into is not None and req.offset is not None:
            return self._insertion_action(Insertion(part, into, req.direction, req.offset))
        cands = [
            ins
            for ins in self._insertions(part, req.direction, into)
            if req.offset is None or ins.offset == req.offset
        ]
        if len(cands) == 1:
            return self._insertion_action(cands[0])
        if not cands:
            where = f" into {group_text(into)}" if into is not None else ""
            offset = f" with offset {vector_text(req.offset)}" if req.offset is not None else ""
            raise IllegalActionError(
                f"{group_text(part)} cannot come in along {req.direction}{where}{offset} anywhere",
                text=text,
                state_key=self.key(),
            )
        on_path = self._path_steps(cands)
        best = max((p for p, _ in on_path if p is not None), default=None)
        if best is not None:
            return self._insertion_action(next(c for p, c in on_path if p == best))
        homely = [c for c in cands if self._at_home(self._inserted(c), c.part | c.into)]
        if len(homely) == 1:
            return self._insertion_action(homely[0])
        shown = homely or cands
        raise AmbiguousActionError(text, [self._insertion_action(c) for c in shown], self.key())

    def _path_steps(self, cands: list[Insertion]) -> list[tuple[int | None, Insertion]]:
        """How far along the plan each insertion lands (None: off it), the same as
        ``path.get(normal_key(self._inserted(c)))``: the joined part of an insertion on the plan
        is a part of a position on it, and that part fixes the shift, so only the shifts the
        plan's parts ask for are keyed (most candidates are off the plan)."""
        t = self.tables
        keyed: dict[tuple[frozenset[str], frozenset[str]], _Joins | None] = {}
        out: list[tuple[int | None, Insertion]] = []
        for c in cands:
            pair = (c.part, c.into)
            if pair not in keyed:
                keyed[pair] = self._joins(*pair)
            joins = keyed[pair]
            if joins is None:  # turned pieces: key the whole position
                out.append((t.path.get(normal_key(self._inserted(c))), c))
                continue
            joined = joins[1].get(c.offset)
            key = None if joined is None else tuple(sorted([*joins[0], joined]))
            out.append((None if key is None else t.path.get(key), c))
        return out

    def _joins(self, part: frozenset[str], into: frozenset[str]) -> _Joins | None:
        """The keys of the other parts, and the offsets at which ``part`` joins ``into`` as a
        part of the plan (with that part's key); None where a piece is turned."""
        asm = self._asm
        if any(asm.rotation_of(n) for n in part | into):
            return None
        names = tuple(sorted(part | into))
        rest = [part_key(asm, p) for p in asm.parts if p != part and p != into]
        found = join_shifts(asm, part, into, self.tables.path_parts.get(names, ()))
        return rest, {self._offset_of(part, into, shift): key for shift, key in found}

    def _inserted(self, ins: Insertion) -> Assembly:
        asm = self._asm
        dx, dy, dz = self._shift_of(ins.part, ins.into, ins.offset)
        offsets = dict(asm.offsets)
        for n in ins.part:
            x, y, z = offsets[n]
            offsets[n] = (x + dx, y + dy, z + dz)
        merged = ins.part | ins.into
        parts = [p for p in asm.parts if p != ins.part and p != ins.into] + [merged]
        return asm.moved(offsets, tuple(sorted(parts, key=lambda p: sorted(p))))

    @staticmethod
    def _at_home(asm: Assembly, part: frozenset[str]) -> bool:
        return len({asm.offsets[n] for n in part}) == 1

    # -- legality -----------------------------------------------------------------------------
    def _move_problem(self, action: Action) -> str | None:
        if isinstance(action, TurnAction):
            if action in self._actions()[1]:
                return None
            return turn_problem(self._asm, action, self.tables.turns, self.tables.max_group)
        if not isinstance(action, MoveAction):
            return "this is a puzzle level: use move or finish"
        move = action.move
        if action.into is None and action.offset is None:  # fast path: a listed move is legal
            listed = self._actions()[0].get((move.pieces, move.direction))
            if listed is not None and action in listed:
                return None
        unknown = sorted(set(move.pieces) - set(self.tables.names))
        if unknown:
            return f"unknown piece {unknown[0]!r}"
        mg = self.tables.max_group
        if mg is not None and len(move.pieces) > mg:
            return f"the rules let one move carry at most {mg} piece(s)"
        parts = {self._asm.part_of(n) for n in move.pieces}
        if len(parts) > 1:
            return f"{group_text(move.pieces)} are in different parts; a move carries one part"
        part = parts.pop()
        if self.mode == "disassemble":
            if action.into is not None or action.offset is not None:
                return "'into' and 'offset' only apply when assembling"
            if part == frozenset(move.pieces):
                return f"{group_text(move.pieces)} is already apart: nothing to move it against"
            return self._blocked(move)
        if action.into is not None or action.offset is not None or part == frozenset(move.pieces):
            return self._insertion_problem(action, part)
        if move.distance is None:
            return "nothing leaves a part while assembling; slide it by a number of units"
        if self._undoes_removal(move.pieces, move.direction):
            back = OPPOSITE[move.direction]
            return (
                f"{group_text(move.pieces)} lies clear of the rest of its part on the {back} "
                f"side; it cannot slide {move.direction} from there (in assembly it comes in "
                "by an insertion)"
            )
        blocked = self._blocked(move)
        if blocked is not None:
            return blocked
        if self._asm.free_distance(move.pieces, move.direction) is None:
            top = self._asm.clearance(move.pieces, move.direction) - 1
            if move.distance > top:
                return (
                    f"that takes {group_text(move.pieces)} clear of the rest of its part "
                    f"(at most {max(top, 0)} unit(s) keep it in); nothing leaves a part while "
                    "assembling"
                )
        return None

    def _blocked(self, move: Move) -> str | None:
        """Why the pieces cannot travel that far (disassembly semantics), or None."""
        free = self._asm.free_distance(move.pieces, move.direction)
        if free is None:
            return None
        if move.distance is not None and move.distance <= free:
            return None
        who = group_text(self._hit_at(move.pieces, move.direction, free + 1))
        if free == 0:
            return f"blocked by {who}: it cannot move {move.direction} at all"
        what = "it cannot leave" if move.distance is None else f"{move.distance} asked"
        return f"blocked by {who} after {free} unit(s); {what}"

    def _hit_at(self, pieces: Sequence[str], direction: str, k: int) -> list[str]:
        dx, dy, dz = DIRECTIONS[direction]
        moved = {
            (x + dx * k, y + dy * k, z + dz * k)
            for n in pieces
            for x, y, z in self._asm.cells_of(n)
        }
        part = self._asm.part_of(pieces[0])
        return [
            o for o in sorted(part - set(pieces)) if not moved.isdisjoint(self._asm.cells_of(o))
        ]

    def _insertion_problem(self, action: MoveAction, part: frozenset[str]) -> str | None:
        move = action.move
        if part != frozenset(move.pieces):
            rest = group_text(part - set(move.pieces))
            return f"{group_text(move.pieces)} is not a whole part (its part also holds {rest})"
        if action.into is None or action.offset is None:
            return "an insertion needs the part it joins and its offset"
        into_parts = {self._asm.part_of(n) for n in action.into}
        if len(into_parts) > 1 or next(iter(into_parts)) != frozenset(action.into):
            return f"{group_text(action.into)} is not a whole part"
        into = next(iter(into_parts))
        if into == part:
            return "a part cannot join itself"
        if move.distance is not None:
            return "an insertion comes in from infinity: its distance is inf"
        shift = self._shift_of(part, into, action.offset)
        rows = self._shift_rows(part, into, move.direction)
        if bool(np.any(np.all(rows == np.asarray(shift, dtype=np.int64), axis=1))):
            return None
        return self._why_no_insertion(part, into, move.direction, shift)

    def _why_no_insertion(
        self, part: frozenset[str], into: frozenset[str], direction: str, shift: Cell
    ) -> str:
        dx, dy, dz = shift
        landed = {
            (x + dx, y + dy, z + dz): n for n in sorted(part) for x, y, z in self._asm.cells_of(n)
        }
        owner = {c: n for n in sorted(into) for c in self._asm.cells_of(n)}
        for c in sorted(landed):
            if c in owner:
                return f"{landed[c]} would overlap {owner[c]} at {cell_text(c)}"
        ax, sign = _axis(direction)
        # Cells of ``into`` by the line along the axis they lie on: a landed cell passed
        # through one of them iff one lies behind it on its line (work bounded by the cells,
        # never by how far away the offset puts the part).
        lines: dict[tuple[int, int], list[tuple[int, str]]] = {}
        for v, n in owner.items():
            rest = (v[(ax + 1) % 3], v[(ax + 2) % 3])
            lines.setdefault(rest, []).append((v[ax], n))
        for c in sorted(landed):
            behind = [
                (sign * (c[ax] - at), who)
                for at, who in lines.get((c[(ax + 1) % 3], c[(ax + 2) % 3]), [])
                if sign * (c[ax] - at) >= 1
            ]
            if behind:
                who = min(behind)[1]
                return (
                    f"{group_text(part)} cannot reach that place along {direction}: "
                    f"on the way in it would pass through {who}"
                )
        return (
            f"{group_text(part)} would land away from {group_text(into)}: parts join only where "
            "their bounding boxes touch or overlap"
        )

    # -- applying -----------------------------------------------------------------------------
    def _after(self, action: Action) -> Any:
        if isinstance(action, TurnAction):  # checked already (listed, or turn_problem)
            return self._asm.turned(action.turn)
        assert isinstance(action, MoveAction)
        if self.mode == "disassemble":
            return self._asm.apply(action.move)
        if action.into is not None and action.offset is not None:
            part = self._asm.part_of(action.move.pieces[0])
            into = self._asm.part_of(action.into[0])
            return self._inserted(Insertion(part, into, action.move.direction, action.offset))
        move = action.move
        assert move.distance is not None
        dx, dy, dz = DIRECTIONS[move.direction]
        k = move.distance
        offsets = dict(self._asm.offsets)
        for n in move.pieces:
            x, y, z = offsets[n]
            offsets[n] = (x + dx * k, y + dy * k, z + dz * k)
        return self._asm.moved(offsets)

    def describe(self, action: Action) -> str:
        if isinstance(action, TurnAction):
            return describe_turn(action)
        if not isinstance(action, MoveAction):
            return "Finished: solved." if self.is_success() else "Finished without solving."
        grp = group_text(action.move.pieces)
        n = len(self.tables.names)
        parts = len(self._asm.parts)
        if action.into is not None:
            return (
                f"OK: {grp} came in along {action.move.direction} and joined "
                f"{group_text(action.into)}. {_count(parts, 'part')} now."
            )
        previous = self._stack[-1][1] if self._stack else None
        if isinstance(previous, Assembly) and len(previous.parts) != parts:
            apart = sum(1 for p in self._asm.parts if len(p) == 1)
            d = action.move.direction
            return f"OK: {grp} was taken out along {d}. {apart} of {n} pieces apart."
        dist = action.move.distance
        return f"OK: {grp} slid {action.move.direction} by {dist} unit(s)."


def _count(n: int, noun: str) -> str:
    return f"{n} {noun}" if n == 1 else f"{n} {noun}s"
