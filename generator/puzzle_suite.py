"""The shipped 32-level puzzle suite (``levels/puzzle``), rebuilt byte for byte from fixed seeds.

``chain generate puzzle-suite [--out levels/puzzle] [--jobs N]``: for each entry of
:data:`SUITE` it tries items ``0, 1, 2, ...`` of the entry's seed with
:func:`generator.puzzle.make` and keeps the first ones whose difficulty (computed from the
solver's figures, see :func:`generator.puzzle.difficulty_of`) is the entry's and whose signature
is new within the entry; a puzzle made by two entries stops the build (change a seed). Entries
are independent, so they run in parallel; ids are then given in :data:`SUITE` order. Every
search is bounded by state caps only, never by time, so every machine makes the same files.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from chaingeo.core.level import Difficulty, Level, revalidate, save_level
from generator.config import PuzzleConfig
from generator.puzzle import make
from generator.result import Rejection


@dataclass(frozen=True)
class SuiteEntry:
    difficulty: Difficulty
    config: PuzzleConfig
    seed: int
    count: int
    goals: tuple[str, ...]  # goal of each of the ``count`` levels, in order


_EASY6 = PuzzleConfig(shape="burr6", hole_rate=0.1, hill_steps=0, min_level=2)
_HOLEY = PuzzleConfig(shape="burr6", hole_rate=0.1, hill_steps=300, min_level=3)
_HARD6 = PuzzleConfig(shape="burr6", hole_rate=0.1, hill_steps=400, min_level=4)
_BURR3E = PuzzleConfig(shape="burr3", hole_rate=0.8, hill_steps=20, min_level=2)
_BURR3M = PuzzleConfig(shape="burr3", hole_rate=0.8, hill_steps=100, min_level=3)
_BURR3H = PuzzleConfig(shape="burr3", hole_rate=0.8, hill_steps=150, min_level=4)
_PLATE3E = PuzzleConfig(shape="plate3", hole_rate=0.4, hill_steps=20, min_level=2)
_PLATE3M = PuzzleConfig(shape="plate3", hole_rate=0.4, hill_steps=100, min_level=3)
_CUBE3 = PuzzleConfig(shape="cube3", pieces=3, min_level=2, hole_rate=0.3, hill_steps=0)
_CUBE4 = PuzzleConfig(shape="cube4", pieces=6, min_level=3, hole_rate=0.5, hill_steps=0)
_CUBE4H = PuzzleConfig(shape="cube4", pieces=6, min_level=3, hole_rate=0.5, hill_steps=20000)
_TOWER = PuzzleConfig(shape="burr12", hole_rate=0.1, hill_steps=100)
_TOWER36 = PuzzleConfig(shape="burr36", hole_rate=0.1, hill_steps=0, max_group=1)

D, A = "disassemble", "assemble"

#: 10 easy, 12 mid, 10 hard: six-piece burrs, three-piece and three-plate burrs, larger burrs
#: (12 pieces and up) and interlocking cubes, both goals in every family.
SUITE: tuple[SuiteEntry, ...] = (
    SuiteEntry("easy", _EASY6, 101, 3, (D, D, A)),
    SuiteEntry("easy", _BURR3E, 401, 2, (D, A)),
    SuiteEntry("easy", _PLATE3E, 411, 2, (D, A)),
    SuiteEntry("easy", _CUBE3, 102, 3, (D, A, D)),
    SuiteEntry("mid", _HOLEY, 201, 4, (D, D, A, A)),
    SuiteEntry("mid", _BURR3M, 402, 2, (D, A)),
    SuiteEntry("mid", _PLATE3M, 412, 2, (D, A)),
    SuiteEntry("mid", _CUBE4, 202, 4, (D, D, A, D)),
    SuiteEntry("hard", _HARD6, 301, 2, (D, A)),
    SuiteEntry("hard", _BURR3H, 403, 2, (D, A)),
    SuiteEntry("hard", _TOWER, 303, 1, (D,)),
    SuiteEntry("hard", _TOWER36, 401, 2, (D, A)),
    SuiteEntry("hard", _CUBE4H, 302, 3, (D, A, D)),
)


def entry_items(entry: SuiteEntry, max_items: int = 400) -> list[Level]:
    """The first ``entry.count`` items of the entry's seed with its difficulty and distinct
    signatures (ids not yet given). Entries are independent, so they can run in parallel."""
    seen: set[str] = set()
    made: list[Level] = []
    for index in range(max_items):
        if len(made) == entry.count:
            break
        goal = entry.goals[len(made)]
        item = make(dataclasses.replace(entry.config, goal=goal), entry.seed, index)  # type: ignore[arg-type]
        if isinstance(item, Rejection):
            continue
        if item.difficulty != entry.difficulty or item.provenance.signature in seen:
            continue
        seen.add(item.provenance.signature)
        made.append(item)
    if len(made) < entry.count:
        raise RuntimeError(
            f"only {len(made)} of {entry.count} {entry.difficulty} {entry.config.shape} levels "
            f"from seed {entry.seed} in {max_items} items"
        )
    return made


def build_puzzle_suite(
    out: Path,
    *,
    max_items: int = 400,
    jobs: int = 1,
    log: Callable[[str], None] | None = None,
) -> list[Level]:
    """Generate every entry of :data:`SUITE` into ``out`` (old ``puzzle-*.json`` removed);
    ``jobs`` entries at a time (joblib processes), the same bytes for any ``jobs``."""
    if jobs > 1:
        from joblib import Parallel, delayed

        per_entry = Parallel(n_jobs=jobs)(delayed(entry_items)(e, max_items) for e in SUITE)
    else:
        per_entry = [entry_items(e, max_items) for e in SUITE]
    owner: dict[str, str] = {}
    for entry, items in zip(SUITE, per_entry, strict=True):
        for item in items:
            where = f"{entry.config.shape} seed {entry.seed}"
            first = owner.setdefault(item.provenance.signature, where)
            if first != where:
                raise RuntimeError(f"the same puzzle comes from {first} and {where}: change a seed")
    out.mkdir(parents=True, exist_ok=True)
    for old in sorted(out.glob("puzzle-*.json")):
        old.unlink()
    made: list[Level] = []
    number = {"easy": 0, "mid": 0, "hard": 0}
    for entry, items in zip(SUITE, per_entry, strict=True):
        for item in items:
            number[entry.difficulty] += 1
            level_id = (
                f"puzzle-{entry.difficulty}-{number[entry.difficulty]:02d}-{entry.config.shape}"
            )
            level = revalidate(dataclasses.replace(item, id=level_id))
            save_level(level, out / f"{level_id}.json")
            made.append(level)
            if log is not None:
                log(
                    f"{level_id}: optimal_steps {level.optimal_steps}, level {level.stats['level']}"
                )
    return made
