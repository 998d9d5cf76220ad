"""Running an agent over a level suite: episodes in parallel, logged as they finish, resumable.

:func:`evaluate` plans one :class:`~chaingeo.evaluation.play.EpisodeTask` per (level, sample),
skips those a resumed run already recorded, runs the rest (in this process, ``jobs`` worker
processes, or on a Dask cluster) and writes each finished episode (images first, then its
record, fsynced) from this process only, so records never interleave. Killing the run at any
moment loses at most the episodes in flight, which ``--resume`` runs again; none is recorded
twice.

Faults stay inside their episode: whatever an agent or the environment raises, or a worker that
dies under its episode, is recorded as an errored episode (class and message) and the run goes
on, except an :class:`~chaingeo.evaluation.agents.base.AuthenticationError`, which stops the run
at once (no episode would get further). Worker processes die with the run: on Linux the kernel
kills them when the parent dies (``PR_SET_PDEATHSIG``), elsewhere a watchdog thread in each
worker exits once its parent is gone; the multiprocessing resource tracker then sees its pipe
close and exits too.
"""

from __future__ import annotations

import concurrent.futures as cf
import ctypes
import multiprocessing
import os
import signal
import sys
import threading
import time
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, TextIO

from tqdm import tqdm

from chaingeo.core.level import Level, level_set_hash
from chaingeo.evaluation.agents.base import AgentSpec, AuthenticationError
from chaingeo.evaluation.agents.http import api_key
from chaingeo.evaluation.agents.registry import make_agent
from chaingeo.evaluation.episode import Outcome, ProtocolConfig
from chaingeo.evaluation.logs import RunLog, make_header
from chaingeo.evaluation.play import EpisodeResult, EpisodeTask, error_record, run_episode
from chaingeo.evaluation.usage import PriceTable, Usage


@dataclass(frozen=True)
class RunConfig:
    samples: int = 1
    seed: int = 0
    jobs: int = 1
    dask: str | None = None  # scheduler address, e.g. tcp://host:8786
    resume: bool = False
    retry_errors: bool = False
    progress: bool = True


class ProgressBar:
    """Episodes done, solved, tokens and dollars so far: a tqdm bar on a terminal (like the
    generator's); elsewhere (logs, CI) one plain line per finished episode, so a log shows
    progress, and the totals at the end."""

    def __init__(self, label: str, total: int, stream: TextIO | None, enabled: bool) -> None:
        self.label, self.total, self.stream = label, total, stream or sys.stderr
        self.enabled = enabled
        self.done = self.solved = self.errors = 0
        self.tokens = 0
        self.cost: float | None = 0.0
        self.started = time.monotonic()
        self.tty = enabled and bool(getattr(self.stream, "isatty", lambda: False)())
        self._bar = tqdm(
            total=total, desc=label, unit="episode", file=self.stream, disable=not self.tty
        )

    def add(self, record: dict[str, Any], *, resumed: bool = False) -> None:
        """Count one episode; ``resumed``: recorded by an earlier run (no line of its own)."""
        self.done += 1
        self.solved += bool(record.get("success"))
        self.errors += record.get("status") == "error"
        self.tokens += Usage.from_json(record.get("usage", {})).total_tokens
        cost = record.get("cost_usd")
        self.cost = None if cost is None or self.cost is None else self.cost + cost
        if self.tty:
            self._bar.update(1)
            self._bar.set_postfix_str(self.totals())
        elif self.enabled and not resumed:
            outcome = (
                "error"
                if record.get("status") == "error"
                else ("solved" if record.get("success") else "unsolved")
            )
            self.stream.write(f"{self.line()} | {record.get('key', '?')} {outcome}\n")
            self.stream.flush()

    def totals(self) -> str:
        cost = "$?" if self.cost is None else f"${self.cost:.4f}"
        err = f" | {self.errors} errors" if self.errors else ""
        return f"solved {self.solved} | {_tokens(self.tokens)} tok | {cost}{err}"

    def line(self) -> str:
        secs = time.monotonic() - self.started
        return f"[{self.label}] {self.done}/{self.total} | {self.totals()} | {secs:.0f}s"

    def close(self) -> None:
        """Close the bar; print the totals where no bar was shown."""
        self._bar.close()
        if self.enabled and not self.tty:
            self.stream.write(self.line() + "\n")
            self.stream.flush()


def _tokens(n: int) -> str:
    if n >= 1_000_000:
        return f"{n / 1e6:.2f}M"
    if n >= 1_000:
        return f"{n / 1e3:.1f}k"
    return str(n)


#: ``prctl`` option: the signal the kernel sends this process when its parent dies (Linux).
PR_SET_PDEATHSIG = 1
#: How often a worker's watchdog looks for its parent, in seconds.
WATCH_INTERVAL = 0.25


def _die_with_parent(parent: int) -> None:
    """Worker initializer: never outlive the run. On Linux ask the kernel for SIGKILL when the
    parent dies; everywhere, a daemon thread exits the process once it has been reparented."""
    if sys.platform.startswith("linux"):
        try:
            libc = ctypes.CDLL(None, use_errno=True)
            libc.prctl(PR_SET_PDEATHSIG, int(signal.SIGKILL), 0, 0, 0)
        except (OSError, AttributeError):
            pass  # the watchdog below still applies
    if os.getppid() != parent:  # the parent died before the request took effect
        os._exit(1)
    threading.Thread(target=_watch_parent, args=(parent,), daemon=True).start()


def _watch_parent(parent: int) -> None:
    while os.getppid() == parent:
        time.sleep(WATCH_INTERVAL)
    os._exit(1)


