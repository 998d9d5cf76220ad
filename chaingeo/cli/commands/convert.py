"""``chain convert``: move levels between our format and the original CHAIN stacking JSON."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any


def register(sub: Any) -> None:
    p = sub.add_parser("convert", help="import/export the original CHAIN stacking JSON format")
    p.add_argument("source", type=Path)
    p.add_argument("target", type=Path)
    p.add_argument(
        "--to",
        choices=("chain-level", "chain-json"),
        required=True,
        help="chain-level: import an original file; chain-json: export one of ours",
    )
    p.add_argument("--id", help="level id on import (default: the file name)")
    p.add_argument("--difficulty", default="easy", choices=("easy", "mid", "hard"))
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from chaingeo.core.formats.chain_json import read_chain_stacking, write_chain_stacking
    from chaingeo.core.level import load_level, save_level

    if args.to == "chain-level":
        save_level(read_chain_stacking(args.source, args.id, args.difficulty), args.target)
    else:
        write_chain_stacking(load_level(args.source), args.target)
    print(args.target)
    return 0
