"""Counting with worker processes: ``chain analyze --jobs 1`` against ``--jobs N``, and burrTxt.

Each row runs three whole processes on one file, in the same run, each ``--repeat`` times
(interleaved, best wall time kept): BurrTools' burrTxt, ``chain analyze --no-optimal --jobs 1``
and ``--jobs N`` (N: the machine's cores, at least 2). It reports their wall times and CPU
seconds (the process and its workers), ``scaling`` (jobs 1 wall / jobs N wall), ``cpu_ratio``
(jobs N CPU / jobs 1 CPU), ``balance`` (least / most counting CPU of a worker), ``vs_burrtxt``
(burrTxt wall / jobs N wall; above 1: faster than burrTxt), whether the two lines of ours are the
same bytes (wall time aside) and whether they agree with burrTxt's counts. The machine's load
average is printed with each row: on a busy machine the workers get no more cores than it has
free. Needs burrTxt (:mod:`chaingeo.benchmarks.burrtxt`).
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any, Final

from chaingeo.benchmarks.burrtxt import (
    BurrTxtError,
    burrtxt_binary,
    run_burrtxt,
    why_unavailable,
)

#: Shipped levels counted: the 518,400-assembly luban (full run) and a small cube (quick).
FULL: Final = ("puzzle-mid-03-luban-15-piece", "puzzle-mid-02-interlocking-cube")
QUICK: Final = ("puzzle-mid-02-interlocking-cube",)


def _children_cpu() -> float:
    ru = resource.getrusage(resource.RUSAGE_CHILDREN)
    return ru.ru_utime + ru.ru_stime


def run_ours(path: Path, jobs: int, seconds: float) -> tuple[float, float, str, list[float]]:
    """``chain analyze PATH --no-optimal --jobs JOBS`` as a whole process: wall seconds, CPU
    seconds (it and its workers), its JSON line without the wall time and the counting CPU
    seconds of each worker (from its standard error; empty with one)."""
    cmd = [sys.executable, "-m", "chaingeo.cli.main", "analyze", str(path), "--no-optimal"]
    cmd += ["--jobs", str(jobs), "--seconds", str(seconds)]
    cpu = _children_cpu()
    t0 = time.perf_counter()
    done = subprocess.run(cmd, capture_output=True, text=True, timeout=seconds + 60, check=False)
    wall = time.perf_counter() - t0
    line = done.stdout.strip().splitlines()[-1] if done.stdout.strip() else "{}"
    row = json.loads(line)
    row.pop("seconds", None)
    row.pop("file", None)
    return wall, _children_cpu() - cpu, json.dumps(row, sort_keys=True), _workers(done.stderr)


def _workers(stderr: str) -> list[float]:
    marker = "counting CPU seconds per worker: "
    for line in stderr.splitlines():
        if marker in line:
            return [float(x) for x in line.split(marker, 1)[1].split(",")]
    return []


def compare(name: str, path: Path, binary: Path, jobs: int, repeat: int) -> dict[str, Any]:
    """One row (see the module's docstring)."""
    seconds = 600.0
    best = {"burrtxt": float("inf"), "jobs1": float("inf"), "jobsN": float("inf")}
    cpu = {"jobs1": 0.0, "jobsN": 0.0}
    lines: dict[str, str] = {}
    workers: list[float] = []
    bt = None
    for _ in range(max(repeat, 1)):
        try:
            bt = run_burrtxt(binary, path, timeout=seconds)
            best["burrtxt"] = min(best["burrtxt"], bt.seconds)
        except (subprocess.TimeoutExpired, BurrTxtError):
            bt = None
        for key, n in (("jobs1", 1), ("jobsN", jobs)):
            wall, used, lines[key], per_worker = run_ours(path, n, seconds)
            if wall < best[key]:
                best[key], cpu[key] = wall, used
                workers = per_worker if key == "jobsN" else workers
    ours = json.loads(lines["jobsN"])
    row: dict[str, Any] = {"instance": name, "jobs": jobs, "load": os.getloadavg()[0]}
    row.update({f"{k}_seconds": round(v, 3) for k, v in best.items()})
    row.update({f"{k}_cpu_seconds": round(v, 3) for k, v in cpu.items()})
    row["ours"] = {k: ours.get(k) for k in ("assemblies", "solutions", "convention")}
    row["same_bytes"] = lines["jobs1"] == lines["jobsN"]
    row["scaling"] = round(best["jobs1"] / best["jobsN"], 2)
    # CPU that N workers spend against one (the cost of cutting and merging), and how evenly
    # they shared it (least / most busy worker): figures a busy machine does not distort.
    row["cpu_ratio"] = round(cpu["jobsN"] / cpu["jobs1"], 2) if cpu["jobs1"] else None
    row["worker_cpu_seconds"] = workers
    busiest = max(workers, default=0.0)
    row["balance"] = round(min(workers) / busiest, 2) if busiest > 0 else None
    if bt is not None:
        row["burrtxt"] = {"assemblies": bt.assemblies, "solutions": bt.solutions}
        row["vs_burrtxt"] = round(best["burrtxt"] / best["jobsN"], 2)
        row["agree"] = (ours.get("assemblies"), ours.get("solutions")) == (
            bt.assemblies,
            bt.solutions,
        )
    return row


def run(args: argparse.Namespace) -> int:
    from chaingeo.core.formats.bt_level import level_puzzle
    from chaingeo.core.formats.burrtools import write_xmpuzzle
    from chaingeo.core.suite import load_level
    from chaingeo.solvers.jobs import default_jobs

    reason = why_unavailable()
    if reason is not None:
        print(json.dumps({"skipped": reason}))
        return 0
    binary = burrtxt_binary()
    jobs = max(2, default_jobs())
    with tempfile.TemporaryDirectory(prefix="chain-bench-jobs-") as tmp:
        for name in QUICK if args.quick else FULL:
            path = write_xmpuzzle(level_puzzle(load_level(name)), Path(tmp) / f"{name}.xmpuzzle")
            row = compare(name, path, binary, jobs, args.repeat)
            print(json.dumps(row, sort_keys=True), flush=True)
    return 0
