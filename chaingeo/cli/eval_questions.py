"""``chain eval --questions FILE``: agents asked the questions of `chain questions` single
turn, scored per category with the three baselines (:mod:`chaingeo.evaluation.question_eval`).

Agents: ``openai`` (a model on an OpenAI-compatible server, asked with and without the
pictures), ``oracle`` (the proven answers: a check of the harness) and ``random``; without
``--agent`` only the baselines run."""

from __future__ import annotations

import argparse
import sys
from typing import TYPE_CHECKING, Any

from chaingeo.cli.errors import CommandError

if TYPE_CHECKING:
    from chaingeo.evaluation.question_eval import Answerer


def _answerers(args: argparse.Namespace, agent_options: dict[str, Any]) -> list[Answerer]:
    from chaingeo.evaluation.question_eval import ModelAnswerer, OracleAnswerer

    out: list[Answerer] = []
    for name in args.agent or []:
        if name == "oracle":
            out.append(OracleAnswerer())
        elif name == "openai":
            options = dict(agent_options)
            for key in ("model", "base_url", "api_key_env", "label"):
                if getattr(args, key, None):
                    options[key] = getattr(args, key)
            if not options.get("model"):
                raise CommandError("--agent openai needs --model")
            out.append(ModelAnswerer(options, pictures=True, seed=args.seed))
            out.append(ModelAnswerer(options, pictures=False, seed=args.seed))
        elif name != "random":  # random is always a baseline column
            raise CommandError(f"--questions: agent {name!r} cannot answer questions; "
                               "use openai, oracle or random")  # fmt: skip
    return out


def run_questions(args: argparse.Namespace, agent_options: dict[str, Any]) -> int:
    from chaingeo.evaluation.question_eval import evaluate_questions
    from chaingeo.evaluation.question_files import read_questions

    path = args.questions
    if not path.is_file():
        raise CommandError(f"--questions: no file {path}")
    every = read_questions(path)
    asked = [q for q in every if args.split == "all" or q.split == args.split]
    train = [q for q in every if q.split == "train"]
    if not asked:
        raise CommandError(f"{path}: no questions in split {args.split!r}")
    if not train:
        train = asked
        print("no train split: the most-frequent baseline learns on the questions asked",
              file=sys.stderr)  # fmt: skip
    images = path.parent / "images"
    report = evaluate_questions(asked, train, images if images.is_dir() else None,
                                _answerers(args, agent_options), seed=args.seed)  # fmt: skip
    print(f"{len(asked)} questions ({args.split}); accuracy % [95% Wilson interval]")
    print(report)
    return 0
