"""``chain bench judge``: the video judge's detection rate per corruption class and its false
alarms on clean videos, on the seeded set of :mod:`chaingeo.worldmodel.corrupt`.

Two disjoint seed ranges: the tuning range (seeds from 0; the judge's thresholds were chosen
looking at these) and the held-out range (seeds from 1,000,000; never looked at while tuning).
Each holds, per class, PER_CLASS corrupted videos and CLEAN clean ones, half flat (our renders)
and half shaded. The judge runs without the level (colours clustered from the video, as for a
video model's clip). A case is caught when a violation of an accepted kind (``ACCEPT``) starts
within the corruption's onset (two frames before to eight after) and names one of the pieces
involved (by colour name, or by its evidence mask lying on the piece). Every rate carries its
95% Wilson interval. ``--quick``: a fifth of the cases. Cases are cached under
``$CHAINGEO_JUDGE_BENCH_DIR`` (default ``/tmp/chaingeo-judge-bench``); processes:
``$CHAINGEO_BENCH_JOBS`` (default 2).
"""

from __future__ import annotations

import argparse
import math
import os
import pickle
import time
from collections import defaultdict
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import Any, Final

import numpy as np

from chaingeo.worldmodel.corrupt import ACCEPT, CLASSES, STYLES, Case, make_case

#: Cases per class and clean cases: held-out range, and the (smaller) tuning range.
PER_CLASS: Final = 32
CLEAN: Final = 100
TUNE_PER_CLASS: Final = 16
TUNE_CLEAN: Final = 50
TUNING: Final = 0
HELD_OUT: Final = 1_000_000
#: Verdict frames counted as the onset: this many before its first frame, after its last.
EARLY, LATE = 2, 8


def wilson(k: int, n: int, z: float = 1.96) -> tuple[float, float]:
    """The 95% Wilson score interval of k successes in n trials."""
    if n == 0:
        return 0.0, 1.0
    p = k / n
    den = 1 + z * z / n
    mid = (p + z * z / (2 * n)) / den
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / den
    return max(0.0, mid - half), min(1.0, mid + half)


