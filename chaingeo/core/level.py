"""The ``chain-level/1`` file: one level per JSON file, validated in full on load.

Loading either returns a complete, verified :class:`Level` or raises one :class:`LevelError`
naming the file, the field and the reason; nothing is ever half-loaded. Writing is canonical
(sorted keys, fixed layout), so the same level is the same bytes and :func:`content_hash`
identifies it in logs. Coordinates in files are 0-based.
"""

from __future__ import annotations

import json
import os
import re
from collections import Counter
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path
from typing import Any, Final, Literal

from chaingeo.core import canonical_json, limits
from chaingeo.core.files import UnreadableFile, atomic_write, read_bounded
from chaingeo.core.geometry import Cell, Shape, box_cells, puzzle_signature
from chaingeo.core.kinematics import (
    DIRECTIONS,
    Move,
    MoveError,
    disassembly_of_assembly_plan,
    replay_disassembly,
)
from chaingeo.core.level_reader import LevelError as LevelError  # re-exported
from chaingeo.core.level_reader import Reader, only_keys, short
from chaingeo.core.level_reader import decode_json as decode_json  # re-exported
from chaingeo.core.rules import (
    STACKING_PROFILES,
    SUPPORT_RULES,
    PuzzleRules,
    StackingRules,
    placement_order_problem,
)
from chaingeo.core.turns import AXES, TurnMove, turn_from_json

FORMAT: Final = "chain-level/1"
FAMILIES: Final = ("stacking", "puzzle")
DIFFICULTIES: Final = ("easy", "mid", "hard")
GOALS: Final = {"stacking": ("pack",), "puzzle": ("disassemble", "assemble")}
_NAME_RE: Final = re.compile(r"[a-z][a-z0-9_-]{0,31}")
_ID_RE: Final = re.compile(r"[A-Za-z0-9][A-Za-z0-9_.-]{0,127}")
_HEX_RE: Final = re.compile(r"#[0-9a-f]{6}")
#: CHAIN's piece ids: the piece's index in CHAIN's level file, in decimal.
_CHAIN_ID_RE: Final = re.compile(r"0|[1-9][0-9]{0,5}")

Family = Literal["stacking", "puzzle"]
Difficulty = Literal["easy", "mid", "hard"]
Goal = Literal["pack", "disassemble", "assemble"]


@dataclass(frozen=True)
class Piece:
    name: str
    rgb: str
    shape: Shape  # stacking: as handed to the agent; puzzle: assembled position
    #: CHAIN's id of the piece (its index in CHAIN's level file, ``"0"``, ``"1"``, ...) when
    #: the level came from CHAIN: agents may name the piece by it. All pieces or none have one.
    chain_id: str | None = None
    #: puzzle cells that are round rods along an axis (0, 1, 2), which spin in place when they
    #: turn about their own axis (:mod:`chaingeo.core.turns`); written only when there are any
    rods: Mapping[Cell, int] = field(default_factory=dict)


@dataclass(frozen=True)
class StackingSolution:
    placements: Mapping[str, Shape]
    order: tuple[str, ...]  # a legal placing order under the level's rules


@dataclass(frozen=True)
class PuzzleSolution:
    moves: tuple[Move | TurnMove, ...]


@dataclass(frozen=True)
class Provenance:
    generator: str
    version: str
    seed: int | None
    index: int | None
    signature: str


