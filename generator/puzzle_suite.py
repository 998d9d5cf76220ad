"""The shipped 32-level puzzle suite (``levels/puzzle``), rebuilt byte for byte.

``chain generate puzzle-suite --models DIR [--out levels/puzzle] [--jobs N]``. Two kinds of
entry, listed in :data:`SUITE`:

* :class:`ModelEntry`: one of CHAIN's published puzzle models (``DIR/NAME``, the folder of
  ``chain import``), imported by :func:`chaingeo.generator.imported.imported_puzzle_level` exactly
  as ``chain import`` does; its tier is what the solver's figures give, and the build stops when
  that is not the entry's tier.
* :class:`PuzzleSuiteEntry`: a generator configuration and seed; items ``0, 1, 2, ...`` of the seed
  are made with :func:`chaingeo.generator.puzzle.make` and the first ones whose tier (from the
  solver's figures, :func:`chaingeo.generator.puzzle.difficulty_of`) is the entry's and whose
  signature is new within the entry are kept. A puzzle made by two entries stops the build (change a
  seed).

Entries are independent, so they run in parallel; ids are then given in :data:`SUITE` order, and
each level gets its complete counts (:mod:`chaingeo.generator.counts`).
Every search is bounded by state caps only, never by time, so every machine makes the same
files.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Literal

from chaingeo.core.formats.models import import_model
from chaingeo.core.level import Difficulty, Level, load_level, revalidate, save_level
from chaingeo.generator.config import PuzzleConfig
from chaingeo.generator.counts import count_level, reuse_counts
from chaingeo.generator.imported import imported_puzzle_level
from chaingeo.generator.puzzle import make
from chaingeo.generator.result import GenerationRejection
from chaingeo.solvers.jobs import Farm
from chaingeo.solvers.limits import SearchLimits

Goal = Literal["disassemble", "assemble"]


@dataclass(frozen=True)
class PuzzleSuiteEntry:
    """``count`` generated levels of one configuration and seed."""

    difficulty: Difficulty
    config: PuzzleConfig
    seed: int
    count: int
    goals: tuple[Goal, ...]  # goal of each of the ``count`` levels, in order


@dataclass(frozen=True)
class ModelEntry:
    """One of CHAIN's models, once per goal in ``goals``."""

    difficulty: Difficulty
    model: str  # folder name under the models root
    goals: tuple[Goal, ...]
    turns: bool = False  # a model that needs quarter turns (its round rods spin)

    @property
    def name(self) -> str:
        return self.model.removesuffix("-puzzle")


#: The caps of a model's analysis in the suite: states only (no clock), so every machine
#: agrees; the largest model (luban-15-piece) needs far fewer.
MODEL_LIMITS = SearchLimits(max_states=500_000, seconds=None, max_total_states=3_000_000)

_EASY6 = PuzzleConfig(shape="burr6", hole_rate=0.1, hill_steps=0, min_level=2)
_HOLEY = PuzzleConfig(shape="burr6", hole_rate=0.1, hill_steps=300, min_level=3)
_HOLEY4 = PuzzleConfig(shape="burr6", hole_rate=0.1, hill_steps=400, min_level=4)
_BURR3E = PuzzleConfig(shape="burr3", hole_rate=0.8, hill_steps=20, min_level=2)
_BURR3M = PuzzleConfig(shape="burr3", hole_rate=0.8, hill_steps=100, min_level=3)
_PLATE3E = PuzzleConfig(shape="plate3", hole_rate=0.4, hill_steps=20, min_level=2)
_PLATE3M = PuzzleConfig(shape="plate3", hole_rate=0.4, hill_steps=100, min_level=3)
_CUBE3 = PuzzleConfig(shape="cube3", pieces=3, min_level=2, hole_rate=0.3, hill_steps=0)
_CUBE4 = PuzzleConfig(shape="cube4", pieces=6, min_level=3, hole_rate=0.5, hill_steps=0)
_CUBE4H = PuzzleConfig(shape="cube4", pieces=6, min_level=5, hole_rate=0.5, hill_steps=20000)
_TOWER = PuzzleConfig(shape="burr12", hole_rate=0.1, hill_steps=100)
_TOWER36 = PuzzleConfig(shape="burr36", hole_rate=0.1, hill_steps=0, max_group=1)
_STANDARD = PuzzleConfig(shape="burr6x8", min_level=7)

D: Goal = "disassemble"
A: Goal = "assemble"