def plan(base: int, per_class: int, clean: int) -> list[tuple[int, str, str]]:
    """(seed, class, style) of every case of a range: classes in turn, styles alternating."""
    kinds = [k for _ in range(per_class) for k in CLASSES] + ["clean"] * clean
    n = len(CLASSES)
    return [
        (base + i, kind, STYLES[(i // n if kind != "clean" else i) % 2])
        for i, kind in enumerate(kinds)
    ]


def _cache() -> Path:
    out = Path(os.environ.get("CHAINGEO_JUDGE_BENCH_DIR", "/tmp/chaingeo-judge-bench"))
    out.mkdir(parents=True, exist_ok=True)
    return out


def cached_case(seed: int, kind: str, style: str) -> Case:
    from chaingeo.worldmodel import corrupt

    path = _cache() / f"{seed}-{kind}-{style}-{corrupt.VERSIONS.get(kind, 1)}.pkl"
    if path.exists():
        with open(path, "rb") as f:
            case: Case = pickle.load(f)
        return case
    case = make_case(seed, kind, style)
    tmp = path.with_suffix(f".{os.getpid()}.part")
    with open(tmp, "wb") as f:
        pickle.dump(case, f)
    tmp.replace(path)
    return case


def score(case: Case, violations: list[Any]) -> bool:
    """Whether the verdict catches the case (clean: whether it raises any alarm)."""
    if case.kind == "clean":
        return bool(violations)
    accept = ACCEPT[case.kind]
    for e in violations:
        if e.kind not in accept or not case.frame - EARLY <= e.frame <= case.end + LATE:
            continue
        named = {n.split("-")[0] for n in (e.piece, e.other) if n}
        if named & set(case.pieces) or _on_truth(case, e.masks):
            return True
    return False


def _on_truth(case: Case, masks: tuple[Any, ...]) -> bool:
    from chaingeo.worldmodel.judge_segment import dilate

    for m in masks:
        for truth in case.truth:
            near = m.shape == truth.shape and m.any()
            if near and float((m & dilate(truth, 3)).sum()) >= 0.3 * float(m.sum()):
                return True
    return False


def judge_case(item: tuple[int, str, str]) -> tuple[int, str, str, bool | None, list[str], float]:
    """Build (or load) one case and judge it: (seed, class, style, caught, violations, s)."""
    from chaingeo.worldmodel.judge_video import judge_frames

    seed, kind, style = item
    try:
        case = cached_case(seed, kind, style)
    except RuntimeError as e:  # no visible corruption of that class from this seed
        return seed, kind, style, None, [str(e)], 0.0
    t0 = time.perf_counter()
    verdict = judge_frames(list(case.frames))
    secs = time.perf_counter() - t0
    said = [f"{e.kind}@{e.frame}:{e.piece}" for e in verdict.violations]
    return seed, kind, style, score(case, list(verdict.violations)), said, secs


def run_range(items: list[tuple[int, str, str]], jobs: int) -> list[Any]:
    if jobs <= 1:
        return [judge_case(i) for i in items]
    with ProcessPoolExecutor(jobs) as pool:
        return list(pool.map(judge_case, items, chunksize=2))


def table(rows: list[Any], title: str) -> list[str]:
    """Per class (and style) detections, and false alarms, each with its interval."""
    out = [title, f"  {'class':20s} {'style':7s} {'caught':>9s}  {'rate':>6s}  95% Wilson"]
    groups: dict[tuple[str, str], list[bool]] = defaultdict(list)
    for _, kind, style, caught, _, _ in rows:
        if caught is None:
            continue
        groups[(kind, style)].append(caught)
        groups[(kind, "both")].append(caught)
    for kind in (*CLASSES, "clean"):
        for style in (*STYLES, "both"):
            got = groups.get((kind, style), [])
            if not got:
                continue
            k, n = sum(got), len(got)
            lo, hi = wilson(k, n)
            label = "false alarm" if kind == "clean" else kind
            out.append(
                f"  {label:20s} {style:7s} {k:4d}/{n:<4d}  {k / n:6.1%}  [{lo:.1%}, {hi:.1%}]"
            )
    return out


def run(args: argparse.Namespace) -> int:
    jobs = int(os.environ.get("CHAINGEO_BENCH_JOBS", "2"))
    q = 5 if args.quick else 1
    sizes = {TUNING: (TUNE_PER_CLASS // q, TUNE_CLEAN // q), HELD_OUT: (PER_CLASS // q, CLEAN // q)}
    print("chain bench judge: the video judge on seeded corruptions of our plan videos")
    print("  judged without the level (colours clustered from the video)")
    for base, name in ((TUNING, "tuning"), (HELD_OUT, "held-out")):
        t0 = time.perf_counter()
        rows = run_range(plan(base, *sizes[base]), jobs)
        unbuilt = [r for r in rows if r[3] is None]
        rows = [r for r in rows if r[3] is not None]
        secs = [r[5] for r in rows]
        head = (
            f"{name} seeds {base}..{base + len(rows) - 1}"
            f" ({'looked at while tuning' if base == TUNING else 'never looked at while tuning'}):"
            f" {len(rows)} videos in {time.perf_counter() - t0:.0f} s,"
            f" judging {np.mean(secs):.2f} +- {np.std(secs) / math.sqrt(len(secs)):.2f} s a video"
        )
        for line in table(rows, head):
            print(line)
        if unbuilt:
            print(f"  {len(unbuilt)} seeds gave no visible corruption and were left out")
        if os.environ.get("CHAINGEO_JUDGE_BENCH_VERBOSE"):
            for r in rows:
                ok = "ok" if r[3] != (r[1] == "clean") else "MISS"
                print(f"    {r[0]} {r[1]} {r[2]} {ok} {r[4]}")
    return 0
