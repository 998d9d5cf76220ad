"""``chain questions``: multiple-choice questions with proven answers, their pictures, and the
files VLMEvalKit and lmms-eval read (:mod:`chaingeo.generator.questions`,
:mod:`chaingeo.evaluation.question_files`). The same levels and seed write the same bytes."""

from __future__ import annotations

import argparse
import sys
import time
from collections import Counter
from pathlib import Path
from typing import Any


def register(sub: Any) -> None:
    from chaingeo.cli.level_arg import add_level_list

    p = sub.add_parser("questions", help="multiple-choice questions with proven answers")
    add_level_list(p)
    p.add_argument(
        "--out",
        type=Path,
        required=True,
        metavar="DIR",
        help="folder for questions.jsonl, images/, questions.tsv and lmms-eval/",
    )
    p.add_argument("--seed", type=int, default=0, help="random seed")
    p.add_argument(
        "--category",
        action="append",
        default=None,
        metavar="NAME",
        help="only this category (repeatable; default: all)",
    )
    p.add_argument(
        "--no-pictures",
        action="store_true",
        help="write questions.jsonl only (no images, TSV or lmms-eval task)",
    )
    p.add_argument(
        "--hf",
        type=Path,
        metavar="DIR",
        help="also write the questions configuration of the Hugging Face dataset export there",
    )
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from chaingeo.cli.level_arg import levels_of
    from chaingeo.evaluation.question_files import (
        write_hf_questions,
        write_lmms_task,
        write_questions,
        write_vlmeval_tsv,
    )
    from chaingeo.generator.questions import LETTERS, generate_questions

    levels = levels_of(args)
    t0 = time.perf_counter()
    questions = generate_questions(levels, args.seed, args.category)
    t1 = time.perf_counter()
    shown = write_questions(
        questions, {lv.id: lv for lv in levels}, args.out, pictures=not args.no_pictures
    )
    if not args.no_pictures:
        write_vlmeval_tsv(shown, args.out / "images", args.out / "questions.tsv")
        write_lmms_task(shown, args.out / "images", args.out / "lmms-eval")
        if args.hf is not None:
            write_hf_questions(shown, args.out / "images", args.hf)
    t2 = time.perf_counter()
    per = Counter(q.category for q in questions)
    letters = Counter(q.letter for q in questions)
    n = len(questions)
    for cat, k in sorted(per.items()):
        print(f"{cat:12s} {k:6d}", file=sys.stderr)
    share = "  ".join(f"{c} {100 * letters[c] / max(n, 1):.1f}%" for c in LETTERS)
    print(
        f"{n} questions in {len(per)} categories from {len(levels)} level(s); answers {share}; "
        f"questions {t1 - t0:.1f} s, pictures and files {t2 - t1:.1f} s",
        file=sys.stderr,
    )
    return 0
