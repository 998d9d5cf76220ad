"""The batch runner: same bytes on every backend, dedup in index order, honest summaries."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from chaingeo.core.geometry import Shape
from chaingeo.core.level import Level, load_levels, stacking_level
from chaingeo.generator.batch import SUMMARY_FILE, GenerationError, GenerationJob, run
from chaingeo.generator.config import get_config
from chaingeo.generator.result import GenerationRejection
from chaingeo.generator.stacking import make
from chaingeo.pictures.pictures import level_pictures

PLATES = [
    Shape([(0, 0, 0), (1, 0, 0), (0, 1, 0), (1, 1, 0)]),
    Shape([(0, 0, 1), (1, 0, 1), (0, 1, 1), (1, 1, 1)]),
]
TRIPODS = [
    Shape([(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)]),
    Shape([(1, 1, 1), (0, 1, 1), (1, 0, 1), (1, 1, 0)]),
]


def fake_make(config: object, seed: int, index: int) -> Level | GenerationRejection:
    """A family of its own: plates, a rejection, tripods, a rejection, plates again..."""
    if index % 2:
        return GenerationRejection("odd-index", seed, index, {"odd-index": 1, "tried-twice": 1})
    packing = PLATES if index % 4 == 0 else TRIPODS
    return stacking_level(f"fake-{index}", "easy", (2, 2, 2), packing, generator="fake")


def _files(folder: Path) -> dict[str, bytes]:
    return {
        str(p.relative_to(folder)): p.read_bytes()
        for p in sorted(folder.rglob("*"))
        if p.is_file() and p.name != SUMMARY_FILE and "signatures" not in p.parts
    }


def _summaries(folder: Path) -> list[dict[str, object]]:
    return [json.loads(line) for line in (folder / SUMMARY_FILE).read_text().splitlines()]


def test_summary_counts_every_outcome_and_attempt(tmp_path: Path) -> None:
    job = GenerationJob("fake", fake_make, None, 0, count=3, max_items=8)
    s = run(job, tmp_path, progress=False)
    assert not s.complete
    assert s.accepted == ["fake-0", "fake-2"]
    assert dict(s.outcomes) == {"accepted": 2, "odd-index": 4, "duplicate-signature": 2}
    assert dict(s.attempt_rejections) == {"odd-index": 4, "tried-twice": 4}
    assert s.items == 8 == sum(s.outcomes.values())
    (line,) = _summaries(tmp_path)
    assert line["accepted"] == 2 and line["outcomes"] == dict(s.outcomes)
    assert line["levels"] == ["fake-0", "fake-2"] and line["backend"] == "serial"
    assert [lv.id for lv in load_levels(tmp_path)] == ["fake-0", "fake-2"]


def test_runs_stop_at_the_count_and_are_idempotent(tmp_path: Path) -> None:
    job = GenerationJob("stacking", make, get_config("2x2x2-easy"), 1, count=1, max_items=3)
    first = run(job, tmp_path, progress=False)
    assert first.accepted == ["stacking-2x2x2-easy-s1-000000"] and first.items == 1
    before = _files(tmp_path)
    again = run(job, tmp_path, progress=False)  # the same level owns its reservation
    assert again.accepted == first.accepted and _files(tmp_path) == before
    other = GenerationJob("stacking", make, get_config("2x2x2-easy"), 2, count=1, max_items=3)
    dup = run(other, tmp_path, progress=False)  # a 2x2x2 box has one easy puzzle only
    assert dup.accepted == [] and dict(dup.outcomes) == {"duplicate-signature": 3}
    assert len(_summaries(tmp_path)) == 3


def test_a_different_level_under_an_existing_id_stops_the_run(tmp_path: Path) -> None:
    (tmp_path / "fake-0.json").write_text("{}")
    job = GenerationJob("fake", fake_make, None, 0, count=1)
    with pytest.raises(GenerationError, match="already holds a different level"):
        run(job, tmp_path, progress=False)
    assert not list((tmp_path / "signatures").iterdir())  # the reservation was given back


def test_bad_jobs_are_refused(tmp_path: Path) -> None:
    with pytest.raises(ValueError, match="count"):
        GenerationJob("fake", fake_make, None, 0, count=0)
    with pytest.raises(ValueError, match="max_items"):
        GenerationJob("fake", fake_make, None, 0, count=5, max_items=2)
    with pytest.raises(ValueError, match="jobs"):
        run(GenerationJob("fake", fake_make, None, 0, count=1), tmp_path, jobs=0)


def _stacking_job(pictures: bool) -> GenerationJob:
    return GenerationJob(
        "stacking",
        make,
        get_config("2x2x3-mid"),
        9,
        count=3,
        pictures=level_pictures if pictures else None,
    )


def test_joblib_workers_write_the_same_bytes_as_one_process(tmp_path: Path) -> None:
    serial = run(_stacking_job(True), tmp_path / "serial", progress=False)
    pooled = run(_stacking_job(True), tmp_path / "pooled", jobs=2, progress=False)
    assert pooled.backend == "joblib" and pooled.workers == 2
    assert serial.accepted == pooled.accepted and len(serial.accepted) == 3
    files = _files(tmp_path / "serial")
    assert files == _files(tmp_path / "pooled")
    pngs = [k for k in files if k.endswith(".png")]
    assert len(pngs) == 6 and all(files[k].startswith(b"\x89PNG") for k in pngs)


def test_a_dask_cluster_of_two_workers_writes_the_same_bytes(tmp_path: Path) -> None:
    distributed = pytest.importorskip("distributed")
    serial = run(_stacking_job(False), tmp_path / "serial", progress=False)
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    ) as cluster:
        remote = run(
            _stacking_job(False), tmp_path / "dask", dask=cluster.scheduler_address, progress=False
        )
    assert remote.backend == "dask" and remote.workers == 2
    assert remote.accepted == serial.accepted
    assert _files(tmp_path / "dask") == _files(tmp_path / "serial")
