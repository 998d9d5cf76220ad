"""``chain report RUN...``: the paper's tables over run directories, the cost plot, and with
``--html DIR`` a static site to browse the runs (leaderboard, levels, every episode's turns)."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from chaingeo.cli.out_arg import add_out


def register(sub: Any) -> None:
    p = sub.add_parser(
        "report",
        help="Table 1, difficulty and protocol tables (markdown + CSV), the cost plot, "
        "and optionally an HTML run viewer",
    )
    p.add_argument("runs", nargs="+", type=Path, help="run directories, or folders of them")
    add_out(p, "folder", "the tables (markdown + CSV) and the plot", default=Path("report"))
    p.add_argument(
        "--html",
        type=Path,
        metavar="DIR",
        help="also write a static site here (open DIR/index.html; no server, no network)",
    )
    p.add_argument(
        "--prices",
        type=Path,
        action="append",
        default=[],
        help="the extra price table the runs used, to price each turn in the site",
    )
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from chaingeo.evaluation.report.tables import find_runs, load_run, tables, write_report
    from chaingeo.evaluation.usage import PriceTable

    runs = [load_run(p) for p in find_runs(args.runs)]
    for _, table in tables(runs):
        print(table.markdown())
    from chaingeo.core.files import folder_locked

    with folder_locked(args.out):  # a second writer of the same folder is refused
        written = write_report(runs, args.out)
    for path in written:
        print(f"wrote {path}")
    if args.html is not None:
        from chaingeo.evaluation.report.site import write_site

        site = write_site(runs, args.html, PriceTable.load(*args.prices))
        print(f"wrote {site / 'index.html'}")
    return 0
