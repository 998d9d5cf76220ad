"""``chain demos``: demonstrations from each level's stored optimal plan, as JSONL.

Each line is one step of a level's plan replayed through its Gymnasium environment: the
observation text shown before the action, the action text, the reward, the episode flags and the
feedback (:mod:`chaingeo.envs.demos`). Canonical JSON, levels sorted by id: the same levels give
the same bytes.
"""

from __future__ import annotations

import argparse
import contextlib
import sys
from typing import Any

from chaingeo.cli.out_arg import add_out


def register(sub: Any) -> None:
    from chaingeo.cli.level_arg import add_level_list

    p = sub.add_parser("demos", help="write demonstrations (optimal plans replayed) as JSONL")
    add_level_list(p)
    add_out(p, "file", "the JSONL demonstrations; - for standard output", default="-", type=str)
    p.add_argument("--text-state", action="store_true", help="show every piece's cells too")
    p.add_argument("--history", type=int, default=5, help="recent turns shown")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from chaingeo.cli.errors import CommandError
    from chaingeo.cli.level_arg import levels_of
    from chaingeo.core.files import atomic_path
    from chaingeo.envs.demos import DemonstrationError, demonstration_lines

    levels = levels_of(args)
    options = {"text_state": args.text_state, "history_window": args.history}
    count = 0
    with contextlib.ExitStack() as files:
        out = (
            sys.stdout
            if args.out == "-"
            else files.enter_context(
                files.enter_context(atomic_path(args.out)).open("w", encoding="ascii", newline="\n")
            )
        )
        try:
            for line in demonstration_lines(levels, **options):
                out.write(line + "\n")
                count += 1
        except DemonstrationError as e:
            raise CommandError(str(e)) from e
    print(f"{count} steps of {len(levels)} level(s)", file=sys.stderr)
    return 0
