"""Generate levels of any family at scale: serially, with joblib locally, or on a Dask cluster.

Underneath is one pure function per family,
``make(config, seed, index) -> Level | GenerationRejection``; a worker runs it (and draws the
pictures) and sends back bytes. The runner, the only writer, takes the results strictly in index
order, reserves each signature (:mod:`chaingeo.generator.dedup`) and writes the accepted ones,
until ``count`` levels are accepted or ``max_items`` indices were tried. So which levels come
out, and their bytes, do not depend on the backend or the
number of workers. Output folder::

    OUT/<level id>.json                  chain-level/1 files (``chain validate OUT`` reads them)
    OUT/pictures/<level id>-<view>.png   the assembly and the pieces
    OUT/signatures/<signature>           reservations (content: the level id)
    OUT/summary.jsonl                    one JSON summary per run: counts of every outcome
"""

from __future__ import annotations

import importlib
import json
import os
import sys
import time
from collections import Counter
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from chaingeo.core.errors import ChainGeoError
from chaingeo.core.files import atomic_write
from chaingeo.core.level import Level, level_bytes
from chaingeo.generator.dedup import Reservation, SignatureStore
from chaingeo.generator.result import ATTEMPTS_KEY, GenerationRejection
from chaingeo.generator.signature import level_signature

MakeFn = Callable[[Any, int, int], "Level | GenerationRejection"]
PictureFn = Callable[[Level], dict[str, bytes]]
SUMMARY_FILE = "summary.jsonl"
PICTURES_DIR = "pictures"
DUPLICATE = "duplicate-signature"
#: The outcome of a level whose split signature is held out (a shipped level, for a train split).
HELD_OUT = "held-out-signature"


class GenerationError(ChainGeoError, RuntimeError):
    """The run cannot go on (e.g. the output folder holds a different level with the same id)."""


@dataclass(frozen=True)
class GenerationJob:
    """What to generate: ``count`` levels of ``family`` from items ``first_index`` onwards.

    ``make`` and ``pictures`` must be module-level functions (they travel to workers by name).
    ``held_out``: split signatures (:mod:`chaingeo.generator.signature`) never accepted, each such
    level counted as :data:`HELD_OUT` (a train split holds out the shipped suite).
    """

    family: str
    make: MakeFn
    config: Any
    seed: int
    count: int
    max_items: int | None = None
    first_index: int = 0
    pictures: PictureFn | None = None
    held_out: frozenset[str] = frozenset()

    def __post_init__(self) -> None:
        if self.count < 1:
            raise ValueError(f"count must be >= 1, got {self.count}")
        if self.max_items is not None and self.max_items < self.count:
            raise ValueError(f"max_items ({self.max_items}) must be >= count ({self.count})")
        if self.first_index < 0:
            raise ValueError(f"first_index must be >= 0, got {self.first_index}")

    @property
    def item_limit(self) -> int:
        return self.max_items if self.max_items is not None else max(10 * self.count, 100)

    @property
    def indices(self) -> range:
        return range(self.first_index, self.first_index + self.item_limit)


@dataclass(frozen=True)
class ItemResult:
    """One item's outcome as sent back by a worker (plain bytes, cheap to pickle)."""

    index: int
    level_id: str | None = None
    signature: str | None = None
    split_signature: str | None = None
    level: bytes | None = None
    pictures: dict[str, bytes] = field(default_factory=dict)
    reason: str | None = None
    attempts: dict[str, int] = field(default_factory=dict)
    seconds: float = 0.0


def run_item(
    make: MakeFn, config: Any, seed: int, index: int, pictures: PictureFn | None
) -> ItemResult:
    """Make item ``index`` (and its pictures); runs on a worker."""
    t0 = time.perf_counter()
    out = make(config, seed, index)
    if isinstance(out, GenerationRejection):
        return ItemResult(
            index,
            reason=out.reason,
            attempts=dict(out.attempts),
            seconds=time.perf_counter() - t0,
        )
    pics = pictures(out) if pictures is not None else {}
    return ItemResult(
        index,
        level_id=out.id,
        signature=out.provenance.signature,
        split_signature=level_signature(out),
        level=level_bytes(out),
        pictures=pics,
        attempts=dict(out.stats.get(ATTEMPTS_KEY, {})),
        seconds=time.perf_counter() - t0,
    )