@dataclass(frozen=True)
class Level:
    id: str
    family: Family
    difficulty: Difficulty
    goal: Goal
    box: tuple[int, int, int] | None
    pieces: tuple[Piece, ...]
    solution: StackingSolution | PuzzleSolution
    optimal_steps: int
    max_steps: int
    rules: StackingRules | PuzzleRules
    provenance: Provenance
    stats: Mapping[str, Any] = field(default_factory=dict)

    def piece(self, name: str) -> Piece:
        for p in self.pieces:
            if p.name == name:
                return p
        raise KeyError(name)

    @property
    def shapes(self) -> dict[str, Shape]:
        return {p.name: p.shape for p in self.pieces}

    @property
    def rods(self) -> dict[str, dict[Cell, int]]:
        """The round rods of the pieces that have any (see :class:`Piece`)."""
        return {p.name: dict(p.rods) for p in self.pieces if p.rods}

    def to_json(self) -> dict[str, Any]:
        sol: dict[str, Any]
        if isinstance(self.solution, StackingSolution):
            sol = {
                "order": list(self.solution.order),
                "placements": {
                    n: [list(c) for c in s.cells]
                    for n, s in sorted(self.solution.placements.items())
                },
            }
        else:
            sol = {"moves": [m.to_json() for m in self.solution.moves]}
        return {
            "format": FORMAT,
            "id": self.id,
            "family": self.family,
            "difficulty": self.difficulty,
            "goal": self.goal,
            "box": list(self.box) if self.box is not None else None,
            "pieces": [_piece_json(p) for p in self.pieces],
            "solution": sol,
            "optimal_steps": self.optimal_steps,
            "max_steps": self.max_steps,
            "rules": self.rules.to_json(),
            "provenance": {
                "generator": self.provenance.generator,
                "version": self.provenance.version,
                "seed": self.provenance.seed,
                "index": self.provenance.index,
                "signature": self.provenance.signature,
            },
            "stats": dict(self.stats),
        }


def _piece_json(p: Piece) -> dict[str, Any]:
    out: dict[str, Any] = {"name": p.name, "rgb": p.rgb, "voxels": [list(c) for c in p.shape.cells]}
    if p.chain_id is not None:
        out["chain_id"] = p.chain_id
    if p.rods:
        out["rods"] = {AXES[a]: sorted(list(c) for c, b in p.rods.items() if b == a) for a in
                       sorted(set(p.rods.values()))}  # fmt: skip
    return out


# ---------------------------------------------------------------------------------------------
# Writing and hashing
# ---------------------------------------------------------------------------------------------


def level_bytes(level: Level) -> bytes:
    """The canonical file bytes of a level."""
    return canonical_json.dumps(level.to_json()).encode("utf-8")


def content_hash(level: Level) -> str:
    """SHA-256 of the canonical bytes: the level's identity in logs."""
    return canonical_json.sha256_hex(level_bytes(level))


def level_set_hash(levels: Iterable[Level]) -> str:
    """SHA-256 over the sorted content hashes of a set of levels (order does not matter)."""
    text = "\n".join(sorted(content_hash(lv) for lv in levels))
    return canonical_json.sha256_hex(text.encode("ascii"))


def save_level(level: Level, path: str | os.PathLike[str]) -> Path:
    """Write atomically (temp file then rename) so a reader never sees half a file."""
    return atomic_write(path, level_bytes(level))


def default_step_budget(optimal_steps: int) -> int:
    """The original benchmark gives 30 to 60 steps; we give three times the optimum in that band."""
    return max(30, min(60, 3 * optimal_steps))


# ---------------------------------------------------------------------------------------------
# Loading and validation
# ---------------------------------------------------------------------------------------------


def is_level_id(text: object) -> bool:
    """Whether ``text`` is a level id as a level file may write it (matched whole)."""
    return isinstance(text, str) and _ID_RE.fullmatch(text) is not None


