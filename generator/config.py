"""Generator settings: one frozen dataclass per family (stacking, puzzles) and a registry of
named stacking configurations.

As in reasoning-gym, a configuration is plain data (it pickles to any worker and is written into
every run summary) and ``make(config, seed, index)`` is the only code that reads it. The named
configurations carry the per-box limits of the CHAIN generator (most pieces, least search
effort for hard levels); :func:`stacking_config` builds one for any other box.
"""

from __future__ import annotations

import dataclasses
import re
from dataclasses import dataclass
from typing import Any, Final, Literal

from chaingeo.core.registry import Registry
from chaingeo.core.rules import SUPPORT_RULES, SupportRule

Mode = Literal["easy", "mid", "hard"]
MODES: Final[tuple[str, ...]] = ("easy", "mid", "hard")

#: Largest cuboid piece in easy mode: a 2x2x2 cube is the biggest cuboid with two equal sides
#: and no filled 2x3 face.
EASY_MAX_PIECE_CELLS: Final = 8


@dataclass(frozen=True)
class StackingConfig:
    """How to make one stacking level.

    ``min_piece`` is tried for the first half of ``attempts``; then ``fallback_min_piece``
    (None: no fallback) for the rest. ``min_nodes`` is the least exact-cover search effort
    (nodes to the first packing) a level must need. ``planar`` (mid mode) keeps every piece in
    one plane after repair; without it pieces are only grown in a plane. ``count_limit`` is
    the node budget for counting every packing (0: do not count).
    """

    box: tuple[int, int, int]
    mode: Mode
    min_piece: int = 4
    fallback_min_piece: int | None = 3
    max_piece_cells: int = 5
    max_pieces: int = 13
    min_nodes: int = 0
    linear_assembly: bool = True
    planar: bool = True
    attempts: int = 400
    repair_moves: int = 64
    easy_packings: int = 64
    count_limit: int = 200_000
    support: SupportRule = "contact"

    def __post_init__(self) -> None:
        box = tuple(int(v) for v in self.box)
        object.__setattr__(self, "box", box)
        if len(box) != 3 or min(box) < 1:
            raise ValueError(f"box must be three positive sizes, got {list(self.box)}")
        if box[0] * box[1] * box[2] < 2:
            raise ValueError("the box must hold at least two cells")
        if self.mode not in MODES:
            raise ValueError(f"mode {self.mode!r} is not one of {list(MODES)}")
        if not 1 <= self.min_piece <= self.max_piece_cells:
            raise ValueError(
                f"need 1 <= min_piece <= max_piece_cells, got {self.min_piece}, "
                f"{self.max_piece_cells}"
            )
        if self.fallback_min_piece is not None and self.fallback_min_piece < 1:
            raise ValueError(f"fallback_min_piece must be >= 1, got {self.fallback_min_piece}")
        if self.max_pieces < 2:
            raise ValueError(
                f"max_pieces must be >= 2 (a level has two pieces or more), got {self.max_pieces}"
            )
        if self.attempts < 1:
            raise ValueError(f"attempts must be >= 1, got {self.attempts}")
        for name in ("min_nodes", "repair_moves", "easy_packings", "count_limit"):
            if getattr(self, name) < 0:
                raise ValueError(f"{name} must be >= 0, got {getattr(self, name)}")
        if self.support not in SUPPORT_RULES:
            raise ValueError(f"support {self.support!r} is not one of {list(SUPPORT_RULES)}")

    @property
    def volume(self) -> int:
        a, b, c = self.box
        return a * b * c

    @property
    def stages(self) -> list[tuple[int, int]]:
        """``(min_piece, attempts)`` per stage: the staged fallback (e.g. 4 then 3)."""
        if self.fallback_min_piece is None or self.fallback_min_piece == self.min_piece:
            return [(self.min_piece, self.attempts)]
        first = (self.attempts + 1) // 2
        return [(self.min_piece, first), (self.fallback_min_piece, self.attempts - first)]

    def to_json(self) -> dict[str, Any]:
        out = dataclasses.asdict(self)
        out["box"] = list(self.box)
        return out

    def replace(self, **changes: Any) -> StackingConfig:
        return dataclasses.replace(self, **changes)


@dataclass(frozen=True)
class BoxLimits:
    """Per-box limits of the CHAIN generator: most pieces, least search effort for hard."""

    max_pieces: int
    hard_min_nodes: int


#: The boxes of the CHAIN stacking split. ``max_pieces`` follows the CHAIN generator;
#: ``hard_min_nodes`` is about the median, over 40 hard partitions per box, of our engine's
#: dancing-links nodes to the first packing, so hard levels are the harder half to search.
BOX_LIMITS: Final[dict[tuple[int, int, int], BoxLimits]] = {
    (2, 2, 2): BoxLimits(2, 0),
    (2, 2, 3): BoxLimits(4, 0),
    (2, 2, 4): BoxLimits(4, 0),
    (2, 3, 3): BoxLimits(5, 10),
    (2, 3, 4): BoxLimits(6, 30),
    (2, 4, 4): BoxLimits(7, 60),
    (3, 3, 3): BoxLimits(6, 25),
    (3, 3, 4): BoxLimits(8, 75),
    (3, 4, 4): BoxLimits(10, 350),
    (4, 4, 4): BoxLimits(13, 1000),
}


def parse_box(text: str) -> tuple[int, int, int]:
    """``"3x3x4"`` -> ``(3, 3, 4)``; ``ValueError`` naming the bad text otherwise."""
    m = re.fullmatch(r"\s*(\d+)\s*[xX]\s*(\d+)\s*[xX]\s*(\d+)\s*", text)
    if not m:
        raise ValueError(f"box {text!r} is not of the form AxBxC, e.g. 3x3x4")
    a, b, c = (int(g) for g in m.groups())
    if min(a, b, c) < 1:
        raise ValueError(f"box {text!r} has a zero side")
    return a, b, c