# ---------------------------------------------------------------------------------------------
# Backends: each yields ItemResults in index order and stops cleanly when the caller stops
# ---------------------------------------------------------------------------------------------


def _serial(job: GenerationJob) -> Iterator[ItemResult]:
    for i in job.indices:
        yield run_item(job.make, job.config, job.seed, i, job.pictures)


def _ordered(
    submit: Callable[[int], Any],
    wait_first: Callable[[list[Any]], Iterable[Any]],
    cancel: Callable[[list[Any]], None],
    indices: range,
    window: int,
) -> Iterator[ItemResult]:
    """Keep ``window`` items in flight, yield results in index order, cancel the rest on exit."""
    todo = iter(indices)
    live: list[Any] = []
    buffer: dict[int, ItemResult] = {}
    expected = indices.start
    try:
        while True:
            while len(live) < window:
                i = next(todo, None)
                if i is None:
                    break
                live.append(submit(i))
            if not live:
                return
            for fut in wait_first(live):
                live.remove(fut)
                res: ItemResult = fut.result()
                buffer[res.index] = res
            while expected in buffer:
                yield buffer.pop(expected)
                expected += 1
    finally:
        cancel(live)


def _joblib(job: GenerationJob, n_jobs: int) -> Iterator[ItemResult]:
    """joblib's process executor (loky), reused across runs so workers stay warm."""
    from concurrent.futures import FIRST_COMPLETED, wait

    from joblib.externals.loky import get_reusable_executor

    pool = get_reusable_executor(max_workers=n_jobs, reuse=True)

    def submit(i: int) -> Any:
        return pool.submit(run_item, job.make, job.config, job.seed, i, job.pictures)

    def wait_first(live: list[Any]) -> Iterable[Any]:
        return wait(live, return_when=FIRST_COMPLETED).done

    def cancel(live: list[Any]) -> None:
        for fut in live:
            fut.cancel()

    yield from _ordered(submit, wait_first, cancel, job.indices, 2 * n_jobs)


def _dask(job: GenerationJob, address: str) -> Iterator[ItemResult]:
    distributed = _distributed()
    with distributed.Client(address, set_as_default=False) as client:
        done = distributed.as_completed(loop=client.loop)

        def submit(i: int) -> Any:
            fut = client.submit(
                run_item, job.make, job.config, job.seed, i, job.pictures, pure=False
            )
            done.add(fut)
            return fut

        def wait_first(live: list[Any]) -> Iterable[Any]:
            return [next(done)]

        window = max(2, 2 * sum(client.nthreads().values()))
        yield from _ordered(submit, wait_first, client.cancel, job.indices, window)


def dask_workers(address: str) -> int:
    """Worker threads of the Dask cluster at ``address``."""
    with _distributed().Client(address, set_as_default=False) as client:
        return int(sum(client.nthreads().values()))


def _distributed() -> Any:
    """The ``distributed`` package (the ``cluster`` extra), untyped: its annotations are partial."""
    try:
        return importlib.import_module("distributed")
    except ImportError:
        raise GenerationError(
            "--dask needs the cluster extra: pip install 'chaingeo[cluster]'"
        ) from None


# ---------------------------------------------------------------------------------------------
# The runner
# ---------------------------------------------------------------------------------------------