def parse_level(data: Any, source: str = "<level>") -> Level:
    """Validate a decoded JSON value and build the level; :class:`LevelError` if anything is off."""
    r = Reader(source)
    top = r.obj(data, "(top level)")
    fmt = r.string(r.get(top, "format", "format"), "format")
    if fmt != FORMAT:
        raise r.fail("format", f"expected {FORMAT!r}, got {fmt!r}")
    level_id = r.string(r.get(top, "id", "id"), "id")
    if not _ID_RE.fullmatch(level_id):
        raise r.fail("id", f"{level_id!r} must be letters, digits, '.', '_' or '-'")
    family = r.string(r.get(top, "family", "family"), "family", FAMILIES)
    difficulty = r.string(r.get(top, "difficulty", "difficulty"), "difficulty", DIFFICULTIES)
    goal = r.string(r.get(top, "goal", "goal"), "goal", GOALS[family])

    box: tuple[int, int, int] | None = None
    raw_box = top.get("box")
    if family == "stacking":
        dims = r.lst(r.get(top, "box", "box"), "box")
        if len(dims) != 3:
            raise r.fail("box", f"expected three sizes [x, y, z], got {len(dims)}")
        a, b, c = (
            r.integer(v, f"box[{i}]", minimum=1, maximum=limits.MAX_COORD)
            for i, v in enumerate(dims)
        )
        box = (a, b, c)
    elif raw_box is not None:
        raise r.fail("box", "puzzle levels have no box; use null or leave it out")

    pieces = _parse_pieces(r, r.get(top, "pieces", "pieces"), box, family)

    rules_obj = r.obj(r.get(top, "rules", "rules"), "rules")
    rules: StackingRules | PuzzleRules
    if family == "stacking":
        only_keys(r, rules_obj, {"support", "profile"}, "rules")
        support = r.string(rules_obj.get("support", "contact"), "rules.support", SUPPORT_RULES)
        if "profile" in rules_obj:  # written only when not the default
            profile = r.string(rules_obj["profile"], "rules.profile", STACKING_PROFILES[1:])
        else:
            profile = "default"
        if profile == "chain" and support != "contact":
            raise r.fail("rules.support", "the chain profile has contact support only")
        rules = StackingRules(support=support, profile=profile)  # type: ignore[arg-type]
    else:
        only_keys(r, rules_obj, {"max_group", "turns"}, "rules")
        mg = rules_obj.get("max_group")
        turns = rules_obj.get("turns", False)
        if turns is not True and "turns" in rules_obj:  # written only when true
            raise r.fail("rules.turns", f"expected true or no field, got {short(turns)}")
        rules = PuzzleRules(
            max_group=None
            if mg is None
            else r.integer(mg, "rules.max_group", 1, limits.MAX_PIECES),
            turns=turns,
        )

    max_steps = r.integer(
        r.get(top, "max_steps", "max_steps"), "max_steps", minimum=1, maximum=limits.MAX_STEPS
    )
    optimal = r.integer(
        r.get(top, "optimal_steps", "optimal_steps"), "optimal_steps", 0, limits.MAX_STEPS
    )
    if max_steps < optimal:
        raise r.fail("max_steps", f"budget {max_steps} is below optimal_steps {optimal}")

    sol_obj = r.obj(r.get(top, "solution", "solution"), "solution")
    solution: StackingSolution | PuzzleSolution
    if family == "stacking":
        assert box is not None and isinstance(rules, StackingRules)
        solution = _parse_stacking_solution(r, sol_obj, pieces, box, rules)
        plan_length = len(solution.order)
    else:
        assert isinstance(rules, PuzzleRules)
        solution = _parse_puzzle_solution(r, sol_obj, pieces, goal, rules)
        plan_length = len(solution.moves)
    if plan_length != optimal:
        raise r.fail(
            "optimal_steps",
            f"{optimal} recorded but the stored optimal plan has {plan_length} steps",
        )

    prov = r.obj(r.get(top, "provenance", "provenance"), "provenance")
    provenance = Provenance(
        generator=r.string(
            r.get(prov, "generator", "provenance.generator"), "provenance.generator"
        ),
        version=r.string(r.get(prov, "version", "provenance.version"), "provenance.version"),
        seed=r.opt_integer(prov.get("seed"), "provenance.seed"),
        index=r.opt_integer(prov.get("index"), "provenance.index"),
        signature=r.string(
            r.get(prov, "signature", "provenance.signature"), "provenance.signature"
        ),
    )
    expected_sig = puzzle_signature(p.shape for p in pieces)
    if provenance.signature != expected_sig:
        raise r.fail("provenance.signature", f"does not match the pieces (expected {expected_sig})")
    stats = r.obj(top.get("stats", {}), "stats")
    return Level(
        id=level_id,
        family=family,  # type: ignore[arg-type]
        difficulty=difficulty,  # type: ignore[arg-type]
        goal=goal,  # type: ignore[arg-type]
        box=box,
        pieces=tuple(pieces),
        solution=solution,
        optimal_steps=optimal,
        max_steps=max_steps,
        rules=rules,
        provenance=provenance,
        stats=dict(stats),
    )


