"""``chain export-dataset [LEVELS...] --out DIR``: the levels as a Hugging Face dataset folder.

Two configurations (``levels``: one row per level; ``demonstrations``: one chat turn pair per
step of each optimal plan) as Parquet shards, plus the dataset card ``README.md``
(:mod:`chaingeo.envs.dataset`, :mod:`chaingeo.envs.dataset_card`). ``datasets.load_dataset(DIR,
"levels")`` reads it. The same levels give the same bytes. Needs ``pip install
'chaingeo[dataset]'`` (pyarrow).
"""

from __future__ import annotations

import argparse
import json
from typing import Any

from chaingeo.cli.out_arg import add_out


def register(sub: Any) -> None:
    from chaingeo.cli.level_arg import add_level_list

    p = sub.add_parser(
        "export-dataset", help="write levels and demonstrations as a Hugging Face dataset folder"
    )
    add_level_list(p)
    add_out(p, "folder", "the dataset (data files and README.md card)", required=True)
    p.add_argument(
        "--split",
        default="test",
        choices=("train", "validation", "test"),
        help="split name of these levels (the shipped suite is the test split)",
    )
    p.add_argument("--image-size", type=int, default=512, help="pixels per picture side")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from chaingeo.cli.errors import CommandError
    from chaingeo.cli.level_arg import levels_of
    from chaingeo.cli.out_arg import out_folder
    from chaingeo.core.files import atomic_write, folder_locked
    from chaingeo.envs.dataset import DatasetError, export_dataset
    from chaingeo.envs.dataset_card import dataset_card
    from chaingeo.envs.demos import DemonstrationError
    from chaingeo.generator.signature import level_signature

    levels = levels_of(args)
    signatures = {lv.id: level_signature(lv) for lv in levels}
    out_folder(args.out)  # an existing file is one error line (it was NotADirectoryError)
    with folder_locked(args.out):  # a second writer of the same folder is refused
        try:
            summary = export_dataset(
                levels,
                args.out,
                split=args.split,
                image_size=args.image_size,
                signatures=signatures,
            )
        except (DatasetError, DemonstrationError) as e:
            raise CommandError(str(e)) from e
        card = dataset_card(args.out, levels, args.split, summary.rows)
        atomic_write(args.out / "README.md", card.encode("utf-8"))
    files = sorted(str(f.relative_to(args.out)) for fs in summary.files.values() for f in fs)
    print(json.dumps({"split": args.split, "rows": summary.rows, "bytes": summary.bytes,
                      "files": files}, sort_keys=True))  # fmt: skip
    return 0
