"""The shipped stacking suite: exactly the CHAIN split, 77 levels, from fixed seeds.

``chain generate suite`` runs every entry below, in this order, into one scratch folder (so
no two levels of the suite share a puzzle signature), then copies the level files into
``levels/stacking``. Running it again reproduces the files byte for byte (with the same
exact-cover engine: hard levels are selected by its node counts, and every file records them).
"""

from __future__ import annotations

import os
import shutil
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import Final

from chaingeo.generator.batch import BatchSummary, GenerationJob, PictureFn, run
from chaingeo.generator.config import StackingConfig, get_config
from chaingeo.generator.stacking import GENERATOR, make

DEFAULT_OUT: Final = Path("levels") / "stacking"


@dataclass(frozen=True)
class SuiteEntry:
    box: tuple[int, int, int]
    mode: str
    count: int
    seed: int

    @property
    def config(self) -> StackingConfig:
        a, b, c = self.box
        return get_config(f"{a}x{b}x{c}-{self.mode}")

    def job(self) -> GenerationJob:
        return GenerationJob("stacking", make, self.config, self.seed, self.count)


#: (box, mode, count, seed): 10 easy, 20 mid, 47 hard, as in CHAIN.
SUITE: Final[tuple[SuiteEntry, ...]] = tuple(
    SuiteEntry(box, mode, count, seed)
    for box, mode, count, seed in (
        ((2, 2, 2), "easy", 1, 101),
        ((2, 2, 2), "mid", 1, 102),
        ((2, 2, 3), "easy", 3, 103),
        ((2, 2, 3), "mid", 3, 104),
        ((2, 2, 4), "easy", 3, 105),
        ((2, 2, 4), "mid", 2, 106),
        ((2, 3, 3), "easy", 2, 107),
        ((2, 3, 3), "mid", 4, 108),
        ((2, 3, 3), "hard", 4, 109),
        ((2, 3, 4), "easy", 1, 110),
        ((2, 3, 4), "mid", 3, 111),
        ((2, 3, 4), "hard", 5, 112),
        ((2, 4, 4), "hard", 8, 113),
        ((3, 3, 3), "mid", 5, 114),
        ((3, 3, 3), "hard", 5, 115),
        ((3, 3, 4), "mid", 2, 116),
        ((3, 3, 4), "hard", 5, 117),
        ((3, 4, 4), "hard", 10, 118),
        ((4, 4, 4), "hard", 10, 119),
    )
)


def suite_entry(box: tuple[int, int, int], mode: str) -> SuiteEntry:
    for e in SUITE:
        if e.box == box and e.mode == mode:
            return e
    raise KeyError(f"no suite entry for {box} {mode}")


def build_suite(
    out: str | os.PathLike[str] = DEFAULT_OUT,
    *,
    jobs: int = 1,
    dask: str | None = None,
    progress: bool = True,
    pictures: str | os.PathLike[str] | None = None,
    picture_maker: PictureFn | None = None,
) -> list[BatchSummary]:
    """Generate the whole suite and write its level files into ``out``.

    Earlier suite files in ``out`` (levels made by this generator) are replaced; other files
    are left alone. With ``pictures``, the pictures ``picture_maker`` draws of each level go to
    that folder. Raises :class:`RuntimeError` if some entry cannot be filled.
    """
    if (pictures is None) != (picture_maker is None):
        raise ValueError("pictures and picture_maker go together")

    target = Path(out)
    summaries: list[BatchSummary] = []
    with tempfile.TemporaryDirectory(prefix="chain-suite-") as scratch:
        for entry in SUITE:
            job = entry.job()
            if pictures is not None:
                job = GenerationJob(
                    job.family, job.make, job.config, job.seed, job.count, pictures=picture_maker
                )
            s = run(job, scratch, jobs=jobs, dask=dask, progress=progress, write_summary=False)
            summaries.append(s)
            if not s.complete:
                raise RuntimeError(
                    f"suite entry {entry.box} {entry.mode}: only {len(s.accepted)} of "
                    f"{entry.count} levels in {s.items} items ({dict(s.outcomes)})"
                )
        target.mkdir(parents=True, exist_ok=True)
        for old in sorted(target.glob("stacking-*.json")):
            if f'"generator": "{GENERATOR}"' in old.read_text(encoding="utf-8"):
                old.unlink()
        for s in summaries:
            for level_id in s.accepted:
                shutil.copyfile(Path(scratch) / f"{level_id}.json", target / f"{level_id}.json")
        if pictures is not None:
            shutil.copytree(Path(scratch) / "pictures", Path(pictures), dirs_exist_ok=True)
    return summaries