def _parse_pieces(
    r: Reader, raw: Any, box: tuple[int, int, int] | None, family: str
) -> list[Piece]:
    items = r.lst(raw, "pieces")
    if not items:
        raise r.fail("pieces", "a level needs at least one piece")
    if len(items) > limits.MAX_PIECES:
        raise r.fail("pieces", f"{len(items)} pieces; a level has at most {limits.MAX_PIECES}")
    total = 0
    pieces: list[Piece] = []
    seen_names: set[str] = set()
    seen_rgb: dict[str, str] = {}
    for i, item in enumerate(items):
        f = f"pieces[{i}]"
        obj = r.obj(item, f)
        name = r.string(r.get(obj, "name", f"{f}.name"), f"{f}.name")
        if not _NAME_RE.fullmatch(name):
            raise r.fail(f"{f}.name", f"{name!r} must be one lowercase word a model can type")
        if name in seen_names:
            raise r.fail(f"{f}.name", f"duplicate piece name {name!r}")
        rgb = r.string(r.get(obj, "rgb", f"{f}.rgb"), f"{f}.rgb")
        if not _HEX_RE.fullmatch(rgb):
            raise r.fail(f"{f}.rgb", f"{rgb!r} is not a lowercase #rrggbb colour")
        if rgb in seen_rgb:
            raise r.fail(f"{f}.rgb", f"duplicate colour {rgb} (also {seen_rgb[rgb]})")
        shape = r.voxels(r.get(obj, "voxels", f"{f}.voxels"), f"{f}.voxels")
        only_keys(r, obj, {"name", "rgb", "voxels", "chain_id", "rods"}, f, "field")
        chain_id = None
        if "chain_id" in obj:
            chain_id = r.string(obj["chain_id"], f"{f}.chain_id")
            if not _CHAIN_ID_RE.fullmatch(chain_id):
                raise r.fail(f"{f}.chain_id", f"{short(chain_id)} is not a piece index")
        total += len(shape)
        if total > limits.MAX_LEVEL_VOXELS:
            raise r.fail(f"{f}.voxels", f"a level has at most {limits.MAX_LEVEL_VOXELS} voxels")
        if not shape.is_connected():
            raise r.fail(f"{f}.voxels", f"piece {name} is not face-connected")
        seen_names.add(name)
        seen_rgb[rgb] = name
        rods = _parse_rods(r, obj.get("rods"), shape, f"{f}.rods", family)
        pieces.append(Piece(name, rgb, shape, chain_id, rods))
    ids = [p.chain_id for p in pieces]
    if any(i is not None for i in ids):
        if None in ids:
            raise r.fail("pieces", "every piece or none has a chain_id")
        dup = sorted({i for i in ids if i is not None and ids.count(i) > 1})
        if dup:
            raise r.fail("pieces", f"duplicate chain_id {dup[0]!r}")
    if family == "stacking":
        assert box is not None
        total = sum(len(p.shape) for p in pieces)
        if total != box[0] * box[1] * box[2]:
            raise r.fail("pieces", f"{total} voxels in all cannot fill a {box} box exactly")
    else:
        owner: dict[tuple[int, int, int], str] = {}
        for p in pieces:
            for c in p.shape:
                if c in owner:
                    raise r.fail("pieces", f"pieces {owner[c]} and {p.name} overlap at {list(c)}")
                owner[c] = p.name
    return pieces


def _parse_rods(r: Reader, raw: Any, shape: Shape, fld: str, family: str) -> dict[Cell, int]:
    """``{"y": [[x, y, z], ...]}``: cells of the piece that are round rods along that axis."""
    if raw is None:
        return {}
    if family != "puzzle":
        raise r.fail(fld, "only puzzle pieces have rods")
    out: dict[Cell, int] = {}
    for axis, cells in sorted(r.obj(raw, fld).items()):
        if axis not in AXES:
            raise r.fail(fld, f"{axis!r} is not an axis (x, y or z)")
        for c in r.voxels(cells, f"{fld}.{axis}").cells:
            if c not in shape.cell_set:
                raise r.fail(f"{fld}.{axis}", f"{list(c)} is not a cell of the piece")
            if c in out:
                raise r.fail(fld, f"{list(c)} is a rod along two axes")
            out[c] = AXES.index(axis)
    return out


