"""BurrTools' command-line solver ``burrTxt``, the oracle our BurrTools figures are measured
against: found or built from its sources beside the project, run, and its output read.

BurrTools is GPL and is never copied into the project: ``../shared/burrtools-src`` holds its
sources and a ``build-burrtxt`` script (g++, zlib), which builds the binary into a cache folder
once. ``CHAIN_BURRTXT`` names a binary to use instead. ``burrTxt -d -r FILE`` prints one
``level: a.b.c`` line per solution it takes apart and a last line
``N assemblies and M solutions found with K iterations``; it always drops mirror and rotated
duplicates (compare with ``mirrors="drop"``).
"""

from __future__ import annotations

import argparse
import os
import re
import shutil
import subprocess
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Final

from chaingeo.core.errors import ChainGeoError

#: The folder beside the checkout that holds BurrTools' sources (``CHAIN_BURRTOOLS_SRC``).
SOURCES_ENV: Final = "CHAIN_BURRTOOLS_SRC"
BINARY_ENV: Final = "CHAIN_BURRTXT"
CACHE_ENV: Final = "CHAIN_BURRTXT_CACHE"
_FINAL = re.compile(r"(\d+) assemblies and (\d+) solutions found with (\d+) iterations")
_LEVEL = re.compile(r"^level: ([0-9.]+)\s*$", re.MULTILINE)


class BurrTxtError(ChainGeoError, RuntimeError):
    """burrTxt could not be built, or did not finish with its final line."""


@dataclass(frozen=True)
class BurrTxtResult:
    assemblies: int
    solutions: int
    levels: tuple[str, ...]  # one per solution, in burrTxt's order
    iterations: int
    seconds: float  # the whole process, wall clock


def sources_dir() -> Path | None:
    """``$CHAIN_BURRTOOLS_SRC``, else ``../shared/burrtools-src`` beside the checkout."""
    env = os.environ.get(SOURCES_ENV)
    path = Path(env) if env else Path(__file__).resolve().parents[3] / "shared" / "burrtools-src"
    return path if (path / "build-burrtxt").is_file() else None


def why_unavailable() -> str | None:
    """Why burrTxt cannot be had here (None: it can)."""
    if os.environ.get(BINARY_ENV):
        return None
    if sources_dir() is None:
        return "BurrTools' sources (../shared/burrtools-src) are not present"
    if shutil.which("g++") is None:
        return "g++ is not installed (needed to build burrTxt; CI installs g++ and zlib1g-dev)"
    return None


def burrtxt_binary(timeout: float = 900.0) -> Path:
    """The burrTxt binary: ``$CHAIN_BURRTXT``, else built (once, cached; into
    ``$CHAIN_BURRTXT_CACHE`` when set) from the sources. :class:`BurrTxtError` says why not."""
    env = os.environ.get(BINARY_ENV)
    if env:
        return Path(env)
    reason = why_unavailable()
    src = sources_dir()
    if reason is not None or src is None:
        raise BurrTxtError(reason or "no sources")
    args = ["bash", str(src / "build-burrtxt")]
    if os.environ.get(CACHE_ENV):
        args.append(os.environ[CACHE_ENV])
    try:
        build = subprocess.run(args, capture_output=True, text=True, timeout=timeout, check=False)
    except (subprocess.SubprocessError, OSError) as e:
        raise BurrTxtError(f"building burrTxt failed: {e}") from None
    lines = build.stdout.strip().splitlines()
    if build.returncode != 0 or not lines or not os.access(lines[-1], os.X_OK):
        raise BurrTxtError(f"building burrTxt failed: {build.stderr.strip()[-500:]}")
    return Path(lines[-1])


def run_burrtxt(
    binary: Path, puzzle: str | os.PathLike[str], *, timeout: float = 120.0, problem: int = 0
) -> BurrTxtResult:
    """``burrTxt -d -r -o PROBLEM FILE``: assemblies, solutions and every solution's level.
    ``subprocess.TimeoutExpired`` past ``timeout``; :class:`BurrTxtError` without a final line."""
    t0 = time.perf_counter()
    done = subprocess.run(
        [str(binary), "-d", "-r", "-o", str(problem), str(puzzle)],
        capture_output=True,
        text=True,
        timeout=timeout,
        check=False,
    )
    seconds = time.perf_counter() - t0
    final = _FINAL.search(done.stdout)
    if final is None:
        raise BurrTxtError(f"{puzzle}: no final line (status {done.returncode})")
    return BurrTxtResult(
        int(final.group(1)),
        int(final.group(2)),
        tuple(_LEVEL.findall(done.stdout)),
        int(final.group(3)),
        seconds,
    )


# -- chain bench burrtxt: whole processes, ours against burrTxt ---------------------------------

#: Files whose whole process stays below this are "small": the target is under 0.35 s there.
SMALL_SECONDS: Final = 0.2


@dataclass(frozen=True)
class BurrTxtCase:
    name: str
    path: Path
    problem: int


