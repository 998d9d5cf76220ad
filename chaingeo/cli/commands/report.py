"""``chain report RUN...``: the paper's tables over run directories, and the cost plot."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any


def register(sub: Any) -> None:
    p = sub.add_parser(
        "report",
        help="Table 1, difficulty and protocol tables (markdown + CSV) and the cost plot",
    )
    p.add_argument("runs", nargs="+", type=Path, help="run directories, or folders of them")
    p.add_argument("--out", type=Path, default=Path("report"), help="where to write files")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from chaingeo.evaluation.report import find_runs, load_run, tables, write_report

    runs = [load_run(p) for p in find_runs(args.runs)]
    for _, table in tables(runs):
        print(table.markdown())
    for path in write_report(runs, args.out):
        print(f"wrote {path}")
    return 0