def _parse_stacking_solution(
    r: Reader,
    sol: Mapping[str, Any],
    pieces: Sequence[Piece],
    box: tuple[int, int, int],
    rules: StackingRules,
) -> StackingSolution:
    raw = r.obj(r.get(sol, "placements", "solution.placements"), "solution.placements")
    names = sorted(p.name for p in pieces)
    if sorted(raw) != names:
        missing = sorted(set(names) - set(raw))
        extra = sorted(set(raw) - set(names))
        raise r.fail(
            "solution.placements",
            f"must place every piece once (missing {missing}, unknown {extra})",
        )
    placements: dict[str, Shape] = {}
    covered: dict[tuple[int, int, int], str] = {}
    for p in pieces:
        f = f"solution.placements.{p.name}"
        cells = r.voxels(raw[p.name], f)
        for c in cells:
            if not all(0 <= c[i] < box[i] for i in range(3)):
                raise r.fail(f, f"voxel {list(c)} is outside the {list(box)} box")
            if c in covered:
                raise r.fail(f, f"overlaps {covered[c]} at {list(c)}")
            covered[c] = p.name
        if cells.canonical() != p.shape.canonical():  # not a rotated translate of it
            raise r.fail(f, f"is not a rotation of piece {p.name}'s shape")
        placements[p.name] = cells
    if set(covered) != box_cells(box).cell_set:
        raise r.fail("solution.placements", "the placements do not fill the box exactly")
    order = [
        r.string(v, "solution.order")
        for v in r.lst(r.get(sol, "order", "solution.order"), "solution.order")
    ]
    if sorted(order) != names:
        raise r.fail("solution.order", "must list every piece exactly once")
    why = placement_order_problem(placements, order, box, rules)
    if why is not None:
        raise r.fail("solution.order", f"not a legal placing order under {rules}: {why}")
    return StackingSolution(placements=placements, order=tuple(order))


def _parse_puzzle_solution(
    r: Reader, sol: Mapping[str, Any], pieces: Sequence[Piece], goal: str, rules: PuzzleRules
) -> PuzzleSolution:
    raw_moves = r.lst(r.get(sol, "moves", "solution.moves"), "solution.moves")
    if len(raw_moves) > limits.MAX_STEPS:
        raise r.fail("solution.moves", f"{len(raw_moves)} moves; at most {limits.MAX_STEPS}")
    names = {p.name for p in pieces}
    moves: list[Move | TurnMove] = []
    for i, m in enumerate(raw_moves):
        f = f"solution.moves[{i}]"
        obj = r.obj(m, f)
        if "axis" in obj:  # a turn
            if not rules.turns:
                raise r.fail(f, "a turn, but the rules do not allow turns")
            only_keys(r, obj, {"pieces", "axis", "angle", "about"}, f)
            try:
                turn = turn_from_json(obj)
            except ValueError as e:
                raise r.fail(f, str(e)) from None
            if set(turn.pieces) - names:
                raise r.fail(f"{f}.pieces", f"unknown piece(s) {sorted(set(turn.pieces) - names)}")
            if rules.max_group is not None and len(turn.pieces) > rules.max_group:
                raise r.fail(
                    f"{f}.pieces", f"turns {len(turn.pieces)} pieces; at most {rules.max_group}"
                )
            moves.append(turn)
            continue
        group = [
            r.string(n, f"{f}.pieces")
            for n in r.lst(r.get(obj, "pieces", f"{f}.pieces"), f"{f}.pieces")
        ]
        unknown = sorted(set(group) - names)
        if unknown:
            raise r.fail(f"{f}.pieces", f"unknown piece(s) {unknown}")
        if rules.max_group is not None and len(group) > rules.max_group:
            raise r.fail(
                f"{f}.pieces", f"moves {len(group)} pieces; the rules allow {rules.max_group}"
            )
        direction = r.string(
            r.get(obj, "direction", f"{f}.direction"), f"{f}.direction", list(DIRECTIONS)
        )
        dist = r.get(obj, "distance", f"{f}.distance")
        distance = (
            None if dist is None else r.integer(dist, f"{f}.distance", 1, limits.MAX_DISTANCE)
        )
        try:
            moves.append(Move(tuple(group), direction, distance))
        except ValueError as e:
            raise r.fail(f, str(e)) from None
    shapes = {p.name: p.shape for p in pieces}
    disassembly = moves if goal == "disassemble" else disassembly_of_assembly_plan(moves)
    try:
        final = replay_disassembly(shapes, disassembly, {p.name: p.rods for p in pieces})
    except MoveError as e:
        raise r.fail("solution.moves", f"does not replay: {e}") from None
    if not final.is_separated():
        raise r.fail("solution.moves", "the plan does not separate every piece")
    return PuzzleSolution(moves=tuple(moves))