@dataclass
class BatchSummary:
    family: str
    config: Any
    seed: int
    requested: int
    backend: str
    workers: int
    accepted: list[str] = field(default_factory=list)
    items: int = 0
    outcomes: Counter[str] = field(default_factory=Counter)
    attempt_rejections: Counter[str] = field(default_factory=Counter)
    seconds: float = 0.0
    worker_seconds: float = 0.0

    @property
    def complete(self) -> bool:
        return len(self.accepted) >= self.requested

    def to_json(self) -> dict[str, Any]:
        cfg = self.config.to_json() if hasattr(self.config, "to_json") else repr(self.config)
        return {
            "family": self.family,
            "config": cfg,
            "seed": self.seed,
            "requested": self.requested,
            "accepted": len(self.accepted),
            "items": self.items,
            "outcomes": dict(sorted(self.outcomes.items())),
            "attempt_rejections": dict(sorted(self.attempt_rejections.items())),
            "levels": list(self.accepted),
            "backend": self.backend,
            "workers": self.workers,
            "seconds": round(self.seconds, 3),
            "worker_seconds": round(self.worker_seconds, 3),
        }


def _store(out: Path, store: SignatureStore, res: ItemResult) -> bool:
    """Reserve and write one level; False if its puzzle is already taken."""
    assert res.level is not None and res.level_id is not None and res.signature is not None
    got = store.reserve(res.signature, res.level_id)
    if got is Reservation.TAKEN:
        return False
    path = out / f"{res.level_id}.json"
    if path.exists() and path.read_bytes() != res.level:
        if got is Reservation.NEW:
            store.release(res.signature, res.level_id)
        raise GenerationError(
            f"{path} already holds a different level with id {res.level_id}; "
            "use another output folder or seed"
        )
    atomic_write(path, res.level)
    if res.pictures:
        (out / PICTURES_DIR).mkdir(exist_ok=True)
        for view, png in sorted(res.pictures.items()):
            atomic_write(out / PICTURES_DIR / f"{res.level_id}-{view}.png", png)
    return True


def run(
    job: GenerationJob,
    out: str | os.PathLike[str],
    *,
    jobs: int = 1,
    dask: str | None = None,
    progress: bool = True,
    write_summary: bool = True,
) -> BatchSummary:
    """Generate ``job.count`` levels into ``out``; returns (and appends to
    ``OUT/summary.jsonl``) the summary, with a count for every outcome and attempt reason."""
    if jobs < 1:
        raise ValueError(f"jobs must be >= 1, got {jobs}")
    folder = Path(out)
    folder.mkdir(parents=True, exist_ok=True)
    store = SignatureStore(folder)
    if dask is not None:
        backend, workers, results = "dask", dask_workers(dask), _dask(job, dask)
    elif jobs > 1:
        backend, workers, results = "joblib", jobs, _joblib(job, jobs)
    else:
        backend, workers, results = "serial", 1, _serial(job)
    summary = BatchSummary(job.family, job.config, job.seed, job.count, backend, workers)
    from tqdm import tqdm

    bar = tqdm(
        total=job.count, unit="level", desc=job.family, disable=not progress, file=sys.stderr
    )
    t0 = time.perf_counter()
    try:
        for res in results:
            summary.items += 1
            summary.worker_seconds += res.seconds
            summary.attempt_rejections.update(res.attempts)
            if res.level is None:
                summary.outcomes[res.reason or "rejected"] += 1
            elif res.split_signature in job.held_out:
                summary.outcomes[HELD_OUT] += 1
            elif _store(folder, store, res):
                summary.outcomes["accepted"] += 1
                summary.accepted.append(res.level_id or "")
                bar.update(1)
            else:
                summary.outcomes[DUPLICATE] += 1
            bar.set_postfix(items=summary.items, refresh=False)
            if summary.complete:
                break
    finally:
        close = getattr(results, "close", None)
        if close is not None:
            close()
        bar.close()
    summary.seconds = time.perf_counter() - t0
    if write_summary:
        with open(folder / SUMMARY_FILE, "a", encoding="utf-8") as f:
            f.write(json.dumps(summary.to_json(), sort_keys=True) + "\n")
    return summary