def instances(folder: Path, quick: bool) -> list[BurrTxtCase]:
    """BurrTools' own example files (when present), our BurrTools examples, and every shipped
    puzzle level without turns, written as ``.xmpuzzle`` files into ``folder``."""
    from chaingeo.core.formats.bt_level import level_puzzle
    from chaingeo.core.formats.burrtools import read_xmpuzzle, write_xmpuzzle
    from chaingeo.core.level import load_levels
    from chaingeo.core.rules import PuzzleRules
    from chaingeo.core.suite import suite_folder
    from chaingeo.generator.bt_examples import EXAMPLES

    out: list[BurrTxtCase] = []
    shared = Path(__file__).resolve().parents[3] / "shared" / "burrtools"
    for path in sorted(shared.glob("*.xmpuzzle")) if shared.is_dir() else []:
        n = len(read_xmpuzzle(path).problems)
        out.extend(
            BurrTxtCase(f"{path.stem}#{i}" if n > 1 else path.stem, path, i) for i in range(n)
        )
    for name, build in EXAMPLES.items():
        puzzle = build()
        path = write_xmpuzzle(puzzle, folder / f"{name}.xmpuzzle")
        n = len(puzzle.problems)
        out.extend(BurrTxtCase(f"{name}#{i}" if n > 1 else name, path, i) for i in range(n))
    for level in load_levels(suite_folder("puzzle")):
        if isinstance(level.rules, PuzzleRules) and level.rules.turns:
            continue  # BurrTools has no turns
        path = write_xmpuzzle(level_puzzle(level), folder / f"{level.id}.xmpuzzle")
        out.append(BurrTxtCase(level.id, path, 0))
    if quick:
        out = [i for i in out if i.name in QUICK]
    return out


QUICK: Final = ("linked_rings", "puzzle-mid-04-burr12", "puzzle-easy-07-burr3", "AlPackino")


def run_ours(instance: BurrTxtCase, seconds: float) -> tuple[float, dict[str, Any]]:
    """``chain analyze FILE --mirrors drop --no-optimal`` as a whole process (its own default
    kernels): wall seconds and the JSON it printed (``error`` when it failed)."""
    import json
    import sys

    cmd = [sys.executable, "-m", "chaingeo.cli.main", "analyze", str(instance.path)]
    cmd += ["--problem", str(instance.problem), "--mirrors", "drop", "--no-optimal"]
    cmd += ["--seconds", str(seconds)]
    t0 = time.perf_counter()
    try:
        done = subprocess.run(cmd, capture_output=True, text=True, timeout=seconds + 30)
    except subprocess.TimeoutExpired:
        return time.perf_counter() - t0, {"error": "timeout"}
    wall = time.perf_counter() - t0
    if done.returncode not in (0, 1) or not done.stdout.strip():  # 1: counts cut short
        return wall, {"error": done.stderr.strip()[-300:]}
    return wall, dict(json.loads(done.stdout.splitlines()[-1]))


def compare(instance: BurrTxtCase, binary: Path, seconds: float, repeat: int) -> dict[str, Any]:
    """One row: both sides' figures and best whole-process wall times, and their ratio."""
    bt: BurrTxtResult | None = None
    bt_s = ours_s = float("inf")
    ours: dict[str, Any] = {}
    for _ in range(max(repeat, 1)):
        try:
            bt = run_burrtxt(binary, instance.path, timeout=seconds, problem=instance.problem)
            bt_s = min(bt_s, bt.seconds)
        except (subprocess.TimeoutExpired, BurrTxtError):
            bt = None
        wall, ours = run_ours(instance, seconds)
        ours_s = min(ours_s, wall)
        if bt is None or "error" in ours:
            break
    row: dict[str, Any] = {"instance": instance.name, "problem": instance.problem}
    keys = ("assemblies", "solutions", "level", "kernels", "counts_complete")
    row["ours"] = {k: ours[k] for k in keys if k in ours}
    if "error" in ours:
        row["ours"] = {"error": ours["error"]}
    row["seconds"] = round(ours_s, 3)
    if bt is not None:
        first = bt.levels[0] if bt.levels else None
        row["burrtxt"] = {"assemblies": bt.assemblies, "solutions": bt.solutions, "level": first}
        row["burrtxt_seconds"] = round(bt_s, 3)
        row["ratio"] = round(ours_s / bt_s, 2) if bt_s > 0 and "error" not in ours else None
        # Our line names the first solution's level; burrTxt lists one per solution.
        row["agree"] = (
            ours.get("counts_complete", True) is True
            and (ours.get("assemblies"), ours.get("solutions")) == (bt.assemblies, bt.solutions)
            and (ours.get("level") in bt.levels or (not bt.levels and ours.get("level") is None))
        )
    else:
        row["burrtxt"] = {"error": f"no result within {seconds:g} s"}
    return row


def run(args: argparse.Namespace) -> int:
    """Every instance through both whole processes; a summary line last: how many agree, the
    largest ratio where burrTxt takes over :data:`SMALL_SECONDS`, the slowest small file."""
    import json
    import tempfile

    reason = why_unavailable()
    if reason is not None:
        print(json.dumps({"skipped": reason}))
        return 0
    binary = burrtxt_binary()
    seconds = float(os.environ.get("CHAIN_BENCH_BT_SECONDS", "20" if args.quick else "120"))
    rows = []
    with tempfile.TemporaryDirectory(prefix="chain-bench-burrtxt-") as tmp:
        for instance in instances(Path(tmp), args.quick):
            row = compare(instance, binary, seconds, args.repeat)
            rows.append(row)
            print(json.dumps(row, sort_keys=True), flush=True)
    print(json.dumps(summary(rows), sort_keys=True))
    return 0


def summary(rows: list[dict[str, Any]]) -> dict[str, Any]:
    timed = [r for r in rows if isinstance(r.get("burrtxt_seconds"), float)]
    big = [r for r in timed if r["burrtxt_seconds"] > SMALL_SECONDS and r["ratio"] is not None]
    small = [r for r in timed if r["burrtxt_seconds"] <= SMALL_SECONDS]
    return {
        "instances": len(rows),
        "agree": sum(1 for r in rows if r.get("agree") is True),
        "burrtxt_failed": len(rows) - len(timed),
        "max_ratio_where_burrtxt_over_0.2s": max((r["ratio"] for r in big), default=None),
        "slowest_small_file_seconds": max((r["seconds"] for r in small), default=None),
    }