def revalidate(level: Level) -> Level:
    """Round-trip a level built in code through the file validator (generators call this)."""
    return parse_level(json.loads(level_bytes(level)), f"<level {level.id}>")


def load_level(path: str | os.PathLike[str]) -> Level:
    """Read and fully validate one level file. A file read before and unchanged since (the
    same size, modification time and inode) gives the same Level again without being read:
    environments, task sets and commands load the suite again and again, and a Level is a
    value that nothing changes."""
    try:
        st = os.stat(path)
    except (OSError, ValueError):
        return _load_level(str(path))  # says why it cannot be read
    return _load_unchanged(str(path), st.st_size, st.st_mtime_ns, st.st_ino, st.st_dev)


@lru_cache(maxsize=1024)
def _load_unchanged(path: str, size: int, mtime_ns: int, inode: int, device: int) -> Level:
    """:func:`_load_level`, remembered by the file's path and stamp."""
    return _load_level(path)


def _load_level(path: str) -> Level:
    source = path
    try:
        raw = read_bounded(path, limits.MAX_FILE_BYTES)
    except UnreadableFile as e:
        raise LevelError(source, "(file)", e.reason) from None
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError:
        raise LevelError(source, "(file)", "not UTF-8 text") from None
    return parse_level(decode_json(text, source), source)


def load_levels(folder: str | os.PathLike[str]) -> list[Level]:
    """All ``*.json`` levels under ``folder`` (recursively), sorted by id."""
    levels = [load_level(p) for p in sorted(Path(folder).rglob("*.json"))]
    counts = Counter(lv.id for lv in levels)
    dup = sorted(i for i, n in counts.items() if n > 1)
    if dup:
        raise LevelError(str(folder), "id", f"duplicate level id {dup[0]!r}")
    return sorted(levels, key=lambda lv: lv.id)


def stacking_level(
    level_id: str,
    difficulty: Difficulty,
    box: Sequence[int],
    placements: Sequence[Shape],
    *,
    rules: StackingRules = StackingRules(),
    handed: Sequence[Shape] | None = None,
    generator: str = "manual",
    version: str = "1",
    seed: int | None = None,
    index: int | None = None,
    stats: Mapping[str, Any] | None = None,
    max_steps: int | None = None,
    chain_ids: Sequence[str] | None = None,
) -> Level:
    """Build and verify a stacking level from a packing (pieces in placement order).

    Pieces get palette colours in order; ``handed`` gives the orientation each piece is shown
    in (default: its normalised placement); ``chain_ids`` CHAIN's id of each piece. The
    ``optimal_steps`` is the number of pieces under either rules profile: each piece must be
    placed at least once, and a legal order (the placement checks of both profiles are the
    same) is found and stored, so that many suffice.
    """
    from chaingeo.core.colors import assign_colors
    from chaingeo.core.rules import find_placing_order

    dims = (int(box[0]), int(box[1]), int(box[2]))
    colors = assign_colors(len(placements))
    shapes = list(handed) if handed is not None else [p.normalized() for p in placements]
    by_name = {c.name: p for c, p in zip(colors, placements, strict=True)}
    order = find_placing_order(by_name, dims, rules)
    if order is None:
        raise LevelError(
            f"<level {level_id}>", "solution.order", f"no legal placing order under {rules}"
        )
    level = Level(
        id=level_id,
        family="stacking",
        difficulty=difficulty,
        goal="pack",
        box=dims,
        pieces=tuple(
            Piece(c.name, c.hex, s, None if chain_ids is None else chain_ids[i])
            for i, (c, s) in enumerate(zip(colors, shapes, strict=True))
        ),
        solution=StackingSolution(placements=by_name, order=tuple(order)),
        optimal_steps=len(placements),
        max_steps=max_steps if max_steps is not None else default_step_budget(len(placements)),
        rules=rules,
        provenance=Provenance(generator, version, seed, index, puzzle_signature(shapes)),
        stats=dict(stats or {}),
    )
    return revalidate(level)
