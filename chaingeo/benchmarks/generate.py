"""``chain bench generate``: accepted stacking levels per second per core, per mode and box.

Each (box, mode) makes items 0..n-1 of one seed serially in this process (one core), without
pictures, after a warm-up that compiles every numba kernel (JIT time is not in the figures).
The reference, timed in the same run, is the exact-cover engine counting all 11520 packings
of the Soma cube: each row also says how many such counts one level costs, which travels
between machines better than seconds. Environment: ``CHAIN_BENCH_GENERATE_ITEMS`` overrides
the items per row.

A second section makes standard six-piece burrs (``--shape burr6x8``, min level 1 so every item
that comes apart counts) and prints the histogram of their levels and the seconds per item
(o_i included). One item is 20 to 50 s, so the default run makes 3 (1 with ``--quick``);
``CHAIN_BENCH_BURR_ITEMS=100`` gives the histogram per 100 items.
"""

from __future__ import annotations

import argparse
import json
import os
import time
from typing import Any

BOXES = ((2, 3, 4), (3, 3, 4), (4, 4, 4))
MODES = ("easy", "mid", "hard")
SEED = 2026


def _reference_seconds(repeat: int) -> float:
    from chaingeo.core.piecesets import SOMA
    from chaingeo.solvers.cover.packings import count_packings

    best = float("inf")
    for _ in range(max(1, repeat)):
        t0 = time.perf_counter()
        res = count_packings(SOMA.pieces, (3, 3, 3), distinct=False)
        best = min(best, time.perf_counter() - t0)
    if res.solutions != 11520:  # the reference must be the published figure
        raise RuntimeError(f"Soma 3x3x3 counted {res.solutions} packings, expected 11520")
    return best


def _warm_up() -> None:
    from chaingeo.generator.config import stacking_config
    from chaingeo.generator.stacking import make

    for mode in MODES:
        make(stacking_config((2, 3, 3), mode), SEED, 10_000)


def run(args: argparse.Namespace) -> int:
    from chaingeo.generator.config import box_text, stacking_config
    from chaingeo.generator.stacking import make

    items = int(os.environ.get("CHAIN_BENCH_GENERATE_ITEMS", 2 if args.quick else 6))
    _warm_up()
    ref = _reference_seconds(args.repeat)
    print(
        f"reference: count all 11520 Soma 3x3x3 packings = {ref * 1e3:.1f} ms (best of "
        f"{max(1, args.repeat)})"
    )
    print(f"{'box':<7} {'mode':<5} {'levels':>6} {'items':>5} {'s/level':>8} "
          f"{'levels/s/core':>13} {'Soma counts/level':>17}")  # fmt: skip
    rows: list[dict[str, Any]] = []
    for box in BOXES:
        for mode in MODES:
            cfg = stacking_config(box, mode)
            t0 = time.perf_counter()
            accepted = sum(not hasattr(make(cfg, SEED, i), "reason") for i in range(items))
            secs = time.perf_counter() - t0
            per = secs / accepted if accepted else float("inf")
            rate = accepted / secs
            row = {
                "box": box_text(box),
                "mode": mode,
                "accepted": accepted,
                "items": items,
                "seconds_per_level": round(per, 4),
                "levels_per_second_per_core": round(rate, 3),
                "reference_ratio": round(per / ref, 1) if accepted else None,
            }
            rows.append(row)
            print(f"{row['box']:<7} {mode:<5} {accepted:>6} {items:>5} {per:>8.3f} "
                  f"{rate:>13.2f} {row['reference_ratio']!s:>17}")  # fmt: skip
    burrs = _standard_burrs(int(os.environ.get("CHAIN_BENCH_BURR_ITEMS", 1 if args.quick else 3)))
    print(
        json.dumps(
            {
                "benchmark": "generate",
                "reference_seconds": round(ref, 5),
                "rows": rows,
                "standard_burrs": burrs,
            }
        )
    )
    return 0


def _standard_burrs(items: int) -> dict[str, Any]:
    """Items 0..items-1 of :data:`SEED` with ``--shape burr6x8``: level histogram, s / item."""
    from chaingeo.generator.config import PuzzleConfig
    from chaingeo.generator.puzzle import make

    make(PuzzleConfig(shape="burr6x8", hill_steps=50), SEED, 10_000)  # compile the kernels
    cfg = PuzzleConfig(shape="burr6x8", min_level=1)
    histogram: dict[str, int] = {}
    seconds: list[float] = []
    for i in range(items):
        t0 = time.perf_counter()
        item = make(cfg, SEED, i)
        seconds.append(time.perf_counter() - t0)
        stats = getattr(item, "stats", None)
        key = str(stats["first_level"]) if stats is not None else "rejected"
        histogram[key] = histogram.get(key, 0) + 1
    order = sorted(histogram, key=lambda k: (k == "rejected", int(k) if k.isdigit() else 0))
    per = sum(seconds) / max(1, items)
    print(f"standard burrs (burr6x8, seed {SEED}): {items} items, {per:.1f} s / item, levels:")
    print("  " + "  ".join(f"{k}: {histogram[k]}" for k in order))
    return {
        "shape": "burr6x8",
        "items": items,
        "seconds_per_item": round(per, 2),
        "max_seconds": round(max(seconds, default=0.0), 2),
        "levels": {k: histogram[k] for k in order},
    }
