"""Our own optimal-plan video of every shipped puzzle level (and of every 4th shipped stacking
level), judged with its level: the measurement behind the false-alarm tests
(``python -m tests.judge_sweep [NAME...]``).

Renders are cached as GIFs in a temporary folder (``JUDGE_SWEEP_DIR``, default
``/tmp/judge-sweep``), never in the repository: a video is rendered once per machine.
"""

from __future__ import annotations

import os
import sys
import time
from pathlib import Path
from typing import Any

from chaingeo.core.level import Level, load_level
from chaingeo.core.suite import suite_folder
from chaingeo.worldmodel.judge_video import judge_video
from chaingeo.worldmodel.video import plan_video, write_gif

SIZE = 256


def cache_dir() -> Path:
    out = Path(os.environ.get("JUDGE_SWEEP_DIR", "/tmp/judge-sweep"))
    out.mkdir(parents=True, exist_ok=True)
    return out


def puzzle_levels() -> list[str]:
    return sorted(p.stem for p in suite_folder("puzzle").glob("*.json"))


def stacking_levels() -> list[str]:
    """Every 4th shipped stacking level: a spread of sizes at a quarter of the render time."""
    return sorted(p.stem for p in suite_folder("stacking").glob("*.json"))[::4]


def level(name: str) -> Level:
    family = "stacking" if name.startswith("stack") else "puzzle"
    return load_level(suite_folder(family) / f"{name}.json")


def rendered(name: str) -> Path:
    """The level's optimal-plan GIF at SIZE, rendered on first use."""
    path = cache_dir() / f"{name}-{SIZE}.gif"
    if not path.exists():
        tmp = path.with_suffix(".part.gif")
        write_gif(plan_video(level(name), size=SIZE), tmp)
        tmp.replace(path)
    return path


def judged(name: str) -> dict[str, Any]:
    return judge_video(rendered(name), level(name))


def main(names: list[str]) -> int:
    failed = 0
    names = names or puzzle_levels() + stacking_levels()
    for name in names:
        t0 = time.perf_counter()
        report = judged(name)
        secs = time.perf_counter() - t0
        why = "; ".join(f"{v['kind']}@{v['frame']} {v['detail']}" for v in report["violations"])
        failed += not report["valid"]
        fit = "unfit" if any("not decidable" in u for u in report["undecided"]) else "fit  "
        verdict = "ok  " if report["valid"] else "FAIL"
        print(f"{name:40s} {verdict} {fit} {secs:5.1f}s {why}", flush=True)
    print(f"{len(names) - failed} pass, {failed} fail")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