def box_text(box: tuple[int, int, int]) -> str:
    return "x".join(str(v) for v in box)


def stacking_config(box: tuple[int, int, int], mode: str, **overrides: Any) -> StackingConfig:
    """The default configuration for a box and mode (CHAIN limits when the box is known).

    Unknown boxes get as many pieces as the average piece size of 4.5 cells suggests.
    """
    if mode not in MODES:
        raise ValueError(f"mode {mode!r} is not one of {list(MODES)}")
    a, b, c = sorted(box)
    limits = BOX_LIMITS.get((a, b, c))
    volume = box[0] * box[1] * box[2]
    max_pieces = limits.max_pieces if limits else max(2, round(volume / 4.5))
    fields: dict[str, Any] = {"box": box, "mode": mode, "max_pieces": max_pieces}
    if mode == "easy":
        fields["max_piece_cells"] = EASY_MAX_PIECE_CELLS
    if mode == "hard" and limits is not None:
        fields["min_nodes"] = limits.hard_min_nodes
    if volume <= 12:
        # With 4-cell pieces a box this small holds too few distinct puzzles (2x2x3: two
        # easy, two mid), so it starts at 3 cells.
        fields["min_piece"] = 3
    if mode == "mid" and volume == 8:
        # Planar pieces of 3..5 cells fill a 2x2x2 box only as two 2x2 plates (the easy
        # level); pieces grown in a plane and completed off it give the mid level.
        fields["planar"] = False
    fields.update(overrides)
    return StackingConfig(**fields)


#: The named stacking configs (``2x2x2-easy``, ...); a taken name is refused.
CONFIGS: Registry[StackingConfig] = Registry("stacking config", missing="no {kind} named {name!r}")


def register_config(name: str, config: StackingConfig) -> None:
    CONFIGS.register(name, config)


def get_config(name: str) -> StackingConfig:
    return CONFIGS.get(name)


def config_names() -> list[str]:
    return sorted(CONFIGS)


for _box in BOX_LIMITS:
    for _mode in MODES:
        register_config(f"{box_text(_box)}-{_mode}", stacking_config(_box, _mode))


@dataclass(frozen=True)
class PuzzleConfig:
    """What to make. ``shape``: a layout name (burr3, plate3, burr6, burr12, burr18, burr24,
    burr36), ``burr6x8`` / ``burr6x8u`` (Cutler's standard six-piece burr, 2x2x8 holey sticks;
    ``u``: unique assembly, :mod:`chaingeo.generator.standard_burr`), ``cubeN`` with ``pieces``, or
    ``mazeN`` (a maze burr on an N x N grid, the best of ``hill_steps`` walks); ``min_level``:
    moves until the first part comes free. Towers (burr12..burr36) with ``max_group=1`` are
    built unit by unit (:mod:`chaingeo.generator.deep`)."""

    shape: str = "burr6"
    min_level: int = 1
    pieces: int = 0  # cube partitions only
    hole_rate: float = 0.1  # chance a shared cell starts empty (0: solid burrs); cubes:
    # the share of inner cells left empty (at least one, see chaingeo.generator.cubes)
    hill_steps: int = 300  # improvement steps (cubes: steering one level deeper at a time)
    goal: Literal["disassemble", "assemble"] = "disassemble"
    max_group: int | None = None
    seconds: float | None = None  # optional time limit of each search (machine-dependent!)
    max_states: int = 500_000  # state cap per part in the final search
    max_total_states: int = 3_000_000  # state cap of the whole optimal-plan search
    probe_states: int = 20_000  # state cap of each evaluation while climbing (over: rejected)
    restarts: int = 2  # standard burrs (burr6x8): annealing runs of hill_steps changes each
    unique: bool = False  # standard burrs: keep only designs that assemble in exactly one way

    def __post_init__(self) -> None:
        # Standard burrs need many more holes and steps than the generic defaults: the CLI
        # passes --hole-rate / --hill-steps only when given, so a generic default here means
        # "not asked for" and becomes the family's own (STANDARD_DEFAULTS).
        if self.shape in STANDARD_SHAPES:
            for name, value in STANDARD_DEFAULTS.items():
                if getattr(self, name) == _GENERIC_DEFAULTS[name]:
                    object.__setattr__(self, name, value)

    def to_json(self) -> dict[str, object]:
        return dataclasses.asdict(self)


#: ``--shape`` names of Cutler's standard six-piece burrs (:mod:`chaingeo.generator.standard_burr`):
#: ``burr6x8`` (six 2x2x8 sticks); ``burr6x8u`` also demands that the pieces assemble in
#: exactly one way (the CLI passes configuration by shape name).
STANDARD_SHAPES: Final = ("burr6x8", "burr6x8u")
#: The family's settings where the generic PuzzleConfig defaults (0.1, 300) were left: half of
#: the inner cells empty as the walk's drift (high levels need room to slide; at 15% to 30% the
#: walks stalled at levels 4 to 6) and 3000 single-cube changes per restart. Tuned on 8 items
#: each (seed 1): mean level 6.1 to 6.5 with 5000 changes, 7.0 with 10000 (2 x 5000, 4 x 2500).
STANDARD_DEFAULTS: Final[dict[str, object]] = {"hole_rate": 0.5, "hill_steps": 3000}
_GENERIC_DEFAULTS: Final[dict[str, object]] = {"hole_rate": 0.1, "hill_steps": 300}