def _played(task: EpisodeTask) -> EpisodeResult:
    """``run_episode`` in this process, with anything that still escapes it made a record."""
    try:
        return run_episode(task)
    except AuthenticationError:
        raise
    except Exception as e:
        return error_record(task, e)


def _collected(fut: Any, task: EpisodeTask) -> EpisodeResult:
    """A finished future's result; a worker that died or a result that could not come back
    becomes the episode's error record."""
    try:
        result: EpisodeResult = fut.result()
    except AuthenticationError:
        raise
    except Exception as e:
        return error_record(task, e)
    return result


def _execute(tasks: Sequence[EpisodeTask], cfg: RunConfig) -> Iterator[EpisodeResult]:
    if not tasks:
        return
    if cfg.dask:
        try:
            import distributed
        except ImportError:
            raise ValueError(
                "--dask needs the 'distributed' package: pip install 'chaingeo[cluster]'"
            ) from None
        client: Any = distributed.Client(cfg.dask)  # type: ignore[no-untyped-call]
        try:
            futures = client.map(run_episode, list(tasks), pure=False)
            by_key = {f.key: t for f, t in zip(futures, tasks, strict=True)}
            completed: Any = distributed.as_completed(futures)  # type: ignore[no-untyped-call]
            for fut in completed:
                yield _collected(fut, by_key[fut.key])
        finally:
            client.close()
        return
    if cfg.jobs <= 1:
        for t in tasks:
            yield _played(t)
        return
    ctx = multiprocessing.get_context("spawn")
    with cf.ProcessPoolExecutor(
        max_workers=cfg.jobs,
        mp_context=ctx,
        initializer=_die_with_parent,
        initargs=(os.getpid(),),
    ) as pool:
        submitted = {pool.submit(run_episode, t): t for t in tasks}
        pending = set(submitted)
        try:
            while pending:
                finished, pending = cf.wait(pending, return_when=cf.FIRST_COMPLETED)
                for fut in sorted(finished, key=lambda f: submitted[f].key):
                    yield _collected(fut, submitted[fut])
        finally:
            for fut in pending:
                fut.cancel()


def _cost(prices: PriceTable, rec: dict[str, Any]) -> float | None:
    """The agent's tokens at its model's price, plus a model judge's at the judge's."""
    cost = prices.cost(rec.get("model"), Usage.from_json(rec["usage"]))
    judge = rec.get("judge")
    if judge and cost is not None:
        extra = prices.cost(judge.get("model"), Usage.from_json(judge["usage"]))
        cost = None if extra is None else cost + extra
    return cost


def _secrets(agent: AgentSpec, protocol: ProtocolConfig) -> list[str]:
    """Every secret the agent or a model judge may send, to be scrubbed from whatever is logged."""
    out = [v for v in agent.secrets.values() if v]
    for options in (agent.options, protocol.judge_options):
        key = api_key(options)
        if key:
            out.append(key)
    return out


class RunOutcomes(list[Outcome]):
    """What :func:`evaluate` returns: every recorded episode's outcome (a list, in the log's
    order), with the run's header and the tool refusals its records note, so a caller reports
    the run without reading it back."""

    def __init__(
        self, outcomes: Sequence[Outcome], header: dict[str, Any], tools_refused: list[str]
    ) -> None:
        super().__init__(outcomes)
        self.header = header
        #: Each episode's note that its server refused native tools (played in text instead).
        self.tools_refused = tools_refused


def _refusals(records: Sequence[dict[str, Any]]) -> list[str]:
    return [
        str(r["agent_notes"]["tools_refused"])
        for r in records
        if isinstance(r.get("agent_notes"), dict) and r["agent_notes"].get("tools_refused")
    ]


def evaluate(
    levels: Sequence[Level],
    agent: AgentSpec,
    run_dir: str | Path,
    protocol: ProtocolConfig | None = None,
    config: RunConfig | None = None,
    prices: PriceTable | None = None,
    stream: TextIO | None = None,
) -> RunOutcomes:
    """Run (or continue) one agent over ``levels``; returns every recorded episode's outcome."""
    protocol = protocol or ProtocolConfig()
    cfg = config or RunConfig()
    prices = prices or PriceTable.load()
    if cfg.samples < 1:
        raise ValueError("samples must be >= 1")
    make_agent(agent).close()  # bad options fail here, before anything is written
    ids = [lv.id for lv in levels]
    if len(set(ids)) != len(ids):
        raise ValueError("duplicate level ids in the suite")
    header = make_header(
        agent=agent.to_json(),
        protocol=protocol.to_json(),
        level_set_hash=level_set_hash(levels),
        levels=ids,
        seed=cfg.seed,
        samples=cfg.samples,
        extra={"label": agent.label, "agent_transport": agent.transport()},
    )
    log = RunLog.create(run_dir, header, resume=cfg.resume, secrets=_secrets(agent, protocol))
    done = log.finished_keys(retry_errors=cfg.retry_errors)
    tasks = [
        EpisodeTask(lv, s, cfg.seed, agent, protocol)
        for lv in levels
        for s in range(cfg.samples)
        if EpisodeTask(lv, s, cfg.seed, agent, protocol).key not in done
    ]
    bar = ProgressBar(agent.label, len(levels) * cfg.samples, stream, cfg.progress)
    for rec in log.latest().values():
        if rec["key"] in done:
            bar.add(rec, resumed=True)
    try:
        for result in _execute(tasks, cfg):
            for png in result.images.values():
                log.put_image(png)  # stored under its SHA-256, the name the record uses
            rec = result.record
            rec["cost_usd"] = _cost(prices, rec)
            log.append(rec)
            bar.add(rec)
    finally:
        bar.close()
        log.close()
    latest = list(log.latest().values())
    return RunOutcomes([Outcome.from_record(r) for r in latest], header, _refusals(latest))
