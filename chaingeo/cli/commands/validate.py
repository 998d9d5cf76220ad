"""``chain validate PATH...``: load and fully verify level files, print a summary line each."""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any


def register(sub: Any) -> None:
    p = sub.add_parser("validate", help="verify level files (format, geometry, stored solutions)")
    p.add_argument("paths", nargs="+", type=Path, help="level files or folders of them")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from chaingeo.core.level import content_hash, level_set_hash, load_level

    files: list[Path] = []
    for path in args.paths:
        files.extend(sorted(path.rglob("*.json")) if path.is_dir() else [path])
    levels = []
    for f in files:
        lv = load_level(f)
        levels.append(lv)
        print(
            json.dumps(
                {
                    "file": str(f),
                    "id": lv.id,
                    "family": lv.family,
                    "difficulty": lv.difficulty,
                    "optimal_steps": lv.optimal_steps,
                    "content_hash": content_hash(lv),
                }
            )
        )
    print(json.dumps({"levels": len(levels), "level_set_hash": level_set_hash(levels)}))
    return 0