#: 10 easy, 12 mid, 10 hard. Every CHAIN model that imports exactly, in the tier its figures
#: give; the generators fill the rest: six-piece burrs (Cutler's standard 2x2x8 burrs of level
#: 7 and up in the hard tier), three-piece and three-plate burrs, interlocking cubes, a
#: 12-piece tower and two 36-piece towers. Both goals in every tier; most generated levels ask
#: for assembly, which neither baseline manages (docs/benchmarks/baselines.md, 'The puzzle suite').
SUITE: tuple[PuzzleSuiteEntry | ModelEntry, ...] = (
    ModelEntry("easy", "luban-3-piece", (D,), turns=True),
    ModelEntry("easy", "luban-6-piece", (D, A)),
    PuzzleSuiteEntry("easy", _EASY6, 101, 3, (D, A, A)),
    PuzzleSuiteEntry("easy", _BURR3E, 401, 1, (A,)),
    PuzzleSuiteEntry("easy", _PLATE3E, 411, 1, (A,)),
    PuzzleSuiteEntry("easy", _CUBE3, 102, 2, (A, A)),
    ModelEntry("mid", "interlocking-cube-puzzle", (D, A)),
    # disassembly only: the reverse of its optimal plan joins sticks that do not touch, which
    # the assembly rules forbid (parts join only where their bounding boxes touch)
    ModelEntry("mid", "luban-15-piece", (D,)),
    PuzzleSuiteEntry("mid", _TOWER, 303, 1, (D,)),
    PuzzleSuiteEntry("mid", _HOLEY, 201, 1, (A,)),
    PuzzleSuiteEntry("mid", _HOLEY4, 301, 2, (A, A)),
    PuzzleSuiteEntry("mid", _BURR3M, 402, 1, (A,)),
    PuzzleSuiteEntry("mid", _PLATE3M, 412, 1, (A,)),
    PuzzleSuiteEntry("mid", _CUBE4, 202, 3, (A, A, A)),
    ModelEntry("hard", "liliput", (A,)),
    ModelEntry("hard", "three-plate-burr-puzzle", (A,)),
    ModelEntry("hard", "luban-separate-pieces", (A,)),
    PuzzleSuiteEntry("hard", _STANDARD, 2026, 4, (D, A, A, A)),
    PuzzleSuiteEntry("hard", _TOWER36, 401, 2, (D, A)),
    PuzzleSuiteEntry("hard", _CUBE4H, 302, 1, (A,)),
)


def model_items(entry: ModelEntry, models: Path) -> list[Level]:
    """The entry's model imported once per goal (ids not yet given)."""
    model = import_model(models / entry.model, "puzzle")
    made = []
    for goal in entry.goals:
        level, _ = imported_puzzle_level(
            model,
            goal=goal,
            turns=entry.turns,
            limits=MODEL_LIMITS,
        )
        if level.difficulty != entry.difficulty:
            raise RuntimeError(
                f"{entry.model} is {level.difficulty} by its figures, not {entry.difficulty}"
            )
        made.append(level)
    return made


def entry_items(entry: PuzzleSuiteEntry, max_items: int = 400) -> list[Level]:
    """The first ``entry.count`` items of the entry's seed with its difficulty and distinct
    signatures (ids not yet given). Entries are independent, so they can run in parallel."""
    seen: set[str] = set()
    made: list[Level] = []
    for index in range(max_items):
        if len(made) == entry.count:
            break
        goal = entry.goals[len(made)]
        item = make(dataclasses.replace(entry.config, goal=goal), entry.seed, index)
        if isinstance(item, GenerationRejection):
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


def _items(entry: PuzzleSuiteEntry | ModelEntry, models: Path, max_items: int) -> list[Level]:
    if isinstance(entry, ModelEntry):
        return model_items(entry, models)
    return entry_items(entry, max_items)


def _shape_of(entry: PuzzleSuiteEntry | ModelEntry) -> str:
    return entry.name if isinstance(entry, ModelEntry) else entry.config.shape


def build_puzzle_suite(
    out: Path,
    models: Path,
    *,
    max_items: int = 400,
    jobs: int = 1,
    log: Callable[[str], None] | None = None,
    counts_from: Path | None = None,
) -> list[Level]:
    """Build every entry of :data:`SUITE` into ``out`` (old ``puzzle-*.json`` removed), CHAIN's
    models read from ``models``; ``jobs`` entries at a time (joblib processes), the same bytes
    for any ``jobs``. Each level then gets its complete counts (:mod:`chaingeo.generator.counts`):
    those stored in ``counts_from`` (default: ``out`` as it was) for the same puzzle, else
    counted on ``jobs`` worker processes."""
    if not models.is_dir():
        raise RuntimeError(
            f"{models}: no such folder (CHAIN's models, e.g. ../shared/chain-models)"
        )
    if jobs > 1:
        from joblib import Parallel, delayed

        per_entry = Parallel(n_jobs=jobs)(delayed(_items)(e, models, max_items) for e in SUITE)
    else:
        per_entry = [_items(e, models, max_items) for e in SUITE]
    owner: dict[str, str] = {}
    for entry, items in zip(SUITE, per_entry, strict=True):
        where = (
            f"model {entry.model}"
            if isinstance(entry, ModelEntry)
            else f"{entry.config.shape} seed {entry.seed}"
        )
        for item in items:
            first = owner.setdefault(item.provenance.signature, where)
            if first != where:
                raise RuntimeError(f"the same puzzle comes from {first} and {where}: change a seed")
    stored = [load_level(p) for p in sorted((counts_from or out).glob("puzzle-*.json"))]
    out.mkdir(parents=True, exist_ok=True)
    for old in sorted(out.glob("puzzle-*.json")):
        old.unlink()
    made: list[Level] = []
    number = {"easy": 0, "mid": 0, "hard": 0}
    for entry, items in zip(SUITE, per_entry, strict=True):
        for item in items:
            number[entry.difficulty] += 1
            level_id = (
                f"puzzle-{entry.difficulty}-{number[entry.difficulty]:02d}-{_shape_of(entry)}"
            )
            level = revalidate(dataclasses.replace(item, id=level_id))
            level = reuse_counts(level, stored) or count_level(level, Farm(jobs))
            save_level(level, out / f"{level_id}.json")
            made.append(level)
            if log is not None:
                log(
                    f"{level_id}: optimal_steps {level.optimal_steps}, level {level.stats['level']}"
                )
    return made
